use crate::loop_file::{read_loop, Reading, Signals};
use crate::plot::{self, Chart, Kind, Series};
use crate::words::{count, seconds};
use crate::{data, spec};
use anyhow::{bail, Result};
use std::path::{Path, PathBuf};
use stiction_core::estimate::IntervalKind;
use stiction_core::quantify::{
    quantify_checked, FitOutput, LinearFamily, Quantification, QuantifyRequest, QuantifyStatus,
    ValveStartKind,
};

#[derive(clap::Args)]
#[command(after_help = "Examples:
  stiction quantify loop.csv --op op --pv pv
  stiction quantify loop.csv --model kano --method aco-r --seed 2 --json
  stiction quantify CHEM1.csv --op OP --pv PV --ts 1 --plot out/chem1
  stiction quantify export.parquet --op FIC101.OP --pv FIC101.PV --tz America/Chicago

Missing values (blank, NaN, #N/A, historian states such as Bad Input) are gaps: short ones (at
most 3 samples in a row, 1 % of the record) are bridged by straight lines; past longer ones the
longest stretch without a gap is used, and a note says which.")]
pub struct Args {
    /// Data file: CSV with a header line, .csv.gz, a workbook, Parquet, or - for standard input
    file: PathBuf,
    /// Column of the controller output
    #[arg(long, default_value = "op")]
    op: String,
    /// Column of the process variable
    #[arg(long, default_value = "pv")]
    pv: String,
    /// Column of time (seconds, or dates such as 2024-03-01 12:00:05) [default: the first of t, time, timestamp, datetime, date and other common names, if any]
    #[arg(long)]
    time: Option<String>,
    /// Sampling time in seconds [default: from the time column, else 1]
    #[arg(long)]
    ts: Option<f64>,
    #[command(flatten)]
    reading: Reading,
    #[command(flatten)]
    fit: spec::FitArgs,
    /// Write the PV-OP phase plot with the fitted model and the trends (PNG and SVG) to this folder
    #[arg(long)]
    plot: Option<PathBuf>,
    /// One parameter's search range, NAME=LO:HI (repeatable) [default: 0 to the OP's range]
    #[arg(long = "bounds", value_name = "NAME=LO:HI")]
    bounds: Vec<String>,
    /// Largest process delay tried, in samples
    #[arg(long, default_value_t = 30)]
    max_delay: usize,
    /// The process is integrating (a level loop); default: tried both ways
    #[arg(long, conflicts_with = "self_regulating")]
    integrating: bool,
    /// The process is self-regulating; default: tried both ways
    #[arg(long)]
    self_regulating: bool,
    /// exact: fit only the trajectories near the best points of a coarse scan (faster; exact there only)
    #[arg(long, conflicts_with = "full")]
    quick: bool,
    /// exact: fit every trajectory of the whole record (slower), not only the best cells of a
    /// search on the first samples (the default from 1,500 samples on)
    #[arg(long)]
    full: bool,
    /// stenman exact: choose where the valve stood at the first sample (candidates across the
    /// OP's span, each searched on the first samples; about 2-4x the time) instead of assuming it
    /// had just moved to the first OP: for records that start mid-cycle
    #[arg(long)]
    estimate_start: bool,
    /// aco, aco-r: ants per iteration
    #[arg(long)]
    ants: Option<usize>,
    /// aco, aco-r: iterations
    #[arg(long)]
    iterations: Option<usize>,
    /// grid: points per parameter
    #[arg(long, default_value_t = 40)]
    points: usize,
}

pub fn run(a: Args) -> Result<()> {
    let (kind, method) = a.fit.resolve()?;
    let table = a.reading.open(&a.file)?;
    let mut wanted = vec![a.op.as_str(), a.pv.as_str()];
    wanted.extend(a.time.as_deref());
    let table = table
        .for_columns(&wanted, &[&a.op, &a.pv], a.time.as_deref())
        .unwrap_or(table);
    let name = table.path.display().to_string();
    let signals = Signals {
        mv: None,
        op: &a.op,
        pv: &a.pv,
        sp: None,
        mode: None,
        time: a.time.as_deref(),
        ts: a.ts,
    };
    let lf = read_loop(&table, &signals, &a.reading.time_spec()?)?;
    let ts = lf.ts;
    // a fit needs a record without gaps: short ones bridged, then the longest stretch without one
    let stretch = data::fit_stretch(
        &table,
        &[(a.op.as_str(), &lf.op), (a.pv.as_str(), &lf.pv)],
        2,
        &|k| lf.row_of(k),
    )?;
    let op = stretch.columns[0][stretch.start..stretch.end].to_vec();
    let pv = stretch.columns[1][stretch.start..stretch.end].to_vec();
    let time = lf
        .time
        .as_ref()
        .map(|t| t[stretch.start..stretch.end].to_vec());

    let mut req = QuantifyRequest::new(kind, method);
    req.ts = ts;
    req.seed = a.fit.seed;
    req.max_delay = a.max_delay;
    req.full_partition = !a.quick;
    req.staged = !a.full;
    req.estimate_start = a.estimate_start;
    req.integrating = if a.integrating {
        Some(true)
    } else if a.self_regulating {
        Some(false)
    } else {
        None
    };
    req.grid.points = a.points;
    if let Some(n) = a.ants {
        req.aco.ants = n;
        req.acor.ants = n;
    }
    if let Some(n) = a.iterations {
        req.aco.iterations = n;
        req.acor.iterations = n;
    }
    if !a.bounds.is_empty() {
        let (lo, hi) = op
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        let b = spec::bounds(
            kind,
            &a.bounds,
            vec![(0.0, (hi - lo).max(f64::MIN_POSITIVE)); kind.dim()],
        )?;
        req.bounds = Some(b);
    }
    let req = req
        .check()
        .map_err(|e| anyhow::anyhow!("{name}: {}", spec::setting_error(e)))?;
    let q = quantify_checked(&op, &pv, &req)
        .map_err(|e| anyhow::anyhow!("{name}: {}", spec::setting_error(e)))?;
    let notes: Vec<&String> = stretch.note.iter().chain(&lf.notes).collect();

    if let Some(dir) = &a.plot {
        if q.status == QuantifyStatus::Ok {
            let t: Vec<f64> = match &time {
                // seconds from the first sample (text timestamps are seconds since 1970)
                Some(t) => t.iter().map(|v| v - t[0]).collect(),
                None => (0..op.len()).map(|k| k as f64 * ts).collect(),
            };
            plots(&q, &t, &op, &pv, dir)?;
        }
    }
    if a.fit.json {
        println!("{}", serde_json::to_string_pretty(&q)?);
        for n in notes {
            eprintln!("note: {name}: {n}");
        }
        return Ok(());
    }
    if q.status != QuantifyStatus::Ok {
        let which = if stretch.note.is_some() {
            format!(
                " (in the longest stretch without gaps, {} to {})",
                table.at(lf.row_of(stretch.start)),
                table.line(lf.row_of(stretch.end - 1))
            )
        } else {
            String::new()
        };
        bail!(
            "{name}: insufficient data{which}: {}",
            q.reason.as_deref().unwrap_or("the loop cannot be judged")
        );
    }
    print_human(&name, &q, a.plot.as_deref());
    for n in notes {
        println!("  note: {n}");
    }
    Ok(())
}

fn print_human(file: &str, q: &Quantification, plot_dir: Option<&Path>) {
    let band = q.apparent_stiction.unwrap_or(f64::NAN);
    let band_name = match q.model {
        stiction_core::ModelKind::Stenman => "the Stenman band d",
        stiction_core::ModelKind::He => "fs + fd",
        _ => "S",
    };
    println!(
        "{file}: apparent stiction {band:.3} (OP units, % of valve span when OP is in %; {band_name}), {:.1} % of the OP range",
        q.apparent_stiction_pct_of_op_range.unwrap_or(f64::NAN)
    );
    println!("  this is an apparent stiction inferred from OP and PV without the valve position");
    println!("  {} model, method {}:", q.model, q.method);
    for spec in q.model.params() {
        let v = q.params[spec.name];
        print!("    {} = {v:.4} ({})", spec.name, spec.description);
        if let Some([lo, hi]) = q.interval.get(spec.name) {
            let what = match q.interval_kind {
                IntervalKind::Exact => "every value in",
                IntervalKind::ExactLocal => "every value (exact near the best scan points) in",
                IntervalKind::ExactStaged => {
                    "every value (exact over the cells kept from a search of the first samples) in"
                }
                IntervalKind::Grid => "grid points at the minimum span",
                IntervalKind::Axis | IntervalKind::None => {
                    "fits equally well with the others fixed over"
                }
            };
            print!("; {what} [{lo:.4}, {hi:.4}]");
        }
        println!();
    }
    if let (Some(x0), Some(kind)) = (q.valve_start, q.valve_start_kind) {
        println!(
            "  valve at the first sample: {x0:.3} ({})",
            match kind {
                ValveStartKind::Estimated =>
                    "estimated: the best of candidates across the OP's span",
                ValveStartKind::Given => "given",
                ValveStartKind::FirstOp => "assumed at the first OP; --estimate-start estimates it",
            }
        );
    }
    if let Some(lm) = &q.linear_model {
        let mut phys = Vec::new();
        if let Some(g) = lm.gain {
            phys.push(if lm.family == LinearFamily::Integrating {
                format!("integration rate {g:.4} per s")
            } else {
                format!("gain {g:.3}")
            });
        }
        if let Some(tc) = lm.time_constant {
            phys.push(format!("time constant {tc:.1} s"));
        }
        phys.push(format!("dead time {:.1} s", lm.dead_time));
        println!(
            "  linear model: {} ARX, na = {}, nb = {}, delay {} samples: {}",
            lm.family,
            lm.na,
            lm.nb,
            lm.nk,
            phys.join(", ")
        );
    }
    if let Some(f) = &q.fit {
        println!(
            "  fit of {}: R² {:.4} in simulation, {:.4} one step ahead",
            if f.output == FitOutput::Pv {
                "PV"
            } else {
                "the PV's change per sample"
            },
            f.r2_simulation,
            f.r2_one_step
        );
        // how much the valve model adds: the same linear process with a valve that follows OP
        println!(
            "  R² in simulation with stiction {:.4}, without stiction {}",
            f.r2_simulation,
            f.r2_simulation_without_stiction.map_or(
                "- (the linear fit without stiction is unstable)".into(),
                |r| format!("{r:.4}")
            )
        );
    }
    let cells = q
        .cells
        .map(|c| format!(", {}", count(c, "valve trajectory", "valve trajectories")))
        .unwrap_or_default();
    println!(
        "  {} at {} s, {}{cells}, {:.1} ms",
        count(q.samples, "sample", "samples"),
        seconds(q.ts),
        count(q.evaluations, "evaluation", "evaluations"),
        q.seconds * 1e3
    );
    for w in &q.warnings {
        println!("  warning: {w}");
    }
    if let Some(d) = plot_dir {
        println!("  plots in {}", d.display());
    }
}

fn plots(q: &Quantification, t: &[f64], op: &[f64], pv: &[f64], dir: &Path) -> Result<()> {
    let phase = Chart {
        title: format!(
            "PV against OP, with the fitted {} model (apparent stiction {:.3})",
            q.model,
            q.apparent_stiction.unwrap_or(f64::NAN)
        ),
        x_label: "controller output OP (%)".into(),
        y_label: "process variable PV".into(),
        series: vec![
            Series {
                label: "measured".into(),
                x: op,
                y: pv,
                kind: Kind::Line,
                color: 5,
                thin: true,
            },
            Series {
                label: "fitted model, simulated".into(),
                x: op,
                y: &q.pv_simulated,
                kind: Kind::Line,
                color: 1,
                thin: false,
            },
        ],
        bands: vec![],
        y_range: None,
    };
    plot::save(&phase, &dir.join("phase_plot"))?;
    let valve = Chart {
        title: "Controller output and the estimated valve position".into(),
        x_label: "time (s)".into(),
        y_label: "% of valve span".into(),
        series: vec![
            Series {
                label: "OP".into(),
                x: t,
                y: op,
                kind: Kind::Line,
                color: 0,
                thin: false,
            },
            Series {
                label: "estimated MV".into(),
                x: t,
                y: &q.mv,
                kind: Kind::Step,
                color: 1,
                thin: false,
            },
        ],
        bands: vec![],
        y_range: None,
    };
    let process = Chart {
        title: "Process variable: measured and simulated by the fitted model".into(),
        x_label: "time (s)".into(),
        y_label: "PV".into(),
        series: vec![
            Series {
                label: "PV measured".into(),
                x: t,
                y: pv,
                kind: Kind::Line,
                color: 5,
                thin: false,
            },
            Series {
                label: "PV simulated".into(),
                x: t,
                y: &q.pv_simulated,
                kind: Kind::Line,
                color: 2,
                thin: false,
            },
        ],
        bands: vec![],
        y_range: None,
    };
    plot::save_panels(&[valve, process], &dir.join("trends"))?;
    Ok(())
}
