//! The data-quality gates.

use super::*;

#[derive(Serialize)]
pub struct GateRow {
    pub gate: Gate,
    pub passed: bool,
    pub value: String,
    pub limit: String,
    pub message: String,
}

#[derive(Serialize)]
pub struct Quality {
    pub summary: String,
    pub gates: Vec<GateRow>,
}

pub fn quality(d: &Diagnosis) -> Quality {
    let failed = d.quality.iter().filter(|f| !f.passed).count();
    let summary = if failed == 0 {
        format!("Every gate passed ({} checked).", d.quality.len())
    } else {
        format!(
            "{failed} of {} gates failed: the record cannot carry a verdict.",
            d.quality.len()
        )
    };
    let gates = d
        .quality
        .iter()
        .map(|f| GateRow {
            gate: f.gate,
            passed: f.passed,
            value: num(f.value),
            limit: num(f.limit),
            message: f.message.clone(),
        })
        .collect();
    Quality { summary, gates }
}
