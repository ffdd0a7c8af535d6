//! The immutable [`Model`] and the mutable [`Data`] workspace (docs/architecture.md, "Layers").
//!
//! A model is a kinematic tree of *bodies* in parent-before-child order; body 0 is the world and
//! every other body `b` hangs from its parent through exactly one movable joint (`joints[b - 1]`).
//! Fixed joints were fused by the compile step; every original link survives as a [`Frame`].

pub mod actuator;
pub mod collision_pairs;
pub mod contact;
mod data;
mod elements;
pub mod equality;
pub mod hfield;
mod joint;
pub mod lengthrange;
pub(crate) mod lengthrange_sim;
mod links;
pub mod options;
pub(crate) mod poses_stamp;
pub mod reset;
pub mod sleep;
pub mod spec;
pub mod tendon;
pub(crate) mod velocity_stamp;
pub mod warning;

pub use actuator::{Actuator, ActuatorHistory, Interp};
pub use collision_pairs::CollisionPair;
pub use contact::{Contact, ContactExclude, ContactPair};
pub use data::{Data, EfcState, EfcType, SLIP_VELOCITY};
pub use elements::{Element, Keyframe};
pub use equality::{Equality, EqualityKind};
pub use hfield::HeightField;
pub use joint::{axis_angle, HingeAxis, JointKind};
pub use links::{Links, SameFrame};
pub use options::{Flags, Options};
pub use tendon::{PathElement, Tendon, TendonKind, WrapShape};
pub use warning::{WarningStat, Warnings};

use crate::spatial::{Mat3, RigidInertia, Transform, Vec3};
use std::path::PathBuf;

/// Where an element came from, for error messages: file and 1-based line.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SourceLoc {
    /// The model file (or `<string>` for a model loaded from text).
    pub file: String,
    /// The 1-based line in it (0 when unknown).
    pub line: u32,
}

impl std::fmt::Display for SourceLoc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line > 0 {
            write!(f, "{}:{}", self.file, self.line)
        } else {
            write!(f, "{}", self.file)
        }
    }
}

/// A movable joint of the compiled tree.
#[derive(Clone, Debug)]
pub struct Joint {
    /// The joint's name in the file (a fixed URDF joint fused away has none here).
    pub name: String,
    /// Hinge, slide, ball, free or planar, with its axis.
    pub kind: JointKind,
    /// Index of the body this joint moves (its child).
    pub body: usize,
    /// Index of the parent body.
    pub parent: usize,
    /// First index of this joint's coordinates in q.
    pub qpos_adr: usize,
    /// First index of this joint's degrees of freedom in v.
    pub dof_adr: usize,
    /// Position limits `[lower, upper]` of a hinge or slide (of a ball joint: the larger entry is
    /// the half-angle of its cone), if limited; enforced by the constraint rows of both modes
    /// (unless `<flag limit>` is off).
    pub limits: Option<[f64; 2]>,
    /// The range `qfrc_actuator` is clamped to on this joint's dofs (MJCF `actuatorfrcrange`).
    pub actuator_force_range: Option<[f64; 2]>,
    /// URDF `<limit effort>` loaded with `--clamp-effort` (see [`Model::dof_effort_limit`]).
    pub effort_limit: Option<f64>,
    /// The joint's viscous damping coefficient as the file gives it (N·m·s/rad or N·s/m). What
    /// the passive stage applies, `−dof_damping ⊙ v`, is [`Model::dof_damping`]: this value plus
    /// the damping of the actuators on the joint (and zero with `<flag damper="disable">`).
    pub damping: f64,
    /// Dry friction of each of the joint's dofs (MJCF `frictionloss`): a friction-loss
    /// constraint row per dof bounds its force by this value.
    pub friction: f64,
    /// The joint's rotor armature as the file gives it. What M's diagonal gets is
    /// [`Model::dof_armature`] (MuJoCo's): this value plus the armature of the actuators on the
    /// joint.
    pub armature: f64,
    /// Spring stiffness and rest position (MuJoCo `stiffness`, `springref`), applied by
    /// `simulate` as `−stiffness·(q − spring_ref)` for hinge and slide joints.
    pub stiffness: f64,
    /// The spring's rest position (MuJoCo's `springref`), radians or metres.
    pub spring_ref: f64,
    /// Soft-constraint parameters of the limit and friction-loss rows (soft mode only).
    pub soft: spec::SoftParams,
    /// MJCF `actuatorgravcomp`: gravity compensation on this joint's dofs goes to
    /// `qfrc_actuator` instead of `qfrc_passive` (MuJoCo's `jnt_actgravcomp`).
    pub actuator_gravcomp: bool,
}

/// A rigid body of the compiled tree (the fused links included).
#[derive(Clone, Debug)]
pub struct Body {
    /// The body's name (the URDF link's or MJCF body's).
    pub name: String,
    /// Parent body (0 = world; the world's own parent is 0).
    pub parent: usize,
    /// Pose of this body's joint frame in the parent body frame (`x_parent_joint`).
    pub x_parent_joint: Transform,
    /// Spatial inertia in body coordinates, fused links included.
    pub inertia: RigidInertia,
}

impl Body {
    /// Mass of the body (fused links included).
    pub fn mass(&self) -> f64 {
        self.inertia.mass
    }
    /// Centre of mass in the body frame.
    pub fn com(&self) -> Vec3 {
        self.inertia.com()
    }
    /// Inertia tensor about the centre of mass, in body-frame axes.
    pub fn inertia_com(&self) -> Mat3 {
        self.inertia.i_com()
    }
}

/// What a named frame stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameKind {
    /// A URDF link or MJCF body (fused into its parent body or not).
    Link,
    /// An MJCF site.
    Site,
    /// An intermediate frame the MJCF loader makes for a joint anchor or the joints of a
    /// multi-joint body.
    Joint,
}

/// A named frame rigidly attached to a body: every URDF link and MJCF body is one (fused or not).
#[derive(Clone, Debug)]
pub struct Frame {
    /// The name of the link, body or site.
    pub name: String,
    /// Whether it is a link/body, a site or a joint-anchor frame.
    pub kind: FrameKind,
    /// The compiled body it is attached to (index in `Model::bodies`).
    pub body: usize,
    /// Pose of the frame in its body's frame (in its mocap body's frame when `mocap` is set).
    pub x_body_frame: Transform,
    /// The link's own mass properties in this frame's coordinates (before fusion; zero for
    /// sites and massless links).
    pub inertia: RigidInertia,
    /// The mocap body carrying the frame (index in `Data::mocap_pos`), if any: its world pose is
    /// then the mocap pose composed with `x_body_frame`.
    pub mocap: Option<usize>,
    /// An MJCF site's shape and size (MuJoCo's `site_type` and `site_size`: a sphere of radius
    /// 0.005 unless the file says otherwise), which the touch sensor's zone, `insidesite` and
    /// contact-sensor site filters use; None for frames that are not sites.
    pub site: Option<crate::mass::Primitive>,
}

/// A geometry of the model file: collision shape (when `collision`) and mass contribution.
#[derive(Clone, Debug, PartialEq)]
pub struct Geom {
    /// The geom's own name (MJCF), empty if unnamed.
    pub name: String,
    /// Name of the link or body it belongs to.
    pub link: String,
    /// The compiled body it is attached to (index in `Model::bodies`).
    pub body: usize,
    /// Pose of the geom frame in its body's frame (in its mocap body's frame when `mocap` is set).
    pub x_body_geom: Transform,
    /// The mocap body carrying the geom (index in `Data::mocap_pos`), if any.
    pub mocap: Option<usize>,
    /// The shape and its sizes (metres).
    pub shape: spec::Shape,
    /// Whether it takes part in collisions (URDF `<collision>`; MJCF contype/conaffinity ≠ 0).
    pub collision: bool,
    /// The mass it contributed to its body (0 if the body's inertia was given explicitly).
    pub mass: f64,
    /// Contact parameters (MuJoCo's defaults for URDF collision geoms).
    pub contact: spec::GeomContact,
    /// For a colliding mesh: its convex hull as MuJoCo's compiler builds it with qhull (the
    /// vertices in the geom frame, their edges, the face polygons: MuJoCo's `mesh_graph` and
    /// `mesh_polyvert`; [`crate::collision::mesh_graph`]). MuJoCo collides meshes by their hulls;
    /// [`Geom::hull`] reads the vertices.
    pub hull_graph: Option<std::sync::Arc<crate::collision::mesh_graph::MeshGraph>>,
    /// MJCF `group` (MuJoCo's `geom_group`; 0 by default): ray casting can select groups.
    pub group: i32,
    /// MJCF `rgba` (MuJoCo's `geom_rgba`; 0.5 0.5 0.5 1 by default): ray casting skips a geom
    /// whose alpha is 0 when it has no material.
    pub rgba: [f32; 4],
    /// The `rgba` of the geom's material, if it has one (MuJoCo's `mat_rgba`): ray casting then
    /// skips the geom when that alpha is 0, whatever its own.
    pub material_rgba: Option<[f32; 4]>,
    /// For any mesh geom (visual ones too): its file's triangles and convex hull, read on first
    /// use by ray casting and geom distances ([`crate::collision::GeomMesh`]); geoms using the
    /// same file and scale share one.
    pub mesh: Option<std::sync::Arc<crate::collision::GeomMesh>>,
    /// `fluidshape="ellipsoid"` with its five `fluidcoef` (MuJoCo's `geom_fluid[1..6]`), if set:
    /// the geom's body then feels the ellipsoid fluid model instead of the inertia-box one.
    pub fluid: Option<[f64; 5]>,
}

impl Geom {
    /// For a colliding mesh, the vertices of its convex hull in the geom frame (qhull's order,
    /// where MuJoCo's collision reads them); None for primitives and non-colliding meshes.
    pub fn hull(&self) -> Option<&[Vec3]> {
        self.hull_graph.as_deref().map(|g| &g.vertices[..])
    }
}

/// The compiled, immutable model. Build it with a loader (e.g. [`crate::io::load`]) or by
/// compiling a [`spec::ModelSpec`].
#[derive(Clone, Debug)]
pub struct Model {
    /// The model's name (MJCF `<mujoco model>`, URDF `<robot name>`).
    pub name: String,
    /// The file it was loaded from (None for a model compiled from a spec or text).
    pub source: Option<PathBuf>,
    /// Gravity acceleration in the world frame (m/s²).
    pub gravity: Vec3,
    /// Bodies, world first, parents before children.
    pub bodies: Vec<Body>,
    /// For each body, the first body of the file body it belongs to: an MJCF body with several
    /// joints compiles to a chain of bodies, one per joint, which MuJoCo treats as one body
    /// (collision filtering); every other body is its own root.
    pub body_root: Vec<usize>,
    /// MuJoCo's bodies (the file's bodies, world first) over the compiled ones: their frames,
    /// parents, and the body of every frame and geom ([`Links`]).
    pub links: Links,
    /// Movable joints: `joints[b - 1]` moves body `b`.
    pub joints: Vec<Joint>,
    /// Named frames: every link or body (fused or not), site and joint anchor.
    pub frames: Vec<Frame>,
    /// Geometries, in file order (collision shapes and mass contributions).
    pub geoms: Vec<Geom>,
    /// Number of generalized coordinates (length of `qpos`).
    pub nq: usize,
    /// Number of degrees of freedom (length of `qvel`).
    pub nv: usize,
    /// For each degree of freedom, the previous degree of freedom on the path to the root
    /// (Featherstone's λ for the tree-sparse factorization, RBDA §6.3), or `usize::MAX`.
    pub dof_parent: Vec<usize>,
    /// For each degree of freedom k, the first index s of the run s..=k of consecutive ancestors
    /// (λ(j) = j − 1 for s < j ≤ k) that ends at k: the ancestor chain of k is such runs, each a
    /// contiguous slice (the LᵀDL factorization walks it run by run). See [`dof_run_starts`].
    pub dof_run_start: Vec<usize>,
    /// For each degree of freedom, the first dof of its kinematic tree (the root of its ancestor
    /// chain): the chain lies in `dof_tree_start[k]..=k`. See [`dof_tree_starts`].
    pub dof_tree_start: Vec<usize>,
    /// For each degree of freedom, the body it moves.
    pub dof_body: Vec<usize>,
    /// For each body, the coordinate axis its hinge turns about ([`JointKind::hinge_axis`];
    /// [`HingeAxis::Other`] for the world and every other joint), for the kernels' dispatch.
    /// Derived when the model is compiled, as `dof_parent` is: code that edits a joint's axis
    /// afterwards updates it too.
    pub hinge_axis: Vec<HingeAxis>,
    /// For each body, whether its joint placement has no rotation (`x_parent_joint.rot` exactly
    /// the identity, as on most MJCF bodies and URDF joints without `rpy`): a hinge's pose is then
    /// its parent's with two columns turned, no 3×3 product (`kinematics::hinge_world_pose`).
    /// Derived when the model is compiled, like [`hinge_axis`](Self::hinge_axis).
    pub placement_unrotated: Vec<bool>,
    /// Armature per degree of freedom, the one M uses (the joint's plus its actuators'; MuJoCo's
    /// `dof_armature`).
    pub dof_armature: Vec<f64>,
    /// Viscous damping per degree of freedom, the one the passive stage and the implicit
    /// integrators use (the joint's plus its actuators'; MuJoCo's `dof_damping`).
    pub dof_damping: Vec<f64>,
    /// The bound on |actuator + applied| generalized force per degree of freedom: a URDF
    /// `<limit effort>` loaded with `--clamp-effort`, else +∞.
    pub dof_effort_limit: Vec<f64>,
    /// Joint springs of hinge and slide joints (`−stiffness·(q − rest)`), empty when the file
    /// disables springs (`<flag spring="disable">`).
    pub springs: Vec<Spring>,
    /// Reference configuration (MuJoCo's `qpos0`: hinge/slide `ref`, a free body's pose in the
    /// file, identity quaternions): the default initial state.
    pub qpos0: Vec<f64>,
    /// Simulation options from the file.
    pub options: Options,
    /// The initial world pose of each mocap body (MJCF `mocap="true"`, in file order, MuJoCo's
    /// `body_mocapid` order): what `Data::new` and `reset` set `mocap_pos` and `mocap_quat` to.
    pub mocap_pose0: Vec<Transform>,
    /// Named initial states (MJCF `<keyframe>`).
    pub keyframes: Vec<Keyframe>,
    /// Equality constraints and URDF mimic couplings (simulated by the constraint layer).
    pub equalities: Vec<Equality>,
    /// Tendons in MuJoCo's order (fixed and spatial, simulated by [`crate::tendon`]).
    pub tendons: Vec<Tendon>,
    /// Actuators in MuJoCo's order (`ctrl` layout).
    pub actuators: Vec<Actuator>,
    /// Sensors in MuJoCo's order (MJCF `<sensor>`), each with its slice of `Data::sensordata`
    /// ([`crate::sensor`]).
    pub sensors: Vec<crate::sensor::Sensor>,
    /// The length of `Data::sensordata` (MuJoCo's `nsensordata`).
    pub nsensordata: usize,
    /// Explicit contact pairs (`<contact><pair>`).
    pub contact_pairs: Vec<ContactPair>,
    /// Body pairs excluded from contact (`<contact><exclude>`).
    pub contact_excludes: Vec<ContactExclude>,
    /// Candidate geom pairs for collision detection, fixed at compile time with their combined
    /// contact parameters ([`collision_pairs::candidate_pairs`]).
    pub collision_pairs: Vec<CollisionPair>,
    /// Elements parsed and kept but not simulated (sensors, …; listed by `lagrange info`).
    pub elements: Vec<Element>,
    /// What the loader ignored or could not interpret, each with file:line.
    pub warnings: Vec<String>,
    /// What is derived from the elements above once, when the model is compiled: the stages
    /// [`forward`](crate::forward::forward) runs, the constraint mode and its solver, the
    /// constraint rows' and collision's fixed structure, the soft mode's inverse weights, the
    /// actuators' resolved bias terms. Code that edits the elements or options afterwards calls
    /// [`rebuild_plan`](Self::rebuild_plan).
    pub plan: crate::forward::Plan,
    /// Gravity compensation (MJCF body `gravcomp`), one entry per compiled body that has any
    /// ([`crate::dynamics::gravcomp`]).
    pub gravcomp: Vec<GravComp>,
    /// MuJoCo's kinematic trees, their sleep policies and the dofs' lengths, for sleeping
    /// islands (`<flag sleep>`; [`sleep::SleepModel`]).
    pub sleep: sleep::SleepModel,
}

/// The gravity compensation of one compiled body: the links fused into it that have a `gravcomp`
/// add up to one force −`mass` · g at `com` (their weights are parallel, so their sum acts at the
/// compensated-mass-weighted centroid).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GravComp {
    /// The compiled body (index in `Model::bodies`).
    pub body: usize,
    /// Σ gravcomp · mass over the fused links (kg).
    pub mass: f64,
    /// The centroid of the compensated masses in the body frame.
    pub com: Vec3,
}

/// A linear spring on a one-dof joint: generalized force `−stiffness·(q[qpos_adr] − rest)` on
/// degree of freedom `dof_adr`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    /// Index of the joint's coordinate in q.
    pub qpos_adr: usize,
    /// Index of the joint's degree of freedom in v.
    pub dof_adr: usize,
    /// Stiffness k (N·m/rad or N/m).
    pub stiffness: f64,
    /// Rest position (rad or m).
    pub rest: f64,
}

/// Marker for "no parent degree of freedom".
pub const NO_DOF: usize = usize::MAX;

impl Model {
    /// Number of actuator activation states (MuJoCo's `na`): one per actuator with activation
    /// dynamics, in actuator order.
    pub fn na(&self) -> usize {
        self.actuators.iter().map(|a| a.actnum()).sum()
    }
    /// Length of `Data::history` (MuJoCo's `nhistory`): 2 + 2·nsample per actuator with a
    /// control history.
    pub fn nhistory(&self) -> usize {
        self.actuators.iter().filter_map(|a| a.history.as_ref()).map(|h| 2 + 2 * h.nsample).sum()
    }
    /// Number of bodies including the world.
    pub fn nbody(&self) -> usize {
        self.bodies.len()
    }
    /// The joint moving body `b` (b ≥ 1).
    #[inline]
    pub fn joint_of(&self, b: usize) -> &Joint {
        &self.joints[b - 1]
    }
    /// Total mass of the moving bodies (body 0, the world with the links welded to it, excluded,
    /// as in MuJoCo and Pinocchio).
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().skip(1).map(|b| b.inertia.mass).sum()
    }
    /// Index of a frame by name: a link or body if one has the name, else a site or joint-anchor
    /// frame (MJCF keeps bodies and sites in separate namespaces; see [`Model::site_id`]).
    pub fn frame_id(&self, name: &str) -> Option<usize> {
        self.frames
            .iter()
            .position(|f| f.name == name && f.kind == FrameKind::Link)
            .or_else(|| self.frames.iter().position(|f| f.name == name))
    }
    /// Index of the frame of an MJCF site by name.
    pub fn site_id(&self, name: &str) -> Option<usize> {
        self.frames.iter().position(|f| f.name == name && f.kind == FrameKind::Site)
    }
    /// Index of a joint by name.
    pub fn joint_id(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }
    /// Index of a keyframe by name.
    pub fn keyframe_id(&self, name: &str) -> Option<usize> {
        self.keyframes.iter().position(|k| k.name == name)
    }
    /// Whether any hinge or slide joint has a simulated spring.
    pub fn has_springs(&self) -> bool {
        !self.springs.is_empty()
    }
    /// Potential energy stored in the joint springs, Σ ½ k (q − rest)².
    ///
    /// # Errors
    /// [`InputError::Length`](crate::error::InputError) when q is not nq long.
    pub fn spring_energy(&self, q: &[f64]) -> Result<f64, crate::error::InputError> {
        crate::error::check::q("Model::spring_energy", self, q)?;
        Ok(self.spring_energy_unchecked(q))
    }

    /// [`spring_energy`](Self::spring_energy) without the length check.
    pub(crate) fn spring_energy_unchecked(&self, q: &[f64]) -> f64 {
        self.springs.iter().map(|s| 0.5 * s.stiffness * (q[s.qpos_adr] - s.rest).powi(2)).sum()
    }
    /// Neutral configuration (zeros, identity quaternions).
    pub fn neutral(&self) -> Vec<f64> {
        let mut q = vec![0.0; self.nq];
        for j in &self.joints {
            j.kind.neutral(&mut q[j.qpos_adr..j.qpos_adr + j.kind.nq()]);
        }
        q
    }
    /// Upper bound on the number of contacts one collision pass can report: the sum of each
    /// candidate pair's bound (MuJoCo's per-pair limits). Nothing is dropped below it: `Data`
    /// reserves room for up to [`INITIAL_CONTACTS`] contacts and its contact buffers grow when a
    /// pass finds more than every earlier pass (as MuJoCo's arena, without its fixed size).
    pub fn max_contacts(&self) -> usize {
        self.collision_pairs.iter().map(|p| p.max_contacts).sum::<usize>()
    }

    /// The most contacts one collision pass keeps: a memory limit on the constraint rows they
    /// make (up to 6 each), whose dense Jacobian and per-row buffers take rows × (nv + 20)
    /// numbers, at most [`CONTACT_MEMORY`] bytes, as MuJoCo's arena bounds its contacts. Where a
    /// solver forms a matrix of rows × rows (the exact mode's Delassus matrix, PGS's and the
    /// no-slip pass's J M⁻¹ Jᵀ), that matrix must fit too, and at most [`MAX_CONTACTS`] are
    /// kept; the soft mode's Newton and CG work on J and M only and keep up to
    /// [`MAX_SOFT_CONTACTS`], as many as keep one Newton iteration's Hessian work bounded (rows ×
    /// (2 · [`Model::max_dof_depth`])² below about 5·10⁸). Never fewer than [`INITIAL_CONTACTS`]. Contacts beyond it are
    /// dropped, counted in [`Data::contacts_dropped`] and raise the `contact_full` warning
    /// (`Data::warnings`, with the count and the time of the pass). [`Options::max_contacts`],
    /// when set, replaces this default, within the memory bounds alone.
    pub fn contact_budget(&self) -> usize {
        let numbers = (CONTACT_MEMORY / 8) as f64;
        // Each row: its J row (nv numbers) and about 20 per-row numbers (efc_* vectors).
        let by_jacobian = numbers / (6.0 * (self.nv + 20) as f64);
        let dense_rows = self.dense_contact_rows();
        if let Some(most) = self.options.max_contacts {
            // One rows × rows matrix within the memory too, where a solver forms one.
            let by_memory = if dense_rows { by_jacobian.min(numbers.sqrt() / 6.0) } else { by_jacobian };
            return most.min(by_memory as usize);
        }
        // Newton's Hessian takes about (nonzeros per row)² per row and iteration; a row touches at
        // most the ancestor dofs of its two bodies.
        let depth = self.plan.max_dof_depth.max(1) as f64;
        let by_work = SOFT_WORK / (6.0 * (2.0 * depth).powi(2));
        let (by_solver, most) =
            if dense_rows { (numbers.sqrt() / 6.0, MAX_CONTACTS) } else { (by_work, MAX_SOFT_CONTACTS) };
        (by_jacobian.min(by_solver) as usize).clamp(INITIAL_CONTACTS, most)
    }

    /// Whether a solver of this model forms a matrix of rows × rows (the exact mode's Delassus
    /// matrix, PGS's and the no-slip pass's J M⁻¹ Jᵀ), which bounds the contacts it keeps.
    pub fn dense_contact_rows(&self) -> bool {
        self.plan.mode() == crate::constraint::ConstraintMode::Exact
            || self.options.solver == options::Solver::Pgs
            || self.options.noslip_iterations > 0
    }

    /// The most dofs on one chain from a root (the longest ancestor chain of a dof, itself
    /// included; 0 without dofs).
    /// O(nv · depth); the plan keeps it (`Plan::max_dof_depth`) for the contact budget.
    pub fn max_dof_depth(&self) -> usize {
        (0..self.nv)
            .map(|k| {
                let (mut depth, mut d) = (1, k);
                while self.dof_parent[d] != NO_DOF {
                    d = self.dof_parent[d];
                    depth += 1;
                }
                depth
            })
            .max()
            .unwrap_or(0)
    }

    /// Whether any degree of freedom has viscous damping (the passive stage's damping term).
    pub fn has_damping(&self) -> bool {
        self.dof_damping.iter().any(|&d| d != 0.0)
    }

    /// Solves the constraints in `mode` from now on: the plan is rebuilt for it, with the mode's
    /// default drift correction (projection in exact mode, none in soft mode) and the exact
    /// solver's iteration settings kept. MJCF models default to soft, URDF models to exact.
    pub fn set_constraint_mode(&mut self, mode: crate::constraint::ConstraintMode) {
        let settings = self.plan.solver.exact().map(|e| e.settings);
        self.plan = crate::forward::Plan::new(self, Some(mode));
        if let (Some(settings), Some(e)) = (settings, self.plan.solver.exact_mut()) {
            e.settings = settings;
        }
    }

    /// Rebuilds [`plan`](Self::plan) after the elements or options were edited (a joint's limit,
    /// `<flag>`s, equality constraints, …), keeping the constraint mode, its reason, the drift
    /// correction and the solver settings.
    pub fn rebuild_plan(&mut self) {
        let old = std::mem::take(&mut self.plan);
        self.plan = crate::forward::Plan::new(self, Some(old.mode()));
        self.plan.mode_reason = old.mode_reason;
        if let (Some(old), Some(e)) = (old.solver.exact(), self.plan.solver.exact_mut()) {
            *e = old.clone();
        }
    }
}

/// [`Model::dof_run_start`] of a λ table: s(k) = s(k − 1) if λ(k) = k − 1, else k.
pub fn dof_run_starts(dof_parent: &[usize]) -> Vec<usize> {
    let mut start: Vec<usize> = (0..dof_parent.len()).collect();
    for k in 1..dof_parent.len() {
        if dof_parent[k] == k - 1 {
            start[k] = start[k - 1];
        }
    }
    start
}

/// [`Model::dof_tree_start`] from `dof_parent`: each dof's root ancestor (parents come first).
pub fn dof_tree_starts(dof_parent: &[usize]) -> Vec<usize> {
    let mut start: Vec<usize> = (0..dof_parent.len()).collect();
    for k in 0..dof_parent.len() {
        if let Some(&p) = dof_parent.get(k).filter(|&&p| p < k) {
            start[k] = start[p];
        }
    }
    start
}

/// How many contacts `Data` reserves room for before the first pass (fewer if the model's
/// [`Model::max_contacts`] is smaller); more grow the buffers once, when first needed.
pub const INITIAL_CONTACTS: usize = 500;

/// The most contacts one collision pass keeps, whatever the memory allows, for the solvers with
/// dense parts (PGS's and no-slip's J M⁻¹ Jᵀ, the exact Delassus matrix), which grow with the
/// square of the rows, so more contacts cost seconds per step (the fuzzer found 2000 too many for
/// no-slip; sparse dual solvers would raise it; see docs/constraints.md).
pub const MAX_CONTACTS: usize = 500;

/// The most contacts one collision pass keeps for the soft mode's Newton and CG solvers (linear
/// in the rows): a bound on a runaway scene; [`Model::contact_budget`]'s memory and work limits
/// are usually lower.
pub const MAX_SOFT_CONTACTS: usize = 100_000;

/// The work one soft Newton iteration's Hessian may take from contact rows (multiply-adds,
/// about 0.2 s): the contact budget keeps rows × (2 · max dof depth)² below it, so that a
/// 400-sphere bin keeps every contact and a chain of hundreds of links stacked in one place
/// keeps [`INITIAL_CONTACTS`].
const SOFT_WORK: f64 = (1u64 << 29) as f64;

/// The memory the rows of one collision pass's contacts may take (bytes; see
/// [`Model::contact_budget`]).
pub const CONTACT_MEMORY: usize = 1 << 30;

/// `q ← q ⊕ v·dt` for the whole configuration (MuJoCo's `mj_integratePos`).
///
/// # Errors
/// [`InputError::Length`](crate::error::InputError) when q is not nq long or v not nv long.
pub fn integrate_configuration(
    model: &Model,
    q: &mut [f64],
    v: &[f64],
    dt: f64,
) -> Result<(), crate::error::InputError> {
    crate::error::check::q("integrate_configuration", model, q)?;
    crate::error::check::v("integrate_configuration", "v", model, v)?;
    integrate_configuration_unchecked(model, q, v, dt);
    Ok(())
}

/// [`integrate_configuration`] without the length checks.
pub(crate) fn integrate_configuration_unchecked(model: &Model, q: &mut [f64], v: &[f64], dt: f64) {
    for j in &model.joints {
        let (qa, va) = (j.qpos_adr, j.dof_adr);
        j.kind.integrate(&mut q[qa..qa + j.kind.nq()], &v[va..va + j.kind.nv()], dt);
    }
}

/// θ̇ = dexp⁻¹(θ) v for the whole configuration (length nv): the rate of the tangent
/// increment θ of `q0 ⊕ θ` when the joint velocity at that configuration is `v`
/// (`JointKind::dexp_inv`); the Runge–Kutta–Munthe-Kaas stages of
/// the integrators use it.
///
/// # Errors
/// [`InputError::Length`](crate::error::InputError) when theta, v or out is not nv long.
pub fn dexp_inv_configuration(
    model: &Model,
    theta: &[f64],
    v: &[f64],
    out: &mut [f64],
) -> Result<(), crate::error::InputError> {
    crate::error::check::v("dexp_inv_configuration", "theta", model, theta)?;
    crate::error::check::v("dexp_inv_configuration", "v", model, v)?;
    crate::error::check::v("dexp_inv_configuration", "out", model, out)?;
    dexp_inv_configuration_unchecked(model, theta, v, out);
    Ok(())
}

/// [`dexp_inv_configuration`] without the length checks.
pub(crate) fn dexp_inv_configuration_unchecked(model: &Model, theta: &[f64], v: &[f64], out: &mut [f64]) {
    for j in &model.joints {
        let (va, nv) = (j.dof_adr, j.kind.nv());
        j.kind.dexp_inv(&theta[va..va + nv], &v[va..va + nv], &mut out[va..va + nv]);
    }
}

/// The tangent `v` (length nv) with `q0 ⊕ v = q1`.
///
/// # Errors
/// [`InputError::Length`](crate::error::InputError) when q0 or q1 is not nq long or v not nv
/// long.
pub fn difference_configuration(
    model: &Model,
    q0: &[f64],
    q1: &[f64],
    v: &mut [f64],
) -> Result<(), crate::error::InputError> {
    crate::error::InputError::check_len("difference_configuration", "q0", q0.len(), model.nq, "nq")?;
    crate::error::InputError::check_len("difference_configuration", "q1", q1.len(), model.nq, "nq")?;
    crate::error::check::v("difference_configuration", "v", model, v)?;
    difference_configuration_unchecked(model, q0, q1, v);
    Ok(())
}

/// [`difference_configuration`] without the length checks.
pub(crate) fn difference_configuration_unchecked(model: &Model, q0: &[f64], q1: &[f64], v: &mut [f64]) {
    for j in &model.joints {
        let (qa, va) = (j.qpos_adr, j.dof_adr);
        let (nq, nv) = (j.kind.nq(), j.kind.nv());
        j.kind.difference(&q0[qa..qa + nq], &q1[qa..qa + nq], &mut v[va..va + nv]);
    }
}
