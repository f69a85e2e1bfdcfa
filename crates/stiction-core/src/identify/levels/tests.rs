//! The levels test against simulated valves and the walk in order.

use super::walk::{walk_chunks, Piece};
use super::*;
use crate::models::{Model, Stenman};
use crate::rng::{gaussian, seeded};

/// A first-order process driven by `valve`, plus white noise.
fn process(valve: &[f64], noise: f64, seed: u64) -> Vec<f64> {
    let mut rng = seeded(seed);
    let mut x = valve[0];
    valve
        .iter()
        .map(|&v| {
            let y = x + noise * gaussian(&mut rng);
            x += 0.1 * (v - x);
            y
        })
        .collect()
}

fn ramp_op(n: usize) -> Vec<f64> {
    (0..n)
        .map(|t| 50.0 + 8.0 * (t as f64 * 0.013).sin() + 0.3 * (t as f64 * 0.71).sin())
        .collect()
}

/// The walk in order of the band, in one piece: the reference the chunked walk must equal.
fn walk_in_order(fit: &LevelsFit, op: &[f64], range: f64) -> (Option<Piece>, usize) {
    let mut scratch = fit.scratch();
    let mut valve = vec![0.0; op.len()];
    let (mut best, mut count) = (None::<Piece>, 0);
    let whole = (0.0, range * (1.0 + 1e-9));
    stenman_walk(
        op,
        op[0],
        (range * 1e-4, range),
        whole,
        &mut valve,
        |cell, mv| {
            count += 1;
            let s = fit.sse(mv, &mut scratch);
            if best.is_none_or(|b| s < b.0) {
                best = Some((s, cell));
            }
        },
    );
    (best, count)
}

#[test]
fn the_chunked_walk_equals_the_walk_in_order() {
    let op = ramp_op(600);
    let range = 16.6;
    for (d, seed) in [(0.0, 1), (0.4, 2), (2.0, 3), (6.0, 4)] {
        let valve = if d > 0.0 {
            Model::Stenman(Stenman::new(d).unwrap()).simulate(&op)
        } else {
            op.clone()
        };
        let fit = LevelsFit::new(&process(&valve, 0.05, seed), &op, false);
        let (a, b) = (
            walk_chunks(&fit, &op, range),
            walk_in_order(&fit, &op, range),
        );
        assert_eq!(a, b, "d = {d}");
    }
}

#[test]
fn a_sticky_valve_is_found_and_op_is_not_beaten_by_chance() {
    let op = ramp_op(800);
    let sticky = Model::Stenman(Stenman::new(2.0).unwrap()).simulate(&op);
    let pv = process(&sticky, 0.05, 7);
    let found = levels_walk(&op, &pv, false).unwrap();
    assert!(found.ratio > 100.0, "ratio {}", found.ratio);
    assert!((found.band - 2.0).abs() < 0.5, "band {}", found.band);
    let healthy = process(&op, 0.05, 7);
    let none = levels_walk(&op, &healthy, false).unwrap();
    assert!(none.ratio < 20.0, "ratio {}", none.ratio);
    assert!(none.trajectories > 10);
}

#[test]
fn a_valve_whose_slips_land_short_of_op_is_fitted_as_one() {
    // He's valve, fs = 3, fd = 0.75: the refinement after the Stenman walk picks it
    let op = ramp_op(800);
    let he = Model::He(He::new(3.0, 0.75).unwrap()).simulate_from(&op, Some(op[0]));
    let pv = process(&he, 0.05, 11);
    let w = levels_walk(&op, &pv, false).unwrap();
    assert!(w.slip_short > 0.0 && w.slip_short < w.band, "{w:?}");
    assert!((w.band - 3.0).abs() < 0.75, "{w:?}");
    assert!(w.ratio > 20.0, "{w:?}");
}

#[test]
fn a_healthy_level_loop_with_little_noise_is_not_a_sticky_one() {
    // PV integrates the valve: the running sum's column is large beside what is left of PV
    let op = ramp_op(2000);
    let mut rng = seeded(5);
    let mut level = 40.0;
    let pv: Vec<f64> = op
        .iter()
        .map(|&u| {
            let y = level + 0.01 * gaussian(&mut rng);
            level += 0.02 * (u - 50.0);
            y
        })
        .collect();
    let w = levels_walk(&op, &pv, true).unwrap();
    assert!(w.ratio.is_finite() && w.ratio < 20.0, "ratio {}", w.ratio);
}

#[test]
fn short_constant_or_broken_records_give_none() {
    assert!(levels_walk(&[1.0; 50], &[1.0; 50], false).is_none());
    assert!(levels_walk(&[1.0; 300], &[2.0; 300], false).is_none());
    let mut op = ramp_op(300);
    op[5] = f64::NAN;
    assert!(levels_walk(&op, &ramp_op(300), false).is_none());
}
