//! Tendons (MJCF `<tendon>`, MuJoCo's `tendon_*`/`wrap_*` arrays). Fixed tendons — linear
//! combinations of joint positions — are simulated; spatial tendons are listed, not simulated.

use super::SourceLoc;

/// One tendon, in MuJoCo's tendon order (fixed and spatial in file order).
#[derive(Clone, Debug, PartialEq)]
pub struct Tendon {
    /// Its `name` (may be empty).
    pub name: String,
    /// Fixed or spatial, with its joints or path.
    pub kind: TendonKind,
    /// Length limits `[lower, upper]` if limited (fixed tendons: limit rows in soft mode;
    /// spatial tendons: not simulated).
    pub range: Option<[f64; 2]>,
    /// Soft-constraint parameters of its limit rows (soft mode).
    pub soft: super::spec::SoftParams,
    /// The range of the total force of the actuators on this tendon (MJCF `actuatorfrcrange`
    /// with `actuatorfrclimited`): outside it, their forces are scaled down together.
    pub actuator_force_range: Option<[f64; 2]>,
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
    /// A spatial tendon through sites and wrapping geoms: kept, not simulated (its path's names).
    Spatial {
        /// Its path element by element: the site or geom name, or `pulley <divisor>`.
        path: Vec<String>,
    },
}

/// Fixed tendon `t`'s length Σ coefᵢ·q[joint i] over configuration `x`, or with `velocity` its
/// rate Σ coefᵢ·v[joint i] over velocity `x` (MuJoCo's `ten_length`, `ten_velocity`); 0 for a
/// spatial tendon (not simulated).
pub(crate) fn fixed_tendon(model: &super::Model, t: usize, x: &[f64], velocity: bool) -> f64 {
    match &model.tendons[t].kind {
        TendonKind::Fixed { joints } => joints
            .iter()
            .map(|&(j, c)| {
                let joint = &model.joints[j];
                c * x[if velocity { joint.dof_adr } else { joint.qpos_adr }]
            })
            .sum(),
        TendonKind::Spatial { .. } => 0.0,
    }
}
