//! Stenman, exact: every distinct valve trajectory (cell of the partition of the d-range) is
//! simulated once and fitted with each of the given linear structures. The range is cut into fixed
//! chunks walked in parallel, so the work spreads over threads and the result does not depend on
//! their number. Without `full`, only the chunks around the best points of a coarse scan are walked
//! (faster, exact only there).

use super::problem::{Hammerstein, OverLag};
use super::search::Outcome;
use crate::estimate::{exact, IntervalKind};
use crate::identify;
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Cells of the first samples carried into the whole-record search of a staged search.
const TOP_CELLS: usize = 24;
/// Chunks the whole d-range is cut into (geometric: bands are usually small).
const CHUNKS: usize = 64;
/// A staged search's ranges are cut into at least this many chunks in all (each range into one
/// to four): enough for the threads, and no more, since each chunk simulates its first valve and
/// sums its first cell over the whole record afresh (with 15-20 ranges, as limit cycles give,
/// four chunks a range made that overhead most of the stage).
const STAGED_CHUNKS: usize = 8;
/// Consecutive cells' sums are updated incrementally; a full recomputation this often bounds
/// rounding.
const FULL_EVERY: usize = 256;

/// A cell of the d-partition with its cost under each structure.
type CellCosts = ((f64, f64), Vec<f64>);

/// One outcome per structure (problem), in order. `only`: a staged search's ranges of d.
pub(super) fn exact_stenman(
    problems: &[Hammerstein],
    (lo, hi): (f64, f64),
    full: bool,
    only: Option<&[(f64, f64)]>,
) -> Vec<Outcome> {
    let full = full || only.is_some();
    let mut chunks = chunks(lo, hi, only);
    let scan: Vec<f64> = chunks.iter().map(|c| 0.5 * (c.0 + c.1)).collect();
    // achievable costs to start from: simulations that exceed them stop early (such a cell can
    // never be optimal, so the optimal set is the same whatever the order of the work)
    let start_bounds: Vec<f64> = if full {
        super::problem::min_costs_1d(problems, &scan)
    } else {
        let scan_costs: Vec<Vec<f64>> = problems.iter().map(|p| p.costs_1d(&scan)).collect();
        chunks = around_best(&chunks, &scan_costs);
        scan_costs
            .iter()
            .map(|c| c.iter().copied().fold(f64::INFINITY, f64::min))
            .collect()
    };
    let n = problems[0].len();
    let per_chunk: Vec<Vec<CellCosts>> = chunks
        .par_iter()
        .map_init(
            || Walk::new(n),
            |walk, &chunk| walk.chunk(problems, chunk, (lo, hi), &start_bounds),
        )
        .collect();
    let cells: Vec<CellCosts> = per_chunk.into_iter().flatten().collect();
    let kind = match (only.is_some(), full) {
        (true, _) => IntervalKind::ExactStaged,
        (false, true) => IntervalKind::Exact,
        (false, false) => IntervalKind::ExactLocal,
    };
    (0..problems.len())
        .map(|s| outcome(&cells, s, (lo, hi), kind, scan.len()))
        .collect()
}

/// The chunks to walk: a staged search's ranges, each cut in a few chunks for the threads
/// ([`STAGED_CHUNKS`]), or the whole range cut geometrically.
fn chunks(lo: f64, hi: f64, only: Option<&[(f64, f64)]>) -> Vec<(f64, f64)> {
    match only {
        Some(ranges) => ranges
            .iter()
            .flat_map(|&(a, b)| {
                let k = (STAGED_CHUNKS / ranges.len()).clamp(1, 4);
                (0..k).map(move |i| {
                    (
                        a + (b - a) * i as f64 / k as f64,
                        a + (b - a) * (i + 1) as f64 / k as f64,
                    )
                })
            })
            .filter(|c| c.1 > c.0)
            .collect(),
        None => {
            let first = (hi - lo) * 1e-4;
            let mut edges: Vec<f64> = (0..CHUNKS)
                .map(|i| lo + first * ((hi - lo) / first).powf(i as f64 / (CHUNKS - 1) as f64))
                // the last edge can pass `hi` by a rounding
                .map(|e| e.min(hi))
                .collect();
            edges[0] = lo;
            edges.push(hi);
            edges.dedup();
            edges.windows(2).map(|w| (w[0], w[1])).collect()
        }
    }
}

/// The chunks around the three best scan points of each structure, with their neighbours.
fn around_best(chunks: &[(f64, f64)], scan_costs: &[Vec<f64>]) -> Vec<(f64, f64)> {
    let mut keep = Vec::new();
    for costs in scan_costs {
        let mut order: Vec<usize> = (0..chunks.len()).collect();
        order.sort_by(|&i, &j| costs[i].total_cmp(&costs[j]));
        keep.extend(
            order
                .iter()
                .take(3)
                .flat_map(|&i| [i.saturating_sub(1), i, (i + 1).min(chunks.len() - 1)]),
        );
    }
    chunks
        .iter()
        .enumerate()
        .filter(|(i, _)| keep.contains(i))
        .map(|(_, &c)| c)
        .collect()
}

/// One thread's buffers for walking chunks of the d-partition.
struct Walk {
    /// The valve trajectory as the linear part sees it (less the offset, or over the lag when the
    /// problems compare changes), and the previous cell's.
    mv: Vec<f64>,
    prev: Vec<f64>,
    /// The previous cell's whole trajectory (for sums over the lag, updated where it moved).
    prev_full: Vec<f64>,
    changed: Vec<usize>,
    rows: Vec<usize>,
}

impl Walk {
    /// `n`: samples the linear part sees.
    fn new(n: usize) -> Self {
        Self {
            mv: vec![0.0; n],
            prev: vec![0.0; n],
            prev_full: Vec::new(),
            changed: Vec::new(),
            rows: Vec::new(),
        }
    }

    /// Every cell of one chunk with its cost under each structure. Consecutive cells'
    /// trajectories differ only on short stretches (they join again at the next slip both make):
    /// the walk names the samples that changed, and the least-squares sums of the previous cell
    /// are updated only on the rows that see them.
    fn chunk(
        &mut self,
        problems: &[Hammerstein],
        chunk: (f64, f64),
        range: (f64, f64),
        start_bounds: &[f64],
    ) -> Vec<CellCosts> {
        let Walk {
            mv: seen,
            prev,
            prev_full,
            changed,
            rows,
        } = self;
        let n = seen.len();
        let (offset, lag, over) = (problems[0].offset, problems[0].lag, problems[0].over);
        let mut out = Vec::new();
        let mut bounds = start_bounds.to_vec();
        let mut sums: Vec<identify::ValveSums> = Vec::new();
        let x0 = problems[0].start.unwrap_or(problems[0].op[0]);
        let prepared: Vec<&identify::Prepared> = problems.iter().map(|p| &p.prepared).collect();
        exact::stenman_walk_changes(problems[0].op, x0, chunk, range, |cell, full, moved| {
            changed.clear();
            let due = sums.is_empty() || out.len() % FULL_EVERY == 0;
            // sums over the lag are updated by each move's change, so now and then summed afresh
            let moved = moved.filter(|_| !(due && over == OverLag::Sum));
            match (moved, over) {
                (None, _) => seen_whole(full, offset, lag, over, seen),
                (Some(moved), OverLag::Change) => {
                    seen_changes(full, moved, offset, lag, seen, prev, changed)
                }
                (Some(moved), OverLag::Sum) => {
                    sums_changes(full, prev_full, moved, lag, seen, prev, changed)
                }
            }
            if over == OverLag::Sum {
                match moved {
                    None => {
                        prev_full.clear();
                        prev_full.extend_from_slice(full);
                    }
                    Some(moved) => moved.iter().for_each(|&i| prev_full[i] = full[i]),
                }
            }
            // (a cell seen whole is always due: the first, or a sum over the lag summed afresh)
            let refresh = due;
            if !refresh && changed.len() < n / 8 {
                for (p, s) in problems.iter().zip(sums.iter_mut()) {
                    p.prepared.update_sums(s, prev, seen, changed, rows);
                }
            } else {
                sums = problems.iter().map(|p| p.prepared.sums(seen)).collect();
            }
            let costs = identify::costs_from_sums(&prepared, &sums, seen, &bounds);
            for (bound, &c) in bounds.iter_mut().zip(&costs) {
                *bound = bound.min(c);
            }
            if moved.is_none() {
                prev.copy_from_slice(seen);
            } else {
                for &t in changed.iter() {
                    prev[t] = seen[t];
                }
            }
            out.push((cell, costs));
        });
        out
    }
}

/// The trajectory as the linear part sees it (`seen`): the valve position less the offset, or
/// over the lag as `over` says.
fn seen_whole(full: &[f64], offset: f64, lag: usize, over: OverLag, seen: &mut [f64]) {
    if lag == 0 {
        for (s, &v) in seen.iter_mut().zip(full) {
            *s = v - offset;
        }
    } else {
        super::problem::over_lag(full, lag, over, offset, seen);
    }
}

/// The trajectory as the linear part sees it (`seen`), updated where the valve moved
/// (`moved`, samples of the whole trajectory `full`), and the samples of `seen` that now differ
/// from `prev` bit for bit, in increasing order.
fn seen_changes(
    full: &[f64],
    moved: &[usize],
    offset: f64,
    lag: usize,
    seen: &mut [f64],
    prev: &[f64],
    changed: &mut Vec<usize>,
) {
    let n = seen.len();
    if lag == 0 {
        for &i in moved {
            seen[i] = full[i] - offset;
            if seen[i].to_bits() != prev[i].to_bits() {
                changed.push(i);
            }
        }
        return;
    }
    // a moved sample i enters the changes over the lag that end at it (t = i - lag) and that
    // start at it (t = i): two increasing sequences, merged
    let ends = &moved[moved.partition_point(|&i| i < lag)..];
    let starts = &moved[..moved.partition_point(|&i| i < n)];
    let (mut e, mut s) = (0, 0);
    while e < ends.len() || s < starts.len() {
        let a = ends.get(e).map_or(usize::MAX, |&i| i - lag);
        let b = starts.get(s).copied().unwrap_or(usize::MAX);
        let t = a.min(b);
        e += usize::from(a == t);
        s += usize::from(b == t);
        seen[t] = full[t + lag] - full[t];
        if seen[t].to_bits() != prev[t].to_bits() {
            changed.push(t);
        }
    }
}

/// The valve summed over the lag (`seen`), updated where the valve moved (`moved`, samples of
/// the whole trajectory `full`, `prev_full` the previous one): a move at sample `i` changes the
/// sums of the windows that hold it, `i - lag + 1 ..= i`; the samples of `seen` that now differ
/// from `prev` bit for bit, in increasing order, into `changed`.
fn sums_changes(
    full: &[f64],
    prev_full: &[f64],
    moved: &[usize],
    lag: usize,
    seen: &mut [f64],
    prev: &[f64],
    changed: &mut Vec<usize>,
) {
    let n = seen.len();
    let mut reach = 0;
    for &i in moved {
        let delta = full[i] - prev_full[i];
        if delta == 0.0 {
            continue;
        }
        let first = (i + 1).saturating_sub(lag);
        let last = i.min(n.saturating_sub(1));
        if first > last || first >= n {
            continue;
        }
        for s in &mut seen[first..=last] {
            *s += delta;
        }
        // the windows of the moves come in increasing order: each sample named once
        for t in first.max(reach)..=last {
            changed.push(t);
        }
        reach = reach.max(last + 1);
    }
    changed.retain(|&t| seen[t].to_bits() != prev[t].to_bits());
}

/// Ranges of d in increasing order of their starts, with those that touch or overlap joined.
pub(super) fn merge_sorted(ranges: impl IntoIterator<Item = (f64, f64)>) -> Vec<(f64, f64)> {
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for r in ranges {
        match merged.last_mut() {
            Some(last) if last.1 >= r.0 => last.1 = last.1.max(r.1),
            _ => merged.push(r),
        }
    }
    merged
}

/// The share of an even part of OP's travel the first samples must see for a staged search. On
/// the catalogue's calibration sets and further draws 1 to 3 (2,340 loops) 0.2 and 0.5 give the
/// verdicts 0.33 gives but one (at 0.2 a sticky fast loop `undetermined`, not `no_stiction`):
/// records either start at rest or do not.
const STAGE_TRAVEL_SHARE: f64 = 0.33;

/// Whether the first `m` samples, where a staged walk keeps its cells, see OP move: OP's travel
/// there (the sum of its absolute changes) at least [`STAGE_TRAVEL_SHARE`] of what an even share
/// of its whole travel would give them. A record that starts at rest and cycles later (a load
/// ramp the stuck valve held until it slipped) gives the first samples no band to tell apart:
/// every band that keeps the valve still fits them alike, and the cells kept can miss the
/// valve's band (routine-c-0003 of the catalogue: a 4.5 % band cycling from sample 620 on, 3 %
/// of OP's travel in the first 600 samples; found as 0.3 %).
pub(crate) fn stage_sees_the_travel(op: &[f64], m: usize) -> bool {
    let travel = |v: &[f64]| v.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f64>();
    let even = m as f64 / op.len() as f64;
    travel(&op[..m]) >= STAGE_TRAVEL_SHARE * even * travel(op)
}

/// The cells of least cost of several outcomes (a staged search's first stage), as ranges of d
/// in increasing order, joined where they touch or overlap.
pub(super) fn merged_top_cells<'a>(outcomes: impl Iterator<Item = &'a Outcome>) -> Vec<(f64, f64)> {
    let mut ranges: Vec<(f64, f64)> = outcomes.flat_map(|o| o.top_cells.iter().copied()).collect();
    ranges.sort_by(|a, b| a.0.total_cmp(&b.0));
    merge_sorted(ranges)
}

/// The optimal set of structure `s` over the walked cells.
fn outcome(
    cells: &[CellCosts],
    s: usize,
    (lo, hi): (f64, f64),
    kind: IntervalKind,
    scanned: usize,
) -> Outcome {
    let best = cells.iter().map(|c| c.1[s]).fold(f64::INFINITY, f64::min);
    // sums updated step by step round differently from fresh ones: a hair of tolerance
    // keeps the pieces of one trajectory together
    let tolerance = 1e-9 * best.abs();
    // (pieces of one cell split at a chunk edge join again)
    let optimal = merge_sorted(
        cells
            .iter()
            .filter(|c| c.1[s] <= best + tolerance)
            .map(|c| c.0),
    );
    // the widest optimal piece's midpoint is the point estimate; the interval their hull
    let (a, b) = optimal
        .iter()
        .copied()
        .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
        .unwrap_or((lo, hi));
    let hull = [
        optimal.first().map_or(lo, |c| c.0),
        optimal.last().map_or(hi, |c| c.1),
    ];
    let mut ranked: Vec<&CellCosts> = cells.iter().collect();
    ranked.sort_by(|x, y| x.1[s].total_cmp(&y.1[s]).then(x.0 .0.total_cmp(&y.0 .0)));
    Outcome {
        best: vec![0.5 * (a + b)],
        interval: BTreeMap::from([("d".to_string(), hull)]),
        interval_kind: kind,
        evaluations: (cells.len() + scanned) as u64,
        cells: Some(cells.len()),
        // the best cells, and the lowest (a valve without stiction is always a candidate)
        top_cells: ranked
            .iter()
            .take(TOP_CELLS)
            .map(|c| c.0)
            .chain(cells.first().map(|c| c.0))
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::{seen_changes, seen_whole, stage_sees_the_travel, sums_changes, OverLag};

    /// A record whose OP moves evenly is staged; one at rest on its first samples, then moving,
    /// is walked whole; one that moves most at its start is staged.
    #[test]
    fn a_stage_must_see_ops_travel() {
        let wave = |t: usize| (t as f64 * 0.3).sin();
        let even: Vec<f64> = (0..2000).map(wave).collect();
        assert!(stage_sees_the_travel(&even, 600));
        let late: Vec<f64> = (0..2000)
            .map(|t| if t < 620 { 0.01 * wave(7 * t) } else { wave(t) })
            .collect();
        assert!(!stage_sees_the_travel(&late, 600));
        let early: Vec<f64> = (0..2000)
            .map(|t| if t < 600 { wave(t) } else { 0.01 * wave(t) })
            .collect();
        assert!(stage_sees_the_travel(&early, 600));
    }

    fn seen_of(full: &[f64], offset: f64, lag: usize) -> Vec<f64> {
        let mut seen = vec![0.0; full.len() - lag];
        seen_whole(full, offset, lag, OverLag::Change, &mut seen);
        seen
    }

    /// Updated where the valve moved, the seen trajectory equals the one computed whole, and the
    /// changes named are exactly the samples that differ from before, in increasing order: moves
    /// at the record's ends, runs of moves, and moves that cancel over the lag.
    #[test]
    fn seen_changes_follow_the_valves_moves() {
        let n = 60;
        let old: Vec<f64> = (0..n).map(|i| ((i * 7) % 11) as f64).collect();
        // [10, 13] at lag 3: the change over the lag from 10 to 13 cancels
        let moves: [&[usize]; 5] = [
            &[0],
            &[n - 1],
            &[3, 4, 5, 6, 20, 21],
            &[0, 1, 58, 59],
            &[10, 13],
        ];
        for lag in [0, 1, 3, 12] {
            for moved in moves {
                let mut new = old.clone();
                for &i in moved {
                    new[i] += 1.5;
                }
                let prev = seen_of(&old, 2.0, lag);
                let mut seen = prev.clone();
                let mut changed = Vec::new();
                seen_changes(&new, moved, 2.0, lag, &mut seen, &prev, &mut changed);
                let whole = seen_of(&new, 2.0, lag);
                assert_eq!(seen, whole, "lag {lag}, moved {moved:?}");
                let truth: Vec<usize> = (0..whole.len())
                    .filter(|&t| whole[t].to_bits() != prev[t].to_bits())
                    .collect();
                assert_eq!(changed, truth, "lag {lag}, moved {moved:?}");
            }
        }
    }

    /// Updated where the valve moved, the valve summed over the lag equals the sums taken whole
    /// (to rounding), and the samples named are those that differ from before, in increasing
    /// order.
    #[test]
    fn sums_over_the_lag_follow_the_valves_moves() {
        let n = 60;
        let old: Vec<f64> = (0..n).map(|i| ((i * 7) % 11) as f64).collect();
        let moves: [&[usize]; 4] = [&[0], &[n - 1], &[3, 4, 5, 6, 20, 21], &[0, 1, 58, 59]];
        for lag in [1, 3, 12] {
            for moved in moves {
                let mut new = old.clone();
                for &i in moved {
                    new[i] += 1.5;
                }
                let whole = |x: &[f64]| {
                    let mut seen = vec![0.0; n - lag];
                    seen_whole(x, 2.0, lag, OverLag::Sum, &mut seen);
                    seen
                };
                let prev = whole(&old);
                let mut seen = prev.clone();
                let mut changed = Vec::new();
                sums_changes(&new, &old, moved, lag, &mut seen, &prev, &mut changed);
                let truth = whole(&new);
                for t in 0..seen.len() {
                    assert!(
                        (seen[t] - truth[t]).abs() < 1e-12,
                        "lag {lag}, moved {moved:?}"
                    );
                }
                let differ: Vec<usize> = (0..truth.len())
                    .filter(|&t| (truth[t] - prev[t]).abs() > 1e-12)
                    .collect();
                assert_eq!(changed, differ, "lag {lag}, moved {moved:?}");
            }
        }
    }
}
