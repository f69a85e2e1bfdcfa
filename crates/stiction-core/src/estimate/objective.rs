//! The fit objective `F(θ) = Σ (mv[t] - x_θ[t])²`, evaluated for many candidates per pass over the
//! data.
//!
//! The recursion is sequential in time but independent across candidates, so candidates are taken
//! in groups of `LANES`: one pass over the samples advances every member of the group (the inner
//! loop over the group is what the compiler vectorises). Nothing here allocates. Large batches are
//! spread over threads by group; each candidate's sum is computed in the same order whatever the
//! thread count, so results never depend on it.

use crate::models::{Choudhury, He, Kano, ModelKind, Stenman, StictionModel};
use rayon::prelude::*;

/// Candidates advanced together in one pass over the data.
const LANES: usize = 8;

/// Stenman candidates per pass: more independent chains hide the latency of the select.
const STENMAN_LANES: usize = 16;

/// Work (samples x candidates) above which a batch is spread over threads.
const PARALLEL_WORK: usize = 1 << 21;

/// Build a model from already repaired parameter values (no validation: the hot path).
pub trait FromValues: StictionModel {
    /// The model with parameters `v`, in the model's parameter order.
    fn from_values(v: &[f64]) -> Self;
}

impl FromValues for Stenman {
    #[inline(always)]
    fn from_values(v: &[f64]) -> Self {
        Stenman { d: v[0] }
    }
}
impl FromValues for He {
    #[inline(always)]
    fn from_values(v: &[f64]) -> Self {
        He { fs: v[0], fd: v[1] }
    }
}
impl FromValues for Kano {
    #[inline(always)]
    fn from_values(v: &[f64]) -> Self {
        Kano { s: v[0], j: v[1] }
    }
}
impl FromValues for Choudhury {
    #[inline(always)]
    fn from_values(v: &[f64]) -> Self {
        Choudhury {
            s: v[0],
            j: v[1],
            velocity_deadzone: 0.0,
            span: (0.0, 100.0),
        }
    }
}

/// The objective for one data set: a command `op` and a measured valve position `mv`.
#[derive(Debug, Clone, Copy)]
pub struct Objective<'a> {
    /// The stiction model fitted.
    pub kind: ModelKind,
    /// The command (op).
    pub op: &'a [f64],
    /// The measured valve position (mv), in op's units.
    pub mv: &'a [f64],
}

impl<'a> Objective<'a> {
    /// The objective for `kind` on `op` and `mv`; panics when their lengths differ.
    pub fn new(kind: ModelKind, op: &'a [f64], mv: &'a [f64]) -> Self {
        assert_eq!(op.len(), mv.len(), "op and mv must have the same length");
        Self { kind, op, mv }
    }

    /// Parameters per candidate.
    pub fn dim(&self) -> usize {
        self.kind.dim()
    }

    /// Evaluate `candidates` (flat, `dim` values each, already repaired) into `out`.
    pub fn eval_batch(&self, candidates: &[f64], out: &mut [f64]) {
        match self.kind {
            ModelKind::Stenman => batch_sse_stenman(self.op, self.mv, candidates, out),
            ModelKind::He => batch_sse::<He>(self.op, self.mv, 2, candidates, out),
            ModelKind::Kano => batch_sse::<Kano>(self.op, self.mv, 2, candidates, out),
            ModelKind::Choudhury => batch_sse::<Choudhury>(self.op, self.mv, 2, candidates, out),
        }
    }

    /// Evaluate one candidate.
    pub fn eval(&self, candidate: &[f64]) -> f64 {
        let mut out = [0.0];
        self.eval_batch(candidate, &mut out);
        out[0]
    }
}

fn batch_sse<M: FromValues>(op: &[f64], mv: &[f64], dim: usize, cands: &[f64], out: &mut [f64]) {
    let count = out.len();
    assert_eq!(cands.len(), count * dim);
    if op.is_empty() {
        out.fill(0.0);
        return;
    }
    let model = |i: usize| M::from_values(&cands[i * dim..(i + 1) * dim]);
    let full = count / LANES * LANES;
    let group = |(g, out_g): (usize, &mut [f64])| {
        let models: [M; LANES] = std::array::from_fn(|l| model(g * LANES + l));
        out_g.copy_from_slice(&sse_lanes(&models, op, mv));
    };
    let (head, tail) = out.split_at_mut(full);
    if op.len() * count >= PARALLEL_WORK {
        head.par_chunks_mut(LANES).enumerate().for_each(group);
    } else {
        head.chunks_mut(LANES).enumerate().for_each(group);
    }
    // the remainder in narrower groups, so a batch of two costs a pass of two, not of eight
    for (k, pair) in tail.chunks_mut(2).enumerate() {
        let i = full + 2 * k;
        if pair.len() == 2 {
            pair.copy_from_slice(&sse_lanes(&[model(i), model(i + 1)], op, mv));
        } else {
            pair[0] = sse_lanes(&[model(i)], op, mv)[0];
        }
    }
}

/// One pass over the data advancing `N` models side by side.
#[inline]
fn sse_lanes<M: StictionModel, const N: usize>(
    models: &[M; N],
    op: &[f64],
    mv: &[f64],
) -> [f64; N] {
    let mut sums = [0.0f64; N];
    let mut states: [M::State; N] = std::array::from_fn(|l| {
        let (state, x0) = models[l].start(op[0]);
        let e = mv[0] - x0;
        sums[l] = e * e;
        state
    });
    for (&u, &y) in op[1..].iter().zip(&mv[1..]) {
        for l in 0..N {
            let e = y - models[l].step(&mut states[l], u);
            sums[l] += e * e;
        }
    }
    sums
}

/// Stenman gets its own kernel: a branch-free select the compiler turns into vector blends, built
/// twice (baseline and AVX2) and chosen at run time, so a plain `cargo build` is fast on modern
/// x86 without tying the binary to one CPU.
fn batch_sse_stenman(op: &[f64], mv: &[f64], ds: &[f64], out: &mut [f64]) {
    assert_eq!(ds.len(), out.len());
    if op.is_empty() {
        out.fill(0.0);
        return;
    }
    let count = out.len();
    let full = count / STENMAN_LANES * STENMAN_LANES;
    let work = |(g, out_g): (usize, &mut [f64])| {
        let d: [f64; STENMAN_LANES] = std::array::from_fn(|l| ds[g * STENMAN_LANES + l]);
        out_g.copy_from_slice(&stenman_lanes_dispatch(&d, op, mv));
    };
    let (head, tail) = out.split_at_mut(full);
    if op.len() * count >= PARALLEL_WORK {
        head.par_chunks_mut(STENMAN_LANES)
            .enumerate()
            .for_each(work);
    } else {
        head.chunks_mut(STENMAN_LANES).enumerate().for_each(work);
    }
    // the rest in groups of four (a local search step evaluates two), padded with the last
    for (g, out_g) in tail.chunks_mut(4).enumerate() {
        let first = full + g * 4;
        let d: [f64; 4] = std::array::from_fn(|l| ds[(first + l).min(count - 1)]);
        let sums = stenman_lanes_dispatch(&d, op, mv);
        out_g.copy_from_slice(&sums[..out_g.len()]);
    }
}

#[inline(always)]
fn stenman_lanes<const N: usize>(d: &[f64; N], op: &[f64], mv: &[f64]) -> [f64; N] {
    let e0 = mv[0] - op[0];
    let mut x = [op[0]; N];
    let mut sums = [e0 * e0; N];
    for (&u, &y) in op[1..].iter().zip(&mv[1..]) {
        for l in 0..N {
            let slips = (u - x[l]).abs() > d[l];
            x[l] = if slips { u } else { x[l] };
            let e = y - x[l];
            sums[l] += e * e;
        }
    }
    sums
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn stenman_lanes_avx2<const N: usize>(d: &[f64; N], op: &[f64], mv: &[f64]) -> [f64; N] {
    stenman_lanes(d, op, mv)
}

fn stenman_lanes_dispatch<const N: usize>(d: &[f64; N], op: &[f64], mv: &[f64]) -> [f64; N] {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            return unsafe { stenman_lanes_avx2(d, op, mv) };
        }
    }
    stenman_lanes(d, op, mv)
}
