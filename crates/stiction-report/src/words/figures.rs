//! Figures as the sentences quote them: a few significant digits, minutes or hours for a
//! stretch, seconds for a period.

/// A figure with three significant digits under 10 and none after the point from 10 (`1.66`,
/// `1.8`, `73`, `0.123`), trailing zeros dropped, `-0` as `0`.
pub(crate) fn fig(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    let s = if a >= 10.0 || a == 0.0 {
        format!("{v:.0}")
    } else {
        let digits = (2 - a.log10().floor() as i32).clamp(0, 12) as usize;
        let t = format!("{v:.digits$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

/// A figure with two significant digits (`0.0099` → `0.0099`, `0.00999` → `0.01`, `12.3` → `12`).
pub(crate) fn fig2(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return fig(v);
    }
    let digits = (1 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    let t = format!("{v:.digits$}");
    let t = if t.contains('.') {
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        t
    };
    if t == "-0" {
        "0".into()
    } else {
        t
    }
}

/// A share as a percentage (`0.82` → `82 %`).
pub(crate) fn percent(share: f64) -> String {
    format!("{} %", fig(100.0 * share))
}

/// A stretch of `minutes`: seconds under 2 minutes, minutes under 10 hours, else hours.
pub(crate) fn stretch(minutes: f64) -> String {
    if minutes < 2.0 {
        format!("{} s", fig(60.0 * minutes))
    } else if minutes < 600.0 {
        format!("{} min", fig(minutes))
    } else {
        format!("{} h", fig(minutes / 60.0))
    }
}

/// A cycle's period, seconds, as "the 105 s cycle" names it (minutes from 10 minutes).
pub(crate) fn period(seconds: f64) -> String {
    if seconds >= 600.0 {
        format!("{} min", fig(seconds / 60.0))
    } else {
        format!("{} s", fig(seconds))
    }
}

/// "the 105 s cycle", or "the cycle" without a period.
pub(crate) fn the_cycle(period_s: Option<f64>) -> String {
    match period_s {
        Some(p) if p.is_finite() && p > 0.0 => format!("the {} cycle", period(p)),
        _ => "the cycle".into(),
    }
}

/// `once`, `twice`, `4 times`.
pub(crate) fn times(n: usize) -> String {
    match n {
        1 => "once".into(),
        2 => "twice".into(),
        n => format!("{n} times"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_read_as_an_engineer_writes_them() {
        assert_eq!(fig(1.8), "1.8");
        assert_eq!(fig(1.6612), "1.66");
        assert_eq!(fig(73.4), "73");
        assert_eq!(fig(0.1234), "0.123");
        assert_eq!(fig(-0.0001), "-0.0001");
        assert_eq!(fig(-0.4), "-0.4");
        assert_eq!(fig(0.0), "0");
        assert_eq!(fig(-0.3), "-0.3");
        assert_eq!(percent(0.823), "82 %");
        assert_eq!(fig2(0.00999), "0.01");
        assert_eq!(fig2(0.0412), "0.041");
        assert_eq!(fig2(12.3), "12");
        assert_eq!(stretch(125.0), "125 min");
        assert_eq!(stretch(1.0), "60 s");
        assert_eq!(stretch(900.0), "15 h");
        assert_eq!(the_cycle(Some(105.2)), "the 105 s cycle");
        assert_eq!(the_cycle(None), "the cycle");
        assert_eq!(times(1), "once");
        assert_eq!(times(4), "4 times");
    }
}
