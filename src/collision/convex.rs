//! Convex geom pairs other than planes and MuJoCo's closed forms: the closest points of two
//! segments (`swept_spheres`, for geom distances; contacts of spheres and capsules are
//! [`super::capsule`]'s), every other pair by GJK and EPA on support maps (contacts by MuJoCo's
//! own solver, `collision::ccd`, see [`mujoco_pair`]; distances by parry3d-f64's
//! `contact_support_map_support_map`, [`support_pair`]) — including the ellipsoid, whose exact support map is
//! written here (a support-map shape, not a polyhedral approximation), and meshes by their hulls.
//! One contact per pair, at the midpoint of the two witness points.

use crate::model::spec::Shape;
use crate::spatial::{Transform, Vec3};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query::epa::EPA;
use parry3d_f64::query::gjk::{self, CsoPoint, GJKResult, VoronoiSimplex};
use std::cell::{Cell, RefCell};

thread_local! {
    /// The EPA workspace of this thread, reused so that overlapping pairs do not allocate
    /// ([`primed_epa`]).
    static EPA_WORK: RefCell<EPA> = RefCell::new(primed_epa());
}

/// A fresh EPA workspace whose buffers (polytope vertices, faces, the silhouette, the face heap)
/// have grown as far as one query can take them: EPA between two deeply overlapping balls, a
/// smooth pair, runs to its iteration limit. Its buffers grow only when a query needs more than
/// any before it, so that a workspace that has only met easy pairs would allocate at the first
/// harder one, inside a step; primed, it does so when the thread first needs EPA.
fn primed_epa() -> EPA {
    let mut epa = EPA::new();
    let ball = Ball::new(1.0);
    let pos12 = Pose::from_translation(Vector::new(0.3, 0.2, 0.1));
    let mut simplex = VoronoiSimplex::new();
    simplex.reset(CsoPoint::from_shapes(&pos12, &ball, &ball, Vector::X));
    if let GJKResult::Intersection = gjk::closest_points(&pos12, &ball, &ball, 0.0, true, &mut simplex) {
        std::hint::black_box(epa.closest_points(&pos12, &ball, &ball, &simplex));
    }
    epa
}
use parry3d_f64::shape::{Ball, Capsule, Cuboid, Cylinder, SupportMap};

/// An ellipsoid with semi-axes `radii` about its frame's axes.
#[derive(Clone, Debug)]
pub struct Ellipsoid {
    /// Semi-axes along the frame's x, y, z (m).
    pub radii: Vector,
}

impl SupportMap for Ellipsoid {
    /// argmax over the surface of p·d: p = D² d / ‖D d‖ (D = diag(radii)).
    fn local_support_point(&self, dir: Vector) -> Vector {
        let scaled = dir * self.radii;
        let norm = scaled.length();
        if norm == 0.0 {
            return Vector::ZERO;
        }
        scaled * self.radii / norm
    }
}

/// A geom's shape for the support-map queries, in the geom frame (parry's cylinder axis is y, so
/// a cylinder carries the rotation from lagrange's z axis).
#[derive(Clone, Debug)]
pub enum ConvexShape {
    /// A sphere.
    Ball(Ball),
    /// A capsule along the geom's z axis.
    Capsule(Capsule),
    /// A box (half-extents).
    Cuboid(Cuboid),
    /// A cylinder, parry's y axis standing for the geom's z axis.
    Cylinder(Cylinder),
    /// An ellipsoid.
    Ellipsoid(Ellipsoid),
    /// A mesh's convex hull, with its vertex adjacency for hill-climbing support queries.
    Hull(Box<super::hull_support::HullSupport>),
}

impl SupportMap for ConvexShape {
    fn local_support_point(&self, dir: Vector) -> Vector {
        match self {
            ConvexShape::Ball(s) => s.local_support_point(dir),
            ConvexShape::Capsule(s) => s.local_support_point(dir),
            ConvexShape::Cuboid(s) => s.local_support_point(dir),
            // z (lagrange) ↔ y (parry): (x, y, z) → (x, z, −y) and back.
            ConvexShape::Cylinder(s) => {
                let p = s.local_support_point(Vector::new(dir.x, dir.z, -dir.y));
                Vector::new(p.x, -p.z, p.y)
            }
            ConvexShape::Ellipsoid(s) => s.local_support_point(dir),
            ConvexShape::Hull(s) => s.local_support_point(dir),
        }
    }
}

/// One contact from a convex query: world witness points on both surfaces, the normal from geom 1
/// towards geom 2, the signed distance.
#[derive(Clone, Copy, Debug)]
pub struct PairPoint {
    /// Witness point on geom 1's surface (world).
    pub p1: Vec3,
    /// Witness point on geom 2's surface (world).
    pub p2: Vec3,
    /// Unit normal from geom 1 towards geom 2 (world).
    pub normal: Vec3,
    /// Signed distance (m), negative = penetration.
    pub dist: f64,
}

fn to_parry(x: &Transform) -> Pose {
    let [w, qx, qy, qz] = x.quat_wxyz();
    Pose::from_parts(Vector::new(x.pos.x, x.pos.y, x.pos.z), Rotation::from_xyzw(qx, qy, qz, w))
}

fn from_parry(v: Vector) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

impl ConvexShape {
    /// The support-map shape of a primitive geom and its bounding-sphere radius about the geom
    /// origin (None for planes, height fields and meshes).
    pub(crate) fn of_primitive(shape: &Shape) -> Option<(ConvexShape, f64)> {
        // (`+ 0.0` turns a size written as −0 into +0: parry asserts a positive sign.)
        Some(match shape {
            Shape::Sphere { radius } => (ConvexShape::Ball(Ball::new(radius + 0.0)), *radius),
            Shape::Capsule { radius, length } => (
                ConvexShape::Capsule(Capsule::new_z(0.5 * length + 0.0, radius + 0.0)),
                radius + 0.5 * length,
            ),
            Shape::Cylinder { radius, length } => (
                ConvexShape::Cylinder(Cylinder::new(0.5 * length + 0.0, radius + 0.0)),
                radius.hypot(0.5 * length),
            ),
            Shape::Box { size } => {
                let h = size / 2.0;
                (ConvexShape::Cuboid(Cuboid::new(Vector::new(h.x + 0.0, h.y + 0.0, h.z + 0.0))), h.norm())
            }
            Shape::Ellipsoid { radii } => (
                ConvexShape::Ellipsoid(Ellipsoid { radii: Vector::new(radii.x, radii.y, radii.z) }),
                radii.max(),
            ),
            Shape::Plane { .. } | Shape::Hfield { .. } | Shape::Mesh { .. } => return None,
        })
    }

    /// Whether the surface is smooth (no vertices, edges or faces): spheres, capsules, ellipsoids.
    pub(crate) fn smooth(&self) -> bool {
        matches!(self, ConvexShape::Ball(_) | ConvexShape::Capsule(_) | ConvexShape::Ellipsoid(_))
    }

    /// The support point in world coordinates of the shape at pose `x` along world direction `d`.
    pub(crate) fn world_support(&self, x: &Transform, d: &Vec3) -> Vec3 {
        let local = x.rot.transpose() * d;
        x.act_point(&from_parry(self.local_support_point(Vector::new(local.x, local.y, local.z))))
    }
}

/// GJK/EPA between two support-map shapes at world poses `x1`, `x2`, if closer than `reach`
/// (parry3d-f64's GJK and EPA). EPA's normal is exact on faces but only first-order accurate
/// between two smooth surfaces; there the penetration direction is refined by Newton steps (`polish`).
pub fn support_pair(
    x1: &Transform,
    s1: &ConvexShape,
    x2: &Transform,
    s2: &ConvexShape,
    reach: f64,
) -> Option<PairPoint> {
    let pos12 = to_parry(&(x1.inverse() * *x2));
    let (s1, s2) = (&Warm::new(s1), &Warm::new(s2));
    // parry's `contact_support_map_support_map`, with this thread's EPA workspace reused (a fresh
    // EPA allocates on every overlapping pair).
    let mut simplex = VoronoiSimplex::new();
    let dir = pos12.translation.try_normalize().unwrap_or(Vector::X);
    simplex.reset(CsoPoint::from_shapes(&pos12, s1, s2, dir));
    let found = match gjk::closest_points(&pos12, s1, s2, reach, true, &mut simplex) {
        GJKResult::ClosestPoints(p1, p2, n) => Some((p1, p2, n)),
        GJKResult::Intersection => {
            EPA_WORK.with(|epa| epa.borrow_mut().closest_points(&pos12, s1, s2, &simplex))
        }
        GJKResult::NoIntersection(_) | GJKResult::Proximity(_) => None,
    };
    // point1 and normal1 in frame 1, point2_1 (point 2) in frame 1 too.
    let (point1, point2_1, normal1) = found?;
    let mut point = PairPoint {
        p1: x1.act_point(&from_parry(point1)),
        p2: x1.act_point(&from_parry(point2_1)),
        normal: x1.rot * from_parry(normal1),
        dist: (point2_1 - point1).dot(normal1),
    };
    if point.dist < 0.0 && s1.shape.smooth() && s2.shape.smooth() {
        point = polish(x1, s1.shape, x2, s2.shape, point);
    }
    (point.dist <= reach).then_some(point)
}

/// A shape whose hull support queries start from the previous answer: GJK and EPA ask for
/// support points along a sequence of nearby directions, so the climb from the last vertex is
/// short (MuJoCo's `mjc_hillclimbSupport` warm-starts the same way). The climb ends at a vertex
/// farthest along the direction from any start; where several are exactly as far, the start
/// picks among them.
struct Warm<'a> {
    shape: &'a ConvexShape,
    /// The last support vertex of a hull (−1: none yet).
    last: Cell<i32>,
}

impl<'a> Warm<'a> {
    fn new(shape: &'a ConvexShape) -> Self {
        Self { shape, last: Cell::new(-1) }
    }
}

impl SupportMap for Warm<'_> {
    fn local_support_point(&self, dir: Vector) -> Vector {
        if let ConvexShape::Hull(h) = self.shape {
            let i = h.support_index_warm(dir, self.last.get());
            self.last.set(i as i32);
            return h.points()[i];
        }
        self.shape.local_support_point(dir)
    }
}

/// The first contact of a convex pair as MuJoCo 4.0's native solver finds it
/// (`ccd::penetration`: GJK/EPA on the geoms inflated by half of `margin` each, to the
/// model's `ccd_tolerance` within `ccd_iterations`): witness points whose midpoint is MuJoCo's
/// contact position, its normal and the contact distance; None when the inflated geoms do not
/// overlap (boxes and meshes too, with a margin or without: MuJoCo's EPA on the margin-inflated
/// polytopes stops at `ccd_tolerance`, and so does this one).
/// `touching` (the pair touched at the last pass) skips the separation test of box and mesh
/// pairs, which does not change the answer.
pub fn mujoco_pair(
    x1: &Transform,
    s1: &ConvexShape,
    x2: &Transform,
    s2: &ConvexShape,
    margin: f64,
    options: &crate::model::Options,
    touching: bool,
) -> Option<PairPoint> {
    mujoco_pair_warm(x1, s1, x2, s2, margin, options, touching, &mut super::ccd::SeparationWarm::none())
        .map(|(p, _)| p)
}

/// [`mujoco_pair`] with the separation test started from `warm` and what it found written back
/// (its last support vertices and separating direction, see [`super::ccd::separated`]): the
/// collision pass keeps them per pair from one pass to the next. With the point, the EPA face
/// it comes from (None when the point is not EPA's: a shallow pair without a GJK simplex).
#[allow(clippy::too_many_arguments)]
pub(crate) fn mujoco_pair_warm(
    x1: &Transform,
    s1: &ConvexShape,
    x2: &Transform,
    s2: &ConvexShape,
    margin: f64,
    options: &crate::model::Options,
    touching: bool,
    warm: &mut super::ccd::SeparationWarm,
) -> Option<(PairPoint, Option<super::ccd::EpaFace>)> {
    let polytope = |s: &ConvexShape| matches!(s, ConvexShape::Cuboid(_) | ConvexShape::Hull(_));
    if polytope(s1) && polytope(s2) {
        // MuJoCo's GJK dismisses most candidate pairs after a few support points (a pair
        // touching at the last pass goes straight to the penetration).
        if !touching
            && super::ccd::separated(
                s1,
                x1,
                s2,
                x2,
                margin,
                options.ccd_tolerance,
                options.ccd_iterations as usize,
                warm,
            )
        {
            return None;
        }
    }
    let c = super::ccd::penetration(
        s1,
        x1,
        s2,
        x2,
        margin,
        options.ccd_tolerance,
        options.ccd_iterations as usize,
    )?;
    Some((PairPoint { p1: c.x1, p2: c.x2, normal: c.normal, dist: c.dist }, c.face))
}

/// The signed distance of two support-map shapes to f64 round-off, if closer than `reach`: when
/// they are apart, the distance and witness points of [`super::gjk::separation`] (parry's GJK
/// stops at a relative gap of ~5e-8, see there), polished on smooth shapes; when they overlap,
/// [`support_pair`]'s EPA. What [`geom_distance`](super::geom_distance) measures with.
pub(crate) fn support_distance(
    x1: &Transform,
    s1: &ConvexShape,
    x2: &Transform,
    s2: &ConvexShape,
    reach: f64,
) -> Option<PairPoint> {
    let Some((p1, p2, dist)) = super::gjk::separation(x1, s1, x2, s2) else {
        return support_pair(x1, s1, x2, s2, reach);
    };
    if dist > reach {
        return None;
    }
    let mut point = PairPoint { p1, p2, normal: (p2 - p1) / dist, dist };
    if s1.smooth() && s2.smooth() {
        point = polish(x1, s1, x2, s2, point);
    }
    (point.dist <= reach).then_some(point)
}

/// Refines the direction of a pair point between two smooth shapes to the minimiser of
/// h₁(n) + h₂(−n) over unit n (support functions h; the minimum is minus the signed distance; its
/// gradient is the tangential part of p₁ − p₂, the difference of the support points) by Newton
/// steps on the tangent plane, the Hessian by central differences of the gradient (the sum of the
/// two surfaces' curvature radii), never accepting a step that does not lower it. GJK and EPA
/// determine the distance to round-off but the witness points on curved surfaces only to the
/// square root of that (the distance is stationary in them); the Newton steps solve the
/// first-order condition instead, which fixes them to round-off.
fn polish(x1: &Transform, s1: &ConvexShape, x2: &Transform, s2: &ConvexShape, start: PairPoint) -> PairPoint {
    let PairPoint { mut p1, mut p2, mut normal, mut dist } = start;
    let depth_at = |n: &Vec3| {
        let (q1, q2) = (s1.world_support(x1, n), s2.world_support(x2, &-n));
        (n.dot(&(q1 - q2)), q1, q2)
    };
    let (mut depth, _, _) = depth_at(&normal);
    for _ in 0..8 {
        let t1 = crate::collision::contact_frame(&normal, None).row(1).transpose();
        let t2 = normal.cross(&t1);
        let grad = |n: &Vec3| {
            let (_, q1, q2) = depth_at(n);
            let d = q1 - q2;
            [t1.dot(&d), t2.dot(&d)]
        };
        let g = grad(&normal);
        if g[0].hypot(g[1]) <= 1e-15 * depth.abs().max(1e-300) {
            break;
        }
        const EPS: f64 = 1e-6;
        let mut h = [[0.0; 2]; 2];
        for (j, t) in [t1, t2].iter().enumerate() {
            let (gp, gm) = (grad(&(normal + t * EPS).normalize()), grad(&(normal - t * EPS).normalize()));
            for i in 0..2 {
                h[i][j] = (gp[i] - gm[i]) / (2.0 * EPS);
            }
        }
        let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
        if det.is_nan() || det <= 0.0 || h[0][0] <= 0.0 {
            break;
        }
        let step = [(-g[0] * h[1][1] + g[1] * h[0][1]) / det, (g[0] * h[1][0] - g[1] * h[0][0]) / det];
        let candidate = (normal + t1 * step[0] + t2 * step[1]).normalize();
        let (d_new, q1, q2) = depth_at(&candidate);
        // Never higher than before (NaN stops too).
        if d_new.is_nan() || d_new > depth + 1e-15 * depth.abs() {
            break;
        }
        (normal, depth, p1, p2, dist) = (candidate, d_new, q1, q2, -d_new);
    }
    PairPoint { p1, p2, normal, dist }
}

/// Closest points of segments [a0, a1] and [b0, b1] (Ericson, *Real-Time Collision Detection*,
/// §5.1.9).
fn segment_closest(a0: &Vec3, a1: &Vec3, b0: &Vec3, b1: &Vec3) -> (Vec3, Vec3) {
    let (d1, d2, r) = (a1 - a0, b1 - b0, a0 - b0);
    let (a, e, f) = (d1.dot(&d1), d2.dot(&d2), d2.dot(&r));
    const EPS: f64 = 1e-24;
    let (s, t) = if a <= EPS && e <= EPS {
        (0.0, 0.0)
    } else if a <= EPS {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= EPS {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > EPS { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (a0 + d1 * s, b0 + d2 * t)
}

/// Two "swept spheres" (a sphere is a segment of zero length): centres c1, c2 on their segments'
/// closest points, radii r1, r2. The normal of coincident centres is x (MuJoCo picks the cross
/// product of the z axes; any unit vector is a valid normal there).
pub fn swept_spheres(seg1: [Vec3; 2], r1: f64, seg2: [Vec3; 2], r2: f64, reach: f64) -> Option<PairPoint> {
    let (c1, c2) = segment_closest(&seg1[0], &seg1[1], &seg2[0], &seg2[1]);
    let d = c2 - c1;
    let len = d.norm();
    let dist = len - r1 - r2;
    if dist > reach {
        return None;
    }
    let normal = if len > 1e-15 { d / len } else { Vec3::x() };
    Some(PairPoint { p1: c1 + normal * r1, p2: c2 - normal * r2, normal, dist })
}
