//! Two output-error simulations side by side: the exact walk fits every valve trajectory under
//! each of a few structures, and each simulation is a recursion whose every step waits for the one
//! before, so one alone leaves the processor idle most of the time. Run in pairs, bit for bit what
//! `simulate_n` gives each (three side by side, or one kernel generic in their number, measured
//! 2-3 % slower on the batch: the registers spill).

use super::simulate::Run;

/// A run's state: the recursion's constants, its lagged inputs, its target and its last outputs.
struct Lane<'a> {
    a0: f64,
    a1: f64,
    p1: f64,
    p2: f64,
    b0: f64,
    b1: f64,
    c: f64,
    m0: &'a [f64],
    m1: &'a [f64],
    target: &'a [f64],
    y1: f64,
    y2: f64,
    bound: f64,
}

impl<'a> Lane<'a> {
    /// The same constants and starting outputs as `simulate_n` with the run's orders (a
    /// missing order's coefficient is 0, which adds a zero product: the same sums).
    fn new(r: &Run<'a>, t0: usize, len: usize) -> Self {
        let a0 = if r.na > 0 { r.a[0] } else { 0.0 };
        let a1 = if r.na > 1 { r.a[1] } else { 0.0 };
        let m0 = &r.mv[t0 - r.nk..t0 - r.nk + len];
        let (m1, b1) = if r.nb > 1 {
            (&r.mv[t0 - r.nk - 1..t0 - r.nk - 1 + len], r.b[1])
        } else {
            (m0, 0.0)
        };
        Self {
            a0,
            a1,
            p1: a0 * a0 + a1,
            p2: a0 * a1,
            b0: r.b[0],
            b1,
            c: r.c,
            m0,
            m1,
            target: &r.y[t0..t0 + len],
            y1: if r.na > 0 { r.y[t0 - 1] } else { 0.0 },
            y2: if r.na > 1 { r.y[t0 - 2] } else { 0.0 },
            bound: r.bound,
        }
    }
}

/// Two output-error simulations from sample `t0` on, interleaved: each is a recursion whose
/// every step waits for the one before, so one alone leaves the processor idle most of the time.
/// Each returns what `simulate_n` returns for it, bit for bit (the same products and sums in
/// the same order; a run over its bound at a check every 64 samples is infinite). Both runs'
/// outputs must be equally long.
pub(super) fn simulate_pair(runs: [&Run; 2], t0: usize) -> [f64; 2] {
    pair::<false>(runs, t0, [&mut [], &mut []])
}

/// As [`simulate_pair`], also writing each run's errors (output less simulation, from `t0` on)
/// into `errors`, as `simulate_n`'s simulated output gives them.
pub(super) fn simulate_pair_errors(
    runs: [&Run; 2],
    t0: usize,
    errors: [&mut Vec<f64>; 2],
) -> [f64; 2] {
    let len = runs[0].y.len() - t0;
    let [ea, eb] = errors;
    ea.resize(len, 0.0);
    eb.resize(len, 0.0);
    pair::<true>(runs, t0, [ea, eb])
}

fn pair<const ERRORS: bool>(runs: [&Run; 2], t0: usize, errors: [&mut [f64]; 2]) -> [f64; 2] {
    let [ea, eb] = errors;
    let len = runs[0].y.len() - t0;
    debug_assert_eq!(runs[1].y.len() - t0, len);
    let (la, lb) = (Lane::new(runs[0], t0, len), Lane::new(runs[1], t0, len));
    // the lanes' constants and state in locals, so both recursions stay in registers
    let (aa0, aa1, ap1, ap2, ab0, ab1, ac) = (la.a0, la.a1, la.p1, la.p2, la.b0, la.b1, la.c);
    let (ba0, ba1, bp1, bp2, bb0, bb1, bc) = (lb.a0, lb.a1, lb.p1, lb.p2, lb.b0, lb.b1, lb.c);
    let (am0, am1, at) = (&la.m0[..len], &la.m1[..len], &la.target[..len]);
    let (bm0, bm1, bt) = (&lb.m0[..len], &lb.m1[..len], &lb.target[..len]);
    let (mut ay1, mut ay2, mut asse) = (la.y1, la.y2, 0.0f64);
    let (mut by1, mut by2, mut bsse) = (lb.y1, lb.y2, 0.0f64);
    let (mut aover, mut bover) = (false, false);
    let mut k = 0;
    while k + 1 < len {
        let (au0, au1) = (
            (ac + ab0 * am0[k]) + ab1 * am1[k],
            (ac + ab0 * am0[k + 1]) + ab1 * am1[k + 1],
        );
        let (bu0, bu1) = (
            (bc + bb0 * bm0[k]) + bb1 * bm1[k],
            (bc + bb0 * bm0[k + 1]) + bb1 * bm1[k + 1],
        );
        let av0 = (au0 + aa1 * ay2) + aa0 * ay1;
        let av1 = (au1 + aa0 * au0 + ap2 * ay2) + ap1 * ay1;
        let bv0 = (bu0 + ba1 * by2) + ba0 * by1;
        let bv1 = (bu1 + ba0 * bu0 + bp2 * by2) + bp1 * by1;
        let (ae0, ae1) = (at[k] - av0, at[k + 1] - av1);
        let (be0, be1) = (bt[k] - bv0, bt[k + 1] - bv1);
        asse += ae0 * ae0 + ae1 * ae1;
        bsse += be0 * be0 + be1 * be1;
        if ERRORS {
            (ea[k], ea[k + 1], eb[k], eb[k + 1]) = (ae0, ae1, be0, be1);
        }
        (ay2, ay1) = (av0, av1);
        (by2, by1) = (bv0, bv1);
        k += 2;
        if k % 64 == 0 {
            aover |= asse > la.bound;
            bover |= bsse > lb.bound;
            if aover && bover {
                return [f64::INFINITY; 2];
            }
        }
    }
    if k < len {
        let av = (((ac + ab0 * am0[k]) + ab1 * am1[k]) + aa1 * ay2) + aa0 * ay1;
        let bv = (((bc + bb0 * bm0[k]) + bb1 * bm1[k]) + ba1 * by2) + ba0 * by1;
        let (ae, be) = (at[k] - av, bt[k] - bv);
        asse += ae * ae;
        bsse += be * be;
        if ERRORS {
            (ea[k], eb[k]) = (ae, be);
        }
    }
    let result = |sse: f64, over: bool| {
        if over || !sse.is_finite() {
            f64::INFINITY
        } else {
            sse
        }
    };
    [result(asse, aover), result(bsse, bover)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::simulate::{simulate_run, simulate_sse};
    use crate::identify::Structure;
    use proptest::prelude::*;

    fn run<'a>(
        y: &'a [f64],
        mv: &'a [f64],
        s: (usize, usize, usize),
        c: [f64; 5],
        bound: f64,
    ) -> Run<'a> {
        Run {
            y,
            mv,
            nk: s.2,
            na: s.0,
            nb: s.1,
            a: [c[0], c[1]],
            b: [c[2], c[3]],
            c: c[4],
            bound,
        }
    }

    proptest! {
        /// Law: each run of a pair gives what it gives alone, bit for bit, with or without a bound
        /// that stops it (before, at or after the last check), and for diverging runs.
        #[test]
        fn a_pair_gives_what_each_run_gives_alone(
            seed in 0u64..1_000_000,
            n in 40usize..300,
            orders in prop::array::uniform2((0usize..=2, 1usize..=2, 1usize..=3)),
            coef in prop::array::uniform2(prop::array::uniform5(-1.2f64..1.2)),
            share in prop::array::uniform2(
                prop::sample::select(vec![0.0, 0.3, 0.9, 1.0, 2.0, f64::INFINITY]),
            ),
        ) {
            let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            let y: Vec<f64> = (0..n).map(|_| next()).collect();
            let mv: Vec<f64> = (0..n).map(|_| 3.0 * next()).collect();
            let t0 = 5;
            let run_i = |i: usize, bound: f64| run(&y, &mv, orders[i], coef[i], bound);
            let alone = |i: usize, bound: f64| simulate_run(&run_i(i, bound), t0, None);
            // bounds as shares of each run's whole error
            let bounds: Vec<f64> = (0..2).map(|i| {
                let whole = alone(i, f64::INFINITY);
                if share[i].is_infinite() { f64::INFINITY } else { share[i] * whole }
            }).collect();
            let runs = [run_i(0, bounds[0]), run_i(1, bounds[1])];
            let pair = simulate_pair([&runs[0], &runs[1]], t0);
            for i in 0..2 {
                prop_assert_eq!(pair[i].to_bits(), alone(i, bounds[i]).to_bits(), "run {}", i);
            }
            // unbounded, with the errors written: what a simulation alone gives and simulates
            let free = [run_i(0, f64::INFINITY), run_i(1, f64::INFINITY)];
            let (mut ea, mut eb) = (Vec::new(), Vec::new());
            let sses = simulate_pair_errors([&free[0], &free[1]], t0, [&mut ea, &mut eb]);
            for (i, errors) in [ea, eb].iter().enumerate() {
                let (na, nb, nk) = orders[i];
                let s = Structure { integrating: false, na, nb, nk };
                let mut sim = Vec::new();
                let (a, b, c) = (&coef[i][..na], &coef[i][2..2 + nb], coef[i][4]);
                let sse = simulate_sse(&y, &mv, s, a, b, c, t0, Some(&mut sim));
                prop_assert_eq!(sses[i].to_bits(), sse.to_bits(), "run {}", i);
                let alone: Vec<u64> =
                    y[t0..].iter().zip(&sim[t0..]).map(|(a, b)| (a - b).to_bits()).collect();
                let paired: Vec<u64> = errors.iter().map(|e| e.to_bits()).collect();
                prop_assert_eq!(paired, alone, "run {}", i);
            }
        }
    }
}
