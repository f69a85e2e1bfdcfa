//! A model with its parameters chosen at run time, and its state.

use super::*;

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
