//! `stiction report`: diagnose a loop and write one self-contained HTML page: inline SVG charts,
//! inline CSS, no scripts, fonts, images or links outside the file, readable on a laptop, a phone
//! and on paper. The page itself is [`stiction_report`]'s
//! (shared with the Python package's `stiction.report`).

use crate::atomic::write_atomic;
use crate::loop_file::Columns;
use crate::words::verdict;
use anyhow::{Context, Result};
use std::path::PathBuf;
use stiction_report::PageOptions;

#[derive(clap::Args)]
#[command(after_help = "Examples:
  stiction report loop.csv --sp sp -o loop.html
  stiction report export.csv --op FIC101.OP --pv FIC101.PV --mode FIC101.MODE -o fic101.html
  stiction report level.csv --op OP --pv PV --integrating --window 2000 -o level.html")]
pub struct Args {
    /// Data file: CSV with a header line, .csv.gz, a workbook, Parquet, or - for standard input
    pub file: PathBuf,
    #[command(flatten)]
    pub columns: Columns,
    /// Add a verdict per window of this many samples (locates intermittent stiction)
    #[arg(long)]
    pub window: Option<usize>,
    /// Skip the closed-loop estimate of the band (faster)
    #[arg(long, conflicts_with = "estimate_start")]
    pub no_quantify: bool,
    /// The HTML file to write (one self-contained page)
    #[arg(short = 'o', long = "output", value_name = "FILE.html")]
    pub output: PathBuf,
    /// Exit with code 4 when the verdict is stiction (after writing the report), for scripts
    #[arg(long, value_enum, value_name = "VERDICT")]
    pub fail_on: Option<crate::exit::FailOn>,
}

pub fn run(a: Args) -> Result<()> {
    let table = a.columns.open(&a.file)?;
    let lf = a.columns.read(&table)?;
    let mut req = a.columns.request(lf.ts);
    req.window = a.window;
    req.quantify = !a.no_quantify;
    let id = table.path.display().to_string();
    let core_error = |e| crate::loop_messages::core_error(&id, &lf, e);
    let req = req.check().map_err(core_error)?;
    let d = crate::diagnosed::diagnose(&lf.record(), &req).map_err(core_error)?;
    let names = a.columns.names();
    let reading = lf.reading_notes();
    let options = PageOptions {
        columns: Some(&names),
        back_link: None,
        reading: &reading,
    };
    let html = stiction_report::loop_page(&id, &lf.data(), &d, &options)
        .with_context(|| format!("{}: cannot render the report", a.output.display()))?;
    write_atomic(&a.output, html.as_bytes())?;
    println!(
        "{id}: {}{}; report written to {}",
        verdict(d.verdict),
        d.probability
            .map(|p| format!(" (P {p:.2})"))
            .unwrap_or_default(),
        a.output.display()
    );
    crate::loop_messages::print_notes(&id, &lf, false);
    crate::exit::FailOn::check(a.fail_on, d.verdict)
}
