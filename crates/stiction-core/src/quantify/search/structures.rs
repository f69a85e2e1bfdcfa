//! The linear structures searched: the pilots, the search per structure in rounds, and what a
//! staged search carries to the whole record.

use super::*;

/// The structures searched first: for two-parameter models the Stenman answer's; a staged
/// search's best of the first samples; the distinct structures the pilots choose, best one-step
/// fit first; and always the structure of a valve without stiction, so the answer is never worse
/// than the linear loop it is compared with. Also returns the Stenman band for two-parameter
/// models (their first guesses).
pub(super) fn starting_structures(
    op: &[f64],
    setup: &Setup,
    req: &QuantifyRequest,
    hint: Option<&Hint>,
    work: &mut Work,
) -> Result<(VecDeque<Structure>, Option<f64>), EstimateError> {
    let Setup {
        search,
        bounds,
        data,
        ..
    } = setup;
    // pilot: the process family and a first structure, chosen at a spread of stiction parameters
    // (a staged search runs them again on the whole record: the first samples may be too few
    // to tell the structure); a quarter of the spread is enough to add the whole record's
    let step = if hint.is_some() { 4 } else { 1 };
    let pilots: Vec<Vec<f64>> = pilot_points(req.model, bounds)
        .into_iter()
        .step_by(step)
        .collect();
    let mut ranked: Vec<identify::Selection> = pilots
        .par_iter()
        .filter_map(|theta| {
            let model = req.model.build(theta).ok()?;
            identify::select(
                data,
                &identify::centred(&model.simulate_from(op, req.valve_start)),
                search,
            )
        })
        .collect();
    work.evaluations += pilots.len() as u64;
    ranked.sort_by(|a, b| a.one_step_bic.total_cmp(&b.one_step_bic));
    let mut queue: VecDeque<Structure> = VecDeque::new();
    // two-parameter models start from the Stenman answer (structure and band), which the exact
    // search finds reliably
    let mut stenman_d = None;
    if req.model.dim() == 2 {
        let mut sreq = QuantifyRequest::new(ModelKind::Stenman, Method::Exact);
        sreq.ts = req.ts;
        sreq.max_delay = req.max_delay;
        sreq.integrating = req.integrating;
        sreq.bounds = Some(vec![(bounds[0].0, bounds[0].1.max(bounds[1].1))]);
        let sq = quantify(op, data.pv, &sreq)?;
        work.evaluations += sq.evaluations;
        if let (Some(lm), Some(d)) = (&sq.linear_model, sq.params.get("d")) {
            queue.push_back(Structure {
                integrating: lm.family == LinearFamily::Integrating,
                na: lm.na,
                nb: lm.nb,
                nk: lm.nk,
            });
            stenman_d = Some(*d);
        }
    }
    if let Some(h) = hint {
        queue.extend(h.structures.iter().take(STARTING_STRUCTURES / 2));
    }
    for c in &ranked {
        if !queue.contains(&c.structure) && queue.len() < STARTING_STRUCTURES {
            queue.push_back(c.structure);
        }
    }
    let lows: Vec<f64> = bounds.iter().map(|b| b.0).collect();
    if let Some(sel) = req.model.build(&lows).ok().and_then(|m| {
        identify::select(
            data,
            &identify::centred(&m.simulate_from(op, req.valve_start)),
            search,
        )
    }) {
        if !queue.contains(&sel.structure) {
            queue.push_back(sel.structure);
        }
    }
    Ok((queue, stenman_d))
}

/// Search the stiction parameters for each structure; confirm the structure at each answer and
/// search again with a new one if it differs. Returns every searched structure with its
/// simulation criterion.
pub(super) fn search_structures(
    op: &[f64],
    setup: &Setup,
    req: &QuantifyRequest,
    hint: Option<&Hint>,
    queue: &mut VecDeque<Structure>,
    stenman_d: Option<f64>,
    work: &mut Work,
) -> Vec<Tried> {
    let mut tried: Vec<Tried> = Vec::new();
    while !queue.is_empty() && tried.len() < MOST_STRUCTURES {
        // the structures of this round: for Stenman exact all queued ones share one walk
        let mut round: Vec<Structure> = Vec::new();
        while let Some(s) = queue.pop_front() {
            if !tried.iter().any(|t| t.structure == s)
                && !round.contains(&s)
                && tried.len() + round.len() < MOST_STRUCTURES
            {
                round.push(s);
            }
            if req.method != Method::Exact && !round.is_empty() {
                break;
            }
        }
        if round.is_empty() {
            break;
        }
        let problems: Vec<Hammerstein> = round
            .iter()
            .map(|&s| Hammerstein::new(req.model, op, &setup.data, s, req.valve_start))
            .collect();
        let outcomes = search_round(&problems, setup, req, hint, stenman_d, work);
        // a walk shared by several structures counts once
        work.evaluations += outcomes.iter().map(|o| o.evaluations).max().unwrap_or(0);
        for (problem, outcome) in problems.iter().zip(outcomes) {
            let mv_c = problem.valve(&outcome.best);
            let criterion = problem.fit(&outcome.best).map_or(f64::INFINITY, |f| {
                identify::level_simulation_bic(&setup.data, &mv_c, &f)
            });
            tried.push(Tried {
                structure: problem.prepared.structure(),
                outcome,
                criterion,
            });
            work.evaluations += 1;
            // confirm the structure at this answer; a different one is searched next, first
            if let Some(next) = identify::select(&setup.data, &mv_c, &setup.search) {
                if !tried.iter().any(|t| t.structure == next.structure)
                    && !queue.contains(&next.structure)
                {
                    queue.push_front(next.structure);
                }
            }
        }
    }
    tried
}

/// One round's searches: the exact walk shared by all its structures, or one heuristic search.
pub(super) fn search_round(
    problems: &[Hammerstein],
    setup: &Setup,
    req: &QuantifyRequest,
    hint: Option<&Hint>,
    stenman_d: Option<f64>,
    work: &mut Work,
) -> Vec<Outcome> {
    let bounds = &setup.bounds;
    match req.method {
        Method::Exact => exact_stenman(
            problems,
            bounds[0],
            req.full_partition,
            hint.map(|h| h.ranges.as_slice()),
        ),
        Method::Grid => vec![grid_search(&problems[0], bounds, &req.grid)],
        Method::Aco | Method::AcoR => {
            let problem = &problems[0];
            work.seed = Some(req.seed);
            let mut rng = seeded(req.seed);
            let mut ev = Evaluator::new(problem);
            if req.method == Method::Aco {
                let mut s = aco::PaperAco::new(req.aco.clone(), req.model, bounds);
                solver::run(&mut s, &mut ev, &mut rng, req.aco.iterations, false);
            } else {
                // the Stenman band is a good first guess for the two-parameter models:
                // Kano and Choudhury with J = S, He with fd = 0 behave alike
                let seeds = stenman_d
                    .map(|d| first_guesses(req.model, d))
                    .unwrap_or_default();
                let mut s = acor::Acor::new(req.acor.clone(), req.model, bounds).with_seeds(seeds);
                solver::run(&mut s, &mut ev, &mut rng, req.acor.iterations, false);
            }
            let (best, cost, polish_evals) = polish(problem, ev.best(), ev.best_cost(), bounds);
            let (interval, extra) = axis_intervals(problem, &best, bounds, cost);
            vec![Outcome {
                best,
                interval,
                interval_kind: IntervalKind::Axis,
                evaluations: ev.evaluations() + extra + polish_evals,
                cells: None,
                top_cells: Vec::new(),
            }]
        }
    }
}

/// For a staged search: the structures best first, and the best cells of the two best, merged.
pub(super) fn hint_for_whole_record(tried: &[Tried]) -> Hint {
    Hint {
        structures: tried.iter().map(|t| t.structure).collect(),
        ranges: merged_top_cells(tried.iter().take(2).map(|t| &t.outcome)),
    }
}
