//! MJCF orientations (MuJoCo's `ResolveOrientation`): `quat` (w x y z, normalized), `axisangle`,
//! `euler` with `compiler eulerseq` (lower case: rotating axes, post-multiplied; upper case: fixed
//! axes, pre-multiplied), `xyaxes` (y made orthogonal to x, z = x × y) and `zaxis` (the shortest
//! rotation taking z to the given axis). Angles follow `compiler angle` (degrees by default).

use super::attrs::Attrs;
use crate::io::LoadError;
use crate::spatial::{quat_to_matrix, Mat3, Vec3};
use nalgebra::{Quaternion, UnitQuaternion};

/// Angle unit and Euler sequence of `<compiler>`.
#[derive(Clone, Debug)]
pub struct AngleConvention {
    /// Multiply angles by this to get radians (π/180 for degrees, 1 for radians).
    pub to_radians: f64,
    /// Three of x y z X Y Z.
    pub eulerseq: [u8; 3],
}

impl Default for AngleConvention {
    fn default() -> Self {
        Self { to_radians: std::f64::consts::PI / 180.0, eulerseq: *b"xyz" }
    }
}

const ORIENTATION_ATTRS: [&str; 5] = ["quat", "axisangle", "euler", "xyaxes", "zaxis"];

/// The rotation an element's orientation attributes give (identity if none).
pub fn rotation(a: &Attrs, angles: &AngleConvention) -> Result<Mat3, LoadError> {
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
    let Some(which) = written.first().copied().or(inherited) else { return Ok(Mat3::identity()) };
    match which {
        "quat" => {
            let q = a.array::<4>("quat")?.unwrap_or([1.0, 0.0, 0.0, 0.0]);
            let Some([w, x, y, z]) = unit_quaternion(q) else {
                return Err(a.error("quat", "is zero; give a nonzero quaternion (w x y z)"));
            };
            Ok(quat_to_matrix(w, x, y, z))
        }
        "axisangle" => {
            let v = a.array::<4>("axisangle")?.unwrap_or_default();
            let axis = Vec3::new(v[0], v[1], v[2]);
            let axis = axis / axis.amax().max(f64::MIN_POSITIVE);
            if axis.norm() < 1e-14 {
                return Err(a.error("axisangle", "has a zero axis"));
            }
            Ok(axis_angle_matrix(&(axis / axis.norm()), v[3] * angles.to_radians))
        }
        "euler" => {
            let e = a.array::<3>("euler")?.unwrap_or_default();
            Ok(euler_matrix(&e, angles))
        }
        "xyaxes" => {
            let v = a.array::<6>("xyaxes")?.unwrap_or_default();
            let x = Vec3::new(v[0], v[1], v[2]);
            let y = Vec3::new(v[3], v[4], v[5]);
            let (x, y) = (x / x.amax().max(f64::MIN_POSITIVE), y / y.amax().max(f64::MIN_POSITIVE));
            let (nx, x) = (x.norm(), x.normalize());
            if nx < 1e-14 {
                return Err(a.error("xyaxes", "has a zero x axis"));
            }
            let y = y - x * x.dot(&y);
            if y.norm() < 1e-14 {
                return Err(a.error("xyaxes", "has a y axis parallel to x"));
            }
            let y = y.normalize();
            let z = x.cross(&y).normalize();
            Ok(Mat3::from_columns(&[x, y, z]))
        }
        _ => {
            let z = a.vec3("zaxis")?.unwrap_or_default();
            let z = z / z.amax().max(f64::MIN_POSITIVE);
            if z.norm() < 1e-14 {
                return Err(a.error("zaxis", "is zero"));
            }
            Ok(z_to_matrix(&z))
        }
    }
}

/// `q` normalized, or `None` when it is zero (below 1e-14 after scaling). It is scaled by its
/// largest component first, so that huge finite components cannot overflow the norm.
pub fn unit_quaternion(q: [f64; 4]) -> Option<[f64; 4]> {
    let largest = q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let q = if largest > 0.0 && largest.is_finite() { q.map(|x| x / largest) } else { q };
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    (n >= 1e-14).then(|| q.map(|x| x / n))
}

/// Rotation about a unit axis.
pub fn axis_angle_matrix(axis: &Vec3, angle: f64) -> Mat3 {
    let (s, c) = (angle / 2.0).sin_cos();
    quat_to_matrix(c, axis.x * s, axis.y * s, axis.z * s)
}

/// The shortest rotation taking the z axis to `v` (MuJoCo's `mjuu_z2quat`).
pub fn z_to_matrix(v: &Vec3) -> Mat3 {
    let v = v.normalize();
    let cross = Vec3::z().cross(&v);
    let s = cross.norm();
    let axis = if s < 1e-10 { Vec3::x() } else { cross / s };
    let angle = s.atan2(v.z);
    axis_angle_matrix(&axis, angle)
}

/// The rotation of Euler angles `e` (in the convention's unit and sequence).
pub(crate) fn euler_matrix(e: &[f64; 3], angles: &AngleConvention) -> Mat3 {
    let mut q = UnitQuaternion::identity();
    for (i, &c) in angles.eulerseq.iter().enumerate() {
        let half = e[i] * angles.to_radians / 2.0;
        let (s, w) = half.sin_cos();
        let axis = match c.to_ascii_lowercase() {
            b'x' => Vec3::new(s, 0.0, 0.0),
            b'y' => Vec3::new(0.0, s, 0.0),
            _ => Vec3::new(0.0, 0.0, s),
        };
        let r = UnitQuaternion::new_unchecked(Quaternion::new(w, axis.x, axis.y, axis.z));
        // Lower case: about the rotating (body) axes; upper case: about the fixed axes.
        q = if c.is_ascii_lowercase() { q * r } else { r * q };
    }
    let q = q.into_inner().normalize();
    quat_to_matrix(q.w, q.i, q.j, q.k)
}
