//! Spatial-algebra operations written as chains of multiply–adds, for the hot kernels that are
//! dispatched at run time to a build with fused multiply–add (FMA3) instructions.
//!
//! Rust never contracts `a * b + c` into one instruction by itself, so the operations of
//! [`Transform`], [`RigidInertia`] and [`Motion`] compile to separate multiplies
//! and adds even where the CPU has FMA. These functions take the policy as a type parameter:
//! [`Fused`] rounds a·b + c once (`f64::mul_add`, one instruction inside a function compiled with
//! `#[target_feature(enable = "fma")]`, a slow library call anywhere else — so use it only there),
//! [`Separate`] rounds twice, as the plain operators do. Same formulas as the methods they mirror
//! (RBDA §2.8–2.13: eq. 2.24 for motions, 2.63 for I v, 2.66 for the change of coordinates of an
//! inertia); the results differ from the methods' only by rounding.

use super::{Force, Mat3, Motion, RigidInertia, Transform, Vec3};

/// How `a·b + c` is evaluated.
pub trait MulAdd {
    /// `a·b + c` under this policy.
    fn madd(a: f64, b: f64, c: f64) -> f64;
}

/// One rounding: `f64::mul_add` (an FMA instruction where the caller enables `fma`).
pub struct Fused;
/// Two roundings: `a * b + c`.
pub struct Separate;

impl MulAdd for Fused {
    #[inline(always)]
    fn madd(a: f64, b: f64, c: f64) -> f64 {
        a.mul_add(b, c)
    }
}

impl MulAdd for Separate {
    #[inline(always)]
    fn madd(a: f64, b: f64, c: f64) -> f64 {
        a * b + c
    }
}

/// `c + a · b` for 3-vectors.
#[inline(always)]
fn dot3_acc<A: MulAdd>(a: &Vec3, b: &Vec3, c: f64) -> f64 {
    A::madd(a.z, b.z, A::madd(a.y, b.y, A::madd(a.x, b.x, c)))
}

/// `a · b` for 3-vectors.
#[inline(always)]
pub fn dot3<A: MulAdd>(a: &Vec3, b: &Vec3) -> f64 {
    A::madd(a.z, b.z, A::madd(a.y, b.y, a.x * b.x))
}

/// `r v`.
#[inline(always)]
pub fn mat_vec<A: MulAdd>(r: &Mat3, v: &Vec3) -> Vec3 {
    let row = |i: usize| A::madd(r[(i, 2)], v.z, A::madd(r[(i, 1)], v.y, r[(i, 0)] * v.x));
    Vec3::new(row(0), row(1), row(2))
}

/// `rᵀ v`.
#[inline(always)]
pub fn mat_tr_vec<A: MulAdd>(r: &Mat3, v: &Vec3) -> Vec3 {
    let col = |j: usize| A::madd(r[(2, j)], v.z, A::madd(r[(1, j)], v.y, r[(0, j)] * v.x));
    Vec3::new(col(0), col(1), col(2))
}

/// `r v + c`.
#[inline(always)]
pub fn mat_vec_add<A: MulAdd>(r: &Mat3, v: &Vec3, c: &Vec3) -> Vec3 {
    let row = |i: usize| A::madd(r[(i, 2)], v.z, A::madd(r[(i, 1)], v.y, A::madd(r[(i, 0)], v.x, c[i])));
    Vec3::new(row(0), row(1), row(2))
}

/// `a × b + c`.
#[inline(always)]
pub fn cross_add<A: MulAdd>(a: &Vec3, b: &Vec3, c: &Vec3) -> Vec3 {
    Vec3::new(
        A::madd(a.y, b.z, A::madd(-a.z, b.y, c.x)),
        A::madd(a.z, b.x, A::madd(-a.x, b.z, c.y)),
        A::madd(a.x, b.y, A::madd(-a.y, b.x, c.z)),
    )
}

/// Composition `x_a_b · x_b_c = x_a_c` (as `Transform * Transform`).
#[inline(always)]
pub fn compose<A: MulAdd>(x_a_b: &Transform, x_b_c: &Transform) -> Transform {
    let r = &x_a_b.rot;
    let o = &x_b_c.rot;
    let c0 = mat_vec::<A>(r, &o.column(0).into_owned());
    let c1 = mat_vec::<A>(r, &o.column(1).into_owned());
    let c2 = mat_vec::<A>(r, &o.column(2).into_owned());
    Transform::new(Mat3::from_columns(&[c0, c1, c2]), mat_vec_add::<A>(r, &x_b_c.pos, &x_a_b.pos))
}

/// A motion vector from b coordinates to a coordinates (as [`Transform::act_motion`]).
#[inline(always)]
pub fn act_motion<A: MulAdd>(x_a_b: &Transform, m_b: &Motion) -> Motion {
    let ang = mat_vec::<A>(&x_a_b.rot, &m_b.ang);
    let lin = mat_vec::<A>(&x_a_b.rot, &m_b.lin);
    Motion { lin: cross_add::<A>(&x_a_b.pos, &ang, &lin), ang }
}

/// [`act_motion`] of a pure rotation (ω, 0), a hinge's motion subspace: (R ω, p × R ω).
#[inline(always)]
pub fn act_rotation<A: MulAdd>(x_a_b: &Transform, ang_b: &Vec3) -> Motion {
    let ang = mat_vec::<A>(&x_a_b.rot, ang_b);
    Motion { lin: cross_add::<A>(&x_a_b.pos, &ang, &Vec3::zeros()), ang }
}

/// The power `m · f` (as [`Motion::dot`]).
#[inline(always)]
pub fn dot<A: MulAdd>(m: &Motion, f: &Force) -> f64 {
    dot3_acc::<A>(&m.lin, &f.lin, dot3_acc::<A>(&m.ang, &f.ang, 0.0))
}

/// Momentum `I v` (as [`RigidInertia::mul_motion`], RBDA eq. 2.63).
#[inline(always)]
pub fn mul_motion<A: MulAdd>(i: &RigidInertia, v: &Motion) -> Force {
    let h_x_w = cross_add::<A>(&i.h, &v.ang, &Vec3::zeros());
    let lin = Vec3::new(
        A::madd(v.lin.x, i.mass, -h_x_w.x),
        A::madd(v.lin.y, i.mass, -h_x_w.y),
        A::madd(v.lin.z, i.mass, -h_x_w.z),
    );
    let ang = cross_add::<A>(&i.h, &v.lin, &mat_vec::<A>(&i.i_origin, &v.ang));
    Force { ang, lin }
}

/// The inertia in frame a given the pose `x_a_b` of its frame b (as
/// [`RigidInertia::transformed`], RBDA eq. 2.66 on the 10 parameters): R I Rᵀ, then the shift
/// −p h'ᵀ − h' pᵀ − m p pᵀ + (2 h'·p + m p·p) 1 with h' = R h.
#[inline(always)]
pub fn transformed<A: MulAdd>(i: &RigidInertia, x_a_b: &Transform) -> RigidInertia {
    let r = &x_a_b.rot;
    let p = &x_a_b.pos;
    let m = i.mass;
    let h = mat_vec::<A>(r, &i.h);
    // T = R I; (R I Rᵀ)(i, j) = row i of T · row j of R.
    let t = Mat3::from_columns(&[
        mat_vec::<A>(r, &i.i_origin.column(0).into_owned()),
        mat_vec::<A>(r, &i.i_origin.column(1).into_owned()),
        mat_vec::<A>(r, &i.i_origin.column(2).into_owned()),
    ]);
    let mp = p * m;
    let diag = A::madd(2.0, h.dot(p), mp.dot(p));
    // −p_i h_j − h_i p_j − m p_i p_j = −p_i (h_j + m p_j) − h_i p_j.
    let hm = h + mp;
    let entry = |a: usize, b: usize| {
        let rot = A::madd(t[(a, 2)], r[(b, 2)], A::madd(t[(a, 1)], r[(b, 1)], t[(a, 0)] * r[(b, 0)]));
        A::madd(-p[a], hm[b], A::madd(-h[a], p[b], rot))
    };
    let (xx, yy, zz) = (entry(0, 0) + diag, entry(1, 1) + diag, entry(2, 2) + diag);
    let (xy, xz, yz) = (entry(0, 1), entry(0, 2), entry(1, 2));
    RigidInertia { mass: m, h: hm, i_origin: Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz) }
}
