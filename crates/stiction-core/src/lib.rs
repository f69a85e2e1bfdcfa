//! `stiction-core`: stiction models, loop simulation and estimators for control valves.
//!
//! Pure numerics: functions take slices and return serde-serialisable results; nothing here reads
//! files, prints or plots. The command-line tool and every other front end share these results.
//!
//! A sticky valve in a simulated PI loop, diagnosed and its stiction band sized:
//!
//! ```
//! use stiction_core::diagnose::{diagnose, DiagnoseRequest, LoopRecord, Verdict};
//! use stiction_core::models::{Model, Stenman};
//! use stiction_core::sim::ClosedLoop;
//!
//! // a Stenman valve with a band of 2 % of span in a first-order loop (the defaults)
//! let mut sim = ClosedLoop::new(Model::Stenman(Stenman::new(2.0)?));
//! sim.samples = 1500;
//! sim.noise = 0.05;
//! sim.seed = 3;
//! let data = sim.run()?;
//!
//! let record = LoopRecord {
//!     op: &data.op,
//!     pv: &data.pv,
//!     sp: Some(&data.sp),
//!     mv: None,
//!     time: None,
//!     auto: None,
//! };
//! let d = diagnose(&record, &DiagnoseRequest::default())?;
//! assert_eq!(d.verdict, Verdict::Stiction);
//! let band = d.band.expect("a stiction verdict sizes the band");
//! assert!((band.band_percent_of_span - 2.0).abs() < 0.5);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]

pub mod checked;
pub mod detect;
pub mod diagnose;
pub mod estimate;
pub mod fleet;
pub mod hidden_valve;
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

pub use checked::Checked;
pub use estimate::{estimate, estimate_checked, Estimate, Method, Request};
pub use models::{Model, ModelKind, StictionModel};
