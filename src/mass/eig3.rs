//! The principal axes of a symmetric 3×3 tensor as MuJoCo's compiler orients them (`mjuu_eig3`,
//! user_util.cc): cyclic Jacobi rotations, each about the axis of the largest off-diagonal entry,
//! accumulated as quaternions from the identity, then the moments sorted in decreasing order by
//! quarter turns. The orientation (not only the axes) is MuJoCo's, signs included, which is what
//! a body's inertial frame (`body_iquat`, and the sensors reading it) and a mesh's collision
//! vertices (stored in its inertial frame) need.
//!
//! Two stopping rules, each matched against the live MuJoCo 4.0 ([`Eig3Rule`]): bodies sweep until
//! the off-diagonal entries are round-off (`body_iquat` to 2e-16, tests/data/mjcf/sensors/
//! frames.xml); meshes stop as MuJoCo 4.0's mesh compiler does — when the largest off-diagonal
//! entry is below 1e-7 of the tensor's largest diagonal entry, however small the rotation it would
//! take — and sort the moments only where they differ by more than 1e-7 of it, with its
//! quaternion normalization (`mjuu_normvec`), so that the `f32` vertices round as MuJoCo's
//! (`mesh_quat` within 5e-14 on 224 Menagerie meshes and scales, the Robotiq 2F-85's among them,
//! where an earlier rule — stopping at a rotation closer than 1e-12 to none, sorting by an
//! absolute 1e-12 — left 1e-7 to 3e-6 rad between them on many, and small meshes with their
//! moments unsorted; tests/mujoco_sameframe.rs). The half-angle of each rotation comes from its
//! tangent (√((1 − cos)/2) cancels to zero below 1e-8 rad).

use crate::spatial::{quat_to_matrix, Mat3};

/// A quaternion `[w, x, y, z]`.
pub(crate) type Quat = [f64; 4];

/// How the sweeps stop, how the moments are sorted and how quaternions are normalized.
pub(crate) struct Eig3Rule {
    /// Stop when the largest off-diagonal entry is below this fraction of a diagonal entry.
    off_rel: f64,
    /// That diagonal entry is the tensor's own largest, and two moments are swapped only when they
    /// differ by more than `off_rel` of it (true); or it is the larger of the two the entry
    /// couples in the rotated tensor, and moments are swapped when they differ by more than 1e-12
    /// (false).
    of_input: bool,
    /// Normalize as `mjuu_normvec` (left alone within 1e-14 of unit length) instead of dividing.
    compiler_normalization: bool,
    /// The cosine of the sorting quarter turns.
    quarter: f64,
}

/// `body_iquat`: sweeps to round-off.
pub(crate) const BODY: Eig3Rule = Eig3Rule {
    off_rel: 1e-16,
    of_input: false,
    compiler_normalization: false,
    quarter: std::f64::consts::FRAC_1_SQRT_2,
};

/// A mesh's inertial frame (`mesh_quat`), as MuJoCo 4.0's mesh compiler stops.
pub(crate) const MESH: Eig3Rule = Eig3Rule {
    off_rel: 1e-7,
    of_input: true,
    compiler_normalization: true,
    // MuJoCo's literal (1e-16 from FRAC_1_SQRT_2): the quaternion follows it to the bit.
    #[allow(clippy::approx_constant)]
    quarter: 0.707106781186548,
};

/// The Hamilton product a ⊗ b (MuJoCo's `mju_mulQuat`).
pub(crate) fn mul_quat(a: &Quat, b: &Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// q / |q|, the identity for a zero quaternion (MuJoCo's `mju_normalize4`).
pub(crate) fn normalize_quat(q: &[f64]) -> Quat {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if n < 1e-15 || !n.is_finite() {
        [1.0, 0.0, 0.0, 0.0]
    } else {
        [q[0] / n, q[1] / n, q[2] / n, q[3] / n]
    }
}

/// MuJoCo's compiler normalization (`mjuu_normvec`: left alone within 1e-14 of unit length).
fn normvec(q: Quat) -> Quat {
    let n = q.iter().map(|a| a * a).sum::<f64>();
    if n < 1e-14 {
        return q;
    }
    let n = n.sqrt();
    if (n - 1.0).abs() > 1e-14 {
        q.map(|a| a / n)
    } else {
        q
    }
}

/// The orientation of the principal axes of `inertia`, moments in decreasing order.
pub(crate) fn principal_quat(inertia: &Mat3, rule: &Eig3Rule) -> Quat {
    let normalize = |q: Quat| if rule.compiler_normalization { normvec(q) } else { normalize_quat(&q) };
    let mut quat: Quat = [1.0, 0.0, 0.0, 0.0];
    let mut eig = [0.0; 3];
    let input_scale = inertia[(0, 0)].abs().max(inertia[(1, 1)].abs()).max(inertia[(2, 2)].abs());
    for _ in 0..500 {
        let e = quat_to_matrix(quat[0], quat[1], quat[2], quat[3]);
        let d = e.transpose() * inertia * e;
        eig = [d[(0, 0)], d[(1, 1)], d[(2, 2)]];
        let (rk, ck, rotk) = if d[(0, 1)].abs() > d[(0, 2)].abs() && d[(0, 1)].abs() > d[(1, 2)].abs() {
            (0, 1, 2)
        } else if d[(0, 2)].abs() > d[(1, 2)].abs() {
            (0, 2, 1)
        } else {
            (1, 2, 0)
        };
        let off = d[(rk, ck)];
        let scale = if rule.of_input { input_scale } else { d[(rk, rk)].abs().max(d[(ck, ck)].abs()) };
        if off.abs() < rule.off_rel * scale || off == 0.0 {
            break;
        }
        let tau = (d[(ck, ck)] - d[(rk, rk)]) / (2.0 * off);
        let t = if tau >= 0.0 {
            1.0 / (tau + (1.0 + tau * tau).sqrt())
        } else {
            -1.0 / (-tau + (1.0 + tau * tau).sqrt())
        };
        let (s, c) = (0.5 * t.atan()).sin_cos();
        let mut r = [c, 0.0, 0.0, 0.0];
        r[rotk + 1] = if rotk == 1 { s } else { -s };
        let r = if rule.compiler_normalization { normvec(r) } else { r };
        quat = normalize(mul_quat(&quat, &r));
    }
    let eps = if rule.of_input { rule.off_rel * input_scale } else { 1e-12 };
    for j in 0..3 {
        let j1 = j % 2;
        if eig[j1] + eps < eig[j1 + 1] {
            eig.swap(j1, j1 + 1);
            let mut r = [rule.quarter, 0.0, 0.0, 0.0];
            r[(j1 + 2) % 3 + 1] = rule.quarter;
            quat = normalize(mul_quat(&quat, &r));
        }
    }
    quat
}
