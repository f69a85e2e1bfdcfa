//! The CLI's integration tests, one binary (each file a module): spawning the built `stiction` as a
//! user would. One binary links once, where a binary per file linked every dev-dependency twelve
//! times. Run one part with a filter: `cargo test -p stiction-cli --test all json_pin`.

mod common;

mod batch;
mod batch_faults;
mod batch_layout;
mod cli;
mod compressed;
mod diagnose;
mod exports;
mod first_hour;
mod json_pin;
mod limit_cycle;
mod no_setpoint;
mod reading;
mod render;
mod report;
mod thorough;
