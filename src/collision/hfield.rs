//! Height-field contacts as MuJoCo 4.0 makes them (`mjc_ConvexHField`, engine_collision_convex.c):
//! the grid cells under the other geom's box (its support points along the height field's axes)
//! are cut into two triangular prisms each, diagonal from (column c−1, row r) to (c, r+1), bottoms at
//! z = −`size[3]`, visited row by row, then column, then the two prisms of the cell. Each prism is a
//! convex solid collided on its own: a prism closer than the pair's margin gives one contact at
//! their true signed distance (at most `MAX_CONTACTS`; measured in MuJoCo 4.0.0, whose older C
//! snapshot lifts the tops instead). A prism whose three tops plus the margin all lie below the
//! geom's lowest point is skipped; cells outside the geom's footprint are not visited.
//!
//! Only spheres are collided here, exactly: the signed distance from the sphere's centre to the
//! prism (the closest point on its boundary triangles outside, the nearest face inside) less the
//! radius. MuJoCo reaches the same through GJK/EPA: exactly while the centre is outside the prism,
//! within its `ccd_tolerance` when the centre is inside (tests/hfield_mujoco.rs).

use crate::model::HeightField;
use crate::spatial::{Transform, Vec3};
use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;

/// MuJoCo's `mjMAXCONPAIR`: the most contacts one height-field pair yields.
pub const MAX_CONTACTS: usize = 50;

/// One height-field contact in world coordinates: the witness points on the prism and on the
/// sphere, the normal from the height field to the sphere and the signed distance.
#[derive(Clone, Copy, Debug)]
pub struct HfieldPoint {
    /// Deepest point of the prism (world, m).
    pub p1: Vec3,
    /// Deepest point of the sphere (world, m).
    pub p2: Vec3,
    /// Unit normal from the height field to the sphere (world).
    pub normal: Vec3,
    /// Signed distance (m, negative: penetration).
    pub dist: f64,
}

/// The contacts of a sphere (centre `p_world`, `radius`) with the height field `field` posed at
/// `x_hfield` and pair margin `margin`, in MuJoCo's order, passed to `out` (at most
/// [`MAX_CONTACTS`]).
pub fn sphere(
    x_hfield: &Transform,
    field: &HeightField,
    p_world: &Vec3,
    radius: f64,
    margin: f64,
    out: &mut impl FnMut(HfieldPoint),
) {
    let (nrow, ncol) = (field.nrow, field.ncol);
    if nrow < 2 || ncol < 2 || field.data.len() < nrow * ncol {
        return;
    }
    let s = field.size;
    let rot = &x_hfield.rot;
    let p = rot.transpose() * (p_world - x_hfield.pos);
    // Box-sphere test (the geom's bounding sphere, a sphere's own radius).
    let rb = radius + margin;
    if s[0] < p.x - rb
        || -s[0] > p.x + rb
        || s[1] < p.y - rb
        || -s[1] > p.y + rb
        || s[2] < p.z - rb
        || -s[3] > p.z + rb
    {
        return;
    }
    // The sphere's box in the height-field frame (support points along ±x, ±y, ±z).
    let (lo, hi) = (p - Vec3::repeat(radius), p + Vec3::repeat(radius));
    let Some(cells) = Cells::under(field, &lo, &hi, margin) else { return };
    let grown = radius;
    let mut n = 0;
    for r in cells.rows.clone() {
        for c in cells.cols.clone() {
            for top in &cells.tops(field, r, c) {
                if top.iter().all(|v| v.z + margin < lo.z) {
                    continue;
                }
                let Some((q, normal, sd)) = point_prism(&p, top, -s[3]) else { continue };
                let dist = sd - grown;
                if dist >= margin {
                    continue;
                }
                let p2 = p - normal * grown;
                out(HfieldPoint {
                    p1: x_hfield.pos + rot * q,
                    p2: x_hfield.pos + rot * p2,
                    normal: rot * normal,
                    dist,
                });
                n += 1;
                if n >= MAX_CONTACTS {
                    return;
                }
            }
        }
    }
}

/// The point of the prism (top triangle `top`, its vertical sides reaching down to z = `bottom`)
/// nearest `p` on its boundary, the unit normal from that point towards `p` (outward when `p` is
/// inside) and `p`'s signed distance to the prism (negative inside). None when degenerate.
fn point_prism(p: &Vec3, top: &[Vec3; 3], bottom: f64) -> Option<(Vec3, Vec3, f64)> {
    let low = top.map(|v| Vec3::new(v.x, v.y, bottom));
    // Outward face planes: (normal, a point on it).
    let centroid = (top[0] + top[1] + top[2] + low[0] + low[1] + low[2]) / 6.0;
    let mut faces: [(Vec3, Vec3); 5] = [(Vec3::zeros(), Vec3::zeros()); 5];
    let mut nt = (top[1] - top[0]).cross(&(top[2] - top[0]));
    if nt.z < 0.0 {
        nt = -nt;
    }
    faces[0] = (nt.try_normalize(0.0)?, top[0]);
    faces[1] = (Vec3::new(0.0, 0.0, -1.0), low[0]);
    for i in 0..3 {
        let (a, b) = (top[i], top[(i + 1) % 3]);
        let mut ns = Vec3::new(b.y - a.y, a.x - b.x, 0.0).try_normalize(0.0)?;
        if ns.dot(&(centroid - a)) > 0.0 {
            ns = -ns;
        }
        faces[2 + i] = (ns, a);
    }
    let (mut best, mut far) = (0, f64::NEG_INFINITY);
    for (k, (nf, o)) in faces.iter().enumerate() {
        let d = nf.dot(&(p - o));
        if d > far {
            (best, far) = (k, d);
        }
    }
    if far <= 0.0 {
        // Inside: the nearest face.
        let nf = faces[best].0;
        return Some((p - nf * far, nf, far));
    }
    // Outside: the nearest of the boundary triangles.
    let pt = |v: &Vec3| Vector::new(v.x, v.y, v.z);
    let tris = [
        [top[0], top[1], top[2]],
        [low[0], low[1], low[2]],
        [top[0], top[1], low[1]],
        [top[0], low[1], low[0]],
        [top[1], top[2], low[2]],
        [top[1], low[2], low[1]],
        [top[2], top[0], low[0]],
        [top[2], low[0], low[2]],
    ];
    let (mut q, mut d2) = (Vec3::zeros(), f64::INFINITY);
    for t in &tris {
        let proj = Triangle::new(pt(&t[0]), pt(&t[1]), pt(&t[2])).project_local_point(pt(p), false);
        let c = Vec3::new(proj.point.x, proj.point.y, proj.point.z);
        let e = (p - c).norm_squared();
        if e < d2 {
            (q, d2) = (c, e);
        }
    }
    let d = d2.sqrt();
    Some((q, (p - q) / d, d))
}

/// The grid cells of a height field under a geom's box `[lo, hi]` (height-field frame) grown by
/// `margin` — MuJoCo 4.0's sub-grid, measured on its contacts — with the grid spacing; shared
/// by the sphere's closed form and the convex geoms' prisms ([`super::hfield_convex`]).
pub(crate) struct Cells {
    /// Rows r of the cells (r, r + 1).
    pub rows: std::ops::Range<usize>,
    /// Columns c of the cells (c − 1, c).
    pub cols: std::ops::RangeInclusive<usize>,
    dx: f64,
    dy: f64,
}

impl Cells {
    /// The cells under `[lo, hi]`, or None when the box grown by `margin` misses the field's
    /// volume (its base at −size[3] to its top at size[2]).
    pub fn under(field: &HeightField, lo: &Vec3, hi: &Vec3, margin: f64) -> Option<Self> {
        let s = field.size;
        let (nrow, ncol) = (field.nrow, field.ncol);
        if lo.x - margin > s[0]
            || hi.x + margin < -s[0]
            || lo.y - margin > s[1]
            || hi.y + margin < -s[1]
            || lo.z - margin > s[2]
            || hi.z + margin < -s[3]
        {
            return None;
        }
        let (glo, ghi) = (lo - Vec3::repeat(margin), hi + Vec3::repeat(margin));
        let cols = (ncol - 1) as f64;
        let rows = (nrow - 1) as f64;
        let cmin = (((glo.x + s[0]) / (2.0 * s[0]) * cols).floor().max(0.0)) as usize;
        let cmax = (((ghi.x + s[0]) / (2.0 * s[0]) * cols).ceil() as i64).clamp(0, ncol as i64 - 1) as usize;
        let rmin = (((glo.y + s[1]) / (2.0 * s[1]) * rows).floor().max(0.0)) as usize;
        let rmax = (((ghi.y + s[1]) / (2.0 * s[1]) * rows).ceil() as i64).clamp(0, nrow as i64 - 1) as usize;
        Some(Self { rows: rmin..rmax, cols: cmin + 1..=cmax, dx: 2.0 * s[0] / cols, dy: 2.0 * s[1] / rows })
    }

    /// A grid point (x, y, its height scaled by size[2]) of row `r`, column `c`.
    fn vertex(&self, field: &HeightField, r: usize, c: usize) -> Vec3 {
        let s = field.size;
        let z = f64::from(field.data[r * field.ncol + c]) * s[2];
        Vec3::new(self.dx * c as f64 - s[0], self.dy * r as f64 - s[1], z)
    }

    /// The tops of the cell's two triangular prisms, in MuJoCo's order.
    pub fn tops(&self, field: &HeightField, r: usize, c: usize) -> [[Vec3; 3]; 2] {
        let v = |r, c| self.vertex(field, r, c);
        [[v(r + 1, c - 1), v(r, c - 1), v(r + 1, c)], [v(r, c - 1), v(r + 1, c), v(r, c)]]
    }
}
