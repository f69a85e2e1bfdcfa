//! Starting points: the stiction parameters at which the linear structure is chosen before the
//! main search, and first guesses for two-parameter models from the Stenman band.

use crate::models::ModelKind;

/// Structures from the pilots that are searched first, and the most searched in all.
pub(super) const STARTING_STRUCTURES: usize = 4;
pub(super) const MOST_STRUCTURES: usize = 8;

/// Parameter sets at which the linear structure is chosen before the main search.
pub(super) fn pilot_points(kind: ModelKind, bounds: &[(f64, f64)]) -> Vec<Vec<f64>> {
    // geometric spread: stiction bands are usually a small share of the OP range
    let axis = |(lo, hi): (f64, f64), k: usize| -> Vec<f64> {
        let first = (hi - lo) * 0.005;
        (0..k)
            .map(|i| lo + first * ((hi - lo) / first).powf(i as f64 / (k - 1) as f64))
            .collect()
    };
    if kind.dim() == 1 {
        let (lo, hi) = bounds[0];
        let mut v: Vec<Vec<f64>> = axis(bounds[0], 24).into_iter().map(|d| vec![d]).collect();
        v.extend((0..8).map(|i| vec![lo + (hi - lo) * (i as f64 + 0.5) / 8.0]));
        v.push(vec![lo]);
        v
    } else {
        let mut out = Vec::new();
        for a in axis(bounds[0], 5) {
            for b in axis(bounds[1], 4) {
                let mut p = vec![a, b];
                kind.repair(&mut p);
                out.push(p);
            }
        }
        out
    }
}

/// Starting points for a two-parameter search from the Stenman band d.
pub(super) fn first_guesses(kind: ModelKind, d: f64) -> Vec<Vec<f64>> {
    let mut out = match kind {
        ModelKind::He => vec![
            vec![d, 0.0],
            vec![d, 0.25 * d],
            vec![d, 0.5 * d],
            vec![1.5 * d, 0.5 * d],
        ],
        _ => vec![
            vec![d, d],
            vec![d, 0.5 * d],
            vec![d, 0.25 * d],
            vec![1.5 * d, 0.5 * d],
            vec![1.5 * d, d],
            vec![2.0 * d, d],
            vec![0.75 * d, 0.75 * d],
        ],
    };
    for g in &mut out {
        kind.repair(g);
    }
    out
}
