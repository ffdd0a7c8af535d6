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
    /// The model's name (URDF `<robot name>`, MJCF `<mujoco model>`).
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
    /// `<compiler><lengthrange>`: how `actuator_lengthrange` is found.
    pub lengthrange: crate::model::lengthrange::LengthRangeOptions,
    /// Explicit contact pairs (`<contact><pair>`).
    pub contact_pairs: Vec<ContactPairSpec>,
    /// Body pairs excluded from contact (`<contact><exclude>`).
    pub contact_excludes: Vec<ContactExcludeSpec>,
    /// Elements kept but not typed (sensors, flex equalities, …), listed by `lagrange info`.
    pub elements: Vec<Element>,
    /// Loader warnings (unknown attributes, ignored elements), each with file:line.
    pub warnings: Vec<String>,
    /// Gravity compensation (MJCF body `gravcomp`): (index in [`links`](Self::links), fraction of
    /// the link's weight cancelled), for the links where it is nonzero.
    pub gravcomp: Vec<(usize, f64)>,
    /// Sleep policies other than `auto` (MJCF body `sleep`): (index in [`links`](Self::links),
    /// policy).
    pub sleep: Vec<(usize, crate::model::sleep::SleepPolicy)>,
}

/// MuJoCo's `<compiler>` rules for mass properties, applied per link in this order: inertia from
/// geoms (decided per link, [`LinkSpec::inertia_from_geoms`]), `boundmass` and `boundinertia` (lower
/// bounds on the mass and the principal moments), `balanceinertia` (replace moments that violate
/// the triangle inequality by their mean), then `settotalmass` (scale the masses of all links but
/// the world).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MassRules {
    /// Lower bound on the mass of every link but the world (kg; MJCF `boundmass`, 0 = none).
    pub bound_mass: f64,
    /// Lower bound on the principal moments of inertia of every link but the world (kg·m²; MJCF
    /// `boundinertia`, 0 = none).
    pub bound_inertia: f64,
    /// Replace principal moments that violate the triangle inequality by their mean (MJCF
    /// `balanceinertia`); otherwise such moments are an error.
    pub balance_inertia: bool,
    /// Scale the masses and inertias of all links but the world so that they total this (kg).
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
    /// The link's (body's) name.
    pub name: String,
    /// Where the link is written.
    pub loc: SourceLoc,
    /// Index of the parent link in [`ModelSpec::links`]; `None` for the root (parent = world).
    pub parent: Option<usize>,
    /// The joint attaching the link to its parent (fixed when the link is welded to it).
    pub joint: JointSpec,
    /// Mass properties as written (`<inertial>`); `None` if the file gives none.
    pub inertial: Option<InertialSpec>,
    /// Compute the mass properties from the geoms' (replacing `inertial`): MJCF
    /// `inertiafromgeom`, decided by the loader.
    pub inertia_from_geoms: bool,
    /// The link's geometries, visual and collision, in file order.
    pub geoms: Vec<GeomSpec>,
    /// What the link's own frame stands for (MJCF joint anchors get
    /// [`FrameKind::Joint`](super::FrameKind::Joint)).
    pub kind: super::FrameKind,
    /// Further named frames rigidly attached to the link (MJCF sites; the MJCF body frame when a
    /// joint anchor or several joints put the link frame elsewhere).
    pub frames: Vec<FrameSpec>,
    /// An MJCF mocap body (`mocap="true"`, a top-level body without joints): its pose is an input
    /// of the simulation (`Data::mocap_pos`, `Data::mocap_quat`), not a state.
    pub mocap: bool,
}

/// A named frame attached to a link.
#[derive(Clone, Debug)]
pub struct FrameSpec {
    /// The frame's name.
    pub name: String,
    /// Where the frame is written (the MJCF `<site>` or `<body>`).
    pub loc: SourceLoc,
    /// What the frame stands for (site, body, joint anchor).
    pub kind: super::FrameKind,
    /// Pose of the frame in the link frame.
    pub x_link_frame: Transform,
    /// An MJCF site's shape and size (MuJoCo's `site_type`, `site_size`); None for other frames.
    pub site: Option<crate::mass::Primitive>,
}

/// Joint types as model files name them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointType {
    /// No motion: the link is welded to its parent (URDF `fixed`, an MJCF body without joints).
    Fixed,
    /// Rotation about `axis` (URDF `revolute`, MJCF `hinge`).
    Revolute,
    /// Rotation about `axis`, unbounded (URDF `continuous`).
    Continuous,
    /// Translation along `axis` (URDF `prismatic`, MJCF `slide`).
    Prismatic,
    /// Six degrees of freedom (URDF `floating`, MJCF `free`).
    Floating,
    /// Translation in the plane normal to `axis` and rotation about it (URDF `planar`).
    Planar,
    /// Three rotational degrees of freedom (MJCF `ball`, URDF `spherical`).
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
    /// The joint's name (may be empty in MJCF).
    pub name: String,
    /// Where the joint is written.
    pub loc: SourceLoc,
    /// The joint's type.
    pub jtype: JointType,
    /// Pose of the joint frame in the parent link frame (URDF `<origin>`).
    pub x_parent_joint: Transform,
    /// Axis in the joint frame as written (the compile step normalizes it; zero is an error).
    pub axis: Vec3,
    /// Position limits `[lower, upper]` (rad or m) if limited; for a ball joint `[0, max angle]`.
    pub limits: Option<[f64; 2]>,
    /// MJCF `actuatorfrcrange` (with `actuatorfrclimited`): the range `qfrc_actuator` is clamped
    /// to on this joint's dofs.
    pub actuator_force_range: Option<[f64; 2]>,
    /// URDF `<limit effort>` when the loader was asked to clamp to it (`--clamp-effort`): the
    /// largest |actuator + applied| generalized force on the joint's dofs.
    pub effort_limit: Option<f64>,
    /// Viscous damping (N·m·s/rad or N·s/m; URDF `<dynamics damping>`, MJCF `damping`).
    pub damping: f64,
    /// Dry friction loss (N·m or N; URDF `<dynamics friction>`, MJCF `frictionloss`).
    pub friction: f64,
    /// Rotor inertia added to the diagonal of the mass matrix (kg·m² or kg; MJCF `armature`).
    pub armature: f64,
    /// Joint spring stiffness (N·m/rad or N/m; MuJoCo `stiffness`).
    pub stiffness: f64,
    /// The spring's rest position, in q (MuJoCo `springref`).
    pub spring_ref: f64,
    /// MJCF `springdamper` (timeconst, dampratio), both positive: stiffness and damping computed
    /// at compile time from the joint's inertia at `qpos0`, replacing `stiffness` and `damping`
    /// (MuJoCo's `mjCModel::AutoSpringDamper`).
    pub springdamper: Option<[f64; 2]>,
    /// The joint's reference configuration (MuJoCo `qpos0`); empty means neutral.
    pub qpos0: Vec<f64>,
    /// URDF `<mimic>`: this joint follows another one.
    pub mimic: Option<MimicSpec>,
    /// Soft-constraint parameters of its limit and friction-loss rows (MJCF `solreflimit`,
    /// `solimplimit`, `solreffriction`, `solimpfriction`, `margin`).
    pub soft: SoftParams,
    /// MJCF `actuatorgravcomp`: the gravity compensation of the joint's dofs is added to
    /// `qfrc_actuator` (subject to `actuatorfrcrange`) instead of `qfrc_passive`.
    pub actuator_gravcomp: bool,
}

/// The soft-constraint parameters of a joint's or a tendon's limit and friction-loss rows
/// (MuJoCo's `jnt_solref`, `jnt_solimp`, `jnt_margin`, `dof_solref`, `dof_solimp`, and the
/// tendon's `tendon_solref_lim`, …; MuJoCo documentation, "XML Reference → joint / tendon").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftParams {
    /// `solref` of the limit rows (MJCF `solreflimit`).
    pub solref_limit: [f64; 2],
    /// `solimp` of the limit rows (MJCF `solimplimit`).
    pub solimp_limit: [f64; 5],
    /// `solref` of the friction-loss rows (MJCF `solreffriction`).
    pub solref_friction: [f64; 2],
    /// `solimp` of the friction-loss rows (MJCF `solimpfriction`).
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
    /// `multiplier` (default 1).
    pub multiplier: f64,
    /// `offset` (rad or m, default 0).
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
            springdamper: None,
            qpos0: Vec::new(),
            mimic: None,
            soft: SoftParams::default(),
            actuator_gravcomp: false,
        }
    }
}

/// Mass properties as written: mass, the pose of the inertial frame in the link frame (its origin
/// is the centre of mass), and the inertia tensor about the centre of mass in inertial-frame axes.
#[derive(Clone, Debug)]
pub struct InertialSpec {
    /// Mass (kg).
    pub mass: f64,
    /// Pose of the inertial frame in the link frame; its origin is the centre of mass.
    pub x_link_inertial: Transform,
    /// Inertia tensor about the centre of mass in inertial-frame axes (kg·m²).
    pub inertia: Mat3,
    /// Where the `<inertial>` is written.
    pub loc: SourceLoc,
}

/// Geometric shapes kept from model files.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A box centred on the geom frame, axes along its axes.
    Box {
        /// Full edge lengths (m; MJCF `size` holds half of them).
        size: Vec3,
    },
    /// A cylinder centred on the geom frame, along its z axis.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Full length (m; MJCF `size` holds the half-length).
        length: f64,
    },
    /// A capsule (a cylinder with hemispherical caps) centred on the geom frame, along its z axis.
    Capsule {
        /// Radius of the cylinder and the caps (m).
        radius: f64,
        /// Full length of the cylindrical part, caps excluded (m; MJCF `size` holds the
        /// half-length).
        length: f64,
    },
    /// A sphere centred on the geom frame.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// An ellipsoid with the given semi-axes (MJCF).
    Ellipsoid {
        /// Semi-axes along the geom frame's x, y, z (m).
        radii: Vec3,
    },
    /// An infinite plane z = 0 of the geom frame (MJCF; `size` is for drawing only).
    Plane {
        /// MJCF `size` as written.
        size: Vec3,
    },
    /// A height field asset (MJCF), by name, with its compiled grid.
    Hfield {
        /// The `<hfield>` asset's name.
        name: String,
        /// The grid and sizes (shared by the geoms naming the asset).
        field: std::sync::Arc<super::hfield::HeightField>,
    },
    /// A mesh (a file resolved to a path on disk, or an inline asset), with its scale.
    Mesh {
        /// Where the mesh's triangles come from.
        source: crate::mass::MeshSource,
        /// Scale factors along the mesh's x, y, z, applied to its vertices.
        scale: Vec3,
    },
}

/// MuJoCo's default `geom_rgba`.
pub const DEFAULT_GEOM_RGBA: [f32; 4] = [0.5, 0.5, 0.5, 1.0];

/// A visual or collision geometry of a link.
#[derive(Clone, Debug)]
pub struct GeomSpec {
    /// The geom's name (may be empty).
    pub name: String,
    /// Where the geom is written.
    pub loc: SourceLoc,
    /// Pose of the geom frame in the link frame.
    pub x_link_geom: Transform,
    /// The geometry.
    pub shape: Shape,
    /// Whether it takes part in collisions (URDF `<collision>`; MJCF contype or conaffinity ≠ 0).
    pub collision: bool,
    /// The mass it contributes when the link's inertia comes from its geoms.
    pub mass: GeomMass,
    /// Whether the mass fills the volume or lies on the surface (MJCF `shellinertia`).
    pub distribution: Distribution,
    /// For meshes: how MuJoCo computes its inertia (`<mesh inertia>`).
    pub mesh_inertia: crate::mass::MeshInertia,
    /// MJCF `group` (0 by default).
    pub group: i32,
    /// MJCF `rgba` (MuJoCo's `geom_rgba`, 0.5 0.5 0.5 1 by default).
    pub rgba: [f32; 4],
    /// The `rgba` of the geom's MJCF `material`, if it names one (MuJoCo's `mat_rgba`).
    pub material_rgba: Option<[f32; 4]>,
    /// Contact parameters (MJCF `contype`, `conaffinity`, `condim`, `priority`, `friction`,
    /// `solmix`, `solref`, `solimp`, `margin`, `gap`; MuJoCo's defaults for URDF).
    pub contact: GeomContact,
    /// MJCF `fluidshape="ellipsoid"` with its `fluidcoef` (blunt drag, slender drag, angular
    /// drag, Kutta lift, Magnus lift; MuJoCo's defaults 0.5 0.25 1.5 1 1): the geom takes part
    /// in MuJoCo's ellipsoid fluid model. None for `fluidshape="none"` (the default).
    pub fluid: Option<[f64; 5]>,
}

/// A geom's contact parameters (MuJoCo documentation, "XML Reference → geom" and "Computation →
/// Collision detection → Contact parameters").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeomContact {
    /// Contact type bit mask (`contype`): two geoms may touch when either's `contype` shares a bit
    /// with the other's `conaffinity`.
    pub contype: u32,
    /// Contact affinity bit mask (`conaffinity`).
    pub conaffinity: u32,
    /// 1 (frictionless), 3 (sliding), 4 (+ torsional), 6 (+ rolling).
    pub condim: u32,
    /// `priority`: of two geoms in contact, the higher one's parameters are used.
    pub priority: i32,
    /// Sliding, torsional, rolling.
    pub friction: [f64; 3],
    /// `solmix`: weight of this geom's `solref`/`solimp` when mixed with the other geom's.
    pub solmix: f64,
    /// `solref` of the contact rows (time constant, damping ratio).
    pub solref: [f64; 2],
    /// `solimp` of the contact rows (dmin, dmax, width, midpoint, power).
    pub solimp: [f64; 5],
    /// Distance below which a contact has constraint rows (m; a dynamic pair adds its geoms').
    pub margin: f64,
    /// Distance beyond `margin` within which contacts are reported without rows (m).
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
            rgba: DEFAULT_GEOM_RGBA,
            material_rgba: None,
            contact: GeomContact::default(),
            fluid: None,
        }
    }
}

/// An equality constraint as written (MJCF `<equality>`), naming the objects it ties together;
/// compiled into [`Equality`](super::Equality).
#[derive(Clone, Debug, PartialEq)]
pub struct EqualitySpec {
    /// Its `name` (may be empty).
    pub name: String,
    /// What it ties together.
    pub kind: EqualitySpecKind,
    /// Whether it is active at the start (`active`).
    pub active: bool,
    /// `solref` of its rows (time constant, damping ratio).
    pub solref: [f64; 2],
    /// `solimp` of its rows (dmin, dmax, width, midpoint, power).
    pub solimp: [f64; 5],
    /// Where it is written.
    pub loc: SourceLoc,
}

/// What an [`EqualitySpec`] ties together, by name. `body2: None` is the world.
#[derive(Clone, Debug, PartialEq)]
pub enum EqualitySpecKind {
    /// `<connect body1 body2 anchor>`: `anchor` in body1 coordinates.
    ConnectBodies {
        /// The first body.
        body1: String,
        /// The second body (`None`: the world).
        body2: Option<String>,
        /// The point that must coincide, in body1 coordinates (m).
        anchor: [f64; 3],
    },
    /// `<connect site1 site2>`.
    ConnectSites {
        /// The first site.
        site1: String,
        /// The second site.
        site2: String,
    },
    /// `<weld body1 body2 anchor relpose torquescale>`: `anchor` in body2 coordinates, `relpose`
    /// the pose of body2's anchor frame in body1 (`None`: taken at `qpos0`).
    WeldBodies {
        /// The first body.
        body1: String,
        /// The second body (`None`: the world).
        body2: Option<String>,
        /// The anchor point in body2 coordinates (m).
        anchor: [f64; 3],
        /// Pose of body2's anchor frame in body1 (`None`: taken at `qpos0`).
        relpose: Option<Transform>,
        /// Weight of the rotational rows relative to the translational ones (0: position only).
        torquescale: f64,
    },
    /// `<weld site1 site2 torquescale>`.
    WeldSites {
        /// The first site.
        site1: String,
        /// The second site.
        site2: String,
        /// Weight of the rotational rows relative to the translational ones (0: position only).
        torquescale: f64,
    },
    /// `<joint joint1 joint2 polycoef>`.
    Joint {
        /// The constrained joint.
        joint1: String,
        /// The joint it follows (`None`: joint1 is held at `qpos0 + polycoef[0]`).
        joint2: Option<String>,
        /// Coefficients a₀…a₄ of the polynomial in joint2's displacement from `qpos0`.
        polycoef: [f64; 5],
    },
    /// `<tendon tendon1 tendon2 polycoef>`.
    Tendon {
        /// The constrained tendon.
        tendon1: String,
        /// The tendon it follows (`None`: tendon1's length is held at its `qpos0` value +
        /// `polycoef[0]`).
        tendon2: Option<String>,
        /// Coefficients a₀…a₄ of the polynomial in tendon2's length change from `qpos0`.
        polycoef: [f64; 5],
    },
}

/// A tendon as written (MJCF `<fixed>` or `<spatial>`); compiled into
/// [`Tendon`](super::Tendon).
#[derive(Clone, Debug, PartialEq)]
pub struct TendonSpec {
    /// Its `name` (may be empty).
    pub name: String,
    /// Fixed or spatial, with its joints or path.
    pub kind: TendonSpecKind,
    /// Length limits if limited (`limited`/`range`, resolved with `autolimits`).
    pub range: Option<[f64; 2]>,
    /// Soft-constraint parameters of its limit rows (`solreflimit`, `solimplimit`, `margin`).
    pub soft: SoftParams,
    /// Total actuator force range if limited (`actuatorfrclimited`/`actuatorfrcrange`).
    pub actuator_force_range: Option<[f64; 2]>,
    /// `stiffness` of the tendon's spring.
    pub stiffness: f64,
    /// `springlength` (one value: both bounds; `[-1, -1]`: the length at `qpos_spring`).
    pub spring_length: [f64; 2],
    /// `damping` along the tendon.
    pub damping: f64,
    /// `frictionloss` along the tendon.
    pub frictionloss: f64,
    /// Where it is written.
    pub loc: SourceLoc,
}

/// What a [`TendonSpec`] is made of, by name.
#[derive(Clone, Debug, PartialEq)]
pub enum TendonSpecKind {
    /// `<fixed>`: its `<joint joint coef>` children (joint name, coefficient, element).
    Fixed {
        /// (joint name, coefficient, element) per `<joint>` child.
        joints: Vec<(String, f64, SourceLoc)>,
    },
    /// `<spatial>`: its path as (element, name, side site): `site` and `geom` with the object's
    /// name (a geom with its `sidesite` if given), `pulley` with its divisor.
    Spatial {
        /// (element tag, name or divisor, `sidesite`) per path element, in file order.
        path: Vec<(String, String, Option<String>)>,
    },
}

/// What an actuator acts on, by name (MJCF `joint`, `jointinparent`, `tendon`, `site` with
/// `refsite`, `body`, `cranksite` with `slidersite`).
#[derive(Clone, Debug, PartialEq)]
pub enum TransmissionSpec {
    /// A joint (`joint`).
    Joint(String),
    /// A joint, the force applied in the parent frame (`jointinparent`; ball and free joints).
    JointInParent(String),
    /// A tendon (`tendon`).
    Tendon(String),
    /// A site (`site`), with an optional reference site (`refsite`).
    Site {
        /// The site the force acts at.
        site: String,
        /// The reference site (`refsite`), if any.
        refsite: Option<String>,
    },
    /// A body (`body`; adhesion actuators).
    Body(String),
    /// A slider-crank (`cranksite`, `slidersite`, `cranklength`).
    SliderCrank {
        /// The crank's site.
        cranksite: String,
        /// The slider's site.
        slidersite: String,
        /// Length of the connecting rod (m).
        cranklength: f64,
    },
}

/// An actuator as written, with its shortcut already expanded into MuJoCo's general form;
/// compiled into [`Actuator`](super::Actuator).
#[derive(Clone, Debug, PartialEq)]
pub struct ActuatorSpec {
    /// Its `name` (may be empty).
    pub name: String,
    /// The MJCF element it was written as.
    pub shortcut: ActuatorShortcut,
    /// What it acts on.
    pub transmission: TransmissionSpec,
    /// `gear` (moment arm scaling; 6 values for site and joint-in-parent transmissions).
    pub gear: [f64; 6],
    /// Activation dynamics (`dyntype`).
    pub dyntype: DynType,
    /// Gain (`gaintype`).
    pub gaintype: GainType,
    /// Bias (`biastype`).
    pub biastype: BiasType,
    /// Activation dynamics parameters (`dynprm`).
    pub dynprm: [f64; 10],
    /// Gain parameters (`gainprm`).
    pub gainprm: [f64; 10],
    /// Bias parameters (`biasprm`).
    pub biasprm: [f64; 10],
    /// Control range if limited (`ctrllimited`/`ctrlrange`, resolved with `autolimits`).
    pub ctrlrange: Option<[f64; 2]>,
    /// Force range if limited (`forcelimited`/`forcerange`).
    pub forcerange: Option<[f64; 2]>,
    /// Activation range if limited (`actlimited`/`actrange`).
    pub actrange: Option<[f64; 2]>,
    /// `actearly`: use the next activation in the force.
    pub actearly: bool,
    /// `inheritrange` (position and intvelocity servos): the control range (activation range for
    /// `intvelocity`) is this fraction of the target joint's or tendon's range, about its middle;
    /// set by the compile step, which knows the target.
    pub inheritrange: Option<f64>,
    /// Actuator-level passive damping (MuJoCo's `actuator_damping`): reflected through the
    /// transmission onto its dofs.
    pub damping: f64,
    /// Actuator-level armature (MuJoCo's `actuator_armature`): reflected through the transmission
    /// onto its dofs.
    pub armature: f64,
    /// `lengthrange` as written ([0, 0] when absent: the compiler computes it).
    pub lengthrange: [f64; 2],
    /// Its control history (`nsample` > 0, with `delay` and `interp`); the compiler sets `adr`.
    pub history: Option<super::ActuatorHistory>,
    /// Where it is written.
    pub loc: SourceLoc,
}

/// `<contact><pair>` as written; compiled into [`ContactPair`](super::ContactPair).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPairSpec {
    /// Its `name` (may be empty).
    pub name: String,
    /// The first geom (`geom1`).
    pub geom1: String,
    /// The second geom (`geom2`).
    pub geom2: String,
    /// 1 (frictionless), 3 (sliding), 4 (+ torsional), 6 (+ rolling).
    pub condim: u32,
    /// Sliding (2), torsional and rolling (2) friction coefficients.
    pub friction: [f64; 5],
    /// `solref` of the normal rows.
    pub solref: [f64; 2],
    /// `solref` of the friction rows of elliptic cones (`[0, 0]`: use `solref`, as MuJoCo does).
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

/// `<contact><exclude>` as written; compiled into [`ContactExclude`](super::ContactExclude).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactExcludeSpec {
    /// Its `name` (may be empty).
    pub name: String,
    /// The first body.
    pub body1: String,
    /// The second body.
    pub body2: String,
    /// Where it is written.
    pub loc: SourceLoc,
}
