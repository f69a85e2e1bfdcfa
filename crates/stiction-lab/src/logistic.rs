//! A weighted logistic regression whose weights are held at or above zero (each input is
//! oriented so that a larger value points to a sticky valve: the fitted effects are monotone),
//! with a ridge penalty on the weights, fitted by projected Newton steps (an active set: a
//! weight at zero whose gradient pushes it below stays there).

// small dense linear algebra reads best with the textbook's indices
#![allow(clippy::needless_range_loop)]

/// The fitted model: `P = 1 / (1 + exp(-(intercept + weights · x)))`.
#[derive(Debug, Clone, PartialEq)]
pub struct Fitted {
    pub intercept: f64,
    pub weights: Vec<f64>,
}

impl Fitted {
    /// The log-odds of one row.
    pub fn log_odds(&self, x: &[f64]) -> f64 {
        self.intercept + self.weights.iter().zip(x).map(|(w, v)| w * v).sum::<f64>()
    }

    /// The probability of one row.
    pub fn probability(&self, x: &[f64]) -> f64 {
        sigmoid(self.log_odds(x))
    }
}

pub fn sigmoid(z: f64) -> f64 {
    1.0 / (1.0 + (-z).exp())
}

/// Fit rows `x` (all of one length) with labels `y` (true: sticky) and weights `w`; `ridge` is
/// the penalty on the squared weights (not on the intercept).
pub fn fit(x: &[Vec<f64>], y: &[bool], w: &[f64], ridge: f64) -> Fitted {
    let k = x.first().map_or(0, Vec::len);
    let mut theta = vec![0.0; k + 1];
    let mut free = vec![true; k + 1];
    for _ in 0..100 {
        let (grad, hess) = derivatives(x, y, w, ridge, &theta);
        // a weight at zero whose gradient points below zero stays fixed
        for j in 1..=k {
            free[j] = theta[j] > 0.0 || grad[j] < 0.0;
        }
        let idx: Vec<usize> = (0..=k).filter(|&j| free[j]).collect();
        let h: Vec<Vec<f64>> = idx
            .iter()
            .map(|&a| idx.iter().map(|&b| hess[a][b]).collect())
            .collect();
        let g: Vec<f64> = idx.iter().map(|&a| grad[a]).collect();
        let Some(step) = solve(h, g) else { break };
        let before = loss(x, y, w, ridge, &theta);
        let mut t = 1.0;
        let mut improved = false;
        for _ in 0..30 {
            let mut trial = theta.clone();
            for (s, &j) in step.iter().zip(&idx) {
                trial[j] -= t * s;
                if j > 0 {
                    trial[j] = trial[j].max(0.0);
                }
            }
            let after = loss(x, y, w, ridge, &trial);
            if after <= before - 1e-12 {
                theta = trial;
                improved = true;
                break;
            }
            t *= 0.5;
        }
        if !improved || step.iter().map(|s| s.abs()).fold(0.0, f64::max) * t < 1e-9 {
            break;
        }
    }
    Fitted {
        intercept: theta[0],
        weights: theta[1..].to_vec(),
    }
}

fn row_z(theta: &[f64], row: &[f64]) -> f64 {
    theta[0] + theta[1..].iter().zip(row).map(|(a, b)| a * b).sum::<f64>()
}

fn loss(x: &[Vec<f64>], y: &[bool], w: &[f64], ridge: f64, theta: &[f64]) -> f64 {
    let mut l = 0.0;
    for ((row, &yi), &wi) in x.iter().zip(y).zip(w) {
        let z = row_z(theta, row);
        // ln(1 + e^z) - y z, written to stay finite for large |z|
        let softplus = if z > 0.0 {
            z + (-z).exp().ln_1p()
        } else {
            z.exp().ln_1p()
        };
        l += wi * (softplus - if yi { z } else { 0.0 });
    }
    l + 0.5 * ridge * theta[1..].iter().map(|v| v * v).sum::<f64>()
}

fn derivatives(
    x: &[Vec<f64>],
    y: &[bool],
    w: &[f64],
    ridge: f64,
    theta: &[f64],
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let k = theta.len();
    let mut g = vec![0.0; k];
    let mut h = vec![vec![0.0; k]; k];
    for ((row, &yi), &wi) in x.iter().zip(y).zip(w) {
        let p = sigmoid(row_z(theta, row));
        let r = wi * (p - if yi { 1.0 } else { 0.0 });
        let s = wi * p * (1.0 - p);
        let xi = |j: usize| if j == 0 { 1.0 } else { row[j - 1] };
        for a in 0..k {
            g[a] += r * xi(a);
            for b in 0..=a {
                h[a][b] += s * xi(a) * xi(b);
            }
        }
    }
    for a in 0..k {
        for b in 0..a {
            h[b][a] = h[a][b];
        }
        if a > 0 {
            g[a] += ridge * theta[a];
            h[a][a] += ridge;
        }
        h[a][a] += 1e-9;
    }
    (g, h)
}

/// Solve `h s = g` by Cholesky (`h` symmetric positive definite).
fn solve(mut h: Vec<Vec<f64>>, mut g: Vec<f64>) -> Option<Vec<f64>> {
    let n = g.len();
    for j in 0..n {
        let mut d = h[j][j];
        for k in 0..j {
            d -= h[j][k] * h[j][k];
        }
        if d <= 0.0 || !d.is_finite() {
            return None;
        }
        let d = d.sqrt();
        h[j][j] = d;
        for i in j + 1..n {
            let mut v = h[i][j];
            for k in 0..j {
                v -= h[i][k] * h[j][k];
            }
            h[i][j] = v / d;
        }
    }
    for i in 0..n {
        for k in 0..i {
            g[i] -= h[i][k] * g[k];
        }
        g[i] /= h[i][i];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            g[i] -= h[k][i] * g[k];
        }
        g[i] /= h[i][i];
    }
    Some(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_monotone_effect_and_holds_a_useless_one_at_zero() {
        // y = 1 when x0 is large; x1 points the other way and must stay at zero
        let mut x = Vec::new();
        let mut y = Vec::new();
        for i in 0..200 {
            let v = i as f64 / 100.0 - 1.0;
            x.push(vec![v, -v]);
            y.push((i * 7919) % 200 < i);
        }
        let w = vec![1.0; x.len()];
        let f = fit(&x, &y, &w, 0.01);
        assert!(f.weights[0] > 1.0, "{f:?}");
        assert_eq!(f.weights[1], 0.0);
        assert!(f.probability(&[0.9, -0.9]) > 0.7);
        assert!(f.probability(&[-0.9, 0.9]) < 0.3);
    }
}
