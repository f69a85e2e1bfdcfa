//! Data-driven stiction models: Stenman, He et al. (2007), Kano et al. (2004), Choudhury et al. (2005).
//!
//! Notation: `op` (u) is the controller output, the valve's command; `mv` (x) is the valve stem
//! position. Both are normally in % of valve span. Every model starts at rest with `x[0] = u[0]`
//! (Kano and Choudhury clamp the command to 0..100 first, so `x[0]` is the clamped command).
//!
//! Each model is a small `Copy` struct of validated parameters implementing [`StictionModel`]:
//! `start` gives the state after the first sample, `step` advances one sample. Simulation into a
//! caller's buffer and the fit error (SSE) are provided on top and never allocate.

use serde::{Deserialize, Serialize};
use std::fmt;

/// Errors raised when a model or its parameters are not valid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A model name that is not one of stenman, he, kano, choudhury.
    #[error("unknown model '{0}'; the models are stenman, he, kano, choudhury")]
    UnknownModel(String),
    /// A parameter name the model does not have.
    #[error("model {model} has no parameter '{name}'; its parameters are {known}")]
    UnknownParameter {
        /// The model's name.
        model: &'static str,
        /// The name given.
        name: String,
        /// The model's parameter names, comma-separated.
        known: String,
    },
    /// A parameter the model needs was not given.
    #[error("model {model} needs a value for parameter '{name}' ({description})")]
    MissingParameter {
        /// The model's name.
        model: &'static str,
        /// The parameter's name.
        name: &'static str,
        /// What the parameter is.
        description: &'static str,
    },
    /// A parameter value out of range.
    #[error("parameter {name} = {value} of model {model} is invalid: {why}")]
    InvalidParameter {
        /// The model's name.
        model: &'static str,
        /// The parameter's name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Why it is invalid.
        why: String,
    },
}

/// One named, bounded parameter of a model.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ParamSpec {
    /// The parameter's name as written on a command line (`d`, `fs`, `S`, ...).
    pub name: &'static str,
    /// Its unit (`% of span`).
    pub unit: &'static str,
    /// What it is, in words.
    pub description: &'static str,
    /// Smallest valid value.
    pub min: f64,
    /// Default search range for estimators (the paper searches d in [0.01, 10]).
    pub search: (f64, f64),
}

/// The behaviour every stiction model shares.
pub trait StictionModel: Copy + Send + Sync {
    /// Whatever the recursion carries from one sample to the next.
    type State: Copy;

    /// State after the first sample and the first valve position `x[0]`.
    fn start(&self, u0: f64) -> (Self::State, f64);

    /// Advance one sample with command `u`; returns the valve position.
    fn step(&self, state: &mut Self::State, u: f64) -> f64;

    /// Simulate the valve position for a whole command sequence into `mv` (same length as `op`).
    fn simulate_into(&self, op: &[f64], mv: &mut [f64]) {
        assert_eq!(
            op.len(),
            mv.len(),
            "op and mv buffers must have the same length"
        );
        if op.is_empty() {
            return;
        }
        let (mut state, x0) = self.start(op[0]);
        mv[0] = x0;
        for (x, &u) in mv[1..].iter_mut().zip(&op[1..]) {
            *x = self.step(&mut state, u);
        }
    }

    /// Sum of squared errors between a measured valve position and this model's output.
    fn sse(&self, op: &[f64], mv_measured: &[f64]) -> f64 {
        if op.is_empty() {
            return 0.0;
        }
        let (mut state, x0) = self.start(op[0]);
        let e0 = mv_measured[0] - x0;
        let mut sum = e0 * e0;
        for (&u, &y) in op[1..].iter().zip(&mv_measured[1..]) {
            let e = y - self.step(&mut state, u);
            sum += e * e;
        }
        sum
    }
}

// ---------------------------------------------------------------------------------------------
// Stenman

/// Stenman's one-parameter model: the valve sticks while `|u[t] - x[t-1]| <= d`, else it slips to
/// the command. `d` is the stiction band.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stenman {
    /// The stiction band, in op's units (normally % of valve span).
    pub d: f64,
}

impl Stenman {
    /// Stenman's model with band `d`; an error unless `d` is a finite number >= 0.
    pub fn new(d: f64) -> Result<Self, ModelError> {
        check_nonneg("stenman", "d", d)?;
        Ok(Self { d })
    }
}

impl StictionModel for Stenman {
    type State = f64;

    #[inline(always)]
    fn start(&self, u0: f64) -> (f64, f64) {
        (u0, u0)
    }

    #[inline(always)]
    fn step(&self, x: &mut f64, u: f64) -> f64 {
        if (u - *x).abs() > self.d {
            *x = u;
        }
        *x
    }
}

// ---------------------------------------------------------------------------------------------
// He et al. 2007

/// He et al.'s two-parameter model with static band `fs` and kinetic band `fd` (fs >= fd >= 0).
///
/// The published recursion carries a residual force `r = u - x`; we carry `x` instead, which is the
/// same model (`p = r[t-1] + u[t] - u[t-1] = u[t] - x[t-1]`) and makes `He(d, 0)` equal Stenman(d)
/// bit for bit, not just up to rounding.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct He {
    /// The static friction band, in op's units (normally % of valve span).
    pub fs: f64,
    /// The kinetic friction band, at most `fs`.
    pub fd: f64,
}

impl He {
    /// He's model; an error unless both bands are finite numbers >= 0 and `fd <= fs`.
    pub fn new(fs: f64, fd: f64) -> Result<Self, ModelError> {
        check_nonneg("he", "fs", fs)?;
        check_nonneg("he", "fd", fd)?;
        if fd > fs {
            return Err(ModelError::InvalidParameter {
                model: "he",
                name: "fd",
                value: fd,
                why: format!("the kinetic band fd must not exceed the static band fs = {fs}"),
            });
        }
        Ok(Self { fs, fd })
    }
}

impl StictionModel for He {
    type State = f64;

    #[inline(always)]
    fn start(&self, u0: f64) -> (f64, f64) {
        (u0, u0)
    }

    #[inline(always)]
    fn step(&self, x: &mut f64, u: f64) -> f64 {
        let p = u - *x;
        if p.abs() > self.fs {
            *x = u - self.fd.copysign(p);
        }
        *x
    }
}

// ---------------------------------------------------------------------------------------------
// Kano et al. 2004

/// Kano et al.'s model: `s` = deadband + stickband, `j` = slip jump, both in % of span.
/// The command is clamped to 0..100 first.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Kano {
    /// Deadband plus stickband S, % of valve span.
    pub s: f64,
    /// Slip jump J, % of valve span.
    pub j: f64,
}

impl Kano {
    /// Kano's model; an error unless S and J are finite numbers >= 0.
    pub fn new(s: f64, j: f64) -> Result<Self, ModelError> {
        check_nonneg("kano", "S", s)?;
        check_nonneg("kano", "J", j)?;
        Ok(Self { s, j })
    }
}

/// The state Kano's recursion carries from one sample to the next.
#[derive(Debug, Clone, Copy)]
pub struct KanoState {
    du_old: f64,
    stopped: bool,
    /// Command at which the valve last came to rest.
    us: f64,
    /// Direction of the last movement (+1 up, -1 down).
    dir: f64,
    u_prev: f64,
    x_prev: f64,
}

impl StictionModel for Kano {
    type State = KanoState;

    fn start(&self, u0: f64) -> (KanoState, f64) {
        let u = u0.clamp(0.0, 100.0);
        let st = KanoState {
            du_old: 0.0,
            stopped: false,
            us: u + (self.s - self.j) / 2.0,
            dir: -1.0,
            u_prev: u,
            x_prev: u,
        };
        (st, u)
    }

    #[inline]
    fn step(&self, st: &mut KanoState, u: f64) -> f64 {
        let u = u.clamp(0.0, 100.0);
        let half_gap = (self.s - self.j) / 2.0;
        let du = u - st.u_prev;
        if du * st.du_old <= 0.0 && !st.stopped {
            // the command stopped or reversed: the valve comes to rest here
            st.us = st.u_prev;
            st.stopped = true;
        }
        let x = if !st.stopped {
            u - st.dir * half_gap
        } else if -st.dir * (u - st.us) > self.s {
            // the command reversed and broke through the band
            st.dir = -st.dir;
            st.stopped = false;
            u - st.dir * half_gap
        } else if st.dir * (u - st.us) > self.j {
            // the command went on in the same direction past the slip jump
            st.stopped = false;
            u - st.dir * half_gap
        } else {
            st.x_prev
        };
        st.du_old = du;
        st.u_prev = u;
        st.x_prev = x;
        x
    }
}

// ---------------------------------------------------------------------------------------------
// Choudhury et al. 2005

/// Choudhury et al.'s model: `s` (deadband + stickband) and `j` (slip jump) in % of span.
///
/// The command is scaled to % of span with `span = (lo, hi)` (default 0..100: already in %) and
/// saturated to 0..100; the output is in the same %. A velocity change smaller than
/// `velocity_deadzone` counts as zero, which keeps noise in OP from looking like stops and
/// reversals (0 = the published model).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Choudhury {
    /// Deadband plus stickband S, % of valve span.
    pub s: f64,
    /// Slip jump J, % of valve span.
    pub j: f64,
    /// A change of the scaled command per sample at most this large (% of span) counts as no
    /// motion.
    pub velocity_deadzone: f64,
    /// The command values of 0 % and 100 % of span.
    pub span: (f64, f64),
}

impl Choudhury {
    /// Choudhury's model with the published behaviour (no velocity deadzone, command already in %
    /// of span); an error unless S and J are finite numbers >= 0.
    pub fn new(s: f64, j: f64) -> Result<Self, ModelError> {
        check_nonneg("choudhury", "S", s)?;
        check_nonneg("choudhury", "J", j)?;
        Ok(Self {
            s,
            j,
            velocity_deadzone: 0.0,
            span: (0.0, 100.0),
        })
    }

    #[inline]
    fn scale(&self, u: f64) -> f64 {
        let (lo, hi) = self.span;
        (100.0 * (u - lo) / (hi - lo)).clamp(0.0, 100.0)
    }

    #[inline]
    fn sign(&self, v: f64) -> f64 {
        if v.abs() <= self.velocity_deadzone {
            0.0
        } else {
            v.signum()
        }
    }
}

/// The state Choudhury's recursion carries from one sample to the next.
#[derive(Debug, Clone, Copy)]
pub struct ChoudhuryState {
    v_old: f64,
    /// Command at which the valve stuck.
    xss: f64,
    /// 1 when the valve stopped while moving (the slip jump J applies), else 0.
    stopped_moving: bool,
    xc_prev: f64,
    x_prev: f64,
}

impl StictionModel for Choudhury {
    type State = ChoudhuryState;

    fn start(&self, u0: f64) -> (ChoudhuryState, f64) {
        let xc = self.scale(u0);
        let st = ChoudhuryState {
            v_old: 0.0,
            xss: xc,
            stopped_moving: false,
            xc_prev: xc,
            x_prev: xc,
        };
        (st, xc)
    }

    #[inline]
    fn step(&self, st: &mut ChoudhuryState, u: f64) -> f64 {
        let xc = self.scale(u);
        let v = xc - st.xc_prev;
        let sv = self.sign(v);
        let half_gap = (self.s - self.j) / 2.0;
        let x = if sv == self.sign(st.v_old) {
            if !st.stopped_moving {
                if (xc - st.xss).abs() > self.s {
                    xc - sv * half_gap
                } else {
                    st.x_prev
                }
            } else if (xc - st.xss).abs() > self.j {
                st.stopped_moving = false;
                xc - sv * half_gap
            } else {
                st.x_prev
            }
        } else {
            // reversal, start or stop
            st.xss = st.xc_prev;
            if sv == 0.0 {
                st.stopped_moving = true;
            }
            st.x_prev
        };
        st.v_old = v;
        st.xc_prev = xc;
        st.x_prev = x;
        x
    }
}

fn check_nonneg(model: &'static str, name: &'static str, value: f64) -> Result<(), ModelError> {
    if !value.is_finite() || value < 0.0 {
        return Err(ModelError::InvalidParameter {
            model,
            name,
            value,
            why: "it must be a finite number >= 0 (in % of valve span)".into(),
        });
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Run-time choice of model

/// Which model, chosen at run time (from a command line or a config).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ModelKind {
    /// Stenman's one-parameter model (band d).
    Stenman,
    /// He et al.'s model (static band fs, kinetic band fd).
    He,
    /// Kano et al.'s model (S, J).
    Kano,
    /// Choudhury et al.'s model (S, J).
    Choudhury,
}

const STENMAN_PARAMS: [ParamSpec; 1] = [ParamSpec {
    name: "d",
    unit: "% of span",
    description: "stiction band",
    min: 0.0,
    search: (0.01, 10.0),
}];
const HE_PARAMS: [ParamSpec; 2] = [
    ParamSpec {
        name: "fs",
        unit: "% of span",
        description: "static friction band",
        min: 0.0,
        search: (0.0, 10.0),
    },
    ParamSpec {
        name: "fd",
        unit: "% of span",
        description: "kinetic friction band, at most fs",
        min: 0.0,
        search: (0.0, 10.0),
    },
];
const KANO_PARAMS: [ParamSpec; 2] = [
    ParamSpec {
        name: "S",
        unit: "% of span",
        description: "deadband plus stickband",
        min: 0.0,
        search: (0.0, 10.0),
    },
    ParamSpec {
        name: "J",
        unit: "% of span",
        description: "slip jump",
        min: 0.0,
        search: (0.0, 10.0),
    },
];

impl ModelKind {
    /// Every model.
    pub const ALL: [ModelKind; 4] = [Self::Stenman, Self::He, Self::Kano, Self::Choudhury];

    /// The model's name, as the CLI and serde write it (`stenman`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Stenman => "stenman",
            Self::He => "he",
            Self::Kano => "kano",
            Self::Choudhury => "choudhury",
        }
    }

    /// The model's parameters, in order.
    pub fn params(self) -> &'static [ParamSpec] {
        match self {
            Self::Stenman => &STENMAN_PARAMS,
            Self::He => &HE_PARAMS,
            Self::Kano | Self::Choudhury => &KANO_PARAMS,
        }
    }

    /// Number of parameters.
    pub fn dim(self) -> usize {
        self.params().len()
    }

    /// Index of a parameter by name (case-insensitive), or a clear error.
    pub fn param_index(self, name: &str) -> Result<usize, ModelError> {
        self.params()
            .iter()
            .position(|p| p.name.eq_ignore_ascii_case(name))
            .ok_or_else(|| ModelError::UnknownParameter {
                model: self.name(),
                name: name.to_string(),
                known: self.param_names().join(", "),
            })
    }

    /// The parameters' names, in order.
    pub fn param_names(self) -> Vec<&'static str> {
        self.params().iter().map(|p| p.name).collect()
    }

    /// Build a validated model from parameter values in the order of [`ModelKind::params`].
    pub fn build(self, values: &[f64]) -> Result<Model, ModelError> {
        assert_eq!(values.len(), self.dim());
        Ok(match self {
            Self::Stenman => Model::Stenman(Stenman::new(values[0])?),
            Self::He => Model::He(He::new(values[0], values[1])?),
            Self::Kano => Model::Kano(Kano::new(values[0], values[1])?),
            Self::Choudhury => Model::Choudhury(Choudhury::new(values[0], values[1])?),
        })
    }

    /// Make a candidate from a search valid in place (He: fd <= fs). Estimators call this on every
    /// candidate they draw so the search space is the feasible set.
    pub fn repair(self, values: &mut [f64]) {
        for (v, p) in values.iter_mut().zip(self.params()) {
            if *v < p.min {
                *v = p.min;
            }
        }
        if self == Self::He && values[1] > values[0] {
            values[1] = values[0];
        }
    }
}

impl fmt::Display for ModelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ModelKind {
    type Err = ModelError;
    fn from_str(s: &str) -> Result<Self, ModelError> {
        Self::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| ModelError::UnknownModel(s.to_string()))
    }
}

/// A model with its parameters, chosen at run time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "lowercase")]
pub enum Model {
    /// Stenman's model.
    Stenman(Stenman),
    /// He et al.'s model.
    He(He),
    /// Kano et al.'s model.
    Kano(Kano),
    /// Choudhury et al.'s model.
    Choudhury(Choudhury),
}

/// Run-time state of any model, for stepping a [`Model`] in a control loop.
#[derive(Debug, Clone, Copy)]
pub enum ModelState {
    /// Stenman's and He's state: the valve position.
    Position(f64),
    /// Kano's state.
    Kano(KanoState),
    /// Choudhury's state.
    Choudhury(ChoudhuryState),
}

impl Model {
    /// Which model this is.
    pub fn kind(&self) -> ModelKind {
        match self {
            Model::Stenman(_) => ModelKind::Stenman,
            Model::He(_) => ModelKind::He,
            Model::Kano(_) => ModelKind::Kano,
            Model::Choudhury(_) => ModelKind::Choudhury,
        }
    }

    /// The parameter values, in the order of [`ModelKind::params`].
    pub fn values(&self) -> Vec<f64> {
        match *self {
            Model::Stenman(m) => vec![m.d],
            Model::He(m) => vec![m.fs, m.fd],
            Model::Kano(m) => vec![m.s, m.j],
            Model::Choudhury(m) => vec![m.s, m.j],
        }
    }

    /// Simulate into a caller's buffer (dispatches once, then runs the monomorphic loop).
    pub fn simulate_into(&self, op: &[f64], mv: &mut [f64]) {
        match self {
            Model::Stenman(m) => m.simulate_into(op, mv),
            Model::He(m) => m.simulate_into(op, mv),
            Model::Kano(m) => m.simulate_into(op, mv),
            Model::Choudhury(m) => m.simulate_into(op, mv),
        }
    }

    /// Simulate the valve position (mv) for the command `op`.
    pub fn simulate(&self, op: &[f64]) -> Vec<f64> {
        let mut mv = vec![0.0; op.len()];
        self.simulate_into(op, &mut mv);
        mv
    }

    /// Simulate with the valve at `start` at the first sample instead of at the first command
    /// (Stenman and He, whose state is the valve position; the other models start as usual).
    /// A record rarely begins just as the valve has moved: this is where it actually stood.
    pub fn simulate_from_into(&self, op: &[f64], start: Option<f64>, mv: &mut [f64]) {
        fn from<M: StictionModel<State = f64>>(m: &M, op: &[f64], x0: f64, mv: &mut [f64]) {
            if op.is_empty() {
                return;
            }
            let mut x = x0;
            mv[0] = x0;
            for (y, &u) in mv[1..].iter_mut().zip(&op[1..]) {
                *y = m.step(&mut x, u);
            }
        }
        match (self, start) {
            (Model::Stenman(m), Some(x0)) => from(m, op, x0, mv),
            (Model::He(m), Some(x0)) => from(m, op, x0, mv),
            _ => self.simulate_into(op, mv),
        }
    }

    /// As [`Model::simulate_from_into`], into a new vector.
    pub fn simulate_from(&self, op: &[f64], start: Option<f64>) -> Vec<f64> {
        let mut mv = vec![0.0; op.len()];
        self.simulate_from_into(op, start, &mut mv);
        mv
    }

    /// Sum of squared errors between a measured valve position and this model's output.
    pub fn sse(&self, op: &[f64], mv_measured: &[f64]) -> f64 {
        match self {
            Model::Stenman(m) => m.sse(op, mv_measured),
            Model::He(m) => m.sse(op, mv_measured),
            Model::Kano(m) => m.sse(op, mv_measured),
            Model::Choudhury(m) => m.sse(op, mv_measured),
        }
    }

    /// Start stepping sample by sample (closed-loop simulation).
    pub fn start(&self, u0: f64) -> (ModelState, f64) {
        match self {
            Model::Stenman(m) => {
                let (s, x) = m.start(u0);
                (ModelState::Position(s), x)
            }
            Model::He(m) => {
                let (s, x) = m.start(u0);
                (ModelState::Position(s), x)
            }
            Model::Kano(m) => {
                let (s, x) = m.start(u0);
                (ModelState::Kano(s), x)
            }
            Model::Choudhury(m) => {
                let (s, x) = m.start(u0);
                (ModelState::Choudhury(s), x)
            }
        }
    }

    /// Advance one sample with command `u`; returns the valve position. Panics if `state` belongs
    /// to another model.
    pub fn step(&self, state: &mut ModelState, u: f64) -> f64 {
        match (self, state) {
            (Model::Stenman(m), ModelState::Position(s)) => m.step(s, u),
            (Model::He(m), ModelState::Position(s)) => m.step(s, u),
            (Model::Kano(m), ModelState::Kano(s)) => m.step(s, u),
            (Model::Choudhury(m), ModelState::Choudhury(s)) => m.step(s, u),
            _ => panic!("model state does not belong to this model"),
        }
    }
}
