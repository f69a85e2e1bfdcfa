//! The loop's kind: an integrating process (a level: PV integrates OP's flow minus the outflow)
//! or a self-regulating one. The request may say so (`--integrating`, `--self-regulating`), a
//! column named by an ISA-5.1 tag hints it (an `L` first letter, `LIC101.PV`, is a level; `F`,
//! `P`, `T`, `A` are not), and otherwise the loop is judged self-regulating. The record's own
//! behaviour is checked either way: a linear model of PV's levels from OP is chosen among
//! integrating and self-regulating structures alike (as the closed-loop fit's first step), and
//! where it integrates while the loop is judged self-regulating (or the other way round) a
//! warning says so. It does not switch the kind itself: a limit cycle fits either family about as
//! well, and a kind read wrongly misreads the cycle's shape.

use serde::{Deserialize, Serialize};

/// Where the loop's kind was read.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "from", rename_all = "snake_case")]
pub enum KindSource {
    /// The request said so.
    Request,
    /// A column's ISA-5.1 tag.
    Tag {
        /// The tag as written (`LIC101`).
        tag: String,
    },
    /// Nothing said: the default, self-regulating.
    Default,
}

/// The loop's kind, where it was read, and how the record behaves.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct LoopKind {
    /// Judged as an integrating process (a level).
    pub integrating: bool,
    /// Where that was read.
    #[serde(flatten)]
    pub source: KindSource,
    /// PV's levels are better explained by an integrating structure from OP than by a
    /// self-regulating one (`None` where no model could be fitted).
    pub behaves_integrating: Option<bool>,
}

/// Whether `pv` behaves as an integrating process of `op`: the structure a BIC choice among both
/// families gives a linear model of PV's levels (delays up to `max_delay` samples).
pub fn behaves_integrating(op: &[f64], pv: &[f64], max_delay: usize) -> Option<bool> {
    use crate::identify::{centred, select, Data, SearchRange};
    let n = op.len();
    let mut search = SearchRange::new(max_delay.min(n / 20).max(1));
    search.integrating = true;
    search.self_regulating = true;
    let data = Data::new(pv, search.t0());
    select(&data, &centred(op), &search).map(|s| s.structure.integrating)
}

/// The kind an ISA-5.1 tag in `name` hints, with the tag: the first letter of a controller's or
/// transmitter's tag (a letter, optionally `I`, `R` or `D` and then `C`, `T` or `Y`, then digits,
/// as in `LIC101`, `FC-12`, `2111LIC23001`). `L` is a level (integrating); `F`, `P`, `T`, `A`
/// are self-regulating; anything else, or no tag, hints nothing.
pub fn hinted_by_tag(name: &str) -> Option<(bool, String)> {
    let chars: Vec<char> = name.chars().collect();
    let n = chars.len();
    for start in 0..n {
        // a tag starts at a letter that no other letter precedes
        if start > 0 && chars[start - 1].is_ascii_alphabetic() {
            continue;
        }
        let first = chars[start].to_ascii_uppercase();
        let mut k = start + 1;
        if k < n && matches!(chars[k].to_ascii_uppercase(), 'I' | 'R' | 'D') {
            k += 1;
        }
        if !(k < n && matches!(chars[k].to_ascii_uppercase(), 'C' | 'T' | 'Y')) {
            continue;
        }
        k += 1;
        // then, after at most a separator, digits
        if k < n && matches!(chars[k], '-' | '_' | ' ') {
            k += 1;
        }
        if !(k < n && chars[k].is_ascii_digit()) {
            continue;
        }
        let end = (k..n)
            .find(|&j| !chars[j].is_ascii_alphanumeric())
            .unwrap_or(n);
        let tag: String = chars[start..end].iter().collect();
        return match first {
            'L' => Some((true, tag)),
            'F' | 'P' | 'T' | 'A' => Some((false, tag)),
            _ => None,
        };
    }
    None
}

#[cfg(test)]
mod tests {
    use super::hinted_by_tag;

    #[test]
    fn isa_tags_hint_the_loops_kind() {
        assert_eq!(hinted_by_tag("LIC101.PV"), Some((true, "LIC101".into())));
        assert_eq!(
            hinted_by_tag("2111LIC23001"),
            Some((true, "LIC23001".into()))
        );
        assert_eq!(hinted_by_tag("FIC-205 OP"), Some((false, "FIC-205".into())));
        assert_eq!(hinted_by_tag("tic_7.pv"), Some((false, "tic_7".into())));
        assert_eq!(hinted_by_tag("PT100"), Some((false, "PT100".into())));
        for plain in ["pv", "op", "OP", "level", "flow rate", "XIC12", "FICX"] {
            assert_eq!(hinted_by_tag(plain), None, "{plain}");
        }
    }
}
