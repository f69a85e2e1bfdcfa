//! Numbers as plant exports write them: a decimal point or a decimal comma, and digits grouped
//! by thousands (`4,999.94`, `4.999,94`, `4 999,94`, `4'999.94`). A column is read with one
//! convention: the one its unambiguous cells show ([`Grouping::of`]), so that `12,345` in a
//! column that also holds `4,999.94` is twelve thousand, not twelve.

/// How a column groups its digits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Grouping {
    /// No grouping seen: a lone comma is a decimal comma (`12,5`).
    #[default]
    None,
    /// Commas group thousands, a point is the decimal mark (`4,999.94`).
    Comma,
    /// Points group thousands, a comma is the decimal mark (`4.999,94`).
    Point,
}

impl Grouping {
    /// The convention `cells` show: the grouping of every cell that has both a comma and a
    /// point, or more than one of either, when they all agree; else none.
    pub fn of<'a>(cells: impl IntoIterator<Item = &'a str>) -> Grouping {
        let mut seen = Grouping::None;
        for c in cells {
            let g = unambiguous(c.trim());
            match (seen, g) {
                (_, Grouping::None) => {}
                (Grouping::None, g) => seen = g,
                (s, g) if s == g => {}
                _ => return Grouping::None,
            }
        }
        seen
    }
}

/// A cell in the plain form most exports write (`-12.5`, `3e-4`): digits, at most one point, a
/// sign or an exponent, no comma or space. Every convention reads it alike, except that a column
/// grouped by points reads no point as a decimal mark.
fn plain(c: &str) -> bool {
    let b = c.as_bytes();
    !b.is_empty()
        && b.iter()
            .all(|&x| x.is_ascii_digit() || matches!(x, b'.' | b'-' | b'+' | b'e' | b'E'))
        && b.iter().filter(|&&x| x == b'.').count() <= 1
}

/// The grouping a single cell shows beyond doubt.
fn unambiguous(c: &str) -> Grouping {
    if plain(c) {
        return Grouping::None;
    }
    let (commas, points) = (c.matches(',').count(), c.matches('.').count());
    let last_comma = c.rfind(',');
    let last_point = c.rfind('.');
    let g = match (commas, points) {
        (0, 0) => return Grouping::None,
        (_, 0) if commas > 1 => Grouping::Comma,
        (0, _) if points > 1 => Grouping::Point,
        (c, p) if c > 0 && p > 0 => {
            if last_point > last_comma {
                Grouping::Comma
            } else {
                Grouping::Point
            }
        }
        _ => return Grouping::None,
    };
    if grouped(c, g).is_some() {
        g
    } else {
        Grouping::None
    }
}

/// `c` read with grouping `g`: the separators must split the integer part in groups of three.
fn grouped(c: &str, g: Grouping) -> Option<f64> {
    let (sep, mark) = match g {
        Grouping::Comma => (',', '.'),
        Grouping::Point => ('.', ','),
        Grouping::None => return None,
    };
    let (int, frac) = match c.rsplit_once(mark) {
        Some((i, f)) => (i, Some(f)),
        None => (c, None),
    };
    let (sign, digits) = match int.strip_prefix(['-', '+']) {
        Some(rest) => (&int[..1], rest),
        None => ("", int),
    };
    let groups: Vec<&str> = digits.split(sep).collect();
    let ok = groups.len() > 1
        && (1..=3).contains(&groups[0].len())
        && groups[1..].iter().all(|g| g.len() == 3)
        && groups.iter().all(|g| g.bytes().all(|b| b.is_ascii_digit()))
        && frac.is_none_or(|f| !f.is_empty() && f.bytes().all(|b| b.is_ascii_digit()));
    if !ok {
        return None;
    }
    let mut plain = format!("{sign}{}", groups.concat());
    if let Some(f) = frac {
        plain.push('.');
        plain.push_str(f);
    }
    plain.parse().ok()
}

/// Spaces and apostrophes between digit groups: `4 999,94` as `4999,94`, when the integer part
/// splits into a group of one to three digits and groups of three.
fn space_grouped(cell: &str) -> Option<String> {
    const SPACES: [char; 4] = [' ', '\'', '\u{a0}', '\u{202f}'];
    if !cell.contains(SPACES) {
        return None;
    }
    let end = cell.find([',', '.']).unwrap_or(cell.len());
    let (int, rest) = cell.split_at(end);
    let digits = int.strip_prefix(['-', '+']).unwrap_or(int);
    let groups: Vec<&str> = digits.split(SPACES).collect();
    let ok = (1..=3).contains(&groups[0].len())
        && groups[1..].iter().all(|g| g.len() == 3)
        && groups.iter().all(|g| g.bytes().all(|b| b.is_ascii_digit()))
        && !rest.contains(SPACES);
    ok.then(|| format!("{}{}", &int[..int.len() - digits.len()], groups.concat()) + rest)
}

/// A number with a decimal point, or a decimal comma and no point (`12,5`), or digits grouped
/// by thousands in a way no other reading allows (`4,999.94`, `1,234,567`, `4.999,94`); spaces
/// and apostrophes between digit groups are dropped (`4 999,94`, `4'999.94`).
pub fn parse_number(cell: &str) -> Option<f64> {
    parse_number_grouped(cell, Grouping::None)
}

/// [`parse_number`] in a column whose convention is `g` ([`Grouping::of`]): with commas
/// grouping, `12,345` is 12345; with points grouping, `1.234` is 1234 and `12,5` is 12.5.
pub fn parse_number_grouped(cell: &str, g: Grouping) -> Option<f64> {
    if g != Grouping::Point && plain(cell) {
        return cell.parse().ok();
    }
    let owned = space_grouped(cell);
    let cell = owned.as_deref().unwrap_or(cell);
    if let Some(v) = match g {
        Grouping::None => None,
        g => grouped(cell, g),
    } {
        return Some(v);
    }
    if g == Grouping::Point {
        // a lone comma is the decimal mark; a point would be a group separator
        return (cell.matches(',').count() <= 1 && !cell.contains('.'))
            .then(|| cell.replace(',', ".").parse().ok())
            .flatten();
    }
    if g == Grouping::None {
        if let g @ (Grouping::Comma | Grouping::Point) = unambiguous(cell) {
            return grouped(cell, g);
        }
    }
    cell.parse().ok().or_else(|| {
        (g == Grouping::None && cell.matches(',').count() == 1 && !cell.contains('.'))
            .then(|| cell.replace(',', ".").parse().ok())
            .flatten()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_decimal_comma_and_grouped_numbers() {
        assert_eq!(parse_number("12.5"), Some(12.5));
        assert_eq!(parse_number("12,5"), Some(12.5));
        assert_eq!(parse_number("-1e3"), Some(-1000.0));
        assert_eq!(parse_number("4,999.94"), Some(4999.94));
        assert_eq!(parse_number("4.999,94"), Some(4999.94));
        assert_eq!(parse_number("1,234,567"), Some(1_234_567.0));
        assert_eq!(parse_number("-1.234.567,5"), Some(-1_234_567.5));
        assert_eq!(parse_number("4 999,94"), Some(4999.94));
        assert_eq!(parse_number("4'999.94"), Some(4999.94));
        // not grouped in threes, or mixed: not a number
        assert_eq!(parse_number("49,99.94"), None);
        assert_eq!(parse_number("1,2,3"), None);
        assert_eq!(parse_number("12 %"), None);
        assert_eq!(parse_number("1 2"), None);
        assert_eq!(parse_number("-12 345 678"), Some(-12_345_678.0));
        assert_eq!(parse_number("abc"), None);
    }

    #[test]
    fn a_column_is_read_with_the_grouping_it_shows() {
        let us = ["4,999.94", "12,345", "7.5"];
        assert_eq!(Grouping::of(us), Grouping::Comma);
        let read: Vec<f64> = us
            .iter()
            .map(|c| parse_number_grouped(c, Grouping::Comma).unwrap())
            .collect();
        assert_eq!(read, vec![4999.94, 12345.0, 7.5]);
        let eu = ["4.999,94", "1.234", "7,5"];
        assert_eq!(Grouping::of(eu), Grouping::Point);
        let read: Vec<f64> = eu
            .iter()
            .map(|c| parse_number_grouped(c, Grouping::Point).unwrap())
            .collect();
        assert_eq!(read, vec![4999.94, 1234.0, 7.5]);
        // no grouped cell: a lone comma stays a decimal comma
        assert_eq!(Grouping::of(["12,345", "7,5"]), Grouping::None);
        assert_eq!(parse_number_grouped("12,345", Grouping::None), Some(12.345));
        // conventions that disagree: none
        assert_eq!(Grouping::of(["4,999.94", "4.999,94"]), Grouping::None);
    }
}
