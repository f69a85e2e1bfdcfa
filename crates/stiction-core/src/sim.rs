//! Signals and loop simulation: open-loop command signals through a valve, and a closed PI loop
//! with a sticky valve, a first-order-plus-dead-time or integrating process and measurement noise.

use crate::models::Model;
use crate::rng::{gaussian, seeded};
use rand::RngExt;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    #[error("{what} must be {rule}, got {value}")]
    Invalid {
        what: &'static str,
        rule: &'static str,
        value: f64,
    },
}

fn require(ok: bool, what: &'static str, rule: &'static str, value: f64) -> Result<(), SimError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(SimError::Invalid { what, rule, value })
    }
}

/// A command (or setpoint, or disturbance) signal over time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Signal {
    /// `offset + amplitude * sin(2 pi t / period)`.
    Sine {
        amplitude: f64,
        period: f64,
        offset: f64,
    },
    /// A symmetric triangle wave between `offset - amplitude` and `offset + amplitude`, starting at
    /// `offset` and rising.
    Triangle {
        amplitude: f64,
        period: f64,
        offset: f64,
    },
    /// `offset` plus a Gaussian random walk with step standard deviation `step_std`.
    RandomWalk {
        step_std: f64,
        offset: f64,
        seed: u64,
    },
    /// Random levels, uniform in `offset ± amplitude`, each held for `hold` seconds.
    Steps {
        amplitude: f64,
        hold: f64,
        offset: f64,
        seed: u64,
    },
    /// `from` until time `at`, then `to`.
    Step { from: f64, to: f64, at: f64 },
    /// A constant.
    Constant { value: f64 },
}

impl Signal {
    pub fn validate(&self) -> Result<(), SimError> {
        match *self {
            Signal::Sine {
                amplitude,
                period,
                offset,
            }
            | Signal::Triangle {
                amplitude,
                period,
                offset,
            } => {
                require(amplitude >= 0.0, "amplitude", ">= 0", amplitude)?;
                require(period > 0.0, "period", "> 0 seconds", period)?;
                require(true, "offset", "finite", offset)
            }
            Signal::RandomWalk {
                step_std, offset, ..
            } => {
                require(step_std >= 0.0, "step_std", ">= 0", step_std)?;
                require(true, "offset", "finite", offset)
            }
            Signal::Steps {
                amplitude,
                hold,
                offset,
                ..
            } => {
                require(amplitude >= 0.0, "amplitude", ">= 0", amplitude)?;
                require(hold > 0.0, "hold", "> 0 seconds", hold)?;
                require(true, "offset", "finite", offset)
            }
            Signal::Step { from, to, at } => {
                require(true, "from", "finite", from)?;
                require(true, "to", "finite", to)?;
                require(true, "at", "finite", at)
            }
            Signal::Constant { value } => require(true, "value", "finite", value),
        }
    }

    /// Sample the signal at `t[k] = k * ts`, `k = 0..samples`.
    pub fn generate(&self, ts: f64, samples: usize) -> Vec<f64> {
        let time = |k: usize| k as f64 * ts;
        match *self {
            Signal::Sine {
                amplitude,
                period,
                offset,
            } => (0..samples)
                .map(|k| offset + amplitude * (std::f64::consts::TAU * time(k) / period).sin())
                .collect(),
            Signal::Triangle {
                amplitude,
                period,
                offset,
            } => (0..samples)
                .map(|k| {
                    // phase in [0, 1): rise 0..0.25 to +A, fall to -A at 0.75, rise back to 0
                    let p = (time(k) / period).rem_euclid(1.0);
                    let tri = if p < 0.25 {
                        4.0 * p
                    } else if p < 0.75 {
                        2.0 - 4.0 * p
                    } else {
                        4.0 * p - 4.0
                    };
                    offset + amplitude * tri
                })
                .collect(),
            Signal::RandomWalk {
                step_std,
                offset,
                seed,
            } => {
                let mut rng = seeded(seed);
                let mut level = offset;
                (0..samples)
                    .map(|k| {
                        if k > 0 {
                            level += step_std * gaussian(&mut rng);
                        }
                        level
                    })
                    .collect()
            }
            Signal::Steps {
                amplitude,
                hold,
                offset,
                seed,
            } => {
                let mut rng = seeded(seed);
                let mut level = offset;
                let mut next_change = 0.0;
                (0..samples)
                    .map(|k| {
                        if time(k) >= next_change - 1e-12 {
                            level = offset + amplitude * (2.0 * rng.random::<f64>() - 1.0);
                            next_change += hold;
                        }
                        level
                    })
                    .collect()
            }
            Signal::Step { from, to, at } => (0..samples)
                .map(|k| if time(k) < at { from } else { to })
                .collect(),
            Signal::Constant { value } => vec![value; samples],
        }
    }
}

/// A simulated loop, one value per sample: time, setpoint, controller output, valve position,
/// process variable. Open-loop runs have no setpoint and no process: `sp` and `pv` are empty.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LoopData {
    pub t: Vec<f64>,
    pub sp: Vec<f64>,
    pub op: Vec<f64>,
    pub mv: Vec<f64>,
    pub pv: Vec<f64>,
}

/// Drive a valve open loop with a command signal. `mv` is the valve position as measured: the
/// model's output plus Gaussian noise of standard deviation `noise` (seeded). An open loop has no
/// setpoint and no process: `sp` and `pv` are empty.
pub fn simulate_open_loop(
    model: &Model,
    command: &Signal,
    ts: f64,
    samples: usize,
    noise: f64,
    seed: u64,
) -> Result<LoopData, SimError> {
    command.validate()?;
    require(ts > 0.0, "the sampling time ts", "> 0 seconds", ts)?;
    require(noise >= 0.0, "noise", ">= 0", noise)?;
    let op = command.generate(ts, samples);
    let mut mv = model.simulate(&op);
    if noise > 0.0 {
        let mut rng = seeded(seed);
        for x in &mut mv {
            *x += noise * gaussian(&mut rng);
        }
    }
    Ok(LoopData {
        t: (0..samples).map(|k| k as f64 * ts).collect(),
        sp: Vec::new(),
        op,
        mv,
        pv: Vec::new(),
    })
}

/// The process the valve drives, in deviation from the operating point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Process {
    /// `K e^{-delay s} / (tau s + 1)`, discretised exactly with a zero-order hold.
    Foptd { k: f64, tau: f64, delay: f64 },
    /// `K e^{-delay s} / s` (a level loop), discretised with a zero-order hold.
    Integrating { k: f64, delay: f64 },
}

impl Process {
    pub fn validate(&self) -> Result<(), SimError> {
        match *self {
            Process::Foptd { k, tau, delay } => {
                require(k != 0.0, "process gain K", "non-zero", k)?;
                require(tau > 0.0, "time constant tau", "> 0 seconds", tau)?;
                require(delay >= 0.0, "dead time delay", ">= 0 seconds", delay)
            }
            Process::Integrating { k, delay } => {
                require(k != 0.0, "process gain K", "non-zero", k)?;
                require(delay >= 0.0, "dead time delay", ">= 0 seconds", delay)
            }
        }
    }

    fn delay(&self) -> f64 {
        match *self {
            Process::Foptd { delay, .. } | Process::Integrating { delay, .. } => delay,
        }
    }
}

/// PI controller gains: `op[t] = op[t-1] + kc (e[t] - e[t-1]) + kc ts / ti e[t]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pi {
    pub kc: f64,
    pub ti: f64,
}

/// Everything a closed-loop run needs. Defaults follow a common literature setup
/// (Choudhury et al.): K = 3, tau = 10 s, delay = 10 s, Kc = 0.2, Ti = 10 s, Ts = 1 s.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClosedLoop {
    pub model: Model,
    pub process: Process,
    pub pi: Pi,
    pub ts: f64,
    pub samples: usize,
    /// Setpoint over time (% of PV range).
    pub setpoint: Signal,
    /// Controller output and valve position at the start, % of span (the operating point).
    pub op0: f64,
    /// Standard deviation of white Gaussian noise added to the measured PV.
    pub noise: f64,
    /// Optional disturbance added to the PV (e.g. an external oscillation).
    pub disturbance: Option<Signal>,
    pub seed: u64,
}

impl ClosedLoop {
    pub fn new(model: Model) -> Self {
        Self {
            model,
            process: Process::Foptd {
                k: 3.0,
                tau: 10.0,
                delay: 10.0,
            },
            pi: Pi { kc: 0.2, ti: 10.0 },
            ts: 1.0,
            samples: 2000,
            setpoint: Signal::Step {
                from: 50.0,
                to: 51.0,
                at: 10.0,
            },
            op0: 50.0,
            noise: 0.0,
            disturbance: None,
            seed: 0,
        }
    }

    pub fn validate(&self) -> Result<(), SimError> {
        self.process.validate()?;
        self.setpoint.validate()?;
        if let Some(d) = &self.disturbance {
            d.validate()?;
        }
        require(
            self.ts > 0.0,
            "the sampling time ts",
            "> 0 seconds",
            self.ts,
        )?;
        require(
            self.pi.kc != 0.0,
            "controller gain Kc",
            "non-zero",
            self.pi.kc,
        )?;
        require(
            self.pi.ti > 0.0,
            "integral time Ti",
            "> 0 seconds",
            self.pi.ti,
        )?;
        require(self.noise >= 0.0, "noise", ">= 0", self.noise)?;
        require(
            (0.0..=100.0).contains(&self.op0),
            "op0",
            "in 0..100 % of span",
            self.op0,
        )
    }

    /// Run the loop. Each sample: measure pv, compute the error, the PI move (clamped to 0..100),
    /// the valve position; the process sees the valve position `delay` later. The process starts at
    /// steady state with pv = sp[0] and op = mv = op0.
    pub fn run(&self) -> Result<LoopData, SimError> {
        self.validate()?;
        let n = self.samples;
        let ts = self.ts;
        let sp = self.setpoint.generate(ts, n);
        let dist = self
            .disturbance
            .as_ref()
            .map(|d| d.generate(ts, n))
            .unwrap_or_else(|| vec![0.0; n]);
        let nd = (self.process.delay() / ts).round() as usize;
        let mut rng = seeded(self.seed);
        let pv0 = sp.first().copied().unwrap_or(0.0);
        let (mut valve, x0) = self.model.start(self.op0);

        let mut data = LoopData {
            t: (0..n).map(|k| k as f64 * ts).collect(),
            sp: sp.clone(),
            op: Vec::with_capacity(n),
            mv: Vec::with_capacity(n),
            pv: Vec::with_capacity(n),
        };
        // process state in deviation from the operating point
        let mut y = 0.0;
        let mut op_prev = self.op0;
        let mut e_prev = 0.0;
        let Pi { kc, ti } = self.pi;
        for t in 0..n {
            let noise = if self.noise > 0.0 {
                self.noise * gaussian(&mut rng)
            } else {
                0.0
            };
            let pv = pv0 + y + dist[t] + noise;
            let e = sp[t] - pv;
            let (op, mv) = if t == 0 {
                (self.op0, x0)
            } else {
                let op = (op_prev + kc * (e - e_prev) + kc * ts / ti * e).clamp(0.0, 100.0);
                (op, self.model.step(&mut valve, op))
            };
            data.pv.push(pv);
            data.op.push(op);
            data.mv.push(mv);
            op_prev = op;
            e_prev = e;
            // the process input is the valve position nd samples ago (the operating point before t = 0)
            let u_in = if t >= nd { data.mv[t - nd] } else { x0 } - x0;
            y = match self.process {
                Process::Foptd { k, tau, .. } => {
                    let a = (-ts / tau).exp();
                    a * y + k * (1.0 - a) * u_in
                }
                Process::Integrating { k, .. } => y + k * ts * u_in,
            };
        }
        Ok(data)
    }
}
