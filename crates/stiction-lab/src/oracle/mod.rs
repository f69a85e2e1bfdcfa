//! The oracles' machinery shared by `oracle_bound` and `setpoint_id`: the loop replayed at full
//! rate with a valve model and the Kalman filter over the load ([`kalman`]), and the process
//! profiled around a guess ([`profile`]).

pub mod kalman;
pub mod profile;
