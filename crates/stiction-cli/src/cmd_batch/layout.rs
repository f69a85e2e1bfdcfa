//! Where each loop's columns are: the flags' (one loop per file, or per loop id of a long-format
//! file), a plant's loop list (`--columns loops.toml` or `loops.csv`: each loop's OP/PV/SP/mode/MV
//! columns and options), or a tag pattern that splits the columns of wide exports into loops
//! (`--tags '{loop}.{role}'`: `FIC101.OP, FIC101.PV, LIC7.OP, ...`).

use crate::loop_file::Columns;
use anyhow::{bail, Context, Result};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A loop's columns and options (the valve position among them when recorded).
#[derive(Clone)]
pub struct LoopSpec {
    pub columns: Columns,
}

impl LoopSpec {
    /// The flags' columns.
    pub fn flags(c: &Columns) -> LoopSpec {
        LoopSpec { columns: c.clone() }
    }

    /// The first column this loop names that `headers` lacks: (column, role).
    pub fn missing_column(&self, headers: &[String]) -> Option<(String, &'static str)> {
        let c = &self.columns;
        let has = |name: &str| headers.iter().any(|h| h.eq_ignore_ascii_case(name.trim()));
        [
            (Some(&c.op), "controller output op"),
            (Some(&c.pv), "process variable pv"),
            (c.sp.as_ref(), "setpoint sp"),
            (c.mode.as_ref(), "controller mode"),
            (c.mv.as_ref(), "valve position mv"),
            (c.time.as_ref(), "time"),
        ]
        .into_iter()
        .find_map(|(name, role)| name.filter(|n| !has(n)).map(|n| (n.clone(), role)))
    }
}

pub enum Layout {
    /// The flags name the columns of every loop.
    Flags,
    List(LoopList),
    Tags(TagPattern),
}

/// One loop of a loop list.
pub struct Entry {
    pub id: String,
    /// The file holding it (resolved against the list's folder), when the list names one.
    pub file: Option<PathBuf>,
    pub spec: LoopSpec,
    /// Where the list says so, for messages: "loops.csv line 4".
    pub at: String,
}

/// A plant's loop list: `--columns FILE.toml` (an array of `[[loop]]` tables) or `FILE.csv` (a
/// row per loop), each loop with an `id` and `op`, `pv`, and optionally `file`, `sp`, `mode`,
/// `mv`, `time`, `integrating`, `ts`.
pub struct LoopList {
    pub path: PathBuf,
    pub entries: Vec<Entry>,
}

/// A loop as the list writes it (every value as text for CSV; typed in TOML).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawEntry {
    #[serde(alias = "loop")]
    id: Option<String>,
    file: Option<String>,
    op: Option<String>,
    pv: Option<String>,
    sp: Option<String>,
    mode: Option<String>,
    mv: Option<String>,
    time: Option<String>,
    integrating: Option<Flag>,
    ts: Option<Number>,
}

/// `true`, or text such as `yes` / `1` in a CSV cell.
#[derive(Deserialize)]
#[serde(untagged)]
enum Flag {
    Bool(bool),
    Text(String),
}

#[derive(Deserialize)]
#[serde(untagged)]
enum Number {
    Float(f64),
    Int(i64),
    Text(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlList {
    #[serde(rename = "loop", default)]
    loops: Vec<RawEntry>,
}

fn blank(s: Option<String>) -> Option<String> {
    s.map(|s| s.trim().to_string()).filter(|s| !s.is_empty())
}

impl LoopList {
    /// Read a loop list; the flags give what a loop leaves out (time column, sampling time,
    /// integrating, the valve start estimate).
    pub fn read(path: &Path, flags: &Columns) -> Result<LoopList> {
        let shown = path.display();
        let text = std::fs::read_to_string(path).with_context(|| {
            format!("{shown}: the loop list cannot be read; check the path given to --columns")
        })?;
        let toml = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
        let raw: Vec<(String, RawEntry)> = if toml {
            let list: TomlList = toml::from_str(&text)
                .map_err(|e| anyhow::anyhow!("{shown}: not a loop list ({}); write one [[loop]] table per loop with id, op and pv", e.message()))?;
            list.loops
                .into_iter()
                .enumerate()
                .map(|(k, e)| (format!("{shown}, loop {}", k + 1), e))
                .collect()
        } else {
            read_csv(path, &text)?
        };
        if raw.is_empty() {
            bail!("{shown}: the loop list names no loop; give one loop per row (CSV) or [[loop]] table (TOML)");
        }
        let folder = path.parent().unwrap_or(Path::new(""));
        let entries = raw
            .into_iter()
            .map(|(at, e)| entry(at, e, folder, flags))
            .collect::<Result<Vec<_>>>()?;
        Ok(LoopList {
            path: path.to_path_buf(),
            entries,
        })
    }
}

/// The rows of a CSV loop list, headers matched case-insensitively.
fn read_csv(path: &Path, text: &str) -> Result<Vec<(String, RawEntry)>> {
    let shown = path.display();
    let text = text.trim_start_matches('\u{feff}');
    let delimiter = crate::data::sniff_delimiter(text.lines().next().unwrap_or(""));
    let mut r = csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers: csv::StringRecord = r
        .headers()
        .with_context(|| format!("{shown}: the header line of the loop list cannot be read"))?
        .iter()
        .map(str::to_ascii_lowercase)
        .collect();
    let mut out = Vec::new();
    for rec in r.records() {
        let rec = rec.with_context(|| format!("{shown}: not a readable CSV loop list"))?;
        let line = rec.position().map_or(0, |p| p.line());
        let e: RawEntry = rec.deserialize(Some(&headers)).map_err(|e| {
            anyhow::anyhow!("{shown}: line {line}: {e}; the columns of a loop list are id, file, op, pv, sp, mode, mv, time, integrating, ts")
        })?;
        out.push((format!("{shown} line {line}"), e));
    }
    Ok(out)
}

fn entry(at: String, e: RawEntry, folder: &Path, flags: &Columns) -> Result<Entry> {
    let Some(id) = blank(e.id) else {
        bail!("{at}: the loop has no id; give each loop an id (the name in the summary)");
    };
    let need = |v: Option<String>, what: &str| {
        blank(v).with_context(|| format!("{at}: loop '{id}' names no {what} column; add it"))
    };
    let op = need(e.op, "op")?;
    let pv = need(e.pv, "pv")?;
    // a loop's integrating true or false says its kind; left out, the flags' (or its tag or
    // behaviour) decide
    let said = (flags.integrating, flags.self_regulating);
    let (integrating, self_regulating) = match e.integrating {
        None => said,
        Some(Flag::Bool(b)) => (b, !b),
        Some(Flag::Text(t)) => match t.trim().to_ascii_lowercase().as_str() {
            "" => said,
            "true" | "yes" | "1" | "y" => (true, false),
            "false" | "no" | "0" | "n" => (false, true),
            _ => bail!("{at}: loop '{id}': integrating is '{t}'; write true or false"),
        },
    };
    let ts = match e.ts {
        None => flags.ts,
        Some(Number::Float(x)) => Some(x),
        Some(Number::Int(x)) => Some(x as f64),
        Some(Number::Text(t)) if t.trim().is_empty() => flags.ts,
        Some(Number::Text(t)) => Some(t.trim().parse::<f64>().map_err(|_| {
            anyhow::anyhow!("{at}: loop '{id}': ts is '{t}', not a number of seconds")
        })?),
    };
    if let Some(ts) = ts.filter(|ts| !(*ts > 0.0 && ts.is_finite())) {
        bail!("{at}: loop '{id}': ts {ts}: the sampling time must be a positive number of seconds");
    }
    Ok(Entry {
        file: blank(e.file).map(|f| folder.join(f)),
        spec: LoopSpec {
            columns: Columns {
                op,
                pv,
                sp: blank(e.sp),
                mode: blank(e.mode),
                time: blank(e.time).or_else(|| flags.time.clone()),
                ts,
                integrating,
                self_regulating,
                estimate_start: flags.estimate_start,
                thorough: flags.thorough,
                mv: blank(e.mv),
                op_range: flags.op_range,
                reading: flags.reading.clone(),
            },
        },
        id,
        at,
    })
}

/// The roles a column can have in a tag pattern.
const ROLES: [&str; 5] = ["op", "pv", "sp", "mode", "mv"];

/// `--tags PATTERN`: a column name made of a loop's name and a role (op, pv, sp, mode, mv), e.g.
/// `{loop}.{role}` for `FIC101.OP` or `{role}_{loop}` for `PV_FIC101`; case-insensitive.
pub struct TagPattern {
    pub text: String,
    re: regex::Regex,
}

/// The columns of one loop found by a tag pattern, in the order of the file.
pub struct Tagged {
    pub loop_name: String,
    /// Role -> column name.
    pub columns: BTreeMap<&'static str, String>,
}

impl TagPattern {
    pub fn parse(text: &str) -> Result<TagPattern> {
        let bad = || {
            anyhow::anyhow!(
                "--tags '{text}': the pattern needs {{loop}} and {{role}} once each, e.g. '{{loop}}.{{role}}' for columns such as FIC101.OP"
            )
        };
        let (before, after) = text.split_once("{loop}").ok_or_else(bad)?;
        let mut re = String::from("(?i)^");
        let roles = ROLES.join("|");
        if let Some((a, b)) = after.split_once("{role}") {
            if before.contains("{role}") || b.contains("{loop}") || b.contains("{role}") {
                return Err(bad());
            }
            re += &format!(
                "{}(?P<loop>.+?){}(?P<role>{roles}){}$",
                regex::escape(before),
                regex::escape(a),
                regex::escape(b)
            );
        } else if let Some((a, b)) = before.split_once("{role}") {
            if after.contains("{loop}") || after.contains("{role}") || a.contains("{loop}") {
                return Err(bad());
            }
            re += &format!(
                "{}(?P<role>{roles}){}(?P<loop>.+?){}$",
                regex::escape(a),
                regex::escape(b),
                regex::escape(after)
            );
        } else {
            return Err(bad());
        }
        Ok(TagPattern {
            text: text.to_string(),
            re: regex::Regex::new(&re).map_err(|_| bad())?,
        })
    }

    /// Split a file's columns into loops (columns the pattern does not fit, such as time, are
    /// left out). A loop named twice with the same role keeps its first column.
    pub fn split(&self, headers: &[String]) -> Vec<Tagged> {
        let mut loops: Vec<Tagged> = Vec::new();
        for h in headers {
            let Some(c) = self.re.captures(h.trim()) else {
                continue;
            };
            let name = c["loop"].to_string();
            let role_text = c["role"].to_ascii_lowercase();
            let Some(role) = ROLES.iter().copied().find(|r| *r == role_text) else {
                continue;
            };
            // historian tags ignore case: FIC101.OP and fic101.pv are one loop
            let k = match loops
                .iter()
                .position(|l| l.loop_name.eq_ignore_ascii_case(&name))
            {
                Some(k) => k,
                None => {
                    loops.push(Tagged {
                        loop_name: name,
                        columns: BTreeMap::new(),
                    });
                    loops.len() - 1
                }
            };
            loops[k]
                .columns
                .entry(role)
                .or_insert_with(|| h.trim().to_string());
        }
        loops
    }

    /// What the pattern expects for a loop's role (for messages): `FIC101.OP`.
    pub fn expected(&self, loop_name: &str, role: &str) -> String {
        self.text
            .replace("{loop}", loop_name)
            .replace("{role}", &role.to_ascii_uppercase())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(p: &TagPattern, headers: &[&str]) -> Vec<(String, Vec<(&'static str, String)>)> {
        let h: Vec<String> = headers.iter().map(|s| s.to_string()).collect();
        p.split(&h)
            .into_iter()
            .map(|t| (t.loop_name, t.columns.into_iter().collect()))
            .collect()
    }

    #[test]
    fn tags_split_wide_exports_into_loops() {
        let p = TagPattern::parse("{loop}.{role}").unwrap();
        let got = names(
            &p,
            &[
                "time",
                "FIC.101.OP",
                "fic.101.pv",
                "LIC7.Pv",
                "LIC7.OP",
                "X.Y",
                "LIC7.op",
            ],
        );
        let want = [
            ("FIC.101", vec![("op", "FIC.101.OP"), ("pv", "fic.101.pv")]),
            ("LIC7", vec![("op", "LIC7.OP"), ("pv", "LIC7.Pv")]),
        ]
        .map(|(n, c)| {
            let c: Vec<(&'static str, String)> =
                c.into_iter().map(|(r, h)| (r, h.to_string())).collect();
            (n.to_string(), c)
        });
        assert_eq!(got, want);
        let p = TagPattern::parse("{role}_{loop}").unwrap();
        assert_eq!(
            names(&p, &["PV_FIC1", "op_FIC1", "t"]),
            [(
                "FIC1".to_string(),
                vec![("op", "op_FIC1".to_string()), ("pv", "PV_FIC1".to_string())]
            )]
        );
        assert_eq!(p.expected("FIC1", "sp"), "SP_FIC1");
        for bad in ["{loop}", "{role}", "x", "{loop}{role}{loop}"] {
            assert!(TagPattern::parse(bad).is_err(), "{bad}");
        }
    }
}
