//! Inertia-tensor algebra of docs/physics.md §2.3 and §3.1–3.2: the parallel-axis shift (eq. 56, in
//! its tensor form), rotation of a tensor into other axes (eq. 81), the principal moments and
//! axes (§3.2, eq. 74) and the principal-axis angle of a planar tensor (eq. 83), and composition
//! of several parts into one body (the sum rule under eq. 50).
//!
//! Tensor entries follow the notes: `I_xx = Σ m (y² + z²)`, `I_xy = −Σ m x y` (eq. 68–69).

use crate::spatial::{Mat3, RigidInertia, Transform, Vec3};

/// Principal moments and axes of an inertia tensor (docs/physics.md §3.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principal {
    /// Principal moments `I₁ ≤ I₂ ≤ I₃` (ascending).
    pub moments: Vec3,
    /// The principal axes as the columns `e₁, e₂, e₃` of a rotation matrix (det = +1), so that
    /// `I = axes · diag(moments) · axesᵀ`.
    pub axes: Mat3,
}

/// Principal moments and axes of the symmetric tensor `i` by symmetric eigen-decomposition,
/// `I = E diag(I₁, I₂, I₃) Eᵀ` (docs/physics.md (74)).
///
/// Deterministic order and sign, so that equal inputs give equal outputs and the axes form a
/// right-handed frame:
/// - moments ascending, `I₁ ≤ I₂ ≤ I₃`;
/// - `e₁` and `e₂` each point so that their component of largest magnitude is positive (the
///   first such component on ties);
/// - `e₃ = e₁ × e₂` (so `det E = +1`; `e₃`'s sign is thereby fixed, not chosen).
///
/// When two moments are equal (a body of revolution) any orthonormal basis of their eigenspace is
/// principal; the one returned is the eigen-solver's, made right-handed as above.
///
/// Only the symmetric part of `i` is used. A tensor with a non-finite entry gives NaN moments
/// (and identity axes) rather than an endless eigen-iteration.
pub fn principal_axes(i: &Mat3) -> (Vec3, Mat3) {
    let p = principal(i);
    (p.moments, p.axes)
}

/// [`principal_axes`] as a [`Principal`].
pub fn principal(i: &Mat3) -> Principal {
    if !i.iter().all(|x| x.is_finite()) {
        return Principal { moments: Vec3::repeat(f64::NAN), axes: Mat3::identity() };
    }
    let sym = (i + i.transpose()) * 0.5;
    let eig = sym.symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let moments = Vec3::new(eig.eigenvalues[order[0]], eig.eigenvalues[order[1]], eig.eigenvalues[order[2]]);
    let canonical = |v: Vec3| {
        let v = v.normalize();
        let mut k = 0;
        for j in 1..3 {
            if v[j].abs() > v[k].abs() {
                k = j;
            }
        }
        if v[k] < 0.0 {
            -v
        } else {
            v
        }
    };
    let e1 = canonical(eig.eigenvectors.column(order[0]).into_owned());
    let mut e2 = canonical(eig.eigenvectors.column(order[1]).into_owned());
    // Re-orthogonalize against e1 (the solver's vectors are orthonormal to round-off already).
    e2 = canonical(e2 - e1 * e1.dot(&e2));
    let e3 = e1.cross(&e2);
    Principal { moments, axes: Mat3::from_columns(&[e1, e2, e3]) }
}

/// The inertia tensor about a point displaced by `r` from the centre of mass, from the tensor
/// `i_com` about the centre of mass (same axes): `I_O = I_C + m (|r|² 1 − r rᵀ)`. Component-wise
/// this is docs/physics.md (56) (`I_z = m l²_CM + I_CM,z`) for each axis, with the products of inertia
/// shifted by `−m r_a r_b` (eq. 69).
pub fn parallel_axis(i_com: &Mat3, mass: f64, r: &Vec3) -> Mat3 {
    i_com + (Mat3::identity() * r.norm_squared() - r * r.transpose()) * mass
}

/// The tensor in frame a of a body whose tensor in frame b is `i_b`, with `r_a_b` the orientation
/// of b's axes in a: `I_a = R I_b Rᵀ`. The rotation (81) of docs/physics.md §3.2 is the inverse direction,
/// `I' = P⁻¹ I P` for new axes given by the columns of `P`.
pub fn rotate_tensor(r_a_b: &Mat3, i_b: &Mat3) -> Mat3 {
    r_a_b * i_b * r_a_b.transpose()
}

/// The angle θ about z that diagonalizes the xy block of a tensor with a principal axis along z
/// (docs/physics.md (80)–(83)): `tan 2θ = 2 I_xy / (I_xx − I_yy)`, taken as `θ = ½ atan2(2 I_xy, I_xx − I_yy)`,
/// so θ ∈ (−π/2, π/2]. The columns of `P` of eq. 81 with this θ are principal axes, and this
/// choice of branch puts the larger in-plane moment, `(I_xx + I_yy)/2 + √(((I_xx − I_yy)/2)² + I_xy²)`,
/// on `(cos θ, sin θ, 0)` (θ = 0 when the block is already isotropic).
pub fn principal_angle_xy(i_xx: f64, i_yy: f64, i_xy: f64) -> f64 {
    0.5 * (2.0 * i_xy).atan2(i_xx - i_yy)
}

/// The mass properties of several parts as one body, in the body frame: each part is given in its
/// own frame with the part's pose `x_body_part` in the body; the sum of the transformed inertias
/// (the sum rule for composite bodies, docs/physics.md §2.3, with eq. 56 and 81 for the shift and
/// rotation).
pub fn compose<'a>(parts: impl IntoIterator<Item = (&'a Transform, &'a RigidInertia)>) -> RigidInertia {
    let mut sum = RigidInertia::zero();
    for (x_body_part, inertia) in parts {
        sum += &inertia.transformed(x_body_part);
    }
    sum
}
