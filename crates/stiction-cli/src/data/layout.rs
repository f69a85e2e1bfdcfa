//! Finding the columns asked for in a table laid out otherwise: a header below a preamble, units
//! below the header, or a narrow export (a row per tag and time) to be pivoted to a column per
//! tag. Each returns a new table with a note, or `None` when there is nothing to change.

use super::missing::is_missing;
use super::table::Table;
use std::collections::HashMap;

/// Rows searched for a header below a preamble.
pub const HEADER_SEARCH: usize = 20;
/// A narrow export has at most this many columns.
const NARROW_WIDTH: usize = 6;

impl Table {
    /// `self` laid out so that the `wanted` columns are named: its header found below a
    /// preamble ([`Table::with_header_naming`]), or a narrow export pivoted
    /// ([`Table::pivoted_narrow`]); `None` when it is already so, or neither finds them.
    pub fn for_columns(
        &self,
        wanted: &[&str],
        signals: &[&str],
        time: Option<&str>,
    ) -> Option<Table> {
        self.with_header_naming(wanted)
            .or_else(|| self.pivoted_narrow(signals, time))
    }

    /// The table with its header where the `wanted` columns are named: when the header lacks
    /// some but one of the first [`HEADER_SEARCH`] rows names them all (a preamble of tag names,
    /// descriptions or units above the real header, as PI DataLink and other exports write),
    /// that row becomes the header and the rows above it are left out; rows of text right below
    /// the header (units, descriptions) are left out too. With a note; `None` when there is
    /// nothing to change (or no row names them all).
    pub fn with_header_naming(&self, wanted: &[&str]) -> Option<Table> {
        let names =
            |i: usize| -> Vec<&str> { (0..self.headers.len()).map(|c| self.cell(i, c)).collect() };
        let at = if wanted.iter().all(|w| self.find(w).is_some()) {
            None
        } else {
            Some((0..self.len().min(HEADER_SEARCH)).find(|&i| {
                let row = names(i);
                wanted
                    .iter()
                    .all(|w| row.iter().any(|c| c.eq_ignore_ascii_case(w.trim())))
            })?)
        };
        // units or descriptions: text, but no number and no missing value (a data row whose
        // values are all historian states stays)
        let text_only = |i: usize| {
            let row = names(i);
            row.iter().any(|c| !c.is_empty())
                && row.iter().all(|c| {
                    c.is_empty()
                        || (stiction_core::record::parse_number(c).is_none() && !is_missing(c))
                })
        };
        let below = at.map_or(0, |a| a + 1);
        let mut first = below;
        while first < self.len() && first < below + 3 && text_only(first) {
            first += 1;
        }
        if at.is_none() && first == 0 {
            return None;
        }
        let headers: Vec<String> = match at {
            Some(a) => names(a).iter().map(|c| c.to_string()).collect(),
            None => self.headers.clone(),
        };
        let mut t = self.with_headers(headers);
        for i in first..self.len() {
            t.push_row(names(i), self.lines[i]);
        }
        let lines = |k: usize| match k {
            1 => "1 line".to_string(),
            k => format!("{k} lines"),
        };
        let shown = |i: usize| names(i).join(", ").chars().take(40).collect::<String>();
        let mut said = Vec::new();
        if let Some(a) = at {
            let above: Vec<String> = std::iter::once(self.headers.join(", "))
                .chain((0..a).map(shown))
                .map(|l| l.chars().take(40).collect())
                .collect();
            said.push(format!(
                "the header is {}, below {} the export put above it ({}), left out",
                self.at(a),
                lines(a + 1),
                above.join("; ")
            ));
        }
        if first > below {
            let text: Vec<String> = (below..first).map(shown).collect();
            said.push(format!(
                "{} of text below the header ({}: units or descriptions) left out",
                lines(first - below),
                text.join("; ")
            ));
        }
        t.notes.push(self.row_word.words(said.join("; ")));
        Some(t)
    }

    /// A narrow export (a row per tag and time: tag, time and value columns, as historians
    /// export archive values) pivoted to a column per tag, for the `signals` asked for: the tag
    /// column is the one whose cells name every signal, the time column `time` or the first of
    /// the common names (`TIME_NAMES`), the value column the one named value (or the only other). One row
    /// per distinct time, in the order of the file; a tag without a value at a time leaves its
    /// cell blank (a merge the record's preparation puts on a grid). `None` when the table is
    /// not so.
    pub fn pivoted_narrow(&self, signals: &[&str], time: Option<&str>) -> Option<Table> {
        if signals.is_empty() || signals.iter().all(|w| self.find(w).is_some()) {
            return None;
        }
        let n = self.len();
        let width = self.headers.len();
        // narrow exports have a handful of columns (tag, time, value, status, units)
        if width > NARROW_WIDTH {
            return None;
        }
        let tag = (0..width).find(|&c| {
            signals
                .iter()
                .all(|w| (0..n).any(|i| self.cell(i, c).eq_ignore_ascii_case(w.trim())))
        })?;
        let time_col = match time {
            Some(name) => self.find(name)?,
            None => stiction_core::record::TIME_NAMES
                .iter()
                .find_map(|c| self.find(c))?,
        };
        let others: Vec<usize> = (0..width).filter(|&c| c != tag && c != time_col).collect();
        let value = self
            .find("value")
            .filter(|c| others.contains(c))
            .or_else(|| (others.len() == 1).then(|| others[0]))?;
        // the signals' tags as the file spells them
        let tags: Vec<String> = signals
            .iter()
            .map(|w| {
                (0..n)
                    .map(|i| self.cell(i, tag))
                    .find(|c| c.eq_ignore_ascii_case(w.trim()))
                    .unwrap_or(w)
                    .to_string()
            })
            .collect();
        let column_of = |cell: &str| tags.iter().position(|t| t.eq_ignore_ascii_case(cell));
        let mut rows: Vec<Vec<&str>> = Vec::new();
        let mut lines: Vec<u64> = Vec::new();
        let mut at: HashMap<&str, usize> = HashMap::new();
        let mut used = 0;
        for i in 0..n {
            let Some(k) = column_of(self.cell(i, tag)) else {
                continue;
            };
            let stamp = self.cell(i, time_col);
            let r = *at.entry(stamp).or_insert_with(|| {
                rows.push(vec![""; tags.len() + 1]);
                lines.push(self.lines[i]);
                rows.len() - 1
            });
            rows[r][0] = stamp;
            if rows[r][k + 1].is_empty() {
                rows[r][k + 1] = self.cell(i, value);
                used += 1;
            }
        }
        let headers: Vec<String> = std::iter::once(self.headers[time_col].clone())
            .chain(tags.iter().cloned())
            .collect();
        let mut t = self.with_headers(headers);
        for (row, line) in rows.iter().zip(&lines) {
            t.push_row(row.iter().copied(), *line);
        }
        let mut note = format!(
            "the file is narrow (a row per tag and time: columns {}, {} and {}): {} values of {} turned into a column per tag at {} distinct times",
            self.headers[tag],
            self.headers[time_col],
            self.headers[value],
            used,
            tags.join(", "),
            rows.len()
        );
        if used < n {
            note.push_str(&format!(
                " ({} of other tags, or repeating a tag's time, left out)",
                match n - used {
                    1 => "1 row".to_string(),
                    k => format!("{k} rows"),
                }
            ));
        }
        t.notes.push(self.row_word.words(note));
        Some(t)
    }
}
