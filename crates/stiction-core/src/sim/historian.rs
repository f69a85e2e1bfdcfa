//! What happens to a measurement on its way to the analyst: quantisation (a converter's or a
//! historian's resolution) and historian compression with its reconstruction.
//!
//! Plant historians store a point only when the signal has left a band around what is already
//! stored, and return the values in between by interpolation (PI and similar) or by holding the last
//! stored value. Two storage rules are modelled:
//! - **deadband (exception) storage**: a point is stored when it differs from the last stored one by
//!   more than the deviation; the sample before it is stored too, as PI's exception reporting
//!   does, so a linear reconstruction does not ramp across the whole flat stretch;
//! - **swinging door** (Bristol, "Swinging door trending", ISA 1990): the stored points are the
//!   fewest (greedily) such that the straight line between two consecutive stored points passes
//!   within the deviation of every sample between them. The two "doors" are the steepest and the
//!   flattest slope from the last stored point that keep every sample seen so far within the
//!   deviation; a sample is stored when the next one could no longer be reached through them.
//!
//! Laws (tested): swinging door with linear reconstruction, and deadband storage held, stay within
//! the deviation of the original; deadband storage read back linearly within twice the deviation.

use super::{require, SimError};
use serde::{Deserialize, Serialize};

/// Rounding to a resolution.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quantisation {
    /// The resolution, in the signal's units (e.g. 0.1 % of span).
    pub step: f64,
    /// Where the rounding happens.
    pub at: QuantiseAt,
}

/// Where a signal is quantised.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum QuantiseAt {
    /// The transmitter or converter: the controller sees the rounded PV too.
    Sensor,
    /// Only the stored record is rounded.
    Historian,
}

impl Quantisation {
    /// An error unless the step is positive.
    pub fn validate(&self) -> Result<(), SimError> {
        require(self.step > 0.0, "quantisation step", "> 0", self.step)
    }

    /// `x` rounded to the nearest multiple of the step.
    #[inline]
    pub fn apply(&self, x: f64) -> f64 {
        (x / self.step).round() * self.step
    }
}

/// How a historian decides which samples to store.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CompressionMethod {
    /// Deadband (exception) storage: a point when the signal leaves the deviation around the last
    /// stored one.
    Deadband,
    /// Swinging door: the fewest points whose straight lines stay within the deviation.
    SwingingDoor,
}

/// How the historian returns values between stored points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reconstruction {
    /// Straight lines between stored points (PI's interpolated values).
    Linear,
    /// The last stored value until the next one.
    Hold,
}

/// Historian compression of one recorded signal.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Compression {
    /// Which storage rule.
    pub method: CompressionMethod,
    /// The compression deviation, in the signal's units.
    pub deviation: f64,
    /// How values between stored points are returned.
    pub reconstruction: Reconstruction,
}

impl Compression {
    /// An error unless the deviation is >= 0.
    pub fn validate(&self) -> Result<(), SimError> {
        require(
            self.deviation >= 0.0,
            "compression deviation",
            ">= 0",
            self.deviation,
        )
    }

    /// Indices of the samples the historian stores (always the first and the last).
    pub fn stored(&self, t: &[f64], x: &[f64]) -> Vec<usize> {
        match self.method {
            CompressionMethod::Deadband => deadband_points(x, self.deviation),
            CompressionMethod::SwingingDoor => swinging_door_points(t, x, self.deviation),
        }
    }

    /// The signal as the historian returns it at the recording times `t`.
    pub fn apply(&self, t: &[f64], x: &[f64]) -> Vec<f64> {
        let kept = self.stored(t, x);
        reconstruct(t, x, &kept, self.reconstruction)
    }
}

/// Compression of the recorded PV and, optionally, OP (no compression by default).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Historian {
    /// Compression of the recorded PV, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pv: Option<Compression>,
    /// Compression of the recorded OP, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub op: Option<Compression>,
    /// Each recorded value is the mean of the plant steps since the previous recording time, as
    /// a historian that stores averages over its interval keeps them (a slip then spreads over
    /// one or two samples, OP's small steps are smoothed); otherwise the latest value.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub average: bool,
}

impl Historian {
    /// Whether the historian records the latest values, uncompressed.
    pub fn is_none(&self) -> bool {
        self.pv.is_none() && self.op.is_none() && !self.average
    }

    /// An error unless every compression's deviation is >= 0.
    pub fn validate(&self) -> Result<(), SimError> {
        self.pv
            .iter()
            .chain(&self.op)
            .try_for_each(|c| c.validate())
    }
}

fn deadband_points(x: &[f64], dev: f64) -> Vec<usize> {
    let Some(&first) = x.first() else {
        return Vec::new();
    };
    let mut kept = vec![0];
    let mut last = first;
    for (i, &v) in x.iter().enumerate().skip(1) {
        if (v - last).abs() > dev {
            // the sample before an exception is stored too (unless it already is)
            if kept.last() != Some(&(i - 1)) {
                kept.push(i - 1);
            }
            kept.push(i);
            last = v;
        }
    }
    if kept.last() != Some(&(x.len() - 1)) {
        kept.push(x.len() - 1);
    }
    kept
}

fn swinging_door_points(t: &[f64], x: &[f64], dev: f64) -> Vec<usize> {
    if x.is_empty() {
        return Vec::new();
    }
    let mut kept = vec![0];
    let mut anchor = 0;
    let (mut low, mut high) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut i = 1;
    while i < x.len() {
        let dt = t[i] - t[anchor];
        let slope = (x[i] - x[anchor]) / dt;
        if slope < low || slope > high {
            // the line to sample i would miss an earlier sample: store the one before it, which
            // was reachable, and start the doors again from there
            anchor = i - 1;
            kept.push(anchor);
            low = f64::NEG_INFINITY;
            high = f64::INFINITY;
            continue;
        }
        low = low.max((x[i] - dev - x[anchor]) / dt);
        high = high.min((x[i] + dev - x[anchor]) / dt);
        i += 1;
    }
    if anchor != x.len() - 1 {
        kept.push(x.len() - 1);
    }
    kept
}

fn reconstruct(t: &[f64], x: &[f64], kept: &[usize], how: Reconstruction) -> Vec<f64> {
    let mut out = Vec::with_capacity(x.len());
    for pair in kept.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        for i in a..b {
            out.push(match how {
                Reconstruction::Hold => x[a],
                Reconstruction::Linear => x[a] + (x[b] - x[a]) * (t[i] - t[a]) / (t[b] - t[a]),
            });
        }
    }
    if let Some(&last) = kept.last() {
        out.push(x[last]);
    }
    out
}
