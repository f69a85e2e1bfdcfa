//! The statistics the verdict's model reads, taken from the families' evidence as they report
//! it, and the findings that tell them.

use super::{Motion, Statistic};
use crate::diagnose::evidence::{Family, FamilyEvidence, ModelEvidence, StickSlipEvidence};
use crate::diagnose::reasons::Finding;

/// Below this share of PV's variation above its noise explained through any valve, OP does not
/// drive PV's cycle.
const MIN_EXPLAINED: f64 = 0.3;

/// A sticky valve's describing function gives the loop's needed lag and gain within this
/// distance (the loop family's tolerance).
const MAX_DESCRIBING: f64 = 0.2;

/// The statistics of one judged stretch (`None`: not measured there).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Measured([Option<f64>; Statistic::ALL.len()]);

fn family(families: &[FamilyEvidence], f: Family) -> Option<&FamilyEvidence> {
    families.iter().find(|e| e.family == f)
}

fn fit(families: &[FamilyEvidence]) -> Option<&ModelEvidence> {
    family(families, Family::Model).and_then(|f| f.model.as_ref())
}

fn sticks(families: &[FamilyEvidence]) -> Option<&StickSlipEvidence> {
    family(families, Family::StickSlip).and_then(|f| f.stick_slip.as_ref())
}

impl Measured {
    /// The statistics of `families`, with OP's noise standard deviation `op_noise` (OP units).
    pub fn of(families: &[FamilyEvidence], op_noise: f64) -> Self {
        let op_noise = op_noise.max(1e-9);
        let finite = |v: f64| v.is_finite().then_some(v);
        let mut m = Measured::default();
        // OP drives PV: the fit explains enough of PV's variation through some valve
        let driven = fit(families).is_none_or(|e| e.explained >= MIN_EXPLAINED);
        for (i, s) in Statistic::ALL.into_iter().enumerate() {
            let st = sticks(families);
            let ft = fit(families).filter(|e| e.judged);
            m.0[i] = match s {
                // (as the cycle's shape: a PV that steps while OP winds, where OP does not drive
                // PV, steps OP's way by chance)
                Statistic::StickShare => st.map(|e| e.stick_share).filter(|_| driven),
                Statistic::Sticks => st.map(|e| (e.sticks as f64).ln_1p()),
                Statistic::Stuck => st.map(|e| e.stuck_travel_percent_of_span.ln_1p()),
                Statistic::FitGain => ft.map(|e| e.improvement.max(0.0)),
                Statistic::FitBand => ft.map(|e| (e.stenman_d / op_noise).ln_1p()),
                Statistic::FitTest => ft.map(|e| e.significance.max(0.0).ln_1p()),
                // a cycle OP does not drive (the fit explains little of PV through any valve) has
                // no valve's shape: its shape is not read
                Statistic::CycleShape => family(families, Family::Shape)
                    .and_then(|f| f.value)
                    .filter(|_| driven),
                // the lag a valve must add, where a sticky valve's describing function gives it
                // (at most a quarter period, the balance closed within its tolerance); a lag no
                // valve gives reads 0
                Statistic::LoopLag => family(families, Family::Loop)
                    .and_then(|f| f.limit_cycle.as_ref())
                    .map(|l| {
                        let given = l
                            .describing
                            .as_ref()
                            .is_some_and(|d| d.distance <= MAX_DESCRIBING);
                        let lag = l.needed_lag_degrees;
                        if given && (0.0..=90.0).contains(&lag) {
                            lag
                        } else {
                            0.0
                        }
                    }),
            }
            .and_then(finite);
        }
        m
    }

    /// One statistic.
    pub fn get(&self, s: Statistic) -> Option<f64> {
        let i = Statistic::ALL.iter().position(|&t| t == s)?;
        self.0[i]
    }

    /// Whether any statistic was measured.
    pub fn any(&self) -> bool {
        self.0.iter().any(Option::is_some)
    }
}

/// The finding that tells statistic `s` of `families`.
pub(super) fn finding(
    s: Statistic,
    families: &[FamilyEvidence],
    measured: &Measured,
    motion: &Motion,
) -> Option<Finding> {
    Some(match s {
        Statistic::StickShare | Statistic::Sticks => {
            let e = sticks(families)?;
            Finding::Sticks {
                sticks: e.sticks,
                steps: e.steps,
                median_travel_percent_of_span: e.median_travel_percent_of_span?,
                minutes: motion.minutes,
            }
        }
        Statistic::Stuck => {
            let e = sticks(families)?;
            let [a, b] = e.stuck_range?;
            Finding::Stuck {
                travel_percent_of_span: e.stuck_travel_percent_of_span,
                minutes: (b - a) as f64 * motion.ts / 60.0,
            }
        }
        Statistic::FitGain => {
            let e = fit(families)?;
            Finding::FitGain {
                improvement: e.improvement,
                band_percent_of_span: e.stenman_d_percent_of_span,
            }
        }
        Statistic::FitBand => {
            let e = fit(families)?;
            Finding::FitBand {
                band_over_op_noise: measured.get(Statistic::FitBand)?.exp_m1(),
                band_percent_of_span: e.stenman_d_percent_of_span,
            }
        }
        Statistic::FitTest => Finding::FitTest {
            ratio: fit(families)?.significance,
        },
        Statistic::CycleShape => Finding::CycleShape {
            score: measured.get(s)?,
            period: motion.period,
        },
        Statistic::LoopLag => Finding::LoopLag {
            degrees: measured.get(s)?,
            period: motion.period,
        },
    })
}
