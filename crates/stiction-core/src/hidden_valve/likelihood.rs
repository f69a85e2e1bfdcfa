//! The two likelihoods: PV given OP through a valve that follows OP (a Kalman filter), and
//! through a Stenman valve whose position the record does not hold (a particle filter over the
//! valve, each particle's loop state filtered exactly: Rao-Blackwellised).

use super::model::{innovation, log_density, predict, update, Gains, LoopModel, STATES};
use crate::rng::seeded;
use rand::RngExt;
use rand_distr::StandardNormal;

/// What both likelihoods read: the record, its sampling time and the valve's travel limits.
#[derive(Debug, Clone, Copy)]
pub struct Record<'a> {
    /// Controller output, one value per sample.
    pub op: &'a [f64],
    /// Process variable, one value per sample.
    pub pv: &'a [f64],
    /// Sampling time, s.
    pub ts: f64,
    /// The valve's travel limits in OP units (a valve cannot pass them), if any.
    pub limits: Option<(f64, f64)>,
}

impl Record<'_> {
    fn clip(&self, u: f64) -> f64 {
        match self.limits {
            Some((lo, hi)) => u.clamp(lo, hi),
            None => u,
        }
    }

    /// The state at the first sample and its variances: the valve at the first OP, the process
    /// at rest there, the loads unknown (a variance of PV's spread).
    fn start(&self, m: &LoopModel) -> ([f64; STATES], [f64; STATES]) {
        let u0 = self.clip(self.op[0]);
        let x0 = if m.integrating { 0.0 } else { m.gain * u0 };
        let spread = variance(self.pv).max(m.noise * m.noise) + 1e-12;
        (
            [u0, x0, self.pv[0] - x0, 0.0, 0.0],
            [1e-9, 1e-9, spread, spread, spread],
        )
    }
}

fn variance(x: &[f64]) -> f64 {
    let n = x.len().max(1) as f64;
    let mean = x.iter().sum::<f64>() / n;
    x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n
}

/// Log-likelihood of PV when the valve follows OP (through its lag; OP's unrecorded moves
/// between the samples enter as input noise).
pub fn healthy_log_likelihood(rec: &Record, m: &LoopModel) -> f64 {
    let mat = m.matrices(rec.ts);
    let (mut mean, p0) = rec.start(m);
    let gains = Gains::of(&mat, p0, rec.pv.len());
    let k = mat.delay_samples;
    let mut ll = 0.0;
    for t in 0..rec.pv.len() {
        let u = rec.clip(rec.op[t.saturating_sub(k)]);
        predict(&mat.f, mat.b[0], &mut mean, u);
        let (g, s, log_s) = gains.at(t);
        let e = innovation(&mean, rec.pv[t]);
        ll += log_density(e, s, log_s);
        update(&mut mean, g, e);
    }
    ll
}

/// The particle filter's settings.
#[derive(Debug, Clone, Copy)]
pub struct Particles {
    /// Particles (valve trajectories) carried.
    pub count: usize,
    /// Seed of the draws: the same seed gives the same likelihood.
    pub seed: u64,
}

impl Default for Particles {
    fn default() -> Self {
        Self {
            count: 200,
            seed: 1,
        }
    }
}

/// The hidden valve: it holds until OP leaves the band, then slips to `short` before OP (OP
/// units; 0: Stenman's valve, which lands on OP; He's valve with `fs = band`, `fd = short`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slip {
    /// The band OP must leave for the valve to move, OP units.
    pub band: f64,
    /// How far short of OP a slip lands, OP units (less than the band).
    pub short: f64,
}

impl Slip {
    /// Stenman's valve of band `band`: a slip lands on OP.
    pub fn stenman(band: f64) -> Self {
        Self { band, short: 0.0 }
    }
}

/// Log-likelihood of PV when a sticky valve (`slip`) stands between OP and the process: it
/// holds until OP, as the controller moved it between the samples too (the recorded OP plus the
/// input noise), leaves the band, then slips to it (or `slip.short` before it). The valve's
/// position is hidden; each particle carries one and the loop's state given it.
pub fn sticky_log_likelihood(rec: &Record, m: &LoopModel, slip: Slip, pf: &Particles) -> f64 {
    let Slip { band, short } = slip;
    let mat = m.matrices(rec.ts);
    let (mean0, p0) = rec.start(m);
    let gains = Gains::of(&mat, p0, rec.pv.len());
    let (n, k) = (pf.count.max(1), mat.delay_samples);
    let mut rng = seeded(pf.seed);
    let mut valve: Vec<f64> = (0..n)
        .map(|_| rec.clip(rec.op[0] + band * (2.0 * rng.random::<f64>() - 1.0)))
        .collect();
    let mut means = vec![mean0; n];
    // each particle's valve positions of the last k + 1 samples (a ring: the dead time)
    let mut ring: Vec<f64> = valve
        .iter()
        .flat_map(|&v| std::iter::repeat_n(v, k + 1))
        .collect();
    let mut log_w = vec![0.0; n];
    let (mut ll, mut weights) = (0.0, vec![0.0; n]);
    // resampling's buffers, kept from one resampling to the next
    let mut picks = Vec::with_capacity(n);
    let mut spare: (Vec<f64>, Vec<[f64; STATES]>, Vec<f64>) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(ring.len()),
    );
    for t in 0..rec.pv.len() {
        // the log density's constant is shared by every particle at this step
        let (g, s, log_s) = gains.at(t);
        let slot = t % (k + 1);
        for i in 0..n {
            // a ziggurat draw: the particles' draws were half the filter's time by Box-Muller
            let z: f64 = rng.sample(StandardNormal);
            let seen = rec.op[t] + m.input_noise * z;
            let gap = seen - valve[i];
            if gap.abs() > band {
                // short = 0 lands on OP exactly (seen - ±0)
                valve[i] = rec.clip(seen - short.copysign(gap));
            }
            // this sample's position in its slot; the input is the position k samples ago, in
            // the slot written next
            let r = &mut ring[i * (k + 1)..(i + 1) * (k + 1)];
            r[slot] = valve[i];
            let u = r[(slot + 1) % (k + 1)];
            let mean = &mut means[i];
            predict(&mat.f, mat.b[0], mean, u);
            let e = innovation(mean, rec.pv[t]);
            log_w[i] += log_density(e, s, log_s);
            update(mean, g, e);
        }
        let top = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut sum = 0.0;
        let mut sum_sq = 0.0;
        for (w, &l) in weights.iter_mut().zip(&log_w) {
            *w = (l - top).exp();
            sum += *w;
            sum_sq += *w * *w;
        }
        if !sum.is_finite() || sum <= 0.0 {
            return f64::NEG_INFINITY;
        }
        if sum * sum / sum_sq < 0.5 * n as f64 || t + 1 == rec.pv.len() {
            ll += top + (sum / n as f64).ln();
            // the drawn particles into the spare buffers, which then take the old ones' place
            systematic(&weights, sum, rng.random::<f64>(), &mut picks);
            spare.0.clear();
            spare.0.extend(picks.iter().map(|&j| valve[j]));
            spare.1.clear();
            spare.1.extend(picks.iter().map(|&j| means[j]));
            spare.2.clear();
            for &j in &picks {
                spare
                    .2
                    .extend_from_slice(&ring[j * (k + 1)..(j + 1) * (k + 1)]);
            }
            std::mem::swap(&mut valve, &mut spare.0);
            std::mem::swap(&mut means, &mut spare.1);
            std::mem::swap(&mut ring, &mut spare.2);
            log_w.iter_mut().for_each(|l| *l = 0.0);
        }
    }
    ll
}

/// Systematic resampling: the particles drawn, in order, for weights summing to `sum`, into
/// `picks`.
fn systematic(weights: &[f64], sum: f64, offset: f64, picks: &mut Vec<usize>) {
    let n = weights.len();
    picks.clear();
    let (mut j, mut acc) = (0, weights[0] / sum);
    for i in 0..n {
        let u = (offset + i as f64) / n as f64;
        while acc < u && j + 1 < n {
            j += 1;
            acc += weights[j] / sum;
        }
        picks.push(j);
    }
}
