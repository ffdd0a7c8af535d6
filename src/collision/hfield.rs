//! Height fields as MuJoCo 4.0 collides them (`mjc_ConvexHField`, engine_collision_convex.c): the
//! grid cells under the other geom's box (its support points along the height field's axes, in
//! the field's frame) are cut into two triangular prisms each, diagonal from (column c−1, row
//! r+1) to (c, r), bottoms at z = −`size[3]`, visited row by row, then column, then the two prisms
//! of the cell. `Cells` is that grid; `hfield_convex` collides each prism with the geom.

use crate::model::HeightField;
use crate::spatial::Vec3;

/// MuJoCo's `mjMAXCONPAIR`: the most contacts one height-field pair yields.
pub const MAX_CONTACTS: usize = 50;

/// One height-field contact in world coordinates: its position, the normal from the height
/// field to the geom and the signed distance.
#[derive(Clone, Copy, Debug)]
pub struct HfieldPoint {
    /// Contact position (world, m): the midpoint of the two witness points.
    pub pos: Vec3,
    /// Unit normal from the height field to the geom (world).
    pub normal: Vec3,
    /// Signed distance (m, negative: penetration).
    pub dist: f64,
}

/// The grid cells of a height field under a geom's box `[lo, hi]` (height-field frame) grown by
/// `margin` — MuJoCo 4.0's sub-grid, measured on its contacts — with the grid spacing; the
/// prisms [`super::hfield_convex`] collides.
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
