//! He, Wang, Pottmann and Qin (2007): a static and a kinetic band.

use super::*;

/// He et al.'s two-parameter model with static band `fs` and kinetic band `fd` (fs >= fd >= 0).
///
/// The published recursion carries a residual force `r = u - x`; we carry `x` instead, which is the
/// same model (`p = r[t-1] + u[t] - u[t-1] = u[t] - x[t-1]`) and makes `He(d, 0)` equal Stenman(d)
/// bit for bit, not just up to rounding.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct He {
    /// The static friction band, in op's units (normally % of valve span).
    pub fs: f64,
    /// The kinetic friction band, at most `fs`.
    pub fd: f64,
}

impl He {
    /// He's model; an error unless both bands are finite numbers >= 0 and `fd <= fs`.
    pub fn new(fs: f64, fd: f64) -> Result<Self, ModelError> {
        check_nonneg("he", "fs", fs)?;
        check_nonneg("he", "fd", fd)?;
        if fd > fs {
            return Err(ModelError::InvalidParameter {
                model: "he",
                name: "fd",
                value: fd,
                why: format!("the kinetic band fd must not exceed the static band fs = {fs}"),
            });
        }
        Ok(Self { fs, fd })
    }
}

impl StictionModel for He {
    type State = f64;

    #[inline(always)]
    fn start(&self, u0: f64) -> (f64, f64) {
        (u0, u0)
    }

    #[inline(always)]
    fn step(&self, x: &mut f64, u: f64) -> f64 {
        let p = u - *x;
        if p.abs() > self.fs {
            *x = u - self.fd.copysign(p);
        }
        *x
    }
}
