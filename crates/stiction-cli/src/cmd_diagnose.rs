//! `stiction diagnose`: quality gates, the families' statistics, the probability of a sticky
//! valve and a verdict for one loop; `--settings` prints how it measures and decides.

use crate::exit::FailOn;
use crate::human::print_diagnosis;
use crate::loop_file::Columns;
use crate::loop_messages::{core_error, print_notes};
use anyhow::Result;
use std::path::PathBuf;

#[derive(clap::Args, Clone)]
#[command(after_help = "Examples:
  stiction diagnose loop.csv --op op --pv pv --sp sp
  stiction diagnose export.csv --op FIC101.OP --pv FIC101.PV --mode FIC101.MODE --json
  stiction diagnose level.xlsx --sheet Data --op OP --pv PV --integrating --window 2000
  stiction diagnose plant.csv.gz --time-format '%d.%m.%Y %H:%M:%S' --tz Europe/Berlin
  stiction diagnose loop.csv --fail-on stiction || echo 'valve needs maintenance'
  stiction diagnose --settings

Reads CSV (comma, semicolon or tab), .csv.gz, .xlsx/.xls/.ods, .parquet, or - for standard
input, the format found from the file's bytes. Blank cells, NaN, #N/A and historian states such as
Bad Input, I/O Timeout, Comm Fail or Shutdown are gaps.")]
pub struct Args {
    /// Data file: CSV with a header line, .csv.gz, a workbook, Parquet, or - for standard input
    #[arg(required_unless_present = "settings")]
    pub file: Option<PathBuf>,
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
    /// Print how diagnose measures (its settings, at their defaults) and decides (the verdict's
    /// model: statistics, knots, weights, references, thresholds), then stop; no FILE needed
    #[arg(long, conflicts_with_all = ["window", "no_quantify", "fail_on"])]
    pub settings: bool,
    /// Exit with code 4 when the verdict is stiction (after printing it), for scripts
    #[arg(long, value_enum, value_name = "VERDICT")]
    pub fail_on: Option<FailOn>,
}

pub fn run(a: Args) -> Result<()> {
    let Some(file) = a.file.as_ref().filter(|_| !a.settings) else {
        return crate::human::settings::print(a.json);
    };
    let table = a.columns.open(file)?;
    let lf = a.columns.read(&table)?;
    let mut req = a.columns.request(lf.ts);
    req.window = a.window;
    req.quantify = !a.no_quantify;
    let name = table.path.display().to_string();
    let req = req.check().map_err(|e| core_error(&name, &lf, e))?;
    let d =
        crate::diagnosed::diagnose(&lf.record(), &req).map_err(|e| core_error(&name, &lf, e))?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&d)?);
        print_notes(&name, &lf, true);
    } else {
        print_diagnosis(&name, &d);
        print_notes(&name, &lf, false);
    }
    FailOn::check(a.fail_on, d.verdict)
}
