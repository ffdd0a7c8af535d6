//! Geoms and sites that share their body's frame or inertial frame, placed as MuJoCo places them
//! (docs/multiccd.md, "The contact scenes still differing").
//!
//! MuJoCo's compiler marks a geom or a site whose frame lies within 1e-6 (`kFrameEps`, every
//! position and quaternion component, either quaternion sign) of its body's frame or of its body's
//! inertial frame (`geom_sameframe`, `site_sameframe`: `setSameframe`, engine_setconst.c), and
//! `mj_local2Global` (engine_core_util.c) then poses it at run time from the body's pose instead of
//! composing its own offset:
//! - `BODY` (position and rotation near the body's): the body's pose `xpos`, `xmat`;
//! - `BODYROT` (rotation alone): the body's rotation, its own position composed;
//! - `INERTIA` (position and rotation near the inertial frame's `body_ipos`, `body_iquat`): the
//!   body's inertial pose `xipos`, `ximat`;
//! - `INERTIAROT` (rotation alone): the inertial rotation, its own position composed.
//!
//! The geom's frame is MuJoCo's: a mesh geom's is its file pose moved to the mesh's inertial frame
//! (`mesh_pos`, `mesh_quat`; [`crate::collision::mesh_graph::MeshGraph::box_frame`]), where
//! MuJoCo's compiler stores the vertices. A body whose inertia comes from a single geom copies
//! that geom's frame as its inertial frame (`mjCBody::InertiaFromGeom`, user_objects.cc), so such a
//! geom is `INERTIA` and keeps its pose exactly; a body with several geoms finds its principal
//! frame by an eigen-solve, which can leave a geom 1e-7 rad from it (the Robotiq 2F-85's links):
//! MuJoCo collides that geom at the principal frame.
//!
//! lagrange places a geom by a fixed pose in its compiled body (`Geom::x_body_geom`) and a site by
//! its frame's (`Frame::x_body_frame`); [`placed`] gives the pose in the MuJoCo body that the flag
//! asks for, so that every later reader (collision, rays, sensors) sees MuJoCo's pose.

pub use crate::model::SameFrame;
use crate::sensor::objects::rot_quat;
use crate::spatial::{quat_to_matrix, Transform, Vec3};

/// MuJoCo's difference below which its compiler takes two frames as one (`kFrameEps`).
pub const FRAME_EPS: f64 = 1e-6;

/// Whether every component of `a` is within [`FRAME_EPS`] of `b`'s.
fn same_vec(a: &Vec3, b: &Vec3) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() < FRAME_EPS)
}

/// Whether `a` is within [`FRAME_EPS`] of `b` or of `−b`, component by component.
fn same_quat(a: &[f64; 4], b: &[f64; 4]) -> bool {
    (0..4).all(|k| (a[k] - b[k]).abs() < FRAME_EPS) || (0..4).all(|k| (a[k] + b[k]).abs() < FRAME_EPS)
}

/// MuJoCo's flag of a geom or site with frame `local` in its body (position, rotation), the body's
/// inertial frame being (`ipos`, `iquat`), tested in `setSameframe`'s order.
pub fn classify(local: &Transform, ipos: &Vec3, iquat: &[f64; 4]) -> SameFrame {
    let q = rot_quat(&local.rot);
    let unit = [1.0, 0.0, 0.0, 0.0];
    if same_quat(&q, &unit) {
        if same_vec(&local.pos, &Vec3::zeros()) {
            SameFrame::Body
        } else {
            SameFrame::BodyRot
        }
    } else if same_quat(&q, iquat) {
        if same_vec(&local.pos, ipos) {
            SameFrame::Inertia
        } else {
            SameFrame::InertiaRot
        }
    } else {
        SameFrame::None
    }
}

/// The frame `mj_local2Global` poses a geom or site of flag `flag` at, in its body: `local` (its
/// own frame in the body) with the position and rotation the flag takes from the body's frame
/// (the identity) or from its inertial frame (`ipos`, `iquat`).
pub fn placed(flag: SameFrame, local: &Transform, ipos: &Vec3, iquat: &[f64; 4]) -> Transform {
    let irot = || quat_to_matrix(iquat[0], iquat[1], iquat[2], iquat[3]);
    match flag {
        SameFrame::None => *local,
        SameFrame::Body => Transform::identity(),
        SameFrame::BodyRot => Transform::new(crate::spatial::Mat3::identity(), local.pos),
        SameFrame::Inertia => Transform::new(irot(), *ipos),
        SameFrame::InertiaRot => Transform::new(irot(), local.pos),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::Mat3;

    fn rot_x(a: f64) -> Mat3 {
        let (s, c) = a.sin_cos();
        Mat3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
    }

    #[test]
    fn frames_within_the_tolerance_take_the_body_or_inertial_frame() {
        let ipos = Vec3::new(0.1, 0.2, 0.3);
        let iquat = [0.8f64.cos(), 0.8f64.sin(), 0.0, 0.0]; // 1.6 rad about x
        let near_body = Transform::new(rot_x(1e-7), Vec3::new(4e-7, 0.0, -4e-7));
        assert_eq!(classify(&near_body, &ipos, &iquat), SameFrame::Body);
        assert_eq!(placed(SameFrame::Body, &near_body, &ipos, &iquat), Transform::identity());
        let body_rot = Transform::new(rot_x(1e-7), Vec3::new(0.5, 0.0, 0.0));
        assert_eq!(classify(&body_rot, &ipos, &iquat), SameFrame::BodyRot);
        let p = placed(SameFrame::BodyRot, &body_rot, &ipos, &iquat);
        assert_eq!((p.rot, p.pos), (Mat3::identity(), body_rot.pos));
        let near_inertial = Transform::new(rot_x(1.6 + 2e-7), ipos + Vec3::new(0.0, 3e-7, 0.0));
        assert_eq!(classify(&near_inertial, &ipos, &iquat), SameFrame::Inertia);
        let p = placed(SameFrame::Inertia, &near_inertial, &ipos, &iquat);
        assert_eq!(p.pos, ipos);
        assert!((p.rot - rot_x(1.6)).amax() < 1e-15);
        let inertial_rot = Transform::new(rot_x(1.6 - 2e-7), Vec3::new(0.0, 0.0, 1.0));
        assert_eq!(classify(&inertial_rot, &ipos, &iquat), SameFrame::InertiaRot);
        assert_eq!(placed(SameFrame::InertiaRot, &inertial_rot, &ipos, &iquat).pos, Vec3::new(0.0, 0.0, 1.0));
        // 1e-5 rad from the body's rotation (5e-6 in a quaternion component): its own frame.
        let apart = Transform::new(rot_x(1e-5), Vec3::zeros());
        assert_eq!(classify(&apart, &ipos, &iquat), SameFrame::None);
        assert_eq!(placed(SameFrame::None, &apart, &ipos, &iquat), apart);
        // The other sign of the same rotation (a turn of 2π) is the same frame.
        let turned = Transform::new(rot_x(2.0 * std::f64::consts::PI + 1.6), ipos);
        assert_eq!(classify(&turned, &ipos, &iquat), SameFrame::Inertia);
    }
}
