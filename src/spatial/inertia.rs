//! Spatial inertia of a rigid body (RBDA §2.13, eq. 2.62–2.63) and articulated-body inertia
//! (RBDA §7.2), with their change of coordinates (RBDA eq. 2.66).

use super::{skew, Force, Mat3, Motion, Transform, Vec3};
use std::ops::AddAssign;

/// Spatial inertia of a rigid body about the origin of the frame it is expressed in, stored
/// compactly as mass `m`, first moment `h = m c` (c the centre of mass) and the rotational inertia
/// about the origin `i_origin = I_c − m [c]×²` (parallel-axis theorem, docs/physics.md (56)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidInertia {
    /// Mass (kg).
    pub mass: f64,
    /// First moment `m c` (kg·m).
    pub h: Vec3,
    /// Rotational inertia about the frame origin (kg·m²).
    pub i_origin: Mat3,
}

impl Default for RigidInertia {
    fn default() -> Self {
        Self::zero()
    }
}

impl RigidInertia {
    /// The inertia of nothing (zero mass).
    pub fn zero() -> Self {
        Self { mass: 0.0, h: Vec3::zeros(), i_origin: Mat3::zeros() }
    }
    /// Whether all ten parameters are zero (the inertia of nothing: every product with it is
    /// zero). The mass is tested first, so a body with mass pays one comparison.
    #[inline]
    pub fn is_zero(&self) -> bool {
        self.mass == 0.0 && self.h == Vec3::zeros() && self.i_origin == Mat3::zeros()
    }
    /// From mass, centre of mass `com` and inertia `i_com` about the centre of mass (same axes).
    pub fn from_com(mass: f64, com: Vec3, i_com: Mat3) -> Self {
        let cx = skew(&com);
        Self { mass, h: com * mass, i_origin: i_com - cx * cx * mass }
    }
    /// Centre of mass (origin if massless).
    pub fn com(&self) -> Vec3 {
        if self.mass > 0.0 {
            self.h / self.mass
        } else {
            Vec3::zeros()
        }
    }
    /// Rotational inertia about the centre of mass, in this frame's axes.
    pub fn i_com(&self) -> Mat3 {
        let c = self.com();
        let cx = skew(&c);
        self.i_origin + cx * cx * self.mass
    }
    /// Momentum `I v` (RBDA eq. 2.63): n = I_o ω + h × v, f = m v − h × ω.
    #[inline]
    pub fn mul_motion(&self, v: &Motion) -> Force {
        Force {
            ang: self.i_origin * v.ang + self.h.cross(&v.lin),
            lin: v.lin * self.mass - self.h.cross(&v.ang),
        }
    }
    /// The same inertia expressed in frame a, given the pose `x_a_b` of its current frame b.
    ///
    /// `I_a = R I_b Rᵀ − ([h']×[p]× + [p]×[h']×) − m [p]×²` with `h' = R h` (RBDA eq. 2.66 on the
    /// 10 parameters); with `[a]×[b]× = b aᵀ − (a·b) 1` the shift is
    /// `−p h'ᵀ − h' pᵀ − m p pᵀ + (2 h'·p + m p·p) 1`, and only the 6 entries of the symmetric
    /// result are computed.
    /// One formula with the kernels' ([`super::fused::transformed`], separate multiply–adds).
    #[inline]
    pub fn transformed(&self, x_a_b: &Transform) -> RigidInertia {
        super::fused::transformed::<super::fused::Separate>(self, x_a_b)
    }
    /// The same body with its density multiplied by `s` (mass, first moment and inertia scale
    /// together; the centre of mass stays).
    pub fn scaled(&self, s: f64) -> RigidInertia {
        RigidInertia { mass: self.mass * s, h: self.h * s, i_origin: self.i_origin * s }
    }
    /// Kinetic energy ½ vᵀ I v.
    #[inline]
    pub fn kinetic_energy(&self, v: &Motion) -> f64 {
        0.5 * v.dot(&self.mul_motion(v))
    }
}

impl AddAssign<&RigidInertia> for RigidInertia {
    fn add_assign(&mut self, o: &RigidInertia) {
        self.mass += o.mass;
        self.h += o.h;
        self.i_origin += o.i_origin;
    }
}

/// A general symmetric 6×6 spatial inertia `[[a, b], [bᵀ, c]]` (angular-first), as articulated
/// bodies have (RBDA §7.2): `a` angular–angular, `b` angular–linear, `c` linear–linear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArticulatedInertia {
    /// Angular–angular block (kg·m²).
    pub a: Mat3,
    /// Angular–linear block (kg·m).
    pub b: Mat3,
    /// Linear–linear block (kg).
    pub c: Mat3,
}

impl Default for ArticulatedInertia {
    fn default() -> Self {
        Self { a: Mat3::zeros(), b: Mat3::zeros(), c: Mat3::zeros() }
    }
}

impl From<&RigidInertia> for ArticulatedInertia {
    fn from(i: &RigidInertia) -> Self {
        let hx = skew(&i.h);
        Self { a: i.i_origin, b: hx, c: Mat3::identity() * i.mass }
    }
}

impl ArticulatedInertia {
    /// `I v`.
    #[inline]
    pub fn mul_motion(&self, v: &Motion) -> Force {
        Force { ang: self.a * v.ang + self.b * v.lin, lin: self.b.tr_mul(&v.ang) + self.c * v.lin }
    }
    /// Subtracts the rank-one update `u uᵀ / d` where `u` is a spatial force (RBDA eq. 7.42 for a
    /// single degree of freedom).
    #[inline]
    pub fn sub_rank_one(&mut self, u: &Force, d_inv: f64) {
        let un = u.ang * d_inv;
        let uf = u.lin * d_inv;
        self.a -= un * u.ang.transpose();
        self.b -= un * u.lin.transpose();
        self.c -= uf * u.lin.transpose();
    }
    /// Adds this inertia, currently in frame b, to `target` expressed in frame a, given `x_a_b`
    /// (the congruence ᵃX*_b I ᵇXₐ, RBDA eq. 2.66): first rotate, then shift the origin by `pos`.
    ///
    /// A rotation about one coordinate axis (a hinge about a principal axis with an unrotated
    /// placement, the common case) is applied as a plane rotation of two rows and two columns
    /// (`coordinate_rotation`), 24 products per 3×3 block instead of 54.
    #[inline]
    pub fn add_transformed_to(&self, x_a_b: &Transform, target: &mut ArticulatedInertia) {
        let r = &x_a_b.rot;
        let turn = |f: fn(&Mat3, f64, f64) -> Mat3, cos: f64, sin: f64| {
            (f(&self.a, cos, sin), f(&self.b, cos, sin), f(&self.c, cos, sin))
        };
        let (a, b, c) = match coordinate_rotation(r) {
            Some((2, cos, sin)) => turn(plane_rotate::<0, 1>, cos, sin),
            Some((0, cos, sin)) => turn(plane_rotate::<1, 2>, cos, sin),
            Some((_, cos, sin)) => turn(plane_rotate::<2, 0>, cos, sin),
            None => {
                let rt = r.transpose();
                (r * self.a * rt, r * self.b * rt, r * self.c * rt)
            }
        };
        let px = skew(&x_a_b.pos);
        // Shift: A'' = A + [p]× Bᵀ + ([p]× Bᵀ)ᵀ + [p]× C [p]×ᵀ,  B'' = B + [p]× C,  C'' = C.
        let pxc = px * c;
        let pxbt = px * b.transpose();
        target.a += a + pxbt + pxbt.transpose() - pxc * px;
        target.b += b + pxc;
        target.c += c;
    }
}

/// If `r` is a rotation about coordinate axis k (column k and row k are eₖ): (k, cos, sin) of its
/// angle, with R eᵢ = cos eᵢ + sin eⱼ for (i, j) = (k + 1, k + 2) mod 3.
#[inline]
fn coordinate_rotation(r: &Mat3) -> Option<(usize, f64, f64)> {
    for (k, i, j) in [(2, 0, 1), (0, 1, 2), (1, 2, 0)] {
        if r[(k, k)] == 1.0 && r[(i, k)] == 0.0 && r[(j, k)] == 0.0 && r[(k, i)] == 0.0 && r[(k, j)] == 0.0 {
            return Some((k, r[(i, i)], r[(j, i)]));
        }
    }
    None
}

/// R M Rᵀ for the plane rotation R of [`coordinate_rotation`] in the plane (I, J): rows I, J of
/// M turn, then columns I, J of the result (RBDA eq. 2.66 with a sparse R).
#[inline]
fn plane_rotate<const I: usize, const J: usize>(m: &Mat3, cos: f64, sin: f64) -> Mat3 {
    let mut out = *m;
    for col in 0..3 {
        let (mi, mj) = (m[(I, col)], m[(J, col)]);
        out[(I, col)] = cos * mi - sin * mj;
        out[(J, col)] = sin * mi + cos * mj;
    }
    for row in 0..3 {
        let (mi, mj) = (out[(row, I)], out[(row, J)]);
        out[(row, I)] = cos * mi - sin * mj;
        out[(row, J)] = sin * mi + cos * mj;
    }
    out
}
