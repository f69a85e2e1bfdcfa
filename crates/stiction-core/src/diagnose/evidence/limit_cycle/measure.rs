//! What the loop family measures: the identified loop, the observed cycle, and the valve whose
//! describing function closes the harmonic balance.

use super::{
    DescribingBand, LoopEvidence, ProcessSource, CALIBRATION, LIMIT_NEAR, MIN_HARMONICS, MIN_PI_R2,
    NOISE_FREE_CYCLE, PERIOD_MATCH, PI_CUTOFF,
};
use crate::diagnose::evidence::Context;
use crate::loop_analysis::cycle::{share, share_above_noise};
use crate::loop_analysis::describing::{harmonic_balance, nearest, valve_loci, ValveLocus};
use crate::loop_analysis::frequency::pi_response;
use crate::loop_analysis::{identify_pi_below, AmplitudeTrend, Complex64, Cycles, OpenLoop};
use crate::spectral::harmonic_distortion;
use std::f64::consts::PI;

/// Everything the vote reads, or why the family cannot judge.
pub(super) fn measure(ctx: &Context) -> Result<LoopEvidence, String> {
    let osc = &ctx.oscillation;
    let periods = osc.periods_in_record.unwrap_or(0.0);
    let period = match osc.period {
        Some(p) if osc.oscillating && periods >= ctx.req.min_periods => p,
        _ => {
            return Err(if osc.oscillating {
                format!("only {periods:.1} oscillation periods with a constant setpoint; the loop family needs {}", ctx.req.min_periods)
            } else {
                "no oscillation above the noise: a loop that does not cycle has no limit cycle to explain".into()
            })
        }
    };
    let Some(fits) = &ctx.fits else {
        return Err("no process model could be fitted from OP to PV".into());
    };
    let (process, source) = match (&fits.stiction_model, &fits.linear_model) {
        (Some(f), _) if f.stable() => (f, ProcessSource::StictionFit),
        (_, Some(f)) => (f, ProcessSource::LinearFit),
        _ => return Err("no stable process model could be fitted from OP to PV".into()),
    };
    let ts = ctx.req.ts;
    // the controller's law below a few times the cycle's frequency, where the loop cycles
    let Some(pi) = identify_pi_below(ctx.op, &ctx.error, ts, PI_CUTOFF * ts / period) else {
        return Err("OP or the control error does not move: no controller to identify".into());
    };
    let caveat = ctx.sp.is_none().then(|| {
        format!(
            "no setpoint recorded: the error is taken as the PV's deviation from {}; the inner loop of a cascade, whose setpoint moves with the outer loop, \
             would weaken this evidence",
            match ctx.setpoint_steps {
                0 => "its mean".to_string(),
                n => format!("the setpoint read off the record ({})", crate::diagnose::gates::plural(n, "step", "steps")),
            }
        )
    });
    if pi.r2 < MIN_PI_R2 {
        return Err(format!(
            "OP does not follow a PI law of the {} (R² {:.2} of its increments){}",
            if ctx.sp.is_some() {
                "control error"
            } else {
                "PV (no setpoint recorded: a cascade's moving setpoint?)"
            },
            pi.r2,
            ""
        ));
    }
    let [s, e] = osc.stretch;
    let (op, pv) = (&ctx.op[s..e], &ctx.pv[s..e]);
    let Some(cycles) = Cycles::find(op, period / ts) else {
        return Err("fewer than 4 whole cycles of OP to measure".into());
    };
    let samples_per_cycle = cycles.period();
    let period = samples_per_cycle * ts;
    let theta = 2.0 * PI * ts / period;
    let op_c = cycles.coefficients(op);
    let pv_c = cycles.coefficients(pv);
    let residual_share = unexplained_share(ctx, &fits.pv_stiction, &cycles, &pv_c, [s, e]);
    // what the PI makes of the error's cycles, against OP's
    let unexplained: Vec<(f64, Complex64)> = cycles
        .coefficients(&ctx.error[s..e])
        .iter()
        .zip(&op_c)
        .map(|(&(th, e1), &(_, o1))| (th, o1 - pi_response(&pi, th) * e1))
        .collect();
    let controller_residual_share = share(&unexplained, &op_c);
    let amps: Vec<f64> = op_c.iter().map(|(_, z)| z.norm()).collect();
    let amplitude = AmplitudeTrend::of(&amps);
    let phase_wander = cycles.phase_wander(op);
    let op_amplitude = amps.iter().sum::<f64>() / amps.len() as f64;
    let pv_amplitude = pv_c.iter().map(|(_, z)| z.norm()).sum::<f64>() / pv_c.len() as f64;
    let harmonic_count = measurable_harmonics(samples_per_cycle);
    let harmonics = (harmonic_count >= MIN_HARMONICS)
        .then(|| {
            [op, pv]
                .iter()
                .filter_map(|x| harmonic_distortion(x, 1.0 / samples_per_cycle, harmonic_count))
                .reduce(f64::max)
        })
        .flatten();
    let open = OpenLoop { process, pi: &pi };
    let margins = open.margins(theta / 20.0, ts);
    let needed = -1.0 / open.response(theta);
    let describing = describing_band(ctx, &open, needed, period, op_amplitude);
    Ok(LoopEvidence {
        controller: pi.clone(),
        setpoint_recorded: ctx.sp.is_some(),
        process: source,
        margins,
        period,
        op_amplitude,
        pv_amplitude,
        harmonics,
        samples_per_cycle,
        harmonic_count: if harmonics.is_some() {
            harmonic_count
        } else {
            0
        },
        residual_share,
        controller_residual_share,
        op_at_limit: at_limit(op, period / ts, ctx.req.op_range),
        amplitude,
        phase_wander,
        needed_gain: needed.norm(),
        needed_lag_degrees: -needed.arg().to_degrees(),
        describing,
        stiction_basis: None,
        caveat,
        calibration: CALIBRATION.into(),
    })
}

/// The share of the PV's cycle (over `stretch`, whose cycles' coefficients are `pv_c`) that the
/// stiction fit's simulated PV `sim` leaves unexplained. PV's measurement noise in a cycle's
/// fundamental is no unexplained input; the noise is estimated from PV's differences, which a
/// cycle of few samples would swell, so it is taken off only on cycles of at least
/// [`NOISE_FREE_CYCLE`] samples.
fn unexplained_share(
    ctx: &Context,
    sim: &[f64],
    cycles: &Cycles,
    pv_c: &[(f64, Complex64)],
    [s, e]: [usize; 2],
) -> f64 {
    let pv = &ctx.pv[s..e];
    let residual: Vec<f64> = if sim.len() == ctx.pv.len() {
        pv.iter().zip(&sim[s..e]).map(|(a, b)| a - b).collect()
    } else {
        pv.to_vec()
    };
    let residual_c = cycles.coefficients(&residual);
    if cycles.period() >= NOISE_FREE_CYCLE {
        share_above_noise(&residual_c, pv_c, ctx.pv_noise)
    } else {
        share(&residual_c, pv_c)
    }
}

/// How many harmonics (up to 5) of a cycle of `samples_per_cycle` samples lie, with their bands of
/// ±0.3 of the fundamental, below the Nyquist frequency (as `harmonic_distortion` requires).
pub(crate) fn measurable_harmonics(samples_per_cycle: f64) -> usize {
    ((0.5 * samples_per_cycle - 0.3).floor().max(0.0) as usize).min(5)
}

/// Share of the cycles whose OP comes within [`LIMIT_NEAR`] of the range's ends (the analysed
/// stretch leaves out the samples at a limit, so their neighbours show it).
fn at_limit(op: &[f64], period: f64, [lo, hi]: [f64; 2]) -> f64 {
    // an OP outside the range is in other units (normalised, engineering): its limits are not
    // the range's (as the usable-stretch rule decides)
    if op.iter().any(|v| *v < lo || *v > hi) {
        return 0.0;
    }
    let near = LIMIT_NEAR * (hi - lo);
    share_of_cycles(op, period, |c| {
        c.iter().any(|v| *v <= lo + near || *v >= hi - near)
    })
}

/// The share of the cycles of `x` (consecutive windows of `samples`, rounded, at least 2; a tail
/// under half a window is no cycle) for which `hit` holds.
pub(crate) fn share_of_cycles<T>(x: &[T], samples: f64, hit: impl Fn(&[T]) -> bool) -> f64 {
    let w = samples.round().max(2.0) as usize;
    let cycles: Vec<&[T]> = x.chunks(w).filter(|c| c.len() * 2 >= w).collect();
    let n = cycles.iter().filter(|c| hit(c)).count();
    n as f64 / cycles.len().max(1) as f64
}

/// The valve describing function nearest `needed`, its band for the observed OP amplitude, and the
/// period its harmonic balance with the identified loop predicts.
fn describing_band(
    ctx: &Context,
    open: &OpenLoop,
    needed: Complex64,
    period: f64,
    op_amplitude: f64,
) -> Option<DescribingBand> {
    let ts = ctx.req.ts;
    let loci = valve_loci(period / ts);
    let near = nearest(&loci, needed)?;
    let band = op_amplitude / near.ratio;
    let theta0 = 2.0 * PI * ts / period;
    let locus: Vec<&ValveLocus> = loci
        .iter()
        .filter(|l| l.kind == near.kind && l.slip_ratio == near.slip_ratio)
        .collect();
    let predicted = locus.first().and_then(|l| {
        harmonic_balance(&open.nyquist(theta0 / 20.0), &l.points)
            .into_iter()
            .min_by(|a, b| {
                (a.theta / theta0)
                    .ln()
                    .abs()
                    .total_cmp(&(b.theta / theta0).ln().abs())
            })
            .map(|b| 2.0 * PI * ts / b.theta)
    });
    Some(DescribingBand {
        model: near.kind,
        slip_ratio: near.slip_ratio,
        band,
        band_percent_of_span: ctx.req.percent_of_span(band),
        amplitude_over_band: near.ratio,
        distance: near.distance,
        predicted_period: predicted,
        period_matches: predicted.is_some_and(|p| (p / period).ln().abs() <= PERIOD_MATCH.ln()),
    })
}
