//! The time grid of a closed-loop run, the values it keeps per plant step, and a cascade's outer
//! controller.

use super::closed_loop::{Cascade, ClosedLoop, Pi};
use super::process::ProcessState;
use crate::rng::{gaussian, seeded};

/// The time grid of a closed-loop run: controller period, plant step, steps simulated, and the
/// plant step read at each recording time (steps count from the warm-up's start).
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Controller period, seconds.
    pub h: f64,
    /// Plant step, seconds.
    pub dt: f64,
    /// Plant steps per controller execution.
    pub substeps: usize,
    /// Plant steps simulated.
    pub steps: usize,
    /// The plant step the historian reads at each recorded sample.
    pub recorded: Vec<usize>,
}

impl Plan {
    /// The grid `cl` runs on.
    pub fn new(cl: &ClosedLoop) -> Self {
        let h = cl.controller_period.unwrap_or(cl.ts);
        let substeps = cl.substeps.unwrap_or(1).max(1);
        let dt = h / substeps as f64;
        let warm = (cl.warmup / dt).round() as usize;
        // the latest plant step at or before each recording time (1e-9: k ts / dt may land a
        // rounding error below a whole number)
        let recorded: Vec<usize> = (0..cl.samples)
            .map(|k| warm + ((k as f64 * cl.ts) / dt + 1e-9).floor() as usize)
            .collect();
        let steps = recorded.last().map_or(0, |&j| j + 1);
        Self {
            h,
            dt,
            substeps,
            steps,
            recorded,
        }
    }
}

/// Every plant step's values, and what happened at the controller's executions.
pub(super) struct Trace {
    pub sp: Vec<f64>,
    pub op: Vec<f64>,
    pub mv: Vec<f64>,
    pub pv: Vec<f64>,
    /// The stiction model's output at the last execution, and whether it had moved then.
    stem: f64,
    moved: bool,
    pub executions: Vec<usize>,
    pub slips: Vec<usize>,
    pub saturated: Vec<usize>,
    pub outer: Option<OuterTrace>,
}

impl Trace {
    pub fn new(n: usize) -> Self {
        let v = || Vec::with_capacity(n);
        Self {
            sp: v(),
            op: v(),
            mv: v(),
            pv: v(),
            stem: f64::NAN,
            // the first move cannot count as a slip: nothing is known before the start
            moved: true,
            executions: Vec::new(),
            slips: Vec::new(),
            saturated: Vec::new(),
            outer: None,
        }
    }

    pub fn push(&mut self, sp: f64, op: f64, mv: f64, pv: f64) {
        self.sp.push(sp);
        self.op.push(op);
        self.mv.push(mv);
        self.pv.push(pv);
    }

    /// Book-keeping at a controller execution: a slip is a move after an execution without one.
    pub fn executed(&mut self, t: usize, op: f64, stem: f64) {
        self.executions.push(t);
        let moved = t > 0 && stem != self.stem;
        if moved && !self.moved {
            self.slips.push(t);
        }
        if t > 0 {
            self.moved = moved;
        }
        self.stem = stem;
        if op <= 0.0 || op >= 100.0 {
            self.saturated.push(t);
        }
    }
}

#[derive(Default)]
pub(super) struct OuterTrace {
    pub sp: Vec<f64>,
    pub op: Vec<f64>,
    pub pv: Vec<f64>,
}

/// The outer controller of a cascade and its process.
pub(super) struct Outer {
    pi: Pi,
    h: f64,
    sp: Vec<f64>,
    dist: Vec<f64>,
    noise: f64,
    rng: crate::rng::Rng,
    process: ProcessState,
    /// Inner PV deviations seen by the outer process, for its dead time.
    inputs: Vec<f64>,
    nd: usize,
    pv0: f64,
    op_prev: f64,
    e_prev: f64,
    pub trace: OuterTrace,
}

impl Outer {
    pub fn new(c: &Cascade, plan: &Plan, inner_sp0: f64) -> Self {
        let (n, dt) = (plan.steps, plan.dt);
        let sp = c.setpoint.generate(dt, n);
        Self {
            pi: c.pi,
            h: plan.h,
            pv0: sp.first().copied().unwrap_or(0.0),
            sp,
            dist: c
                .disturbance
                .as_ref()
                .map(|d| d.generate(dt, n))
                .unwrap_or_else(|| vec![0.0; n]),
            noise: c.noise,
            // its own stream, so the inner loop's noise is the same with or without a cascade
            rng: seeded(0x0063_6173_6361_6465),
            process: c.process.discretise(dt),
            inputs: Vec::with_capacity(n),
            nd: (c.process.delay() / dt).round() as usize,
            op_prev: inner_sp0,
            e_prev: 0.0,
            trace: OuterTrace::default(),
        }
    }

    /// The outer controller's output at step `t` (the inner loop's setpoint); it moves only when
    /// the controller `executes`.
    pub fn control(&mut self, t: usize, executes: bool) -> f64 {
        let noise = if self.noise > 0.0 {
            self.noise * gaussian(&mut self.rng)
        } else {
            0.0
        };
        let pv = self.pv0 + self.process.output() + self.dist[t] + noise;
        if executes {
            let e = self.sp[t] - pv;
            let Pi { kc, ti } = self.pi;
            if t > 0 {
                self.op_prev = (self.op_prev + kc * (e - self.e_prev) + kc * self.h / ti * e)
                    .clamp(0.0, 100.0);
            }
            self.e_prev = e;
        }
        self.trace.sp.push(self.sp[t]);
        self.trace.op.push(self.op_prev);
        self.trace.pv.push(pv);
        self.op_prev
    }

    /// Step the outer process with the inner PV's deviation now.
    pub fn advance(&mut self, inner_pv: f64) {
        self.inputs.push(inner_pv);
        let t = self.inputs.len() - 1;
        let u = if t >= self.nd {
            self.inputs[t - self.nd]
        } else {
            0.0
        };
        self.process.advance(u);
    }
}
