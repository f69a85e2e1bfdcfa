//! The searches' parts: coordinate ascent over the loop model, the grid of hidden valves, the
//! sticky hypothesis's ascent with its valve, and the memory of likelihoods already judged.

use super::coordinates::{set, values, Coordinate, Scales};
use super::likelihood::Slip;
use super::model::LoopModel;
use super::search::TestSettings;
use std::collections::HashMap;

/// A model's parameters, bit for bit: the key under which a likelihood is remembered.
fn key(m: &LoopModel) -> [u64; 10] {
    [
        m.gain,
        m.tau,
        m.delay,
        m.valve_lag,
        m.noise,
        m.drift,
        m.cycle,
        m.cycle_radius,
        m.cycle_angle,
        m.input_noise,
    ]
    .map(f64::to_bits)
}

/// `f` remembered: the ascents come back to models (and valves) they have judged, each
/// coordinate's grid holding the current value; a remembered likelihood is the same number.
pub(super) fn remembered<K: std::hash::Hash + Eq, A: Copy>(
    f: impl Fn(&LoopModel, A) -> f64,
    with: impl Fn(A) -> K,
) -> impl FnMut(&LoopModel, A) -> f64 {
    let mut seen: HashMap<([u64; 10], K), f64> = HashMap::new();
    move |m, a| *seen.entry((key(m), with(a))).or_insert_with(|| f(m, a))
}

/// Coordinate ascent of `f` from `(best, m)` over `coords`, `sweeps` times.
pub(super) fn ascend(
    f: &mut dyn FnMut(&LoopModel) -> f64,
    (mut best, mut m): (f64, LoopModel),
    coords: &[Coordinate],
    sweeps: usize,
    s: &Scales,
) -> (f64, LoopModel) {
    for _ in 0..sweeps {
        for &c in coords {
            for v in values(c, s) {
                let mut trial = m;
                set(&mut trial, c, v);
                let l = f(&trial);
                if l > best {
                    (best, m) = (l, trial);
                }
            }
        }
    }
    (best, m)
}

/// The valves tried: every band at every share of it a slip may land short of OP, share by
/// share (a share's bands in order, so a band's neighbours on the grid sit beside it).
pub(super) struct Grid {
    pub(super) slips: Vec<Slip>,
    bands: usize,
}

impl Grid {
    pub(super) fn new(set: &TestSettings) -> Self {
        let (a, b) = set.band_range;
        let bands: Vec<f64> = (0..set.bands)
            .map(|i| set.op_span * a * (b / a).powf(i as f64 / (set.bands.max(2) - 1) as f64))
            .collect();
        let slips = set
            .short_shares
            .iter()
            .flat_map(|&share| {
                bands.iter().map(move |&band| Slip {
                    band,
                    short: share * band,
                })
            })
            .collect();
        Self {
            slips,
            bands: set.bands,
        }
    }

    /// `slip` and its neighbours in band at the same share.
    fn near(&self, slip: Slip) -> &[Slip] {
        let i = self.slips.iter().position(|&s| s == slip).unwrap_or(0);
        let row = i / self.bands * self.bands;
        let lo = i.saturating_sub(1).max(row);
        let hi = (i + 2).min(row + self.bands);
        &self.slips[lo..hi]
    }
}

/// The best of `best` (likelihood, valve) and every valve of `slips` under model `m`.
pub(super) fn scan(
    sticky: &mut dyn FnMut(&LoopModel, Slip) -> f64,
    slips: &[Slip],
    m: &LoopModel,
    best: (f64, Slip),
) -> (f64, Slip) {
    slips.iter().fold(best, |b, &v| {
        let l = sticky(m, v);
        if l > b.0 {
            (l, v)
        } else {
            b
        }
    })
}

/// Coordinate ascent of the sticky likelihood (two sweeps), each move judged at the valve and
/// its neighbours in band: another gain or dead time slips the valve at other samples, and the
/// band that fits moves with them.
pub(super) fn ascend_with_band(
    sticky: &mut dyn FnMut(&LoopModel, Slip) -> f64,
    grid: &Grid,
    (mut best, mut m, mut slip): (f64, LoopModel, Slip),
    coords: &[Coordinate],
    s: &Scales,
) -> (f64, LoopModel, Slip) {
    for _ in 0..2 {
        for &c in coords {
            for v in values(c, s) {
                let mut trial = m;
                set(&mut trial, c, v);
                let (l, d) = scan(sticky, grid.near(slip), &trial, (f64::NEG_INFINITY, slip));
                if l > best {
                    (best, m, slip) = (l, trial, d);
                }
            }
        }
    }
    (best, m, slip)
}

/// The valves the sticky ascents start from at a healthy optimum `m`: the scan's best and, with
/// `basins` 2, the best whose band lies more than a grid step from it. At a healthy optimum,
/// whose model has absorbed part of a sticky valve's effect, a small band can beat the true one
/// until the model moves, and an ascent that moves a band a step at a time stays by it.
pub(super) fn band_starts(
    sticky: &mut dyn FnMut(&LoopModel, Slip) -> f64,
    m: &LoopModel,
    grid: &Grid,
    basins: usize,
) -> Vec<(f64, Slip)> {
    let scored: Vec<(usize, f64)> = (0..grid.slips.len())
        .map(|i| (i, sticky(m, grid.slips[i])))
        .collect();
    let best_of = |keep: &dyn Fn(usize) -> bool| {
        scored
            .iter()
            .filter(|(i, _)| keep(*i))
            .fold(None, |b: Option<(usize, f64)>, &(i, l)| match b {
                Some((_, bl)) if bl >= l => b,
                _ => Some((i, l)),
            })
    };
    let Some((first, l)) = best_of(&|_| true) else {
        return Vec::new();
    };
    let mut starts = vec![(l, grid.slips[first])];
    let band = |i: usize| i % grid.bands;
    if basins > 1 {
        if let Some((j, l)) = best_of(&|i| band(i).abs_diff(band(first)) > 1) {
            starts.push((l, grid.slips[j]));
        }
    }
    starts
}

/// The sticky hypothesis from a healthy optimum `m` and a valve `start` of the scan there: the
/// model ascended with the valve (two sweeps), the valves scanned again. Returns the likelihood,
/// model and valve.
pub(super) fn sticky_optimum(
    sticky: &mut dyn FnMut(&LoopModel, Slip) -> f64,
    m: &LoopModel,
    start: (f64, Slip),
    grid: &Grid,
    scales: &Scales,
) -> (f64, LoopModel, Slip) {
    let (l1, slip) = start;
    let order = [
        Coordinate::Noise,
        Coordinate::Cycle,
        Coordinate::Drift,
        Coordinate::CycleRadius,
        Coordinate::CycleAngle,
        Coordinate::Gain,
        Coordinate::Tau,
        Coordinate::Delay,
        Coordinate::ValveLag,
    ];
    let (l1, m1, slip) = ascend_with_band(sticky, grid, (l1, *m, slip), &order, scales);
    let (l1, slip) = scan(sticky, &grid.slips, &m1, (l1, slip));
    (l1, m1, slip)
}
