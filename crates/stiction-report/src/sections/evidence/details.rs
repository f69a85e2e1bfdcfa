//! One family's detail as key-value rows: what it measured, the rule it is held to, and its
//! own figures (the fits' R², the sticks, the valve position's band, the linear loop's balance).

use super::super::{kv, KvRow};
use crate::words::{count, duration, num, opt};
use stiction_core::diagnose::evidence::{
    HiddenValveEvidence, LoopEvidence, ModelEvidence, StickSlipEvidence, ValveEvidence,
};
use stiction_core::diagnose::FamilyEvidence;

/// Every row of family `f`'s detail.
pub fn rows(f: &FamilyEvidence) -> Vec<KvRow> {
    let mut rows = vec![
        kv("Statistic", f.statistic.clone()),
        kv("Value", opt(f.value)),
        kv("Rule", f.threshold.clone()),
        kv("Strength", num(f.strength)),
    ];
    if let Some(m) = &f.model {
        rows.extend(model(m));
    }
    if let Some(s) = &f.stick_slip {
        rows.extend(stick_slip(s));
    }
    if let Some(v) = &f.valve {
        rows.extend(valve(v));
    }
    if let Some(l) = &f.limit_cycle {
        rows.extend(limit_cycle(l));
    }
    if let Some(h) = &f.hidden_valve {
        rows.extend(hidden_valve(h));
    }
    rows
}

fn model(m: &ModelEvidence) -> Vec<KvRow> {
    vec![
        kv(
            "R² in simulation",
            format!(
                "{} with a valve that follows OP, {} with Stenman's band, {} with a slip jump (Kano)",
                num(m.r2_without_stiction),
                num(m.r2_stenman),
                num(m.r2_slip_jump)
            ),
        ),
        kv(
            "Band fitted",
            format!("{} % of span (Stenman's d)", num(m.stenman_d_percent_of_span)),
        ),
        kv(
            "Gain with the band",
            format!(
                "{} % of PV's variation above its noise",
                num(100.0 * m.improvement)
            ),
        ),
        kv("Test ratio", num(m.significance)),
        kv(
            "Explained with the band",
            format!("{} % of PV's variation above its noise", num(100.0 * m.explained)),
        ),
    ]
}

fn stick_slip(s: &StickSlipEvidence) -> Vec<KvRow> {
    let mut rows = vec![
        kv(
            "Sticks",
            format!(
                "{} of PV's {} ({} %)",
                s.sticks,
                count(s.steps, "step", "steps"),
                num(100.0 * s.stick_share)
            ),
        ),
        kv(
            "OP travel per stick",
            s.median_travel_percent_of_span
                .map_or("–".into(), |t| format!("median {} % of span", num(t))),
        ),
        kv(
            "Longest hold",
            format!(
                "OP travelled {} % of span while PV held off the setpoint{}",
                num(s.stuck_travel_percent_of_span),
                s.stuck_range.map_or(String::new(), |[a, b]| format!(
                    " (samples {a} to {b} of the analysed stretch)"
                ))
            ),
        ),
        kv(
            "Controller",
            if s.controller_sign > 0.0 {
                "reverse acting (OP rises when PV is below the setpoint)"
            } else {
                "direct acting (OP rises when PV is above the setpoint)"
            }
            .to_string(),
        ),
    ];
    rows.push(kv(
        "Noise",
        format!(
            "PV {}, OP {} (standard deviations)",
            num(s.pv_noise),
            num(s.op_noise)
        ),
    ));
    rows
}

fn valve(v: &ValveEvidence) -> Vec<KvRow> {
    vec![
        kv(
            "Band of the valve position",
            format!(
                "{} % of span{}",
                num(v.d_percent_of_span),
                v.interval.map_or(String::new(), |[lo, hi]| format!(
                    " (optimal set {} to {} %)",
                    num(lo),
                    num(hi)
                ))
            ),
        ),
        kv(
            "R² of MV",
            format!(
                "{} with the band, {} with a valve that follows OP",
                num(v.r2),
                num(v.r2_without_stiction)
            ),
        ),
    ]
}

fn limit_cycle(l: &LoopEvidence) -> Vec<KvRow> {
    let mut rows = vec![
        kv("Cycle", duration(l.period)),
        kv(
            "Gain margin",
            l.margins.gain_margin.map_or("none".into(), num),
        ),
        kv(
            "What the valve must do",
            format!(
                "lag OP by {}° with a gain of {} for the identified loop to sustain the cycle",
                num(l.needed_lag_degrees),
                num(l.needed_gain)
            ),
        ),
    ];
    if let Some(b) = &l.describing {
        rows.push(kv(
            "Describing function",
            format!(
                "a band of {} % of span{}",
                num(b.band_percent_of_span),
                b.predicted_period.map_or(String::new(), |p| format!(
                    ", predicted period {}",
                    duration(p)
                ))
            ),
        ));
    }
    rows
}

fn hidden_valve(h: &HiddenValveEvidence) -> Vec<KvRow> {
    vec![
        kv("Log-likelihood ratio", num(h.ratio)),
        kv(
            "Best band",
            format!("{} % of span", num(h.band_percent_of_span)),
        ),
    ]
}
