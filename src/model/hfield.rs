//! A height field (MJCF `<asset><hfield>`) as MuJoCo compiles it (`mjCHField::Compile`,
//! user_objects.cc): an `nrow` × `ncol` grid of elevations in single precision, normalised to
//! [0, 1] (the minimum subtracted, then divided by the range when it exceeds MuJoCo's `mjEPS`),
//! spread over the rectangle [−`size[0]`, `size[0]`] × [−`size[1]`, `size[1]`] of the geom frame,
//! elevation `data · size[2]` above z = 0, the solid reaching down to z = −`size[3]`.
//!
//! Row `r` lies at y = −size₁ + r·2·size₁/(nrow − 1), column `c` at
//! x = −size₀ + c·2·size₀/(ncol − 1) (MuJoCo's `hfield_data[r·ncol + c]`): row 0 is the
//! lowest y, which is the *last* line of a PNG image or of the `elevation` attribute (MuJoCo
//! reverses both so that the text and the picture read top to bottom as seen from above).

/// A compiled height field (MuJoCo's `hfield_nrow`, `hfield_ncol`, `hfield_size`, `hfield_data`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HeightField {
    /// Number of rows (along y), at least 1.
    pub nrow: usize,
    /// Number of columns (along x), at least 1.
    pub ncol: usize,
    /// MuJoCo's `hfield_size`: radius along x, radius along y, elevation scale along z, depth of
    /// the base below z = 0 (m, all positive).
    pub size: [f64; 4],
    /// Normalised elevations in [0, 1], row-major (`data[r·ncol + c]`), single precision as
    /// MuJoCo stores them.
    pub data: Vec<f32>,
}

/// MuJoCo's `mjEPS`: a range of elevations at most this is left unscaled.
const MJ_EPS: f64 = 1e-14;

impl HeightField {
    /// A height field of `nrow` × `ncol` raw elevations (row-major, row 0 at the lowest y), with
    /// MuJoCo's normalisation to [0, 1] applied (in single precision, as MuJoCo does).
    pub fn new(nrow: usize, ncol: usize, size: [f64; 4], mut data: Vec<f32>) -> Self {
        let (mut emin, mut emax) = (1e10_f32, -1e10_f32);
        for &v in &data {
            emin = emin.min(v);
            emax = emax.max(v);
        }
        for v in &mut data {
            *v -= emin;
            if f64::from(emax - emin) > MJ_EPS {
                *v /= emax - emin;
            }
        }
        Self { nrow, ncol, size, data }
    }

    /// The elevation of grid point (row `r`, column `c`) above z = 0 (m).
    pub fn height(&self, r: usize, c: usize) -> f64 {
        f64::from(self.data[r * self.ncol + c]) * self.size[2]
    }

    /// MuJoCo's `geom_rbound` of a height field geom: the radius of the sphere about the geom
    /// origin holding its bounding box.
    pub fn rbound(&self) -> f64 {
        let s = &self.size;
        (s[0] * s[0] + s[1] * s[1] + (s[2] * s[2]).max(s[3] * s[3])).sqrt()
    }

    /// The half-extents of the box MuJoCo gives a height field geom for its mass and inertia
    /// (`geom_size`: size₀, size₁, size₂/4 + size₃/2).
    pub fn mass_box(&self) -> [f64; 3] {
        let s = &self.size;
        [s[0], s[1], 0.25 * s[2] + 0.5 * s[3]]
    }
}
