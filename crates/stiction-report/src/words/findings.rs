//! A finding in words, with the record's figures: what was measured and, where its part in the
//! verdict is known, which way it points.

use super::figures::{fig, fig2, percent, stretch, the_cycle, times};
use stiction_core::diagnose::{Finding, Reason};

/// Which way a finding points: towards a sticky valve, away from one, or not known (a finding on
/// its own, without its share of the log-odds).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Towards {
    Sticky,
    Healthy,
    Unknown,
}

impl Towards {
    fn of(contribution: Option<f64>) -> Self {
        match contribution {
            Some(c) if c > 0.0 => Towards::Sticky,
            Some(c) if c < 0.0 => Towards::Healthy,
            _ => Towards::Unknown,
        }
    }
}

/// A finding in words, from its figures alone.
pub fn finding(f: &Finding) -> String {
    words(f, Towards::Unknown)
}

/// A reason in words: its finding, worded the way its share of the log-odds points.
pub fn reason(r: &Reason) -> String {
    words(&r.finding, Towards::of(r.contribution))
}

pub(crate) fn words(f: &Finding, towards: Towards) -> String {
    match f {
        Finding::Sticks {
            sticks,
            steps,
            median_travel_percent_of_span,
            minutes,
        } => sticks_words(*sticks, *steps, *median_travel_percent_of_span, *minutes, towards),
        Finding::Stuck {
            travel_percent_of_span,
            minutes,
        } => stuck_words(*travel_percent_of_span, *minutes, towards),
        Finding::FitGain {
            improvement,
            band_percent_of_span,
        } => fit_gain_words(*improvement, *band_percent_of_span, towards),
        Finding::FitBand {
            band_over_op_noise,
            band_percent_of_span,
        } => fit_band_words(*band_over_op_noise, *band_percent_of_span, towards),
        Finding::FitTest { ratio } => fit_test_words(*ratio, towards),
        Finding::CycleShape { score, period } => cycle_shape_words(*score, *period, towards),
        Finding::LoopLag { degrees, period } => loop_lag_words(*degrees, *period, towards),
        Finding::ValvePosition {
            band_percent_of_span,
            sticky,
        } => valve_words(*band_percent_of_span, *sticky),
        Finding::NothingOfAStickyValve => "no statistic points to a sticky valve".into(),
        Finding::Between {
            probability,
            below,
            from,
        } => format!(
            "P = {probability:.2} lies between {below:.2} (no stiction) and {from:.2} (stiction): too weak to decide"
        ),
        Finding::UnresolvedCycle { period, samples } => format!(
            "a regular cycle of {} s has only {} samples a period: too few for any family to read it \
             (at a few samples a cycle it passes for measurement noise)",
            fig(*period),
            fig(*samples)
        ),
        Finding::NotExcited => {
            "OP and PV hardly move above their noise: nothing shows how the loop responds to the valve"
                .into()
        }
        Finding::Record { message } => message.clone(),
    }
}

fn sticks_words(sticks: usize, steps: usize, travel: f64, minutes: f64, t: Towards) -> String {
    let over = stretch(minutes);
    if sticks == 0 {
        return format!(
            "none of PV's {steps} steps in {over} ended a stick (OP winding while PV stayed in its noise, then PV stepping OP's way)"
        );
    }
    let share = format!("{sticks} of PV's {steps} steps");
    match t {
        Towards::Healthy => format!(
            "only {share} in {over} ended a stick (OP moved a median {} % of span while PV stayed in its noise, then PV stepped OP's way)",
            fig2(travel)
        ),
        _ => format!(
            "OP moved a median {} % of span while PV stayed in its noise, {} in {over}, each time ended by a PV step OP's way ({share})",
            fig2(travel),
            times(sticks)
        ),
    }
}

fn stuck_words(travel: f64, minutes: f64, t: Towards) -> String {
    match t {
        Towards::Healthy => format!(
            "PV held off the setpoint without moving towards it only while OP travelled {} % of span (over {}): the valve moves when OP does",
            fig(travel),
            stretch(minutes)
        ),
        _ => format!(
            "OP travelled {} % of span over {} while PV held off the setpoint without moving towards it (the valve does not move)",
            fig(travel),
            stretch(minutes)
        ),
    }
}

fn fit_gain_words(improvement: f64, band: f64, t: Towards) -> String {
    match t {
        Towards::Healthy if improvement < 0.005 => {
            "a sticky valve explains no more of PV's variation than a valve that follows OP (closed-loop fit)".into()
        }
        Towards::Healthy => format!(
            "a sticky valve explains only {} more of PV's variation above its noise than a valve that follows OP (closed-loop fit)",
            percent(improvement)
        ),
        _ => format!(
            "a sticky valve with a band of {} % of span explains {} more of PV's variation above its noise than a valve that follows OP (closed-loop fit)",
            fig(band),
            percent(improvement)
        ),
    }
}

fn fit_band_words(over_noise: f64, band: f64, t: Towards) -> String {
    match t {
        Towards::Healthy => format!(
            "the band the closed-loop fit finds, {} % of span, is only {} times OP's noise: noise alone could make it",
            fig(band),
            fig(over_noise)
        ),
        _ => format!(
            "the band the closed-loop fit finds, {} % of span, is {} times OP's noise: more than noise makes",
            fig(band),
            fig(over_noise)
        ),
    }
}

fn fit_test_words(ratio: f64, t: Towards) -> String {
    match t {
        Towards::Healthy => format!(
            "the closed-loop fit's gain with a band is within what chance gives (test ratio {})",
            fig(ratio)
        ),
        Towards::Sticky => format!(
            "the closed-loop fit's gain with a band is far beyond what chance gives (test ratio {})",
            fig(ratio)
        ),
        Towards::Unknown => format!(
            "the closed-loop fit's gain with a band, held against chance: test ratio {}",
            fig(ratio)
        ),
    }
}

fn cycle_shape_words(score: f64, period: Option<f64>, t: Towards) -> String {
    let cycle = the_cycle(period);
    let sticky = match t {
        Towards::Sticky => true,
        Towards::Healthy => false,
        Towards::Unknown => score > 0.0,
    };
    if sticky {
        format!(
            "{cycle} has a sticky valve's shape, triangles or squares rather than a sine (shape score {score:.2})"
        )
    } else if score < 0.0 {
        format!(
            "{cycle} is sinusoidal (shape score {score:.2}): a linear cause, not a sticky valve's"
        )
    } else {
        format!(
            "{cycle} is nearer a sine than a sticky valve's triangles or squares (shape score {score:.2})"
        )
    }
}

fn loop_lag_words(degrees: f64, period: Option<f64>, t: Towards) -> String {
    let cycle = the_cycle(period);
    match t {
        Towards::Healthy => format!(
            "the identified linear loop sustains {cycle} with the valve lagging OP by {}° only: a loop near its stability limit cycles so",
            fig(degrees)
        ),
        _ => format!(
            "for the identified linear loop to sustain {cycle}, the valve must lag OP by {}°: a lag a sticky valve adds and a linear valve does not",
            fig(degrees)
        ),
    }
}

fn valve_words(band: Option<f64>, sticky: bool) -> String {
    match (sticky, band) {
        (true, Some(b)) => format!(
            "the recorded valve position shows a band of {} % of span: the valve holds while OP moves (measured on the valve itself)",
            fig(b)
        ),
        (true, None) => {
            "the recorded valve position holds while OP moves (measured on the valve itself)".into()
        }
        (false, _) => {
            "the recorded valve position follows OP without a band (measured on the valve itself)"
                .into()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_briefs_sentences() {
        let s = finding(&Finding::Sticks {
            sticks: 4,
            steps: 6,
            median_travel_percent_of_span: 1.8,
            minutes: 125.0,
        });
        assert_eq!(
            s,
            "OP moved a median 1.8 % of span while PV stayed in its noise, 4 times in 125 min, \
             each time ended by a PV step OP's way (4 of PV's 6 steps)"
        );
        let s = finding(&Finding::Stuck {
            travel_percent_of_span: 73.2,
            minutes: 118.0,
        });
        assert_eq!(
            s,
            "OP travelled 73 % of span over 118 min while PV held off the setpoint without moving \
             towards it (the valve does not move)"
        );
        let s = finding(&Finding::FitGain {
            improvement: 0.82,
            band_percent_of_span: 1.66,
        });
        assert_eq!(
            s,
            "a sticky valve with a band of 1.66 % of span explains 82 % more of PV's variation \
             above its noise than a valve that follows OP (closed-loop fit)"
        );
        let s = finding(&Finding::CycleShape {
            score: -0.67,
            period: None,
        });
        assert_eq!(
            s,
            "the cycle is sinusoidal (shape score -0.67): a linear cause, not a sticky valve's"
        );
        let s = finding(&Finding::Between {
            probability: 0.52,
            below: 0.4,
            from: 0.6,
        });
        assert_eq!(
            s,
            "P = 0.52 lies between 0.40 (no stiction) and 0.60 (stiction): too weak to decide"
        );
    }

    #[test]
    fn a_reason_against_a_sticky_valve_is_worded_so() {
        let r = Reason {
            finding: Finding::FitGain {
                improvement: 0.01,
                band_percent_of_span: 0.3,
            },
            contribution: Some(-1.2),
            text: String::new(),
        };
        assert!(reason(&r).contains("only 1 % more"), "{}", reason(&r));
        let r = Reason {
            finding: Finding::CycleShape {
                score: -0.5,
                period: Some(300.0),
            },
            contribution: Some(-1.0),
            text: String::new(),
        };
        assert!(
            reason(&r).starts_with("the 300 s cycle is sinusoidal"),
            "{}",
            reason(&r)
        );
        let r = Reason {
            finding: Finding::CycleShape {
                score: 0.6,
                period: Some(100.0),
            },
            contribution: Some(1.0),
            text: String::new(),
        };
        assert!(
            reason(&r).contains("sticky valve's shape"),
            "{}",
            reason(&r)
        );
    }

    #[test]
    fn every_finding_has_words() {
        let all = [
            Finding::FitBand {
                band_over_op_noise: 12.0,
                band_percent_of_span: 1.2,
            },
            Finding::FitTest { ratio: 76.0 },
            Finding::LoopLag {
                degrees: 60.0,
                period: Some(100.0),
            },
            Finding::ValvePosition {
                band_percent_of_span: Some(2.0),
                sticky: true,
            },
            Finding::ValvePosition {
                band_percent_of_span: None,
                sticky: false,
            },
            Finding::NothingOfAStickyValve,
            Finding::UnresolvedCycle {
                period: 6.0,
                samples: 3.0,
            },
            Finding::NotExcited,
            Finding::Record {
                message: "too short".into(),
            },
            Finding::Sticks {
                sticks: 0,
                steps: 3,
                median_travel_percent_of_span: 0.0,
                minutes: 30.0,
            },
        ];
        for f in &all {
            assert!(!finding(f).is_empty(), "{f:?}");
        }
    }
}
