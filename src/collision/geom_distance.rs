//! The signed distance between two geoms, capped: MuJoCo's `mj_geomDistance` (engine_support.c),
//! what the `geomdist`, `geomnormal` and `geomfromto` sensors read.
//!
//! MuJoCo runs the pair's collision function with the cap `distmax` as its margin and keeps the
//! deepest contact; for the pairs it collides by GJK/EPA (its `mjc_Convex` pairs: ellipsoids,
//! meshes, cylinder against capsule, cylinder, box or mesh, sphere or capsule against ellipsoid or
//! mesh) and for box–box it calls its GJK/EPA directly (`nativeccd`) for the distance and the
//! witness points. Here each pair goes through the narrow phase lagrange's collision uses
//! ([`super::collide`]), with the same split:
//!
//! | pair (lower MuJoCo type first) | how | fromto |
//! |---|---|---|
//! | plane – sphere, capsule, box, cylinder, ellipsoid, mesh | the plane closed forms ([`super::plane`]; a mesh by its hull's vertices) | MuJoCo's: from the contact's position ∓ normal · dist/2 |
//! | sphere – sphere, capsule; capsule – capsule | closest points of segments ([`super::convex::swept_spheres`]) | as above |
//! | sphere, capsule – box | MuJoCo's closed forms ([`super::box_primitive`]) | as above |
//! | sphere – cylinder | GJK/EPA ([`super::convex::support_pair`]), as lagrange's collision does | as above |
//! | the GJK pairs and box – box | GJK/EPA on the support maps (meshes by their hulls) | the witness points |
//! | plane – plane | none (MuJoCo has no function): `distmax`, no fromto | — |
//!
//! The result is the smallest distance below `distmax` (else `distmax` itself) and, when one is
//! found, the segment `fromto` from the point on geom 1's surface to the point on geom 2's (for a
//! penetration, each point lies inside the other geom; the segment still runs from geom 1's
//! surface point to geom 2's). Height fields are refused (not collided by lagrange).
//!
//! Agreement with MuJoCo: the closed forms follow MuJoCo's to round-off; GJK/EPA gives the exact
//! distance of polytopes and converges on curved shapes, where MuJoCo stops at its
//! `ccd_tolerance` (1e-6 by default): there the two differ by up to that tolerance.

use super::box_primitive;
use super::convex::{support_distance, swept_spheres, ConvexShape, PairPoint};
use super::plane::{self, PlanePoint};
use crate::error::InputError;
use crate::model::collision_pairs::type_rank;
use crate::model::spec::Shape;
use crate::model::{Data, Geom, Model};
use crate::spatial::{Transform, Vec3};

/// The distance between two geoms, capped (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeomDistance {
    /// The signed distance (m; negative when the geoms overlap), or `distmax` when the geoms are
    /// at least that far apart.
    pub dist: f64,
    /// From the point on geom 1's surface to the point on geom 2's (world), when the distance is
    /// below `distmax` (MuJoCo's `fromto`, which is zero otherwise).
    pub fromto: Option<[Vec3; 2]>,
}

/// The signed distance between geoms `geom1` and `geom2` (indices in `Model::geoms`) at the poses
/// of `data` (after forward kinematics), capped at `distmax`, with the from–to segment: MuJoCo's
/// `mj_geomDistance(m, d, geom1, geom2, distmax, fromto)`. Visual geoms count; the first distance
/// to a mesh geom reads its file.
///
/// # Errors
/// [`InputError`] when `data` was not made for `model`, a geom does not exist, `distmax` is NaN,
/// a geom is a height field, or a mesh geom's file cannot be read.
///
/// # Example
/// ```
/// use lagrange::collision::geom_distance;
/// use lagrange::{Data, Model};
///
/// let model = Model::from_str(
///     r#"<mujoco><worldbody>
///          <geom name="floor" type="plane" size="0 0 1"/>
///          <body pos="0 0 1"><freejoint/><geom name="ball" size="0.25"/></body>
///        </worldbody></mujoco>"#,
/// )?;
/// let mut data = Data::new(&model);
/// lagrange::forward::forward(&model, &mut data);
/// let d = geom_distance(&model, &data, 1, 0, 10.0)?;
/// assert!((d.dist - 0.75).abs() < 1e-15);
/// let [from, to] = d.fromto.expect("closer than 10 m");
/// assert!((from.z - 0.75).abs() < 1e-15 && to.z.abs() < 1e-15); // ball bottom → floor
/// // Beyond the cap: the cap itself, no segment.
/// assert_eq!(geom_distance(&model, &data, 1, 0, 0.5)?.dist, 0.5);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn geom_distance(
    model: &Model,
    data: &Data,
    geom1: usize,
    geom2: usize,
    distmax: f64,
) -> Result<GeomDistance, InputError> {
    const F: &str = "collision::geom_distance";
    crate::error::check::data(F, model, data)?;
    for g in [geom1, geom2] {
        if g >= model.geoms.len() {
            return Err(InputError::Index { function: F, what: "geom", index: g, count: model.geoms.len() });
        }
    }
    if distmax.is_nan() {
        return Err(InputError::NonFinite { function: F, argument: "distmax", index: 0, value: distmax });
    }
    for g in [geom1, geom2] {
        let geom = &model.geoms[g];
        let refuse = |reason: String| InputError::Unsupported {
            function: F,
            what: format!("geom {g} ('{}')", geom.name),
            reason,
        };
        match &geom.shape {
            Shape::Hfield { .. } => {
                return Err(refuse(": it is a height field, which lagrange does not collide".into()))
            }
            Shape::Mesh { .. } => {
                if let Some(Err(e)) = geom.mesh.as_deref().map(|m| m.hull()) {
                    return Err(refuse(format!(": its mesh has no hull ({e})")));
                }
            }
            _ => {}
        }
    }
    Ok(geom_distance_unchecked(model, data, geom1, geom2, distmax))
}

/// [`geom_distance`] without the argument checks (a height field or an unreadable mesh gives
/// `distmax` and no segment).
pub(crate) fn geom_distance_unchecked(
    model: &Model,
    data: &Data,
    geom1: usize,
    geom2: usize,
    distmax: f64,
) -> GeomDistance {
    let none = GeomDistance { dist: distmax, fromto: None };
    let pose = |g: &Geom| data.attached_pose(g.body, g.mocap, &g.x_body_geom);
    let (user1, user2) = (&model.geoms[geom1], &model.geoms[geom2]);
    // MuJoCo's order: the lower type first; `flip` when that swaps the caller's geoms.
    // MuJoCo's geom type order (`mjtGeom`): a pair's collision function takes the lower type first.
    let flip = type_rank(&user1.shape) > type_rank(&user2.shape);
    let (ga, gb) = if flip { (user2, user1) } else { (user1, user2) };
    let (xa, xb) = (pose(ga), pose(gb));
    // The deepest contact below distmax (the first of equals), as (position, normal from a to b,
    // distance).
    let mut best: Option<(Vec3, Vec3, f64)> = None;
    let mut keep = |pos: Vec3, normal: Vec3, dist: f64| {
        if dist < best.map_or(distmax, |b| b.2) {
            best = Some((pos, normal, dist));
        }
    };
    let mut pair = |p: PairPoint| keep((p.p1 + p.p2) * 0.5, p.normal, p.dist);
    match (&ga.shape, &gb.shape) {
        (Shape::Plane { .. }, Shape::Plane { .. })
        | (Shape::Hfield { .. }, _)
        | (_, Shape::Hfield { .. }) => return none,
        (Shape::Plane { .. }, shape_b) => {
            let n = xa.rot.column(2).into_owned();
            let mut out = |p: PlanePoint| {
                let (p1, p2) = (p.surface - n * p.dist, p.surface);
                keep((p1 + p2) * 0.5, n, p.dist)
            };
            match shape_b {
                Shape::Sphere { radius } => plane::sphere(&xa, &xb.pos, *radius, distmax, &mut out),
                Shape::Capsule { radius, length } => {
                    plane::capsule(&xa, &xb, *radius, 0.5 * length, distmax, &mut out)
                }
                Shape::Box { size } => plane::cuboid(&xa, &xb, &(size / 2.0), distmax, &mut out),
                Shape::Cylinder { radius, length } => {
                    plane::cylinder(&xa, &xb, *radius, 0.5 * length, distmax, &mut out)
                }
                Shape::Ellipsoid { radii } => plane::ellipsoid(&xa, &xb, radii, distmax, &mut out),
                Shape::Mesh { .. } => match gb.mesh.as_deref().map(|m| m.hull()) {
                    Some(Ok(h)) => plane::hull(&xa, &xb, &h.vertices, distmax, &mut out),
                    _ => return none,
                },
                Shape::Plane { .. } | Shape::Hfield { .. } => {}
            }
        }
        (Shape::Sphere { radius: ra }, Shape::Sphere { radius: rb }) => {
            pair_opt(swept_spheres([xa.pos, xa.pos], *ra, [xb.pos, xb.pos], *rb, distmax), &mut pair)
        }
        (Shape::Sphere { radius: ra }, Shape::Capsule { radius: rb, length }) => {
            pair_opt(swept_spheres([xa.pos, xa.pos], *ra, segment(&xb, *length), *rb, distmax), &mut pair)
        }
        (Shape::Capsule { radius: ra, length: la }, Shape::Capsule { radius: rb, length: lb }) => {
            pair_opt(swept_spheres(segment(&xa, *la), *ra, segment(&xb, *lb), *rb, distmax), &mut pair)
        }
        (Shape::Sphere { radius }, Shape::Box { size }) => {
            box_primitive::sphere_box(&xa.pos, *radius, &xb, &(size / 2.0), distmax, 0, &mut |p, _| pair(p))
        }
        (Shape::Capsule { radius, length }, Shape::Box { size }) => box_primitive::capsule_box(
            &xa,
            *radius,
            0.5 * length,
            &xb,
            &(size / 2.0),
            distmax,
            &mut |p, _| pair(p),
        ),
        (Shape::Sphere { .. }, Shape::Cylinder { .. }) => {
            if let (Some(sa), Some(sb)) = (support_shape(ga), support_shape(gb)) {
                pair_opt(support_distance(&xa, sa.get(), &xb, sb.get(), distmax), &mut pair)
            }
        }
        // MuJoCo's GJK/EPA pairs and box–box: the witness points, in the caller's order.
        _ => {
            let (Some(s1), Some(s2)) = (support_shape(user1), support_shape(user2)) else { return none };
            let (x1, x2) = if flip { (xb, xa) } else { (xa, xb) };
            return match support_distance(&x1, s1.get(), &x2, s2.get(), distmax) {
                Some(p) if p.dist < distmax => GeomDistance { dist: p.dist, fromto: Some([p.p1, p.p2]) },
                _ => none,
            };
        }
    }
    match best {
        None => none,
        Some((pos, normal, dist)) => {
            // MuJoCo: from = pos − s·normal·dist/2, to = pos + s·normal·dist/2, s = −1 when flipped.
            let half = normal * (0.5 * if flip { -dist } else { dist });
            GeomDistance { dist, fromto: Some([pos - half, pos + half]) }
        }
    }
}

/// Feeds an optional pair point to `out`.
#[inline]
fn pair_opt(p: Option<PairPoint>, out: &mut impl FnMut(PairPoint)) {
    if let Some(p) = p {
        out(p)
    }
}

/// A capsule's segment (its axis between the cap centres) at pose `x`.
fn segment(x: &Transform, length: f64) -> [Vec3; 2] {
    let a = x.rot.column(2) * (0.5 * length);
    [x.pos - a, x.pos + a]
}

/// A support-map shape borrowed from a mesh's hull or built for a primitive (no allocation).
enum Support<'a> {
    Owned(ConvexShape),
    Borrowed(&'a ConvexShape),
}

impl Support<'_> {
    fn get(&self) -> &ConvexShape {
        match self {
            Support::Owned(s) => s,
            Support::Borrowed(s) => s,
        }
    }
}

/// The support-map shape of a geom (None for planes, height fields and meshes without a hull).
fn support_shape(g: &Geom) -> Option<Support<'_>> {
    match &g.shape {
        Shape::Mesh { .. } => g.mesh.as_deref()?.hull().ok().map(|h| Support::Borrowed(&h.shape)),
        shape => ConvexShape::of_primitive(shape).map(|(s, _)| Support::Owned(s)),
    }
}
