//! The levels test's walk: every distinct Stenman valve trajectory scored, in fixed chunks in
//! parallel, with the walk in order's result.

use super::*;

/// The best Stenman valve of the levels test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelsWalk {
    /// The log-likelihood ratio of the best trajectory against OP.
    pub ratio: f64,
    /// The best valve's band, OP units (the middle of its Stenman cell, or He's fs).
    pub band: f64,
    /// How far short of OP the best valve's slips land (He's fd), OP units; 0 for Stenman's.
    pub slip_short: f64,
    /// Distinct trajectories scored.
    pub trajectories: usize,
}

/// Score every distinct Stenman valve trajectory from `op` (the valve at the first OP, bands from
/// 10⁻⁴ of OP's range to its range) by the levels test on `pv`; `None` for a record too short or
/// an OP that does not move.
pub fn levels_walk(op: &[f64], pv: &[f64], integrating: bool) -> Option<LevelsWalk> {
    let n = op.len();
    if n < MIN_SAMPLES || pv.len() != n || op.iter().chain(pv).any(|v| !v.is_finite()) {
        return None;
    }
    let (lo, hi) = op
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let range = hi - lo;
    if range <= 0.0 {
        return None;
    }
    let fit = LevelsFit::new(pv, op, integrating);
    let mut scratch = fit.scratch();
    let with_op = fit.sse(op, &mut scratch);
    let (best_walk, trajectories) = walk_chunks(&fit, op, range);
    let (mut best, mut band) = match best_walk {
        Some((s, cell)) if s < with_op => (s, 0.5 * (cell.0 + cell.1)),
        _ => (with_op, 0.0),
    };
    let mut valve = vec![0.0; n];
    // a slip that lands short of OP (He's dynamic friction fd, Kano's slip jump below the band)
    // near the best band: a few fits beside the walk's thousands
    let mut slip_short = 0.0;
    if band > 0.0 {
        let found = band;
        let tries = [0.8, 0.9, 1.0, 1.1, 1.25]
            .into_iter()
            .flat_map(|m| [0.25, 0.5, 0.75].map(|k| (m * found, k * m * found)));
        for (fs, fd) in tries {
            if let Ok(m) = He::new(fs, fd) {
                Model::He(m).simulate_from_into(op, Some(op[0]), &mut valve);
                let s = fit.sse(&valve, &mut scratch);
                if s < best {
                    (best, band, slip_short) = (s, fs, fd);
                }
            }
        }
    }
    let ratio = fit.ratio(with_op, best);
    if !ratio.is_finite() {
        return None;
    }
    Some(LevelsWalk {
        ratio,
        band,
        slip_short,
        trajectories,
    })
}

/// Chunks the band's range is cut into (geometric), walked in parallel; the result is the
/// sequential walk's, whatever the number of threads.
const WALK_CHUNKS: usize = 32;

/// What one chunk's walk found: its best piece of a cell and that piece's error, its first and
/// last pieces' errors (a cell that crosses the chunk's edge is walked in two pieces, one in each
/// chunk, with the same trajectory and so the same error), and the pieces walked.
pub(super) struct ChunkWalk {
    best: Option<Piece>,
    first: Option<Piece>,
    last: Option<Piece>,
    pieces: usize,
}

/// A walked piece of a cell: the error of its trajectory and the piece's bands.
pub(super) type Piece = (f64, (f64, f64));

/// Every distinct Stenman trajectory of bands in `[range 10⁻⁴, range)`, walked in fixed chunks
/// in parallel: the best trajectory's error and whole cell (the first in order of the band
/// among equals, as a walk in order keeps), and the number of distinct trajectories.
pub(super) fn walk_chunks(fit: &LevelsFit, op: &[f64], range: f64) -> (Option<Piece>, usize) {
    use rayon::prelude::*;
    let (first, hi) = (range * 1e-4, range);
    let mut edges: Vec<f64> = (0..=WALK_CHUNKS)
        .map(|i| first * (hi / first).powf(i as f64 / WALK_CHUNKS as f64))
        .collect();
    edges[0] = first;
    edges[WALK_CHUNKS] = hi;
    let whole = (0.0, range * (1.0 + 1e-9));
    let walks: Vec<ChunkWalk> = edges
        .par_windows(2)
        .map_init(
            || (fit.scratch(), vec![0.0; op.len()]),
            |(scratch, valve), w| {
                let mut c = ChunkWalk {
                    best: None,
                    first: None,
                    last: None,
                    pieces: 0,
                };
                stenman_walk(op, op[0], (w[0], w[1]), whole, valve, |cell, mv| {
                    let s = fit.sse(mv, scratch);
                    c.pieces += 1;
                    if c.best.is_none_or(|b| s < b.0) {
                        c.best = Some((s, cell));
                    }
                    if c.first.is_none() {
                        c.first = Some((s, cell));
                    }
                    c.last = Some((s, cell));
                });
                c
            },
        )
        .collect();
    // a piece whose error equals the next chunk's first piece's is one cell split at the edge
    let split = |i: usize| match (walks[i].last, walks.get(i + 1).and_then(|w| w.first)) {
        (Some(a), Some(b)) => a.0 == b.0 && a.1 .1 == b.1 .0,
        _ => false,
    };
    let trajectories = walks.iter().map(|w| w.pieces).sum::<usize>()
        - (0..walks.len()).filter(|&i| split(i)).count();
    let mut best: Option<(f64, (f64, f64), usize)> = None;
    for (i, w) in walks.iter().enumerate() {
        if let Some((s, cell)) = w.best {
            if best.is_none_or(|b| s < b.0) {
                best = Some((s, cell, i));
            }
        }
    }
    let best = best.map(|(s, cell, mut i)| {
        // the best piece ends at its chunk's edge: the cell goes on into the next chunks
        let mut piece = cell;
        while walks[i].last.is_some_and(|l| l.1 == piece) && split(i) {
            piece = walks[i + 1].first.map_or(piece, |f| f.1);
            i += 1;
        }
        (s, (cell.0, piece.1))
    });
    (best, trajectories)
}
