//! The loop as a whole: the controller identified from the control error and OP, the process from
//! OP and PV, their open loop's frequency response and stability margins, and the describing
//! function of a sticky valve, whose harmonic balance with the identified loop predicts the limit
//! cycle a band sustains. Pure numerics; the `diagnose` family of the same name reads them.
//!
//! - [`controller`]: a PI in velocity form, least squares on the OP increments;
//! - [`frequency`]: frequency responses of the ARX process and the PI, the open loop, its margins;
//! - [`describing`]: describing functions of Kano's (S, J) valve (Stenman's band is S = J) and
//!   of any sampled valve model, and the harmonic balance;
//! - [`cycle`]: the observed cycle: Fourier coefficients at its frequency and the amplitude of
//!   each cycle.
//!
//! The argument (a stable linear loop does not limit-cycle on its own) is the describing-function
//! method of Gelb and Vander Velde (1968), "Multiple-input describing functions and nonlinear
//! system design" (McGraw-Hill), applied to valve stiction by Choudhury, Thornhill and Shah (2005),
//! "Modelling valve stiction", Control Engineering Practice 13, 641-658.

// `!(x > 0.0)` and the like are deliberate: they reject NaN along with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod controller;
pub mod cycle;
pub mod describing;
pub mod frequency;

pub use controller::{identify_pi, identify_pi_below, Action, PiFit};
pub use cycle::{fundamental, AmplitudeTrend, Cycles};
pub use describing::{harmonic_balance, nearest, valve_loci, Balance, Nearest, ValveLocus};
pub use frequency::{Margins, OpenLoop};

/// Complex numbers of the frequency responses.
pub use rustfft::num_complex::Complex64;
