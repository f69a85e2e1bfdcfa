//! `stiction diagnose`: quality gates, oscillation, stiction indices and a verdict for one loop.

use crate::exit::FailOn;
use crate::human::print_diagnosis;
use crate::loop_file::Columns;
use crate::loop_messages::{core_error, print_notes};
use anyhow::Result;
use std::path::PathBuf;
use stiction_core::diagnose::diagnose_checked;

#[derive(clap::Args, Clone)]
#[command(after_help = "Examples:
  stiction diagnose loop.csv --op op --pv pv --sp sp
  stiction diagnose export.csv --op FIC101.OP --pv FIC101.PV --mode FIC101.MODE --json
  stiction diagnose level.xlsx --sheet Data --op OP --pv PV --integrating --window 2000
  stiction diagnose plant.csv.gz --time-format '%d.%m.%Y %H:%M:%S' --tz Europe/Berlin
  stiction diagnose loop.csv --fail-on stiction || echo 'valve needs maintenance'

Reads CSV (comma, semicolon or tab), .csv.gz, .xlsx/.xls/.ods, .parquet, or - for standard
input, the format found from the file's bytes. Blank cells, NaN, #N/A and historian states such as
Bad Input, I/O Timeout, Comm Fail or Shutdown are gaps.")]
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
    /// Print the diagnosis as JSON
    #[arg(long)]
    pub json: bool,
    /// Exit with code 4 when the verdict is stiction (after printing it), for scripts
    #[arg(long, value_enum, value_name = "VERDICT")]
    pub fail_on: Option<FailOn>,
}

pub fn run(a: Args) -> Result<()> {
    let table = a.columns.open(&a.file)?;
    let lf = a.columns.read(&table)?;
    let mut req = a.columns.request(lf.ts);
    req.window = a.window;
    req.quantify = !a.no_quantify;
    let name = table.path.display().to_string();
    let req = req.check().map_err(|e| core_error(&name, &lf, e))?;
    let d = diagnose_checked(&lf.record(), &req).map_err(|e| core_error(&name, &lf, e))?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&d)?);
        print_notes(&name, &lf, true);
    } else {
        print_diagnosis(&name, &d);
        print_notes(&name, &lf, false);
    }
    FailOn::check(a.fail_on, d.verdict)
}
