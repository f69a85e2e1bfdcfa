//! Requests checked once, when built (as linfa's checked parameters): a request type's `check`
//! turns it into a [`Checked`] value or names the first setting that is wrong, and the functions
//! that run a request take the checked value, so nothing downstream checks it again.
//!
//! ```
//! use stiction_core::estimate::{estimate_checked, EstimateError, Method, Request};
//! use stiction_core::models::{Model, ModelKind, Stenman};
//!
//! // a setting out of range is found when the request is checked, before any data are read
//! let mut req = Request::new(ModelKind::Stenman, Method::Aco);
//! req.aco.ants = 0;
//! assert!(matches!(req.check(), Err(EstimateError::Setting { name: "ants", .. })));
//!
//! // the paper's ACO (20 ants) on a Stenman valve of band 0.5 driven by a sine
//! req.aco.ants = 20;
//! let req = req.check()?;
//! let op: Vec<f64> = (0..500).map(|k| 3.0 * (k as f64 * 0.05).sin()).collect();
//! let mv = Model::Stenman(Stenman::new(0.5)?).simulate(&op);
//! let e = estimate_checked(&op, &mv, &req)?;
//! assert!((e.params["d"] - 0.5).abs() < 0.05);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use serde::Serialize;
use std::ops::Deref;

/// A request whose settings hold (only its type's `check` builds one). It reads as the request
/// itself; [`Checked::into_inner`] gives the request back to change it (then check it again).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(transparent)]
pub struct Checked<R>(R);

impl<R> Checked<R> {
    /// Wrap a request the caller has just checked.
    pub(crate) fn new(request: R) -> Self {
        Self(request)
    }

    /// The request, to be changed (a changed request must be checked again).
    pub fn into_inner(self) -> R {
        self.0
    }

    /// Change a setting in a way that keeps the request valid (the caller's promise; crate
    /// internal, for the staged searches that narrow a checked request).
    pub(crate) fn adjust(&self, change: impl FnOnce(&mut R)) -> Self
    where
        R: Clone,
    {
        let mut r = self.0.clone();
        change(&mut r);
        Self(r)
    }
}

impl<R> Deref for Checked<R> {
    type Target = R;
    fn deref(&self) -> &R {
        &self.0
    }
}

impl<R> AsRef<R> for Checked<R> {
    fn as_ref(&self) -> &R {
        &self.0
    }
}
