//! A plain output-error test of "does this valve trajectory explain PV better than OP does?",
//! shared by the model-family studies (`model_ceiling`, `clean_walk`).
//!
//! PV on its levels is regressed by least squares on a bank of first-order filters of the valve
//! position (each delayed a sample) and pure delays, for a level loop also the valve's running
//! sum, beside a piecewise-linear drift (a knot every [`KNOT_EVERY`] samples). The regressors hold
//! only valve positions from before each PV sample and the drift is smooth, so the PV's
//! measurement noise, which the controller feeds back into OP at once, cannot favour OP. The
//! drift is projected out once per record (an orthonormal basis), so a valve trajectory costs its
//! filter columns and their small Gram matrix.

/// Samples between the drift's knots.
pub const KNOT_EVERY: usize = 150;

/// The linear part: first-order filters (time constants in samples) and pure delays (samples).
pub struct Bank {
    pub taus: &'static [f64],
    pub delays: &'static [usize],
}

/// One record's PV with its drift projected out.
pub struct CleanFit {
    bank: Bank,
    integrating: bool,
    /// Orthonormal basis of the drift (a constant and hinges at the knots).
    drift: Vec<Vec<f64>>,
    /// PV with the drift projected out, and its sum of squares.
    y: Vec<f64>,
    yy: f64,
}

impl CleanFit {
    pub fn new(pv: &[f64], integrating: bool, bank: Bank) -> Self {
        let n = pv.len();
        let knots = (n / KNOT_EVERY).max(2);
        let mut cols = vec![vec![1.0; n]];
        for k in 0..knots {
            let at = k * n / knots;
            cols.push(
                (0..n)
                    .map(|t| t.saturating_sub(at) as f64 / n as f64)
                    .collect(),
            );
        }
        let drift = orthonormal(cols);
        let mut y = pv.to_vec();
        project_out(&drift, &mut y);
        let yy = y.iter().map(|v| v * v).sum();
        Self {
            bank,
            integrating,
            drift,
            y,
            yy,
        }
    }

    /// Residual sum of squares of PV explained by `valve` (beside the drift).
    pub fn sse(&self, valve: &[f64]) -> f64 {
        let mut cols = self.columns(valve);
        for c in cols.iter_mut() {
            project_out(&self.drift, c);
        }
        let p = cols.len();
        let mut a = vec![vec![0.0; p]; p];
        let mut b = vec![0.0; p];
        for i in 0..p {
            b[i] = dot(&cols[i], &self.y);
            for j in i..p {
                a[i][j] = dot(&cols[i], &cols[j]);
                a[j][i] = a[i][j];
            }
        }
        (self.yy - explained(a, &b)).max(0.0)
    }

    /// The log-likelihood ratio `n/2 ln(SSE with OP / SSE with the valve)`, given OP's SSE.
    pub fn llr(&self, with_op: f64, valve: &[f64]) -> f64 {
        self.y.len() as f64 / 2.0 * (with_op / self.sse(valve).max(f64::MIN_POSITIVE)).ln()
    }

    fn columns(&self, valve: &[f64]) -> Vec<Vec<f64>> {
        let n = valve.len();
        let mean = valve.iter().sum::<f64>() / n as f64;
        let u: Vec<f64> = valve.iter().map(|v| v - mean).collect();
        let mut cols = Vec::new();
        for &tau in self.bank.taus {
            let a = (-1.0f64 / tau).exp();
            let mut s = u[0];
            let mut c = vec![0.0; n];
            for t in 1..n {
                c[t] = s;
                s = a * s + (1.0 - a) * u[t];
            }
            cols.push(c);
        }
        for &d in self.bank.delays {
            cols.push(
                (0..n)
                    .map(|t| if t >= d { u[t - d] } else { 0.0 })
                    .collect(),
            );
        }
        if self.integrating {
            let mut s = 0.0;
            cols.push(
                (0..n)
                    .map(|t| {
                        let c = s;
                        s += u[t];
                        c
                    })
                    .collect(),
            );
        }
        cols
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Gram-Schmidt, twice per column; columns that add nothing are dropped.
fn orthonormal(cols: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = Vec::new();
    for mut c in cols {
        for _ in 0..2 {
            project_out(&out, &mut c);
        }
        let norm = dot(&c, &c).sqrt();
        if norm > 1e-9 {
            out.push(c.iter().map(|x| x / norm).collect());
        }
    }
    out
}

/// `c -= Q Qᵀ c` for an orthonormal `q`.
fn project_out(q: &[Vec<f64>], c: &mut [f64]) {
    for qq in q {
        let p = dot(qq, c);
        for (x, a) in c.iter_mut().zip(qq) {
            *x -= p * a;
        }
    }
}

/// `bᵀ A⁻¹ b` (the sum of squares the columns explain), by Cholesky with a small ridge.
fn explained(mut a: Vec<Vec<f64>>, b: &[f64]) -> f64 {
    let p = b.len();
    for (i, row) in a.iter_mut().enumerate() {
        row[i] += 1e-9 * row[i].abs() + 1e-300;
    }
    let mut l = vec![vec![0.0; p]; p];
    for i in 0..p {
        for j in 0..=i {
            let s: f64 = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            l[i][j] = if i == j {
                s.max(1e-300).sqrt()
            } else {
                s / l[j][j]
            };
        }
    }
    let mut z = vec![0.0; p];
    for i in 0..p {
        z[i] = (b[i] - (0..i).map(|k| l[i][k] * z[k]).sum::<f64>()) / l[i][i];
    }
    z.iter().map(|v| v * v).sum()
}
