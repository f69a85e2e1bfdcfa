//! The tables the program writes: the real records out of fold, record by record and in sum,
//! the probability's reliability, the simulated sets, and each statistic's separation on real and
//! simulated records.

use crate::samples::{Sample, Source};
use std::fmt::Write as _;
use stiction_core::diagnose::{Statistic, Verdict, VerdictModel};

/// The verdict a probability gives under a model's thresholds (`None`: not judged).
pub fn verdict(m: &VerdictModel, p: Option<f64>) -> Verdict {
    match p {
        None => Verdict::InsufficientData,
        Some(p) if p >= m.stiction_from => Verdict::Stiction,
        Some(p) if p < m.no_stiction_below => Verdict::NoStiction,
        Some(_) => Verdict::Undetermined,
    }
}

/// Right: a sticky record called `stiction`, a healthy one `no_stiction`.
pub fn right(sticky: bool, v: Verdict) -> bool {
    v == if sticky {
        Verdict::Stiction
    } else {
        Verdict::NoStiction
    }
}

/// Sensitivity, specificity and balanced accuracy of `(sticky, verdict)` pairs.
pub fn accuracy(pairs: &[(bool, Verdict)]) -> (f64, f64, f64) {
    let share = |sticky: bool| {
        let of: Vec<&(bool, Verdict)> = pairs.iter().filter(|p| p.0 == sticky).collect();
        of.iter().filter(|p| right(p.0, p.1)).count() as f64 / of.len().max(1) as f64
    };
    let (se, sp) = (share(true), share(false));
    (se, sp, (se + sp) / 2.0)
}

/// The area under the ROC curve of `values` (sticky against healthy; missing values lowest).
pub fn auc(pairs: &[(bool, Option<f64>)]) -> f64 {
    let v = |x: Option<f64>| x.unwrap_or(f64::NEG_INFINITY);
    let pos: Vec<f64> = pairs.iter().filter(|p| p.0).map(|p| v(p.1)).collect();
    let neg: Vec<f64> = pairs.iter().filter(|p| !p.0).map(|p| v(p.1)).collect();
    if pos.is_empty() || neg.is_empty() {
        return f64::NAN;
    }
    let mut s = 0.0;
    for a in &pos {
        for b in &neg {
            s += if a > b {
                1.0
            } else if a == b {
                0.5
            } else {
                0.0
            };
        }
    }
    s / (pos.len() * neg.len()) as f64
}

fn name(v: Verdict) -> &'static str {
    v.as_str()
}

/// The real records out of fold: one row each, then the sums.
pub fn real_table(md: &mut String, m: &VerdictModel, real: &[(&Sample, Option<f64>)]) {
    let _ = writeln!(
        md,
        "| record | source | kind | label | P out of fold | verdict | right |\n|---|---|---|---|---|---|---|"
    );
    for (s, p) in real {
        let v = verdict(m, *p);
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} |",
            s.id,
            if s.source == Source::Plant {
                "plant"
            } else {
                "ISDB"
            },
            s.class,
            if s.sticky { "stiction" } else { "no_stiction" },
            p.map_or("-".into(), |p| format!("{p:.2}")),
            name(v),
            if right(s.sticky, v) { "yes" } else { "**no**" }
        );
    }
    let _ = writeln!(md);
    let _ = writeln!(
        md,
        "| real records | records | sticky | healthy | sensitivity | specificity | balanced accuracy |\n|---|---|---|---|---|---|---|"
    );
    for (label, keep) in [
        ("plant windows", Some(Source::Plant)),
        ("ISDB", Some(Source::Isdb)),
        ("all", None),
    ] {
        let pairs: Vec<(bool, Verdict)> = real
            .iter()
            .filter(|(s, _)| keep.is_none_or(|k| s.source == k))
            .map(|(s, p)| (s.sticky, verdict(m, *p)))
            .collect();
        let (se, sp, ba) = accuracy(&pairs);
        let sticky = pairs.iter().filter(|p| p.0).count();
        let _ = writeln!(
            md,
            "| {label} | {} | {sticky} | {} | {se:.2} | {sp:.2} | **{ba:.3}** |",
            pairs.len(),
            pairs.len() - sticky
        );
    }
    let _ = writeln!(md);
}

/// Of the records given a probability in each band, how many are sticky.
pub fn reliability(md: &mut String, real: &[(&Sample, Option<f64>)]) {
    let _ = writeln!(
        md,
        "| P out of fold | records | sticky | share sticky |\n|---|---|---|---|"
    );
    for k in 0..5 {
        let (lo, hi) = (k as f64 * 0.2, (k + 1) as f64 * 0.2);
        let in_band: Vec<&(&Sample, Option<f64>)> = real
            .iter()
            .filter(|(_, p)| p.is_some_and(|p| p >= lo && (p < hi || (k == 4 && p <= 1.0))))
            .collect();
        let sticky = in_band.iter().filter(|(s, _)| s.sticky).count();
        let _ = writeln!(
            md,
            "| {lo:.1}-{hi:.1} | {} | {sticky} | {} |",
            in_band.len(),
            if in_band.is_empty() {
                "-".into()
            } else {
                format!("{:.2}", sticky as f64 / in_band.len() as f64)
            }
        );
    }
    let _ = writeln!(md);
}

/// The simulated records under a model: per source and class.
pub fn simulated_table(md: &mut String, m: &VerdictModel, sims: &[(&Sample, f64)]) {
    let _ = writeln!(
        md,
        "| simulated set | class | loops | stiction | no_stiction | undetermined | right |\n|---|---|---|---|---|---|---|"
    );
    let mut keys: Vec<(Source, String)> = sims
        .iter()
        .map(|(s, _)| (s.source, s.class.clone()))
        .collect();
    keys.sort_by(|a, b| (a.0 as u8, &a.1).cmp(&(b.0 as u8, &b.1)));
    keys.dedup();
    for (src, class) in &keys {
        let of: Vec<Verdict> = sims
            .iter()
            .filter(|(s, _)| s.source == *src && &s.class == class)
            .map(|(s, p)| {
                if s.judged {
                    verdict(m, Some(*p))
                } else {
                    Verdict::InsufficientData
                }
            })
            .collect();
        let sticky = sims
            .iter()
            .find(|(s, _)| s.source == *src && &s.class == class)
            .is_some_and(|(s, _)| s.sticky);
        let count = |v: Verdict| of.iter().filter(|&&x| x == v).count();
        let r = of.iter().filter(|&&v| right(sticky, v)).count();
        let _ = writeln!(
            md,
            "| {} | {class} | {} | {} | {} | {} | {:.0} % |",
            src.name(),
            of.len(),
            count(Verdict::Stiction),
            count(Verdict::NoStiction),
            count(Verdict::Undetermined),
            100.0 * r as f64 / of.len().max(1) as f64
        );
    }
    let _ = writeln!(md);
    let _ = writeln!(
        md,
        "| simulated set | loops | sensitivity | specificity | balanced accuracy | the same, visible sticky valves only |\n|---|---|---|---|---|---|"
    );
    let mut sources: Vec<Source> = sims.iter().map(|(s, _)| s.source).collect();
    sources.sort_by_key(|s| *s as u8);
    sources.dedup();
    for src in sources {
        let pairs = |visible_only: bool| -> Vec<(bool, Verdict)> {
            sims.iter()
                .filter(|(s, _)| s.source == src)
                .filter(|(s, _)| {
                    !(visible_only && s.sticky && s.visibility.is_some_and(|v| v < 3.0))
                })
                .map(|(s, p)| {
                    (
                        s.sticky,
                        if s.judged {
                            verdict(m, Some(*p))
                        } else {
                            Verdict::InsufficientData
                        },
                    )
                })
                .collect()
        };
        let all = pairs(false);
        let (se, sp, ba) = accuracy(&all);
        let (_, _, bav) = accuracy(&pairs(true));
        let _ = writeln!(
            md,
            "| {} | {} | {se:.2} | {sp:.2} | **{ba:.3}** | {bav:.3} |",
            src.name(),
            all.len()
        );
    }
    let _ = writeln!(md);
}

/// Each statistic's separation (area under the ROC curve, sticky against healthy) and medians,
/// on each source.
pub fn separation(md: &mut String, samples: &[Sample]) {
    let mut sources: Vec<Source> = samples.iter().map(|s| s.source).collect();
    sources.sort_by_key(|s| *s as u8);
    sources.dedup();
    let _ = write!(md, "| statistic |");
    for s in &sources {
        let _ = write!(md, " {} |", s.name());
    }
    let _ = writeln!(md);
    let _ = writeln!(md, "|---|{}", "---|".repeat(sources.len()));
    for (i, st) in Statistic::ALL.iter().enumerate() {
        let _ = write!(md, "| {st:?} |");
        for src in &sources {
            let of: Vec<&Sample> = samples
                .iter()
                .filter(|s| s.source == *src && s.judged)
                .filter(|s| !(s.sticky && s.visibility.is_some_and(|v| v < 3.0)))
                .collect();
            let pairs: Vec<(bool, Option<f64>)> =
                of.iter().map(|s| (s.sticky, s.measured[i])).collect();
            let med = |sticky: bool| {
                let mut v: Vec<f64> = of
                    .iter()
                    .filter(|s| s.sticky == sticky)
                    .filter_map(|s| s.measured[i])
                    .collect();
                v.sort_by(f64::total_cmp);
                v.get(v.len() / 2).copied()
            };
            let f = |x: Option<f64>| x.map_or("-".into(), |x| format!("{x:.2}"));
            let _ = write!(
                md,
                " {:.2} ({} / {}) |",
                auc(&pairs),
                f(med(true)),
                f(med(false))
            );
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md);
}
