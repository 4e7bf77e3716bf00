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

/// [`closest_rotation`] near `previous`, a rotation close to the answer (in ARAP: the vertex's
/// rotation of the last local step), by Newton's method on the rotation group
/// ([`newton_rotation`]); where that does not converge (a start too far, a reflection-like input)
/// the answer is [`closest_rotation_warm`]'s with `frame`, which is then also updated. The same
/// rotation either way, to rounding (Newton's is the more accurate when the singular values spread
/// widely: the Jacobi SVD works on `m^T m`). Where Newton answers it takes one to three steps of a
/// few dozen flops: about a third of the warm Jacobi SVD's time (docs/results.md, issue 63).
pub fn closest_rotation_near(m: &Mat3, previous: &Mat3, frame: &mut Mat3) -> Mat3 {
    newton_rotation(m, previous).unwrap_or_else(|| closest_rotation_warm(m, frame))
}

/// Newton steps of at most this many; a start that needs more takes the SVD.
const NEWTON_STEPS: usize = 8;

/// Diagonal shifts of the Newton Hessian (times `|m|_F`), tried in turn until it is positive
/// definite. The first keeps rank-one inputs, whose `H` is singular in their flat direction, from
/// dividing by zero; the larger ones damp the step where a rank-deficient input's flat direction
/// curves the wrong way away from the optimum. As the iteration closes in, the smallest shift is
/// definite again.
const NEWTON_SHIFTS: [f64; 4] = [1e-12, 1e-6, 1e-3, 3e-2];

/// Newton's stopping test: the gradient `g` at most this fraction of `|m|_F`. At a rotation `eps`
/// from the optimum `|g| ~ (s_j + s_k) eps`, so a well-conditioned `m` stops within about `1e-14`
/// rad of it; directions in which `m` is flat (a rank-one `m`: rotations about its one axis) have
/// `g ~ 0`, and any rotation along them is as good.
const NEWTON_GRADIENT: f64 = 1e-14;

/// A Newton step at most this long (radians) is the last: by quadratic convergence the rotation is
/// then within about `1e-14` of the optimum in the stiff directions.
const NEWTON_LAST_STEP: f64 = 1e-7;

/// The rotation maximizing `tr(R^T m)` by Newton's method on the rotation group from the rotation
/// `guess`, or `None` when it does not converge within [`NEWTON_STEPS`] steps (or takes a step
/// over 1 rad, or ends where the unshifted Hessian is not positive definite: signs of a start too
/// far away or of a point that is not the maximum).
///
/// At `R`, with `M = R^T m`, `f(R exp[w]x) = f(R) + w.g - w^T H w / 2 + O(|w|^3)` with
/// `g = (M_32 - M_23, M_13 - M_31, M_21 - M_12)` and `H = tr(M) I - sym(M)`, so the step is
/// `w = H^-1 g` (`H` shifted by [`NEWTON_SHIFTS`] where it is not definite). `f` is the quadratic
/// form `q^T N q` of Horn's 4x4 matrix on unit quaternions, whose only local maximum is the global
/// one: a stationary point with `H` positive definite is the answer. The rotation is kept as a
/// quaternion, so it stays orthonormal to rounding.
fn newton_rotation(m: &Mat3, guess: &Mat3) -> Option<Mat3> {
    let scale = m.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    let mut q = quaternion_of(guess);
    for _ in 0..NEWTON_STEPS {
        let r = rotation_of(q);
        let a = matmul_tn(&r, m);
        let g = [a[2][1] - a[1][2], a[0][2] - a[2][0], a[1][0] - a[0][1]];
        let t = a[0][0] + a[1][1] + a[2][2];
        let (h01, h02, h12) =
            (-0.5 * (a[0][1] + a[1][0]), -0.5 * (a[0][2] + a[2][0]), -0.5 * (a[1][2] + a[2][1]));
        let mut step = None;
        for (k, shift) in NEWTON_SHIFTS.iter().enumerate() {
            let (h00, h11, h22) =
                (t - a[0][0] + shift * scale, t - a[1][1] + shift * scale, t - a[2][2] + shift * scale);
            // Positive definite iff the leading minors are positive; then w = adj(H) g / det(H).
            let c00 = h11 * h22 - h12 * h12;
            let c01 = h02 * h12 - h01 * h22;
            let c02 = h01 * h12 - h02 * h11;
            let minor2 = h00 * h11 - h01 * h01;
            let det = h00 * c00 + h01 * c01 + h02 * c02;
            if h00 > 0.0 && minor2 > 0.0 && det > 0.0 {
                step = Some((k, [h00, h22, c00, c01, c02, minor2, det]));
                break;
            }
        }
        let (shifted, [h00, h22, c00, c01, c02, minor2, det]) = step?;
        if dot(g, g) <= (NEWTON_GRADIENT * scale) * (NEWTON_GRADIENT * scale) {
            // Stationary; the maximum if H is definite (with the least shift).
            return (shifted == 0).then_some(r);
        }
        let c11 = h00 * h22 - h02 * h02;
        let c12 = h01 * h02 - h00 * h12;
        let inverse = 1.0 / det;
        let w = [
            (c00 * g[0] + c01 * g[1] + c02 * g[2]) * inverse,
            (c01 * g[0] + c11 * g[1] + c12 * g[2]) * inverse,
            (c02 * g[0] + c12 * g[1] + minor2 * g[2]) * inverse,
        ];
        let step2 = dot(w, w);
        if !(step2 <= 1.0) {
            return None;
        }
        // q <- q (1, w / 2): R <- R exp[w]x to third order, then normalized.
        let (x, y, z) = (0.5 * w[0], 0.5 * w[1], 0.5 * w[2]);
        let next = [
            q[0] - q[1] * x - q[2] * y - q[3] * z,
            q[1] + q[0] * x + q[2] * z - q[3] * y,
            q[2] + q[0] * y + q[3] * x - q[1] * z,
            q[3] + q[0] * z + q[1] * y - q[2] * x,
        ];
        let len = next.iter().map(|v| v * v).sum::<f64>().sqrt();
        q = next.map(|v| v / len);
        if step2 <= NEWTON_LAST_STEP * NEWTON_LAST_STEP && shifted == 0 {
            return Some(rotation_of(q));
        }
    }
    None
}

/// The rotation of the unit quaternion `q = (w, x, y, z)`.
pub(crate) fn rotation_of(q: [f64; 4]) -> Mat3 {
    let [w, x, y, z] = q;
    [
        [w * w + x * x - y * y - z * z, 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
        [2.0 * (x * y + w * z), w * w - x * x + y * y - z * z, 2.0 * (y * z - w * x)],
        [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), w * w - x * x - y * y + z * z],
    ]
}

/// A unit quaternion of the rotation `r` (Shepperd: from the largest of `1 + tr` and the
/// diagonal's, so no small divisor).
pub(crate) fn quaternion_of(r: &Mat3) -> [f64; 4] {
    let t = r[0][0] + r[1][1] + r[2][2];
    let q = if t >= r[0][0].max(r[1][1]).max(r[2][2]) {
        let w = (1.0 + t).max(0.0).sqrt() * 2.0;
        [w / 4.0, (r[2][1] - r[1][2]) / w, (r[0][2] - r[2][0]) / w, (r[1][0] - r[0][1]) / w]
    } else if r[0][0] >= r[1][1] && r[0][0] >= r[2][2] {
        let x = (1.0 + r[0][0] - r[1][1] - r[2][2]).max(0.0).sqrt() * 2.0;
        [(r[2][1] - r[1][2]) / x, x / 4.0, (r[0][1] + r[1][0]) / x, (r[0][2] + r[2][0]) / x]
    } else if r[1][1] >= r[2][2] {
        let y = (1.0 + r[1][1] - r[0][0] - r[2][2]).max(0.0).sqrt() * 2.0;
        [(r[0][2] - r[2][0]) / y, (r[0][1] + r[1][0]) / y, y / 4.0, (r[1][2] + r[2][1]) / y]
    } else {
        let z = (1.0 + r[2][2] - r[0][0] - r[1][1]).max(0.0).sqrt() * 2.0;
        [(r[1][0] - r[0][1]) / z, (r[0][2] + r[2][0]) / z, (r[1][2] + r[2][1]) / z, z / 4.0]
    };
    let len = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    if len > 0.0 && len.is_finite() {
        q.map(|v| v / len)
    } else {
        [1.0, 0.0, 0.0, 0.0]
    }
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

    /// Random 3x3 matrices: `rotation * diag(s) * rotation`, with a sign flip for reflections.
    fn sample(seed: u64, singular: [f64; 3]) -> Mat3 {
        let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15).wrapping_add(1);
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut axis = || [2.0 * next() - 1.0, 2.0 * next() - 1.0, 2.0 * next() - 1.0];
        let (a, b) = (axis(), axis());
        let (u, v) = (rot(a, 3.0 * norm(a)), rot(b, 3.0 * norm(b)));
        let d = [[singular[0], 0.0, 0.0], [0.0, singular[1], 0.0], [0.0, 0.0, singular[2]]];
        matmul(&u, &matmul(&d, &v))
    }

    #[test]
    fn quaternions_and_rotations_round_trip() {
        for seed in 0..40 {
            let r = rot([seed as f64 - 20.0, 1.0, -2.0], 0.16 * seed as f64);
            assert!(max_diff(&rotation_of(quaternion_of(&r)), &r) < 1e-14, "seed {seed}");
        }
    }

    #[test]
    fn the_rotation_near_the_last_one_is_the_closest_rotation() {
        // Well conditioned, planar (rank two), reflections, nearly equal singular values, widely
        // spread ones, rank one: from a nearby rotation (the ARAP case) and from far ones.
        let spectra = [
            [3.0, 2.0, 1.0],
            [2.0, 1.0, 0.0],
            [1.0, 0.5, -0.2],
            [1.0, 1.0, 1.0 - 1e-9],
            [1.0, 1e-3, 1e-4],
            [1.0, 0.0, 0.0],
        ];
        for (k, singular) in spectra.iter().enumerate() {
            for seed in 0..50 {
                let m = sample(100 * k as u64 + seed, *singular);
                let best = closest_rotation(&m);
                let near = matmul(&best, &rot([1.0, seed as f64, 2.0], 0.05));
                for (start, previous) in [near, IDENTITY, rot([0.0, 1.0, 0.0], 3.1)].into_iter().enumerate() {
                    let mut frame = IDENTITY;
                    let got = closest_rotation_near(&m, &previous, &mut frame);
                    assert!((det(&got) - 1.0).abs() < 1e-12);
                    // Optimal: R^T m symmetric (stationary on SO(3)) and tr(R^T m) the largest value
                    // (the other stationary rotations have lower ones). Rank one has many optima.
                    let rtm = matmul_tn(&got, &m);
                    let asymmetry =
                        (0..9).map(|i| (rtm[i / 3][i % 3] - rtm[i % 3][i / 3]).abs()).fold(0.0, f64::max);
                    // Newton is accurate to rounding; the Jacobi SVD fallback, working on
                    // m^T m, to about 1e-11 when the singular values spread over 1e4.
                    let by_newton = newton_rotation(&m, &previous).is_some();
                    // From a rotation 0.05 rad away, as in ARAP's iterations, Newton answers
                    // (except where the best rotation is not unique).
                    assert!(
                        by_newton || start != 0 || k == 5,
                        "{singular:?} seed {seed}: near start refused"
                    );
                    let bound = if by_newton { 1e-13 } else { 1e-10 };
                    assert!(asymmetry < bound, "{singular:?} seed {seed}: R^T m asymmetric by {asymmetry:e}");
                    let value = |r: &Mat3| -> f64 { (0..9).map(|i| r[i / 3][i % 3] * m[i / 3][i % 3]).sum() };
                    assert!(value(&got) >= value(&best) - 1e-12, "{singular:?} seed {seed}: not optimal");
                    // Where the Jacobi SVD of m^T m is itself accurate, the two agree.
                    if k < 4 {
                        assert!(
                            max_diff(&got, &best) < 1e-10,
                            "{singular:?} seed {seed}: {got:?} vs {best:?}"
                        );
                    }
                }
            }
        }
    }
}
