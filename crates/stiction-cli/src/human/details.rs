//! The `details:` block of `diagnose`: one line per family (its vote, its statistics' share of
//! the log-odds, its note), then the closed-loop fits, the linear loop's balance and the shape
//! indices.

use stiction_core::diagnose::{Diagnosis, Vote};

/// A share of the log-odds, signed (`+1.20`; `0.00` for less than half a hundredth either
/// way), or `-` where the model reads none of a family's statistics.
fn log_odds(c: Option<f64>) -> String {
    match c {
        None => "-".into(),
        Some(c) if c.abs() < 0.005 => "0.00".into(),
        Some(c) => format!("{c:+.2}"),
    }
}

/// Print the details block.
pub fn print(d: &Diagnosis) {
    if d.families.is_empty() && d.indices.is_empty() {
        return;
    }
    println!("  details (family, vote, share of the log-odds, note):");
    for f in &d.families {
        println!(
            "    {:<24} {:<13} {:>6}  {}",
            f.family.words(),
            crate::words::vote(f.vote),
            log_odds(f.contribution),
            f.note
        );
    }
    fits(d);
    indices(d);
}

/// The closed-loop fits and the linear loop's balance.
fn fits(d: &Diagnosis) {
    if let Some(m) = d.families.iter().find_map(|f| f.model.as_ref()) {
        if m.band_fits_better() {
            println!(
                "    closed-loop fit: R² {:.3} without stiction, {:.3} with (Stenman), {:.3} with a slip jump (Kano)",
                m.r2_without_stiction, m.r2_stenman, m.r2_slip_jump
            );
        } else {
            println!(
                "    closed-loop fit: R² {:.3} without stiction; no band found fits better (the search's best: {:.3} with Stenman's band, {:.3} with a slip jump)",
                m.r2_without_stiction, m.r2_stenman, m.r2_slip_jump
            );
        }
    }
    if let Some(l) = d.families.iter().find_map(|f| f.limit_cycle.as_ref()) {
        println!(
            "    linear loop: gain margin {}; to sustain the {:.0} s cycle the valve must lag OP by {:.0}° (gain {:.2}){}",
            l.margins
                .gain_margin
                .map_or("none".into(), |g| format!("{g:.2}")),
            l.period,
            l.needed_lag_degrees,
            l.needed_gain,
            l.describing.as_ref().map_or(String::new(), |b| format!(
                "; describing function: a band of {:.2} % of span{}",
                b.band_percent_of_span,
                b.predicted_period
                    .map_or(String::new(), |p| format!(", predicted period {p:.0} s"))
            ))
        );
    }
}

/// The shape family's indices.
fn indices(d: &Diagnosis) {
    if d.indices.is_empty() {
        return;
    }
    println!("    shape indices (oscillating stretch):");
    for i in &d.indices {
        println!(
            "      {:<18} {:>8}  {:<13} {}{}",
            i.name,
            i.value.map_or("-".into(), |v| format!("{v:.3}")),
            crate::words::vote(i.vote),
            i.threshold,
            if i.weight == 0.0 {
                " [shown, not counted]"
            } else if i.only_votes.is_some() && i.vote == Vote::Undetermined {
                " [one-sided: silent]"
            } else {
                ""
            }
        );
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn shares_of_the_log_odds_are_signed_and_never_minus_zero() {
        assert_eq!(super::log_odds(Some(1.204)), "+1.20");
        assert_eq!(super::log_odds(Some(-0.42)), "-0.42");
        assert_eq!(super::log_odds(Some(-0.001)), "0.00");
        assert_eq!(super::log_odds(None), "-");
    }
}
