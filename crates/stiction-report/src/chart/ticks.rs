//! Tick labels: as many decimals as the tick spacing needs, no trailing zeros ("10", not
//! "10.0"), and no negative zero ("0", not "-0.0": a tick computed as -1e-17 is zero).

/// The spacing plotters' ten or so ticks over `lo..hi` will have, about: a 1-2-5 step.
pub fn step(lo: f64, hi: f64) -> f64 {
    let span = (hi - lo).abs();
    if !span.is_finite() || span == 0.0 {
        return 1.0;
    }
    let raw = span / 10.0;
    let mag = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * mag)
}

/// The label of a tick at `v` on an axis whose ticks are `step` apart.
pub fn tick_label(v: f64, step: f64) -> String {
    if !v.is_finite() {
        return String::new();
    }
    let step = if step.is_finite() && step > 0.0 {
        step
    } else {
        1.0
    };
    // a value within a millionth of a step of zero is zero (no "-0")
    if v.abs() < step * 1e-6 {
        return "0".into();
    }
    let big = v.abs().max(step);
    if !(1e-4..1e7).contains(&big) {
        let s = format!("{v:.2e}");
        return s.replace(".00e", "e").replace("0e", "e");
    }
    // one decimal more than the step's own, then the zeros that say nothing are dropped
    let decimals = (-(step.log10().floor()) as i32 + 1).clamp(0, 10) as usize;
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_negative_zero_and_no_trailing_zeros() {
        assert_eq!(tick_label(-0.0, 0.5), "0");
        assert_eq!(tick_label(-1e-17, 0.2), "0");
        assert_eq!(tick_label(-0.04, 1.0), "0");
        assert_eq!(tick_label(10.0, 2.0), "10");
        assert_eq!(tick_label(120.0, 20.0), "120");
        assert_eq!(tick_label(2.5, 0.5), "2.5");
        assert_eq!(tick_label(-1.5, 0.5), "-1.5");
        assert_eq!(tick_label(0.30000000000000004, 0.1), "0.3");
        assert_eq!(tick_label(0.05, 0.05), "0.05");
        assert_eq!(tick_label(3600.0, 600.0), "3600");
        for k in -20..=20 {
            let v = k as f64 * 0.1 - 1e-16;
            let s = tick_label(v, step(-2.0, 2.0));
            assert!(!s.starts_with("-0") || s.starts_with("-0."), "{v}: {s}");
            assert_ne!(s, "-0");
            assert!(!s.ends_with(".0"), "{v}: {s}");
        }
    }

    #[test]
    fn steps_are_one_two_five() {
        assert_eq!(step(0.0, 10.0), 1.0);
        assert_eq!(step(0.0, 3.0), 0.5);
        assert_eq!(step(-1.0, 1.0), 0.2);
        assert_eq!(step(5.0, 5.0), 1.0);
    }
}
