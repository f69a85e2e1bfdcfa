//! Seeded draws for the catalogue's parameters (one generator per loop, so a loop's parameters do
//! not depend on which other loops are generated, nor on the thread that generates it).

use rand::RngExt;
use stiction_core::rng::{seeded, Rng};

/// SplitMix64's finaliser: spreads consecutive integers into unrelated seeds.
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

pub struct Draw(Rng);

impl Draw {
    pub fn new(seed: u64) -> Self {
        Self(seeded(seed))
    }

    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.0.random::<f64>()
    }

    /// Uniform in the logarithm: as many bands between 0.5 and 1 % as between 2.5 and 5 %.
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (self.uniform(lo.ln(), hi.ln())).exp()
    }

    pub fn chance(&mut self, p: f64) -> bool {
        self.0.random::<f64>() < p
    }

    pub fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        let i = (self.0.random::<f64>() * items.len() as f64) as usize;
        items[i.min(items.len() - 1)]
    }

    pub fn weighted<T: Copy>(&mut self, items: &[(T, f64)]) -> T {
        let total: f64 = items.iter().map(|i| i.1).sum();
        let mut x = self.uniform(0.0, total);
        for &(item, w) in items {
            if x < w {
                return item;
            }
            x -= w;
        }
        items[items.len() - 1].0
    }

    /// A seed for a signal or the loop's noise.
    pub fn seed(&mut self) -> u64 {
        self.0.random::<u64>()
    }
}
