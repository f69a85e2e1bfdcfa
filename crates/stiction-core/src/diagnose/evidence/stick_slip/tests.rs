use super::*;

fn settings(unrecorded: &[bool]) -> Settings<'_> {
    Settings {
        pv_noise: 0.01,
        op_noise: 0.01,
        pv_quantum: None,
        unrecorded,
        pv_linear: None,
        rate: None,
        gain: Some(1.0),
        dead_samples: 2,
        response_samples: 3,
    }
}

/// OP ramps 1 unit over 20 samples while PV holds, then PV steps up: repeated 5 times.
fn stick_slip_record() -> (Vec<f64>, Vec<f64>) {
    sticks(5)
}

/// OP ramps 1 unit over 20 samples while PV holds, then PV steps up: repeated `n` times.
fn sticks(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut op = Vec::new();
    let mut pv = Vec::new();
    let mut level = 0.0;
    for _ in 0..n {
        for k in 0..20 {
            op.push(level + k as f64 / 20.0);
            pv.push(level);
        }
        level += 1.0;
    }
    (op, pv)
}

#[test]
fn stick_then_slip_is_counted_with_its_travel() {
    let (op, pv) = stick_slip_record();
    let unrecorded = vec![false; op.len()];
    let e = episodes(&op, &pv, &settings(&unrecorded));
    assert_eq!(e.episodes, 4, "{e:?}");
    // OP travels 0.95 in each stick
    let t = e.median_travel.unwrap();
    assert!((t - 0.95).abs() < 0.1, "{t}");
    assert!(e.stuck_share > 0.7);
}

#[test]
fn many_episodes_holding_most_of_the_travel_decide_a_few_only_corroborate() {
    let vote = |n: usize| {
        let (op, pv) = sticks(n);
        let unrecorded = vec![false; op.len()];
        let e = episodes(&op, &pv, &settings(&unrecorded));
        assert!(e.stuck_share >= DECISIVE_SHARE, "{e:?}");
        (e.episodes, ballot(&e, op.len()))
    };
    let (few, (v, strength, _)) = vote(8);
    assert!(few < DECISIVE_EPISODES);
    assert_eq!(v, Vote::Stiction);
    assert_eq!(strength, STICTION_STRENGTH);
    let (many, (v, strength, why)) = vote(DECISIVE_EPISODES + 2);
    assert!(many >= DECISIVE_EPISODES, "{many}");
    assert_eq!(v, Vote::Stiction);
    assert_eq!(strength, DECISIVE_STRENGTH);
    assert!(why.contains("healthy loops do not give it"), "{why}");
}

#[test]
fn pv_that_was_not_recorded_is_no_episode() {
    let (op, pv) = stick_slip_record();
    let unrecorded = vec![true; op.len()];
    let e = episodes(&op, &pv, &settings(&unrecorded));
    assert_eq!(e.episodes, 0);
    assert_eq!(e.skipped_unrecorded, 4);
}

#[test]
fn a_pv_move_against_op_is_no_episode() {
    let (op, pv) = stick_slip_record();
    let unrecorded = vec![false; op.len()];
    let s = Settings {
        gain: Some(-1.0),
        ..settings(&unrecorded)
    };
    let e = episodes(&op, &pv, &s);
    assert_eq!(e.episodes, 0);
    assert_eq!(e.skipped_direction, 4);
}
