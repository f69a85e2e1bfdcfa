//! `stiction diagnose`: quality gates, oscillation, stiction indices and a verdict for one loop.

use crate::exit::{Ending, Exit};
use crate::words::{count, seconds};
use anyhow::Result;
use std::path::PathBuf;
use stiction_core::diagnose::{diagnose, BandSource, DiagnoseError, Diagnosis, Verdict, Vote};

// the loop-record types moved to their own module; these paths stay for the other commands
pub use crate::loop_file::{Columns, LoopFile};

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

/// Verdicts a script can gate on with `--fail-on`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FailOn {
    /// The verdict is stiction (exit code 4)
    Stiction,
}

impl FailOn {
    /// The ending for `--fail-on` when the verdict calls for it.
    pub fn check(fail_on: Option<FailOn>, verdict: Verdict) -> Result<()> {
        match fail_on {
            Some(FailOn::Stiction) if verdict == Verdict::Stiction => Err(Ending::error(
                Exit::StictionFound,
                "stiction found (--fail-on stiction: exit code 4)",
            )),
            _ => Ok(()),
        }
    }
}

pub fn run(a: Args) -> Result<()> {
    let table = a.columns.open(&a.file)?;
    let lf = a.columns.read(&table)?;
    let mut req = a.columns.request(lf.ts);
    req.window = a.window;
    req.quantify = !a.no_quantify;
    let name = table.path.display().to_string();
    let d = diagnose(&lf.record(), &req).map_err(|e| core_error(&name, &lf, e))?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&d)?);
        print_notes(&name, &lf, true);
    } else {
        print_human(&name, &d);
        print_notes(&name, &lf, false);
    }
    FailOn::check(a.fail_on, d.verdict)
}

/// The core's error in one sentence, naming the file and the flag to change.
pub fn core_error(name: &str, _lf: &LoopFile, e: DiagnoseError) -> anyhow::Error {
    match e {
        DiagnoseError::Window { window, least } => anyhow::anyhow!(
            "{name}: --window {window}: a window needs at least {least} samples; give a larger --window"
        ),
        DiagnoseError::Ts(ts) => anyhow::anyhow!(
            "{name}: --ts {ts}: the sampling time must be a positive number of seconds"
        ),
        DiagnoseError::OpRange { lo, hi } => anyhow::anyhow!(
            "{name}: --op-range {lo}:{hi}: the value of a fully open valve must exceed that of a closed one"
        ),
        e => anyhow::anyhow!("{name}: {e}"),
    }
}

/// What the reader decided (gaps, time order, time form): lines of the human output, or notes
/// on standard error beside JSON.
pub fn print_notes(name: &str, lf: &LoopFile, stderr: bool) {
    for n in lf.missing_note().iter().chain(&lf.notes) {
        if stderr {
            eprintln!("note: {name}: {n}");
        } else {
            println!("  note: {n}");
        }
    }
}

fn band_source(s: BandSource) -> &'static str {
    match s {
        BandSource::Valve => "from the recorded valve position",
        BandSource::ClosedLoop => "closed-loop estimate, Stenman exact",
        BandSource::FitScan => "closed-loop fit's scan",
        BandSource::StickSlip => "median OP travel per stick",
        BandSource::DescribingFunction => "describing function of the limit cycle",
    }
}

pub fn print_human(file: &str, d: &Diagnosis) {
    let verdict = match d.verdict {
        Verdict::Stiction => "STICTION",
        Verdict::NoStiction => "no stiction",
        Verdict::Undetermined => "undetermined",
        Verdict::InsufficientData => "insufficient data",
    };
    match d.confidence {
        Some(c) => println!("{file}: {verdict} (confidence {c:.2})"),
        None => println!("{file}: {verdict}"),
    }
    if let Some(r) = &d.reason {
        println!("  reason: {r}");
    }
    if let Some(b) = &d.band {
        let interval = b
            .interval_percent_of_span
            .map(|[lo, hi]| format!(", optimal set {lo:.2} to {hi:.2} %"))
            .unwrap_or_default();
        let mut others: Vec<String> = b
            .others
            .iter()
            .map(|(s, v)| format!("{} {v:.2} %", band_source(*s)))
            .collect();
        if let Some(e) = b.ellipse_percent_of_span {
            others.push(format!("ellipse {e:.2} %"));
        }
        println!(
            "  stiction band: {:.2} % of valve span ({}{interval}){}",
            b.band_percent_of_span,
            band_source(b.source),
            if others.is_empty() {
                String::new()
            } else {
                format!("; beside it: {}", others.join(", "))
            }
        );
    }
    if let Some(m) = d.families.iter().find_map(|f| f.model.as_ref()) {
        println!(
            "  closed-loop fit: R² {:.3} without stiction, {:.3} with (Stenman), {:.3} with a slip jump (Kano)",
            m.r2_without_stiction, m.r2_stenman, m.r2_slip_jump
        );
    }
    if let Some(l) = d.families.iter().find_map(|f| f.limit_cycle.as_ref()) {
        println!(
            "  linear loop: gain margin {}; to sustain the {:.0} s cycle the valve must lag OP by {:.0}° (gain {:.2}){}",
            l.margins
                .gain_margin
                .map_or("none".into(), |g| format!("{g:.2}")),
            l.period,
            l.needed_lag_degrees,
            l.needed_gain,
            l.describing.as_ref().map_or(String::new(), |b| format!(
                "; describing function: a band of {:.2} % of span{}",
                b.band_percent_of_span,
                b.predicted_period
                    .map_or(String::new(), |p| format!(", predicted period {p:.0} s"))
            ))
        );
    }
    println!("  next step: {}", d.next_step);
    println!("  evidence:");
    for f in &d.families {
        println!(
            "    {:<21} {:<13} {}",
            f.family.words(),
            crate::words::vote(f.vote),
            f.note
        );
    }
    if !d.indices.is_empty() {
        println!("  shape indices (oscillating stretch):");
        for i in &d.indices {
            println!(
                "    {:<18} {:>8}  {:<13} {}{}",
                i.name,
                i.value.map_or("-".into(), |v| format!("{v:.3}")),
                crate::words::vote(i.vote),
                i.threshold,
                if i.weight == 0.0 {
                    " [shown, not counted]"
                } else if i.only_votes.is_some() && i.vote == Vote::Undetermined {
                    " [one-sided: silent]"
                } else {
                    ""
                }
            );
        }
    }
    println!(
        "  {} at {} s; analysed samples {} to {} ({})",
        count(d.samples, "sample", "samples"),
        seconds(d.ts),
        d.analysed[0],
        d.analysed[1],
        count(d.stretches.len(), "usable stretch", "usable stretches")
    );
    if let Some(o) = &d.oscillation {
        println!(
            "  oscillation: {}; period {}; regularity {:.2} (threshold {}); {} half periods with a large IAE",
            if o.oscillating { "yes" } else { "no" },
            o.period.map_or("-".into(), |p| format!("{p:.1} s")),
            o.regularity.regularity,
            o.regularity.threshold,
            o.iae.exceedances
        );
    }
    let failed: Vec<_> = d.quality.iter().filter(|f| !f.passed).collect();
    if failed.is_empty() {
        println!(
            "  data quality: every check passed ({} made)",
            d.quality.len()
        );
    } else {
        for f in failed {
            println!("  data quality, {}: {}", f.gate, f.message);
        }
    }
    if !d.windows.is_empty() {
        println!("  windows:");
        for w in &d.windows {
            println!(
                "    samples {:>7} to {:>7} (t {:.0} to {:.0} s): {}{}{}",
                w.start,
                w.end,
                w.t_start,
                w.t_end,
                w.verdict,
                w.confidence
                    .map(|c| format!(" ({c:.2})"))
                    .unwrap_or_default(),
                w.reason
                    .as_deref()
                    .map(|r| format!(": {r}"))
                    .unwrap_or_default()
            );
        }
    }
    for w in &d.warnings {
        println!("  note: {w}");
    }
}
