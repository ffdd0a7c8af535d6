//! Actuators (MJCF `<actuator>`, MuJoCo's `actuator_*` arrays) in MuJoCo's general form: every
//! shortcut (`motor`, `position`, `velocity`, …) is stored as the gain, bias and dynamics
//! parameters MuJoCo expands it to (MuJoCo documentation, "Actuation model"). Typed here so that
//! nothing is read back out of strings; simulated by the actuation stage (`forward::actuation`)
//! except the kinds [`unsimulated_reason`] names, which `info` lists as not simulated, the loader
//! warns about, and which exert no force.

use super::{JointKind, Model, SourceLoc};

/// The MJCF element the actuator was written as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ActuatorShortcut {
    /// `<general>`: the parameters as written.
    General,
    /// `<motor>`: force = control (gain 1, no bias).
    Motor,
    /// `<position>`: a position servo (gain `kp`, bias −`kp` · length − `kv` · velocity).
    Position,
    /// `<velocity>`: a velocity servo (gain `kv`, bias −`kv` · velocity).
    Velocity,
    /// `<intvelocity>`: a position servo on an integrated velocity control.
    IntVelocity,
    /// `<damper>`: force −`kv` · control · velocity.
    Damper,
    /// `<cylinder>`: a pneumatic or hydraulic cylinder (first-order filter on the pressure).
    Cylinder,
    /// `<muscle>`: MuJoCo's muscle model.
    Muscle,
    /// `<adhesion>`: an adhesive body force (a body transmission).
    Adhesion,
    /// `<plugin>`: an engine plugin (the MJCF loader keeps plugin actuators as untyped elements,
    /// so none has this shortcut).
    Plugin,
}

impl ActuatorShortcut {
    /// The MJCF element name (`motor`, `position`, ...).
    pub fn name(self) -> &'static str {
        match self {
            ActuatorShortcut::General => "general",
            ActuatorShortcut::Motor => "motor",
            ActuatorShortcut::Position => "position",
            ActuatorShortcut::Velocity => "velocity",
            ActuatorShortcut::IntVelocity => "intvelocity",
            ActuatorShortcut::Damper => "damper",
            ActuatorShortcut::Cylinder => "cylinder",
            ActuatorShortcut::Muscle => "muscle",
            ActuatorShortcut::Adhesion => "adhesion",
            ActuatorShortcut::Plugin => "plugin",
        }
    }
}

/// What the actuator acts on (`actuator_trntype` and `actuator_trnid`), by index.
#[derive(Clone, Debug, PartialEq)]
pub enum Transmission {
    /// A joint (index in `Model::joints`).
    Joint(usize),
    /// A joint, with the force applied in the parent frame (ball and free joints).
    JointInParent(usize),
    /// A tendon (index in `Model::tendons`).
    Tendon(usize),
    /// A site (index in `Model::frames`), with an optional reference site.
    Site {
        /// The site the force acts at (index in `Model::frames`).
        site: usize,
        /// The reference site (`refsite`; index in `Model::frames`), if any.
        refsite: Option<usize>,
    },
    /// A body (adhesion; index in `Model::bodies`).
    Body(usize),
    /// A slider-crank between two sites (frame indices).
    SliderCrank {
        /// The crank's site (index in `Model::frames`).
        cranksite: usize,
        /// The slider's site (index in `Model::frames`).
        slidersite: usize,
        /// Length of the connecting rod (m).
        cranklength: f64,
    },
}

/// Activation dynamics (`dyntype`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DynType {
    /// No activation state: the force acts on the control (`none`, `mjDYN_NONE`).
    #[default]
    None,
    /// ẇ = u (`integrator`).
    Integrator,
    /// ẇ = (u − w) / τ, τ = `dynprm[0]` (`filter`), integrated by the stepper.
    Filter,
    /// The same filter integrated exactly over a step (`filterexact`).
    FilterExact,
    /// MuJoCo's muscle activation (`muscle`).
    Muscle,
    /// A user callback (`user`).
    User,
}

/// Gain (`gaintype`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GainType {
    /// gain = `gainprm[0]` (`fixed`).
    #[default]
    Fixed,
    /// gain = `gainprm[0]` + `gainprm[1]` · length + `gainprm[2]` · velocity (`affine`).
    Affine,
    /// MuJoCo's muscle gain (`muscle`).
    Muscle,
    /// A user callback (`user`).
    User,
}

/// Bias (`biastype`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BiasType {
    /// No bias (`none`).
    #[default]
    None,
    /// bias = `biasprm[0]` + `biasprm[1]` · length + `biasprm[2]` · velocity (`affine`; a
    /// positive `biasprm[2]` of a position servo is a damping ratio, resolved in the model's plan).
    Affine,
    /// MuJoCo's muscle bias (`muscle`).
    Muscle,
    /// A user callback (`user`).
    User,
}

/// One actuator with MuJoCo's parameter vectors (lengths as `mjNDYN`, `mjNGAIN`, `mjNBIAS`).
#[derive(Clone, Debug, PartialEq)]
pub struct Actuator {
    /// Its `name` (may be empty).
    pub name: String,
    /// The MJCF element it was written as.
    pub shortcut: ActuatorShortcut,
    /// What it acts on.
    pub transmission: Transmission,
    /// Gear (moment arm scaling; 6 values for site and joint-in-parent transmissions).
    pub gear: [f64; 6],
    /// Activation dynamics (`dyntype`, `actuator_dyntype`).
    pub dyntype: DynType,
    /// Gain (`gaintype`, `actuator_gaintype`).
    pub gaintype: GainType,
    /// Bias (`biastype`, `actuator_biastype`).
    pub biastype: BiasType,
    /// Activation dynamics parameters (`dynprm`, `actuator_dynprm`).
    pub dynprm: [f64; 10],
    /// Gain parameters (`gainprm`, `actuator_gainprm`).
    pub gainprm: [f64; 10],
    /// Bias parameters (`biasprm`, `actuator_biasprm`).
    pub biasprm: [f64; 10],
    /// Control range if limited (`ctrllimited`, resolved with `autolimits`).
    pub ctrlrange: Option<[f64; 2]>,
    /// Force range if limited.
    pub forcerange: Option<[f64; 2]>,
    /// Activation range if limited.
    pub actrange: Option<[f64; 2]>,
    /// `actearly`: use the next activation in the force (MuJoCo ≥ 3).
    pub actearly: bool,
    /// The range of its length a muscle's gain and bias are normalized by (MuJoCo's
    /// `actuator_lengthrange`): the `lengthrange` written, else (with
    /// `<compiler><lengthrange uselimit="true">`) its joint's or tendon's range; [0, 0] when
    /// neither is given ([`crate::model::lengthrange`]).
    pub lengthrange: [f64; 2],
    /// |M₀⁻¹ momentᵀ| at `qpos0` (MuJoCo's `actuator_acc0`): the acceleration a unit force gives,
    /// which scales a muscle's `force` when that is negative ([`crate::model::lengthrange`]).
    pub acc0: f64,
    /// Its control history (`nsample` > 0), MuJoCo's `actuator_history`, `actuator_historyadr`
    /// and `actuator_delay`: None without one.
    pub history: Option<ActuatorHistory>,
    /// Where it is written.
    pub loc: SourceLoc,
}

/// How a history buffer is read between two samples (MJCF `interp`, MuJoCo's
/// `actuator_history[2i+1]`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Interp {
    /// `zoh`: the older sample (MuJoCo's default).
    #[default]
    ZeroOrderHold,
    /// `linear`: linear interpolation.
    Linear,
    /// `cubic`: a cubic Hermite spline with Catmull–Rom slopes.
    Cubic,
}

impl Interp {
    /// The MJCF keyword.
    pub fn name(self) -> &'static str {
        match self {
            Interp::ZeroOrderHold => "zoh",
            Interp::Linear => "linear",
            Interp::Cubic => "cubic",
        }
    }
}

/// An actuator's control history (MJCF `nsample`, `delay`, `interp`; `forward::history`): the
/// last `nsample` controls with their times, kept in `Data::history` from `adr` on
/// (2 + 2·nsample entries), and the delay with which the actuation stage reads them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActuatorHistory {
    /// Number of samples kept (MuJoCo's `actuator_history[2i]`, > 0).
    pub nsample: usize,
    /// How it is read between samples.
    pub interp: Interp,
    /// The delay (s) with which the force sees the control (MuJoCo's `actuator_delay`); 0 keeps
    /// the history without delaying the control.
    pub delay: f64,
    /// Its first entry in `Data::history` (MuJoCo's `actuator_historyadr`), set by the compiler.
    pub adr: usize,
}

impl Actuator {
    /// Number of activation states this actuator adds (MuJoCo's `actuator_actnum`: 0 or 1 here).
    pub fn actnum(&self) -> usize {
        usize::from(self.dyntype != DynType::None)
    }
}

/// Why actuator `a` of `model` is not simulated, or None if it is: user dynamics, gains and biases;
/// a muscle without `lengthrange`;
/// planar-joint transmissions; body (adhesion) transmissions on a body merged with bodies welded
/// to it (MuJoCo tells their contacts apart).
pub fn unsimulated_reason(model: &Model, a: &Actuator) -> Option<&'static str> {
    if a.dyntype == DynType::User {
        return Some("user activation dynamics");
    }
    if a.gaintype == GainType::User {
        return Some("user gain");
    }
    if a.biastype == BiasType::User {
        return Some("user bias");
    }
    let muscle = a.gaintype == GainType::Muscle || a.biastype == BiasType::Muscle;
    if muscle && a.lengthrange[0] >= a.lengthrange[1] {
        return Some("a muscle without lengthrange (<compiler><lengthrange mode=\"none\"> leaves it [0, 0]: give lengthrange, or drop mode=\"none\")");
    }
    match &a.transmission {
        Transmission::Joint(j) | Transmission::JointInParent(j) => {
            matches!(model.joints[*j].kind, JointKind::Planar { .. }).then_some("a planar joint transmission")
        }
        Transmission::Tendon(_) | Transmission::Site { .. } | Transmission::SliderCrank { .. } => None,
        Transmission::Body(b) => crate::forward::adhesion::unsupported_reason(model, *b),
    }
}
