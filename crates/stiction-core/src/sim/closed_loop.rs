//! The closed PI loop with a sticky valve, and the plant features around it: a controller faster
//! than the historian, actuator lag, the installed characteristic, load and output disturbances,
//! quantisation, historian compression, a cascade and a warm-up before the record starts.
//!
//! Every feature is off by default, and then `ClosedLoop::run` gives bit for bit what it always
//! gave: one simulation step per recorded sample, the arithmetic in the same order.

use super::historian::{Historian, Quantisation, QuantiseAt};
use super::process::Process;
use super::stepping::{Outer, Plan, Trace};
use super::valve::{Characteristic, ValveLag};
use super::{require, LoopData, Signal, SimError};
use crate::models::Model;
use crate::rng::{gaussian, seeded};
use serde::{Deserialize, Serialize};

/// PI controller gains: `op[t] = op[t-1] + kc (e[t] - e[t-1]) + kc h / ti e[t]` (velocity form,
/// `h` the controller period), clamped to 0..100 % (which also stops integral wind-up).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pi {
    /// Controller gain Kc, % of OP per PV unit (negative for direct action).
    pub kc: f64,
    /// Integral time Ti, seconds.
    pub ti: f64,
}

impl Pi {
    fn validate(&self, what: &'static str) -> Result<(), SimError> {
        require(self.kc != 0.0, what, "a non-zero gain Kc", self.kc)?;
        require(self.ti > 0.0, "integral time Ti", "> 0 seconds", self.ti)
    }
}

/// An outer loop whose controller output is the inner loop's setpoint (a cascade): e.g. a
/// temperature controller setting the setpoint of a flow controller. The outer process is driven by
/// the inner loop's true PV (in deviation from where it started); its PV, setpoint and output are
/// in % as the inner loop's. It runs at the inner controller's period.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cascade {
    /// The outer process, driven by the inner loop's PV.
    pub process: Process,
    /// The outer controller.
    pub pi: Pi,
    /// The outer setpoint over time.
    pub setpoint: Signal,
    /// Standard deviation of white noise on the outer PV.
    pub noise: f64,
    /// Disturbance added to the outer PV.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub disturbance: Option<Signal>,
}

impl Cascade {
    fn validate(&self) -> Result<(), SimError> {
        self.process.validate()?;
        self.pi.validate("outer controller gain Kc")?;
        self.setpoint.validate()?;
        if let Some(d) = &self.disturbance {
            d.validate()?;
        }
        require(self.noise >= 0.0, "outer noise", ">= 0", self.noise)
    }
}

/// Everything a closed-loop run needs. Defaults follow a common literature setup
/// (Choudhury et al.): K = 3, tau = 10 s, delay = 10 s, Kc = 0.2, Ti = 10 s, Ts = 1 s.
///
/// The fields after `seed` are plant features, all off by default (serialised only when set).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClosedLoop {
    /// The valve's stiction model.
    pub model: Model,
    /// The process from valve position to PV.
    pub process: Process,
    /// The PI controller.
    pub pi: Pi,
    /// Recording interval, seconds (and the controller period unless `controller_period` is set).
    pub ts: f64,
    /// Recorded samples.
    pub samples: usize,
    /// Setpoint over time (% of PV range); generated at the controller period. With a cascade only
    /// its first value is used (the outer loop moves it afterwards).
    pub setpoint: Signal,
    /// Controller output and valve position at the start, % of span (the operating point).
    pub op0: f64,
    /// Standard deviation of white Gaussian noise added to the measured PV.
    pub noise: f64,
    /// Optional output disturbance added to the PV (e.g. an external oscillation).
    pub disturbance: Option<Signal>,
    /// Seed of the PV measurement noise.
    pub seed: u64,
    /// The controller executes (and the plant is stepped) every this many seconds; the historian
    /// samples the latest values every `ts` (as a DCS historian reads the function block). `None`:
    /// every `ts`. Need not divide `ts`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller_period: Option<f64>,
    /// Plant steps per controller period: the process, the actuator and the PV measurement are
    /// simulated this many times between two controller executions, so a historian sampling
    /// faster than the controller records a moving PV and a held OP. `None`: 1 (the PV the
    /// historian reads is the one the controller last read).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub substeps: Option<usize>,
    /// First-order actuator lag after the stiction model, seconds (0: none). The recorded `mv` is
    /// the lagged position.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub valve_lag: f64,
    /// Installed characteristic from valve position to the flow the process sees.
    #[serde(default, skip_serializing_if = "is_linear")]
    pub characteristic: Characteristic,
    /// Input (load) disturbance added to the valve's flow before the process, % of flow.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load: Option<Signal>,
    /// Feed-forward of the measured load: the controller adds `-gain × load` to its output (1
    /// cancels a load that enters with the valve's flow, in steady state). Needs `load`. The
    /// recorded OP is the sum; the PI part is held where it saturates (back-calculation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed_forward: Option<f64>,
    /// Rounding of PV, at the sensor or only in the record.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quantisation: Option<Quantisation>,
    /// Historian compression of the recorded PV and OP.
    #[serde(default, skip_serializing_if = "Historian::is_none")]
    pub historian: Historian,
    /// An outer loop setting this loop's setpoint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cascade: Option<Cascade>,
    /// Seconds simulated before the record starts (signals start at the warm-up's beginning), so
    /// the record opens on a loop in operation rather than at rest.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub warmup: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_linear(c: &Characteristic) -> bool {
    *c == Characteristic::Linear
}

/// A run with what the record alone does not show.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoopRun {
    /// The record as the historian returns it.
    pub data: LoopData,
    /// The outer loop of a cascade, sampled as `data` (its `mv` is empty).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outer: Option<LoopData>,
    /// Times the valve broke away within the record: the stiction model's output moved after
    /// standing still for at least one controller period.
    pub slips: usize,
    /// Controller executions within the record with OP at 0 or 100 %.
    pub saturated: usize,
    /// Controller executions within the record.
    pub steps: usize,
}

impl ClosedLoop {
    /// A loop with `model` as the valve and the literature setup of [`ClosedLoop`] (K = 3, tau =
    /// 10 s, delay = 10 s, Kc = 0.2, Ti = 10 s, Ts = 1 s): 2000 samples, a setpoint step from 50 to
    /// 51 at 10 s, OP starting at 50 %, no noise, seed 0, no plant features.
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
            controller_period: None,
            substeps: None,
            valve_lag: 0.0,
            characteristic: Characteristic::Linear,
            load: None,
            feed_forward: None,
            quantisation: None,
            historian: Historian::default(),
            cascade: None,
            warmup: 0.0,
        }
    }

    /// An error naming the first setting that is out of range.
    pub fn validate(&self) -> Result<(), SimError> {
        self.process.validate()?;
        self.setpoint.validate()?;
        for s in self.disturbance.iter().chain(&self.load) {
            s.validate()?;
        }
        require(
            self.ts > 0.0,
            "the sampling time ts",
            "> 0 seconds",
            self.ts,
        )?;
        self.pi.validate("controller gain Kc")?;
        require(self.noise >= 0.0, "noise", ">= 0", self.noise)?;
        require(
            (0.0..=100.0).contains(&self.op0),
            "op0",
            "in 0..100 % of span",
            self.op0,
        )?;
        if let Some(h) = self.controller_period {
            require(h > 0.0, "controller period", "> 0 seconds", h)?;
        }
        if let Some(m) = self.substeps {
            require(m >= 1, "substeps", ">= 1", m as f64)?;
        }
        require(
            self.valve_lag >= 0.0,
            "valve lag",
            ">= 0 seconds",
            self.valve_lag,
        )?;
        require(self.warmup >= 0.0, "warm-up", ">= 0 seconds", self.warmup)?;
        if let Some(g) = self.feed_forward {
            require(g.is_finite(), "feed-forward gain", "finite", g)?;
            require(
                self.load.is_some(),
                "feed-forward (a load to measure)",
                "given with a load",
                g,
            )?;
        }
        self.characteristic.validate()?;
        if let Some(q) = &self.quantisation {
            q.validate()?;
        }
        self.historian.validate()?;
        if let Some(c) = &self.cascade {
            c.validate()?;
        }
        Ok(())
    }

    /// Run the loop. Each controller period: measure pv, compute the error, the PI move (clamped
    /// to 0..100), the valve position; the process sees the valve position `delay` later. The
    /// process starts at steady state with `pv = sp[0]` and `op = mv = op0`.
    ///
    /// ```
    /// use stiction_core::models::{Kano, Model};
    /// use stiction_core::sim::ClosedLoop;
    ///
    /// let mut sim = ClosedLoop::new(Model::Kano(Kano::new(2.0, 1.0)?));
    /// sim.samples = 600;
    /// sim.seed = 7;
    /// let data = sim.run()?;
    /// assert_eq!(data.pv.len(), 600);
    /// // the valve sticks: it holds its position while OP moves
    /// let held = data.mv.windows(2).filter(|w| w[0] == w[1]).count();
    /// assert!(held > 100);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn run(&self) -> Result<LoopData, SimError> {
        Ok(self.simulate()?.data)
    }

    /// Run the loop and report what happened inside it (slips, saturation, the outer loop).
    pub fn simulate(&self) -> Result<LoopRun, SimError> {
        self.validate()?;
        let plan = Plan::new(self);
        let mut trace = Trace::new(plan.steps);
        self.step_all(&plan, &mut trace);
        Ok(self.record(&plan, &trace))
    }

    /// The inner and the outer loop, step by step, into `trace`.
    fn step_all(&self, plan: &Plan, tr: &mut Trace) {
        let (n, dt, m, h) = (plan.steps, plan.dt, plan.substeps, plan.h);
        let mut sp = self.setpoint.generate(dt, n);
        let dist = self
            .disturbance
            .as_ref()
            .map(|d| d.generate(dt, n))
            .unwrap_or_else(|| vec![0.0; n]);
        let load = self.load.as_ref().map(|d| d.generate(dt, n));
        let nd = (self.process.delay() / dt).round() as usize;
        let mut rng = seeded(self.seed);
        let pv0 = sp.first().copied().unwrap_or(0.0);
        let (mut valve, x0) = self.model.start(self.op0);
        let mut lag = ValveLag::new(self.valve_lag, dt, x0);
        let flow0 = self.characteristic.flow(x0);
        let mut outer = self.cascade.as_ref().map(|c| Outer::new(c, plan, pv0));
        let mut process = self.process.discretise(dt);
        let (mut op, mut stem) = (self.op0, x0);
        let mut op_prev = self.op0;
        let mut e_prev = 0.0;
        let Pi { kc, ti } = self.pi;
        let sensor = self.quantisation.filter(|q| q.at == QuantiseAt::Sensor);
        for t in 0..n {
            let control = t % m == 0;
            if let Some(o) = outer.as_mut() {
                sp[t] = o.control(t, control);
            }
            let noise = if self.noise > 0.0 {
                self.noise * gaussian(&mut rng)
            } else {
                0.0
            };
            let mut pv = pv0 + process.output() + dist[t] + noise;
            if let Some(q) = sensor {
                pv = q.apply(pv);
            }
            if control {
                let e = sp[t] - pv;
                if t > 0 {
                    let pi = op_prev + kc * (e - e_prev) + kc * h / ti * e;
                    op = match (self.feed_forward, &load) {
                        (Some(g), Some(l)) => {
                            let ff = -g * l[t];
                            let total = (pi + ff).clamp(0.0, 100.0);
                            // the PI part, held where the sum saturates
                            op_prev = total - ff;
                            total
                        }
                        _ => pi.clamp(0.0, 100.0),
                    };
                    stem = self.model.step(&mut valve, op);
                }
                if self.feed_forward.is_none() {
                    op_prev = op;
                }
                e_prev = e;
                tr.executed(t, op, stem);
            }
            let mv = if t == 0 { x0 } else { lag.step(stem) };
            tr.push(sp[t], op, mv, pv);
            if let Some(o) = outer.as_mut() {
                o.advance(process.output() + dist[t]);
            }
            // the process input is the valve's flow nd steps ago (the operating point before t = 0)
            let position = if t >= nd { tr.mv[t - nd] } else { x0 };
            let mut u_in = self.characteristic.flow(position) - flow0;
            if let Some(l) = &load {
                u_in += l[t];
            }
            process.advance(u_in);
        }
        tr.outer = outer.map(|o| o.trace);
    }

    /// Sample the trace at the recording times and pass it through the historian.
    fn record(&self, plan: &Plan, tr: &Trace) -> LoopRun {
        let idx = &plan.recorded;
        let per = ((self.ts / plan.dt).round() as usize).max(1);
        let average = self.historian.average;
        // the setpoint is a setting, kept as the latest value
        let latest = |v: &[f64]| idx.iter().map(|&j| v[j]).collect::<Vec<f64>>();
        let pick = |v: &[f64]| -> Vec<f64> {
            if !average {
                return latest(v);
            }
            idx.iter()
                .enumerate()
                .map(|(k, &j)| {
                    // the plant steps since the previous recording (the first: one interval)
                    let from = if k == 0 {
                        j + 1 - per.min(j + 1)
                    } else {
                        idx[k - 1] + 1
                    };
                    v[from..=j].iter().sum::<f64>() / (j + 1 - from) as f64
                })
                .collect()
        };
        let t: Vec<f64> = (0..idx.len()).map(|k| k as f64 * self.ts).collect();
        let mut data = LoopData {
            t: t.clone(),
            sp: latest(&tr.sp),
            op: pick(&tr.op),
            mv: pick(&tr.mv),
            pv: pick(&tr.pv),
        };
        if let Some(q) = self.quantisation.filter(|q| q.at == QuantiseAt::Historian) {
            data.pv.iter_mut().for_each(|v| *v = q.apply(*v));
        }
        if let Some(c) = &self.historian.pv {
            data.pv = c.apply(&t, &data.pv);
        }
        if let Some(c) = &self.historian.op {
            data.op = c.apply(&t, &data.op);
        }
        let outer = tr.outer.as_ref().map(|o| LoopData {
            t: t.clone(),
            sp: latest(&o.sp),
            op: pick(&o.op),
            mv: Vec::new(),
            pv: pick(&o.pv),
        });
        let span = idx
            .first()
            .map_or(0..0, |&a| a..idx.last().map_or(a, |&b| b + 1));
        let within = |steps: &[usize]| steps.iter().filter(|j| span.contains(j)).count();
        LoopRun {
            data,
            outer,
            slips: within(&tr.slips),
            saturated: within(&tr.saturated),
            steps: within(&tr.executions),
        }
    }
}
