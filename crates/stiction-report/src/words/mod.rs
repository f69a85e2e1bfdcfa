//! Stiction's words, written once for the terminal (the CLI uses this module), the loop report,
//! the fleet page and Python: the verdict's reasons and next step from the core's typed values
//! ([`finding`], [`reason`], [`next_step`], all filled into a diagnosis by [`fill`]), the
//! statistics of the verdict's model by name ([`statistic`]), and the small pieces: counts with
//! the right plural, seconds rounded for a person to read, numbers as the pages print them, and
//! each verdict, outcome and vote named once.
//!
//! The words quote the record's own figures, never a benchmark's.

mod figures;
mod fill;
mod findings;
mod next_step;
mod reach;
mod statistics;

pub use fill::fill;
pub use findings::{finding, reason};
pub use next_step::{action, next_step};
pub use reach::reach;
pub use statistics::{measured_by, statistic, statistic_value};

use stiction_core::diagnose::{Verdict, Vote};
use stiction_core::fleet::Outcome;

/// `1 gap`, `2 gaps`: the count and the noun in the right number.
pub fn count(n: impl std::fmt::Display, one: &str, many: &str) -> String {
    let n = n.to_string();
    let noun = if n == "1" { one } else { many };
    format!("{n} {noun}")
}

/// A number of seconds as a person writes it: at most 6 significant digits, no trailing zeros
/// (`0.2`, not `0.20000000000004547`; `1`, not `1.0`).
pub fn seconds(s: f64) -> String {
    if !s.is_finite() {
        return format!("{s}");
    }
    if s == 0.0 {
        return "0".into();
    }
    let digits = (5 - s.abs().log10().floor() as i32).clamp(0, 12) as usize;
    let text = format!("{s:.digits$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// What of a long record was judged, in words: "judged on means of 29 samples (29 s), 2061 of
/// them" or "judged on samples 5000 to 25000, where OP moves most".
pub fn judged_on(j: &stiction_core::diagnose::averaging::JudgedOn, analysed: [usize; 2]) -> String {
    let mut out = String::from("judged on ");
    if j.over > 1 {
        out.push_str(&format!(
            "means of {} samples ({} s), {} of them",
            j.over,
            seconds(j.ts),
            j.samples
        ));
    }
    if j.stretch
        != [
            analysed[0],
            analysed[0] + (analysed[1] - analysed[0]) / j.over * j.over,
        ]
    {
        if j.over > 1 {
            out.push_str(", over ");
        }
        out.push_str(&format!(
            "samples {} to {}, where OP moves most",
            j.stretch[0], j.stretch[1]
        ));
    }
    out
}

/// A verdict in words: "no stiction", "insufficient data".
pub fn verdict(v: Verdict) -> &'static str {
    match v {
        Verdict::Stiction => "stiction",
        Verdict::NoStiction => "no stiction",
        Verdict::Undetermined => "undetermined",
        Verdict::InsufficientData => "insufficient data",
    }
}

/// A fleet outcome in words: a verdict's words, or "failed".
pub fn outcome(o: Outcome) -> &'static str {
    match o {
        Outcome::Stiction => verdict(Verdict::Stiction),
        Outcome::NoStiction => verdict(Verdict::NoStiction),
        Outcome::Undetermined => verdict(Verdict::Undetermined),
        Outcome::InsufficientData => verdict(Verdict::InsufficientData),
        Outcome::Failed => "failed",
    }
}

/// A vote in words.
pub fn vote(v: Vote) -> &'static str {
    match v {
        Vote::Stiction => "stiction",
        Vote::NoStiction => "no stiction",
        Vote::Undetermined => "undetermined",
    }
}

/// A vote's name in files and CSS classes (`no_stiction`).
pub fn vote_code(v: Vote) -> &'static str {
    match v {
        Vote::Stiction => "stiction",
        Vote::NoStiction => "no_stiction",
        Vote::Undetermined => "undetermined",
    }
}

/// The text with its first letter in upper case.
pub fn capital(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

/// A number with about four significant digits as the pages print it: no trailing zeros, a true
/// minus sign, never "−0"; ∞ and – for the non-finite.
pub fn num(v: f64) -> String {
    if v.is_nan() {
        return "–".into();
    }
    if v.is_infinite() {
        return if v > 0.0 {
            "∞".into()
        } else {
            "−∞".into()
        };
    }
    let a = v.abs();
    let s = if a == 0.0 {
        "0".to_string()
    } else if !(1e-3..1e6).contains(&a) {
        format!("{v:.3e}")
    } else if a >= 1000.0 {
        format!("{v:.0}")
    } else if a >= 100.0 {
        format!("{v:.1}")
    } else if a >= 10.0 {
        format!("{v:.2}")
    } else if a >= 1.0 {
        format!("{v:.3}")
    } else {
        format!("{v:.4}")
    };
    // 12.00 → 12, 0.0500 → 0.05 (not in the exponent form)
    let s = if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    s.replace('-', "−")
}

/// [`num`], or – for none.
pub fn opt(v: Option<f64>) -> String {
    v.map_or("–".into(), num)
}

/// A duration: seconds, with minutes or hours beside them when they read better.
pub fn duration(v: f64) -> String {
    if v >= 7200.0 {
        format!("{} s ({} h)", num(v), num(v / 3600.0))
    } else if v >= 120.0 {
        format!("{} s ({} min)", num(v), num(v / 60.0))
    } else {
        format!("{} s", num(v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_as_the_pages_print_them() {
        assert_eq!(num(12.0), "12");
        assert_eq!(num(0.05), "0.05");
        assert_eq!(num(-0.0), "0");
        assert_eq!(num(-1.5), "−1.5");
        assert_eq!(num(f64::NAN), "–");
        assert_eq!(duration(7200.0), "7200 s (2 h)");
        assert_eq!(capital("no stiction"), "No stiction");
        assert_eq!(outcome(Outcome::InsufficientData), "insufficient data");
    }

    #[test]
    fn plurals_and_rounded_seconds() {
        assert_eq!(count(1, "gap", "gaps"), "1 gap");
        assert_eq!(count(0, "gap", "gaps"), "0 gaps");
        assert_eq!(seconds(0.20000000000004547), "0.2");
        assert_eq!(seconds(1.0), "1");
        assert_eq!(seconds(86_400.0), "86400");
        assert_eq!(seconds(0.001), "0.001");
        assert_eq!(seconds(1.5e-7), "0.00000015");
        assert_eq!(seconds(123456789.0), "123456789");
    }
}
