//! The oriented-bounding-box test between the broad and the narrow phase (MuJoCo's
//! `mj_collideOBB`, engine_collision_driver.c, on its `geom_aabb`): each colliding geom's box in
//! its own frame — centre and half-extents of the primitive, or of a mesh's hull vertices along
//! MuJoCo's axes of the mesh (its principal axes, where `geom_aabb` is axis-aligned; the collision
//! pass tries the box along the geom frame's axes too, `CollisionModel::file_box`) — and a
//! separating-axis test of two such boxes at the geoms' world poses ([`WorldBox`], formed at most
//! once per geom and pass): first along the three world axes (the boxes' world-axis-aligned
//! bounds, which reject most far pairs for a few comparisons), then over the 15 axes of two boxes
//! (the 3 face normals of each, the 9 cross products of their edges; Gottschalk, Lin & Manocha,
//! "OBBTree", SIGGRAPH 1996).
//!
//! A pair is rejected only when an axis shows a gap wider than the pair's margin + gap between
//! the boxes' projections; the distance of two convex sets is at least the gap of their
//! projections on any unit axis, so a rejected pair has no contact and the narrow phase's answer
//! for the others is unchanged. It spares the GJK and EPA of mesh pairs whose bounding spheres
//! overlap but whose shapes are far apart (the limbs of a robot, its gripper's fingers).

use crate::model::spec::Shape;
use crate::spatial::{Mat3, Transform, Vec3};

/// A geom's bounding box in its own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalBox {
    /// Centre (geom frame, m).
    pub centre: Vec3,
    /// Half-extents along the box's axes (m).
    pub half: Vec3,
    /// The box's axes in the geom frame (columns; MuJoCo's mesh frame for a mesh, `None` for the
    /// geom's own axes).
    pub axes: Option<Mat3>,
}

impl LocalBox {
    /// The box of a primitive `shape`, or of a mesh geom's `hull` vertices (geom frame) along
    /// the axes of `frame` = (origin, axes) — MuJoCo's mesh frame, where its `geom_aabb` is
    /// axis-aligned (the principal axes hug an elongated mesh far better than the file's); None
    /// for planes, height fields and meshes without a hull.
    pub fn of(shape: &Shape, hull: Option<&[Vec3]>, frame: Option<&(Vec3, Mat3)>) -> Option<Self> {
        let at_origin = |half: Vec3| Some(Self { centre: Vec3::zeros(), half, axes: None });
        match shape {
            Shape::Sphere { radius } => at_origin(Vec3::repeat(*radius)),
            Shape::Capsule { radius, length } => {
                at_origin(Vec3::new(*radius, *radius, 0.5 * length + radius))
            }
            Shape::Cylinder { radius, length } => at_origin(Vec3::new(*radius, *radius, 0.5 * length)),
            Shape::Box { size } => at_origin(size / 2.0),
            Shape::Ellipsoid { radii } => at_origin(*radii),
            Shape::Mesh { .. } => {
                let hull = hull?;
                let (origin, axes) = frame.copied().unwrap_or((Vec3::zeros(), Mat3::identity()));
                let local = |v: &Vec3| axes.tr_mul(&(v - origin));
                let first = local(hull.first()?);
                let (lo, hi) = hull.iter().fold((first, first), |(lo, hi), v| {
                    let u = local(v);
                    (lo.inf(&u), hi.sup(&u))
                });
                let rotated = axes != Mat3::identity();
                Some(Self {
                    centre: origin + axes * ((lo + hi) / 2.0),
                    half: (hi - lo) / 2.0,
                    axes: rotated.then_some(axes),
                })
            }
            Shape::Plane { .. } | Shape::Hfield { .. } => None,
        }
    }
}

/// Added to every |R_ij| so that near-parallel edges (whose cross product vanishes) cannot
/// separate boxes by round-off; it only makes the test more conservative.
const PARALLEL_EPS: f64 = 1e-12;

/// A geom's box at the geom's world pose, formed once per collision pass: its world centre and
/// axes, and the half-extents of the world-axis-aligned box around it (the first, cheapest test
/// of [`WorldBox::apart`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldBox {
    /// Centre (world, m).
    pub centre: Vec3,
    /// The box's axes in world coordinates (columns).
    pub axes: Mat3,
    /// Half-extents along `axes` (m).
    pub half: Vec3,
    /// Half-extents of the world-axis-aligned box that holds it (m): Σ_j |axes_kj| half_j.
    pub extent: Vec3,
}

impl Default for WorldBox {
    fn default() -> Self {
        Self { centre: Vec3::zeros(), axes: Mat3::identity(), half: Vec3::zeros(), extent: Vec3::zeros() }
    }
}

impl WorldBox {
    /// Box `b` of a geom at world pose `x`.
    #[inline]
    pub fn new(b: &LocalBox, x: &Transform) -> Self {
        let axes = match &b.axes {
            Some(a) => x.rot * a,
            None => x.rot,
        };
        let centre = x.act_point(&b.centre);
        let h = &b.half;
        let extent = Vec3::from_fn(|k, _| {
            axes[(k, 0)].abs() * h.x + axes[(k, 1)].abs() * h.y + axes[(k, 2)].abs() * h.z
        });
        Self { centre, axes, half: b.half, extent }
    }

    /// Whether this box and `other` are farther apart than `margin` along a world axis or one
    /// of the 15 separating axes of two boxes (then the geoms cannot touch within `margin`).
    /// The world axes first (the boxes' world-aligned bounds, three comparisons), then the face
    /// normals of each box, then the edge cross products: the rows of the relative rotation are
    /// formed as the tests reach them, so a pair rejected early costs little.
    #[inline]
    pub fn apart(&self, other: &WorldBox, margin: f64) -> bool {
        let d = other.centre - self.centre;
        if d.x.abs() > self.extent.x + other.extent.x + margin
            || d.y.abs() > self.extent.y + other.extent.y + margin
            || d.z.abs() > self.extent.z + other.extent.z + margin
        {
            return true;
        }
        let (u, v) = (&self.axes, &other.axes);
        let (a, b) = (&self.half, &other.half);
        // Box 2 in box 1's axes: rotation r (row i: box 1's axis i against box 2's axes), centre
        // offset t; each row tested as soon as formed (box 1's face normal i).
        let mut r = [[0.0f64; 3]; 3];
        let mut abs = [[0.0f64; 3]; 3];
        let mut t = [0.0f64; 3];
        for i in 0..3 {
            let (ux, uy, uz) = (u[(0, i)], u[(1, i)], u[(2, i)]);
            t[i] = ux * d.x + uy * d.y + uz * d.z;
            for j in 0..3 {
                r[i][j] = ux * v[(0, j)] + uy * v[(1, j)] + uz * v[(2, j)];
                abs[i][j] = r[i][j].abs() + PARALLEL_EPS;
            }
            let rb = b.x * abs[i][0] + b.y * abs[i][1] + b.z * abs[i][2];
            if t[i].abs() > a[i] + rb + margin {
                return true;
            }
        }
        // Box 2's face normals.
        for j in 0..3 {
            let ra = a.x * abs[0][j] + a.y * abs[1][j] + a.z * abs[2][j];
            let tj = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
            if tj.abs() > ra + b[j] + margin {
                return true;
            }
        }
        // Edge cross products A_i × B_j (unnormalised: lengths sin θ_ij, the margin scaled alike).
        for i in 0..3 {
            let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
            for j in 0..3 {
                let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
                let ra = a[i1] * abs[i2][j] + a[i2] * abs[i1][j];
                let rb = b[j1] * abs[i][j2] + b[j2] * abs[i][j1];
                let tl = t[i2] * r[i1][j] - t[i1] * r[i2][j];
                // The margin term is ≥ 0 (for a margin ≥ 0) and rounding is monotone, so the axis
                // can separate only when |tl| exceeds ra + rb + ε: the length's square root is
                // taken for those axes alone, the test itself unchanged.
                let bound = ra + rb;
                if margin < 0.0 || tl.abs() > bound + PARALLEL_EPS {
                    let length = (1.0 - r[i][j] * r[i][j]).max(0.0).sqrt();
                    if tl.abs() > bound + margin * length + PARALLEL_EPS {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// Whether boxes `b1` at pose `x1` and `b2` at pose `x2` are farther apart than `margin` (see
/// [`WorldBox::apart`]).
pub fn apart(b1: &LocalBox, x1: &Transform, b2: &LocalBox, x2: &Transform, margin: f64) -> bool {
    WorldBox::new(b1, x1).apart(&WorldBox::new(b2, x2), margin)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::quat_to_matrix;

    fn pose(pos: [f64; 3], axis: [f64; 3], angle: f64) -> Transform {
        let n = Vec3::from(axis).normalize() * (0.5 * angle).sin();
        let rot = quat_to_matrix((0.5 * angle).cos(), n.x, n.y, n.z);
        Transform { rot, pos: Vec3::from(pos) }
    }

    /// Random box pairs: whenever the test calls two boxes apart, their distance (parry's exact
    /// box–box distance) exceeds the margin.
    #[test]
    fn never_rejects_boxes_within_the_margin() {
        use parry3d_f64::query;
        use parry3d_f64::shape::Cuboid;
        let mut seed = 12345u64;
        let mut rand = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64) / ((1u64 << 53) as f64)
        };
        let mut rejected = 0;
        for _ in 0..20000 {
            let b1 = LocalBox {
                centre: Vec3::new(rand() - 0.5, rand() - 0.5, rand() - 0.5) * 0.2,
                half: Vec3::new(rand(), rand(), rand()) * 0.3 + Vec3::repeat(0.01),
                axes: None,
            };
            // Box 2 along axes of its own in its geom frame (a mesh's principal axes) half the time.
            let axes = pose([0.0; 3], [rand() - 0.5, rand() - 0.5, rand() - 0.5], 6.0 * rand()).rot;
            let b2 = LocalBox {
                centre: Vec3::new(rand() - 0.5, rand() - 0.5, rand() - 0.5) * 0.2,
                half: Vec3::new(rand(), rand(), rand()) * 0.3 + Vec3::repeat(0.01),
                axes: (rand() < 0.5).then_some(axes),
            };
            let x1 = pose([rand(), rand(), rand()], [rand() - 0.5, rand() - 0.5, rand() - 0.5], 6.0 * rand());
            let x2 = pose([rand(), rand(), rand()], [rand() - 0.5, rand() - 0.5, rand() - 0.5], 6.0 * rand());
            let margin = 0.1 * rand();
            if !apart(&b1, &x1, &b2, &x2, margin) {
                continue;
            }
            rejected += 1;
            let to_pose = |x: &Transform, b: &LocalBox| {
                let c = x.act_point(&b.centre);
                let box_frame = Transform { rot: b.axes.map_or(x.rot, |a| x.rot * a), pos: c };
                let [w, qx, qy, qz] = box_frame.quat_wxyz();
                parry3d_f64::math::Pose::from_parts(
                    parry3d_f64::math::Vector::new(c.x, c.y, c.z),
                    parry3d_f64::math::Rotation::from_xyzw(qx, qy, qz, w),
                )
            };
            let cub =
                |b: &LocalBox| Cuboid::new(parry3d_f64::math::Vector::new(b.half.x, b.half.y, b.half.z));
            let d = query::distance(&to_pose(&x1, &b1), &cub(&b1), &to_pose(&x2, &b2), &cub(&b2))
                .unwrap()
                .distance;
            assert!(d > margin - 1e-12, "rejected at distance {d} < margin {margin}");
        }
        assert!(rejected > 1000, "the test rejected only {rejected} of 20000 pairs");
    }

    #[test]
    fn boxes_of_primitives_and_hulls() {
        let b = LocalBox::of(&Shape::Capsule { radius: 0.25, length: 1.0 }, None, None).unwrap();
        assert_eq!(b.half, Vec3::new(0.25, 0.25, 0.75));
        let hull = [Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.0, 5.0)];
        let b = LocalBox::of(
            &Shape::Mesh { source: crate::mass::MeshSource::File("m.stl".into()), scale: Vec3::repeat(1.0) },
            Some(&hull),
            None,
        )
        .unwrap();
        assert_eq!((b.centre, b.half), (Vec3::new(0.0, 1.0, 4.0), Vec3::new(1.0, 1.0, 1.0)));
        // Along a frame turned 90° about z with its origin at (1, 0, 0): u = Rᵀ (v − o).
        let turn = Mat3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let mesh =
            Shape::Mesh { source: crate::mass::MeshSource::File("m.stl".into()), scale: Vec3::repeat(1.0) };
        let b = LocalBox::of(&mesh, Some(&hull), Some(&(Vec3::new(1.0, 0.0, 0.0), turn))).unwrap();
        assert_eq!(b.axes, Some(turn));
        assert!((b.half - Vec3::new(1.0, 1.0, 1.0)).norm() < 1e-15);
        assert!((b.centre - Vec3::new(0.0, 1.0, 4.0)).norm() < 1e-15);
        assert!(LocalBox::of(&Shape::Plane { size: Vec3::repeat(1.0) }, None, None).is_none());
    }
}
