//! The oracles without the band, and the one that sees OP only at the recorded samples.

use super::hidden;
use super::kalman::{llrs, FullRun, Llr};
use super::profile;
use super::Pick;
use stiction_core::models::{Model, Stenman};
use stiction_core::sim::ClosedLoop;
use stiction_core::sim::Process;
use stiction_lab::catalogue::BenchmarkLoop;

/// The band-unknown oracle: the log Bayes factor of "a Stenman valve of some band" against a
/// healthy valve, the band's likelihood averaged over `bands` log-uniform in the suite's range
/// (0.5-5 % of span, the catalogue's prior), each band's valve started as the simulator starts it.
/// With the prior right, "stiction when the factor exceeds 1" is the test with the smallest sum of
/// the two errors over sticky loops and twins among all tests that do not know the band.
pub fn band_unknown(setup: &ClosedLoop, run: &FullRun, bands: usize) -> Llr {
    let each: Vec<Llr> = profile::band_grid(bands)
        .map(|d| llrs(setup, &Model::Stenman(Stenman { d }), run))
        .collect();
    let mean = |pick: Pick| {
        let top = each.iter().map(pick).fold(f64::NEG_INFINITY, f64::max);
        top + (each.iter().map(|l| (pick(l) - top).exp()).sum::<f64>() / bands as f64).ln()
    };
    Llr {
        known_load: mean(|l| l.known_load),
        every_step: mean(|l| l.every_step),
        recorded: mean(|l| l.recorded),
    }
}

/// The band-unknown oracle's ratios on a Stenman loop and its twin, and the "recorded" oracle's
/// with OP too seen only at the recorded samples (held between them), band known and unknown.
pub struct Unknown {
    pub sticky: Llr,
    pub twin: Llr,
    pub held_known: (f64, f64),
    pub held: (f64, f64),
    pub interpolated_known: (f64, f64),
    pub interpolated: (f64, f64),
    /// The load's model known, PV at the recorded samples, OP at every execution, band known,
    /// under a process a little off the truth (`hidden::OFF`): sticky loop, twin.
    pub off: [(f64, f64); 3],
    /// The same with the process as the closed-loop fit identifies it (`hidden::identified`),
    /// band known and unknown: (sticky loop, twin) each.
    pub identified: Option<((f64, f64), (f64, f64))>,
    /// The same with the process profiled under each hypothesis (`profile::profiled_llr`), band
    /// known: (sticky loop, twin).
    pub profiled: (f64, f64),
    /// The same over a wide grid (`profile::WIDE`, 0.25-4 times the truth).
    pub profiled_wide: (f64, f64),
    /// The wide profile with the band free too (`profile::profiled_band_free_llr`).
    pub profiled_band_free: (f64, f64),
    /// The coordinate search's ratios (`kalman::searched_llr`): band free; band, noise and drift
    /// free. (Sticky loop, twin) each.
    pub searched: [(f64, f64); 2],
    /// The search with everything free, started from the process the closed-loop fit identifies.
    pub searched_identified: Option<(f64, f64)>,
    /// The wide profile with the band free, centred on the process the closed-loop fit
    /// identifies (the noise as the record shows it; the drift's intensity still known).
    pub profiled_identified: Option<(f64, f64)>,
    /// The wide profile with the band free around the true process, the noise as the record
    /// shows it.
    pub profiled_noise_read: (f64, f64),
    /// The wide profile with the band free around the fit's process, the true noise.
    pub profiled_fit_true_noise: Option<(f64, f64)>,
}

/// The loop a search or profile starts from: the fit's process (`fit`), its time constant at
/// least a sample (`ts`) and its dead time at least 0.25 s, the noise as
/// `detect::measurement_noise` reads it from the record's `pv`.
fn from_fit(fit: &ClosedLoop, pv: &[f64], ts: f64) -> ClosedLoop {
    let mut s = noise_read(fit, pv);
    match &mut s.process {
        Process::Foptd { tau, delay, .. } => {
            *tau = tau.max(ts);
            *delay = delay.max(0.25);
        }
        Process::Integrating { delay, .. } => *delay = delay.max(0.25),
        Process::Soptd { .. } => {}
    }
    s
}

/// The loop with the noise as `detect::measurement_noise` reads it from the record's `pv`.
fn noise_read(s: &ClosedLoop, pv: &[f64]) -> ClosedLoop {
    let mut s = s.clone();
    s.noise = stiction_core::detect::measurement_noise(pv).max(1e-3);
    s
}

/// The run with OP as the historian has it: held from one recorded sample to the next (before
/// the record, the controller's own).
pub fn held(run: &FullRun) -> FullRun {
    let mut op = run.op.clone();
    let mut at = run.recorded.iter().peekable();
    let mut last = None;
    for (t, o) in op.iter_mut().enumerate() {
        while at.peek().is_some_and(|&&j| j <= t) {
            last = at.next().map(|&j| run.op[j]);
        }
        if let Some(v) = last {
            *o = v;
        }
    }
    run.with_op(op)
}

/// The run with OP as a straight line from one recorded sample to the next (before the first
/// record, the controller's own; after the last, held): the best a deterministic valve model can
/// guess of OP between the samples without the controller's law.
pub fn interpolated(run: &FullRun) -> FullRun {
    let mut op = run.op.clone();
    for w in run.recorded.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (oa, ob) = (run.op[a], run.op[b]);
        for (i, o) in op[a + 1..b].iter_mut().enumerate() {
            *o = oa + (ob - oa) * (i + 1) as f64 / (b - a) as f64;
        }
    }
    if let Some(&last) = run.recorded.last() {
        let v = run.op[last];
        op[last..].iter_mut().for_each(|o| *o = v);
    }
    run.with_op(op)
}

/// The band-unknown oracles and the oracles that know less, on a Stenman loop `l` (run at full
/// rate as `run`) and its twin (`twin_setup`, run as `twin_run`).
pub fn less_known(
    l: &BenchmarkLoop,
    twin_setup: &ClosedLoop,
    run: &FullRun,
    twin_run: &FullRun,
    bands: usize,
) -> Unknown {
    let twin_data = twin_setup.run().expect("a catalogue loop's twin runs");
    let fitted = hidden::identified(l, &l.setup, &l.data.op, &l.data.pv).zip(hidden::identified(
        l,
        twin_setup,
        &twin_data.op,
        &twin_data.pv,
    ));
    let free = profile::Free {
        band: true,
        noise_and_drift: true,
    };
    // each record's own fit, the noise as the record shows it
    let starts = fitted.as_ref().map(|(s1, s0)| {
        (
            from_fit(s1, &l.data.pv, l.setup.ts),
            from_fit(s0, &twin_data.pv, l.setup.ts),
        )
    });
    let searched_identified = starts.as_ref().map(|(s1, s0)| {
        // each record's own fit starts both hypotheses' searches on it
        (
            profile::searched_wide(s1, &l.setup.model, run, free),
            profile::searched_wide(s0, &l.setup.model, twin_run, free),
        )
    });
    let (profiled_identified, profiled_noise_read, profiled_fit_true_noise) = wide_profiles(
        l,
        twin_setup,
        &twin_data.pv,
        starts.as_ref(),
        (run, twin_run),
    );
    // the "recorded" oracle's ratios on the sticky loop and its twin under loops `s1`, `s0`
    // and runs `r1`, `r0`: band known, band unknown
    let known = |s1: &ClosedLoop, s0: &ClosedLoop, r1: &FullRun, r0: &FullRun| {
        (
            llrs(s1, &l.setup.model, r1).recorded,
            llrs(s0, &l.setup.model, r0).recorded,
        )
    };
    let unknown = |s1: &ClosedLoop, s0: &ClosedLoop, r1: &FullRun, r0: &FullRun| {
        (
            band_unknown(s1, r1, bands).recorded,
            band_unknown(s0, r0, bands).recorded,
        )
    };
    let identified = fitted.map(|(s1, s0)| {
        (
            known(&s1, &s0, run, twin_run),
            unknown(&s1, &s0, run, twin_run),
        )
    });
    let (hs, ht) = (held(run), held(twin_run));
    let (is, it) = (interpolated(run), interpolated(twin_run));
    Unknown {
        sticky: band_unknown(&l.setup, run, bands),
        twin: band_unknown(twin_setup, twin_run, bands),
        held_known: known(&l.setup, twin_setup, &hs, &ht),
        held: unknown(&l.setup, twin_setup, &hs, &ht),
        interpolated_known: known(&l.setup, twin_setup, &is, &it),
        interpolated: unknown(&l.setup, twin_setup, &is, &it),
        identified,
        searched_identified,
        profiled_identified,
        profiled_noise_read,
        profiled_fit_true_noise,
        profiled: (
            profile::profiled_llr(&l.setup, &l.setup.model, run, &profile::NARROW),
            profile::profiled_llr(twin_setup, &l.setup.model, twin_run, &profile::NARROW),
        ),
        profiled_band_free: (
            profile::profiled_band_free_llr(&l.setup, run, &profile::WIDE),
            profile::profiled_band_free_llr(twin_setup, twin_run, &profile::WIDE),
        ),
        profiled_wide: (
            profile::profiled_llr(&l.setup, &l.setup.model, run, &profile::WIDE),
            profile::profiled_llr(twin_setup, &l.setup.model, twin_run, &profile::WIDE),
        ),
        searched: [false, true].map(|noise_and_drift| {
            let free = profile::Free {
                band: true,
                noise_and_drift,
            };
            (
                profile::searched_llr(&l.setup, &l.setup.model, run, free),
                profile::searched_llr(twin_setup, &l.setup.model, twin_run, free),
            )
        }),
        off: hidden::OFF.map(|(_, change)| {
            let (mut s1, mut s0) = (l.setup.clone(), twin_setup.clone());
            change(&mut s1);
            change(&mut s0);
            (
                llrs(&s1, &l.setup.model, run).recorded,
                llrs(&s0, &l.setup.model, twin_run).recorded,
            )
        }),
    }
}

/// A profile's (sticky loop, twin) ratios with and without it, where they were computed.
type Around = (Option<(f64, f64)>, (f64, f64), Option<(f64, f64)>);

/// The wide profile with the band free around the fit's process (`starts`, the noise read from
/// the record), and what its drop from the truth's profile comes from: around the true process
/// with the noise read from the record (`twin_pv`: the twin's record); around the fit's process
/// with the true noise.
fn wide_profiles(
    l: &BenchmarkLoop,
    twin_setup: &ClosedLoop,
    twin_pv: &[f64],
    starts: Option<&(ClosedLoop, ClosedLoop)>,
    (run, twin_run): (&FullRun, &FullRun),
) -> Around {
    let wide = |s1: &ClosedLoop, s0: &ClosedLoop| {
        (
            profile::profiled_band_free_llr(s1, run, &profile::WIDE),
            profile::profiled_band_free_llr(s0, twin_run, &profile::WIDE),
        )
    };
    let around_fit = starts.map(|(s1, s0)| wide(s1, s0));
    let noise_read = wide(
        &noise_read(&l.setup, &l.data.pv),
        &noise_read(twin_setup, twin_pv),
    );
    let fit_true_noise = starts.map(|(s1, s0)| {
        let (mut s1, mut s0) = (s1.clone(), s0.clone());
        s1.noise = l.setup.noise;
        s0.noise = twin_setup.noise;
        wide(&s1, &s0)
    });
    (around_fit, noise_read, fit_true_noise)
}
