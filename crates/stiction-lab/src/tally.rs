//! Verdict counts for the studies' tables: stiction, no_stiction, and the undecided.

use stiction_core::diagnose::Verdict;

/// Verdict counts: stiction, no_stiction, undetermined or insufficient data.
#[derive(Default, Clone, Copy)]
pub struct Tally([usize; 3]);

impl Tally {
    pub fn add(&mut self, v: Verdict) {
        let i = match v {
            Verdict::Stiction => 0,
            Verdict::NoStiction => 1,
            _ => 2,
        };
        self.0[i] += 1;
    }

    /// Three table cells: called stiction (count and share), no_stiction, the undecided.
    pub fn cells(&self) -> String {
        let n: usize = self.0.iter().sum();
        let pct = |k: usize| 100.0 * k as f64 / n.max(1) as f64;
        format!(
            "{} of {n} ({:.1} %) | {:.1} % | {:.1} %",
            self.0[0],
            pct(self.0[0]),
            pct(self.0[1]),
            pct(self.0[2])
        )
    }
}
