//! Reproduction of the paper's open-loop cases (Table 2 and Figs 5-8).
//!
//! The paper does not give its input signal, sampling or length. We use a unit sine of period 10 s
//! sampled every 0.1 s for 100 s (1001 samples) driving a Stenman valve with true d = 0.2 and 0.5,
//! and estimate d from (op, mv) with the paper's ACO settings over seeds 1..=20. The exact solver
//! gives the whole optimal set of d for each case, so every seed's answer can be checked.

use crate::estimate::{self, exact, AcoSettings, Method, Request, TraceRow};
use crate::models::{Model, ModelKind, Stenman};
use crate::sim::{simulate_open_loop, LoopData, Signal};
use serde::{Deserialize, Serialize};

/// The paper's Table 2: (true d, the paper's estimate).
const PAPER_TABLE_2: [(f64, f64); 2] = [(0.2, 0.2), (0.5, 0.48)];

/// How the paper's open-loop cases are reproduced: the command, its sampling, the seeds and the ACO
/// settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PaperSetup {
    /// The command driving the valve (a unit sine of period 10 s by default).
    pub signal: Signal,
    /// Sampling time, seconds.
    pub ts: f64,
    /// Samples simulated.
    pub samples: usize,
    /// Seeds of the ACO runs, one run each.
    pub seeds: Vec<u64>,
    /// The ACO settings (the paper's).
    pub aco: AcoSettings,
    /// Search range of d (the paper: from 0.01 up to 10).
    pub bounds: (f64, f64),
}

impl Default for PaperSetup {
    fn default() -> Self {
        Self {
            signal: Signal::Sine {
                amplitude: 1.0,
                period: 10.0,
                offset: 0.0,
            },
            ts: 0.1,
            samples: 1001,
            seeds: (1..=20).collect(),
            aco: AcoSettings::default(),
            bounds: (0.01, 10.0),
        }
    }
}

/// One case of Table 2: a true d, the exact optimal set, and the ACO runs against it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PaperCase {
    /// The band d the valve was simulated with, in op's units.
    pub true_d: f64,
    /// The paper's estimate of d for this case.
    pub paper_estimate: f64,
    /// Hull of the exact optimal set of d.
    pub interval: [f64; 2],
    /// The exact optimal set as half-open pieces [lo, hi).
    pub pieces: Vec<[f64; 2]>,
    /// The least fit error (sum of squares), that of every d in the optimal set.
    pub optimal_sse: f64,
    /// The seeds run.
    pub seeds: Vec<u64>,
    /// The ACO estimate per seed.
    pub estimates: Vec<f64>,
    /// The fit error of each seed's estimate.
    pub sse: Vec<f64>,
    /// Mean of the ACO estimates.
    pub mean: f64,
    /// The estimate farthest from the true d.
    pub worst: f64,
    /// Seeds whose estimate lies in the exact optimal set.
    pub inside: usize,
    /// Whether the true d lies in the exact optimal set.
    pub true_d_inside: bool,
    /// Whether the paper's estimate lies in the exact optimal set.
    pub paper_estimate_inside: bool,
    /// Mean time per ACO run, seconds.
    pub seconds_per_run: f64,
    /// The simulated data (op, mv).
    #[serde(skip)]
    pub data: LoopData,
    /// Convergence trace per seed (for the figures).
    #[serde(skip)]
    pub traces: Vec<Vec<TraceRow>>,
}

/// The reproduction: the setup and one case per row of Table 2.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PaperReproduction {
    /// The setup used.
    pub setup: PaperSetup,
    /// One case per row of Table 2.
    pub cases: Vec<PaperCase>,
}

/// Run every case of Table 2 with `setup`.
pub fn reproduce_paper(setup: &PaperSetup) -> PaperReproduction {
    let cases = PAPER_TABLE_2
        .iter()
        .map(|&(true_d, paper_estimate)| run_case(setup, true_d, paper_estimate))
        .collect();
    PaperReproduction {
        setup: setup.clone(),
        cases,
    }
}

fn run_case(setup: &PaperSetup, true_d: f64, paper_estimate: f64) -> PaperCase {
    let valve = Model::Stenman(Stenman { d: true_d });
    let data = simulate_open_loop(&valve, &setup.signal, setup.ts, setup.samples, 0.0, 0)
        .expect("the paper's setup is valid");
    let (lo, hi) = setup.bounds;
    let sol = exact::solve_stenman(&data.op, &data.mv, lo, hi, &Default::default());
    let mut req = Request::new(ModelKind::Stenman, Method::Aco);
    req.aco = setup.aco.clone();
    req.bounds = Some(vec![setup.bounds]);
    req.trace = true;
    req.certify = false;
    let mut estimates = Vec::new();
    let mut sse = Vec::new();
    let mut traces = Vec::new();
    let mut seconds = 0.0;
    for &seed in &setup.seeds {
        req.seed = seed;
        let est = estimate::estimate(&data.op, &data.mv, &req).expect("the paper's case is valid");
        estimates.push(est.params["d"]);
        sse.push(est.sse);
        seconds += est.seconds;
        traces.push(est.trace);
    }
    let n = estimates.len().max(1) as f64;
    let worst = estimates
        .iter()
        .copied()
        .max_by(|a, b| (a - true_d).abs().total_cmp(&(b - true_d).abs()))
        .unwrap_or(f64::NAN);
    PaperCase {
        true_d,
        paper_estimate,
        interval: [sol.hull().0, sol.hull().1],
        pieces: sol.pieces.iter().map(|&(a, b)| [a, b]).collect(),
        optimal_sse: sol.sse,
        seeds: setup.seeds.clone(),
        mean: estimates.iter().sum::<f64>() / n,
        worst,
        inside: estimates.iter().filter(|&&d| sol.contains(d)).count(),
        true_d_inside: sol.contains(true_d),
        paper_estimate_inside: sol.contains(paper_estimate),
        seconds_per_run: seconds / n,
        estimates,
        sse,
        data,
        traces,
    }
}
