//! Tendons (MJCF `<tendon>`, MuJoCo's `tendon_*`/`wrap_*` arrays): fixed tendons — linear
//! combinations of joint positions — and spatial tendons — paths through sites that wrap around
//! spheres and cylinders, split by pulleys. Their lengths, Jacobians and wrap points are computed
//! each evaluation by [`crate::tendon`] into `Data::ten_*`.

use super::SourceLoc;

/// One tendon, in MuJoCo's tendon order (fixed and spatial in file order).
#[derive(Clone, Debug, PartialEq)]
pub struct Tendon {
    /// Its `name` (may be empty).
    pub name: String,
    /// Fixed or spatial, with its joints or path.
    pub kind: TendonKind,
    /// Length limits `[lower, upper]` if limited (limit rows in soft mode).
    pub range: Option<[f64; 2]>,
    /// Soft-constraint parameters of its limit and friction-loss rows (soft mode).
    pub soft: super::spec::SoftParams,
    /// The range of the total force of the actuators on this tendon (MJCF `actuatorfrcrange`
    /// with `actuatorfrclimited`): outside it, their forces are scaled down together.
    pub actuator_force_range: Option<[f64; 2]>,
    /// Spring stiffness along the tendon (MJCF `stiffness`, MuJoCo's `tendon_stiffness`).
    pub stiffness: f64,
    /// The spring's rest lengths `[lower, upper]` (MuJoCo's `tendon_lengthspring`): no spring
    /// force between them (a dead band when they differ). MJCF `springlength="-1 -1"` (the
    /// default) is resolved at compile time to the length at `qpos_spring`.
    pub spring_length: [f64; 2],
    /// Damping along the tendon (MJCF `damping`, MuJoCo's `tendon_damping`).
    pub damping: f64,
    /// Dry friction along the tendon (MJCF `frictionloss`): a friction row in soft mode.
    pub frictionloss: f64,
    /// Where it is written.
    pub loc: SourceLoc,
}

/// What a [`Tendon`] is made of.
#[derive(Clone, Debug, PartialEq)]
pub enum TendonKind {
    /// Length `L = Σ coefᵢ · q[joint i]` over hinge and slide joints (`<fixed><joint coef>`):
    /// (joint index, coefficient) pairs.
    Fixed {
        /// (index in `Model::joints`, coefficient) per joint.
        joints: Vec<(usize, f64)>,
    },
    /// A spatial tendon: a path through sites, wrapping geoms and pulleys.
    Spatial {
        /// Its path element by element, as written: the site or geom name, or `pulley <divisor>`.
        path: Vec<String>,
        /// The same path resolved (MuJoCo's `wrap_type`, `wrap_objid`, `wrap_prm`).
        wraps: Vec<PathElement>,
    },
}

/// The object a spatial tendon wraps around (MuJoCo's `mjWRAP_SPHERE`, `mjWRAP_CYLINDER`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WrapShape {
    /// A sphere.
    Sphere,
    /// A cylinder, about its local z axis (infinitely long for wrapping).
    Cylinder,
}

/// One element of a spatial tendon's path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PathElement {
    /// A site the tendon passes through (index in `Model::frames`).
    Site(usize),
    /// A sphere or cylinder geom the tendon wraps around, between the sites on either side.
    Geom {
        /// Index in `Model::geoms`.
        geom: usize,
        /// Sphere or cylinder.
        shape: WrapShape,
        /// The geom's radius (m).
        radius: f64,
        /// The side site choosing the wrap side (index in `Model::frames`), if any.
        sidesite: Option<usize>,
    },
    /// A pulley: the branches after it count `1/divisor` of their length.
    Pulley {
        /// MJCF `divisor`.
        divisor: f64,
    },
}

/// The most wrap points spatial tendon path `wraps` can produce (a bound for `Data::wrap_xpos`):
/// each site and pulley one, each geom two.
pub(crate) fn max_wrap_points(kind: &TendonKind) -> usize {
    match kind {
        TendonKind::Fixed { .. } => 0,
        TendonKind::Spatial { wraps, .. } => {
            wraps.iter().map(|w| if matches!(w, PathElement::Geom { .. }) { 2 } else { 1 }).sum()
        }
    }
}
