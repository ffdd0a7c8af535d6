//! The model *spec*: what a loader parsed, before the compile step (docs/architecture.md, "Layers") resolves
//! it into a [`Model`](super::Model). Links are a tree in depth-first file order; fixed joints are
//! still present here. Equality constraints, tendons, actuators and contact pairs name the objects
//! they act on; the compile step resolves the names to indices ([`EqualitySpec`] and the types
//! after it).

use super::actuator::{ActuatorShortcut, BiasType, DynType, GainType};
use super::{Element, Keyframe, Options, SourceLoc};
use crate::mass::{Distribution, GeomMass};
use crate::spatial::{Mat3, Transform, Vec3};
use std::path::PathBuf;

/// A parsed model, ready to compile.
#[derive(Clone, Debug, Default)]
pub struct ModelSpec {
    pub name: String,
    /// The file the model came from.
    pub source: Option<PathBuf>,
    /// Gravity in the world frame.
    pub gravity: Vec3,
    /// Links in depth-first file order: every link's parent comes before it; `links[0]` is the
    /// root, attached to the world by its `joint` (fixed, or free when floating).
    pub links: Vec<LinkSpec>,
    /// Rules the compile step applies to every link's mass properties (MJCF `<compiler>`).
    pub mass_rules: MassRules,
    /// Simulation options (MJCF `<option>`; defaults for URDF).
    pub options: Options,
    /// Named initial states (MJCF `<keyframe>`), in qpos/qvel layout.
    pub keyframes: Vec<Keyframe>,
    /// Equality constraints (MJCF `<equality>`), in file order; URDF mimics are on their joints.
    pub equalities: Vec<EqualitySpec>,
    /// Tendons (MJCF `<tendon>`), in file order (MuJoCo's tendon order).
    pub tendons: Vec<TendonSpec>,
    /// Actuators (MJCF `<actuator>`) in file order, shortcuts expanded.
    pub actuators: Vec<ActuatorSpec>,
    /// Explicit contact pairs (`<contact><pair>`).
    pub contact_pairs: Vec<ContactPairSpec>,
    /// Body pairs excluded from contact (`<contact><exclude>`).
    pub contact_excludes: Vec<ContactExcludeSpec>,
    /// Elements kept but not typed (sensors, flex equalities, …), listed by `lagrange info`.
    pub elements: Vec<Element>,
    /// Loader warnings (unknown attributes, ignored elements), each with file:line.
    pub warnings: Vec<String>,
}

/// MuJoCo's `<compiler>` rules for mass properties, applied per link in this order: inertia from
/// geoms (decided per link, [`LinkSpec::inertia_from_geoms`]), `boundmass` and `boundinertia` (lower
/// bounds on the mass and the principal moments), `balanceinertia` (replace moments that violate
/// the triangle inequality by their mean), then `settotalmass` (scale all moving masses).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MassRules {
    pub bound_mass: f64,
    pub bound_inertia: f64,
    pub balance_inertia: bool,
    /// Scale the masses and inertias of the moving links so that they total this (kg).
    pub total_mass: Option<f64>,
    /// Every moving body (its welded links included) must have mass and principal moments of at
    /// least MuJoCo's `mjMINVAL` (MJCF; URDF allows massless moving links with massive children).
    pub require_moving_mass: bool,
    /// Keep non-physical inertias (triangle inequality, negative principal moments) as written,
    /// with a warning, instead of rejecting them.
    pub accept_nonphysical: bool,
}

/// One link (URDF) or body (MJCF) with the joint that attaches it to its parent.
#[derive(Clone, Debug)]
pub struct LinkSpec {
    pub name: String,
    pub loc: SourceLoc,
    /// Index of the parent link in [`ModelSpec::links`]; `None` for the root (parent = world).
    pub parent: Option<usize>,
    pub joint: JointSpec,
    pub inertial: Option<InertialSpec>,
    /// Compute the mass properties from the geoms' (replacing `inertial`): MJCF
    /// `inertiafromgeom`, decided by the loader.
    pub inertia_from_geoms: bool,
    pub geoms: Vec<GeomSpec>,
    /// What the link's own frame stands for (MJCF joint anchors get [`FrameKind::Joint`]).
    pub kind: super::FrameKind,
    /// Further named frames rigidly attached to the link (MJCF sites; the MJCF body frame when a
    /// joint anchor or several joints put the link frame elsewhere).
    pub frames: Vec<FrameSpec>,
}

/// A named frame attached to a link.
#[derive(Clone, Debug)]
pub struct FrameSpec {
    pub name: String,
    pub loc: SourceLoc,
    pub kind: super::FrameKind,
    pub x_link_frame: Transform,
}

/// Joint types as model files name them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointType {
    Fixed,
    Revolute,
    Continuous,
    Prismatic,
    Floating,
    Planar,
    Ball,
}

impl JointType {
    /// Degrees of freedom of a joint of this type.
    pub fn nv(self) -> usize {
        match self {
            JointType::Fixed => 0,
            JointType::Revolute | JointType::Continuous | JointType::Prismatic => 1,
            JointType::Ball | JointType::Planar => 3,
            JointType::Floating => 6,
        }
    }
}

/// The joint between a link and its parent.
#[derive(Clone, Debug)]
pub struct JointSpec {
    pub name: String,
    pub loc: SourceLoc,
    pub jtype: JointType,
    /// Pose of the joint frame in the parent link frame (URDF `<origin>`).
    pub x_parent_joint: Transform,
    /// Axis in the joint frame as written (the compile step normalizes it; zero is an error).
    pub axis: Vec3,
    pub limits: Option<[f64; 2]>,
    /// MJCF `actuatorfrcrange` (with `actuatorfrclimited`): the range `qfrc_actuator` is clamped
    /// to on this joint's dofs.
    pub actuator_force_range: Option<[f64; 2]>,
    /// URDF `<limit effort>` when the loader was asked to clamp to it (`--clamp-effort`): the
    /// largest |actuator + applied| generalized force on the joint's dofs.
    pub effort_limit: Option<f64>,
    pub damping: f64,
    pub friction: f64,
    pub armature: f64,
    /// Joint spring: stiffness and its rest position (in q), MuJoCo `stiffness` / `springref`.
    pub stiffness: f64,
    pub spring_ref: f64,
    /// The joint's reference configuration (MuJoCo `qpos0`); empty means neutral.
    pub qpos0: Vec<f64>,
    /// URDF `<mimic>`: this joint follows another one.
    pub mimic: Option<MimicSpec>,
    /// Soft-constraint parameters of its limit and friction-loss rows (MJCF `solreflimit`,
    /// `solimplimit`, `solreffriction`, `solimpfriction`, `margin`).
    pub soft: SoftParams,
}

/// The soft-constraint parameters of a joint's or a tendon's limit and friction-loss rows
/// (MuJoCo's `jnt_solref`, `jnt_solimp`, `jnt_margin`, `dof_solref`, `dof_solimp`, and the
/// tendon's `tendon_solref_lim`, …; MuJoCo documentation, "XML Reference → joint / tendon").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftParams {
    pub solref_limit: [f64; 2],
    pub solimp_limit: [f64; 5],
    pub solref_friction: [f64; 2],
    pub solimp_friction: [f64; 5],
    /// Distance from a bound within which the limit row is active (MuJoCo's `jnt_margin`).
    pub margin: f64,
}

impl Default for SoftParams {
    fn default() -> Self {
        use crate::model::equality::{DEFAULT_SOLIMP, DEFAULT_SOLREF};
        Self {
            solref_limit: DEFAULT_SOLREF,
            solimp_limit: DEFAULT_SOLIMP,
            solref_friction: DEFAULT_SOLREF,
            solimp_friction: DEFAULT_SOLIMP,
            margin: 0.0,
        }
    }
}

/// URDF `<mimic joint multiplier offset>`: `q = multiplier · q[leader] + offset`.
#[derive(Clone, Debug, PartialEq)]
pub struct MimicSpec {
    /// The joint followed (`joint` attribute).
    pub leader: String,
    pub multiplier: f64,
    pub offset: f64,
    /// The `<mimic>` element.
    pub loc: SourceLoc,
}

impl JointSpec {
    /// A joint of type `jtype` at the identity placement with axis x and no limits.
    pub fn new(name: &str, jtype: JointType, loc: SourceLoc) -> Self {
        Self {
            name: name.to_string(),
            loc,
            jtype,
            x_parent_joint: Transform::identity(),
            axis: Vec3::x(),
            limits: None,
            actuator_force_range: None,
            effort_limit: None,
            damping: 0.0,
            friction: 0.0,
            armature: 0.0,
            stiffness: 0.0,
            spring_ref: 0.0,
            qpos0: Vec::new(),
            mimic: None,
            soft: SoftParams::default(),
        }
    }
}

/// Mass properties as written: mass, the pose of the inertial frame in the link frame (its origin
/// is the centre of mass), and the inertia tensor about the centre of mass in inertial-frame axes.
#[derive(Clone, Debug)]
pub struct InertialSpec {
    pub mass: f64,
    pub x_link_inertial: Transform,
    pub inertia: Mat3,
    pub loc: SourceLoc,
}

/// Geometric shapes kept from model files.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Box {
        size: Vec3,
    },
    Cylinder {
        radius: f64,
        length: f64,
    },
    Capsule {
        radius: f64,
        length: f64,
    },
    Sphere {
        radius: f64,
    },
    /// An ellipsoid with the given semi-axes (MJCF).
    Ellipsoid {
        radii: Vec3,
    },
    /// An infinite plane z = 0 of the geom frame (MJCF; `size` is for drawing only).
    Plane {
        size: Vec3,
    },
    /// A height field asset (MJCF), by name.
    Hfield {
        name: String,
    },
    /// A mesh file, resolved to a path on disk, with its scale.
    Mesh {
        path: PathBuf,
        scale: Vec3,
    },
}

/// A visual or collision geometry of a link.
#[derive(Clone, Debug)]
pub struct GeomSpec {
    pub name: String,
    pub loc: SourceLoc,
    pub x_link_geom: Transform,
    pub shape: Shape,
    /// Whether it takes part in collisions (URDF `<collision>`; MJCF contype or conaffinity ≠ 0).
    pub collision: bool,
    /// The mass it contributes when the link's inertia comes from its geoms.
    pub mass: GeomMass,
    pub distribution: Distribution,
    /// For meshes: how MuJoCo computes its inertia (`<mesh inertia>`).
    pub mesh_inertia: crate::mass::MeshInertia,
    /// MJCF `group`.
    pub group: i32,
    /// Contact parameters (MJCF `contype`, `conaffinity`, `condim`, `priority`, `friction`,
    /// `solmix`, `solref`, `solimp`, `margin`, `gap`; MuJoCo's defaults for URDF).
    pub contact: GeomContact,
}

/// A geom's contact parameters (MuJoCo documentation, "XML Reference → geom" and "Computation →
/// Collision detection → Contact parameters").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeomContact {
    pub contype: u32,
    pub conaffinity: u32,
    /// 1 (frictionless), 3 (sliding), 4 (+ torsional), 6 (+ rolling).
    pub condim: u32,
    pub priority: i32,
    /// Sliding, torsional, rolling.
    pub friction: [f64; 3],
    pub solmix: f64,
    pub solref: [f64; 2],
    pub solimp: [f64; 5],
    pub margin: f64,
    pub gap: f64,
}

impl Default for GeomContact {
    /// MuJoCo's defaults.
    fn default() -> Self {
        Self {
            contype: 1,
            conaffinity: 1,
            condim: 3,
            priority: 0,
            friction: [1.0, 0.005, 0.0001],
            solmix: 1.0,
            solref: [0.02, 1.0],
            solimp: [0.9, 0.95, 0.001, 0.5, 2.0],
            margin: 0.0,
            gap: 0.0,
        }
    }
}

impl GeomSpec {
    /// A massless geom of `shape` at `x_link_geom` with MuJoCo's default contact parameters.
    pub fn new(shape: Shape, x_link_geom: Transform, loc: SourceLoc) -> Self {
        Self {
            name: String::new(),
            loc,
            x_link_geom,
            shape,
            collision: true,
            mass: GeomMass::None,
            distribution: Distribution::Volume,
            mesh_inertia: Default::default(),
            group: 0,
            contact: GeomContact::default(),
        }
    }
}

/// An equality constraint as written (MJCF `<equality>`), naming the objects it ties together;
/// compiled into [`Equality`](super::Equality).
#[derive(Clone, Debug, PartialEq)]
pub struct EqualitySpec {
    pub name: String,
    pub kind: EqualitySpecKind,
    pub active: bool,
    pub solref: [f64; 2],
    pub solimp: [f64; 5],
    pub loc: SourceLoc,
}

/// What an [`EqualitySpec`] ties together, by name. `body2: None` is the world.
#[derive(Clone, Debug, PartialEq)]
pub enum EqualitySpecKind {
    /// `<connect body1 body2 anchor>`: `anchor` in body1 coordinates.
    ConnectBodies { body1: String, body2: Option<String>, anchor: [f64; 3] },
    /// `<connect site1 site2>`.
    ConnectSites { site1: String, site2: String },
    /// `<weld body1 body2 anchor relpose torquescale>`: `anchor` in body2 coordinates, `relpose`
    /// the pose of body2's anchor frame in body1 (`None`: taken at `qpos0`).
    WeldBodies {
        body1: String,
        body2: Option<String>,
        anchor: [f64; 3],
        relpose: Option<Transform>,
        torquescale: f64,
    },
    /// `<weld site1 site2 torquescale>`.
    WeldSites { site1: String, site2: String, torquescale: f64 },
    /// `<joint joint1 joint2 polycoef>`.
    Joint { joint1: String, joint2: Option<String>, polycoef: [f64; 5] },
    /// `<tendon tendon1 tendon2 polycoef>`.
    Tendon { tendon1: String, tendon2: Option<String>, polycoef: [f64; 5] },
}

/// A tendon as written (MJCF `<fixed>` or `<spatial>`); compiled into
/// [`Tendon`](super::Tendon).
#[derive(Clone, Debug, PartialEq)]
pub struct TendonSpec {
    pub name: String,
    pub kind: TendonSpecKind,
    /// Length limits if limited (`limited`/`range`, resolved with `autolimits`).
    pub range: Option<[f64; 2]>,
    /// Soft-constraint parameters of its limit rows (`solreflimit`, `solimplimit`, `margin`).
    pub soft: SoftParams,
    /// Total actuator force range if limited (`actuatorfrclimited`/`actuatorfrcrange`).
    pub actuator_force_range: Option<[f64; 2]>,
    pub loc: SourceLoc,
}

#[derive(Clone, Debug, PartialEq)]
pub enum TendonSpecKind {
    /// `<fixed>`: its `<joint joint coef>` children (joint name, coefficient, element).
    Fixed { joints: Vec<(String, f64, SourceLoc)> },
    /// `<spatial>`: its path as (element, name): `site` and `geom` with the object's name,
    /// `pulley` with its divisor.
    Spatial { path: Vec<(String, String)> },
}

/// What an actuator acts on, by name (MJCF `joint`, `jointinparent`, `tendon`, `site` with
/// `refsite`, `body`, `cranksite` with `slidersite`).
#[derive(Clone, Debug, PartialEq)]
pub enum TransmissionSpec {
    Joint(String),
    JointInParent(String),
    Tendon(String),
    Site { site: String, refsite: Option<String> },
    Body(String),
    SliderCrank { cranksite: String, slidersite: String, cranklength: f64 },
}

/// An actuator as written, with its shortcut already expanded into MuJoCo's general form;
/// compiled into [`Actuator`](super::Actuator).
#[derive(Clone, Debug, PartialEq)]
pub struct ActuatorSpec {
    pub name: String,
    pub shortcut: ActuatorShortcut,
    pub transmission: TransmissionSpec,
    pub gear: [f64; 6],
    pub dyntype: DynType,
    pub gaintype: GainType,
    pub biastype: BiasType,
    pub dynprm: [f64; 10],
    pub gainprm: [f64; 10],
    pub biasprm: [f64; 10],
    pub ctrlrange: Option<[f64; 2]>,
    pub forcerange: Option<[f64; 2]>,
    pub actrange: Option<[f64; 2]>,
    pub actearly: bool,
    /// `inheritrange` (position and intvelocity servos): the control range (activation range for
    /// `intvelocity`) is this fraction of the target joint's or tendon's range, about its middle;
    /// set by the compile step, which knows the target.
    pub inheritrange: Option<f64>,
    /// Actuator-level passive damping and armature (MuJoCo's `actuator_damping`,
    /// `actuator_armature`): reflected through the transmission onto its dofs.
    pub damping: f64,
    pub armature: f64,
    pub loc: SourceLoc,
}

/// `<contact><pair>` as written; compiled into [`ContactPair`](super::ContactPair).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPairSpec {
    pub name: String,
    pub geom1: String,
    pub geom2: String,
    pub condim: u32,
    pub friction: [f64; 5],
    pub solref: [f64; 2],
    pub solreffriction: [f64; 2],
    pub solimp: [f64; 5],
    pub margin: f64,
    pub gap: f64,
    pub loc: SourceLoc,
}

/// `<contact><exclude>` as written; compiled into [`ContactExclude`](super::ContactExclude).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactExcludeSpec {
    pub name: String,
    pub body1: String,
    pub body2: String,
    pub loc: SourceLoc,
}
