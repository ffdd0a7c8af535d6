//! Ray casting against geoms and sites: MuJoCo's `mj_ray`, `mju_rayGeom` and `mj_rayMesh`
//! (engine_ray.c), what the rangefinder and touch sensors use.
//!
//! A ray is `p + x·v` for `x ≥ 0`, `v` not necessarily unit: distances are in units of |v|, as
//! MuJoCo returns them. [`ray`] finds the nearest geom the ray hits among **all** of the model's
//! geoms — visual ones (contype = conaffinity = 0) included — except those MuJoCo's
//! `ray_eliminate` skips ([`RayFilter`]): geoms of an excluded body; geoms whose alpha is 0 (their
//! material's alpha when they have a material, else their own `rgba`'s); geoms of static bodies
//! (the world and the bodies welded to it; mocap bodies are not static) unless asked for; geoms
//! whose group (clamped to 0..=5) is not selected.
//!
//! Per shape, the closed forms of MuJoCo (each in the geom's frame unless said otherwise):
//!
//! | shape | hit |
//! |---|---|
//! | plane | only from its front (+z) side; within its `size` rectangle when the size is positive, anywhere otherwise; normal +z |
//! | sphere | smallest non-negative root of the quadratic (world frame); from inside, the exit point |
//! | capsule | bounding-sphere test, then the side (between the caps) and the two hemispherical caps |
//! | ellipsoid | the quadratic of the scaled coordinates; normal along the gradient |
//! | cylinder | bounding-sphere test, then the flat caps, then the side |
//! | box | bounding-sphere test, then the six faces (axes x, y, z, sides −, +) |
//! | mesh | its triangles (not its hull): the nearest one crossing the ray, either face, normal from the triangle's winding |
//!
//! "Smallest non-negative root": a ray starting inside a shape reports where it leaves it, with
//! the outward normal there. Ties (a ray through an edge) go to the first in the order above, as
//! in MuJoCo. Quadratics are solved as MuJoCo's `ray_quad` does (no root when the leading
//! coefficient is below 1e-15), and a face parallel to the ray within 1e-15 is not hit.
//!
//! Height fields are not hit (lagrange does not read height field data), nor a mesh whose file
//! cannot be read ([`GeomMesh::triangles`](super::GeomMesh::triangles) says why).

use super::mesh::MeshTriangles;
use crate::error::InputError;
use crate::mass::Primitive;
use crate::model::spec::Shape;
use crate::model::{Data, Model};
use crate::spatial::{Transform, Vec3};
use parry3d_f64::math::Vector;
use parry3d_f64::query::Ray;

/// MuJoCo's `mjMINVAL`: the smallest leading coefficient, denominator or vector norm it divides by.
const MINVAL: f64 = 1e-15;

/// MuJoCo's number of geom groups (`mjNGROUP`): a geom's group is clamped to 0..NGROUP−1 when
/// rays select groups.
pub const NGROUP: usize = 6;

/// Which geoms a ray may hit, besides the alpha rule every ray applies (MuJoCo's `mj_ray`
/// arguments `geomgroup`, `flg_static`, `bodyexclude`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayFilter {
    /// Per geom group 0..=5, whether the ray may hit geoms of that group (a geom's group is
    /// clamped to 0..=5); `None` selects every group (MuJoCo's `geomgroup = NULL`).
    pub geomgroup: Option<[bool; NGROUP]>,
    /// Whether the geoms of static bodies (the world and bodies welded to it; not mocap bodies)
    /// may be hit (MuJoCo's `flg_static`).
    pub include_static: bool,
    /// The MuJoCo body id ([`Links::of_geom`](crate::model::Links::of_geom), 0 = the world) whose
    /// geoms the ray ignores, if any (MuJoCo's `bodyexclude`; the rangefinder passes its site's
    /// body).
    pub body_exclude: Option<usize>,
}

impl Default for RayFilter {
    /// Every group, static geoms included, no body excluded: what the rangefinder uses, less its
    /// own body.
    fn default() -> Self {
        Self { geomgroup: None, include_static: true, body_exclude: None }
    }
}

/// The nearest geom a ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Distance along the ray in units of the direction's length (`p + dist·v` is the hit point).
    pub dist: f64,
    /// The geom hit (index in `Model::geoms`, MuJoCo's geom id).
    pub geom: usize,
    /// The unit surface normal at the hit point, world frame (MuJoCo's `normal`): outward for
    /// primitives, by the triangle's winding for meshes.
    pub normal: Vec3,
}

/// The nearest geom hit by the ray `p_world + x·vec_world`, x ≥ 0, among the geoms `filter`
/// allows, or `None` (MuJoCo's `mj_ray` returning −1). Reads the body poses of `data`: call after
/// [`forward`](crate::forward::forward) or
/// [`forward_kinematics`](crate::kinematics::forward_kinematics) (mocap bodies are posed from
/// `data.mocap_pos`, `data.mocap_quat`). The first ray that reaches a mesh geom reads its file.
///
/// # Errors
/// [`InputError`] when `data` was not made for `model`, a coordinate is not finite, or
/// `vec_world` is shorter than 1e-15 (MuJoCo's "vector length is too small").
///
/// # Example
/// ```
/// use lagrange::collision::{ray, RayFilter};
/// use lagrange::spatial::Vec3;
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
/// // Straight down from 3 m: the ball's top at 1.25 m, 1.75 m away (in units of |v| = 2: 0.875).
/// let hit = ray(&model, &data, Vec3::new(0.0, 0.0, 3.0), Vec3::new(0.0, 0.0, -2.0), &RayFilter::default())?
///     .expect("the ball is below");
/// assert_eq!(model.geoms[hit.geom].name, "ball");
/// assert!((hit.dist - 0.875).abs() < 1e-15 && hit.normal == Vec3::z());
/// // Without static geoms and the ball's body (MuJoCo body 1), nothing is hit.
/// let filter = RayFilter { include_static: false, body_exclude: Some(1), ..RayFilter::default() };
/// assert!(ray(&model, &data, Vec3::new(0.0, 0.0, 3.0), -Vec3::z(), &filter)?.is_none());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn ray(
    model: &Model,
    data: &Data,
    p_world: Vec3,
    vec_world: Vec3,
    filter: &RayFilter,
) -> Result<Option<RayHit>, InputError> {
    const F: &str = "collision::ray";
    crate::error::check::data(F, model, data)?;
    check_ray(F, &p_world, &vec_world)?;
    Ok(ray_unchecked(model, data, &p_world, &vec_world, filter))
}

/// The finiteness and length checks of a ray's point and direction.
fn check_ray(function: &'static str, p: &Vec3, v: &Vec3) -> Result<(), InputError> {
    InputError::check_finite(function, "p_world", p.as_slice())?;
    InputError::check_finite(function, "vec_world", v.as_slice())?;
    if v.norm() < MINVAL {
        return Err(InputError::Value {
            function,
            argument: "vec_world",
            detail: format!("has length {:e}; a ray direction needs a length of at least 1e-15", v.norm()),
        });
    }
    Ok(())
}

/// [`ray`] without the argument checks (`vec_world` nonzero and finite).
pub(crate) fn ray_unchecked(
    model: &Model,
    data: &Data,
    p_world: &Vec3,
    vec_world: &Vec3,
    filter: &RayFilter,
) -> Option<RayHit> {
    let mut best: Option<RayHit> = None;
    for (g, geom) in model.geoms.iter().enumerate() {
        if eliminated(model, g, filter) {
            continue;
        }
        let x = data.attached_pose(geom.body, geom.mocap, &geom.x_body_geom);
        let hit = match &geom.shape {
            Shape::Plane { size } => ray_plane(&x, [size.x, size.y], p_world, vec_world),
            Shape::Mesh { .. } => match geom.mesh.as_deref().map(|m| m.triangles()) {
                Some(Ok(mesh)) => ray_mesh(&x, mesh, p_world, vec_world),
                _ => None,
            },
            Shape::Hfield { .. } => None,
            shape => primitive_of(shape).and_then(|s| ray_primitive(&x, &s, p_world, vec_world)),
        };
        if let Some((dist, normal)) = hit {
            if best.is_none_or(|b| dist < b.dist) {
                best = Some(RayHit { dist, geom: g, normal });
            }
        }
    }
    best
}

/// Whether MuJoCo's `ray_eliminate` skips geom `g` under `filter`.
pub(crate) fn eliminated(model: &Model, g: usize, filter: &RayFilter) -> bool {
    let geom = &model.geoms[g];
    if filter.body_exclude == Some(model.links.of_geom[g]) {
        return true;
    }
    let alpha = geom.material_rgba.unwrap_or(geom.rgba)[3];
    if alpha == 0.0 {
        return true;
    }
    // Static: on the world body (welded bodies are fused into it) and not on a mocap body.
    if !filter.include_static && geom.body == 0 && geom.mocap.is_none() {
        return true;
    }
    match filter.geomgroup {
        None => false,
        Some(groups) => !groups[geom.group.clamp(0, NGROUP as i32 - 1) as usize],
    }
}

/// A primitive geom's shape in MuJoCo's half-size convention (None for planes, height fields and
/// meshes).
pub(crate) fn primitive_of(shape: &Shape) -> Option<Primitive> {
    match *shape {
        Shape::Sphere { radius } => Some(Primitive::Sphere { radius }),
        Shape::Capsule { radius, length } => Some(Primitive::Capsule { radius, half_length: 0.5 * length }),
        Shape::Cylinder { radius, length } => Some(Primitive::Cylinder { radius, half_length: 0.5 * length }),
        Shape::Box { size } => Some(Primitive::Box { half_extents: size * 0.5 }),
        Shape::Ellipsoid { radii } => Some(Primitive::Ellipsoid { radii }),
        Shape::Plane { .. } | Shape::Hfield { .. } | Shape::Mesh { .. } => None,
    }
}

/// The unit vector along `v`, or x when |v| < 1e-15 (MuJoCo's `mju_normalize3`).
#[inline]
fn unit(v: Vec3) -> Vec3 {
    let n = v.norm();
    if n < MINVAL {
        Vec3::x()
    } else {
        v * (1.0 / n)
    }
}

/// The real roots x₀ ≤ x₁ of a x² + 2 b x + c = 0, or None when there are none or a < 1e-15
/// (MuJoCo's `ray_quad`).
#[inline]
fn roots(a: f64, b: f64, c: f64) -> Option<[f64; 2]> {
    let det = b * b - a * c;
    if det < 0.0 || a < MINVAL {
        return None;
    }
    let s = det.sqrt();
    Some([(-b - s) / a, (-b + s) / a])
}

/// The smaller non-negative root of [`roots`], if any.
#[inline]
fn first_root(a: f64, b: f64, c: f64) -> Option<f64> {
    let [x0, x1] = roots(a, b, c)?;
    if x0 >= 0.0 {
        Some(x0)
    } else if x1 >= 0.0 {
        Some(x1)
    } else {
        None
    }
}

/// Whether the ray meets the sphere of squared radius `r2` about `centre` at some x ≥ 0 (the
/// bounding-sphere test of capsules, cylinders and boxes, in the world frame).
#[inline]
fn meets_sphere(centre: &Vec3, r2: f64, p: &Vec3, v: &Vec3) -> bool {
    let d = p - centre;
    first_root(v.dot(v), v.dot(&d), d.dot(&d) - r2).is_some()
}

/// The ray in the frame of `x`: (point, direction).
#[inline]
fn local(x: &Transform, p: &Vec3, v: &Vec3) -> (Vec3, Vec3) {
    (x.rot.tr_mul(&(p - x.pos)), x.rot.tr_mul(v))
}

/// Whether the ray meets a primitive shape at pose `x`: `ray_primitive(..).is_some()`, without
/// the hit's normal, and for a capsule without its caps once its side is met (the touch sensors'
/// test, which needs no distance).
pub(crate) fn ray_meets_primitive(x: &Transform, shape: &Primitive, p: &Vec3, v: &Vec3) -> bool {
    let Primitive::Capsule { radius, half_length: h } = *shape else {
        return ray_primitive(x, shape, p, v).is_some();
    };
    if !meets_sphere(&x.pos, (radius + h) * (radius + h), p, v) {
        return false;
    }
    let (lp, lv) = local(x, p, v);
    // The same tests as `ray_primitive`'s capsule arm: its side's first root within the
    // cylinder, or a root x ≥ 0 of either cap's sphere on the cap.
    let side = first_root(
        lv.x * lv.x + lv.y * lv.y,
        lv.x * lp.x + lv.y * lp.y,
        lp.x * lp.x + lp.y * lp.y - radius * radius,
    );
    if side.is_some_and(|t| (lp.z + t * lv.z).abs() <= h) {
        return true;
    }
    [1.0, -1.0].into_iter().any(|cap| {
        let d = Vec3::new(lp.x, lp.y, lp.z - cap * h);
        roots(lv.dot(&lv), lv.dot(&d), d.dot(&d) - radius * radius).is_some_and(|ts| {
            ts.into_iter().any(|t| {
                let z = lp.z + t * lv.z;
                t >= 0.0 && if cap > 0.0 { z >= h } else { z <= -h }
            })
        })
    })
}

/// The ray against a primitive shape at pose `x` (MuJoCo's `mju_rayGeom` for the primitive
/// types): the distance (units of |v|) and the world unit normal at the hit, or None.
pub(crate) fn ray_primitive(x: &Transform, shape: &Primitive, p: &Vec3, v: &Vec3) -> Option<(f64, Vec3)> {
    match *shape {
        Primitive::Sphere { radius } => {
            let d = p - x.pos;
            let t = first_root(v.dot(v), v.dot(&d), d.dot(&d) - radius * radius)?;
            Some((t, unit(p + v * t - x.pos)))
        }
        Primitive::Capsule { radius, half_length: h } => {
            if !meets_sphere(&x.pos, (radius + h) * (radius + h), p, v) {
                return None;
            }
            let (lp, lv) = local(x, p, v);
            // (distance, which part: −1 bottom cap, 0 side, 1 top cap)
            let mut best: Option<(f64, f64)> = None;
            let side = first_root(
                lv.x * lv.x + lv.y * lv.y,
                lv.x * lp.x + lv.y * lp.y,
                lp.x * lp.x + lp.y * lp.y - radius * radius,
            );
            if let Some(t) = side.filter(|t| (lp.z + t * lv.z).abs() <= h) {
                best = Some((t, 0.0));
            }
            for cap in [1.0, -1.0] {
                let d = Vec3::new(lp.x, lp.y, lp.z - cap * h);
                let Some(ts) = roots(lv.dot(&lv), lv.dot(&d), d.dot(&d) - radius * radius) else { continue };
                for t in ts {
                    let z = lp.z + t * lv.z;
                    let on_cap = if cap > 0.0 { z >= h } else { z <= -h };
                    if t >= 0.0 && on_cap && best.is_none_or(|(b, _)| t < b) {
                        best = Some((t, cap));
                    }
                }
            }
            let (t, part) = best?;
            let n = Vec3::new(
                lp.x + lv.x * t,
                lp.y + lv.y * t,
                if part == 0.0 { 0.0 } else { lp.z + lv.z * t - h * part },
            );
            Some((t, x.rot * unit(n)))
        }
        Primitive::Ellipsoid { radii } => {
            let (lp, lv) = local(x, p, v);
            let s =
                Vec3::new(1.0 / (radii.x * radii.x), 1.0 / (radii.y * radii.y), 1.0 / (radii.z * radii.z));
            let t = first_root(
                s.x * lv.x * lv.x + s.y * lv.y * lv.y + s.z * lv.z * lv.z,
                s.x * lv.x * lp.x + s.y * lv.y * lp.y + s.z * lv.z * lp.z,
                s.x * lp.x * lp.x + s.y * lp.y * lp.y + s.z * lp.z * lp.z - 1.0,
            )?;
            let l = lp + lv * t;
            Some((t, x.rot * unit(s.component_mul(&l))))
        }
        Primitive::Cylinder { radius, half_length: h } => {
            if !meets_sphere(&x.pos, radius * radius + h * h, p, v) {
                return None;
            }
            let (lp, lv) = local(x, p, v);
            let mut best: Option<(f64, f64)> = None;
            if lv.z.abs() > MINVAL {
                for cap in [-1.0, 1.0] {
                    let t = (cap * h - lp.z) / lv.z;
                    let (a, b) = (lp.x + t * lv.x, lp.y + t * lv.y);
                    if t >= 0.0 && a * a + b * b <= radius * radius && best.is_none_or(|(x, _)| t < x) {
                        best = Some((t, cap));
                    }
                }
            }
            let side = first_root(
                lv.x * lv.x + lv.y * lv.y,
                lv.x * lp.x + lv.y * lp.y,
                lp.x * lp.x + lp.y * lp.y - radius * radius,
            );
            if let Some(t) = side.filter(|t| (lp.z + t * lv.z).abs() <= h) {
                if best.is_none_or(|(b, _)| t < b) {
                    best = Some((t, 0.0));
                }
            }
            let (t, part) = best?;
            let n = if part == 0.0 {
                unit(Vec3::new(lp.x + lv.x * t, lp.y + lv.y * t, 0.0))
            } else {
                Vec3::new(0.0, 0.0, part)
            };
            Some((t, x.rot * n))
        }
        Primitive::Box { half_extents: s } => {
            if !meets_sphere(&x.pos, s.dot(&s), p, v) {
                return None;
            }
            let (lp, lv) = local(x, p, v);
            let mut best: Option<(f64, usize, f64)> = None;
            for i in 0..3 {
                if lv[i].abs() <= MINVAL {
                    continue;
                }
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                let (j, k) = (j.min(k), j.max(k));
                for side in [-1.0, 1.0] {
                    let t = (side * s[i] - lp[i]) / lv[i];
                    if t >= 0.0
                        && (lp[j] + t * lv[j]).abs() <= s[j]
                        && (lp[k] + t * lv[k]).abs() <= s[k]
                        && best.is_none_or(|(b, _, _)| t < b)
                    {
                        best = Some((t, i, side));
                    }
                }
            }
            let (t, axis, side) = best?;
            Some((t, x.rot.column(axis) * side))
        }
    }
}

/// The ray against a plane at pose `x` with MJCF half-sizes `size` (MuJoCo's `ray_plane`): hit
/// from the front only, within the rectangle where a size is positive.
pub(crate) fn ray_plane(x: &Transform, size: [f64; 2], p: &Vec3, v: &Vec3) -> Option<(f64, Vec3)> {
    let (lp, lv) = local(x, p, v);
    if lv.z > -MINVAL {
        return None;
    }
    let t = -lp.z / lv.z;
    if t < 0.0 {
        return None;
    }
    let (a, b) = (lp.x + t * lv.x, lp.y + t * lv.y);
    let within = (size[0] <= 0.0 || a.abs() <= size[0]) && (size[1] <= 0.0 || b.abs() <= size[1]);
    within.then(|| (t, x.rot.column(2).into_owned()))
}

/// The ray against a mesh's triangles at pose `x`: the nearest triangle crossing the ray at
/// x ≥ 0, either face, with the triangle's normal (MuJoCo's `mj_rayMesh`).
pub(crate) fn ray_mesh(x: &Transform, mesh: &MeshTriangles, p: &Vec3, v: &Vec3) -> Option<(f64, Vec3)> {
    let (lp, lv) = local(x, p, v);
    let basis = normal_plane_basis(&lv);
    let ray = Ray::new(Vector::new(lp.x, lp.y, lp.z), Vector::new(lv.x, lv.y, lv.z));
    let hit = |k: u32| ray_triangle(&mesh.corners(k as usize), &lp, &lv, &basis).filter(|(t, _)| *t >= 0.0);
    let (k, _) = mesh.bvh.cast_ray(&ray, f64::MAX, |k, _| hit(k).map(|(t, _)| t))?;
    let (t, n) = hit(k)?;
    Some((t, x.rot * n))
}

/// Two unit vectors spanning the plane normal to `v` (MuJoCo's construction in `mju_rayTree`:
/// start from (1, 1, 1) with the component of v's largest coordinate zeroed).
fn normal_plane_basis(v: &Vec3) -> [Vec3; 2] {
    let mut b0 = Vec3::repeat(1.0);
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        b0.x = 0.0;
    } else if a.y >= a.z {
        b0.y = 0.0;
    } else {
        b0.z = 0.0;
    }
    let b1 = unit(b0 - v * (v.dot(&b0) / v.dot(v)));
    let b0 = unit(b1.cross(v));
    [b0, b1]
}

/// The ray `p + t·v` against the triangle `c`: t (possibly negative: the caller keeps t ≥ 0) and
/// the unit normal (c₀ − c₂) × (c₁ − c₂), or None when the ray misses it or runs parallel to it
/// (MuJoCo's `ray_triangle`: the triangle projected on the plane normal to v, `basis`, must
/// contain the ray's point, with a projected determinant of at least 1e-15).
fn ray_triangle(c: &[Vec3; 3], p: &Vec3, v: &Vec3, basis: &[Vec3; 2]) -> Option<(f64, Vec3)> {
    // The corners relative to p, projected on the basis.
    let q = c.map(|ci| {
        let d = ci - p;
        [basis[0].dot(&d), basis[1].dot(&d)]
    });
    for k in 0..2 {
        if (q[0][k] > 0.0 && q[1][k] > 0.0 && q[2][k] > 0.0)
            || (q[0][k] < 0.0 && q[1][k] < 0.0 && q[2][k] < 0.0)
        {
            return None;
        }
    }
    // Barycentric coordinates of the origin in the projected triangle.
    let (e0, e1) = ([q[0][0] - q[2][0], q[0][1] - q[2][1]], [q[1][0] - q[2][0], q[1][1] - q[2][1]]);
    let det = e0[0] * e1[1] - e1[0] * e0[1];
    if det.abs() < MINVAL {
        return None;
    }
    let (r0, r1) = (-q[2][0], -q[2][1]);
    let t0 = (e1[1] * r0 - e1[0] * r1) / det;
    let t1 = (-e0[1] * r0 + e0[0] * r1) / det;
    if t0 < 0.0 || t1 < 0.0 || t0 + t1 > 1.0 {
        return None;
    }
    let n = (c[0] - c[2]).cross(&(c[1] - c[2]));
    let denom = v.dot(&n);
    if denom.abs() < MINVAL {
        return None;
    }
    let t = -(p - c[2]).dot(&n) / denom;
    Some((t, unit(n)))
}

/// The ray `p_world + x·vec_world`, x ≥ 0, against the shape of site `site` (an index in
/// `Model::frames` of an MJCF site), as MuJoCo's touch sensor casts it (`mju_rayGeom` on the
/// site's type and size): the distance (units of |vec_world|) and the world unit normal at the
/// hit, or None. Reads the site poses of `data` (after forward kinematics).
///
/// # Errors
/// [`InputError`] when `data` was not made for `model`, `site` is not a site with a primitive
/// shape, a coordinate is not finite, or `vec_world` is shorter than 1e-15.
pub fn ray_site(
    model: &Model,
    data: &Data,
    site: usize,
    p_world: Vec3,
    vec_world: Vec3,
) -> Result<Option<(f64, Vec3)>, InputError> {
    const F: &str = "collision::ray_site";
    crate::error::check::data(F, model, data)?;
    let shape = site_shape(F, model, site)?;
    check_ray(F, &p_world, &vec_world)?;
    Ok(ray_primitive(&data.x_world_frame[site], &shape, &p_world, &vec_world))
}

/// The primitive shape of site frame `site`, or the error naming what is wrong.
pub(crate) fn site_shape(
    function: &'static str,
    model: &Model,
    site: usize,
) -> Result<Primitive, InputError> {
    crate::error::check::frame(function, model, site)?;
    let frame = &model.frames[site];
    frame.site.ok_or_else(|| InputError::Value {
        function,
        argument: "site",
        detail: format!(
            "is frame {site} ('{}'), which is not a site with a primitive shape ({:?}; mesh sites keep no shape)",
            frame.name, frame.kind
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::Mat3;

    fn at(pos: Vec3) -> Transform {
        Transform::new(Mat3::identity(), pos)
    }

    /// `ray_meets_primitive` answers as `ray_primitive(..).is_some()` over a fan of rays from
    /// points around and inside a tilted capsule (side, caps, misses, grazing).
    #[test]
    fn meets_is_whether_the_ray_hits() {
        let rot = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1).into_inner();
        let x = Transform::new(rot, Vec3::new(0.1, -0.2, 0.3));
        let shapes = [
            Primitive::Capsule { radius: 0.25, half_length: 0.5 },
            Primitive::Sphere { radius: 0.5 },
            Primitive::Box { half_extents: Vec3::new(0.5, 0.3, 0.75) },
        ];
        let (mut hits, mut misses) = (0, 0);
        for shape in &shapes {
            for i in 0..7 {
                for j in 0..7 {
                    let p = Vec3::new(
                        0.1 + 0.3 * (i as f64 - 3.0),
                        -0.2 + 0.25 * (j as f64 - 3.0),
                        0.3 + 0.2 * i as f64 - 0.6,
                    );
                    for k in 0..12 {
                        let a = k as f64 * 0.55;
                        let v = Vec3::new(a.cos(), a.sin(), 0.8 * (0.7 * a).cos() - 0.2);
                        let want = ray_primitive(&x, shape, &p, &v).is_some();
                        assert_eq!(ray_meets_primitive(&x, shape, &p, &v), want, "{shape:?} {p:?} {v:?}");
                        if want {
                            hits += 1;
                        } else {
                            misses += 1;
                        }
                    }
                }
            }
        }
        assert!(hits > 100 && misses > 100, "{hits} hits, {misses} misses");
    }

    #[test]
    fn primitives_from_outside_and_inside() {
        let origin = at(Vec3::zeros());
        let down = -Vec3::z();
        let top = Vec3::new(0.0, 0.0, 3.0);
        let cases = [
            (Primitive::Sphere { radius: 0.5 }, 2.5),
            (Primitive::Capsule { radius: 0.25, half_length: 0.5 }, 2.25),
            (Primitive::Cylinder { radius: 0.25, half_length: 0.5 }, 2.5),
            (Primitive::Box { half_extents: Vec3::new(0.5, 0.5, 0.75) }, 2.25),
            (Primitive::Ellipsoid { radii: Vec3::new(0.5, 0.5, 1.0) }, 2.0),
        ];
        for (shape, d) in cases {
            let (t, n) = ray_primitive(&origin, &shape, &top, &down).unwrap();
            assert_eq!((t, n), (d, Vec3::z()), "{shape:?}");
            // From the centre: the exit point, the outward normal (downwards).
            let (t, n) = ray_primitive(&origin, &shape, &Vec3::zeros(), &down).unwrap();
            assert_eq!((t, n), (3.0 - d, -Vec3::z()), "{shape:?} from inside");
            // Pointing away: no hit.
            assert!(ray_primitive(&origin, &shape, &top, &Vec3::z()).is_none());
        }
    }

    #[test]
    fn plane_is_one_sided_and_bounded() {
        let plane = at(Vec3::zeros());
        assert_eq!(
            ray_plane(&plane, [0.0, 0.0], &Vec3::new(5.0, 0.0, 1.0), &-Vec3::z()),
            Some((1.0, Vec3::z()))
        );
        assert!(ray_plane(&plane, [0.0, 0.0], &Vec3::new(0.0, 0.0, -1.0), &Vec3::z()).is_none());
        assert!(ray_plane(&plane, [1.0, 1.0], &Vec3::new(5.0, 0.0, 1.0), &-Vec3::z()).is_none());
        assert!(ray_plane(&plane, [0.0, 0.0], &Vec3::new(0.0, 0.0, 1.0), &Vec3::x()).is_none());
    }

    #[test]
    fn triangle_hits_either_face() {
        let c = [Vec3::zeros(), Vec3::x(), Vec3::y()];
        let p = Vec3::new(0.25, 0.25, 1.0);
        let basis = normal_plane_basis(&-Vec3::z());
        assert_eq!(ray_triangle(&c, &p, &-Vec3::z(), &basis), Some((1.0, Vec3::z())));
        let basis = normal_plane_basis(&Vec3::z());
        let below = Vec3::new(0.25, 0.25, -1.0);
        assert_eq!(ray_triangle(&c, &below, &Vec3::z(), &basis), Some((1.0, Vec3::z())));
    }
}
