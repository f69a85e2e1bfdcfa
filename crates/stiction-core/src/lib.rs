//! `stiction-core`: stiction models, loop simulation and estimators for control valves.
//!
//! Pure numerics: functions take slices and return serde-serialisable results; nothing here reads
//! files, prints or plots. The command-line tool and every other front end share these results.

pub mod detect;
pub mod diagnose;
pub mod estimate;
pub mod fleet;
pub mod identify;
pub mod loop_analysis;
pub mod models;
pub mod quality;
pub mod quantify;
pub mod record;
pub mod reproduce;
pub mod rng;
pub mod sim;
pub mod sim_check;
pub mod spec;
pub mod spectral;

pub use estimate::{estimate, Estimate, Method, Request};
pub use models::{Model, ModelKind, StictionModel};
