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
use super::hfield::{Cells, HfieldPoint, MAX_CONTACTS};
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
    let Some(cells) = Cells::under(field, &lo, &hi, margin) else { return };
    let mut n = 0;
    for r in cells.rows.clone() {
        for c in cells.cols.clone() {
            for top in &cells.tops(field, r, c) {
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
