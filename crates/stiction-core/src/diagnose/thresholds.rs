//! The diagnosis's thresholds as one table: what a study or a test reads of them, each with what
//! it is and why it stands there. Built from the constants the families read; changing a field
//! changes no diagnosis (the table is a report of the settings, not a setting).

use serde::Serialize;

use crate::diagnose::evidence::{hidden_valve, model, stick_slip};

/// The thresholds and settings of `diagnose`, as it applies them ([`Thresholds::default`]).
///
/// ```
/// let t = stiction_core::diagnose::Thresholds::default();
/// assert!(t.significance_none < t.significance_stiction);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Thresholds {
    /// Thornhill's regularity at and above which the control error oscillates (his default).
    pub regularity: f64,
    /// Model family: the test ratio at and above which the fit votes stiction; between the 95th
    /// and 97.5th percentiles that simulated healthy loops give.
    pub significance_stiction: f64,
    /// Model family: the ratio at and below which the fit votes against stiction (weakly); about
    /// the 85th percentile of simulated healthy loops.
    pub significance_none: f64,
    /// Model family: the ratio at and above which the comparison over whole periods votes
    /// stiction (the fit's own threshold).
    pub cycle_cancelled_stiction: f64,
    /// Model family: the regularity from which a cycle keeps time like an input of fixed period,
    /// so the fit's gain is compared over whole periods too; above the sticky limit cycles of
    /// the calibration set.
    pub forced_regularity: f64,
    /// Model family: a fitted valve whose PV carries this many times the recorded PV's harmonics
    /// has a shape the record lacks; above every sticky valve of the calibration draws.
    pub foreign_shape: f64,
    /// Model family: where the fit's lag reaches its bound, the changes are also compared over
    /// the bound divided by this.
    pub bound_lag_divisor: usize,
    /// Model family: under this loop gain (process gain times the PI's), off a limit cycle, the
    /// stiction vote is withdrawn: the fit mirrors the controller instead of the process.
    pub min_loop_gain: f64,
    /// The levels test (`thorough`): the ratio at and above which it votes stiction; about the
    /// 98th percentile of simulated healthy loops.
    pub levels_stiction: f64,
    /// Stick-slip family: half-width of PV's noise band in noise standard deviations (PV still).
    pub pv_band_sigmas: f64,
    /// Stick-slip family: OP must travel more than this many of its noise standard deviations in
    /// an episode (OP moving while PV holds).
    pub op_travel_sigmas: f64,
    /// Stick-slip family: the episodes at and above which it votes stiction.
    pub min_episodes: usize,
    /// Hidden-valve family (`thorough`): the log-likelihood ratio from which it votes stiction;
    /// above every look-alike of the calibration sets.
    pub hidden_valve_threshold: f64,
    /// Hidden-valve family: draws of the particle filter's noise whose median decides a vote
    /// (one draw alone can cross the threshold by chance).
    pub hidden_valve_draws: u64,
    /// Hidden-valve family: particles of the sticky hypothesis's filter (the calibrated setting).
    pub hidden_valve_particles: usize,
}

impl Default for Thresholds {
    fn default() -> Self {
        Self {
            regularity: crate::detect::REGULARITY_THRESHOLD,
            significance_stiction: model::SIGNIFICANCE_STICTION,
            significance_none: model::SIGNIFICANCE_NONE,
            cycle_cancelled_stiction: model::CYCLE_CANCELLED_STICTION,
            forced_regularity: model::FORCED_REGULARITY,
            foreign_shape: model::FOREIGN_SHAPE,
            bound_lag_divisor: model::BOUND_LAG_DIVISOR,
            min_loop_gain: model::MIN_LOOP_GAIN,
            levels_stiction: model::LEVELS_STICTION,
            pv_band_sigmas: stick_slip::PV_BAND_SIGMAS,
            op_travel_sigmas: stick_slip::OP_TRAVEL_SIGMAS,
            min_episodes: stick_slip::MIN_EPISODES,
            hidden_valve_threshold: hidden_valve::THRESHOLD,
            hidden_valve_draws: hidden_valve::DRAWS,
            hidden_valve_particles: hidden_valve::PARTICLES,
        }
    }
}
