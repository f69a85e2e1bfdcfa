//! A sticky valve as a hidden state: the likelihood of the record under a valve whose position it
//! does not hold, against a valve that follows OP.
//!
//! Where the controller moves OP between the recorded samples, no valve model run on the recorded
//! OP reproduces a sticky valve: noise the record does not hold decides the sample at which it
//! slips (`stiction-lab/results/sampled-valve.md`). The closed-loop fits then see no band, yet PV
//! shows every slip. Here the valve's position is hidden: a particle filter carries many positions,
//! each slipping when OP, as the controller may have moved it between the samples, leaves the band,
//! and each with the loop's state filtered exactly (the loop is linear and Gaussian given the
//! valve). Against it, a Kalman filter with the valve following OP and the same unrecorded moves of
//! OP as input noise. Both share one loop model ([`LoopModel`]): valve lag, first-order process or
//! integrator, dead time, a drifting and a cycling load (at PV's strongest cycle, or at the cycle
//! the loop shows when the caller knows it: [`TestSettings::cycle_period`]), measurement noise; its
//! parameters are found by coordinate ascent on each hypothesis's likelihood ([`fn@test`]), and the
//! healthy one is searched again from the sticky one's optimum, so the ratio is never an artefact
//! of a search that stopped short.
//!
//! Where it holds was set by the lab's `hidden_valve` study
//! (`stiction-lab/results/hidden-valve-fast.md`, `hidden-valve-routine.md`); `diagnose --thorough`
//! runs it there as the hidden-valve family ([`crate::diagnose::evidence::hidden_valve`]).

mod ascent;
mod coordinates;
mod likelihood;
mod model;
mod search;

pub use likelihood::{healthy_log_likelihood, sticky_log_likelihood, Particles, Record, Slip};
pub use model::LoopModel;
pub use search::{test, HiddenValveTest, TestSettings};

#[cfg(test)]
mod tests;
