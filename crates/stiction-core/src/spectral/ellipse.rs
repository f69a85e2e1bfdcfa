//! The direct least-squares ellipse fit (Fitzgibbon, Pilu and Fisher 1999, in Halir and
//! Flusser's stable form) and the apparent stiction from the PV-OP plot.

#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use super::*;

/// An ellipse fitted to a PV-OP plot (x = OP, y = PV), in the data's units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ellipse {
    /// Centre (OP, PV).
    pub centre: [f64; 2],
    /// Semi-major axis a, data units.
    pub semi_major: f64,
    /// Semi-minor axis b, data units.
    pub semi_minor: f64,
    /// Angle of the major axis from the x (OP) axis, radians, in (−π/2, π/2].
    pub angle: f64,
    /// The chord parallel to x through the centre, `2ab / sqrt(a² sin²α + b² cos²α)`: the apparent
    /// stiction when x is OP (Choudhury et al. 2006).
    pub width_along_x: f64,
    /// Root mean square of the points' (shortest, geometric) distance to the ellipse, data units.
    pub rms_residual: f64,
}

/// Direct least-squares ellipse fit (Fitzgibbon, Pilu and Fisher 1999) in the numerically
/// stable form of Halíř and Flusser (1998): minimise the algebraic distance of the conic
/// `A x² + B xy + C y² + D x + E y + F = 0` under the constraint `4AC − B² = 1`, which makes an
/// ellipse the only possible answer, non-iteratively.
///
/// The data are centred and scaled to unit standard deviation first (the scatter matrix of raw
/// PV-OP data in % spans many orders of magnitude), the conic is mapped back. The linear part is
/// eliminated through `T = −S3⁻¹ S2ᵀ`, leaving the 3x3 generalised eigenproblem
/// `(S1 + S2 T) a = λ C a`, solved here as a symmetric one through the Cholesky factor of the
/// reduced scatter matrix (a tiny ridge keeps it definite when the points lie exactly on a
/// conic); the one eigenvector with `4AC − B² > 0` is the ellipse.
///
/// Pairs beyond the shorter slice are ignored. `None` with fewer than 6 points, non-finite values,
/// points on a line (or a point), or a conic that is not a real ellipse.
pub fn fit_ellipse(x: &[f64], y: &[f64]) -> Option<Ellipse> {
    let n = x.len().min(y.len());
    let (x, y) = (&x[..n], &y[..n]);
    if n < 6 || x.iter().chain(y).any(|v| !v.is_finite()) {
        return None;
    }
    let (mx, my) = (mean(x), mean(y));
    let sd =
        |v: &[f64], m: f64| (v.iter().map(|a| (a - m) * (a - m)).sum::<f64>() / n as f64).sqrt();
    let (sx, sy) = (sd(x, mx), sd(y, my));
    if !(sx > 1e-12 * mx.abs()) || !(sy > 1e-12 * my.abs()) {
        return None;
    }
    // scatter matrices of D1 = [u², uv, v²] and D2 = [u, v, 1]
    let (mut s1, mut s2, mut s3) = ([[0.0; 3]; 3], [[0.0; 3]; 3], [[0.0; 3]; 3]);
    for (&xi, &yi) in x.iter().zip(y) {
        let (u, v) = ((xi - mx) / sx, (yi - my) / sy);
        let d1 = [u * u, u * v, v * v];
        let d2 = [u, v, 1.0];
        for i in 0..3 {
            for j in 0..3 {
                s1[i][j] += d1[i] * d1[j];
                s2[i][j] += d1[i] * d2[j];
                s3[i][j] += d2[i] * d2[j];
            }
        }
    }
    let s3_inv = spd_inverse(&s3)?; // fails for collinear points
    let mut t = mat_mul(&s3_inv, &transpose(&s2));
    for row in &mut t {
        for v in row.iter_mut() {
            *v = -*v;
        }
    }
    let s2t = mat_mul(&s2, &t);
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = s1[i][j] + 0.5 * (s2t[i][j] + s2t[j][i]);
        }
    }
    let ridge = 1e-12 * (m[0][0] + m[1][1] + m[2][2]);
    for (i, row) in m.iter_mut().enumerate() {
        row[i] += ridge;
    }
    // M a = λ C a  <=>  (L⁻¹ C L⁻ᵀ) b = (1/λ) b with M = L Lᵀ, b = Lᵀ a; C has exactly one
    // positive eigenvalue, so (by Sylvester's law of inertia) has L⁻¹ C L⁻ᵀ, and its eigenvector
    // is the one with aᵀ C a = 4AC − B² > 0.
    let li = lower_inverse(&cholesky(&m)?);
    let c = [[0.0, 0.0, 2.0], [0.0, -1.0, 0.0], [2.0, 0.0, 0.0]];
    let k = mat_mul(&mat_mul(&li, &c), &transpose(&li));
    let (values, vectors) = symmetric_eigen(k);
    let best = (0..3).max_by(|&i, &j| values[i].total_cmp(&values[j]))?;
    if !(values[best] > 0.0) {
        return None;
    }
    let b = [vectors[0][best], vectors[1][best], vectors[2][best]];
    let lit = transpose(&li);
    let a1: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| lit[i][j] * b[j]).sum());
    let a2: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| t[i][j] * a1[j]).sum());
    // back to centred data coordinates (x - mx, y - my)
    let conic = [
        a1[0] / (sx * sx),
        a1[1] / (sx * sy),
        a1[2] / (sy * sy),
        a2[0] / sx,
        a2[1] / sy,
        a2[2],
    ];
    let mut e = ellipse_from_conic(conic)?;
    let (sin, cos) = e.angle.sin_cos();
    let sq: f64 = x
        .iter()
        .zip(y)
        .map(|(&xi, &yi)| {
            // in the ellipse's own axes
            let (u, v) = (xi - mx - e.centre[0], yi - my - e.centre[1]);
            let d = distance_to_ellipse(
                e.semi_major,
                e.semi_minor,
                u * cos + v * sin,
                v * cos - u * sin,
            );
            d * d
        })
        .sum();
    e.rms_residual = (sq / n as f64).sqrt();
    e.centre[0] += mx;
    e.centre[1] += my;
    Some(e)
}

/// Centre, axes and angle of the conic `a x² + b xy + c y² + d x + e y + f = 0`, if it is a real
/// ellipse. `rms_residual` is left at 0.
pub(super) fn ellipse_from_conic([a, b, c, d, e, f]: [f64; 6]) -> Option<Ellipse> {
    let det = 4.0 * a * c - b * b;
    if !(det > 0.0) {
        return None;
    }
    let x0 = (b * e - 2.0 * c * d) / det;
    let y0 = (b * d - 2.0 * a * e) / det;
    // value at the centre; make the quadratic form positive definite
    let mut f0 = f + 0.5 * (d * x0 + e * y0);
    let (mut a, mut b, mut c) = (a, b, c);
    if a < 0.0 {
        (a, b, c, f0) = (-a, -b, -c, -f0);
    }
    if !(f0 < 0.0) {
        return None;
    }
    let mid = 0.5 * (a + c);
    let r = (0.25 * (a - c) * (a - c) + 0.25 * b * b).sqrt();
    let (small, large) = (mid - r, mid + r);
    if !(small > 0.0) {
        return None;
    }
    // 0.5 atan2(b, a - c) is the direction of the larger eigenvalue (the minor axis)
    let minor_dir = if r > 1e-15 * mid {
        0.5 * b.atan2(a - c)
    } else {
        0.0
    };
    let mut angle = minor_dir + std::f64::consts::FRAC_PI_2;
    if angle > std::f64::consts::FRAC_PI_2 {
        angle -= std::f64::consts::PI;
    }
    let semi_major = (-f0 / small).sqrt();
    let semi_minor = (-f0 / large).sqrt();
    Some(Ellipse {
        centre: [x0, y0],
        semi_major,
        semi_minor,
        angle,
        width_along_x: 2.0 * (-f0 / a).sqrt(),
        rms_residual: 0.0,
    })
}

/// Shortest distance from the point (p0, p1) to the ellipse `(x/a)² + (y/b)² = 1`, `a >= b > 0`
/// (Eberly, "Distance from a point to an ellipse": the closest point solves a monotone equation
/// in one unknown, found by bisection, which cannot fail).
pub(super) fn distance_to_ellipse(a: f64, b: f64, p0: f64, p1: f64) -> f64 {
    let (y0, y1) = (p0.abs(), p1.abs());
    if y1 > 0.0 {
        if y0 > 0.0 {
            let (z0, z1) = (y0 / a, y1 / b);
            let g = z0 * z0 + z1 * z1 - 1.0;
            if g == 0.0 {
                return 0.0;
            }
            let r0 = (a / b) * (a / b);
            let n0 = r0 * z0;
            let (mut lo, mut hi) = (z1 - 1.0, if g < 0.0 { 0.0 } else { n0.hypot(z1) - 1.0 });
            let mut t = lo;
            for _ in 0..200 {
                t = 0.5 * (lo + hi);
                // a residual to a part in 1e10 is plenty for a goodness of fit
                if t == lo || t == hi || hi - lo <= 1e-10 * (1.0 + t.abs()) {
                    break;
                }
                let (q0, q1) = (n0 / (t + r0), z1 / (t + 1.0));
                let gt = q0 * q0 + q1 * q1 - 1.0;
                if gt > 0.0 {
                    lo = t;
                } else if gt < 0.0 {
                    hi = t;
                } else {
                    break;
                }
            }
            let (x0, x1) = (r0 * y0 / (t + r0), y1 / (t + 1.0));
            (x0 - y0).hypot(x1 - y1)
        } else {
            (y1 - b).abs()
        }
    } else {
        let (numer, denom) = (a * y0, a * a - b * b);
        if numer < denom {
            let xa = numer / denom;
            (a * xa - y0).hypot(b * (1.0 - xa * xa).sqrt())
        } else {
            (y0 - a).abs()
        }
    }
}

/// Apparent stiction from routine data (Choudhury, Shah, Thornhill and Shook 2006; book 2008):
/// band-pass OP and PV to the oscillation's band `[low, high]` (cycles per sample, with
/// [`band_pass`], which has no phase shift) and fit an ellipse to the PV-OP plot (x = OP,
/// y = PV). The ellipse's width along OP is the apparent stiction, in OP's units: the stiction as
/// the loop sees it, which with a PI controller is not the valve's `d` itself.
pub fn apparent_stiction_ellipse(op: &[f64], pv: &[f64], low: f64, high: f64) -> Option<Ellipse> {
    fit_ellipse(&band_pass(op, low, high), &band_pass(pv, low, high))
}
