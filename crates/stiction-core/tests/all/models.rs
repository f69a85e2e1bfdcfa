//! Model conformance: laws between models, hand-computed sequences per regime, Stenman properties.

use proptest::prelude::*;
use stiction_core::models::*;

fn run<M: StictionModel>(m: M, u: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; u.len()];
    m.simulate_into(u, &mut x);
    x
}

/// A ramp up with a pause, then down: exercises start, move, stop, same-direction restart and reversal.
const RAMP: [f64; 16] = [
    50., 51., 52., 53., 54., 55., 55., 56., 57., 58., 57., 56., 55., 54., 53., 52.,
];

fn command() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-5.0f64..5.0, 2..300).prop_map(|steps| {
        let mut u = 50.0;
        steps
            .into_iter()
            .map(|s| {
                u = (u + s).clamp(0.0, 100.0);
                u
            })
            .collect()
    })
}

proptest! {
    #[test]
    fn stenman_equals_he_with_zero_kinetic_band(u in command(), d in 0.0f64..8.0) {
        let a = run(Stenman::new(d).unwrap(), &u);
        let b = run(He::new(d, 0.0).unwrap(), &u);
        prop_assert_eq!(a, b); // bit for bit
    }

    #[test]
    fn stenman_output_is_always_an_earlier_command(u in command(), d in 0.0f64..8.0) {
        let x = run(Stenman::new(d).unwrap(), &u);
        for t in 0..u.len() {
            prop_assert!(u[..=t].contains(&x[t]), "x[{}] = {} is no earlier command", t, x[t]);
        }
    }

    #[test]
    fn stenman_sticks_exactly_while_inside_the_band(u in command(), d in 0.0f64..8.0) {
        let x = run(Stenman::new(d).unwrap(), &u);
        for t in 1..u.len() {
            if (u[t] - x[t - 1]).abs() <= d {
                prop_assert_eq!(x[t], x[t - 1]);
            } else {
                prop_assert_eq!(x[t], u[t]);
            }
        }
    }

    #[test]
    fn an_ideal_valve_follows_the_command(u in command()) {
        prop_assert_eq!(run(Stenman::new(0.0).unwrap(), &u), u.clone());
        prop_assert_eq!(run(He::new(0.0, 0.0).unwrap(), &u), u.clone());
        prop_assert_eq!(run(Kano::new(0.0, 0.0).unwrap(), &u), u.clone());
    }

    #[test]
    fn simulate_and_sse_agree_for_every_model(u in command(), a in 0.0f64..6.0, b in 0.0f64..6.0) {
        let y: Vec<f64> = u.iter().map(|v| v + 0.3).collect();
        let (fs, fd) = if a >= b { (a, b) } else { (b, a) };
        for m in [
            Model::Stenman(Stenman::new(a).unwrap()),
            Model::He(He::new(fs, fd).unwrap()),
            Model::Kano(Kano::new(a, b).unwrap()),
            Model::Choudhury(Choudhury::new(a, b).unwrap()),
        ] {
            let x = m.simulate(&u);
            let direct: f64 = x.iter().zip(&y).map(|(x, y)| (y - x) * (y - x)).sum();
            let sse = m.sse(&u, &y);
            prop_assert!((direct - sse).abs() <= 1e-9 * direct.max(1.0));
            // stepping one sample at a time gives the same sequence
            let (mut st, x0) = m.start(u[0]);
            let mut stepped = vec![x0];
            for &v in &u[1..] {
                stepped.push(m.step(&mut st, v));
            }
            prop_assert_eq!(stepped, x);
        }
    }
}

#[test]
fn kano_pure_deadband_j0() {
    // S = 2, J = 0: no slip jump; the moving valve lags the command by (S-J)/2 = 1
    let x = run(Kano::new(2.0, 0.0).unwrap(), &RAMP);
    let want = [
        50., 50., 50., 52., 53., 54., 54., 55., 56., 57., 57., 57., 56., 55., 54., 53.,
    ];
    assert_eq!(x, want);
}

#[test]
fn kano_undershoot_j_below_s() {
    // S = 2, J = 1: lag 0.5; after the pause at 55 the valve sticks until the command passes 55 + J
    let x = run(Kano::new(2.0, 1.0).unwrap(), &RAMP);
    let want = [
        50., 50., 50., 52.5, 53.5, 54.5, 54.5, 54.5, 56.5, 57.5, 57.5, 57.5, 55.5, 54.5, 53.5, 52.5,
    ];
    assert_eq!(x, want);
}

#[test]
fn kano_no_offset_j_equals_s() {
    // S = J = 2: the moving valve follows the command exactly
    let x = run(Kano::new(2.0, 2.0).unwrap(), &RAMP);
    let want = [
        50., 50., 50., 53., 54., 55., 55., 55., 55., 58., 58., 58., 55., 54., 53., 52.,
    ];
    assert_eq!(x, want);
}

#[test]
fn kano_overshoot_j_above_s() {
    // S = 2, J = 3: the moving valve leads the command by 0.5; after the pause it stays stuck
    // (the command never gets J past the rest point) until the reversal breaks through S
    let x = run(Kano::new(2.0, 3.0).unwrap(), &RAMP);
    let want = [
        50., 50., 50., 53.5, 54.5, 55.5, 55.5, 55.5, 55.5, 55.5, 55.5, 55.5, 55.5, 55.5, 55.5, 51.5,
    ];
    assert_eq!(x, want);
}

#[test]
fn choudhury_regimes() {
    // J = 0: unlike Kano, the zero-velocity sample at 55 counts as a stop and the next move as a
    // reversal, so the valve holds one sample longer
    let cases: [((f64, f64), [f64; 16]); 4] = [
        (
            (2.0, 0.0),
            [
                50., 50., 50., 52., 53., 54., 54., 54., 56., 57., 57., 57., 56., 55., 54., 53.,
            ],
        ),
        (
            (2.0, 1.0),
            [
                50., 50., 50., 52.5, 53.5, 54.5, 54.5, 54.5, 56.5, 57.5, 57.5, 57.5, 55.5, 54.5,
                53.5, 52.5,
            ],
        ),
        (
            (2.0, 2.0),
            [
                50., 50., 50., 53., 54., 55., 55., 55., 55., 58., 58., 58., 55., 54., 53., 52.,
            ],
        ),
        (
            (2.0, 3.0),
            [
                50., 50., 50., 53.5, 54.5, 55.5, 55.5, 55.5, 55.5, 55.5, 55.5, 55.5, 55.5, 53.5,
                52.5, 51.5,
            ],
        ),
    ];
    for ((s, j), want) in cases {
        assert_eq!(
            run(Choudhury::new(s, j).unwrap(), &RAMP),
            want,
            "S = {s}, J = {j}"
        );
    }
}

#[test]
fn choudhury_velocity_deadzone_ignores_jitter() {
    // a command that drifts up by 0.1 a sample under jitter of ±0.1: the sample-to-sample moves
    // alternate -0.1 and +0.3, so without a dead zone every sample is a reversal and the valve
    // never moves; with a dead zone above 0.3 the jitter is no movement and the drift shows
    let u: Vec<f64> = (0..40)
        .map(|k| 50.0 + 0.1 * k as f64 + if k % 2 == 0 { 0.1 } else { -0.1 })
        .collect();
    let mut m = Choudhury::new(2.0, 1.0).unwrap();
    let stuck = run(m, &u);
    m.velocity_deadzone = 0.35;
    let moving = run(m, &u);
    assert!(
        stuck.iter().all(|&x| x == stuck[0]),
        "jitter keeps the published model stuck"
    );
    assert!(
        moving[39] > 53.0,
        "with a dead zone the valve follows the ramp: {}",
        moving[39]
    );
}

#[test]
fn kano_clamps_the_command_to_the_span() {
    let x = run(Kano::new(0.0, 0.0).unwrap(), &[50.0, 120.0, -5.0]);
    assert_eq!(x, [50.0, 100.0, 0.0]);
}

#[test]
fn invalid_parameters_are_refused_with_the_reason() {
    assert!(Stenman::new(-0.1).is_err());
    assert!(Stenman::new(f64::NAN).is_err());
    let e = He::new(1.0, 2.0).unwrap_err().to_string();
    assert!(e.contains("must not exceed"), "{e}");
    assert!(Kano::new(1.0, -1.0).is_err());
    let e = ModelKind::Kano.param_index("d").unwrap_err().to_string();
    assert!(e.contains("S, J"), "{e}");
    assert!("bogus".parse::<ModelKind>().is_err());
    assert_eq!("KANO".parse::<ModelKind>().unwrap(), ModelKind::Kano);
}
