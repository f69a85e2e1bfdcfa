//! Small dense 3x3 linear algebra for the ellipse fit: products, Cholesky, inverses and the
//! symmetric eigen-decomposition.

#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub(super) type Mat3 = [[f64; 3]; 3];

pub(super) fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

pub(super) fn transpose(a: &Mat3) -> Mat3 {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = a[j][i];
        }
    }
    t
}

/// Lower Cholesky factor of a symmetric positive-definite matrix; `None` if a pivot is not
/// clearly positive.
pub(super) fn cholesky(a: &Mat3) -> Option<Mat3> {
    let scale = a[0][0].abs().max(a[1][1].abs()).max(a[2][2].abs());
    let mut l = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..=i {
            let s = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if !(s > 1e-13 * scale) {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    Some(l)
}

/// Inverse of a lower-triangular matrix.
pub(super) fn lower_inverse(l: &Mat3) -> Mat3 {
    let mut inv = [[0.0; 3]; 3];
    for j in 0..3 {
        inv[j][j] = 1.0 / l[j][j];
        for i in j + 1..3 {
            let s: f64 = (j..i).map(|k| l[i][k] * inv[k][j]).sum();
            inv[i][j] = -s / l[i][i];
        }
    }
    inv
}

/// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations: eigenvalues and the
/// eigenvectors as columns.
pub(super) fn symmetric_eigen(mut a: Mat3) -> ([f64; 3], Mat3) {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let diag = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if !(off > 1e-300 + 1e-16 * diag) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            // signum(0) = 1: a 45° rotation for equal diagonal entries
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A <- Jᵀ A J and V <- V J: columns of A and V first, then rows p and q of A (p < q)
            for row in a.iter_mut().chain(v.iter_mut()) {
                let (rp, rq) = (row[p], row[q]);
                row[p] = c * rp - s * rq;
                row[q] = s * rp + c * rq;
            }
            let (top, bottom) = a.split_at_mut(q);
            for (ap, aq) in top[p].iter_mut().zip(bottom[0].iter_mut()) {
                let (rp, rq) = (*ap, *aq);
                *ap = c * rp - s * rq;
                *aq = s * rp + c * rq;
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2]], v)
}

/// Inverse of a symmetric positive-definite 3x3 matrix via its Cholesky factor.
pub(super) fn spd_inverse(a: &Mat3) -> Option<Mat3> {
    let li = lower_inverse(&cholesky(a)?);
    Some(mat_mul(&transpose(&li), &li))
}
