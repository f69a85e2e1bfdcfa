use crate::atomic::write_atomic;
use crate::plot::{self, Chart, HBand, Kind, Series};
use anyhow::{bail, Result};
use std::path::{Path, PathBuf};
use stiction_core::reproduce::{reproduce_paper, PaperCase, PaperReproduction, PaperSetup};

/// What `reproduce` can reproduce.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum Target {
    /// The ACO stiction paper's open-loop cases (Table 2 and Figs 5-8)
    Paper,
}

#[derive(clap::Args)]
#[command(after_help = "Example:
  stiction reproduce paper --out out/paper")]
pub struct Args {
    /// What to reproduce
    #[arg(value_enum)]
    what: Target,
    /// Folder for the figures (PNG and SVG) and results.json
    #[arg(long, default_value = "out/paper")]
    out: PathBuf,
    /// Print one JSON object instead of text
    #[arg(long)]
    json: bool,
    /// Number of seeds (1..=N)
    #[arg(long, default_value_t = 20)]
    seeds: u64,
}

pub fn run(a: Args) -> Result<()> {
    let Target::Paper = a.what;
    if a.seeds == 0 {
        bail!("--seeds must be at least 1");
    }
    let setup = PaperSetup {
        seeds: (1..=a.seeds).collect(),
        ..PaperSetup::default()
    };
    let rep = reproduce_paper(&setup);
    let json = serde_json::to_string_pretty(&rep)?;
    std::fs::create_dir_all(&a.out)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", a.out.display()))?;
    write_atomic(&a.out.join("results.json"), json.as_bytes())?;
    let files = figures(&rep, &a.out)?;
    if a.json {
        println!("{json}");
    } else {
        print_table(&rep);
        println!("\nFigures and results in {}:", a.out.display());
        for f in files {
            println!("  {}", f.display());
        }
    }
    Ok(())
}

fn print_table(rep: &PaperReproduction) {
    let s = &rep.setup;
    println!(
        "Reproducing Table 2 of the paper: Stenman valve, d estimated from (op, mv) by the paper's ACO"
    );
    println!(
        "  input: unit sine, period 10 s, sampled every {} s for {} samples; no noise",
        s.ts, s.samples
    );
    println!(
        "  ACO: {} ants x {} iterations, rho {}, Q {}, D {}, nodes {}..{} step {}, tau0 {}, local search {} nodes; {} seeds",
        s.aco.ants,
        s.aco.iterations,
        s.aco.rho,
        s.aco.q,
        s.aco.elitist,
        s.bounds.0,
        s.bounds.1,
        s.aco.resolution,
        s.aco.tau0,
        s.aco.local_search,
        s.seeds.len()
    );
    println!();
    println!(
        "  {:<16} {:>6} {:>8} | {:>8} {:>8} {:>21} {:>14} {:>9}",
        "case", "true d", "paper", "ours", "worst", "exact optimal set", "seeds inside", "ms/run"
    );
    for c in &rep.cases {
        let label = if c.true_d < 0.3 {
            "weak stiction"
        } else {
            "strong stiction"
        };
        println!(
            "  {:<16} {:>6} {:>8} | {:>8.4} {:>8.4} {:>21} {:>14} {:>9.3}",
            label,
            c.true_d,
            c.paper_estimate,
            c.mean,
            c.worst,
            format!("[{:.4}, {:.4})", c.interval[0], c.interval[1]),
            format!("{}/{}", c.inside, c.seeds.len()),
            c.seconds_per_run * 1e3
        );
    }
    println!();
    println!(
        "  'ours' is the mean estimate over seeds; 'worst' the estimate farthest from the true d."
    );
    for c in &rep.cases {
        println!(
            "  d = {}: the true d {} in the optimal set; the paper's {} {}.",
            c.true_d,
            if c.true_d_inside { "is" } else { "is NOT" },
            c.paper_estimate,
            if c.paper_estimate_inside {
                "is in it too"
            } else {
                "is not in it for this input (the paper's input signal is not published)"
            }
        );
    }
}

fn figures(rep: &PaperReproduction, out: &Path) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for (c, fig, name) in [(&rep.cases[0], 5, "weak"), (&rep.cases[1], 6, "strong")] {
        files.extend(response_figure(c, fig, name, out)?);
    }
    files.extend(phase_figure(&rep.cases, out)?);
    for (c, fig, name) in [(&rep.cases[0], 7, "weak"), (&rep.cases[1], 8, "strong")] {
        files.extend(trajectory_figure(c, fig, name, out)?);
    }
    Ok(files)
}

fn response_figure(c: &PaperCase, fig: usize, name: &str, out: &Path) -> Result<Vec<PathBuf>> {
    let chart = Chart {
        title: format!(
            "Fig. {fig}: open-loop response, Stenman valve, {name} stiction (d = {})",
            c.true_d
        ),
        x_label: "time (s)".into(),
        y_label: "% of valve span".into(),
        series: vec![
            Series {
                label: "command op".into(),
                x: &c.data.t,
                y: &c.data.op,
                kind: Kind::Line,
                color: 0,
                thin: false,
            },
            Series {
                label: "valve position mv".into(),
                x: &c.data.t,
                y: &c.data.mv,
                kind: Kind::Step,
                color: 1,
                thin: false,
            },
        ],
        bands: vec![],
        y_range: None,
    };
    plot::save(&chart, &out.join(format!("fig{fig}_response_{name}")))
}

fn phase_figure(cases: &[PaperCase], out: &Path) -> Result<Vec<PathBuf>> {
    let series = cases
        .iter()
        .enumerate()
        .map(|(i, c)| Series {
            label: format!("d = {}", c.true_d),
            x: &c.data.op,
            y: &c.data.mv,
            kind: Kind::Line,
            color: i + 1,
            thin: false,
        })
        .collect();
    let chart = Chart {
        title: "Command-position phase plot, Stenman valve".into(),
        x_label: "command op (% of span)".into(),
        y_label: "valve position mv (% of span)".into(),
        series,
        bands: vec![],
        y_range: None,
    };
    plot::save(&chart, &out.join("fig5-6_phase_plot"))
}

fn trajectory_figure(c: &PaperCase, fig: usize, name: &str, out: &Path) -> Result<Vec<PathBuf>> {
    let iters: Vec<Vec<f64>> = c
        .traces
        .iter()
        .map(|t| t.iter().map(|r| r.iteration as f64).collect())
        .collect();
    let best: Vec<Vec<f64>> = c
        .traces
        .iter()
        .map(|t| t.iter().map(|r| r.best[0]).collect())
        .collect();
    let series = iters
        .iter()
        .zip(&best)
        .map(|(x, y)| Series {
            label: format!("best-so-far d, one line per seed ({} seeds)", c.seeds.len()),
            x,
            y,
            kind: Kind::Step,
            color: 0,
            thin: true,
        })
        .collect();
    // zoom on the answer: early excursions of a few seeds (up to 10) would flatten the picture
    let top = 3.0 * c.true_d;
    let chart = Chart {
        title: format!(
            "Fig. {}: trajectories of the estimated d, {name} stiction (d = {})",
            fig, c.true_d
        ),
        // (the y axis stops at 3 x true d)
        x_label: "iteration".into(),
        y_label: "estimated d (% of span)".into(),
        series,
        bands: vec![
            HBand {
                lo: c.interval[0],
                hi: c.interval[1],
                label: format!(
                    "exact optimal set [{:.4}, {:.4})",
                    c.interval[0], c.interval[1]
                ),
                color: 2,
            },
            HBand {
                lo: c.true_d,
                hi: c.true_d,
                label: format!("true d = {}", c.true_d),
                color: 1,
            },
        ],
        y_range: Some((0.0, top)),
    };
    plot::save(&chart, &out.join(format!("fig{fig}_trajectories_{name}")))
}
