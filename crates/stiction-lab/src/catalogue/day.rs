//! A plant's day: loops drawn as the plant windows' are (the same processes, tunings and
//! operators), recorded at 1 s for as long as asked, one sticky valve in ten. For timing
//! `diagnose` at plant scale and its cost against the record's length.

use super::draw::{mix, Draw};
use super::plant::finish;
use super::windows::{build_shaped, Shape};
use super::{BenchmarkLoop, LoopClass, Set, Suite, MAX_ATTEMPTS};

const SEED: u64 = 20_261_203;

/// The sticky classes, taken in turn by every tenth loop.
const STICKY: [LoopClass; 3] = [
    LoopClass::StenmanValve,
    LoopClass::KanoValve,
    LoopClass::HeValve,
];

/// The healthy classes, taken in turn by the others.
const HEALTHY: [LoopClass; 6] = [
    LoopClass::Healthy,
    LoopClass::NearUnstable,
    LoopClass::ExternalOscillation,
    LoopClass::LoadSteps,
    LoopClass::FeedForward,
    LoopClass::SlowLongDelay,
];

/// The class of a day's loop `index`: every tenth sticky.
pub fn day_class(index: usize) -> LoopClass {
    if index.is_multiple_of(10) {
        STICKY[(index / 10) % STICKY.len()]
    } else {
        HEALTHY[(index - index / 10 - 1) % HEALTHY.len()]
    }
}

/// Loop `index` of the day, `samples` 1-s values long (the same draw at every length, so a
/// loop's cost can be read against its length); a sticky valve that never slips is drawn again.
pub fn plant_day(index: usize, samples: usize) -> BenchmarkLoop {
    let class = day_class(index);
    let shape = Shape {
        samples,
        ts: 1.0,
        average: false,
    };
    let seed = mix(SEED.wrapping_add(index as u64));
    let mut kept = None;
    for attempt in 0..MAX_ATTEMPTS {
        let mut draw = Draw::new(mix(seed ^ attempt.wrapping_mul(0x5851_F42D_4C95_7F2D)));
        let l = finish(class, build_shaped(class, &mut draw, shape), attempt + 1);
        let slipped = l.slips >= 1 || class.truth() != super::Truth::Sticky;
        kept = Some(l);
        if slipped {
            break;
        }
    }
    let mut l = kept.expect("at least one attempt");
    l.id = format!("day-{index:04}");
    l.suite = Suite::Plant;
    l.set = Set::Extra(0);
    l
}
