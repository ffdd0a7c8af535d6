//! The contact frame from a contact normal (MuJoCo's `mju_makeFrame` convention, so that frames
//! compare with MuJoCo's `contact.frame`): rows (normal, tangent1, tangent2), tangent1 the
//! collision function's hint (a capsule's axis) made orthogonal to the normal, or else world y —
//! or world z when the normal is within 60° of y — made orthogonal; tangent2 = normal × tangent1.

use crate::spatial::{Mat3, Vec3};

/// The frame with rows (n, t₁, t₂) for unit normal `n` and an optional tangent hint.
pub fn contact_frame(n: &Vec3, hint: Option<&Vec3>) -> Mat3 {
    let mut t1 = match hint {
        Some(h) if h.norm_squared() >= 0.25 => *h,
        _ if n.y.abs() < 0.5 => Vec3::new(0.0, 1.0, 0.0),
        _ => Vec3::new(0.0, 0.0, 1.0),
    };
    t1 -= n * n.dot(&t1);
    if t1.norm() < 1e-15 {
        // A hint along the normal (a capsule standing on a plane): MuJoCo's mju_normalize3 makes
        // the vanished tangent (1, 0, 0). Kept orthogonal to n here, and where x is along n too
        // (MuJoCo's frame is then degenerate) the hint-free choice.
        t1 = Vec3::x() - n * n.x;
        if t1.norm() < 0.5 {
            t1 = if n.y.abs() < 0.5 { Vec3::y() } else { Vec3::z() };
            t1 -= n * n.dot(&t1);
        }
    }
    t1.normalize_mut();
    let t2 = n.cross(&t1);
    Mat3::from_rows(&[n.transpose(), t1.transpose(), t2.transpose()])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_follow_mujoco() {
        // Normal +z: tangent1 = y, tangent2 = z × y = −x (MuJoCo's frame for a floor contact).
        let f = contact_frame(&Vec3::z(), None);
        assert_eq!(f.row(1).transpose(), Vec3::y());
        assert_eq!(f.row(2).transpose(), -Vec3::x());
        let n = Vec3::new(0.3, 0.8, -0.2).normalize();
        let f = contact_frame(&n, None);
        assert!((f * f.transpose() - Mat3::identity()).amax() < 1e-15 && f.determinant() > 0.0);
        let f = contact_frame(&Vec3::z(), Some(&Vec3::new(1.0, 0.0, 0.3)));
        assert!((f.row(1).transpose() - Vec3::x()).norm() < 1e-15);
        // A hint along the normal (a capsule standing on a floor): MuJoCo's frame (z, x, y).
        let f = contact_frame(&Vec3::z(), Some(&Vec3::z()));
        assert_eq!((f.row(1).transpose(), f.row(2).transpose()), (Vec3::x(), Vec3::y()));
        // Along x too: still orthonormal, no NaN.
        let f = contact_frame(&Vec3::x(), Some(&Vec3::x()));
        assert!((f * f.transpose() - Mat3::identity()).amax() < 1e-15 && f.determinant() > 0.0);
    }
}
