//! Stenman's one-parameter model.

use super::*;

/// Stenman's one-parameter model: the valve sticks while `|u[t] - x[t-1]| <= d`, else it slips to
/// the command. `d` is the stiction band.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stenman {
    /// The stiction band, in op's units (normally % of valve span).
    pub d: f64,
}

impl Stenman {
    /// Stenman's model with band `d`; an error unless `d` is a finite number >= 0.
    pub fn new(d: f64) -> Result<Self, ModelError> {
        check_nonneg("stenman", "d", d)?;
        Ok(Self { d })
    }
}

impl StictionModel for Stenman {
    type State = f64;

    #[inline(always)]
    fn start(&self, u0: f64) -> (f64, f64) {
        (u0, u0)
    }

    #[inline(always)]
    fn step(&self, x: &mut f64, u: f64) -> f64 {
        if (u - *x).abs() > self.d {
            *x = u;
        }
        *x
    }
}
