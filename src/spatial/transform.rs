//! Rigid transforms and the Plücker transforms they induce on spatial vectors (RBDA §2.8).

use super::{Force, Mat3, Motion, Vec3};
use nalgebra::UnitQuaternion;
use std::ops::Mul;

/// Pose `x_a_b` of frame b in frame a: a point with coordinates `p_b` in b has coordinates
/// `p_a = rot * p_b + pos` in a. `rot` is the orientation of b's axes in a, `pos` the position of
/// b's origin in a.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Orientation of b's axes in a (columns: b's axes in a's coordinates).
    pub rot: Mat3,
    /// Position of b's origin in a (m).
    pub pos: Vec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self::identity()
    }
}

/// The skew-symmetric matrix `[v]×` with `[v]× w = v × w`.
#[inline]
pub fn skew(v: &Vec3) -> Mat3 {
    Mat3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Rotation matrix of a quaternion given as `[w, x, y, z]` (normalized first), with MuJoCo's
/// arithmetic to the bit (`mju_normalize4`, then `mju_quat2Mat`, engine_util_blas.c and
/// engine_util_spatial.c): a quaternion within 1e-15 of unit norm is used as given, one shorter
/// than 1e-15 is the identity, and the matrix is formed from the ten products `qᵢqⱼ` as MuJoCo
/// 4.0.0's library sums them. Body and
/// geom orientations then equal MuJoCo's to the last bit where its kinematics forms them from the
/// same quaternion (a free body's, a ball joint's), which the tolerance-stopped GJK/EPA of convex
/// contacts is sensitive to (docs/multiccd.md).
///
/// ```
/// use lagrange::spatial::quat_to_matrix;
/// let r = quat_to_matrix(0.0, 0.0, 0.0, 2.0); // a half turn about z, normalized first
/// assert_eq!(r[(0, 0)], -1.0);
/// assert_eq!(r[(1, 1)], -1.0);
/// assert_eq!(r[(2, 2)], 1.0);
/// ```
pub fn quat_to_matrix(w: f64, x: f64, y: f64, z: f64) -> Mat3 {
    let mut q = [w, x, y, z];
    // Summed in pairs, as MuJoCo 4.0.0's compiled `mju_normalize4` (2000 of 2000 random cases).
    let norm = ((q[0] * q[0] + q[1] * q[1]) + (q[2] * q[2] + q[3] * q[3])).sqrt();
    if norm < 1e-15 {
        q = [1.0, 0.0, 0.0, 0.0];
    } else if (norm - 1.0).abs() > 1e-15 {
        let inv = 1.0 / norm;
        for c in &mut q {
            *c *= inv;
        }
    }
    if q == [1.0, 0.0, 0.0, 0.0] {
        return Mat3::identity();
    }
    let (q00, q01, q02, q03) = (q[0] * q[0], q[0] * q[1], q[0] * q[2], q[0] * q[3]);
    let (q11, q12, q13) = (q[1] * q[1], q[1] * q[2], q[1] * q[3]);
    let (q22, q23, q33) = (q[2] * q[2], q[2] * q[3], q[3] * q[3]);
    // The diagonal's sums paired as the live MuJoCo 4.0.0 library rounds them (its compiled
    // `mju_quat2Mat`, checked on 2000 random quaternions; the source's left-to-right sum differs
    // in the last bit on two thirds of them).
    Mat3::new(
        (q00 - q22) + (q11 - q33),
        2.0 * (q12 - q03),
        2.0 * (q13 + q02),
        2.0 * (q12 + q03),
        (q00 + q22) - (q11 + q33),
        2.0 * (q23 - q01),
        2.0 * (q13 - q02),
        2.0 * (q23 + q01),
        (q00 - q22) - (q11 - q33),
    )
}

impl Transform {
    /// The identity: b coincides with a.
    pub fn identity() -> Self {
        Self { rot: Mat3::identity(), pos: Vec3::zeros() }
    }
    /// The pose with orientation `rot` and position `pos`.
    pub fn new(rot: Mat3, pos: Vec3) -> Self {
        Self { rot, pos }
    }
    /// A pure translation by `pos`.
    pub fn from_translation(pos: Vec3) -> Self {
        Self { rot: Mat3::identity(), pos }
    }
    /// Pose from URDF `xyz` and `rpy`: R = Rz(yaw) · Ry(pitch) · Rx(roll) (fixed-axis roll, pitch,
    /// yaw), as the URDF specification defines it.
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Self {
        let rot = nalgebra::Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2]).into_inner();
        Self { rot, pos: Vec3::new(xyz[0], xyz[1], xyz[2]) }
    }
    /// Orientation as a unit quaternion `[w, x, y, z]` with `w ≥ 0`.
    pub fn quat_wxyz(&self) -> [f64; 4] {
        // `from_rotation_matrix` is closed-form (Shepperd's method) and exact for half turns,
        // where the iterative `from_matrix` stalls at the identity.
        let q = UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(self.rot));
        let s = if q.w < 0.0 { -1.0 } else { 1.0 };
        [s * q.w, s * q.i, s * q.j, s * q.k]
    }
    /// The inverse pose `x_b_a`.
    #[inline]
    pub fn inverse(&self) -> Self {
        let rt = self.rot.transpose();
        Self { rot: rt, pos: -(rt * self.pos) }
    }
    /// Coordinates in a of a point given in b.
    #[inline]
    pub fn act_point(&self, p_b: &Vec3) -> Vec3 {
        self.rot * p_b + self.pos
    }
    /// Motion vector from b coordinates to a coordinates (RBDA eq. 2.24, the inverse of `ᵇXₐ`).
    #[inline]
    pub fn act_motion(&self, m_b: &Motion) -> Motion {
        let ang = self.rot * m_b.ang;
        Motion { ang, lin: self.rot * m_b.lin + self.pos.cross(&ang) }
    }
    /// Motion vector from a coordinates to b coordinates (`ᵇXₐ m`).
    #[inline]
    pub fn inv_act_motion(&self, m_a: &Motion) -> Motion {
        let rt = self.rot.transpose();
        Motion { ang: rt * m_a.ang, lin: rt * (m_a.lin - self.pos.cross(&m_a.ang)) }
    }
    /// Force vector from b coordinates to a coordinates (`ᵃX*_b f`, RBDA eq. 2.25).
    #[inline]
    pub fn act_force(&self, f_b: &Force) -> Force {
        let lin = self.rot * f_b.lin;
        Force { ang: self.rot * f_b.ang + self.pos.cross(&lin), lin }
    }
    /// Force vector from a coordinates to b coordinates.
    #[inline]
    pub fn inv_act_force(&self, f_a: &Force) -> Force {
        let rt = self.rot.transpose();
        Force { ang: rt * (f_a.ang - self.pos.cross(&f_a.lin)), lin: rt * f_a.lin }
    }
}

impl Mul for Transform {
    type Output = Transform;
    /// Composition `x_a_b * x_b_c = x_a_c`.
    #[inline]
    fn mul(self, o: Transform) -> Transform {
        Transform { rot: self.rot * o.rot, pos: self.rot * o.pos + self.pos }
    }
}

impl Mul<&Transform> for &Transform {
    type Output = Transform;
    #[inline]
    fn mul(self, o: &Transform) -> Transform {
        Transform { rot: self.rot * o.rot, pos: self.rot * o.pos + self.pos }
    }
}
