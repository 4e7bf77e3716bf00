//! The rotation closest to a 3x3 matrix (orthogonal Procrustes), the local step of ARAP.

/// A 3x3 matrix, row major.
pub type Mat3 = [[f64; 3]; 3];

/// The rotation `R` (det = +1) maximizing `tr(R^T m)`, i.e. the rotational polar factor of `m`
/// (Umeyama / Kabsch). For ARAP with `m = sum_j w_ij e'_ij e_ij^T` (current edge times rest edge)
/// it minimizes `sum_j w_ij |e'_ij - R e_ij|^2` (Sorkine & Alexa 2007, eq 5-6).
///
/// Computed as `U V^T` from the SVD `m = U S V^T`, with `V` from a Jacobi eigendecomposition of
/// `m^T m` and `u_k = m v_k / s_k`; rank-deficient inputs complete `U` by cross products (planar
/// one-rings have `s_3 = 0`). A reflection is turned into a rotation by flipping the singular
/// vector of the smallest singular value.
pub fn closest_rotation(m: &Mat3) -> Mat3 {
    closest_rotation_warm(m, &mut IDENTITY.clone())
}

/// [`closest_rotation`] warm-started from `frame`, an orthonormal guess of the right singular vectors
/// (columns), which is overwritten with the ones found. In ARAP the singular frames change little
/// from one iteration to the next, so `frame^T m^T m frame` is nearly diagonal and Jacobi converges
/// in about one sweep instead of three or four.
pub fn closest_rotation_warm(m: &Mat3, frame: &mut Mat3) -> Mat3 {
    let mut mtm = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in i..3 {
            let s = m[0][i] * m[0][j] + m[1][i] * m[1][j] + m[2][i] * m[2][j];
            mtm[i][j] = s;
            mtm[j][i] = s;
        }
    }
    let g = *frame;
    let rotated = matmul_tn(&g, &matmul(&mtm, &g));
    let (eigenvalues, w) = symmetric_eigen3(rotated);
    let v = matmul(&g, &w);
    *frame = v;
    // Order by descending singular value.
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eigenvalues[b].total_cmp(&eigenvalues[a]));
    let vcol = |k: usize| [v[0][order[k]], v[1][order[k]], v[2][order[k]]];
    let (v0, v1) = (vcol(0), vcol(1));
    let v2 = cross(v0, v1); // right-handed V
    let s0 = eigenvalues[order[0]].max(0.0).sqrt();
    if !(s0 > 0.0) || !s0.is_finite() {
        return IDENTITY;
    }
    let tiny = 1e-12 * s0;
    let u0 = normalize(mul(m, v0));
    let mv1 = mul(m, v1);
    let u1 = if norm(mv1) > tiny {
        // Re-orthogonalize against u0 for accuracy when s1 << s0.
        normalize(sub(mv1, scale(u0, dot(u0, mv1))))
    } else {
        any_orthogonal(u0)
    };
    // u2 = u0 x u1 makes U a rotation; if m itself is orientation-reversing, s2 takes the sign, which is
    // exactly the flip of the smallest singular vector that the Procrustes solution with det=+1 needs.
    let u2 = cross(u0, u1);
    let u = [u0, u1, u2];
    let vv = [v0, v1, v2];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = u[0][i] * vv[0][j] + u[1][i] * vv[1][j] + u[2][i] * vv[2][j];
        }
    }
    r
}

/// `sum_k to_k from_k^T` over `(from, to)` vector pairs, in their order: the matrix whose
/// [`closest_rotation`] best maps the `from` vectors onto the `to` ones.
pub fn cross_covariance(pairs: impl IntoIterator<Item = ([f64; 3], [f64; 3])>) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (from, to) in pairs {
        for a in 0..3 {
            for b in 0..3 {
                m[a][b] += to[a] * from[b];
            }
        }
    }
    m
}

/// The angle of the rotation `r` about its axis (radians, in `[0, pi]`).
pub fn rotation_angle(r: &Mat3) -> f64 {
    ((r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0).clamp(-1.0, 1.0).acos()
}

/// The singular values of `m`, descending (square roots of the eigenvalues of `m^T m`).
pub fn singular_values(m: &Mat3) -> [f64; 3] {
    let mtm: Mat3 = std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| m[k][i] * m[k][j]).sum()));
    let (eigenvalues, _) = symmetric_eigen3(mtm);
    let mut s = eigenvalues.map(|e| e.max(0.0).sqrt());
    s.sort_by(|a, b| b.total_cmp(a));
    s
}

/// The 3x3 identity.
pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations: `(eigenvalues, V)` with
/// the eigenvectors in the columns of `V`.
pub fn symmetric_eigen3(mut a: Mat3) -> ([f64; 3], Mat3) {
    let mut v = IDENTITY;
    let scale2 = (0..3).map(|i| a[i][i] * a[i][i]).sum::<f64>() + 1e-300;
    for _sweep in 0..32 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        // Off-diagonal below 1e-14 of the diagonal: a tighter bound sits at the rounding level of the
        // rotations themselves and can cost all 32 sweeps without improving the result.
        if off <= 1e-28 * scale2 {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            let apq = a[p][q];
            if apq == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A <- J^T A J with J the (p, q) rotation.
            for k in 0..3 {
                let akp = a[k][p];
                let akq = a[k][q];
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let apk = a[p][k];
                let aqk = a[q][k];
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for k in 0..3 {
                let vkp = v[k][p];
                let vkq = v[k][q];
                v[k][p] = c * vkp - s * vkq;
                v[k][q] = s * vkp + c * vkq;
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2]], v)
}

#[inline]
fn matmul(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
    })
}

/// `a^T b`.
#[inline]
fn matmul_tn(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| a[0][i] * b[0][j] + a[1][i] * b[1][j] + a[2][i] * b[2][j])
    })
}

#[inline]
fn mul(m: &Mat3, x: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2])
}
#[inline]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    meshes::vector::cross(a, b)
}
#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    meshes::vector::dot(a, b)
}
#[inline]
fn norm(a: [f64; 3]) -> f64 {
    meshes::vector::norm(a)
}
#[inline]
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    meshes::vector::sub(a, b)
}
#[inline]
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    meshes::vector::scale(a, s)
}
#[inline]
fn normalize(a: [f64; 3]) -> [f64; 3] {
    meshes::vector::normalize_or_zero(a)
}

fn any_orthogonal(u: [f64; 3]) -> [f64; 3] {
    let axis = if u[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    normalize(cross(u, axis))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn det(m: &Mat3) -> f64 {
        dot(m[0], cross(m[1], m[2]))
    }
    fn rot(axis: [f64; 3], angle: f64) -> Mat3 {
        let t = meshes::AffineTransform::rotation_about(axis, angle, [0.0; 3]);
        std::array::from_fn(|i| std::array::from_fn(|j| t.rows()[i][j]))
    }
    fn max_diff(a: &Mat3, b: &Mat3) -> f64 {
        (0..9).map(|k| (a[k / 3][k % 3] - b[k / 3][k % 3]).abs()).fold(0.0, f64::max)
    }

    #[test]
    fn recovers_rotation_times_spd() {
        let r = rot([0.3, -0.5, 0.8], 2.1);
        let spd = [[3.0, 0.2, 0.1], [0.2, 1.5, -0.3], [0.1, -0.3, 0.7]];
        let got = closest_rotation(&matmul(&r, &spd));
        assert!(max_diff(&got, &r) < 1e-12, "{got:?} vs {r:?}");
    }

    #[test]
    fn reflection_becomes_rotation() {
        let r = rot([1.0, 2.0, 3.0], 0.7);
        let reflect = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -0.1]];
        let got = closest_rotation(&matmul(&r, &reflect));
        assert!((det(&got) - 1.0).abs() < 1e-12);
        // Closest proper rotation of R * diag(1, 1, -0.1) is R itself.
        assert!(max_diff(&got, &r) < 1e-12);
    }

    #[test]
    fn planar_rank_two_input() {
        let r = rot([0.0, 1.0, 1.0], -1.2);
        let flat = [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]];
        let got = closest_rotation(&matmul(&r, &flat));
        assert!(max_diff(&got, &r) < 1e-12);
    }

    #[test]
    fn warm_start_gives_the_same_rotation() {
        let r = rot([0.3, -0.5, 0.8], 2.1);
        let spd = [[3.0, 0.2, 0.1], [0.2, 1.5, -0.3], [0.1, -0.3, 0.7]];
        let m = matmul(&r, &spd);
        for guess in [IDENTITY, rot([1.0, 1.0, 0.0], 0.3), rot([0.0, 0.2, 1.0], 3.0)] {
            let mut frame = guess;
            let got = closest_rotation_warm(&m, &mut frame);
            assert!(max_diff(&got, &r) < 1e-12);
            // The returned frame diagonalizes m^T m.
            let mut again = frame;
            assert!(max_diff(&closest_rotation_warm(&m, &mut again), &r) < 1e-12);
        }
    }

    #[test]
    fn equal_singular_values() {
        let r = rot([0.2, 0.1, -1.0], 3.0);
        let got = closest_rotation(&matmul(&r, &[[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]]));
        assert!(max_diff(&got, &r) < 1e-12);
    }
}
