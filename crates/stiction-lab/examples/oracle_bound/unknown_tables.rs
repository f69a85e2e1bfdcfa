//! The band-unknown table and the rows that know less, and the profile by loop kind.

use super::hidden::OFF;
use super::unknown::Unknown;
use super::{balanced, pct, share, Row, ORACLES};
use std::fmt::Write as _;
use stiction_lab::catalogue::LoopKind;

/// The band-unknown table: the three oracles with and without the band, then the rows that know
/// less.
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
    less_known_rows(md, rows);
}

/// The rows that know less than the oracles, for each set of records.
fn less_known_rows(md: &mut String, rows: &[Row]) {
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
pub fn shares(p: &[(f64, f64)]) -> ((usize, usize), (usize, usize)) {
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

/// The rows whose ratio is no calibrated test (a band, and maybe the process, maximised under the
/// sticky hypothesis), at every threshold: the area under the ROC curve and the balanced accuracy
/// at the threshold that does best on these very pairs. That threshold is chosen in-sample, so the
/// figure is an upper bound on what any threshold calibrated elsewhere reaches with that ratio.
pub fn ranking_table(md: &mut String, rows: &[Row]) {
    let _ = writeln!(
        md,
        "\n### The band free, at every threshold\n\n\
         The rows above whose ratio is held to 1 though a band (and the process) is maximised under the sticky hypothesis are no calibrated test. \
         Here each at every threshold: the area under the ROC curve (the chance that a sticky loop's ratio exceeds a twin's) and the balanced \
         accuracy at the threshold that does best on these very pairs. That threshold is chosen on the pairs it is judged on, so the figure is \
         an upper bound on what the same ratio reaches with a threshold set elsewhere.\n\n\
         | oracle | records | pairs | area under the ROC curve | best balanced accuracy (in-sample threshold) | at ratio 1 |\n|---|---|---|---|---|---|"
    );
    type Pick = fn(&Unknown) -> Option<(f64, f64)>;
    let prefix = "load's model known, PV at the recorded samples,";
    let picks: [(&str, Pick); 7] = [
        (
            "the process profiled under each hypothesis over 0.25-4 times the truth, the band over 16 bands",
            |u| Some(u.profiled_band_free),
        ),
        (
            "the process and the band searched under each hypothesis (coordinate ascent from the true process)",
            |u| Some(u.searched[0]),
        ),
        (
            "the process, band, noise and drift's intensity searched (the same)",
            |u| Some(u.searched[1]),
        ),
        (
            "the same around the true process, the noise as the record shows it",
            |u| Some(u.profiled_noise_read),
        ),
        (
            "the process, band, noise and drift's intensity searched from the process the closed-loop fit identifies",
            |u| u.searched_identified,
        ),
        (
            "the process and the band profiled around the process the closed-loop fit identifies (0.25-4 times it, 16 bands)",
            |u| u.profiled_identified,
        ),
        (
            "the process as the closed-loop fit identifies it, the band averaged",
            |u| u.identified.map(|(_, unknown)| unknown),
        ),
    ];
    for (what, pick) in picks {
        for (fine, words) in [
            (None, "all"),
            (Some(true), "2,000 at 1 s"),
            (Some(false), "750 at 10 s"),
        ] {
            let pairs: Pairs = rows
                .iter()
                .filter(|r| fine.is_none_or(|f| r.fine == f))
                .filter_map(|r| r.unknown.as_ref().and_then(pick))
                .collect();
            let (hit, twin) = shares(&pairs);
            let _ = writeln!(
                md,
                "| {prefix} {what} | {words} | {} | {:.3} | {:.3} | {:.3} |",
                pairs.len(),
                area_under_roc(&pairs),
                best_balanced(&pairs),
                balanced(hit, twin)
            );
        }
    }
}

/// The chance that a sticky loop's ratio exceeds a twin's (ties count half), over every sticky
/// loop and every twin.
pub fn area_under_roc(pairs: &[(f64, f64)]) -> f64 {
    let mut wins = 0.0;
    for &(s, _) in pairs {
        for &(_, t) in pairs {
            wins += if s > t {
                1.0
            } else if s == t {
                0.5
            } else {
                0.0
            };
        }
    }
    wins / (pairs.len().max(1) as f64).powi(2)
}

/// The best balanced accuracy of "sticky where the ratio exceeds c" over every threshold c.
pub fn best_balanced(pairs: &[(f64, f64)]) -> f64 {
    let n = pairs.len().max(1) as f64;
    let mut cuts: Vec<f64> = pairs.iter().flat_map(|&(s, t)| [s, t]).collect();
    cuts.push(f64::NEG_INFINITY);
    cuts.into_iter()
        .map(|c| {
            let hit = pairs.iter().filter(|p| p.0 > c).count() as f64;
            let healthy = pairs.iter().filter(|p| p.1 <= c).count() as f64;
            0.5 * (hit + healthy) / n
        })
        .fold(0.0, f64::max)
}
