//! The core's integration tests, one binary (each file a module), through the public API only.
//! One binary links once, where a binary per file linked the crate and proptest eight times.
//! Run one part with a filter: `cargo test -p stiction-core --test all plant_sim`.

mod diagnose;
mod estimation;
mod limit_cycle;
mod models;
mod plant_sim;
mod quantify;
mod simulation;
