//! `stiction-lab`: the experiments beside the product. The simulated catalogue of benchmark
//! loops ([`catalogue`]) and what the studies in `examples/` share: a catalogue loop read as the
//! CLI reads it, the studies' command line, verdict tallies, the clean output-error fit, the fast
//! loop simulator, the identification from the setpoint, the oracles' Kalman filter and the ISDB
//! reader. Never published; it depends on `stiction-core`, never the other way round.

pub mod catalogue;
pub mod catalogue_loop;
pub mod clean_fit;
pub mod fast_loop;
pub mod isdb;
pub mod logistic;
pub mod oracle;
pub mod real;
pub mod setpoint;
pub mod study_args;
pub mod tally;
