//! Small pieces of the CLI's own wording: counts with the right plural, seconds rounded for a
//! person to read.

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

#[cfg(test)]
mod tests {
    use super::*;

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
