//! The notes: warnings, caveats and how the record was read.

use super::*;

#[derive(Serialize)]
pub struct Notes {
    /// What reading the record decided.
    pub reading: Vec<String>,
    pub warnings: Vec<String>,
    pub caveat: String,
}

pub fn notes(d: &Diagnosis, q: Option<&Quantification>, reading: &[String]) -> Notes {
    let warnings = d
        .warnings
        .iter()
        .chain(q.iter().flat_map(|q| q.warnings.iter()))
        .cloned()
        .collect();
    let caveat = match d.quantification.as_ref() {
        Some(q) => capital(&q.caveat),
        None => {
            "No closed-loop estimate was run: the verdict rests on the statistics the families \
                 read from OP and PV, without measuring the valve position"
                .into()
        }
    };
    Notes {
        reading: reading.to_vec(),
        warnings,
        caveat: format!("{}.", caveat.trim_end_matches('.')),
    }
}
