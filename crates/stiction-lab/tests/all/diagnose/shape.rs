//! The shape family on a catalogue loop: a compressed PV.

use super::*;
use stiction_core::diagnose::Verdict;

#[test]
fn a_compressed_pvs_straight_lines_are_not_read_as_a_valves_shape() {
    // routine-b-0380 of the plant benchmark: a healthy level loop whose historian stores PV with
    // compression (straight lines between stored points in 99 % of the samples); the shape
    // indices read the lines' kinks as a valve's
    let d = judge_catalogue("routine-b-0380");
    let shape = family_of(&d, Family::Shape);
    // a shape that points to a valve is not read there: none, or one that points away
    assert!(shape.value.is_none_or(|v| v <= 0.0), "{shape:?}");
    if shape.value.is_none() {
        assert!(
            shape.note.contains("historian compression"),
            "{}",
            shape.note
        );
    }
    assert_ne!(d.verdict, Verdict::Stiction, "{:?}", d.reasons);
}
