//! How the search converged.

use super::*;

#[derive(Serialize)]
pub struct Convergence {
    pub rows: Vec<KvRow>,
    pub why: &'static str,
}

pub fn convergence(q: &Quantification) -> Convergence {
    let rows = vec![
        kv("Method", format!("{} ({} model)", q.method, q.model)),
        kv("Evaluations", q.evaluations.to_string()),
        kv(
            "Distinct valve trajectories (cells)",
            q.cells.map_or("–".into(), |c| c.to_string()),
        ),
        kv("Time", duration(q.seconds)),
        kv("Samples", format!("{} at {} s", q.samples, num(q.ts))),
    ];
    let why = match q.interval_kind {
        IntervalKind::Exact => {
            "The exact method does not search: the band d changes the estimated valve \
             trajectory only at a finite set of values, so the whole range of d splits into \
             cells with one valve trajectory each; every cell was fitted once. The optimum \
             is proven over every distinct valve trajectory, not found by chance."
        }
        IntervalKind::ExactStaged => {
            "The exact method does not search: the band d changes the estimated valve \
             trajectory only at a finite set of values, so the whole range of d splits into \
             cells with one valve trajectory each. Every cell of the first samples was fitted, \
             then, on the whole record, every cell inside the best of them (each cell of the \
             whole record lies inside one cell of its first samples). The optimum is proven \
             over every distinct valve trajectory kept, not found by chance."
        }
        IntervalKind::ExactLocal => {
            "The exact method fitted every valve trajectory near the best points of a \
             coarse scan: the optimum is proven there only."
        }
        IntervalKind::Grid | IntervalKind::Axis | IntervalKind::None => {
            "A search method: the optimum is the best point found, not proven."
        }
    };
    Convergence { rows, why }
}
