//! Plane against convex geoms in closed form, with MuJoCo's multi-point rules so that resting
//! contact is stable (MuJoCo's `mjc_Plane*` functions, engine_collision_primitive.c): the plane is
//! infinite (z = 0 of its frame, its normal the frame's z axis; geoms below it are in contact).
//!
//! | shape | contacts |
//! |---|---|
//! | sphere | the point of the sphere deepest below the plane |
//! | capsule | one per end sphere (2), tangent hint along the axis |
//! | box | every corner within the distance, at most 4 |
//! | cylinder | the deepest rim point of the lower cap, the same rim point of the other cap, and, when the lower cap lies on the plane, two more points of that cap's rim at ±120° (a triangle) |
//! | ellipsoid | its support point along −normal |
//! | mesh | the collision pass: [`super::plane_mesh`] (MuJoCo 4.0's deepest vertex and vertices of its face polygon facing the plane, at most 4); [`hull`] here (the deepest vertex and up to 3 more, spread out) serves geom distances |
//!
//! Each contact is (position on the plane side's midpoint, signed distance, tangent hint); the
//! normal is the plane's.

use crate::spatial::{Transform, Vec3};

/// One plane contact: the point on the geom's surface, its signed distance to the plane, and a
/// tangent hint.
#[derive(Clone, Copy, Debug)]
pub struct PlanePoint {
    /// The point on the geom's surface (world).
    pub surface: Vec3,
    /// Its signed distance above the plane (m), negative = penetration.
    pub dist: f64,
    /// Direction for the contact frame's first tangent (a capsule's axis), if any.
    pub hint: Option<Vec3>,
    /// Which feature of the geom: corner, end, rim point or hull vertex index.
    pub feature: u32,
}

/// Signed distance of a point above the plane.
fn height(plane: &Transform, n: &Vec3, p: &Vec3) -> f64 {
    n.dot(&(p - plane.pos))
}

/// Sphere of `radius` centred at `c`.
pub fn sphere(plane: &Transform, c: &Vec3, radius: f64, reach: f64, out: &mut impl FnMut(PlanePoint)) {
    let n = plane.rot.column(2).into_owned();
    let d = height(plane, &n, c) - radius;
    if d <= reach {
        out(PlanePoint { surface: c - n * radius, dist: d, hint: None, feature: 0 });
    }
}

/// Capsule: its two end spheres.
pub fn capsule(
    plane: &Transform,
    x: &Transform,
    radius: f64,
    half: f64,
    reach: f64,
    out: &mut impl FnMut(PlanePoint),
) {
    let axis = x.rot.column(2).into_owned();
    for (k, end) in [x.pos + axis * half, x.pos - axis * half].into_iter().enumerate() {
        sphere(plane, &end, radius, reach, &mut |p| {
            out(PlanePoint { hint: Some(axis), feature: k as u32, ..p })
        });
    }
}

/// Box with half-extents `half`: the corners within reach, at most four (MuJoCo's order).
pub fn cuboid(plane: &Transform, x: &Transform, half: &Vec3, reach: f64, out: &mut impl FnMut(PlanePoint)) {
    let n = plane.rot.column(2).into_owned();
    let centre = height(plane, &n, &x.pos);
    let mut count = 0;
    for i in 0..8 {
        let local = Vec3::new(
            if i & 1 != 0 { half.x } else { -half.x },
            if i & 2 != 0 { half.y } else { -half.y },
            if i & 4 != 0 { half.z } else { -half.z },
        );
        let corner = x.rot * local;
        let along = n.dot(&corner);
        if centre + along > reach || along > 0.0 {
            continue;
        }
        out(PlanePoint { surface: x.pos + corner, dist: centre + along, hint: None, feature: i });
        count += 1;
        if count == 4 {
            return;
        }
    }
}

/// Cylinder of `radius` and half-length `half` (axis z of `x`).
pub fn cylinder(
    plane: &Transform,
    x: &Transform,
    radius: f64,
    half: f64,
    reach: f64,
    out: &mut impl FnMut(PlanePoint),
) {
    let n = plane.rot.column(2).into_owned();
    let mut axis = x.rot.column(2).into_owned();
    let mut along = n.dot(&axis);
    if along > 0.0 {
        axis = -axis;
        along = -along;
    }
    let centre = height(plane, &n, &x.pos);
    // Rim direction towards the plane: −n without its axial part, scaled to the radius.
    let mut rim = axis * along - n;
    let len = rim.norm();
    rim = if len >= 1e-15 { rim * (radius / len) } else { x.rot.column(0).into_owned() * radius };
    let rim_height = n.dot(&rim);
    let axial = axis * half;
    let axial_height = along * half;
    let first = centre + axial_height + rim_height;
    if first > reach {
        return;
    }
    out(PlanePoint { surface: x.pos + rim + axial, dist: first, hint: None, feature: 0 });
    let second = centre - axial_height + rim_height;
    if second <= reach {
        out(PlanePoint { surface: x.pos + rim - axial, dist: second, hint: None, feature: 1 });
    }
    // Two more rim points of the lower cap at ±120° from the first (half the rim height).
    let third = centre + axial_height - 0.5 * rim_height;
    if third <= reach {
        let side = rim.cross(&axis).normalize() * (radius * 3f64.sqrt() / 2.0);
        for (k, s) in [side, -side].into_iter().enumerate() {
            out(PlanePoint {
                surface: x.pos + s + axial - rim * 0.5,
                dist: third,
                hint: None,
                feature: 2 + k as u32,
            });
        }
    }
}

/// Ellipsoid with semi-axes `radii`: the support point along −n, p = R D² Rᵀ(−n) / ‖D Rᵀ n‖.
pub fn ellipsoid(
    plane: &Transform,
    x: &Transform,
    radii: &Vec3,
    reach: f64,
    out: &mut impl FnMut(PlanePoint),
) {
    let n = plane.rot.column(2).into_owned();
    let n_local = x.rot.transpose() * n;
    let scaled = n_local.component_mul(radii);
    let norm = scaled.norm();
    if norm == 0.0 {
        return;
    }
    let p_local = -scaled.component_mul(radii) / norm;
    let surface = x.pos + x.rot * p_local;
    let d = height(plane, &n, &surface);
    if d <= reach {
        out(PlanePoint { surface, dist: d, hint: None, feature: 0 });
    }
}

/// Convex hull (vertices in the geom frame): the deepest vertex, then up to three more within
/// reach, each the farthest from those already taken (a spread-out support polygon).
pub fn hull(
    plane: &Transform,
    x: &Transform,
    vertices: &[Vec3],
    reach: f64,
    out: &mut impl FnMut(PlanePoint),
) {
    let n = plane.rot.column(2).into_owned();
    let at = |i: usize| {
        let p = x.act_point(&vertices[i]);
        (p, height(plane, &n, &p))
    };
    let mut taken: [Option<usize>; 4] = [None; 4];
    // Deepest vertex.
    let mut best: Option<(usize, f64)> = None;
    for i in 0..vertices.len() {
        let (_, d) = at(i);
        if d <= reach && best.is_none_or(|(_, bd)| d < bd) {
            best = Some((i, d));
        }
    }
    let Some((first, _)) = best else { return };
    taken[0] = Some(first);
    for k in 1..4 {
        let mut far: Option<(usize, f64)> = None;
        for i in 0..vertices.len() {
            let (p, d) = at(i);
            if d > reach {
                continue;
            }
            let spread =
                taken[..k].iter().flatten().map(|&j| (p - at(j).0).norm()).fold(f64::INFINITY, f64::min);
            if spread > 1e-9 && far.is_none_or(|(_, s)| spread > s) {
                far = Some((i, spread));
            }
        }
        match far {
            Some((i, _)) => taken[k] = Some(i),
            None => break,
        }
    }
    for i in taken.into_iter().flatten() {
        let (p, d) = at(i);
        out(PlanePoint { surface: p, dist: d, hint: None, feature: i as u32 });
    }
}
