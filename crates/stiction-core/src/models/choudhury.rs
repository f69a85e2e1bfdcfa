//! Choudhury, Thornhill and Shah (2005): a band and a slip jump; the valve stops and reverses
//! where the command's velocity does.

use super::*;

/// Choudhury et al.'s model: `s` (deadband + stickband) and `j` (slip jump) in % of span.
///
/// The command is scaled to % of span with `span = (lo, hi)` (default 0..100: already in %) and
/// saturated to 0..100; the output is in the same %. A velocity change smaller than
/// `velocity_deadzone` counts as zero, which keeps noise in OP from looking like stops and
/// reversals (0 = the published model).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Choudhury {
    /// Deadband plus stickband S, % of valve span.
    pub s: f64,
    /// Slip jump J, % of valve span.
    pub j: f64,
    /// A change of the scaled command per sample at most this large (% of span) counts as no
    /// motion.
    pub velocity_deadzone: f64,
    /// The command values of 0 % and 100 % of span.
    pub span: (f64, f64),
}

impl Choudhury {
    /// Choudhury's model with the published behaviour (no velocity deadzone, command already in %
    /// of span); an error unless S and J are finite numbers >= 0.
    pub fn new(s: f64, j: f64) -> Result<Self, ModelError> {
        check_nonneg("choudhury", "S", s)?;
        check_nonneg("choudhury", "J", j)?;
        Ok(Self {
            s,
            j,
            velocity_deadzone: 0.0,
            span: (0.0, 100.0),
        })
    }

    #[inline]
    fn scale(&self, u: f64) -> f64 {
        let (lo, hi) = self.span;
        (100.0 * (u - lo) / (hi - lo)).clamp(0.0, 100.0)
    }

    #[inline]
    fn sign(&self, v: f64) -> f64 {
        if v.abs() <= self.velocity_deadzone {
            0.0
        } else {
            v.signum()
        }
    }
}

/// The state Choudhury's recursion carries from one sample to the next.
#[derive(Debug, Clone, Copy)]
pub struct ChoudhuryState {
    v_old: f64,
    /// Command at which the valve stuck.
    xss: f64,
    /// 1 when the valve stopped while moving (the slip jump J applies), else 0.
    stopped_moving: bool,
    xc_prev: f64,
    x_prev: f64,
}

impl StictionModel for Choudhury {
    type State = ChoudhuryState;

    fn start(&self, u0: f64) -> (ChoudhuryState, f64) {
        let xc = self.scale(u0);
        let st = ChoudhuryState {
            v_old: 0.0,
            xss: xc,
            stopped_moving: false,
            xc_prev: xc,
            x_prev: xc,
        };
        (st, xc)
    }

    #[inline]
    fn step(&self, st: &mut ChoudhuryState, u: f64) -> f64 {
        let xc = self.scale(u);
        let v = xc - st.xc_prev;
        let sv = self.sign(v);
        let half_gap = (self.s - self.j) / 2.0;
        let x = if sv == self.sign(st.v_old) {
            if !st.stopped_moving {
                if (xc - st.xss).abs() > self.s {
                    xc - sv * half_gap
                } else {
                    st.x_prev
                }
            } else if (xc - st.xss).abs() > self.j {
                st.stopped_moving = false;
                xc - sv * half_gap
            } else {
                st.x_prev
            }
        } else {
            // reversal, start or stop
            st.xss = st.xc_prev;
            if sv == 0.0 {
                st.stopped_moving = true;
            }
            st.x_prev
        };
        st.v_old = v;
        st.xc_prev = xc;
        st.x_prev = x;
        x
    }
}
