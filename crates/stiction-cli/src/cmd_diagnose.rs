use crate::data;
use anyhow::{bail, Context, Result};
use std::path::PathBuf;
use stiction_core::diagnose::{diagnose, DiagnoseRequest, Diagnosis, LoopRecord, Verdict, Vote};

#[derive(clap::Args, Clone)]
#[command(after_help = "Examples:
  stiction diagnose loop.csv --op op --pv pv --sp sp
  stiction diagnose export.csv --op FIC101.OP --pv FIC101.PV --mode FIC101.MODE --json
  stiction diagnose level.csv --op OP --pv PV --integrating --window 2000")]
pub struct Args {
    /// CSV file with a header line (comma, semicolon or tab separated)
    pub file: PathBuf,
    #[command(flatten)]
    pub columns: Columns,
    /// Add a verdict per window of this many samples (locates intermittent stiction)
    #[arg(long)]
    pub window: Option<usize>,
    /// Skip the closed-loop estimate of the band (faster)
    #[arg(long)]
    pub no_quantify: bool,
    /// Print the diagnosis as JSON
    #[arg(long)]
    pub json: bool,
}

/// The columns of a loop record and how to read them (shared by diagnose, report and batch).
#[derive(clap::Args, Clone)]
pub struct Columns {
    /// Column of the controller output
    #[arg(long, default_value = "op")]
    pub op: String,
    /// Column of the process variable
    #[arg(long, default_value = "pv")]
    pub pv: String,
    /// Column of the setpoint [default: none; the error is then PV's deviation from its mean]
    #[arg(long)]
    pub sp: Option<String>,
    /// Column of the controller mode (auto/manual or 1/0); only automatic stretches are judged
    #[arg(long)]
    pub mode: Option<String>,
    /// Column of time (seconds, or dates such as 2024-03-01 12:00:05) [default: t, time or timestamp if present]
    #[arg(long)]
    pub time: Option<String>,
    /// Sampling time in seconds [default: the median step of the time column, else 1]
    #[arg(long)]
    pub ts: Option<f64>,
    /// The process is integrating (a level loop): the indices use their integrating variants
    #[arg(long)]
    pub integrating: bool,
    /// Closed-loop estimate: estimate where the valve stood at the first sample (as quantify
    /// --estimate-start; about 3-4x the estimate's time)
    #[arg(long)]
    pub estimate_start: bool,
}

/// A loop record read from a file.
pub struct LoopFile {
    pub op: Vec<f64>,
    pub pv: Vec<f64>,
    pub sp: Option<Vec<f64>>,
    pub time: Option<Vec<f64>>,
    pub auto: Option<Vec<bool>>,
    pub ts: f64,
}

impl LoopFile {
    pub fn record(&self) -> LoopRecord<'_> {
        LoopRecord {
            op: &self.op,
            pv: &self.pv,
            sp: self.sp.as_deref(),
            time: self.time.as_deref(),
            auto: self.auto.as_deref(),
        }
    }
}

impl Columns {
    pub fn read(&self, table: &data::Table) -> Result<LoopFile> {
        if let Some(ts) = self.ts {
            if !(ts > 0.0 && ts.is_finite()) {
                bail!("--ts {ts}: the sampling time must be a positive number of seconds");
            }
        }
        let file = table.path.display();
        if table.len() == 0 {
            bail!("{file}: the file has a header but no data rows");
        }
        let op = table.numbers(table.require(&self.op, "--op", "controller output op")?)?;
        let pv = table.numbers(table.require(&self.pv, "--pv", "process variable pv")?)?;
        let sp = match &self.sp {
            Some(c) => Some(table.numbers(table.require(c, "--sp", "setpoint sp")?)?),
            None => None,
        };
        let auto = match &self.mode {
            Some(c) => Some(table.modes(table.require(c, "--mode", "controller mode")?)?),
            None => None,
        };
        let time_col = data::time_column(table, self.time.as_deref())?;
        let time = time_col.map(|c| table.times(c)).transpose()?;
        let ts = match (self.ts, &time) {
            (Some(ts), _) => ts,
            (None, Some(t)) => data::sampling_time(t).with_context(|| {
                format!(
                    "{file}: the time column '{}' does not increase; give the sampling time with --ts SECONDS",
                    table.headers[time_col.unwrap_or(0)]
                )
            })?,
            (None, None) => 1.0,
        };
        Ok(LoopFile {
            op,
            pv,
            sp,
            time,
            auto,
            ts,
        })
    }

    pub fn request(&self, ts: f64) -> DiagnoseRequest {
        DiagnoseRequest {
            ts,
            integrating: self.integrating,
            estimate_start: self.estimate_start,
            ..DiagnoseRequest::default()
        }
    }
}

pub fn run(a: Args) -> Result<()> {
    let table = data::Table::read(&a.file)?;
    let lf = a.columns.read(&table)?;
    let mut req = a.columns.request(lf.ts);
    req.window = a.window;
    req.quantify = !a.no_quantify;
    let d =
        diagnose(&lf.record(), &req).map_err(|e| anyhow::anyhow!("{}: {e}", a.file.display()))?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&d)?);
    } else {
        print_human(&a.file.display().to_string(), &d);
    }
    Ok(())
}

fn vote_word(v: Vote) -> &'static str {
    match v {
        Vote::Stiction => "stiction",
        Vote::NoStiction => "no stiction",
        Vote::Undetermined => "undetermined",
    }
}

pub fn print_human(file: &str, d: &Diagnosis) {
    println!(
        "{file}: {} (confidence {:.2})",
        match d.verdict {
            Verdict::Stiction => "STICTION",
            Verdict::NoStiction => "no stiction",
            Verdict::Undetermined => "undetermined",
            Verdict::InsufficientData => "insufficient data",
        },
        d.confidence
    );
    if let Some(r) = &d.reason {
        println!("  reason: {r}");
    }
    println!(
        "  {} samples at {} s; analysed samples {} to {}",
        d.samples, d.ts, d.analysed[0], d.analysed[1]
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
    if !d.indices.is_empty() {
        println!("  indices:");
        for i in &d.indices {
            println!(
                "    {:<18} {:>8}  {:<13} {}{}",
                i.name,
                i.value.map_or("-".into(), |v| format!("{v:.3}")),
                vote_word(i.vote),
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
    if let Some(c) = &d.closed_loop_check {
        println!(
            "  closed-loop check: OP explains {:.0} % of the PV's variation above its noise ({} without stiction; at least {:.0} % for a valve-driven oscillation): {}",
            100.0 * c.explained.max(0.0),
            c.explained_without_stiction
                .map_or("-".into(), |w| format!("{:.0} %", 100.0 * w.max(0.0))),
            100.0 * c.limit,
            if c.passed { "passed" } else { "failed" }
        );
    }
    if let Some(a) = &d.apparent_stiction {
        if let Some(v) = a.closed_loop {
            let interval = a
                .closed_loop_interval
                .map(|[lo, hi]| format!(" (optimal set [{lo:.3}, {hi:.3}])"))
                .unwrap_or_default();
            println!(
                "  apparent stiction, closed-loop estimate (Stenman d): {v:.3} OP units{interval}"
            );
        }
        if let Some(v) = a.ellipse {
            println!("  apparent stiction, ellipse fit: {v:.3} OP units");
        }
    }
    let failed: Vec<_> = d.quality.iter().filter(|f| !f.passed).collect();
    if failed.is_empty() {
        println!(
            "  data quality: every gate passed ({} checked)",
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
                "    samples {:>7} to {:>7} (t {:.0} to {:.0} s): {} ({:.2}){}",
                w.start,
                w.end,
                w.t_start,
                w.t_end,
                w.verdict,
                w.confidence,
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
