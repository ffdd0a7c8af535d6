//! Joint models: configuration → transform, motion subspace and velocity-product term
//! (RBDA §4.4, Table 4.1), in MuJoCo's qpos/qvel layout (docs/architecture.md, "Conventions").

use crate::spatial::{quat_to_matrix, Mat3, Motion, Transform, Vec3};

/// The kind of a movable joint, with its axis data in the joint frame. Fixed joints never reach a
/// [`Model`](crate::Model): the compile step fuses them.
#[derive(Clone, Debug, PartialEq)]
pub enum JointKind {
    /// Rotation by q about the unit `axis` (URDF `revolute` and `continuous`, MJCF `hinge`).
    Revolute {
        /// The unit rotation axis in the joint frame.
        axis: Vec3,
        /// URDF `continuous`: a revolute joint without limits, named `continuous` by `info`.
        continuous: bool,
    },
    /// Translation by q along the unit `axis` (URDF `prismatic`, MJCF `slide`).
    Prismatic {
        /// The unit translation axis in the joint frame.
        axis: Vec3,
    },
    /// Six degrees of freedom. q = [x y z qw qx qy qz] (position of the body origin in the parent,
    /// orientation w-first); v = [linear velocity of the body origin in the *parent* frame,
    /// angular velocity in the *body* frame] — MuJoCo's free joint.
    Free,
    /// Three rotational degrees of freedom. q = [qw qx qy qz], v = body-frame angular velocity.
    Ball,
    /// Motion in the plane normal to `normal`: q = [x y θ], the translation `x·axis1 + y·axis2` in
    /// the joint frame followed by a rotation θ about `normal`; v = q̇ (the layout MuJoCo gives a
    /// slide–slide–hinge chain).
    Planar {
        /// The unit direction of the first translation, in the plane.
        axis1: Vec3,
        /// The unit direction of the second translation: `normal × axis1`.
        axis2: Vec3,
        /// The unit plane normal (the rotation axis), in the joint frame.
        normal: Vec3,
    },
}

/// Which coordinate axis a hinge turns about, decided once when the model is compiled so that the
/// kernels dispatch on it instead of comparing the axis's components at every call
/// ([`Model::hinge_axis`](crate::Model::hinge_axis)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HingeAxis {
    /// ±x: only the joint frame's y and z columns turn.
    X,
    /// ±y.
    Y,
    /// ±z.
    Z,
    /// Any other axis, or not a hinge.
    Other,
}

impl JointKind {
    /// The coordinate axis a hinge's unit axis lies along (exactly: ±1 there, 0 elsewhere), if any.
    pub fn hinge_axis(&self) -> HingeAxis {
        match self {
            JointKind::Revolute { axis, .. } if axis.y == 0.0 && axis.z == 0.0 && axis.x.abs() == 1.0 => {
                HingeAxis::X
            }
            JointKind::Revolute { axis, .. } if axis.x == 0.0 && axis.z == 0.0 && axis.y.abs() == 1.0 => {
                HingeAxis::Y
            }
            JointKind::Revolute { axis, .. } if axis.x == 0.0 && axis.y == 0.0 && axis.z.abs() == 1.0 => {
                HingeAxis::Z
            }
            _ => HingeAxis::Other,
        }
    }

    /// Number of position coordinates.
    pub fn nq(&self) -> usize {
        match self {
            JointKind::Revolute { .. } | JointKind::Prismatic { .. } => 1,
            JointKind::Free => 7,
            JointKind::Ball => 4,
            JointKind::Planar { .. } => 3,
        }
    }
    /// Number of velocity coordinates (degrees of freedom).
    pub fn nv(&self) -> usize {
        match self {
            JointKind::Revolute { .. } | JointKind::Prismatic { .. } => 1,
            JointKind::Free => 6,
            JointKind::Ball | JointKind::Planar { .. } => 3,
        }
    }
    /// Type name as `lagrange info` prints it.
    pub fn type_name(&self) -> &'static str {
        match self {
            JointKind::Revolute { continuous: false, .. } => "revolute",
            JointKind::Revolute { continuous: true, .. } => "continuous",
            JointKind::Prismatic { .. } => "prismatic",
            JointKind::Free => "free",
            JointKind::Ball => "ball",
            JointKind::Planar { .. } => "planar",
        }
    }
    /// Neutral configuration (zero displacement, identity quaternions) into `q` (length nq).
    pub fn neutral(&self, q: &mut [f64]) {
        q.fill(0.0);
        match self {
            JointKind::Free => q[3] = 1.0,
            JointKind::Ball => q[0] = 1.0,
            _ => {}
        }
    }

    /// Joint transform `X_J(q)`: pose of the child body frame in the joint frame.
    #[inline]
    pub(crate) fn transform(&self, q: &[f64]) -> Transform {
        match self {
            JointKind::Revolute { axis, .. } => Transform::new(axis_angle(axis, q[0]), Vec3::zeros()),
            JointKind::Prismatic { axis } => Transform::from_translation(axis * q[0]),
            JointKind::Free => {
                Transform::new(quat_to_matrix(q[3], q[4], q[5], q[6]), Vec3::new(q[0], q[1], q[2]))
            }
            JointKind::Ball => Transform::new(quat_to_matrix(q[0], q[1], q[2], q[3]), Vec3::zeros()),
            JointKind::Planar { axis1, axis2, normal } => {
                Transform::new(axis_angle(normal, q[2]), axis1 * q[0] + axis2 * q[1])
            }
        }
    }

    /// Motion subspace columns `S` in child-body coordinates (one per degree of freedom), given the
    /// joint transform `x_j` from `transform`. For free and planar joints the
    /// translational columns are the parent-frame directions seen from the body: `Rᵀ eₖ`.
    #[inline]
    pub fn motion_subspace(&self, x_j: &Transform, s: &mut [Motion]) {
        let z = Vec3::zeros();
        match self {
            JointKind::Revolute { axis, .. } => s[0] = Motion::new(*axis, z),
            JointKind::Prismatic { axis } => s[0] = Motion::new(z, *axis),
            JointKind::Free => {
                for k in 0..3 {
                    // Row k of R is Rᵀ eₖ.
                    let col = x_j.rot.row(k).transpose();
                    s[k] = Motion::new(z, col);
                    s[k + 3] = Motion::new(Vec3::ith(k, 1.0), z);
                }
            }
            JointKind::Ball => {
                for (k, sk) in s.iter_mut().enumerate().take(3) {
                    *sk = Motion::new(Vec3::ith(k, 1.0), z);
                }
            }
            JointKind::Planar { axis1, axis2, normal } => {
                s[0] = Motion::new(z, x_j.rot.tr_mul(axis1));
                s[1] = Motion::new(z, x_j.rot.tr_mul(axis2));
                s[2] = Motion::new(*normal, z);
            }
        }
    }

    /// Velocity-product term `c_J = S̊ q̇` (RBDA eq. 4.40) for joint velocity `v_j = S q̇` in body
    /// coordinates. Only joints whose translation directions turn with the body have one:
    /// d/dt(Rᵀ e) = −ω × Rᵀ e, so c_J = [0; −ω_J × v_J,lin].
    #[inline]
    pub fn bias_motion(&self, v_j: &Motion) -> Motion {
        match self {
            JointKind::Free | JointKind::Planar { .. } => Motion::new(Vec3::zeros(), v_j.lin.cross(&v_j.ang)),
            _ => Motion::zero(),
        }
    }

    /// Configuration integration on the joint's manifold: `q ← q ⊕ v·dt` (MuJoCo's
    /// `mj_integratePos`: quaternions right-multiplied by the exponential of the body-frame
    /// rotation vector, then normalized).
    #[inline]
    pub(crate) fn integrate(&self, q: &mut [f64], v: &[f64], dt: f64) {
        match self {
            JointKind::Revolute { .. } | JointKind::Prismatic { .. } | JointKind::Planar { .. } => {
                for (qi, vi) in q.iter_mut().zip(v) {
                    *qi += vi * dt;
                }
            }
            JointKind::Free => {
                for k in 0..3 {
                    q[k] += v[k] * dt;
                }
                quat_integrate(&mut q[3..7], &v[3..6], dt);
            }
            JointKind::Ball => quat_integrate(&mut q[0..4], &v[0..3], dt),
        }
    }

    /// The rate of the tangent coordinates θ of `q = q0 ⊕ θ` for joint velocity `v` at `q`:
    /// θ̇ = dexp⁻¹(θ) v. Flat coordinates: θ̇ = v. Quaternion parts (body-frame ω, right
    /// trivialization): θ̇ = J_r⁻¹(θ) ω = ω + ½ θ×ω + (1/|θ|² − (1 + cos|θ|)/(2|θ| sin|θ|)) θ×(θ×ω)
    /// (the inverse right Jacobian of SO(3); Iserles, Munthe-Kaas, Nørsett & Zanna, *Lie-group
    /// methods*, Acta Numerica 2000, §2.3 and eq. 3.14 for the RKMK stages that need it).
    pub(crate) fn dexp_inv(&self, theta: &[f64], v: &[f64], out: &mut [f64]) {
        out.copy_from_slice(v);
        match self {
            JointKind::Free => so3_dexp_inv(&theta[3..6], &v[3..6], &mut out[3..6]),
            JointKind::Ball => so3_dexp_inv(&theta[0..3], &v[0..3], &mut out[0..3]),
            _ => {}
        }
    }

    /// The tangent `v` with `q0 ⊕ v = q1` (unit time): the inverse of [`integrate`](Self::integrate).
    pub(crate) fn difference(&self, q0: &[f64], q1: &[f64], v: &mut [f64]) {
        match self {
            JointKind::Revolute { .. } | JointKind::Prismatic { .. } | JointKind::Planar { .. } => {
                for k in 0..v.len() {
                    v[k] = q1[k] - q0[k];
                }
            }
            JointKind::Free => {
                for k in 0..3 {
                    v[k] = q1[k] - q0[k];
                }
                quat_difference(&q0[3..7], &q1[3..7], &mut v[3..6]);
            }
            JointKind::Ball => quat_difference(&q0[0..4], &q1[0..4], &mut v[0..3]),
        }
    }
}

/// out = J_r⁻¹(θ) ω for a rotation vector θ (see [`JointKind::dexp_inv`]); the θ×(θ×ω)
/// coefficient is replaced by its series 1/12 + |θ|²/720 below |θ| = 1e-4.
fn so3_dexp_inv(theta: &[f64], omega: &[f64], out: &mut [f64]) {
    let th = Vec3::new(theta[0], theta[1], theta[2]);
    let w = Vec3::new(omega[0], omega[1], omega[2]);
    let a2 = th.norm_squared();
    let a = a2.sqrt();
    let c2 =
        if a < 1e-4 { 1.0 / 12.0 + a2 / 720.0 } else { 1.0 / a2 - (1.0 + a.cos()) / (2.0 * a * a.sin()) };
    let tw = th.cross(&w);
    let r = w + 0.5 * tw + c2 * th.cross(&tw);
    out.copy_from_slice(r.as_slice());
}

/// Rotation matrix for angle `angle` about unit `axis` (Rodrigues).
#[inline]
pub fn axis_angle(axis: &Vec3, angle: f64) -> Mat3 {
    let (s, c) = libm::sincos(angle);
    let k = crate::spatial::skew(axis);
    Mat3::identity() + k * s + k * k * (1.0 - c)
}

/// The unit quaternion of a joint's coordinates q = [w x y z], normalized as MuJoCo does
/// (`mju_normalize4`): one shorter than 1e-15 (zero, or so small that its norm underflows) is the
/// identity; a non-finite one stays non-finite, for the divergence check to report.
fn to_unit_quat(q: &[f64]) -> nalgebra::UnitQuaternion<f64> {
    let quat = nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]);
    let norm = quat.norm();
    if norm < 1e-15 {
        nalgebra::UnitQuaternion::identity()
    } else {
        nalgebra::UnitQuaternion::new_unchecked(quat / norm)
    }
}

/// q ← normalize(q ⊗ exp(ω dt / 2)), quaternion stored [w x y z].
fn quat_integrate(q: &mut [f64], omega: &[f64], dt: f64) {
    let w = Vec3::new(omega[0], omega[1], omega[2]) * dt;
    let dq = nalgebra::UnitQuaternion::from_scaled_axis(w);
    let r = to_unit_quat(q) * dq;
    q[0] = r.w;
    q[1] = r.i;
    q[2] = r.j;
    q[3] = r.k;
}

/// ω with q0 ⊗ exp(ω/2) = q1 (shortest rotation).
fn quat_difference(q0: &[f64], q1: &[f64], v: &mut [f64]) {
    let d = to_unit_quat(q0).inverse() * to_unit_quat(q1);
    let w = d.scaled_axis();
    v.copy_from_slice(w.as_slice());
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hinge is classed by the coordinate axis it lies along (either sign); a tilted axis, a
    /// near-axis one and every other joint kind are `Other` (they take the general formulas).
    #[test]
    fn hinge_axes_are_classed_exactly() {
        let hinge =
            |x: f64, y: f64, z: f64| JointKind::Revolute { axis: Vec3::new(x, y, z), continuous: false };
        assert_eq!(hinge(1.0, 0.0, 0.0).hinge_axis(), HingeAxis::X);
        assert_eq!(hinge(0.0, -1.0, 0.0).hinge_axis(), HingeAxis::Y);
        assert_eq!(hinge(0.0, 0.0, -1.0).hinge_axis(), HingeAxis::Z);
        assert_eq!(hinge(0.0, 0.6, 0.8).hinge_axis(), HingeAxis::Other);
        assert_eq!(hinge(1e-17, 0.0, 1.0).hinge_axis(), HingeAxis::Other);
        assert_eq!(JointKind::Prismatic { axis: Vec3::z() }.hinge_axis(), HingeAxis::Other);
        assert_eq!(JointKind::Ball.hinge_axis(), HingeAxis::Other);
    }
}
