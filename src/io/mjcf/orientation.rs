//! MJCF orientations (MuJoCo's `ResolveOrientation`): `quat` (w x y z, normalized), `axisangle`,
//! `euler` with `compiler eulerseq` (lower case: rotating axes, post-multiplied; upper case: fixed
//! axes, pre-multiplied), `xyaxes` (y made orthogonal to x, z = x × y) and `zaxis` (the shortest
//! rotation taking z to the given axis). Angles follow `compiler angle` (degrees by default).

use super::attrs::Attrs;
use crate::io::LoadError;
use crate::spatial::{quat_to_matrix, Mat3, Vec3};

/// Angle unit and Euler sequence of `<compiler>`.
#[derive(Clone, Debug)]
pub struct AngleConvention {
    /// Multiply angles by this to get radians (π/180 for degrees, 1 for radians).
    pub to_radians: f64,
    /// Three of x y z X Y Z.
    pub eulerseq: [u8; 3],
}

impl AngleConvention {
    /// `x` in radians, computed as MuJoCo's compiler does (`x / 180 · π` for degrees).
    pub fn radians(&self, x: f64) -> f64 {
        if self.to_radians == 1.0 {
            x
        } else {
            x / 180.0 * std::f64::consts::PI
        }
    }
}

impl Default for AngleConvention {
    fn default() -> Self {
        Self { to_radians: std::f64::consts::PI / 180.0, eulerseq: *b"xyz" }
    }
}

const ORIENTATION_ATTRS: [&str; 5] = ["quat", "axisangle", "euler", "xyaxes", "zaxis"];

/// The rotation an element's orientation attributes give (identity if none): MuJoCo's quaternion
/// of them (`ResolveOrientation`, the same arithmetic in the same order, so that a body at the
/// world's top level gets MuJoCo's `xmat` to the bit) as a matrix.
pub fn rotation(a: &Attrs, angles: &AngleConvention) -> Result<Mat3, LoadError> {
    let [w, x, y, z] = orientation_quat(a, angles)?;
    Ok(quat_to_matrix(w, x, y, z))
}

/// The quaternion (w x y z) of an element's orientation attributes, as MuJoCo's compiler makes
/// it (`mjCBody::Compile`: the `quat` normalized; `ResolveOrientation` for the others).
fn orientation_quat(a: &Attrs, angles: &AngleConvention) -> Result<[f64; 4], LoadError> {
    // Two orientations written on one element are an error (as in MuJoCo); one written on the
    // element overrides any a default class supplies.
    let written: Vec<&str> =
        ORIENTATION_ATTRS.iter().copied().filter(|n| a.explicit.iter().any(|e| e == n)).collect();
    if written.len() > 1 {
        return Err(
            a.error(written[1], format!("conflicts with '{}': give only one orientation", written[0]))
        );
    }
    let inherited = ORIENTATION_ATTRS.iter().copied().find(|n| a.has(n));
    let Some(which) = written.first().copied().or(inherited) else { return Ok([1.0, 0.0, 0.0, 0.0]) };
    match which {
        "quat" => {
            let q = a.array::<4>("quat")?.unwrap_or([1.0, 0.0, 0.0, 0.0]);
            unit_quaternion(q).ok_or_else(|| a.error("quat", "is zero; give a nonzero quaternion (w x y z)"))
        }
        "axisangle" => {
            let v = a.array::<4>("axisangle")?.unwrap_or_default();
            let Some(axis) = unit_vector([v[0], v[1], v[2]]) else {
                return Err(a.error("axisangle", "has a zero axis"));
            };
            // Not normalized further (MuJoCo's neither): the kinematics normalize it.
            let half = angles.radians(v[3]) / 2.0;
            let (s, c) = (half.sin(), half.cos());
            Ok([c, s * axis[0], s * axis[1], s * axis[2]])
        }
        "euler" => {
            let e = a.array::<3>("euler")?.unwrap_or_default();
            Ok(euler_quat(&e, angles))
        }
        "xyaxes" => {
            let v = a.array::<6>("xyaxes")?.unwrap_or_default();
            let Some(x) = unit_vector([v[0], v[1], v[2]]) else {
                return Err(a.error("xyaxes", "has a zero x axis"));
            };
            // y made orthogonal to x, then normalized; z = x × y, normalized.
            let d = x[0] * v[3] + x[1] * v[4] + x[2] * v[5];
            let y = [v[3] - x[0] * d, v[4] - x[1] * d, v[5] - x[2] * d];
            let Some(y) = unit_vector(y) else {
                return Err(a.error("xyaxes", "has a y axis parallel to x"));
            };
            let Some(z) = unit_vector(cross(&x, &y)) else {
                return Err(a.error("xyaxes", "has a y axis parallel to x"));
            };
            Ok(frame_quat(&x, &y, &z))
        }
        _ => {
            let z = a.array::<3>("zaxis")?.unwrap_or_default();
            let Some(z) = unit_vector(z) else {
                return Err(a.error("zaxis", "is zero"));
            };
            Ok(z_quat(&z))
        }
    }
}

/// MuJoCo's `mjEPS` (1e-14), its compiler's threshold for a zero norm and for a norm already 1.
const MJ_EPS: f64 = 1e-14;

/// a·a summed left to right, as MuJoCo's compiler (`mjuu_normvec`).
fn squared_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |acc, x| acc + x * x)
}

/// MuJoCo's compiler normalization (`mjuu_normvec`): the vector divided by its norm unless the
/// norm is within 1e-14 of 1. Components too large or too small for that arithmetic (a squared
/// norm that overflows, or below 1e-14) are scaled by the largest first; None when all are zero.
fn normalized<const N: usize>(v: [f64; N]) -> Option<[f64; N]> {
    let sq = squared_norm(&v);
    if sq.is_finite() && sq >= MJ_EPS {
        let n = sq.sqrt();
        return Some(if (n - 1.0).abs() > MJ_EPS { v.map(|x| x / n) } else { v });
    }
    let largest = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(largest > 0.0 && largest.is_finite()) {
        return None;
    }
    let v = v.map(|x| x / largest);
    let n = squared_norm(&v).sqrt();
    Some(v.map(|x| x / n))
}

/// A unit 3-vector along `v` (MuJoCo's `mjuu_normvec`), None when `v` is zero.
fn unit_vector(v: [f64; 3]) -> Option<[f64; 3]> {
    normalized(v)
}

/// b × c (MuJoCo's `mjuu_crossvec`).
fn cross(b: &[f64; 3], c: &[f64; 3]) -> [f64; 3] {
    [b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]]
}

/// The product of two quaternions, normalized (MuJoCo's `mjuu_mulquat`).
fn mul_quat(a: &[f64; 4], b: &[f64; 4]) -> [f64; 4] {
    let q = [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ];
    normalized(q).unwrap_or(q)
}

/// The quaternion of the frame whose axes are x, y, z (MuJoCo's `mjuu_frame2quat`: from the
/// largest of the four, then normalized).
fn frame_quat(x: &[f64; 3], y: &[f64; 3], z: &[f64; 3]) -> [f64; 4] {
    let m = [x, y, z]; // m[column][row]
    let q = if m[0][0] + m[1][1] + m[2][2] > 0.0 {
        let w = 0.5 * (1.0 + m[0][0] + m[1][1] + m[2][2]).sqrt();
        [w, 0.25 * (m[1][2] - m[2][1]) / w, 0.25 * (m[2][0] - m[0][2]) / w, 0.25 * (m[0][1] - m[1][0]) / w]
    } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
        let i = 0.5 * (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt();
        [0.25 * (m[1][2] - m[2][1]) / i, i, 0.25 * (m[1][0] + m[0][1]) / i, 0.25 * (m[2][0] + m[0][2]) / i]
    } else if m[1][1] > m[2][2] {
        let j = 0.5 * (1.0 - m[0][0] + m[1][1] - m[2][2]).sqrt();
        [0.25 * (m[2][0] - m[0][2]) / j, 0.25 * (m[1][0] + m[0][1]) / j, j, 0.25 * (m[2][1] + m[1][2]) / j]
    } else {
        let k = 0.5 * (1.0 - m[0][0] - m[1][1] + m[2][2]).sqrt();
        [0.25 * (m[0][1] - m[1][0]) / k, 0.25 * (m[2][0] + m[0][2]) / k, 0.25 * (m[2][1] + m[1][2]) / k, k]
    };
    normalized(q).unwrap_or(q)
}

/// The shortest rotation taking the z axis to `v` (MuJoCo's `mjuu_z2quat`; `v` need not be unit).
fn z_quat(v: &[f64; 3]) -> [f64; 4] {
    let c = cross(&[0.0, 0.0, 1.0], v);
    let s = squared_norm(&c);
    // MuJoCo leaves an axis of squared norm below 1e-14 as it is, then takes x when its norm
    // is below 1e-10.
    let (axis, s) = if s >= MJ_EPS {
        let n = s.sqrt();
        (if (n - 1.0).abs() > MJ_EPS { c.map(|x| x / n) } else { c }, n)
    } else {
        (c, 0.0)
    };
    let axis = if s < 1e-10 { [1.0, 0.0, 0.0] } else { axis };
    let half = s.atan2(v[2]) / 2.0;
    let (sn, cs) = (half.sin(), half.cos());
    [cs, axis[0] * sn, axis[1] * sn, axis[2] * sn]
}

/// `q` normalized as MuJoCo's compiler does (`mjuu_normvec`), or `None` when it is zero. Components
/// whose squared norm would overflow are scaled by the largest first.
pub fn unit_quaternion(q: [f64; 4]) -> Option<[f64; 4]> {
    normalized(q)
}

/// Rotation about a unit axis.
pub fn axis_angle_matrix(axis: &Vec3, angle: f64) -> Mat3 {
    let (s, c) = (angle / 2.0).sin_cos();
    quat_to_matrix(c, axis.x * s, axis.y * s, axis.z * s)
}

/// The shortest rotation taking the z axis to `v` (a geom's `fromto`: MuJoCo normalizes the
/// direction, then `mjuu_z2quat`).
pub fn z_to_matrix(v: &Vec3) -> Mat3 {
    let u = unit_vector([v.x, v.y, v.z]).unwrap_or([0.0, 0.0, 1.0]);
    let [w, x, y, z] = z_quat(&u);
    quat_to_matrix(w, x, y, z)
}

/// The rotation of Euler angles `e` (in the convention's unit and sequence).
pub(crate) fn euler_matrix(e: &[f64; 3], angles: &AngleConvention) -> Mat3 {
    let [w, x, y, z] = euler_quat(e, angles);
    quat_to_matrix(w, x, y, z)
}

/// The quaternion of Euler angles `e` as MuJoCo's compiler makes it: one rotation per angle,
/// about the rotating axes (lower case, post-multiplied) or the fixed ones (upper case,
/// pre-multiplied), each product normalized, and the result normalized.
fn euler_quat(e: &[f64; 3], angles: &AngleConvention) -> [f64; 4] {
    let mut q = [1.0, 0.0, 0.0, 0.0];
    for (i, &c) in angles.eulerseq.iter().enumerate() {
        let angle = angles.radians(e[i]);
        let mut rot = [(angle / 2.0).cos(), 0.0, 0.0, 0.0];
        let s = (angle / 2.0).sin();
        match c.to_ascii_lowercase() {
            b'x' => rot[1] = s,
            b'y' => rot[2] = s,
            _ => rot[3] = s,
        }
        q = if c.is_ascii_lowercase() { mul_quat(&q, &rot) } else { mul_quat(&rot, &q) };
    }
    normalized(q).unwrap_or(q)
}
