//! The plant-window suite: windows as a plant historian keeps them, and what the verdict's
//! statistics read of them.

use stiction_core::diagnose::{diagnose, Statistic};
use stiction_lab::catalogue::{self, LoopClass, Set, Suite, Truth};
use stiction_lab::catalogue_loop;

#[test]
fn plant_windows_are_ten_second_means_with_a_visibility_for_sticky_valves() {
    let sticky = catalogue::generate(Suite::Plant, Set::Calibration, 0).unwrap();
    assert_eq!(sticky.class, LoopClass::StenmanValve);
    assert_eq!((sticky.ts(), sticky.data.pv.len()), (10.0, 750));
    assert!(sticky.setup.historian.average);
    assert!(sticky.slips >= 1);
    assert!(sticky.visibility.is_some_and(|v| v >= 0.0));
    // a healthy valve has no visibility, and a band of at most a quarter per cent
    let (start, _) = catalogue::plan(Suite::Plant)
        .iter()
        .take_while(|(c, _)| *c != LoopClass::Healthy)
        .fold((0, 0), |(s, _), (_, n)| (s + n, 0));
    let healthy = catalogue::generate(Suite::Plant, Set::Calibration, start).unwrap();
    assert_eq!(healthy.truth, Truth::NotSticky);
    assert!(healthy.visibility.is_none());
    assert!(healthy.setup.model.values()[0] <= 0.25);
}

#[test]
fn a_visible_sticky_windows_sticks_are_read() {
    // the first sticky plant windows whose slips move PV by 6 noise standard deviations: the
    // stick-slip family finds PV's steps ending sticks there, and the model moves towards a
    // sticky valve
    let mut found = 0;
    for i in 0..60 {
        let l = catalogue::generate(Suite::Plant, Set::Calibration, i).unwrap();
        if !l.visibility.is_some_and(|v| v >= 6.0) || l.integrating {
            continue;
        }
        let d = diagnose(&catalogue_loop::record(&l), &catalogue_loop::request(&l)).unwrap();
        let read = d.statistics.as_ref().unwrap();
        let share = read
            .contributions
            .iter()
            .find(|c| c.statistic == Statistic::StickShare)
            .unwrap();
        if share.value.is_some_and(|v| v > 0.0) {
            found += 1;
        }
        if found == 3 {
            break;
        }
    }
    assert_eq!(
        found, 3,
        "sticks found in fewer than 3 visible sticky windows"
    );
}
