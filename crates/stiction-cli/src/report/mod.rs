//! The HTML pages: a loop's report (`stiction report`, and each loop's page of `stiction batch
//! --reports`) and the fleet's index page, rendered from minijinja templates (`templates/`,
//! embedded in the binary) with one stylesheet (`style.css`) and the words of [`crate::words`].
//!
//! Each page is self-contained: inline CSS, inline SVG charts, no fonts, images or scripts from
//! elsewhere (the fleet page carries a few lines of inline script to sort and filter). Every text
//! taken from the data (file, column and loop names) is escaped by the templates.
//!
//! The context of a page is built first as plain serialisable structs ([`context`], [`sections`],
//! [`fleet`]); the templates only lay it out.

mod context;
pub mod fleet;
mod plots;
mod sections;
mod series;

pub use context::Link;

use crate::atomic::write_atomic;
use crate::loop_file::{Columns, LoopFile};
use anyhow::{Context as _, Result};
use minijinja::{AutoEscape, Environment, Value};
use std::path::Path;
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

/// How a loop's page is rendered beyond its data.
#[derive(Default)]
pub struct PageOptions<'a> {
    /// The columns the loop was read from, named in the header when known.
    pub columns: Option<&'a Columns>,
    /// A link above the title: (href, text), e.g. batch's `("../index.html", "all loops")`.
    pub back_link: Option<(String, String)>,
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

/// A loop's report as one HTML document. `loop_id` names the loop in the title (a file name or
/// tag).
pub fn loop_page(loop_id: &str, lf: &LoopFile, d: &Diagnosis, o: &PageOptions) -> Result<String> {
    let ctx = context::build(loop_id, lf, d, o)?;
    render_template("report.html", ctx)
}

/// Write a loop's report to `path` (atomically: a temporary file, then a rename).
pub fn write_loop_page(
    path: &Path,
    loop_id: &str,
    lf: &LoopFile,
    d: &Diagnosis,
    o: &PageOptions,
) -> Result<()> {
    let html = loop_page(loop_id, lf, d, o)
        .with_context(|| format!("{}: cannot render the report", path.display()))?;
    write_atomic(path, html.as_bytes())
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
