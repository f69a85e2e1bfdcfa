//! The evidence: the verdict, each family's vote and the indices.

use super::*;

#[derive(Serialize)]
pub struct FamilyRow {
    pub family: &'static str,
    pub value: String,
    pub vote: Chip,
    pub statistic: String,
    pub threshold: String,
    pub note: String,
}

#[derive(Serialize)]
pub struct IndexRow {
    pub name: String,
    pub value: String,
    pub vote: Chip,
    pub threshold: String,
    pub weight: String,
    pub reference: String,
    pub note: String,
}

#[derive(Serialize)]
pub struct Evidence {
    pub families: Vec<FamilyRow>,
    pub indices: Vec<IndexRow>,
    /// Why no index was computed, when none was.
    pub no_index: Option<&'static str>,
}

pub fn evidence(d: &Diagnosis) -> Evidence {
    let mut families: Vec<FamilyRow> = d
        .families
        .iter()
        .map(|f| FamilyRow {
            family: f.family.words(),
            value: opt(f.value),
            vote: vote_chip(f.vote),
            statistic: f.statistic.clone(),
            threshold: f.threshold.clone(),
            note: f.note.clone(),
        })
        .collect();
    if let Some(c) = &d.combined {
        families.push(FamilyRow {
            family: "statistics combined",
            value: num(c.probability),
            vote: vote_chip(c.vote()),
            statistic: "probability of a sticky valve from the families' statistics read together (trained trees)".into(),
            threshold: format!(
                "stiction from {:.2}; never a vote against stiction (trained on simulated loops only)",
                c.threshold
            ),
            note: format!("{}; towards a sticky valve most: {}", capital(c.role()), c.leading()),
        });
    }
    let indices = d
        .indices
        .iter()
        .map(|i| IndexRow {
            name: i.name.clone(),
            value: opt(i.value),
            vote: vote_chip(i.vote),
            threshold: i.threshold.clone(),
            weight: num(i.weight),
            reference: i.reference.clone(),
            note: i.note.clone(),
        })
        .collect();
    let no_index = d.indices.is_empty().then_some(match d.verdict {
        Verdict::InsufficientData => "the record cannot carry a verdict (see the reason above)",
        _ => "the loop does not oscillate regularly with a constant setpoint, so there is no shape for them to read",
    });
    Evidence {
        families,
        indices,
        no_index,
    }
}
