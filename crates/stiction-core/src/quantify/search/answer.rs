//! The answer: the best structure's parameters, fit and warnings, as a `Quantification`.

use super::*;

/// The R² in simulation of the best linear model of the structure's family with a valve that
/// follows OP exactly: the chosen structure, and the structure of the same family the search
/// picks for it. An unstable fit's simulation runs away: no answer rather than an R² of -1e50.
pub(super) fn r2_without_stiction(
    problem: &Hammerstein,
    setup: &Setup,
    structure: Structure,
) -> Option<f64> {
    let mv0 = problem.valve(&vec![0.0; problem.kind.dim()]);
    let mut same = setup.search.clone();
    same.integrating = structure.integrating;
    same.self_regulating = !structure.integrating;
    let chosen = problem
        .prepared
        .fit(&mv0)
        .filter(Fit::stable)
        .map(|f| f.r2_simulation());
    let reselected = identify::select(&setup.data, &mv0, &same)
        .and_then(|sel| identify::fit(&setup.data, &mv0, sel.structure))
        .filter(Fit::stable)
        .map(|f| f.r2_simulation());
    match (chosen, reselected) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
    .filter(|v| v.is_finite())
}

/// Warnings about the answer: a poor fit, a parameter at the top of its range, too few moves.
pub(super) fn answer_warnings(
    fit: &Fit,
    outcome: &Outcome,
    bounds: &[(f64, f64)],
    names: &[&str],
    mv: &[f64],
) -> Vec<String> {
    let mut warnings = Vec::new();
    if fit.r2_simulation() < 0.5 {
        warnings.push(format!(
            "the simulated PV explains only {:.0} % of its variance: the stiction model and a linear process \
             do not describe this loop well; treat the estimate with care",
            100.0 * fit.r2_simulation().max(0.0)
        ));
    }
    for (p, &(lo, hi)) in bounds.iter().enumerate() {
        if let Some([a, b]) = outcome.interval.get(names[p]) {
            if *b >= hi && outcome.best[p] > lo + 0.5 * (hi - lo) {
                warnings.push(format!(
                    "{} reaches the top of its search range [{lo}, {hi}] ({a:.4} to {b:.4} fit equally): widen --bounds",
                    names[p]
                ));
            }
        }
    }
    let moves = mv.windows(2).filter(|w| w[1] != w[0]).count();
    if moves < 4 {
        warnings.push(format!(
            "the estimated valve moves only {moves} times: too few to identify the process"
        ));
    }
    warnings
}

/// The quantification from the best structure's outcome; `Err(reason)` when its fit is unusable.
pub(super) fn result(
    op: &[f64],
    setup: &Setup,
    req: &QuantifyRequest,
    best: Tried,
    work: &Work,
    started: Instant,
) -> Result<Quantification, String> {
    let Tried {
        structure, outcome, ..
    } = best;
    let problem = Hammerstein::new(req.model, op, &setup.data, structure, req.valve_start);
    let Some(fit) = problem.fit(&outcome.best) else {
        return Err("the best valve trajectory leaves the linear fit singular".into());
    };
    if !fit.sse_simulation.is_finite() {
        return Err("no candidate gives a stable simulation of the PV".into());
    }
    let model = req.model.build(&outcome.best).expect("repaired");
    let mv = model.simulate_from(op, req.valve_start);
    let pv_simulated = identify::simulate_pv(&setup.data, &problem.valve(&outcome.best), &fit);
    let phys = identify::physical(&fit, req.ts);
    let names = req.model.param_names();
    let r2_without = r2_without_stiction(&problem, setup, structure);
    let band = match req.model {
        ModelKind::Stenman => outcome.best[0],
        ModelKind::He => outcome.best[0] + outcome.best[1],
        ModelKind::Kano | ModelKind::Choudhury => outcome.best[0],
    };
    let warnings = answer_warnings(&fit, &outcome, &setup.bounds, &names, &mv);
    let search = &setup.search;
    let s = fit.structure;
    let with_start = matches!(req.model, ModelKind::Stenman | ModelKind::He);
    Ok(Quantification {
        status: QuantifyStatus::Ok,
        reason: None,
        model: req.model,
        method: req.method,
        params: names
            .iter()
            .zip(&outcome.best)
            .map(|(n, &v)| (n.to_string(), v))
            .collect(),
        interval: outcome.interval,
        interval_kind: outcome.interval_kind,
        linear_model: Some(LinearModel {
            family: if s.integrating {
                LinearFamily::Integrating
            } else {
                LinearFamily::SelfRegulating
            },
            na: s.na,
            nb: s.nb,
            nk: s.nk,
            a: fit.a.clone(),
            b: fit.b.clone(),
            c: fit.c,
            gain: phys.gain,
            time_constant: phys.time_constant,
            dead_time: phys.dead_time,
            criterion: format!(
                "BIC of one-step prediction over na in {:?}, nb 1..={}, delay 1..={} samples, {}",
                search.na,
                search.nb_max,
                search.nk_max,
                match (search.self_regulating, search.integrating) {
                    (true, true) => "self-regulating and integrating",
                    (true, false) => "self-regulating",
                    _ => "integrating",
                }
            ),
        }),
        fit: Some(FitQuality {
            output: if s.integrating {
                FitOutput::DeltaPv
            } else {
                FitOutput::Pv
            },
            r2_simulation: fit.r2_simulation(),
            r2_one_step: fit.r2_one_step(),
            sse_simulation: fit.sse_simulation,
            r2_simulation_without_stiction: r2_without,
        }),
        apparent_stiction: Some(band),
        apparent_stiction_pct_of_op_range: Some(100.0 * band / setup.op_range),
        op_range: setup.op_range,
        evaluations: work.evaluations,
        cells: outcome.cells,
        valve_start: with_start.then(|| req.valve_start.unwrap_or(op[0])),
        valve_start_kind: with_start.then(|| {
            if req.valve_start.is_some() {
                ValveStartKind::Given
            } else {
                ValveStartKind::FirstOp
            }
        }),
        seconds: started.elapsed().as_secs_f64(),
        samples: op.len(),
        ts: req.ts,
        seed: work.seed,
        warnings,
        caveat: CAVEAT.into(),
        mv,
        pv_simulated,
    })
}
