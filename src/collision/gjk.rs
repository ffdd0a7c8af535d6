//! The distance between two separated convex shapes given by support maps: the
//! Gilbert–Johnson–Keerthi algorithm (Gilbert, Johnson, Keerthi 1988; van den Bergen,
//! *Collision Detection in Interactive 3D Environments*, §4.3), run to f64 round-off.
//!
//! On the Minkowski difference C = A − B it keeps a simplex W of at most four support points and
//! v, the point of conv(W) nearest the origin; each step adds w, the support point of C along −v,
//! and stops when v·w certifies the distance to within 1e-15 of |v|² (the lower bound v·w / |v|
//! and the upper bound |v| agree), when w adds nothing, or when |v| stops decreasing. The nearest
//! point of a simplex is found over its faces directly (each face's affine projection of the
//! origin, kept when its barycentric coordinates are non-negative: at most 15 tiny solves), so
//! no degeneracy threshold limits the accuracy.
//!
//! parry3d-f64's GJK (which lagrange's EPA path starts from) stops at a relative gap of ~5e-8
//! between its bounds and was measured to return a sphere–box distance 7e-5 too large; MuJoCo's
//! `mj_geomDistance` converges to its `ccd_tolerance`. The distance found here is exact to
//! round-off for polytopes and within ~1e-15 relative on curved shapes, where the witness points
//! are determined to √ε of the shapes' size (the distance is stationary in them); the caller
//! polishes those on smooth shapes ([`super::convex::support_pair`]).

use super::convex::ConvexShape;
use crate::spatial::{Transform, Vec3};

/// A vertex of the simplex: the support point w = a − b and its two parts.
#[derive(Clone, Copy, Debug)]
struct Vertex {
    w: Vec3,
    a: Vec3,
    b: Vec3,
}

/// The witness points (on A, on B) and the distance of two separated shapes, or None when they
/// overlap or touch (closer than 1e-12 of their size): the caller then needs penetration (EPA).
/// No allocation.
pub(crate) fn separation(
    x1: &Transform,
    s1: &ConvexShape,
    x2: &Transform,
    s2: &ConvexShape,
) -> Option<(Vec3, Vec3, f64)> {
    let support = |d: &Vec3| {
        let a = s1.world_support(x1, d);
        let b = s2.world_support(x2, &-d);
        Vertex { w: a - b, a, b }
    };
    // Start towards the difference of the origins.
    let mut v = x1.pos - x2.pos;
    if v.norm_squared() == 0.0 {
        v = Vec3::x();
    }
    let mut simplex = Simplex {
        vertices: [Vertex { w: Vec3::zeros(), a: Vec3::zeros(), b: Vec3::zeros() }; 4],
        len: 0,
        coords: [0.0; 4],
    };
    let mut scale: f64 = 0.0;
    for _ in 0..256 {
        let w = support(&-v);
        scale = scale.max(w.w.norm());
        let vv = v.norm_squared();
        // Converged: |v|² − v·w ≤ ε |v|² (the bounds |v| and v·w / |v| agree).
        if simplex.len > 0 && vv - v.dot(&w.w) <= 1e-15 * vv {
            break;
        }
        if simplex.vertices[..simplex.len].iter().any(|p| p.w == w.w) {
            break;
        }
        let mut grown = simplex;
        grown.vertices[grown.len] = w;
        grown.len += 1;
        let Some((v_new, reduced)) = nearest(&grown) else { break };
        if simplex.len > 0 && v_new.norm_squared() >= vv {
            break; // no progress: keep the previous simplex's answer
        }
        v = v_new;
        simplex = reduced;
        if simplex.len == 4 || v.norm() <= 1e-12 * scale {
            return None;
        }
    }
    if simplex.len == 0 || v.norm() <= 1e-12 * scale {
        return None;
    }
    let (mut pa, mut pb) = (Vec3::zeros(), Vec3::zeros());
    for (p, l) in simplex.vertices[..simplex.len].iter().zip(&simplex.coords) {
        pa += p.a * *l;
        pb += p.b * *l;
    }
    Some((pa, pb, (pb - pa).norm()))
}

/// Up to four simplex vertices with the barycentric coordinates of the nearest point.
#[derive(Clone, Copy, Debug)]
struct Simplex {
    vertices: [Vertex; 4],
    len: usize,
    coords: [f64; 4],
}

/// The point of the simplex's hull nearest the origin and the smallest sub-simplex holding it
/// (with its barycentric coordinates); None when no face gives one (NaN input).
fn nearest(s: &Simplex) -> Option<(Vec3, Simplex)> {
    let n = s.len;
    let mut best: Option<(f64, Vec3, Simplex)> = None;
    for mask in 1u32..(1 << n) {
        let mut face = Simplex { vertices: s.vertices, len: 0, coords: [0.0; 4] };
        for i in (0..n).filter(|&i| mask & (1 << i) != 0) {
            face.vertices[face.len] = s.vertices[i];
            face.len += 1;
        }
        let Some(coords) = affine_projection(&face.vertices[..face.len]) else { continue };
        if coords[..face.len].iter().any(|&c| c < 0.0) {
            continue;
        }
        face.coords = coords;
        let p: Vec3 = face.vertices[..face.len].iter().zip(&coords).map(|(v, &c)| v.w * c).sum();
        let d = p.norm_squared();
        if best.as_ref().is_none_or(|(bd, ..)| d < *bd) {
            best = Some((d, p, face));
        }
    }
    best.map(|(_, p, face)| (p, face))
}

/// The barycentric coordinates of the origin's projection on the affine hull of `points`, or None
/// when they are affinely dependent.
fn affine_projection(points: &[Vertex]) -> Option<[f64; 4]> {
    let k = points.len() - 1;
    let p0 = points[0].w;
    if k == 0 {
        return Some([1.0, 0.0, 0.0, 0.0]);
    }
    // Minimise |p0 + Σ μᵢ eᵢ|²: the normal equations G μ = −Eᵀ p0, G = EᵀE (k ≤ 3).
    let mut e = [Vec3::zeros(); 3];
    for (ei, p) in e.iter_mut().zip(&points[1..]) {
        *ei = p.w - p0;
    }
    let mut g = [[0.0; 4]; 3];
    for r in 0..k {
        for c in 0..k {
            g[r][c] = e[r].dot(&e[c]);
        }
        g[r][3] = -e[r].dot(&p0);
    }
    // Gaussian elimination with partial pivoting; a pivot below 1e-24 of the Gram matrix's
    // scale means the points are (nearly) affinely dependent.
    let scale = (0..k).map(|r| g[r][r]).fold(0.0, f64::max);
    for col in 0..k {
        let piv = (col..k).max_by(|&a, &b| g[a][col].abs().total_cmp(&g[b][col].abs()))?;
        if g[piv][col].abs() <= 1e-24 * scale || g[piv][col].is_nan() {
            return None;
        }
        g.swap(col, piv);
        for r in col + 1..k {
            let f = g[r][col] / g[col][col];
            for c in col..4 {
                g[r][c] -= f * g[col][c];
            }
        }
    }
    let mut mu = [0.0; 3];
    for r in (0..k).rev() {
        let s: f64 = (r + 1..k).map(|c| g[r][c] * mu[c]).sum();
        mu[r] = (g[r][3] - s) / g[r][r];
    }
    let mut out = [0.0; 4];
    out[0] = 1.0 - mu[..k].iter().sum::<f64>();
    out[1..=k].copy_from_slice(&mu[..k]);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::Mat3;
    use parry3d_f64::math::Vector;
    use parry3d_f64::shape::{Ball, Cuboid};

    #[test]
    fn sphere_box_distance_is_exact() {
        // A sphere of 0.125 above a box's corner region: the exact distance is
        // |c − corner| − r with the box's nearest point a corner.
        let x1 = Transform::new(Mat3::identity(), Vec3::new(0.5, 0.4, 0.3));
        let x2 = Transform::new(Mat3::identity(), Vec3::zeros());
        let ball = ConvexShape::Ball(Ball::new(0.125));
        let cube = ConvexShape::Cuboid(Cuboid::new(Vector::new(0.25, 0.125, 0.0625)));
        let (pa, pb, d) = separation(&x1, &ball, &x2, &cube).unwrap();
        let exact = (Vec3::new(0.5, 0.4, 0.3) - Vec3::new(0.25, 0.125, 0.0625)).norm() - 0.125;
        assert!((d - exact).abs() < 1e-15, "{d} vs {exact}");
        assert!((pb - Vec3::new(0.25, 0.125, 0.0625)).amax() < 1e-15);
        assert!(((pa - x1.pos).norm() - 0.125).abs() < 1e-15);
        // Overlapping: no separation.
        let x1 = Transform::new(Mat3::identity(), Vec3::new(0.3, 0.0, 0.0));
        assert!(separation(&x1, &ball, &x2, &cube).is_none());
    }
}
