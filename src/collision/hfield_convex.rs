//! Height-field contacts with capsules, boxes, cylinders, ellipsoids and meshes as MuJoCo 4.0 makes
//! them (`mjc_ConvexHField`, engine_collision_convex.c): the other geom's box in the height field's
//! frame (its support points along ±x, ±y, ±z) grown by the margin selects the grid cells; each
//! cell is cut into two triangular prisms (diagonal from column c−1, row r+1 to column c, row r;
//! base at z = −`size[3]`), visited row by row, then column, then the cell's two prisms. A prism
//! whose three tops plus the margin lie below the geom's lowest point is skipped; every other is a
//! convex solid collided with the geom by MuJoCo's native GJK/EPA (`collision::ccd`, the prism's
//! support as MuJoCo's `mjc_prism_support`), one contact per prism closer than the margin, at most
//! [`super::hfield::MAX_CONTACTS`]. Spheres keep their exact closed form
//! ([`super::hfield::sphere`]).

use super::ccd::penetration_prism;
use super::convex::ConvexShape;
use super::hfield::{HfieldPoint, MAX_CONTACTS};
use crate::model::{HeightField, Options};
use crate::spatial::{Transform, Vec3};

/// The contacts of the convex geom `shape` posed at `x_geom` with the height field `field` posed
/// at `x_hfield`, pair margin `margin`, in MuJoCo's order, passed to `out` (at most
/// [`MAX_CONTACTS`]). The normal points from the height field to the geom.
pub fn convex(
    x_hfield: &Transform,
    field: &HeightField,
    shape: &ConvexShape,
    x_geom: &Transform,
    margin: f64,
    options: &Options,
    out: &mut impl FnMut(HfieldPoint),
) {
    let (nrow, ncol) = (field.nrow, field.ncol);
    if nrow < 2 || ncol < 2 || field.data.len() < nrow * ncol {
        return;
    }
    let s = field.size;
    let rot = &x_hfield.rot;
    // The geom's box in the height-field frame: its support points along the frame's axes.
    let (mut lo, mut hi) = (Vec3::zeros(), Vec3::zeros());
    for k in 0..3 {
        let axis = rot.column(k).into_owned();
        let local = |p: Vec3| (rot.transpose() * (p - x_hfield.pos))[k];
        hi[k] = local(shape.world_support(x_geom, &axis));
        lo[k] = local(shape.world_support(x_geom, &-axis));
    }
    if lo.x - margin > s[0]
        || hi.x + margin < -s[0]
        || lo.y - margin > s[1]
        || hi.y + margin < -s[1]
        || lo.z - margin > s[2]
        || hi.z + margin < -s[3]
    {
        return;
    }
    // The sub-grid under the geom's box grown by the margin (as the sphere's, MuJoCo 4.0.0).
    let (glo, ghi) = (lo - Vec3::repeat(margin), hi + Vec3::repeat(margin));
    let cols = (ncol - 1) as f64;
    let rows = (nrow - 1) as f64;
    let cmin = (((glo.x + s[0]) / (2.0 * s[0]) * cols).floor().max(0.0)) as usize;
    let cmax = (((ghi.x + s[0]) / (2.0 * s[0]) * cols).ceil() as i64).clamp(0, ncol as i64 - 1) as usize;
    let rmin = (((glo.y + s[1]) / (2.0 * s[1]) * rows).floor().max(0.0)) as usize;
    let rmax = (((ghi.y + s[1]) / (2.0 * s[1]) * rows).ceil() as i64).clamp(0, nrow as i64 - 1) as usize;
    let dx = 2.0 * s[0] / cols;
    let dy = 2.0 * s[1] / rows;
    let vert = |r: usize, c: usize| {
        Vec3::new(dx * c as f64 - s[0], dy * r as f64 - s[1], f64::from(field.data[r * ncol + c]) * s[2])
    };
    let mut n = 0;
    for r in rmin..rmax {
        for c in cmin + 1..=cmax {
            let cell = [
                [vert(r + 1, c - 1), vert(r, c - 1), vert(r + 1, c)],
                [vert(r, c - 1), vert(r + 1, c), vert(r, c)],
            ];
            for top in &cell {
                if top.iter().all(|v| v.z + margin < lo.z) {
                    continue;
                }
                let base = top.map(|v| Vec3::new(v.x, v.y, -s[3]));
                let prism = [base[0], base[1], base[2], top[0], top[1], top[2]];
                let Some(con) = penetration_prism(
                    &prism,
                    x_hfield,
                    shape,
                    x_geom,
                    margin,
                    options.ccd_tolerance,
                    options.ccd_iterations as usize,
                ) else {
                    continue;
                };
                out(HfieldPoint { p1: con.x1, p2: con.x2, normal: con.normal, dist: con.dist });
                n += 1;
                if n >= MAX_CONTACTS {
                    return;
                }
            }
        }
    }
}
