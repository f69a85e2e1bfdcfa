//! The statistics of the verdict's model by name, and their values as a person reads them (the
//! model reads some through `ln(1 + x)`; these words undo it).

use super::figures::{fig, percent};
use stiction_core::diagnose::{Family, Statistic};

/// The family that measures a statistic.
pub fn measured_by(s: Statistic) -> Family {
    match s {
        Statistic::StickShare | Statistic::Sticks | Statistic::Stuck => Family::StickSlip,
        Statistic::FitGain | Statistic::FitBand | Statistic::FitTest => Family::Model,
        Statistic::CycleShape => Family::Shape,
        Statistic::LoopLag => Family::Loop,
    }
}

/// A statistic's name in words.
pub fn statistic(s: Statistic) -> &'static str {
    match s {
        Statistic::StickShare => "share of PV's steps that end a stick",
        Statistic::Sticks => "sticks found",
        Statistic::Stuck => "OP's travel while PV holds off the setpoint, % of span",
        Statistic::FitGain => {
            "closed-loop fit's gain with a band (share of PV's variation above its noise)"
        }
        Statistic::FitBand => "closed-loop fit's band over OP's noise",
        Statistic::FitTest => "closed-loop fit's test ratio",
        Statistic::CycleShape => "cycle's shape score (-1 a sine, 1 a sticky valve's)",
        Statistic::LoopLag => "lag the valve must add for the linear loop to cycle, degrees",
    }
}

/// A statistic's value as the model reads it (`value`), in the statistic's own units: the count
/// of sticks, % of span, a ratio, a share in %, degrees.
pub fn statistic_value(s: Statistic, value: f64) -> String {
    match s {
        Statistic::StickShare | Statistic::FitGain => percent(value),
        Statistic::Sticks => fig(value.exp_m1().round()),
        Statistic::Stuck => format!("{} %", fig(value.exp_m1())),
        Statistic::FitBand | Statistic::FitTest => fig(value.exp_m1()),
        Statistic::CycleShape => format!("{value:.2}"),
        Statistic::LoopLag => format!("{}°", fig(value)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_read_back_in_their_units() {
        assert_eq!(statistic_value(Statistic::Sticks, 4f64.ln_1p()), "4");
        assert_eq!(statistic_value(Statistic::Stuck, 73f64.ln_1p()), "73 %");
        assert_eq!(statistic_value(Statistic::FitGain, 0.25), "25 %");
        assert_eq!(statistic_value(Statistic::CycleShape, -0.671), "-0.67");
        for s in Statistic::ALL {
            assert!(!statistic(s).is_empty());
        }
    }
}
