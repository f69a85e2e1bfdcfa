//! How large the band in a `stiction` verdict is against the simulated one: per sticky class, the
//! reported band over the simulated band (Stenman `d`, Kano `S`, He `fs`) and where it came from.

use super::tables::{pct, Groups};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use stiction_core::diagnose::Verdict;
use stiction_lab::catalogue::Truth;

/// The table: for each sticky class, the loops called `stiction` with a band.
pub(super) fn band_table(md: &mut String, groups: &Groups) {
    let _ = writeln!(
        md,
        "The band of the sticky loops called stiction, over the simulated band (Stenman d, Kano S, He fs), and where it came from:\n"
    );
    let _ = writeln!(
        md,
        "| class | loops | median | quartiles | within 1.5x | within 2x | source (loops) |\n|---|---|---|---|---|---|---|"
    );
    let mut all = Vec::new();
    for (class, items) in groups.iter().filter(|(c, _)| c.truth() == Truth::Sticky) {
        let mut sources: BTreeMap<&str, usize> = BTreeMap::new();
        let mut ratios: Vec<f64> = Vec::new();
        for (l, d) in items {
            let Some(b) = d.band.as_ref().filter(|_| d.verdict == Verdict::Stiction) else {
                continue;
            };
            ratios.push(b.band_percent_of_span / l.setup.model.values()[0]);
            *sources.entry(b.source.as_str()).or_default() += 1;
        }
        all.extend_from_slice(&ratios);
        let mut by_count: Vec<(&str, usize)> = sources.into_iter().collect();
        by_count.sort_by_key(|&(_, n)| std::cmp::Reverse(n));
        let words: Vec<String> = by_count.iter().map(|(s, n)| format!("{s} {n}")).collect();
        row(md, &class.to_string(), &mut ratios, &words.join(", "));
    }
    row(md, "all sticky", &mut all, "");
    let _ = writeln!(md);
}

fn row(md: &mut String, name: &str, ratios: &mut [f64], sources: &str) {
    let n = ratios.len();
    if n == 0 {
        let _ = writeln!(md, "| {name} | 0 | - | - | - | - | {sources} |");
        return;
    }
    ratios.sort_by(f64::total_cmp);
    let at = |q: f64| ratios[((n - 1) as f64 * q).round() as usize];
    let within = |f: f64| ratios.iter().filter(|&&r| r > 1.0 / f && r < f).count();
    let _ = writeln!(
        md,
        "| {name} | {n} | {:.2} | {:.2} to {:.2} | {} | {} | {sources} |",
        at(0.5),
        at(0.25),
        at(0.75),
        pct(within(1.5), n),
        pct(within(2.0), n)
    );
}
