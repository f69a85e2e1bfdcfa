//! The oracles without the band, and the one that sees OP only at the recorded samples.

use super::hidden::{self, OFF};
use super::kalman::{llrs, FullRun, Llr};
use super::profile;
use super::{balanced, pct, share, Pick, Row, ORACLES};
use std::fmt::Write as _;
use stiction_core::models::{Model, Stenman};
use stiction_core::sim::catalogue::{BenchmarkLoop, LoopKind};
use stiction_core::sim::ClosedLoop;
use stiction_core::sim::Process;

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
    let mut s = fit.clone();
    match &mut s.process {
        Process::Foptd { tau, delay, .. } => {
            *tau = tau.max(ts);
            *delay = delay.max(0.25);
        }
        Process::Integrating { delay, .. } => *delay = delay.max(0.25),
        Process::Soptd { .. } => {}
    }
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
    let wide = |s1: &ClosedLoop, s0: &ClosedLoop| {
        (
            profile::profiled_band_free_llr(s1, run, &profile::WIDE),
            profile::profiled_band_free_llr(s0, twin_run, &profile::WIDE),
        )
    };
    let profiled_identified = starts.as_ref().map(|(s1, s0)| wide(s1, s0));
    // what the drop from the truth's profile to the fit's comes from: the noise as the record
    // shows it around the true process; the fit's process with the true noise
    let noise_read = |s: &ClosedLoop, pv: &[f64]| {
        let mut s = s.clone();
        s.noise = stiction_core::detect::measurement_noise(pv).max(1e-3);
        s
    };
    let profiled_noise_read = wide(
        &noise_read(&l.setup, &l.data.pv),
        &noise_read(twin_setup, &twin_data.pv),
    );
    let profiled_fit_true_noise = starts.as_ref().map(|(s1, s0)| {
        let (mut s1, mut s0) = (s1.clone(), s0.clone());
        s1.noise = l.setup.noise;
        s0.noise = twin_setup.noise;
        wide(&s1, &s0)
    });
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

pub fn unknown_table(md: &mut String, rows: &[Row], bands: usize) {
    let _ = writeln!(
        md,
        "\n## The band unknown (Stenman loops and their twins; the band's likelihood averaged over {bands} bands log-uniform in 0.5-5 % of span)\n\n\
         Below the three oracles, for each set of records, rows that know less. First the process: as the closed-loop fit identifies it \
         (`compare_fits`' gain, time constant and dead time as a first-order process, the actuator lag left to it, the noise raised to the fit's misfit); \
         profiled under each hypothesis (each hypothesis's likelihood maximised over a grid of the process's gain, time constants and dead time, \
         0.7 to 1.4 or 0.25 to 4 times the truth: a likelihood-ratio test with the process free; on the wide grid also with the band free, \
         every one of 16 bands tried at every point, so no search can stop short); searched by coordinate ascent with the band free too \
         (16 bands log-uniform in 0.5-5 % of span; the ratio is then a generalised likelihood ratio held to 1, not a calibrated test), and the noise and the drift's \
         intensity too; and the same search started from the process the closed-loop fit identifies (time constant at least a sample, dead time at least \
         0.25 s, the noise as `detect::measurement_noise` reads it from the record; 5 sweeps of steps 0.25-4 times). Then the process a fixed amount wrong, \
         under both hypotheses. These rows still see OP at every controller execution and start the valve as the simulator does. \
         The last two rows see OP, too, only at the recorded samples (held between them, or a straight line between them) and drive the valve model with it, \
         as every method that models the valve as a deterministic function of the recorded OP does. Where the controller runs between the samples (the records of 10 s) \
         the valve slips at instants the record does not hold: the true band's valve then explains PV worse than an average over bands, and this \
         oracle falls well short of the ones above. These rows are not a bound: the best test would treat the valve between the samples as hidden.\n"
    );
    let _ = writeln!(
        md,
        "| oracle | records | sticky called stiction, band known | band unknown | twins called healthy, band known | band unknown | balanced accuracy, band known | band unknown |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|");
    for (name, pick) in ORACLES {
        for (fine, words) in [
            (None, "all"),
            (Some(true), "2,000 at 1 s"),
            (Some(false), "750 at 10 s"),
        ] {
            let part: Vec<(&Row, &Unknown)> = rows
                .iter()
                .filter(|r| fine.is_none_or(|f| r.fine == f))
                .filter_map(|r| r.unknown.as_ref().map(|u| (r, u)))
                .collect();
            let known_hit = share(part.iter().map(|(r, _)| pick(&r.sticky) > 0.0));
            let known_twin = share(part.iter().map(|(r, _)| pick(&r.twin) <= 0.0));
            let hit = share(part.iter().map(|(_, u)| pick(&u.sticky) > 0.0));
            let twin = share(part.iter().map(|(_, u)| pick(&u.twin) <= 0.0));
            let _ = writeln!(
                md,
                "| {name} | {words} | {} | {} | {} | {} | {:.3} | {:.3} |",
                pct(known_hit),
                pct(hit),
                pct(known_twin),
                pct(twin),
                balanced(known_hit, known_twin),
                balanced(hit, twin)
            );
        }
    }
    for (fine, words) in [
        (None, "all"),
        (Some(true), "2,000 at 1 s"),
        (Some(false), "750 at 10 s"),
    ] {
        let part: Vec<&Unknown> = rows
            .iter()
            .filter(|r| fine.is_none_or(|f| r.fine == f))
            .filter_map(|r| r.unknown.as_ref())
            .collect();
        let pairs = |f: fn(&Unknown) -> (f64, f64)| -> Vec<(f64, f64)> {
            part.iter().map(|u| f(u)).collect()
        };
        let prefix = "load's model known, PV at the recorded samples,";
        for (profiled, range) in [
            (
                (|u| u.profiled) as fn(&Unknown) -> (f64, f64),
                "gain, time constants and dead time 0.7-1.4 times the truth",
            ),
            (
                |u| u.profiled_wide,
                "gain, time constants and dead time 0.25-4 times the truth",
            ),
            (
                |u| u.profiled_band_free,
                "the same, and the band over 16 bands in 0.5-5 % of span: a likelihood ratio held to 1, not calibrated",
            ),
        ] {
            let name = format!("{prefix} the process profiled under each hypothesis ({range})");
            row(md, &name, words, Some(&pairs(profiled)), None);
        }
        for (i, what) in [
            "the process and the band searched under each hypothesis (coordinate ascent from the true process)",
            "the process, band, noise and drift's intensity searched (the same)",
        ]
        .iter()
        .enumerate()
        {
            let searched: Vec<(f64, f64)> = part.iter().map(|u| u.searched[i]).collect();
            row(md, &format!("{prefix} {what}"), words, None, Some(&searched));
        }
        let from_fit: Vec<(f64, f64)> = part.iter().filter_map(|u| u.searched_identified).collect();
        let name = format!(
            "{prefix} the process, band, noise and drift's intensity searched from the process the closed-loop fit identifies (5 sweeps, steps 0.25-4)"
        );
        row(md, &name, words, None, Some(&from_fit));
        let around_fit: Vec<(f64, f64)> =
            part.iter().filter_map(|u| u.profiled_identified).collect();
        let name = format!(
            "{prefix} the process and the band profiled around the process the closed-loop fit identifies (0.25-4 times it, 16 bands; the noise as the record shows it)"
        );
        row(md, &name, words, None, Some(&around_fit));
        let name =
            format!("{prefix} the same around the true process, the noise as the record shows it");
        row(
            md,
            &name,
            words,
            None,
            Some(&pairs(|u| u.profiled_noise_read)),
        );
        let fit_true_noise: Vec<(f64, f64)> = part
            .iter()
            .filter_map(|u| u.profiled_fit_true_noise)
            .collect();
        let name = format!(
            "{prefix} the same around the process the closed-loop fit identifies, the true noise"
        );
        row(md, &name, words, None, Some(&fit_true_noise));
        for (i, (words_off, _)) in OFF.iter().enumerate() {
            let off: Vec<(f64, f64)> = part.iter().map(|u| u.off[i]).collect();
            row(
                md,
                &format!("{prefix} {words_off}"),
                words,
                Some(&off),
                None,
            );
        }
        let (fit_known, fit_unknown): (Pairs, Pairs) =
            part.iter().filter_map(|u| u.identified).unzip();
        let name = format!(
            "{prefix} the process as the closed-loop fit identifies it (the noise raised to its misfit)"
        );
        row(md, &name, words, Some(&fit_known), Some(&fit_unknown));
        let name = "load's model known, OP and PV at the recorded samples (OP held between them)";
        row(
            md,
            name,
            words,
            Some(&pairs(|u| u.held_known)),
            Some(&pairs(|u| u.held)),
        );
        let name = "the same, OP a straight line between the recorded samples";
        let interpolated = pairs(|u| u.interpolated);
        row(
            md,
            name,
            words,
            Some(&pairs(|u| u.interpolated_known)),
            Some(&interpolated),
        );
    }
}

/// The wide profile with the band free around the true process and around the fit's, by loop
/// kind: where the fit's process costs the test.
pub fn by_kind_table(md: &mut String, rows: &[Row]) {
    let _ = writeln!(
        md,
        "\n### The wide profile with the band free, by loop kind (all records)\n\n\
         Around the true process and around the process the closed-loop fit identifies (a first-order process with dead time, \
         or an integrator, without the actuator lag; the noise as the record shows it).\n\n\
         | kind | pairs | around the truth: sticky called stiction | twins called healthy | around the fit's process: sticky called stiction | twins called healthy |\n|---|---|---|---|---|---|"
    );
    let mut kinds: Vec<LoopKind> = rows
        .iter()
        .filter(|r| r.unknown.is_some())
        .map(|r| r.kind)
        .collect();
    kinds.sort_by_key(|k| k.name());
    kinds.dedup();
    for kind in kinds {
        let part: Vec<&Unknown> = rows
            .iter()
            .filter(|r| r.kind == kind)
            .filter_map(|r| r.unknown.as_ref())
            .collect();
        let truth: Pairs = part.iter().map(|u| u.profiled_band_free).collect();
        let fit: Pairs = part.iter().filter_map(|u| u.profiled_identified).collect();
        let (ts, tt) = shares(&truth);
        let (fs, ft) = shares(&fit);
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} |",
            kind.name(),
            part.len(),
            pct(ts),
            pct(tt),
            pct(fs),
            pct(ft)
        );
    }
}

/// The shares of sticky loops called sticky (ratio above 0) and of twins called healthy.
fn shares(p: &[(f64, f64)]) -> ((usize, usize), (usize, usize)) {
    (
        share(p.iter().map(|u| u.0 > 0.0)),
        share(p.iter().map(|u| u.1 <= 0.0)),
    )
}

/// Ratios on sticky loops and their twins.
type Pairs = Vec<(f64, f64)>;

/// One row of the band-unknown table: the shares of sticky loops called sticky (ratio above 0) and
/// of twins called healthy, band known and unknown ("-" where the oracle has no such column), and
/// the balanced accuracies.
fn row(
    md: &mut String,
    name: &str,
    words: &str,
    known: Option<&[(f64, f64)]>,
    unknown: Option<&[(f64, f64)]>,
) {
    let (k, u) = (known.map(shares), unknown.map(shares));
    let cell = |x: Option<(usize, usize)>| x.map_or("-".to_string(), pct);
    let ba = |x: Option<((usize, usize), (usize, usize))>| {
        x.map_or("-".to_string(), |(h, t)| format!("{:.3}", balanced(h, t)))
    };
    let _ = writeln!(
        md,
        "| {name} | {words} | {} | {} | {} | {} | {} | {} |",
        cell(k.map(|x| x.0)),
        cell(u.map(|x| x.0)),
        cell(k.map(|x| x.1)),
        cell(u.map(|x| x.1)),
        ba(k),
        ba(u)
    );
}
