//! Kano, Maruta, Kugemoto and Shimizu (2004): a band and a slip jump, with the command clamped.

use super::*;

/// Kano et al.'s model: `s` = deadband + stickband, `j` = slip jump, both in % of span.
/// The command is clamped to 0..100 first.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Kano {
    /// Deadband plus stickband S, % of valve span.
    pub s: f64,
    /// Slip jump J, % of valve span.
    pub j: f64,
}

impl Kano {
    /// Kano's model; an error unless S and J are finite numbers >= 0.
    pub fn new(s: f64, j: f64) -> Result<Self, ModelError> {
        check_nonneg("kano", "S", s)?;
        check_nonneg("kano", "J", j)?;
        Ok(Self { s, j })
    }
}

/// The state Kano's recursion carries from one sample to the next.
#[derive(Debug, Clone, Copy)]
pub struct KanoState {
    du_old: f64,
    stopped: bool,
    /// Command at which the valve last came to rest.
    us: f64,
    /// Direction of the last movement (+1 up, -1 down).
    dir: f64,
    u_prev: f64,
    x_prev: f64,
}

impl StictionModel for Kano {
    type State = KanoState;

    fn start(&self, u0: f64) -> (KanoState, f64) {
        let u = u0.clamp(0.0, 100.0);
        let st = KanoState {
            du_old: 0.0,
            stopped: false,
            us: u + (self.s - self.j) / 2.0,
            dir: -1.0,
            u_prev: u,
            x_prev: u,
        };
        (st, u)
    }

    #[inline]
    fn step(&self, st: &mut KanoState, u: f64) -> f64 {
        let u = u.clamp(0.0, 100.0);
        let half_gap = (self.s - self.j) / 2.0;
        let du = u - st.u_prev;
        if du * st.du_old <= 0.0 && !st.stopped {
            // the command stopped or reversed: the valve comes to rest here
            st.us = st.u_prev;
            st.stopped = true;
        }
        let x = if !st.stopped {
            u - st.dir * half_gap
        } else if -st.dir * (u - st.us) > self.s {
            // the command reversed and broke through the band
            st.dir = -st.dir;
            st.stopped = false;
            u - st.dir * half_gap
        } else if st.dir * (u - st.us) > self.j {
            // the command went on in the same direction past the slip jump
            st.stopped = false;
            u - st.dir * half_gap
        } else {
            st.x_prev
        };
        st.du_old = du;
        st.u_prev = u;
        st.x_prev = x;
        x
    }
}
