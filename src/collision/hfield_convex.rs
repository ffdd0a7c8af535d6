//! Height-field contacts as MuJoCo 4.0 makes them (`mjc_ConvexHField`, engine_collision_convex.c),
//! for every geom it collides with a height field (spheres, capsules, boxes, cylinders, ellipsoids,
//! meshes), computed in the height field's frame as MuJoCo computes them: the geom's pose relative
//! to the field (its position difference rotated into the field, its rotation Rᵀ_field R_geom), its
//! box in that frame (support points along ±x, ±y, ±z) grown by the margin selecting the grid cells
//! (`hfield::Cells`); each cell cut into two triangular prisms (base at z = −`size[3]`),
//! visited row by row, then column, then the cell's two prisms. A prism whose three tops plus the
//! margin lie below the geom's lowest point is skipped; every other is a convex solid collided with
//! the geom by MuJoCo's native GJK/EPA (`collision::ccd`: the prism's support as `mjc_prism_support`,
//! which leaves the vertex index at −1, GJK started from the prism's centre — the mean of its six
//! vertices — and the geom's), one contact per prism closer than the margin, at most
//! [`super::hfield::MAX_CONTACTS`]: the witnesses' midpoint and normal turned back to world. Read
//! from the live 4.0.0 library's support calls (docs/multiccd.md, "Reading the live library").

use super::ccd::{penetration_prism, support_box};
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
    // Everything below in the height field's frame, as MuJoCo computes it: the geom's pose
    // relative to the field (position difference, then rotated) and the prisms in field
    // coordinates; contacts are turned back to world at the end.
    let x_local = Transform::new(rot.tr_mul(&x_geom.rot), rot.tr_mul(&(x_geom.pos - x_hfield.pos)));
    // The geom's box in the height-field frame: its support points along the frame's axes.
    let (lo, hi) = support_box(shape, &x_local);
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
                    &Transform::identity(),
                    shape,
                    &x_local,
                    margin,
                    options.ccd_tolerance,
                    options.ccd_iterations as usize,
                ) else {
                    continue;
                };
                // MuJoCo's contact: the witnesses' midpoint and the normal, rotated and moved
                // back to world.
                let pos = rot * ((con.x1 + con.x2) * 0.5) + x_hfield.pos;
                out(HfieldPoint { pos, normal: rot * con.normal, dist: con.dist });
                n += 1;
                if n >= MAX_CONTACTS {
                    return;
                }
            }
        }
    }
}
