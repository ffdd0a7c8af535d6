//! Explicit contact pairs and exclusions (MJCF `<contact>`), with resolved geom and body indices.
//! The collision layer's candidate pairs (`model::collision_pairs`) are built from them.

use super::SourceLoc;

/// `<pair>`: a candidate contact between two geoms with its own parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPair {
    /// Its `name` (may be empty).
    pub name: String,
    /// Indices in [`Model::geoms`](super::Model).
    pub geom1: usize,
    /// The second geom (index in `Model::geoms`).
    pub geom2: usize,
    /// 1 (frictionless), 3 (sliding), 4 (+ torsional), 6 (+ rolling).
    pub condim: u32,
    /// Sliding (2), torsional and rolling (2) friction.
    pub friction: [f64; 5],
    /// `solref` of the normal rows.
    pub solref: [f64; 2],
    /// `solref` of the friction rows of elliptic cones (`[0, 0]`: use `solref`).
    pub solreffriction: [f64; 2],
    /// `solimp` of the rows.
    pub solimp: [f64; 5],
    /// Distance below which a contact has constraint rows (m).
    pub margin: f64,
    /// Distance beyond `margin` within which contacts are reported without rows (m).
    pub gap: f64,
    /// Where it is written.
    pub loc: SourceLoc,
}

/// `<exclude>`: no contacts between the geoms of two bodies (indices in
/// [`Model::bodies`](super::Model)).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactExclude {
    /// Its `name` (may be empty).
    pub name: String,
    /// The first body (index in `Model::bodies`).
    pub body1: usize,
    /// The second body (index in `Model::bodies`).
    pub body2: usize,
    /// The two bodies as MuJoCo numbers them (`Model::links`; the file's bodies, a body fused
    /// into its parent keeping its own id), in `body1`, `body2` order: what the exclusion compares
    /// with each geom's body (MuJoCo's `geom_bodyid`).
    pub mujoco_body: [usize; 2],
    /// Where it is written.
    pub loc: SourceLoc,
}

/// One contact between two geoms found by the collision layer (MuJoCo's `mjContact`), world
/// coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Indices in [`Model::geoms`](super::Model); `geom[0]` is MuJoCo's geom1.
    pub geom: [usize; 2],
    /// Midpoint between the two surfaces.
    pub pos: crate::spatial::Vec3,
    /// Rows: the normal (pointing from geom1 towards geom2), tangent1, tangent2.
    pub frame: crate::spatial::Mat3,
    /// Signed distance, negative = penetration.
    pub dist: f64,
    /// The distance below which the contact has constraint rows: the pair's margin (MuJoCo 4.0:
    /// the geoms' margins add up, and contacts are detected up to margin + gap, the gap's
    /// contacts being kept without rows).
    pub includemargin: f64,
    /// The pair's gap: the contact is reported while `dist` < `includemargin` + `gap` (the
    /// exact mode's collision looks a little further; adhesion counts only these).
    pub gap: f64,
    /// 1 (frictionless), 3 (sliding), 4 (+ torsional), 6 (+ rolling).
    pub condim: u32,
    /// tangent1, tangent2, torsional, rolling1, rolling2.
    pub friction: [f64; 5],
    /// `solref` of the normal rows (time constant, damping ratio).
    pub solref: [f64; 2],
    /// `solref` of the friction rows of elliptic cones (`[0, 0]`: use `solref`).
    pub solreffriction: [f64; 2],
    /// `solimp` of the rows (dmin, dmax, width, midpoint, power).
    pub solimp: [f64; 5],
    /// Index in `Model::contact_pairs` for explicit pairs.
    pub pair: Option<usize>,
    /// Which feature of the pair made the contact (a box corner, a capsule end, a hull vertex;
    /// 0 for single-contact pairs): with `geom`, the contact's identity from one configuration to
    /// the next (lagrange's addition to MuJoCo's fields).
    pub feature: u32,
}
