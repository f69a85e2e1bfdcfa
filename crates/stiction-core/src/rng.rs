//! Seeded, portable random numbers (Xoshiro256++; never a thread- or platform-dependent generator).

use rand::{RngExt, SeedableRng};
pub use rand_xoshiro::Xoshiro256PlusPlus as Rng;

/// The generator seeded with `seed`: the same seed gives the same stream on every platform.
pub fn seeded(seed: u64) -> Rng {
    Rng::seed_from_u64(seed)
}

/// A standard normal draw (Box-Muller; one of the pair is used so the stream stays simple).
pub fn gaussian(rng: &mut Rng) -> f64 {
    loop {
        let u1: f64 = rng.random();
        if u1 > f64::MIN_POSITIVE {
            let u2: f64 = rng.random();
            return (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
        }
    }
}
