//! Small dense linear algebra for the levels test: Gram matrices, solves, the AR noise model's
//! whitening and orthonormal columns.

// small dense linear algebra reads best with the textbook's indices
#![allow(clippy::needless_range_loop)]

pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The Gram matrix of `cols` and their products with `y`.
pub(super) fn gram(cols: &[Vec<f64>], y: &[f64]) -> (Vec<Vec<f64>>, Vec<f64>) {
    let p = cols.len();
    let mut a = vec![vec![0.0; p]; p];
    let mut b = vec![0.0; p];
    for i in 0..p {
        b[i] = dot(&cols[i], y);
        for j in i..p {
            a[i][j] = dot(&cols[i], &cols[j]);
            a[j][i] = a[i][j];
        }
    }
    (a, b)
}

/// `A⁻¹ b` by Gaussian elimination with partial pivoting and a small ridge.
pub(super) fn solve(mut a: Vec<Vec<f64>>, b: &[f64]) -> Vec<f64> {
    let p = b.len();
    let mut x = b.to_vec();
    for (i, row) in a.iter_mut().enumerate() {
        row[i] += 1e-9 * row[i].abs() + 1e-300;
    }
    for k in 0..p {
        let piv = (k..p)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
            .unwrap_or(k);
        a.swap(k, piv);
        x.swap(k, piv);
        for i in k + 1..p {
            let f = a[i][k] / a[k][k];
            for j in k..p {
                a[i][j] -= f * a[k][j];
            }
            x[i] -= f * x[k];
        }
    }
    for k in (0..p).rev() {
        let s: f64 = (k + 1..p).map(|j| a[k][j] * x[j]).sum();
        x[k] = (x[k] - s) / a[k][k];
    }
    x
}

/// `bᵀ A⁻¹ b` (the sum of squares the columns explain), by Cholesky with a small ridge.
pub(super) fn explained(mut a: Vec<Vec<f64>>, b: &[f64]) -> f64 {
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

/// AR coefficients `a_1..a_p` of `r` (least squares): `r_t + a_1 r_{t-1} + ... = e_t`.
pub(super) fn ar_fit(r: &[f64], order: usize) -> Vec<f64> {
    if order == 0 || r.len() <= 2 * order {
        return Vec::new();
    }
    let cols: Vec<Vec<f64>> = (1..=order)
        .map(|k| r[order - k..r.len() - k].to_vec())
        .collect();
    let (a, b) = gram(&cols, &r[order..]);
    let c = solve(a, &b);
    if c.iter().all(|v| v.is_finite()) {
        c.into_iter().map(|v| -v).collect()
    } else {
        Vec::new()
    }
}

/// `c ← A(q) c` in place (the first samples use the lags they have).
pub(super) fn whiten(ar: &[f64], c: &mut [f64]) {
    if ar.is_empty() {
        return;
    }
    for t in (0..c.len()).rev() {
        let mut s = c[t];
        for (k, a) in ar.iter().enumerate() {
            if t > k {
                s += a * c[t - k - 1];
            }
        }
        c[t] = s;
    }
}

/// Gram-Schmidt, twice per column; columns that add nothing are dropped.
pub(super) fn orthonormal(cols: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
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
pub(super) fn project_out(q: &[Vec<f64>], c: &mut [f64]) {
    for qq in q {
        let p = dot(qq, c);
        for (x, a) in c.iter_mut().zip(qq) {
            *x -= p * a;
        }
    }
}
