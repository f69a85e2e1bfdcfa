//! The lab's tests, one binary: the catalogue itself, and the diagnosis on catalogue loops (the
//! cases found in the studies, each a loop id). The core's own tests use the public simulation
//! only. Run one part with a filter: `cargo test -p stiction-lab --test all model`.

mod catalogue;
mod diagnose;
