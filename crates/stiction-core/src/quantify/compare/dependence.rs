//! How many samples one independent piece of evidence spans in the comparison's test.
//!
//! The fit with stiction gains over the linear loop along one direction: the change the valve's
//! band makes to the simulated output. Under the hypothesis of a healthy valve that gain is the
//! residual's share along that direction, and its expected size is the residual's variance times
//! the long-run overlap of the residual with that direction (a Newey-West sum: the products of
//! their autocorrelations, Bartlett-weighted). For white residuals it is one sample; for changes
//! over a lag of L samples with a smooth direction about L (what the test assumed before); for a
//! residual and a direction that oscillate together (an external oscillation the band partly
//! absorbs) it is many more: a free band that follows a cycle gains what the cycle gives it, not
//! what a sticky valve would.

use crate::identify::{self, Data, Fit};

/// The Bartlett window spans this many lags of the compared changes.
const WINDOW_LAGS: usize = 4;

/// The samples one independent change spans (at least 1): `1 + 2 sum_k w_k r_e(k) r_g(k)` over
/// `k = 1 ..= WINDOW_LAGS * lag`, `r_e` the autocorrelation of the stiction fit's residual,
/// `r_g` that of the stiction fit's output less the linear loop's, `w_k` Bartlett's weights.
/// `data`: the compared output; the stiction fit with the valve trajectory it sees (differenced
/// as the output), and the linear loop's fit with OP's (`None` when it could not be fitted: the
/// direction is then the stiction fit's whole output).
pub fn correlation_span(
    data: &Data,
    lag: usize,
    (mv_stiction, fit_stiction): (&[f64], &Fit),
    linear: Option<(&[f64], &Fit)>,
) -> f64 {
    let t0 = data.t0;
    let y_s = identify::simulate_pv(data, mv_stiction, fit_stiction);
    let y_l = linear.map(|(mv, f)| identify::simulate_pv(data, mv, f));
    let n = y_s.len();
    if n < t0 + 8 {
        return lag.max(1) as f64;
    }
    let residual: Vec<f64> = (t0..n).map(|t| data.pv[t] - y_s[t]).collect();
    let direction: Vec<f64> = match &y_l {
        Some(l) => (t0..n).map(|t| y_s[t] - l[t]).collect(),
        None => y_s[t0..].to_vec(),
    };
    let k_max = (WINDOW_LAGS * lag.max(1)).min(residual.len() / 4).max(1);
    let r_e = crate::detect::autocorrelation(&residual, k_max);
    let r_g = crate::detect::autocorrelation(&direction, k_max);
    let sum: f64 = (1..=k_max.min(r_e.len() - 1).min(r_g.len() - 1))
        .map(|k| (1.0 - k as f64 / (k_max + 1) as f64) * r_e[k] * r_g[k])
        .sum();
    (1.0 + 2.0 * sum).max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::Structure;

    fn gain_only(b: f64) -> Fit {
        Fit {
            structure: Structure {
                na: 0,
                nb: 1,
                nk: 0,
                integrating: false,
            },
            a: vec![],
            b: vec![b],
            c: 0.0,
            sse_one_step: 0.0,
            sse_simulation: 0.0,
            sst: 1.0,
        }
    }

    /// Seeded white Gaussian noise.
    fn white(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = crate::rng::seeded(seed);
        (0..n).map(|_| crate::rng::gaussian(&mut rng)).collect()
    }

    #[test]
    fn white_residuals_span_about_one_sample() {
        let n = 2000;
        let mv = white(n, 1);
        let noise = white(n, 2);
        let y: Vec<f64> = mv.iter().zip(&noise).map(|(m, e)| 2.0 * m + e).collect();
        let data = Data::new(&y, 1);
        let f = gain_only(2.0);
        let g = gain_only(1.9);
        let span = correlation_span(&data, 5, (&mv, &f), Some((&mv, &g)));
        assert!(span < 1.5, "white residuals: {span}");
    }

    #[test]
    fn a_cycle_shared_by_residual_and_direction_spans_many_samples() {
        let n = 2000;
        let cycle: Vec<f64> = (0..n)
            .map(|t| (2.0 * std::f64::consts::PI * t as f64 / 40.0).sin())
            .collect();
        let noise = white(n, 3);
        // the PV carries a cycle OP does not drive; the stiction fit's output follows half of it
        let y: Vec<f64> = cycle.iter().zip(&noise).map(|(c, e)| c + 0.1 * e).collect();
        let data = Data::new(&y, 1);
        let half: Vec<f64> = cycle.iter().map(|c| 0.5 * c).collect();
        let zero = vec![0.0; n];
        let span = correlation_span(
            &data,
            5,
            (&half, &gain_only(1.0)),
            Some((&zero, &gain_only(1.0))),
        );
        assert!(span > 5.0, "a shared cycle: {span}");
    }
}
