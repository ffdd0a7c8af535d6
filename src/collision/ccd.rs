//! MuJoCo 4.0's native convex collision solver (`mjc_ccd` in engine_collision_gjk.c, its support
//! functions and `mjc_penetration` in engine_collision_convex.c), read for its semantics and
//! written anew, so that the convex pairs stop where MuJoCo's stop: GJK with the signed-volume
//! distance subalgorithm (Montanari et al., ToG 2017) and MuJoCo's Frank–Wolfe duality-gap stop
//! (`ccd_tolerance`, exact on boxes and meshes without margin), the initial polytope built from
//! GJK's 1-, 2- or 3-simplex, and EPA with MuJoCo's face map, horizon and bounds
//! (`ccd_tolerance`, `ccd_iterations`).
//!
//! The C source read is a snapshot of 2026-08; the live MuJoCo 4.0.0 (the reference) differs from
//! it. Its library `libmujoco.so.4.0.0` (the Python wheel's) is not stripped and has no fused
//! multiply-adds, so its `gjk`, `S2D`, `S1D`, `epa` and support functions were read from their
//! machine code (`objdump -d`) and their support calls traced under `gdb` against this module's
//! on the goldens (`docs/multiccd.md`, "Reading the live library"); this module follows that code
//! operation for operation where they differ:
//! - GJK's next x_k is the origin's projection on the line or plane of the reduced simplex (the
//!   barycentric combination only when it is degenerate); the separation test comes before the
//!   duality-gap test, which the first iteration skips; |x_k| is tested after each update;
//!   there is no hand-over of a tetrahedron to an intersection test on the contact path
//!   ([`separated`], lagrange's own early-out, keeps the snapshot's `gjkIntersect`: a proof of
//!   separation either way) and no direction tuning for discrete geoms (the projection is
//!   already orthogonal to the simplex);
//! - `S2D`'s barycentric coordinates are signed areas from the vertices relative to the projected
//!   origin, divided by their sum; `S1D` returns the second vertex for a segment shorter than
//!   1e-15;
//! - the ellipsoid's support scales each component by (1/|s|)·size;
//! - the first GJK runs on the cores for every pair with a sphere, a capsule or a margin: spheres
//!   and capsules shrunk to their centre and segment, every geom without the margin (the source
//!   shrinks only spheres and capsules, keeping the margin of the others);
//! - EPA stops when this iteration's upper bound (not the running minimum) is within the
//!   tolerance of the lower one, and drops a first-iteration face whose bound is below it by
//!   the tolerance.
//!
//! Each geom is inflated by half the pair's margin (MuJoCo's `support`); a shallow contact found
//! on the cores is their distance less the radii and the margin.
//!
//! The result is the EPA face's witness points, normal and distance, and the face's three
//! polytope vertices as the geom features their support points came from ([`EpaFace`]: from
//! which [`super::multiccd`] finds the other points of a multi-point contact, as MuJoCo's
//! `multicontact` does). No allocation once the thread's workspace has grown.

use super::convex::ConvexShape;
use crate::spatial::{Transform, Vec3};
use std::cell::RefCell;

/// MuJoCo's `mjMINVAL`.
const MINVAL: f64 = 1e-15;
/// MuJoCo's `mjMAXVAL`.
const MAXVAL: f64 = 1e10;
/// MuJoCo's `mjMAX_LIMIT` (double precision).
const MAX_LIMIT: f64 = f64::MAX;
/// Hull size below which MuJoCo scans every mesh vertex instead of hill climbing
/// (`mjMESH_HILLCLIMB_MIN`).
const HILLCLIMB_MIN: usize = 10;

/// How one geom's support points are taken: its shape, or (spheres and capsules in the first
/// pass) its centre or its segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Core {
    Shape,
    Point,
    Line,
}

/// One geom as the solver sees it (MuJoCo's `mjCCDObj`).
pub(crate) struct CcdObj<'a> {
    shape: &'a ConvexShape,
    x: &'a Transform,
    /// The pair's margin: the support adds half of it along the direction.
    margin: f64,
    core: Core,
    /// The last support vertex (box corner bits, hull vertex index, a cylinder's cap: 0 top, 1
    /// bottom; −1 for the other curved shapes).
    vertindex: i32,
    /// The hill climb's warm start (−1: none yet).
    meshindex: i32,
    /// A height-field prism standing in for `shape` (its frame's three base then three top
    /// vertices, MuJoCo's `data.hfield.prism`), or None.
    prism: Option<&'a [Vec3; 6]>,
    /// A hull's MuJoCo mesh frame in the world (its rotation, then its origin `x·c`): MuJoCo
    /// poses a mesh geom there and stores the vertices in it, so a support point is this frame
    /// applied to the stored vertex, rounded as MuJoCo's is (the identity for other shapes).
    mesh_frame: (crate::spatial::Mat3, Vec3),
}

impl<'a> CcdObj<'a> {
    /// Geom `shape` at pose `x`, inflated by half of `margin`.
    pub(crate) fn new(shape: &'a ConvexShape, x: &'a Transform, margin: f64) -> Self {
        let mesh_frame = match shape {
            ConvexShape::Hull(h) => {
                let (c, axes) = &h.graph().box_frame;
                let rot = if h.mesh_axes_identity() { x.rot } else { x.rot * axes };
                (rot, x.act_point(c))
            }
            _ => (crate::spatial::Mat3::identity(), Vec3::zeros()),
        };
        Self { shape, x, margin, core: Core::Shape, vertindex: -1, meshindex: -1, prism: None, mesh_frame }
    }

    fn discrete(&self) -> bool {
        self.prism.is_some() || matches!(self.shape, ConvexShape::Cuboid(_) | ConvexShape::Hull(_))
    }

    /// The support point along unit world direction `dir` (no margin).
    #[inline(always)]
    fn support(&mut self, dir: &Vec3) -> Vec3 {
        let (rot, pos) = (&self.x.rot, &self.x.pos);
        match self.core {
            Core::Point => return *pos,
            Core::Line => {
                let z = rot.column(2);
                let len = match self.shape {
                    ConvexShape::Capsule(c) => c.segment.b.z,
                    _ => 0.0,
                };
                let scl = if z.dot(dir) >= 0.0 { len } else { -len };
                return z * scl + pos;
            }
            Core::Shape => {}
        }
        let local = rot.tr_mul(dir);
        if let Some(prism) = self.prism {
            // MuJoCo's `mjc_prism_support`: the best of the base or the top by dir.z.
            let start = if local.z < 0.0 { 0 } else { 3 };
            let (mut ibest, mut best) = (start, prism[start].dot(&local));
            for (i, v) in prism.iter().enumerate().skip(start + 1).take(2) {
                let d = v.dot(&local);
                if d > best {
                    (ibest, best) = (i, d);
                }
            }
            // MuJoCo's prism support leaves the vertex index alone (−1): EPA's repeated-vertex
            // test then compares the other geom's features only.
            return rot * prism[ibest] + pos;
        }
        let supp = match self.shape {
            ConvexShape::Ball(b) => return dir * b.radius + pos,
            ConvexShape::Capsule(c) => {
                let mut s = local * c.radius;
                s.z += if local.z >= 0.0 { c.segment.b.z } else { -c.segment.b.z };
                s
            }
            ConvexShape::Ellipsoid(e) => {
                let size = Vec3::new(e.radii.x, e.radii.y, e.radii.z);
                let s = local.component_mul(&size);
                let norm2 = s.dot(&s);
                if norm2 < MINVAL * MINVAL {
                    return rot.column(0) * size.x + pos;
                }
                // MuJoCo scales each component by (1/|s|)·size, not (s/|s|)·size: the
                // product of the two factors is rounded first (the live 4.0.0's code).
                let inv = 1.0 / norm2.sqrt();
                Vec3::new(s.x * (inv * size.x), s.y * (inv * size.y), s.z * (inv * size.z))
            }
            ConvexShape::Cylinder(c) => {
                // MuJoCo 4.0.0 marks the cap: 0 the top, 1 the bottom.
                self.vertindex = (local.z < 0.0) as i32;
                let n2 = local.x * local.x + local.y * local.y;
                let scl = if n2 >= MINVAL * MINVAL { c.radius / n2.sqrt() } else { 0.0 };
                Vec3::new(
                    scl * local.x,
                    scl * local.y,
                    if local.z >= 0.0 { c.half_height } else { -c.half_height },
                )
            }
            ConvexShape::Cuboid(b) => {
                let h = b.half_extents;
                let s = Vec3::new(
                    if local.x >= 0.0 { h.x } else { -h.x },
                    if local.y >= 0.0 { h.y } else { -h.y },
                    if local.z >= 0.0 { h.z } else { -h.z },
                );
                self.vertindex = (s.x > 0.0) as i32 | ((s.y > 0.0) as i32) << 1 | ((s.z > 0.0) as i32) << 2;
                s
            }
            ConvexShape::Hull(h) => {
                let d = parry3d_f64::math::Vector::new(local.x, local.y, local.z);
                // MuJoCo climbs meshes of at least HILLCLIMB_MIN vertices (all of the mesh's,
                // `mesh_vertnum`), and scans the others in their vertex-list order.
                let i = if h.graph().nvert < HILLCLIMB_MIN {
                    h.support_index_scan(d, self.vertindex)
                } else {
                    let i = h.support_index_warm(d, self.meshindex);
                    self.meshindex = i as i32;
                    i
                };
                self.vertindex = i as i32;
                // MuJoCo's world support point: its mesh frame applied to the stored vertex.
                let p = h.mujoco_point(i);
                return self.mesh_frame.0 * Vec3::new(p.x, p.y, p.z) + self.mesh_frame.1;
            }
        };
        rot * supp + pos
    }
}

/// A polytope vertex: the support point of the difference and its two parts.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Vertex {
    vert: Vec3,
    vert1: Vec3,
    vert2: Vec3,
    /// The geoms' vertex indices of the parts (see [`CcdObj::vertindex`]).
    pub(crate) index1: i32,
    pub(crate) index2: i32,
}

const ZERO_VERTEX: Vertex = Vertex {
    vert: Vec3::new(0.0, 0.0, 0.0),
    vert1: Vec3::new(0.0, 0.0, 0.0),
    vert2: Vec3::new(0.0, 0.0, 0.0),
    index1: -1,
    index2: -1,
};

/// The support vertex of the difference along `dir` (geom 2 along `dir_neg`), margins added.
fn support(o1: &mut CcdObj, o2: &mut CcdObj, dir: &Vec3, dir_neg: &Vec3) -> Vertex {
    let mut vert1 = o1.support(dir);
    if o1.margin > 0.0 && o1.core == Core::Shape {
        vert1 += dir * (0.5 * o1.margin);
    }
    let mut vert2 = o2.support(dir_neg);
    if o2.margin > 0.0 && o2.core == Core::Shape {
        vert2 += dir_neg * (0.5 * o2.margin);
    }
    Vertex { vert: vert1 - vert2, vert1, vert2, index1: o1.vertindex, index2: o2.vertindex }
}

fn gjk_support(o1: &mut CcdObj, o2: &mut CcdObj, x_k: &Vec3, x_norm: f64) -> Vertex {
    let dir_neg = x_k * (1.0 / x_norm);
    let dir = dir_neg * -1.0;
    support(o1, o2, &dir, &dir_neg)
}

fn det3(a: &Vec3, b: &Vec3, c: &Vec3) -> f64 {
    a.x * (b.y * c.z - b.z * c.y) + a.y * (b.z * c.x - b.x * c.z) + a.z * (b.x * c.y - b.y * c.x)
}

#[inline]
fn lincomb(coef: &[f64], v: [&Vec3; 4]) -> Vec3 {
    let mut r = Vec3::zeros();
    for k in 0..3 {
        r[k] = match coef.len() {
            1 => coef[0] * v[0][k],
            2 => coef[0] * v[0][k] + coef[1] * v[1][k],
            3 => coef[0] * v[0][k] + coef[1] * v[1][k] + coef[2] * v[2][k],
            4 => coef[0] * v[0][k] + coef[1] * v[1][k] + coef[2] * v[2][k] + coef[3] * v[3][k],
            _ => 0.0,
        };
    }
    r
}

/// MuJoCo's `mju_normalize3`: (1, 0, 0) for a vector shorter than `mjMINVAL`.
fn normalize3(v: &Vec3) -> Vec3 {
    let n = v.norm();
    if n < MINVAL {
        Vec3::x()
    } else {
        v * (1.0 / n)
    }
}

/// The solver's state (MuJoCo's `mjCCDStatus`, one witness pair).
struct Status {
    separated: bool,
    dist: f64,
    x1: Vec3,
    x2: Vec3,
    max_iterations: usize,
    tolerance: f64,
    dist_cutoff: f64,
    gjk_iterations: usize,
    simplex: [Vertex; 4],
    nsimplex: usize,
    /// When GJK proves the geoms apart by a support plane: the plane's normal direction x_k
    /// (zero otherwise).
    axis: Vec3,
    /// Whether GJK, with no distance wanted, hands a tetrahedron to the intersection test
    /// (`gjk_intersect`, the source snapshot's fallback). The live MuJoCo 4.0.0 does not on its
    /// contact path (see [`penetration`]); [`separated`] does, as a faster proof of separation.
    intersect_fallback: bool,
}

impl Status {
    /// A solver run between geoms at `x1` and `x2` (GJK starts from their origins), to
    /// `tolerance` within `iterations`, no distance wanted.
    fn start(x1: &Transform, x2: &Transform, tolerance: f64, iterations: usize) -> Self {
        Status {
            separated: false,
            dist: 0.0,
            x1: x1.pos,
            x2: x2.pos,
            max_iterations: iterations,
            tolerance,
            dist_cutoff: 0.0,
            gjk_iterations: 0,
            simplex: [ZERO_VERTEX; 4],
            nsimplex: 0,
            axis: Vec3::zeros(),
            intersect_fallback: false,
        }
    }
}

/// GJK as the live MuJoCo 4.0.0 runs it (its `gjk`, read from the library's machine code; it
/// differs from the C source snapshot): the next x_k is the origin's projection on the affine hull
/// of the reduced simplex (its line or plane; the barycentric combination only when that hull is
/// degenerate, and the single vertex itself), the separation test comes before the duality-gap
/// test, which is skipped on the first iteration, and the stopping tests on |x_k| follow each
/// update (MINVAL for a single vertex or when a distance is wanted, `tolerance` otherwise for
/// curved geoms).
fn gjk(st: &mut Status, o1: &mut CcdObj, o2: &mut CcdObj) {
    let get_dist = st.dist_cutoff > 0.0;
    let mut backup = !get_dist && st.intersect_fallback;
    let (mut n, mut k) = (0usize, 0usize);
    let kmax = st.max_iterations;
    let mut lambda = [0.0f64; 4];
    let tol2 = st.tolerance * st.tolerance;
    st.separated = false;
    let discrete = o1.discrete() && o2.discrete() && o1.margin == 0.0 && o2.margin == 0.0;
    let epsilon = if discrete { 0.0 } else { 0.5 * tol2 };
    let min_norm = if discrete || get_dist { MINVAL } else { st.tolerance };
    let mut x_k = st.x1 - st.x2;
    let mut x_norm = x_k.norm();
    if x_norm < MINVAL {
        x_k = Vec3::x();
        x_norm = 1.0;
    }
    let separated = |st: &mut Status, k| {
        st.separated = true;
        st.gjk_iterations = k;
        st.nsimplex = 0;
        st.dist = MAX_LIMIT;
    };
    while k < kmax {
        st.simplex[n] = gjk_support(o1, o2, &x_k, x_norm);
        let s_k = st.simplex[n].vert;
        let lower = x_k.dot(&s_k);
        if get_dist {
            if lower > 0.0 {
                // MuJoCo 4.0.0 marks the pair apart here even when it goes on.
                st.separated = true;
                if st.dist_cutoff < MAX_LIMIT && lower >= st.dist_cutoff * x_norm {
                    st.axis = x_k;
                    return separated(st, k);
                }
            }
        } else if lower > 0.0 {
            st.axis = x_k;
            return separated(st, k);
        }
        if k != 0 && x_k.dot(&(x_k - s_k)) < epsilon {
            break;
        }
        if n == 3 && backup {
            st.gjk_iterations = k;
            let ret = gjk_intersect(st, o1, o2);
            if ret != -1 {
                st.separated = ret == 0;
                st.dist = if ret > 0 { 0.0 } else { MAX_LIMIT };
                return;
            }
            k = st.gjk_iterations;
            backup = false;
        }
        subdistance(&mut lambda, n + 1, &st.simplex);
        n = 0;
        for i in 0..4 {
            if lambda[i] == 0.0 {
                continue;
            }
            // A vertex already in its place is not copied onto itself.
            if n != i {
                st.simplex[n] = st.simplex[i];
                lambda[n] = lambda[i];
            }
            n += 1;
        }
        if n < 1 {
            return separated(st, k);
        }
        if n == 4 {
            break;
        }
        let s = &st.simplex;
        x_k = match n {
            1 => s[0].vert * lambda[0],
            2 => {
                let diff = s[1].vert - s[0].vert;
                let dd = diff.dot(&diff);
                if dd < MINVAL * MINVAL {
                    lincomb(&lambda[..2], [&s[0].vert, &s[1].vert, &s[1].vert, &s[1].vert])
                } else {
                    let scl = -(s[1].vert.dot(&diff) / dd);
                    s[1].vert + diff * scl
                }
            }
            _ => project_origin_plane(&s[0].vert, &s[1].vert, &s[2].vert)
                .unwrap_or_else(|| lincomb(&lambda[..3], [&s[0].vert, &s[1].vert, &s[2].vert, &s[2].vert])),
        };
        let x_norm_prev = x_norm;
        x_norm = x_k.norm();
        if x_norm < if n == 1 { MINVAL } else { min_norm } {
            break;
        }
        if k != 0 && (x_norm - x_norm_prev).abs() < MINVAL {
            break;
        }
        k += 1;
    }
    if n > 0 {
        let s = &st.simplex;
        st.x1 = lincomb(&lambda[..n], [&s[0].vert1, &s[1].vert1, &s[2].vert1, &s[3].vert1]);
        st.x2 = lincomb(&lambda[..n], [&s[0].vert2, &s[1].vert2, &s[2].vert2, &s[3].vert2]);
    }
    // MuJoCo 4.0.0 checks the separation once more along x_k unless the simplex is a
    // tetrahedron, which holds the origin (its machine code and support counts show it: the source
    // snapshot checks every time, one support call more per penetrating pair).
    if n <= 3 && !st.separated && x_norm >= MINVAL {
        let tmp = gjk_support(o1, o2, &x_k, x_norm);
        if x_k.dot(&tmp.vert) > 0.0 {
            st.separated = true;
            st.axis = x_k;
        }
    }
    st.gjk_iterations = k;
    st.nsimplex = n;
    st.dist = if n == 4 && !st.separated { 0.0 } else { x_norm };
}

/// The unit normal of face (v1, v2, v3) and the origin's signed distance along it (MAX when
/// the face is degenerate).
fn signed_distance(v1: &Vec3, v2: &Vec3, v3: &Vec3) -> (Vec3, f64) {
    let normal = (v3 - v1).cross(&(v2 - v1));
    let norm2 = normal.dot(&normal);
    if norm2 > MINVAL * MINVAL && norm2 < MAXVAL * MAXVAL {
        let n = normal * (1.0 / norm2.sqrt());
        return (n, n.dot(v1));
    }
    (normal, MAX_LIMIT)
}

/// 1 if the tetrahedron in `st.simplex` can be grown to contain the origin, 0 if the origin is
/// outside the difference, −1 if inconclusive (MuJoCo's `gjkIntersect`).
fn gjk_intersect(st: &mut Status, o1: &mut CcdObj, o2: &mut CcdObj) -> i32 {
    let mut simplex = st.simplex;
    // The simplex's order: entries are 0..4 (`& 3` below only tells the compiler so).
    let mut s = [0usize, 1, 2, 3];
    let mut k = st.gjk_iterations;
    while k < st.max_iterations {
        let v = s.map(|i| simplex[i & 3].vert);
        let f = [
            signed_distance(&v[2], &v[1], &v[3]),
            signed_distance(&v[0], &v[2], &v[3]),
            signed_distance(&v[1], &v[0], &v[3]),
            signed_distance(&v[0], &v[1], &v[2]),
        ];
        if f.iter().any(|(_, d)| *d == 0.0) {
            st.gjk_iterations = k;
            return -1;
        }
        let i = if f[0].1 < f[1].1 { 0 } else { 1 };
        let j = if f[2].1 < f[3].1 { 2 } else { 3 };
        let index = if f[i].1 < f[j].1 { i } else { j };
        if f[index].1 > 0.0 {
            st.nsimplex = 4;
            st.simplex = s.map(|i| simplex[i & 3]);
            st.gjk_iterations = k;
            return 1;
        }
        let dir = f[index].0;
        let w = support(o1, o2, &dir, &-dir);
        simplex[s[index] & 3] = w;
        let reach = dir.dot(&w.vert);
        if reach < 0.0 {
            st.nsimplex = 0;
            st.gjk_iterations = k;
            // The Minkowski difference lies beyond the plane of normal −dir: GJK's x_k of it.
            st.axis = dir * reach;
            return 0;
        }
        s.swap((index + 1) & 3, (index + 2) & 3);
        k += 1;
    }
    st.gjk_iterations = k;
    -1
}

/// The origin projected on the plane through v1, v2, v3 (None: degenerate).
fn project_origin_plane(v1: &Vec3, v2: &Vec3, v3: &Vec3) -> Option<Vec3> {
    let (d21, d31, d32) = (v2 - v1, v3 - v1, v3 - v2);
    let n = d32.cross(&d21);
    let (nv, nn) = (n.dot(v2), n.dot(&n));
    if nn == 0.0 {
        return None;
    }
    if nv != 0.0 && nn > MINVAL {
        return Some(n * (nv / nn));
    }
    let n = d21.cross(&d31);
    let (nv, nn) = (n.dot(v1), n.dot(&n));
    if nn == 0.0 {
        return None;
    }
    if nv != 0.0 && nn > MINVAL {
        return Some(n * (nv / nn));
    }
    let n = d31.cross(&d32);
    let (nv, nn) = (n.dot(v3), n.dot(&n));
    Some(n * (nv / nn))
}

fn same_sign(a: f64, b: f64) -> bool {
    (a > 0.0 && b > 0.0) || (a < 0.0 && b < 0.0)
}

fn subdistance(lambda: &mut [f64; 4], n: usize, s: &[Vertex; 4]) {
    *lambda = [0.0; 4];
    match n {
        4 => s3d(lambda, &s[0].vert, &s[1].vert, &s[2].vert, &s[3].vert),
        3 => {
            let mut l = [0.0; 3];
            s2d(&mut l, &s[0].vert, &s[1].vert, &s[2].vert);
            lambda[..3].copy_from_slice(&l);
        }
        2 => {
            let l = s1d(&s[0].vert, &s[1].vert);
            lambda[..2].copy_from_slice(&l);
        }
        _ => lambda[0] = 1.0,
    }
}

fn s3d(lambda: &mut [f64; 4], s1: &Vec3, s2: &Vec3, s3: &Vec3, s4: &Vec3) {
    let c41 = -det3(s2, s3, s4);
    let c42 = det3(s1, s3, s4);
    let c43 = -det3(s1, s2, s4);
    let c44 = det3(s1, s2, s3);
    let m_det = c41 + c42 + c43 + c44;
    let comp = [same_sign(m_det, c41), same_sign(m_det, c42), same_sign(m_det, c43), same_sign(m_det, c44)];
    if comp.iter().all(|&c| c) {
        *lambda = [c41 / m_det, c42 / m_det, c43 / m_det, c44 / m_det];
        return;
    }
    let mut dmin = MAX_LIMIT;
    // Faces opposite each vertex whose sign differs, in MuJoCo's order (the first candidate
    // unconditionally, later ones when strictly closer).
    let faces: [([&Vec3; 3], [usize; 3]); 4] = [
        ([s2, s3, s4], [1, 2, 3]),
        ([s1, s3, s4], [0, 2, 3]),
        ([s1, s2, s4], [0, 1, 3]),
        ([s1, s2, s3], [0, 1, 2]),
    ];
    for (f, (v, idx)) in faces.iter().enumerate() {
        if comp[f] {
            continue;
        }
        let mut l = [0.0; 3];
        s2d(&mut l, v[0], v[1], v[2]);
        let x = lincomb(&l, [v[0], v[1], v[2], v[2]]);
        let d = x.dot(&x);
        if f == 0 || d < dmin {
            *lambda = [0.0; 4];
            for (k, &i) in idx.iter().enumerate() {
                lambda[i] = l[k];
            }
            dmin = d;
        }
    }
}

/// The origin's closest point on triangle (s1, s2, s3) as barycentric coordinates, as the live
/// MuJoCo 4.0.0's `S2D` computes them (read from its machine code; its C source snapshot
/// differs): the dropped axis by the largest component of (s2 − s1) × (s3 − s1), the signed
/// areas of the sub-triangles with the projected origin from vertex coordinates relative to it,
/// the coordinates normalised by the areas' sum; every edge searched when the plane is
/// degenerate.
fn s2d(lambda: &mut [f64; 3], s1: &Vec3, s2: &Vec3, s3: &Vec3) {
    let mut comp = [false; 3];
    if let Some(p_o) = project_origin_plane(s1, s2, s3) {
        let (a, b) = (s2 - s1, s3 - s1);
        let m14 = a[1] * b[2] - a[2] * b[1];
        let m24 = a[0] * b[2] - a[2] * b[0];
        let m34 = a[0] * b[1] - a[1] * b[0];
        let (m_max, x, y) = projection_axes(m14, m24, m34);
        // The three vertices relative to the projected origin, in the kept axes.
        let (a0, a1) = (s1[x] - p_o[x], s1[y] - p_o[y]);
        let (b0, b1) = (s2[x] - p_o[x], s2[y] - p_o[y]);
        let (c0, c1) = (s3[x] - p_o[x], s3[y] - p_o[y]);
        let c31 = c1 * b0 - c0 * b1;
        let c32 = c0 * a1 - a0 * c1;
        let c33 = a0 * b1 - b0 * a1;
        comp = [same_sign(m_max, c31), same_sign(m_max, c32), same_sign(m_max, c33)];
        if comp.iter().all(|&c| c) {
            let sum = c31 + c32 + c33;
            *lambda = [c31 / sum, c32 / sum, c33 / sum];
            return;
        }
    }
    let mut dmin = MAX_LIMIT;
    let edges: [([&Vec3; 2], [usize; 2]); 3] = [([s2, s3], [1, 2]), ([s1, s3], [0, 2]), ([s1, s2], [0, 1])];
    for (e, (v, idx)) in edges.iter().enumerate() {
        if comp[e] {
            continue;
        }
        let l = s1d(v[0], v[1]);
        let p = lincomb(&l, [v[0], v[1], v[1], v[1]]);
        let d = p.dot(&p);
        // MuJoCo takes the first edge's candidate unconditionally, later ones when strictly closer.
        if e == 0 || d < dmin {
            *lambda = [0.0; 3];
            lambda[idx[0]] = l[0];
            lambda[idx[1]] = l[1];
            dmin = d;
        }
    }
}

/// The origin's closest point on segment (s1, s2) as barycentric coordinates (MuJoCo 4.0.0's
/// `S1D`: the second vertex alone when the segment is shorter than 1e-15).
fn s1d(s1: &Vec3, s2: &Vec3) -> [f64; 2] {
    // The origin projected on the line.
    let diff = s2 - s1;
    let dd = diff.dot(&diff);
    if dd < MINVAL * MINVAL {
        return [0.0, 1.0];
    }
    let scl = -(s2.dot(&diff) / dd);
    let p_o = s2 + diff * scl;
    let mut mu_max = s1[0] - s2[0];
    let mut index = 0;
    for i in 1..3 {
        let mu = s1[i] - s2[i];
        if mu.abs() >= mu_max.abs() {
            mu_max = mu;
            index = i;
        }
    }
    let c1 = p_o[index] - s2[index];
    let c2 = s1[index] - p_o[index];
    if same_sign(mu_max, c1) && same_sign(mu_max, c2) {
        [c1 / mu_max, c2 / mu_max]
    } else {
        [0.0, 1.0]
    }
}

// ------------------------------------------------------------------------------------------
// EPA

/// A face of the polytope.
#[derive(Clone, Copy, Debug)]
struct Face {
    verts: [usize; 3],
    /// Adjacent faces across edges (v1, v2), (v2, v3), (v3, v1).
    adj: [usize; 3],
    /// The origin's projection on the face (its outward normal scaled by its distance).
    v: Vec3,
    dist2: f64,
    /// Index in the map; −1 not in it, −2 deleted.
    index: i64,
}

/// The expanding polytope and its scratch (MuJoCo's `Polytope`), reused per thread.
#[derive(Default)]
struct Polytope {
    verts: Vec<Vertex>,
    faces: Vec<Face>,
    maxfaces: usize,
    center: Vec3,
    map: Vec<usize>,
    /// `map_dist2[k]` is `faces[map[k]].dist2`: the search for the nearest face reads the
    /// distances in a row.
    map_dist2: Vec<f64>,
    /// `keys[i]` is vertex i's two feature indices in one word ([`feature_key`]): the repeated
    /// support test of discrete geoms reads them in a row.
    keys: Vec<u64>,
    /// The horizon found by [`Self::horizon`]: (face, edge) pairs, one push per edge.
    rim: Vec<(usize, usize)>,
    h_w: Vec3,
}

thread_local! {
    static POLYTOPE: RefCell<Polytope> = RefCell::new(Polytope::default());
}

/// EPA failures before the expansion (MuJoCo's `mjEPAStatus`); any of them means no contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PolytopeError {
    NonConvex,
    BadNormal,
    InvalidV4,
    InvalidV5,
    MissingOrigin,
    OriginOnFace,
}

impl Polytope {
    fn reset(&mut self) {
        self.verts.clear();
        self.keys.clear();
        self.faces.clear();
        self.map.clear();
        self.map_dist2.clear();
        self.rim.clear();
    }

    #[inline(always)]
    fn insert(&mut self, v: Vertex) -> usize {
        self.keys.push(feature_key(&v));
        self.verts.push(v);
        self.verts.len() - 1
    }

    #[inline(always)]
    fn epa_support(&mut self, o1: &mut CcdObj, o2: &mut CcdObj, d: &Vec3, dnorm: f64) -> usize {
        let (mut dir, mut dir_neg) = (Vec3::x(), -Vec3::x());
        if dnorm > MINVAL {
            dir = Vec3::new(d.x / dnorm, d.y / dnorm, d.z / dnorm);
            dir_neg = dir * -1.0;
        }
        let v = support(o1, o2, &dir, &dir_neg);
        self.insert(v)
    }

    /// Appends face (v1, v2, v3) with its adjacency; returns its squared distance (0: degenerate).
    #[inline(always)]
    fn attach(&mut self, v1: usize, v2: usize, v3: usize, a1: usize, a2: usize, a3: usize) -> f64 {
        let (p1, p2, p3) = (self.verts[v1].vert, self.verts[v2].vert, self.verts[v3].vert);
        self.attach_at([v1, v2, v3], [&p1, &p2, &p3], [a1, a2, a3])
    }

    /// [`Self::attach`] of face `verts` whose vertices' points `pts` the caller holds (no
    /// look-ups), adjacency `adj`.
    #[inline(always)]
    fn attach_at(&mut self, verts: [usize; 3], pts: [&Vec3; 3], adj: [usize; 3]) -> f64 {
        let mut face = Face { verts, adj, v: Vec3::zeros(), dist2: 0.0, index: -1 };
        let ret = project_origin_plane(pts[2], pts[1], pts[0]);
        let Some(mut v) = ret else {
            self.faces.push(face);
            return 0.0;
        };
        let outward = pts[0] - self.center;
        if v.dot(&outward) < 0.0 {
            v *= -1.0;
        }
        face.v = v;
        face.dist2 = v.dot(&v);
        self.faces.push(face);
        face.dist2
    }

    #[inline(always)]
    fn populate_map(&mut self) {
        self.map.clear();
        self.map_dist2.clear();
        for i in 0..self.faces.len() {
            self.map.push(i);
            self.map_dist2.push(self.faces[i].dist2);
            self.faces[i].index = i as i64;
        }
    }

    /// Puts face `f` at the end of the map.
    #[inline(always)]
    fn map_push(&mut self, f: usize) {
        self.faces[f].index = self.map.len() as i64;
        self.map.push(f);
        self.map_dist2.push(self.faces[f].dist2);
    }

    #[inline(always)]
    fn delete_face(&mut self, f: usize) {
        let idx = self.faces[f].index;
        if idx >= 0 {
            let last = self.map.pop().expect("a face in the map");
            let last_dist2 = self.map_dist2.pop().expect("a distance per face in the map");
            if (idx as usize) < self.map.len() {
                self.map[idx as usize] = last;
                self.map_dist2[idx as usize] = last_dist2;
                self.faces[last].index = idx;
            }
        }
        self.faces[f].index = -2;
    }

    #[inline(always)]
    fn get_edge(&self, f: usize, vertex: usize) -> usize {
        let v = self.faces[f].verts;
        if v[0] == vertex {
            0
        } else if v[1] == vertex {
            1
        } else {
            2
        }
    }

    fn horizon_rec(&mut self, f: usize, e: usize) -> bool {
        // Only the face's projection and distance for the test; its edges once it is deleted.
        let (v, dist2) = (self.faces[f].v, self.faces[f].dist2);
        if v.dot(&self.h_w) - dist2 > MINVAL {
            let (adjs, verts) = (self.faces[f].adj, self.faces[f].verts);
            self.delete_face(f);
            // Edges e + 1 and e + 2 (mod 3), in that order.
            let i1 = NEXT3[e];
            for i in [i1, NEXT3[i1]] {
                let adj = adjs[i];
                if self.faces[adj].index > -2 {
                    let adj_edge = self.get_edge(adj, verts[NEXT3[i]]);
                    if !self.horizon_rec(adj, adj_edge) {
                        self.rim.push((adj, adj_edge));
                    }
                }
            }
            return true;
        }
        false
    }

    fn horizon(&mut self, f: usize) {
        self.delete_face(f);
        let face = self.faces[f];
        for (a, vert) in [(0, 1), (1, 2), (2, 0)] {
            let adj = face.adj[a];
            let adj_edge = self.get_edge(adj, face.verts[vert]);
            if (a == 0 || self.faces[adj].index > -2) && !self.horizon_rec(adj, adj_edge) {
                self.rim.push((adj, adj_edge));
            }
        }
    }

    fn replace_simplex3(&mut self, st: &mut Status, v1: usize, v2: usize, v3: usize) {
        st.nsimplex = 3;
        st.simplex[0] = self.verts[v1];
        st.simplex[1] = self.verts[v2];
        st.simplex[2] = self.verts[v3];
        self.reset();
    }

    fn polytope2(&mut self, st: &mut Status, o1: &mut CcdObj, o2: &mut CcdObj) -> Result<(), PolytopeError> {
        let (v1, v2) = (st.simplex[0].vert, st.simplex[1].vert);
        self.center = (v1 + v2) * 0.5;
        let diff = v2 - v1;
        let (mut value, mut index) = (MAX_LIMIT, 0);
        for i in 0..3 {
            if diff[i].abs() < value {
                value = diff[i].abs();
                index = i;
            }
        }
        let mut e = Vec3::zeros();
        e[index] = 1.0;
        let d1 = e.cross(&diff);
        let r = rotmat(&diff);
        let d2 = r * d1;
        let d3 = r * d2;
        let v1i = self.insert(st.simplex[0]);
        let v2i = self.insert(st.simplex[1]);
        let v3i = self.epa_support(o1, o2, &d1, d1.norm());
        let v4i = self.epa_support(o1, o2, &d2, d2.norm());
        let v5i = self.epa_support(o1, o2, &d3, d3.norm());
        let faces = [
            (v1i, v3i, v4i, 1, 3, 2),
            (v1i, v5i, v3i, 2, 4, 0),
            (v1i, v4i, v5i, 0, 5, 1),
            (v2i, v4i, v3i, 5, 0, 4),
            (v2i, v3i, v5i, 3, 1, 5),
            (v2i, v5i, v4i, 4, 2, 3),
        ];
        for (a, b, c, x, y, z) in faces {
            if self.attach(a, b, c, x, y, z) < MINVAL * MINVAL {
                self.replace_simplex3(st, a, b, c);
                return self.polytope3(st, o1, o2);
            }
        }
        let (p3, p4, p5) = (self.verts[v3i].vert, self.verts[v4i].vert, self.verts[v5i].vert);
        if ray_triangle(&v1, &v2, &p3, &p4, &p5) == 0 {
            return Err(PolytopeError::NonConvex);
        }
        self.populate_map();
        Ok(())
    }

    fn polytope3(&mut self, st: &mut Status, o1: &mut CcdObj, o2: &mut CcdObj) -> Result<(), PolytopeError> {
        let (v1, v2, v3) = (st.simplex[0].vert, st.simplex[1].vert, st.simplex[2].vert);
        self.center = (v1 + v2 + v3) * (1.0 / 3.0);
        let n = (v2 - v1).cross(&(v3 - v1));
        let n_norm = n.norm();
        if n_norm < MINVAL {
            return Err(PolytopeError::BadNormal);
        }
        let n_neg = n * -1.0;
        let v1i = self.insert(st.simplex[0]);
        let v2i = self.insert(st.simplex[1]);
        let v3i = self.insert(st.simplex[2]);
        let v5i = self.epa_support(o1, o2, &n_neg, n_norm);
        let v4i = self.epa_support(o1, o2, &n, n_norm);
        let (v4, v5) = (self.verts[v4i].vert, self.verts[v5i].vert);
        if tri_point_intersect(&v1, &v2, &v3, &v4) {
            return Err(PolytopeError::InvalidV4);
        }
        if tri_point_intersect(&v1, &v2, &v3, &v5) {
            return Err(PolytopeError::InvalidV5);
        }
        if st.dist > 10.0 * MINVAL && !test_tetra(&v1, &v2, &v3, &v4) && !test_tetra(&v1, &v2, &v3, &v5) {
            return Err(PolytopeError::MissingOrigin);
        }
        let faces = [
            (v4i, v1i, v2i, 1, 3, 2),
            (v4i, v3i, v1i, 2, 4, 0),
            (v4i, v2i, v3i, 0, 5, 1),
            (v5i, v2i, v1i, 5, 0, 4),
            (v5i, v1i, v3i, 3, 1, 5),
            (v5i, v3i, v2i, 4, 2, 3),
        ];
        for (a, b, c, x, y, z) in faces {
            if self.attach(a, b, c, x, y, z) < MINVAL * MINVAL {
                return Err(PolytopeError::OriginOnFace);
            }
        }
        self.populate_map();
        Ok(())
    }

    fn polytope4(&mut self, st: &mut Status, o1: &mut CcdObj, o2: &mut CcdObj) -> Result<(), PolytopeError> {
        // The four simplex vertices appended at once (indices v1..v4 in order).
        let v1 = self.verts.len();
        self.verts.extend_from_slice(&st.simplex);
        self.keys.extend(st.simplex.iter().map(feature_key));
        // The points held here, not looked up in the polytope.
        let q = st.simplex.map(|v| v.vert);
        self.center = (q[0] + q[1] + q[2] + q[3]) * 0.25;
        // Faces (1, 2, 3), (1, 4, 2), (1, 3, 4), (4, 3, 2) of the simplex, with their adjacency.
        let faces =
            [([0, 1, 2], [1, 3, 2]), ([0, 3, 1], [2, 3, 0]), ([0, 2, 3], [0, 3, 1]), ([3, 2, 1], [2, 0, 1])];
        for (f, adj) in faces {
            let verts = f.map(|i| v1 + i);
            if self.attach_at(verts, f.map(|i| &q[i]), adj) < MINVAL * MINVAL {
                self.replace_simplex3(st, verts[0], verts[1], verts[2]);
                return self.polytope3(st, o1, o2);
            }
        }
        if !test_tetra(&q[0], &q[1], &q[2], &q[3]) {
            return Err(PolytopeError::MissingOrigin);
        }
        self.populate_map();
        Ok(())
    }

    /// The expansion: the face that approximates the penetration (None: no contact).
    fn epa(&mut self, st: &Status, o1: &mut CcdObj, o2: &mut CcdObj) -> Option<usize> {
        let (mut upper, mut upper2) = (MAX_LIMIT, MAX_LIMIT);
        let mut face: Option<usize> = None;
        let discrete = o1.discrete() && o2.discrete() && o1.margin == 0.0 && o2.margin == 0.0;
        let tolerance = if discrete { MINVAL } else { st.tolerance };
        let kmax = st.max_iterations.min(1000);
        self.maxfaces = 6 * st.max_iterations;
        for k in 0..kmax {
            let pface = face;
            let mut lower2 = MAX_LIMIT;
            for (&f, &dist2) in self.map.iter().zip(&self.map_dist2) {
                if dist2 < lower2 {
                    face = Some(f);
                    lower2 = dist2;
                }
            }
            let Some(f) = face.filter(|_| lower2 <= upper2) else {
                face = pface;
                break;
            };
            if lower2 <= 0.0 {
                break;
            }
            let lower = lower2.sqrt();
            let fv = self.faces[f].v;
            let wi = self.epa_support(o1, o2, &fv, lower);
            let w_vert = self.verts[wi].vert;
            let upper_k = fv.dot(&w_vert) / lower;
            if upper_k < upper {
                upper = upper_k;
                upper2 = upper * upper;
            }
            // MuJoCo 4.0.0 (its machine code) stops on this iteration's bound, not the running
            // minimum, and drops a first-iteration face whose bound is below by the tolerance.
            if upper_k - lower < tolerance {
                if k == 0 && upper < lower - tolerance {
                    face = None;
                }
                break;
            }
            if discrete && self.keys[..wi].contains(&self.keys[wi]) {
                break;
            }
            self.h_w = w_vert;
            self.rim.clear();
            self.horizon(f);
            let nedges = self.rim.len();
            if nedges < 3 {
                face = None;
                break;
            }
            let nfaces = self.faces.len();
            if nedges > self.maxfaces.saturating_sub(nfaces) {
                break;
            }
            for i in 0..nedges {
                let cur = nfaces + i;
                let (hi, he) = self.rim[i];
                let hv = self.faces[hi].verts;
                let (v1, v2) = (hv[he], hv[NEXT3[he]]);
                self.faces[hi].adj[he] = cur;
                let prev = if i == 0 { nfaces + nedges - 1 } else { cur - 1 };
                let next = if i + 1 == nedges { nfaces } else { cur + 1 };
                let (p2, p1) = (self.verts[v2].vert, self.verts[v1].vert);
                let dist2 = self.attach_at([wi, v2, v1], [&w_vert, &p2, &p1], [prev, hi, next]);
                if dist2 == 0.0 {
                    face = None;
                    break;
                }
                if dist2 >= lower2 && dist2 <= upper2 {
                    self.map_push(cur);
                }
            }
            if self.map.is_empty() || face.is_none() {
                break;
            }
        }
        face
    }

    /// The geom features of face `f`'s vertices.
    fn face_features(&self, f: usize) -> EpaFace {
        let v = self.faces[f].verts.map(|i| &self.verts[i]);
        EpaFace { index1: v.map(|x| x.index1), index2: v.map(|x| x.index2), vert1: v.map(|x| x.vert1) }
    }

    /// The witness points of face `f` and its signed distance (MuJoCo's `epaWitness`).
    fn witness(&self, f: usize) -> (Vec3, Vec3, f64) {
        let face = &self.faces[f];
        let [a, b, c] = face.verts.map(|i| &self.verts[i]);
        let l = tri_affine_coord(&a.vert, &b.vert, &c.vert, &face.v);
        let x1 = lincomb(&l, [&a.vert1, &b.vert1, &c.vert1, &c.vert1]);
        let x2 = lincomb(&l, [&a.vert2, &b.vert2, &c.vert2, &c.vert2]);
        (x1, x2, -face.dist2.sqrt())
    }
}

/// The next corner of a triangle: `NEXT3[i]` is (i + 1) mod 3 (a table, not a division).
const NEXT3: [usize; 3] = [1, 2, 0];

/// A vertex's two feature indices (geom 1's, geom 2's) in one word: equal keys, equal pairs.
#[inline(always)]
fn feature_key(v: &Vertex) -> u64 {
    (u64::from(v.index1 as u32) << 32) | u64::from(v.index2 as u32)
}

/// The rotation by 120° about `axis` (row-major as MuJoCo's `rotmat`).
fn rotmat(axis: &Vec3) -> crate::spatial::Mat3 {
    let n = axis.norm();
    let (u1, u2, u3) = (axis.x / n, axis.y / n, axis.z / n);
    let sin = 0.86602540378;
    let cos = -0.5;
    crate::spatial::Mat3::new(
        cos + u1 * u1 * (1.0 - cos),
        u1 * u2 * (1.0 - cos) - u3 * sin,
        u1 * u3 * (1.0 - cos) + u2 * sin,
        u2 * u1 * (1.0 - cos) + u3 * sin,
        cos + u2 * u2 * (1.0 - cos),
        u2 * u3 * (1.0 - cos) - u1 * sin,
        u1 * u3 * (1.0 - cos) - u2 * sin,
        u2 * u3 * (1.0 - cos) + u1 * sin,
        cos + u3 * u3 * (1.0 - cos),
    )
}

fn same_side(p0: &Vec3, p1: &Vec3, p2: &Vec3, p3: &Vec3) -> bool {
    let n = (p1 - p0).cross(&(p2 - p0));
    let dot1 = n.dot(&(p3 - p0));
    let dot2 = n.dot(&(p0 * -1.0));
    (dot1 > 0.0 && dot2 > 0.0) || (dot1 < 0.0 && dot2 < 0.0)
}

fn test_tetra(p0: &Vec3, p1: &Vec3, p2: &Vec3, p3: &Vec3) -> bool {
    same_side(p0, p1, p2, p3)
        && same_side(p1, p2, p3, p0)
        && same_side(p2, p3, p0, p1)
        && same_side(p3, p0, p1, p2)
}

fn ray_triangle(v1: &Vec3, v2: &Vec3, v3: &Vec3, v4: &Vec3, v5: &Vec3) -> i32 {
    let (d12, d13, d14, d15) = (v2 - v1, v3 - v1, v4 - v1, v5 - v1);
    let vol1 = det3(&d13, &d14, &d12);
    let vol2 = det3(&d14, &d15, &d12);
    let vol3 = det3(&d15, &d13, &d12);
    if vol1 >= 0.0 && vol2 >= 0.0 && vol3 >= 0.0 {
        return 1;
    }
    if vol1 <= 0.0 && vol2 <= 0.0 && vol3 <= 0.0 {
        return -1;
    }
    0
}

/// The plane a triangle is projected on for its 2-D areas: from the components (m14, m24, m34) of
/// its normal (x, y, z), the largest in magnitude and the two axes kept (dropping x, y or z).
fn projection_axes(m14: f64, m24: f64, m34: f64) -> (f64, usize, usize) {
    let (mu1, mu2, mu3) = (m14.abs(), m24.abs(), m34.abs());
    if mu1 >= mu2 && mu1 >= mu3 {
        (m14, 1, 2)
    } else if mu2 >= mu3 {
        (m24, 0, 2)
    } else {
        (m34, 0, 1)
    }
}

fn tri_affine_coord(v1: &Vec3, v2: &Vec3, v3: &Vec3, p: &Vec3) -> [f64; 3] {
    let m14 = v2[1] * v3[2] - v2[2] * v3[1] - v1[1] * v3[2] + v1[2] * v3[1] + v1[1] * v2[2] - v1[2] * v2[1];
    let m24 = v2[0] * v3[2] - v2[2] * v3[0] - v1[0] * v3[2] + v1[2] * v3[0] + v1[0] * v2[2] - v1[2] * v2[0];
    let m34 = v2[0] * v3[1] - v2[1] * v3[0] - v1[0] * v3[1] + v1[1] * v3[0] + v1[0] * v2[1] - v1[1] * v2[0];
    let (m_max, x, y) = projection_axes(m14, m24, m34);
    let c31 = p[x] * v2[y] + p[y] * v3[x] + v2[x] * v3[y] - p[x] * v3[y] - p[y] * v2[x] - v3[x] * v2[y];
    let c32 = p[x] * v3[y] + p[y] * v1[x] + v3[x] * v1[y] - p[x] * v1[y] - p[y] * v3[x] - v1[x] * v3[y];
    let c33 = p[x] * v1[y] + p[y] * v2[x] + v1[x] * v2[y] - p[x] * v2[y] - p[y] * v1[x] - v2[x] * v1[y];
    [c31 / m_max, c32 / m_max, c33 / m_max]
}

fn tri_point_intersect(v1: &Vec3, v2: &Vec3, v3: &Vec3, p: &Vec3) -> bool {
    let l = tri_affine_coord(v1, v2, v3, p);
    if l[0] < 0.0 || l[1] < 0.0 || l[2] < 0.0 {
        return false;
    }
    let pr = v1 * l[0] + v2 * l[1] + v3 * l[2];
    (pr - p).norm() < MINVAL
}

/// The face EPA ended on, by where its three vertices' support points lie on each geom: per
/// vertex (the face's order), the box corner (bit 0 +x, bit 1 +y, bit 2 +z) or hull vertex
/// index on geom 1 (`index1`) and geom 2 (`index2`), −1 on a curved geom (MuJoCo's
/// `Vertex.index1`, `index2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct EpaFace {
    /// Geom 1's feature index of each face vertex.
    pub index1: [i32; 3],
    /// Geom 2's feature index of each face vertex.
    pub index2: [i32; 3],
    /// Geom 1's support point of each face vertex (world; inflated by half the margin).
    pub vert1: [Vec3; 3],
}

/// A contact from the solver: the witness points (of the geoms inflated by half the margin
/// each; their midpoint is the contact position), the unit normal from geom 1 to geom 2, the
/// contact distance (the margin plus the inflated geoms' signed distance).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CcdContact {
    /// Witness point on geom 1 (world).
    pub x1: Vec3,
    /// Witness point on geom 2 (world).
    pub x2: Vec3,
    /// Unit normal from geom 1 to geom 2.
    pub normal: Vec3,
    /// Contact distance (m).
    pub dist: f64,
    /// The EPA face the contact comes from (None: a shallow contact of a sphere's or capsule's
    /// core, found by GJK alone).
    pub face: Option<EpaFace>,
}

/// MuJoCo's `mjc_penetration` with one contact: the penetration of the two geoms inflated by
/// half of `margin` each (a contact when the inflated geoms overlap), by GJK/EPA to
/// `tolerance` within `iterations`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn penetration(
    s1: &ConvexShape,
    x1: &Transform,
    s2: &ConvexShape,
    x2: &Transform,
    margin: f64,
    tolerance: f64,
    iterations: usize,
) -> Option<CcdContact> {
    penetration_with(s1, None, x1, s2, x2, margin, tolerance, iterations)
}

/// The box of geom `s` at pose `x` along the axes of `x`'s parent frame: the lowest and highest
/// coordinate of its support points along −e_k and +e_k (MuJoCo's six support calls at the start
/// of `mjc_ConvexHField`, no margin).
pub(crate) fn support_box(s: &ConvexShape, x: &Transform) -> (Vec3, Vec3) {
    let mut o = CcdObj::new(s, x, 0.0);
    let (mut lo, mut hi) = (Vec3::zeros(), Vec3::zeros());
    for k in 0..3 {
        let mut dir = Vec3::zeros();
        dir[k] = 1.0;
        hi[k] = o.support(&dir)[k];
        dir[k] = -1.0;
        lo[k] = o.support(&dir)[k];
    }
    (lo, hi)
}

/// [`penetration`] of a height-field prism (`prism`: base then top vertices in the frame `x1`)
/// and geom `s2`: MuJoCo's `mjc_penetration` call in `mjc_ConvexHField`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn penetration_prism(
    prism: &[Vec3; 6],
    x1: &Transform,
    s2: &ConvexShape,
    x2: &Transform,
    margin: f64,
    tolerance: f64,
    iterations: usize,
) -> Option<CcdContact> {
    // The shape is unused when a prism stands in for it (any non-core shape will do).
    let stand_in =
        ConvexShape::Cuboid(parry3d_f64::shape::Cuboid::new(parry3d_f64::math::Vector::new(0.0, 0.0, 0.0)));
    penetration_with(&stand_in, Some(prism), x1, s2, x2, margin, tolerance, iterations)
}

#[allow(clippy::too_many_arguments)]
fn penetration_with(
    s1: &ConvexShape,
    prism1: Option<&[Vec3; 6]>,
    x1: &Transform,
    s2: &ConvexShape,
    x2: &Transform,
    margin: f64,
    tolerance: f64,
    iterations: usize,
) -> Option<CcdContact> {
    let mut o1 = CcdObj::new(s1, x1, margin);
    o1.prism = prism1;
    let mut o2 = CcdObj::new(s2, x2, margin);
    let mut st = Status::start(x1, x2, tolerance, iterations);
    // GJK starts from MuJoCo's geom centres (`mjc_center`).
    // A prism's centre is the mean of its six vertices (MuJoCo's `mjc_center`: summed in order,
    // then scaled by 1/6).
    let centre1 = match prism1 {
        Some(prism) => {
            let sum = prism.iter().fold(Vec3::zeros(), |acc, v| acc + v);
            x1.act_point(&(sum * (1.0 / 6.0)))
        }
        None => centre(s1, x1),
    };
    let start = (centre1, centre(s2, x2));
    (st.x1, st.x2) = start;
    let core = |s: &ConvexShape| match s {
        ConvexShape::Ball(b) => Some((Core::Point, b.radius)),
        ConvexShape::Capsule(c) => Some((Core::Line, c.radius)),
        _ => None,
    };
    let (c1, c2) = (core(s1), core(s2));
    // MuJoCo 4.0.0 (its `mjc_ccd`'s machine code) first runs GJK on the cores: spheres and
    // capsules shrunk to their centre and segment, and every geom without the pair's margin.
    if c1.is_some() || c2.is_some() || margin > 0.0 {
        let mut full = [0.0; 2];
        for (k, (o, c)) in [(&mut o1, c1), (&mut o2, c2)].into_iter().enumerate() {
            full[k] = 0.5 * margin;
            o.margin = 0.0;
            if let Some((kind, radius)) = c {
                full[k] += radius;
                o.core = kind;
            }
        }
        st.dist_cutoff = full[0] + full[1];
        gjk(&mut st, &mut o1, &mut o2);
        st.dist_cutoff = 0.0;
        for o in [&mut o1, &mut o2] {
            o.core = Core::Shape;
            o.margin = margin;
        }
        if st.dist > st.tolerance {
            // Shallow: the cores' witness points moved out by the radii.
            let n = normalize3(&(st.x2 - st.x1));
            if full[0] != 0.0 {
                st.x1 += n * full[0];
            }
            if full[1] != 0.0 {
                st.x2 -= n * full[1];
            }
            st.dist -= full[0] + full[1];
            if st.dist > st.dist_cutoff || st.dist >= 0.0 {
                return None;
            }
            // MuJoCo 4.0.0 reads a shallow contact's features off GJK's simplex as off an EPA
            // face (its first, second and third vertices, the first repeated when fewer).
            let face = (st.nsimplex > 0).then(|| {
                let k = [0, usize::from(st.nsimplex > 1), if st.nsimplex > 2 { 2 } else { 0 }];
                let v = k.map(|i| &st.simplex[i]);
                EpaFace {
                    index1: v.map(|x| x.index1),
                    index2: v.map(|x| x.index2),
                    vert1: v.map(|x| x.vert1),
                }
            });
            return Some(contact(&st, margin, face));
        }
        st.gjk_iterations = 0;
        (st.x1, st.x2) = start;
    }
    gjk(&mut st, &mut o1, &mut o2);
    if !(st.dist <= tolerance && st.nsimplex > 1 && !st.separated) {
        return None;
    }
    st.dist = 0.0;
    POLYTOPE.with(|pt| {
        let pt = &mut *pt.borrow_mut();
        pt.reset();
        let built = match st.nsimplex {
            2 => pt.polytope2(&mut st, &mut o1, &mut o2),
            3 => pt.polytope3(&mut st, &mut o1, &mut o2),
            _ => pt.polytope4(&mut st, &mut o1, &mut o2),
        };
        built.ok()?;
        let f = pt.epa(&st, &mut o1, &mut o2)?;
        let (w1, w2, d) = pt.witness(f);
        (st.x1, st.x2, st.dist) = (w1, w2, d);
        if st.dist >= 0.0 {
            return None;
        }
        Some(contact(&st, margin, Some(pt.face_features(f))))
    })
}

/// What the separation test of one candidate pair keeps from one collision pass to the next
/// (none of it changes the answer, only how soon it is found).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SeparationWarm {
    /// The two hulls' hill-climb starts: the last support vertices (−1: none).
    pub index: [i32; 2],
    /// The direction x_k of the support plane that proved the pair apart at the last test (zero:
    /// none): geoms that moved little since are proved apart again by its first support point.
    pub axis: Vec3,
}

impl SeparationWarm {
    /// Nothing kept: the climbs start from their grid of extreme vertices, GJK from MuJoCo's
    /// geom centres.
    pub(crate) fn none() -> Self {
        Self { index: [-1, -1], axis: Vec3::zeros() }
    }
}

/// Whether GJK proves the two geoms, inflated by half of `margin` each, apart: a support plane
/// separating them found within `iterations` (MuJoCo's early exit in `gjk` with no distance
/// wanted: the first support point with x_k·s_k > 0). Exact when true — a separating plane is a
/// certificate, whatever direction GJK started from — so a caller may skip its own narrow phase;
/// false leaves the pair undecided. `warm` is read before and written after: the hill climbs
/// start from the same pair's last support vertices, GJK from the direction that separated the
/// pair at the last test or else from MuJoCo's geom centres (`mjc_center`: a mesh's at its centre
/// of mass, where MuJoCo places the geom; the file's origin can lie far outside the mesh).
#[allow(clippy::too_many_arguments)]
pub(crate) fn separated(
    s1: &ConvexShape,
    x1: &Transform,
    s2: &ConvexShape,
    x2: &Transform,
    margin: f64,
    tolerance: f64,
    iterations: usize,
    warm: &mut SeparationWarm,
) -> bool {
    let mut o1 = CcdObj::new(s1, x1, margin);
    let mut o2 = CcdObj::new(s2, x2, margin);
    (o1.meshindex, o2.meshindex) = (warm.index[0], warm.index[1]);
    let mut st = Status::start(x1, x2, tolerance, iterations);
    st.intersect_fallback = true;
    let c1 = centre(s1, x1);
    // GJK's first direction is st.x1 − st.x2.
    (st.x1, st.x2) = if warm.axis != Vec3::zeros() { (c1, c1 - warm.axis) } else { (c1, centre(s2, x2)) };
    gjk(&mut st, &mut o1, &mut o2);
    warm.index = [o1.meshindex, o2.meshindex];
    warm.axis = if st.separated { st.axis } else { Vec3::zeros() };
    st.separated
}

/// MuJoCo's centre of a geom at pose `x` (world): its mesh frame's origin for a hull, the geom
/// origin otherwise.
fn centre(s: &ConvexShape, x: &Transform) -> Vec3 {
    match s {
        ConvexShape::Hull(h) => x.act_point(&h.graph().box_frame.0),
        _ => x.pos,
    }
}

fn contact(st: &Status, margin: f64, face: Option<EpaFace>) -> CcdContact {
    CcdContact { x1: st.x1, x2: st.x2, normal: normalize3(&(st.x1 - st.x2)), dist: margin + st.dist, face }
}
