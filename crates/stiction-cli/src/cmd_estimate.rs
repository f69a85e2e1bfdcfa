use crate::loop_file::Reading;
use crate::words::count;
use crate::{atomic::write_atomic, data, spec};
use anyhow::{bail, Result};
use std::path::PathBuf;
use stiction_core::estimate::{self, Estimate, IntervalKind, Method, Request};
use stiction_core::models::ModelKind;

#[derive(clap::Args)]
#[command(after_help = "Examples:
  stiction estimate open.csv --model stenman --method exact
  stiction estimate open.csv --op op --mv mv --model stenman --method aco --seed 3 --json
  stiction estimate kano.csv --model kano --method aco-r --seed 1 --trace trace.csv
  stiction estimate valve.xlsx --sheet 'Step test' --op OUT --mv POS

Missing values (blank, NaN, #N/A, historian states such as Bad Input) are gaps: the longest
stretch without one is used, and a note says which.")]
pub struct Args {
    /// Data file: CSV with a header line, .csv.gz, a workbook, Parquet, or - for standard input
    file: PathBuf,
    /// Column of the controller output (the valve's command)
    #[arg(long, default_value = "op")]
    op: String,
    /// Column of the measured valve position
    #[arg(long, default_value = "mv")]
    mv: String,
    /// Column of time [default: the first of t, time, timestamp, datetime, date and other common names, if any]
    #[arg(long)]
    time: Option<String>,
    #[command(flatten)]
    reading: Reading,
    #[command(flatten)]
    fit: spec::FitArgs,
    /// Write the best parameters and fit error per iteration to this CSV (aco, aco-r)
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Lower end of every parameter's search range
    #[arg(long)]
    lo: Option<f64>,
    /// Upper end of every parameter's search range
    #[arg(long)]
    hi: Option<f64>,
    /// One parameter's search range, NAME=LO:HI (repeatable; overrides --lo/--hi)
    #[arg(long = "bounds", value_name = "NAME=LO:HI")]
    bounds: Vec<String>,
    /// aco, aco-r: ants per iteration [default: 20]
    #[arg(long)]
    ants: Option<usize>,
    /// aco, aco-r: iterations [default: 100]
    #[arg(long)]
    iterations: Option<usize>,
    /// aco: evaporation rate rho
    #[arg(long, default_value_t = 0.2)]
    rho: f64,
    /// aco: pheromone quantity Q
    #[arg(long, default_value_t = 100.0)]
    q: f64,
    /// aco: encouragement coefficient D of the best-so-far deposit
    #[arg(long, default_value_t = 100.0)]
    elitist: f64,
    /// aco: spacing of the parameter grid's nodes
    #[arg(long, default_value_t = 0.01)]
    resolution: f64,
    /// aco: initial pheromone per node
    #[arg(long, default_value_t = 1e4)]
    tau0: f64,
    /// aco: guard added to the fit error before dividing Q by it
    #[arg(long, default_value_t = 1e-9)]
    epsilon: f64,
    /// aco: most nodes the iteration's best ant walks in its local search (0: plain Ant System)
    #[arg(long, default_value_t = 10)]
    local_search: usize,
    /// aco-r: archive size k
    #[arg(long, default_value_t = 50)]
    archive: usize,
    /// aco-r: locality q of the rank weights
    #[arg(long, default_value_t = 0.1)]
    locality: f64,
    /// aco-r: spread xi of the sampling kernels
    #[arg(long, default_value_t = 0.85)]
    xi: f64,
    /// grid: points per parameter
    #[arg(long, default_value_t = 1000)]
    points: usize,
}

pub fn run(a: Args) -> Result<()> {
    let (kind, method) = a.fit.resolve()?;
    let mut req = Request::new(kind, method);
    req.seed = a.fit.seed;
    req.trace = a.trace.is_some();
    req.bounds = bounds(kind, &a)?;
    req.aco.ants = a.ants.unwrap_or(req.aco.ants);
    req.aco.iterations = a.iterations.unwrap_or(req.aco.iterations);
    req.aco.rho = a.rho;
    req.aco.q = a.q;
    req.aco.elitist = a.elitist;
    req.aco.resolution = a.resolution;
    req.aco.tau0 = a.tau0;
    req.aco.epsilon = a.epsilon;
    req.aco.local_search = a.local_search;
    req.acor.ants = a.ants.unwrap_or(req.acor.ants);
    req.acor.iterations = a.iterations.unwrap_or(req.acor.iterations);
    req.acor.archive = a.archive;
    req.acor.q = a.locality;
    req.acor.xi = a.xi;
    req.grid.points = a.points;
    if a.trace.is_some() && !matches!(method, Method::Aco | Method::AcoR) {
        bail!("--trace: the {method} method has no iterations to trace; use --method aco or aco-r");
    }
    // the request is checked once, before the file is read, so a typo fails fast
    let req = req.check().map_err(spec::setting_error)?;

    let table = a.reading.open(&a.file)?;
    let mut wanted = vec![a.op.as_str(), a.mv.as_str()];
    wanted.extend(a.time.as_deref());
    let table = table
        .for_columns(&wanted, &[&a.op, &a.mv], a.time.as_deref())
        .unwrap_or(table);
    let spec = a.reading.time_spec()?;
    let pair = data::read_pair(
        &table,
        (&a.op, "--op", "controller output op"),
        (&a.mv, "--mv", "valve position mv"),
        a.time.as_deref().map(|t| (t, &spec)),
        estimate::MIN_SAMPLES,
    )?;
    let name = table.path.display().to_string();
    let est = estimate::estimate_checked(&pair.a, &pair.b, &req)
        .map_err(|e| anyhow::anyhow!("{name}: {}", spec::setting_error(e)))?;
    if let Some(path) = &a.trace {
        write_trace(path, kind, &est)?;
    }
    let said = bad_fit(&est)
        .map(|w| ("warning", w))
        .into_iter()
        .chain(pair.note.map(|n| ("note", n)));
    if a.fit.json {
        println!("{}", serde_json::to_string_pretty(&est)?);
        // beside JSON, on standard error
        for (kind, text) in said {
            eprintln!("{kind}: {name}: {text}");
        }
    } else {
        print_human(&name, &est);
        for (kind, text) in said {
            println!("  {kind}: {text}");
        }
    }
    Ok(())
}

fn bounds(kind: ModelKind, a: &Args) -> Result<Option<Vec<(f64, f64)>>> {
    if a.lo.is_none() && a.hi.is_none() && a.bounds.is_empty() {
        return Ok(None);
    }
    let defaults = kind
        .params()
        .iter()
        .map(|p| (a.lo.unwrap_or(p.search.0), a.hi.unwrap_or(p.search.1)))
        .collect();
    spec::bounds(kind, &a.bounds, defaults).map(Some)
}

fn write_trace(path: &std::path::Path, kind: ModelKind, est: &Estimate) -> Result<()> {
    let names = kind.param_names();
    let mut text = String::from("iteration");
    for n in &names {
        text.push_str(&format!(",best_{n}"));
    }
    text.push_str(",best_sse");
    for n in &names {
        text.push_str(&format!(",iteration_best_{n}"));
    }
    text.push_str(",iteration_best_sse,evaluations\n");
    for r in &est.trace {
        text.push_str(&r.iteration.to_string());
        for v in &r.best {
            text.push_str(&format!(",{v}"));
        }
        text.push_str(&format!(",{}", r.best_sse));
        for v in &r.iteration_best {
            text.push_str(&format!(",{v}"));
        }
        text.push_str(&format!(",{},{}\n", r.iteration_best_sse, r.evaluations));
    }
    write_atomic(path, text.as_bytes())
}

/// A fit worse than MV's mean (R² < 0) means the model explains nothing of MV: the columns
/// are likelier wrong than the valve.
fn bad_fit(e: &Estimate) -> Option<String> {
    (e.r2 < 0.0).then(|| {
        format!(
            "the fit is worse than MV's mean (R² {:.3}): is MV really the valve position, and OP its command? \
             Check --op and --mv, and that the two columns are the same valve's",
            e.r2
        )
    })
}

fn print_human(file: &str, e: &Estimate) {
    let seed = e.seed.map(|s| format!(", seed {s}")).unwrap_or_default();
    println!(
        "{file}: {} model, method {}{seed}, {}",
        e.model,
        e.method,
        count(e.samples, "sample", "samples")
    );
    for spec in e.model.params() {
        let v = e.params[spec.name];
        print!(
            "  {} = {v:.4} {} ({})",
            spec.name, spec.unit, spec.description
        );
        if let Some([lo, hi]) = e.interval.get(spec.name) {
            if e.interval_kind == IntervalKind::Exact {
                print!("; proven optimal set [{lo:.4}, {hi:.4})");
            } else {
                print!("; grid points at the minimum span [{lo:.4}, {hi:.4}]");
            }
        }
        println!();
    }
    if let Some(pieces) = &e.pieces {
        let p: Vec<String> = pieces
            .iter()
            .map(|[a, b]| format!("[{a:.4}, {b:.4})"))
            .collect();
        println!("  the optimal set is not one piece: {}", p.join(" U "));
    }
    if let Some(c) = &e.certificate {
        println!(
            "  check against the exact solver: optimal d in [{:.4}, {:.4}], SSE {:.6}; the estimate {} optimal",
            c.optimal_interval[0],
            c.optimal_interval[1],
            c.optimal_sse,
            if c.estimate_is_optimal { "is" } else { "is NOT" }
        );
    }
    // R² is undefined when MV never moves (a valve stuck the whole record)
    let r2 = if e.r2.is_finite() {
        format!("{:.4}", e.r2)
    } else {
        "- (MV does not vary: the valve never moved)".into()
    };
    println!("  fit: SSE {:.6}, RMSE {:.6}, R² {r2}", e.sse, e.rmse);
    println!(
        "  {}, {}, {:.2} ms",
        count(e.evaluations, "evaluation", "evaluations"),
        if e.method == Method::Exact {
            count(e.iterations, "cell", "cells")
        } else {
            count(e.iterations, "iteration", "iterations")
        },
        e.seconds * 1e3
    );
    for w in &e.warnings {
        println!("  warning: {w}");
    }
}
