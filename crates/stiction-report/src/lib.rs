//! The HTML pages of stiction: a loop's report (`stiction report`, each loop's page of `stiction
//! batch --reports`, and `stiction.report` in Python) and the fleet's index page, rendered from
//! minijinja templates (`templates/`, embedded in the library) with one stylesheet (`style.css`)
//! and the words of [`words`]. The CLI and the Python package both call [`loop_page`], so the
//! same loop gives the same page whichever front end wrote it.
//!
//! Each page is self-contained: inline CSS, inline SVG charts, no fonts, images or scripts from
//! elsewhere (the fleet page carries a few lines of inline script to sort and filter). Every text
//! taken from the data (file, column and loop names) is escaped by the templates.
//!
//! The context of a page is built first as plain serialisable structs (the private `context`
//! and `sections`, and [`fleet`]); the templates only lay it out.

pub mod chart;
mod context;
pub mod fleet;
mod plots;
mod sections;
mod series;
pub mod words;

pub use context::Link;

use anyhow::Result;
use minijinja::{AutoEscape, Environment, Value};
use std::sync::OnceLock;
use stiction_core::diagnose::Diagnosis;

/// The stylesheet every page inlines.
const CSS: &str = include_str!("style.css");

const TEMPLATES: [(&str, &str); 4] = [
    ("base.html", include_str!("templates/base.html")),
    ("macros.html", include_str!("templates/macros.html")),
    ("report.html", include_str!("templates/report.html")),
    ("fleet.html", include_str!("templates/fleet.html")),
];

/// A loop's signals as the diagnosis read them (after the record's preparation: rows in time
/// order, gaps as NaN in op, pv and sp, not automatic in `auto`).
#[derive(Clone, Copy)]
pub struct LoopData<'a> {
    pub op: &'a [f64],
    pub pv: &'a [f64],
    pub sp: Option<&'a [f64]>,
    /// Seconds, when the record had a time axis (else sample k is at k * ts).
    pub time: Option<&'a [f64]>,
    pub auto: Option<&'a [bool]>,
    /// Sampling time, seconds.
    pub ts: f64,
}

/// The names of the columns a loop was read from, for the page's header.
#[derive(Clone, Debug, Default)]
pub struct ColumnNames {
    pub op: String,
    pub pv: String,
    pub sp: Option<String>,
    pub mode: Option<String>,
    /// The time column when it was named; `None` with a time axis says it was found by its name.
    pub time: Option<String>,
    pub integrating: bool,
}

/// How a loop's page is rendered beyond its data.
#[derive(Default)]
pub struct PageOptions<'a> {
    /// The columns the loop was read from, named in the header when known.
    pub columns: Option<&'a ColumnNames>,
    /// A link above the title: (href, text), e.g. batch's `("../index.html", "all loops")`.
    pub back_link: Option<(String, String)>,
    /// What reading the record decided (gaps, a grid, a pivot, the time's form), shown in the
    /// page's notes.
    pub reading: &'a [String],
}

/// Escape text for HTML element content and quoted attribute values.
pub fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// The templates, parsed once. Output is escaped with [`esc`] (minijinja's own escaping would
/// also turn `/` into `&#x2f;`, which makes paths hard to read in the source).
fn environment() -> &'static Environment<'static> {
    static ENV: OnceLock<Environment<'static>> = OnceLock::new();
    ENV.get_or_init(|| {
        let mut env = Environment::new();
        env.set_auto_escape_callback(|_| AutoEscape::Html);
        env.set_formatter(|out, state, value| {
            if *state.auto_escape() == AutoEscape::None || value.is_safe() {
                return minijinja::escape_formatter(out, state, value);
            }
            match value.as_str() {
                Some(s) => out.write_str(&esc(s)).map_err(minijinja::Error::from),
                None if value.is_none() || value.is_undefined() => Ok(()),
                None => out
                    .write_str(&esc(&value.to_string()))
                    .map_err(minijinja::Error::from),
            }
        });
        for (name, source) in TEMPLATES {
            env.add_template(name, source)
                .expect("the embedded templates parse");
        }
        env.add_global("css", Value::from_safe_string(CSS.to_string()));
        env
    })
}

/// Render the template `name` with `ctx`.
fn render_template(name: &str, ctx: impl serde::Serialize) -> Result<String> {
    let tmpl = environment().get_template(name)?;
    tmpl.render(Value::from(minijinja::value::Serde(&ctx)))
        .map_err(|e| anyhow::anyhow!("the {name} template: {e:#}"))
}

/// A loop's report as one HTML document: `data` the signals the diagnosis `d` read, `loop_id`
/// names the loop in the title (a file name or tag). The only parts that change from run to run
/// of the same loop are the times the diagnosis and the estimate took.
pub fn loop_page(loop_id: &str, data: &LoopData, d: &Diagnosis, o: &PageOptions) -> Result<String> {
    let ctx = context::build(loop_id, data, d, o)?;
    render_template("report.html", ctx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_template_parses_and_text_is_escaped_once() {
        let env = environment();
        for (name, _) in TEMPLATES {
            assert!(env.get_template(name).is_ok(), "{name}");
        }
        let t = env
            .template_from_str("{{ a }}|{{ b }}|{{ n }}|{{ none }}")
            .unwrap();
        let out = t
            .render(minijinja::context! { a => "a<b>&'c/d", b => Value::from_safe_string("<i>".into()), n => 1.5, none => () })
            .unwrap();
        assert_eq!(out, "a&lt;b&gt;&amp;&#39;c/d|<i>|1.5|");
    }
}
