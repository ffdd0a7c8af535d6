//! The mutable workspace of the algorithms, allocated once per model.
//!
//! Two kinds of buffers live here: the kernels' own (poses, velocities, composite and
//! articulated inertias, `tau` of RNEA, `aba_qacc` of ABA), and the named buffers of the staged
//! `forward` pipeline, which carry MuJoCo's names and meanings (MuJoCo documentation,
//! "Computation → Forward dynamics"): `qfrc_bias`, `qfrc_passive`, `qfrc_actuator`,
//! `qfrc_applied`, `qfrc_smooth`, `qacc_smooth`, `qfrc_constraint`, `qacc`, and the constraint rows
//! `efc_*`. Each buffer keeps one meaning.

use super::{Contact, FrameKind, JointKind, Model};
use crate::constraint::soft::SoftWork;
use crate::constraint::{ExactWork, RowLifecycle};
use crate::dynamics::RnePost;
use crate::integrate::StepperSlot;
use crate::spatial::{quat_to_matrix, ArticulatedInertia, Force, Motion, RigidInertia, Transform, Vec3};
use nalgebra::{DMatrix, DVector, Matrix6};

/// Contacts whose rows `Data::new` makes room for; a scene with more touching contacts grows the
/// row buffers once ([`Data::reserve_rows`]) — the dense Delassus matrix of every candidate pair's
/// worst case would not fit in memory for a model with thousands of pairs.
const INITIAL_CONTACT_ROWS: usize = 64;

/// Slip speed (m/s, rad/s) above which a contact or a dof with friction loss counts as sliding.
pub const SLIP_VELOCITY: f64 = 1e-9;

/// The kind of a constraint row (MuJoCo's `mjtConstraint`, for the kinds simulated so far).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EfcType {
    /// A bilateral row of an equality constraint or mimic coupling: J q̈ + J̇v = 0, λ free.
    Equality,
    /// Dry friction of one degree of freedom (`frictionloss`): |λ| ≤ the joint's friction loss,
    /// opposing the dof's velocity (MuJoCo's `mjCNSTR_FRICTION_DOF`).
    FrictionDof,
    /// A joint limit (unilateral): the row's acceleration w ≥ 0, λ ≥ 0, w λ = 0.
    LimitJoint,
    /// Soft mode: dry friction along a tendon (`frictionloss`): |λ| ≤ the tendon's friction
    /// loss, J = the tendon's Jacobian (MuJoCo's `mjCNSTR_FRICTION_TENDON`).
    FrictionTendon,
    /// The normal row of a frictionless contact (condim 1), unilateral like a limit.
    ContactFrictionless,
    /// The rows of a frictional contact (condim 3, 4 or 6): the normal row first (unilateral),
    /// then the friction rows, whose forces lie in the elliptic Coulomb cone
    /// Σ (λ_i / μ_i)² ≤ λ_n² (MuJoCo's `mjCNSTR_CONTACT_ELLIPTIC`).
    ContactElliptic,
    /// Soft mode: a tendon's length limit (MuJoCo's `mjCNSTR_LIMIT_TENDON`), unilateral.
    LimitTendon,
    /// Soft mode, pyramidal cone (MuJoCo's `mjCNSTR_CONTACT_PYRAMIDAL`): a contact of dimension
    /// d gives 2(d − 1) rows J_n ± μ_i J_i, each with a force ≥ 0 (MuJoCo documentation,
    /// "Computation → Constraint model → Contact").
    ContactPyramidal,
}

impl EfcType {
    /// Whether the row's force has a sign (λ ≥ 0) — true for the rows of limits and contacts
    /// (use [`Data::efc_is_normal`] to tell a contact's normal row from its friction rows).
    pub fn is_unilateral(self) -> bool {
        matches!(
            self,
            EfcType::LimitJoint
                | EfcType::LimitTendon
                | EfcType::ContactFrictionless
                | EfcType::ContactElliptic
                | EfcType::ContactPyramidal
        )
    }

    /// MuJoCo's name of the row kind (`mjtConstraint` without the prefix, lower case).
    pub fn name(self) -> &'static str {
        match self {
            EfcType::Equality => "equality",
            EfcType::FrictionDof => "friction_dof",
            EfcType::FrictionTendon => "friction_tendon",
            EfcType::LimitJoint => "limit_joint",
            EfcType::ContactFrictionless => "contact_frictionless",
            EfcType::ContactElliptic => "contact_elliptic",
            EfcType::ContactPyramidal => "contact_pyramidal",
            EfcType::LimitTendon => "limit_tendon",
        }
    }

    /// Whether the row belongs to a contact.
    pub fn is_contact(self) -> bool {
        matches!(self, EfcType::ContactFrictionless | EfcType::ContactElliptic | EfcType::ContactPyramidal)
    }
}

/// The state of a row in the soft cost (MuJoCo's `mjtConstraintState`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EfcState {
    /// No force: a unilateral row that is not pressed, or an elliptic cone's top zone.
    #[default]
    Satisfied,
    /// Quadratic cost ½ D (J a − aref)²: equality rows, pressed unilateral rows, friction within
    /// its bound, an elliptic cone's bottom zone.
    Quadratic,
    /// Friction loss at its bound, force +frictionloss.
    LinearNeg,
    /// Friction loss at its bound, force −frictionloss.
    LinearPos,
    /// An elliptic contact on the surface of its cone (middle zone).
    Cone,
}

impl EfcState {
    /// MuJoCo's name of the state (`mjtConstraintState` without the prefix, lower case).
    pub fn name(self) -> &'static str {
        match self {
            EfcState::Satisfied => "satisfied",
            EfcState::Quadratic => "quadratic",
            EfcState::LinearNeg => "linearneg",
            EfcState::LinearPos => "linearpos",
            EfcState::Cone => "cone",
        }
    }
}

/// The simulation state and every buffer the algorithms write into (MuJoCo's `mjData`).
/// `Data::new(&model)` allocates them all; afterwards the algorithms allocate nothing. Per-body
/// arrays are indexed by body (0 = world), per-dof arrays by degree of freedom.
///
/// The state is `time`, `qpos`, `qvel`, `act`, and the inputs `ctrl`, `qfrc_applied` and
/// `xfrc_applied`: a
/// stepper advances it, [`forward`](crate::forward::forward) reads it. Everything else is an
/// output of the stages or scratch.
#[derive(Clone, Debug)]
pub struct Data {
    // --- state (MuJoCo's names) ---
    /// Simulation time (s).
    pub time: f64,
    /// Generalized coordinates, nq values in MuJoCo's layout (a free joint's position then its
    /// unit quaternion w x y z; a ball joint's quaternion; one value per hinge and slide).
    pub qpos: DVector<f64>,
    /// Generalized velocities, nv values (a free joint's linear velocity in the world frame, then
    /// its angular velocity in the body frame; a ball joint's body-frame angular velocity).
    pub qvel: DVector<f64>,

    /// Pose of each body frame in its parent body frame (joint placement · joint transform).
    pub x_parent_body: Vec<Transform>,
    /// Pose of each body frame in the world.
    pub x_world_body: Vec<Transform>,
    /// Pose of each named frame in the world (filled by `forward_kinematics`).
    pub x_world_frame: Vec<Transform>,
    /// Motion subspace column of each degree of freedom, in its body's coordinates.
    pub s_body: Vec<Motion>,
    /// Motion subspace column of each degree of freedom in world axes about its tree's origin
    /// (`p_world_tree`; CRBA's; not formed for a floating base, whose block of M CRBA takes from
    /// the composite inertia directly).
    pub s_world: Vec<Motion>,
    /// For each body, the world position of its tree's origin, the origin of its root body (the
    /// ancestor whose parent is the world): CRBA's reference point, as MuJoCo's `subtree_com` of
    /// the root is `mj_crb`'s (a world-origin reference loses digits with distance).
    pub p_world_tree: Vec<Vec3>,
    /// CRBA's body poses about their tree's origin (world axes; `p_world_tree` apart), kept apart
    /// from `x_world_body` so that the world poses of the same configuration survive it.
    pub(crate) x_tree_body: Vec<Transform>,
    /// The configuration `x_parent_body`, `x_world_body` and `s_body` were last formed at, while
    /// they hold (one pose pass per evaluation).
    pub(crate) poses_stamp: super::poses_stamp::PosesStamp,
    /// The state (q, v) `v_body` was last formed at by RNEA or ABA, while it holds.
    pub(crate) velocity_stamp: super::velocity_stamp::VelocityStamp,
    /// Spatial velocity of each body, body coordinates.
    pub v_body: Vec<Motion>,
    /// Spatial acceleration of each body (including the gravity offset in RNEA/ABA), body coords.
    pub a_body: Vec<Motion>,
    /// Velocity-product acceleration `c_J + v × v_J` of each body (ABA), body coordinates.
    pub c_body: Vec<Motion>,
    /// Net spatial force on each body (RNEA) or articulated bias force (ABA), body coordinates.
    pub f_body: Vec<Force>,
    /// Composite rigid-body inertia of each subtree (CRBA), world axes about the tree's origin
    /// (`p_world_tree`).
    pub i_composite: Vec<RigidInertia>,
    /// Articulated-body inertia of each body (ABA), body coordinates.
    pub i_articulated: Vec<ArticulatedInertia>,
    /// `U = Iᴬ S` per degree of freedom (ABA).
    pub u_dof: Vec<Force>,
    /// `u = τ − Sᵀ pᴬ` per degree of freedom (ABA).
    pub u_tau: DVector<f64>,
    /// `D⁻¹ = (Sᵀ U)⁻¹` of each body's joint, top-left nv×nv block (ABA).
    pub d_inv: Vec<Matrix6<f64>>,
    /// Joint-space inertia matrix M(q) (CRBA), armature included. CRBA writes the entries of
    /// dofs on one ancestor chain; the others are zero from `Data::new` and stay so.
    pub mass_matrix: DMatrix<f64>,
    /// Tree-sparse LᵀDL factor of M (RBDA §6.3): D on the diagonal, row k of the unit L in
    /// column k (`L[k][j]` at (j, k), j an ancestor of k); other entries are not used.
    pub mass_factor: DMatrix<f64>,
    /// Generalized forces from RNEA (the kernel's output).
    pub tau: DVector<f64>,
    /// Generalized accelerations from ABA (the kernel's output).
    pub aba_qacc: DVector<f64>,
    /// Scratch vector of length nv.
    pub scratch_v: DVector<f64>,
    /// Spatial acceleration of each body at q̈ = 0 without gravity (the velocity-product part of
    /// the acceleration, for J̇v), body coordinates.
    pub a_bias_body: Vec<Motion>,

    // --- forward pipeline (MuJoCo's names) ---
    /// Controls, one per actuator (MuJoCo's `ctrl`).
    pub ctrl: DVector<f64>,
    /// Actuator activations, one per activation state (MuJoCo's `act`, `na` values in actuator
    /// order): part of the state, advanced by the steppers from `act_dot`.
    pub act: DVector<f64>,
    /// Time derivative of `act` (MuJoCo's `act_dot`), written by the actuation stage.
    pub act_dot: DVector<f64>,
    /// The actuators' control histories (MuJoCo's `history`, `nhistory` values in MuJoCo's
    /// layout; `forward::history`): part of the state, like `act`. Each step records the
    /// controls at the time it starts; actuators with a `delay` read their control from here.
    /// Set by `Data::new` and `reset` to MuJoCo's initial buffers (zero controls at −n·h … −h).
    pub history: DVector<f64>,
    /// Generalized forces applied by the user (MuJoCo's `qfrc_applied`).
    pub qfrc_applied: DVector<f64>,
    /// Cartesian wrenches applied by the user to bodies (MuJoCo's `xfrc_applied`): one per
    /// MuJoCo body (the model's frames of kind `Link`, world first, in file order), force then
    /// torque in world axes, the force acting at the body's own centre of mass. Honoured by
    /// `forward` and every integrator.
    pub xfrc_applied: Vec<[f64; 6]>,
    /// World position of each mocap body (MuJoCo's `mocap_pos`, one per `mocap="true"` body in
    /// file order): an input, like `ctrl`, that poses the body, its geoms and sites, and the
    /// equality constraints anchored on it. Starts at the body's pose in the file.
    pub mocap_pos: Vec<Vec3>,
    /// World orientation of each mocap body as a quaternion w x y z (MuJoCo's `mocap_quat`),
    /// normalized where it is read (a zero quaternion is the identity).
    pub mocap_quat: Vec<[f64; 4]>,
    /// `xfrc_applied` as generalized forces (Jᵀ of the wrenches), formed by the acceleration
    /// stage when a wrench is nonzero.
    pub qfrc_xfrc: DVector<f64>,
    /// Bias forces c(q, v) = RNEA(q, v, 0) (Coriolis, centrifugal, gravity). Filled by the velocity
    /// stage when the plan solves with M (constraint rows present); the ABA path does not need it.
    pub qfrc_bias: DVector<f64>,
    /// Passive forces: joint damping and springs.
    pub qfrc_passive: DVector<f64>,
    /// The fluid forces' part of `qfrc_passive` (MuJoCo's `qfrc_fluid`): zero unless
    /// `<option density>` or `viscosity` is nonzero (`dynamics::fluid`).
    pub qfrc_fluid: DVector<f64>,
    /// Actuator forces in joint space (the actuation stage).
    pub qfrc_actuator: DVector<f64>,
    /// Gravity compensation (body `gravcomp`) as generalized forces, MuJoCo's `qfrc_gravcomp`:
    /// added to `qfrc_passive`, or to `qfrc_actuator` on joints with `actuatorgravcomp`.
    pub qfrc_gravcomp: DVector<f64>,
    /// Per actuator: transmission length, velocity, and scalar force (MuJoCo's names).
    pub actuator_length: DVector<f64>,
    /// Per actuator: the transmission's velocity (MuJoCo's `actuator_velocity`).
    pub actuator_velocity: DVector<f64>,
    /// Per actuator: the scalar force (MuJoCo's `actuator_force`).
    pub actuator_force: DVector<f64>,
    /// Per actuator (rows) and dof (columns): the moment arm ∂actuator_length/∂q̇ (MuJoCo's
    /// `actuator_moment`, stored dense here), so that qfrc_actuator = momentᵀ · actuator_force
    /// before the joints' `actuatorfrcrange`. Zero rows for actuators not simulated.
    pub actuator_moment: DMatrix<f64>,
    /// qfrc_passive + qfrc_actuator + qfrc_applied − qfrc_bias (filled on the M path).
    pub qfrc_smooth: DVector<f64>,
    /// Unconstrained acceleration M⁻¹(qfrc_passive + qfrc_actuator + qfrc_applied − qfrc_bias).
    pub qacc_smooth: DVector<f64>,
    /// Constraint forces Jᵀλ (docs/physics.md §1.6, eq. 22).
    pub qfrc_constraint: DVector<f64>,
    /// The acceleration: qacc_smooth + M⁻¹ qfrc_constraint.
    pub qacc: DVector<f64>,

    // --- constraint rows (capacity = all equality rows of the model) ---
    /// Whether each equality constraint is active (MuJoCo's `eq_active`, from `Equality::active`).
    pub eq_active: Vec<bool>,
    /// Number of active constraint rows.
    pub nefc: usize,
    /// Constraint Jacobian J, rows 0..nefc used (∂φ/∂q in tangent coordinates).
    pub efc_j: DMatrix<f64>,
    /// Position residual φ per row (MuJoCo's `efc_pos` for equality rows).
    pub efc_pos: DVector<f64>,
    /// J v per row (MuJoCo's `efc_vel`).
    pub efc_vel: DVector<f64>,
    /// J̇ v per row.
    pub efc_jdotv: DVector<f64>,
    /// Multiplier λ per row (MuJoCo's `efc_force`): the generalized constraint force is Jᵀλ.
    pub efc_force: DVector<f64>,
    /// For each row, what kind of row it is (MuJoCo's `efc_type`).
    pub efc_type: Vec<EfcType>,
    /// For each row, the element it comes from: the equality (index in `Model::equalities`) or
    /// the limited joint (index in `Model::joints`) (MuJoCo's `efc_id`).
    pub efc_id: Vec<usize>,
    /// Active-set changes of the last unilateral solve (0 without unilateral rows).
    pub efc_iterations: u32,
    /// Rank of J M⁻¹ Jᵀ at the last solve (< nefc: redundant rows, minimum-norm multipliers).
    pub efc_rank: usize,
    /// Set by the frictional solve when it restarted after diverging: sliding contacts were then
    /// solved with the symmetric cone projection instead of the maximal-dissipation law.
    pub efc_safe_friction: bool,
    /// Residual of the last iterative (Coulomb) solve: the largest change its last sweep made to
    /// the motion, max |M⁻¹Jᵀ Δλ| (an acceleration, or a velocity at the velocity level); 0 after a
    /// direct solve.
    pub efc_residual: f64,
    /// Whether the last iterative solve met its tolerance within its iteration limit (exact
    /// mode's Coulomb solve; soft mode's Newton, CG and PGS by MuJoCo's criterion).
    pub efc_converged: bool,
    /// Iterative solves since `Data::new` that stopped at their iteration limit (or on a
    /// non-finite value) without meeting the tolerance, and the largest residual they left.
    /// Exact mode: Coulomb solves. Soft mode: every solve whose scaled gradient and scaled
    /// improvement both stayed at or above `<option tolerance>` after `<option iterations>`.
    pub efc_unconverged: u64,
    /// The largest residual an unconverged iterative solve left: exact mode, max |M⁻¹Jᵀ Δλ| of
    /// its last sweep; soft mode, the scaled gradient norm (Newton, CG; MuJoCo's
    /// `solver_gradient`) or the last sweep's scaled cost improvement (PGS).
    pub efc_unconverged_residual: f64,
    /// Exact mode: unconverged solves whose forces would have added kinetic energy and were
    /// scaled down instead (`constraint::energy_guard`, docs/constraints.md).
    pub efc_energy_limited: u64,
    /// Run-time warnings (MuJoCo's `d->warning`): a singular mass matrix regularized, bad
    /// controls zeroed ([`Warnings`](super::Warnings)).
    pub warnings: super::Warnings,
    /// The exact solver's workspace (Delassus matrix, factors, warm start, active set).
    pub(crate) exact: ExactWork,
    /// Which limit and contact rows exist within a step ([`RowLifecycle`]).
    pub(crate) lifecycle: RowLifecycle,
    /// The stepper of [`step`](crate::integrate::step) (the model's integrator) and its buffers.
    pub(crate) stepper: StepperSlot,
    /// MuJoCo's `cacc`, `cfrc_ext`, `cfrc_int` per MuJoCo body and their work buffers, filled by
    /// [`rne_post_constraint`](crate::dynamics::rne_post_constraint).
    pub(crate) rne_post: RnePost,
    /// Stage skipping for finite differences (`forward::ForwardSkip`, MuJoCo's `mj_forwardSkip`).
    pub(crate) forward_skip: crate::forward::ForwardSkip,

    // --- soft (MuJoCo-compatible) constraint model, MuJoCo's buffer names ---
    /// Rows of equality constraints and of friction loss in the soft solve (MuJoCo's `ne`, `nf`;
    /// the rows come in MuJoCo's order: equality, friction, limits, contacts).
    pub ne: usize,
    /// Rows of dof friction loss (MuJoCo's `nf`).
    pub nf: usize,
    /// Per row: the margin within which it is active (MuJoCo's `efc_margin`), its friction loss
    /// (`efc_frictionloss`), the approximate diagonal of J M⁻¹ Jᵀ (`efc_diagA`), the regularizer
    /// R and D = 1/R (`efc_R`, `efc_D`), stiffness, damping, impedance and its derivative
    /// (`efc_KBIP`), the reference acceleration (`efc_aref`) and the row's state in the cost
    /// (`efc_state`).
    pub efc_margin: DVector<f64>,
    /// Per row: its friction loss (MuJoCo's `efc_frictionloss`).
    pub efc_frictionloss: DVector<f64>,
    /// Per row: the approximate diagonal of J M⁻¹ Jᵀ (MuJoCo's `efc_diagA`).
    pub efc_diag_a: DVector<f64>,
    /// Per row: the regularizer R (MuJoCo's `efc_R`).
    pub efc_r: DVector<f64>,
    /// Per row: D = 1/R (MuJoCo's `efc_D`).
    pub efc_d: DVector<f64>,
    /// Per row: stiffness, damping, impedance and its derivative (MuJoCo's `efc_KBIP`).
    pub efc_kbip: Vec<[f64; 4]>,
    /// Per row: the reference acceleration (MuJoCo's `efc_aref`).
    pub efc_aref: DVector<f64>,
    /// Per row: its state in the soft cost (MuJoCo's `efc_state`).
    pub efc_state: Vec<EfcState>,
    /// Per contact (index in `contacts`): the friction coefficient of the regularized cone
    /// (MuJoCo's `mjContact.mu`), set by the soft mode.
    pub contact_mu: Vec<f64>,
    /// The previous soft solve's acceleration (MuJoCo's `qacc_warmstart`).
    pub qacc_warmstart: DVector<f64>,
    /// Iterations of the last soft solve and its final scaled improvement and gradient
    /// (MuJoCo's `solver_niter` and `solver` statistics).
    pub solver_niter: u32,
    /// The last soft solve's final scaled improvement of the cost (MuJoCo's `solver.improvement`).
    pub solver_improvement: f64,
    /// The last soft solve's final scaled gradient norm (MuJoCo's `solver.gradient`).
    pub solver_gradient: f64,
    /// Scratch of the soft solvers (sized nv, nefc or nv × nv).
    pub(crate) soft: SoftWork,

    // --- collision ---
    /// World pose of each geom that collides, from the last collision pass (MuJoCo's `geom_xpos`,
    /// `geom_xmat`).
    pub x_world_geom: Vec<Transform>,
    /// The broad phase's per-pass scratch (sweep and prune, `crate::collision::broadphase`).
    pub(crate) broadphase: crate::collision::broadphase::BroadphaseWork,
    /// Contacts of the last collision pass (MuJoCo's `contact`). Room for
    /// [`INITIAL_CONTACTS`](crate::model::INITIAL_CONTACTS) is reserved; a pass that finds more
    /// grows it (once: the capacity is kept), up to [`Model::contact_budget`].
    pub contacts: Vec<Contact>,
    /// Contacts dropped because a collision pass found more than [`Model::contact_budget`]
    /// (cumulative; MuJoCo's `mjWARN_CONTACTFULL`).
    pub contacts_dropped: u64,

    // --- sensors ---
    /// The sensors' values from the last `forward` (MuJoCo's `sensordata`; each sensor's slice at
    /// its `Sensor::adr`, `Sensor::dim`).
    pub sensordata: DVector<f64>,
    /// The sensor stage's scratch.
    pub(crate) sensor_work: crate::sensor::SensorWork,

    // --- tendons (crate::tendon, at the start of each evaluation) ---
    /// Each tendon's length (MuJoCo's `ten_length`, m; a fixed tendon's Σ coef·q).
    pub ten_length: DVector<f64>,
    /// Each tendon's rate of length change `ten_J · v` (MuJoCo's `ten_velocity`).
    pub ten_velocity: DVector<f64>,
    /// The tendon Jacobian ∂ten_length/∂q, ntendon × nv (MuJoCo's `ten_J`, dense; its rows are
    /// the tendons' moment arms).
    pub ten_j: DMatrix<f64>,
    /// Per tendon, its first wrap point in `wrap_obj`/`wrap_xpos` (MuJoCo's `ten_wrapadr`).
    pub ten_wrapadr: Vec<usize>,
    /// Per tendon, its number of wrap points (MuJoCo's `ten_wrapnum`; 0 for fixed tendons).
    pub ten_wrapnum: Vec<usize>,
    /// Per wrap point: −1 a site, −2 a pulley, else the index of the geom wrapped around
    /// (MuJoCo's `wrap_obj`).
    pub wrap_obj: Vec<i64>,
    /// Per wrap point: its world position (MuJoCo's `wrap_xpos`; zero for a pulley).
    pub wrap_xpos: Vec<crate::spatial::Vec3>,
    /// Sleeping islands: MuJoCo's `tree_asleep` and what derives from it, and the counts of
    /// trees put to sleep and woken ([`super::sleep::SleepState`]; `<flag sleep>`).
    pub sleep: super::sleep::SleepState,
}

impl Data {
    /// Allocates every buffer for `model`; the state is the model's `qpos0` at rest at time 0,
    /// with zero controls, activations and applied forces (MuJoCo's `mj_makeData`).
    pub fn new(model: &Model) -> Self {
        Self::build(model, true)
    }

    /// A `Data` for kinematics and dynamics only (the compiler's scratch: `set_acc0`, the soft
    /// rows' inverse weights): no exact-mode matrices, whatever the model's mode.
    pub(crate) fn scratch(model: &Model) -> Self {
        Self::build(model, false)
    }

    fn build(model: &Model, exact_matrices: bool) -> Self {
        let nb = model.nbody();
        let nv = model.nv;
        let nwrap: usize = model.tendons.iter().map(|t| super::tendon::max_wrap_points(&t.kind)).sum();
        // Equality rows, and one row per limited hinge/slide joint (one side is active at a time).
        // Equality rows, one row per limited hinge/slide/ball joint (one side is active at a
        // time), one per dof with friction loss, and up to 6 per contact.
        let nefc: usize = model.equalities.iter().map(|e| e.kind.nrow()).sum::<usize>()
            + model
                .joints
                .iter()
                .filter(|j| j.limits.is_some() && (j.kind.nv() == 1 || j.kind == JointKind::Ball))
                .count()
            + model.joints.iter().filter(|j| j.friction > 0.0).map(|j| j.kind.nv()).sum::<usize>()
            + 6 * model.max_contacts().min(INITIAL_CONTACT_ROWS);
        Self {
            time: 0.0,
            qpos: DVector::from_column_slice(&model.qpos0),
            qvel: DVector::zeros(nv),
            x_parent_body: vec![Transform::identity(); nb],
            x_world_body: vec![Transform::identity(); nb],
            x_world_frame: vec![Transform::identity(); model.frames.len()],
            s_body: vec![Motion::zero(); nv],
            s_world: vec![Motion::zero(); nv],
            p_world_tree: vec![Vec3::zeros(); nb],
            x_tree_body: vec![Transform::identity(); nb],
            poses_stamp: super::poses_stamp::PosesStamp::with_capacity(model.nq),
            velocity_stamp: super::velocity_stamp::VelocityStamp::with_capacity(model.nq, model.nv),
            v_body: vec![Motion::zero(); nb],
            a_body: vec![Motion::zero(); nb],
            c_body: vec![Motion::zero(); nb],
            f_body: vec![Force::zero(); nb],
            i_composite: vec![RigidInertia::zero(); nb],
            i_articulated: vec![ArticulatedInertia::default(); nb],
            u_dof: vec![Force::zero(); nv],
            u_tau: DVector::zeros(nv),
            d_inv: vec![Matrix6::zeros(); nb],
            mass_matrix: DMatrix::zeros(nv, nv),
            mass_factor: DMatrix::zeros(nv, nv),
            tau: DVector::zeros(nv),
            aba_qacc: DVector::zeros(nv),
            scratch_v: DVector::zeros(nv),
            a_bias_body: vec![Motion::zero(); nb],
            ctrl: DVector::zeros(model.actuators.len()),
            act: DVector::zeros(model.na()),
            act_dot: DVector::zeros(model.na()),
            history: {
                let mut history = DVector::zeros(model.nhistory());
                crate::forward::reset_actuator_buffers(model, history.as_mut_slice());
                history
            },
            qfrc_applied: DVector::zeros(nv),
            xfrc_applied: vec![[0.0; 6]; model.frames.iter().filter(|f| f.kind == FrameKind::Link).count()],
            qfrc_xfrc: DVector::zeros(nv),
            mocap_pos: model.mocap_pose0.iter().map(|x| x.pos).collect(),
            mocap_quat: model.mocap_pose0.iter().map(|x| x.quat_wxyz()).collect(),
            qfrc_bias: DVector::zeros(nv),
            qfrc_passive: DVector::zeros(nv),
            qfrc_fluid: DVector::zeros(nv),
            qfrc_actuator: DVector::zeros(nv),
            qfrc_gravcomp: DVector::zeros(nv),
            actuator_length: DVector::zeros(model.actuators.len()),
            actuator_velocity: DVector::zeros(model.actuators.len()),
            actuator_moment: DMatrix::zeros(model.actuators.len(), model.nv),
            actuator_force: DVector::zeros(model.actuators.len()),
            qfrc_smooth: DVector::zeros(nv),
            qacc_smooth: DVector::zeros(nv),
            qfrc_constraint: DVector::zeros(nv),
            qacc: DVector::zeros(nv),
            eq_active: model.equalities.iter().map(|e| e.active).collect(),
            nefc: 0,
            efc_j: DMatrix::zeros(nefc, nv),
            efc_pos: DVector::zeros(nefc),
            efc_vel: DVector::zeros(nefc),
            efc_jdotv: DVector::zeros(nefc),
            efc_force: DVector::zeros(nefc),
            efc_type: vec![EfcType::Equality; nefc],
            efc_id: vec![0; nefc],
            efc_iterations: 0,
            efc_rank: 0,
            efc_safe_friction: false,
            efc_residual: 0.0,
            efc_converged: true,
            efc_unconverged: 0,
            efc_unconverged_residual: 0.0,
            efc_energy_limited: 0,
            warnings: super::Warnings::new(nv),
            exact: exact_work(model, nefc, exact_matrices),
            lifecycle: RowLifecycle::new(model),
            stepper: StepperSlot::for_model(model),
            rne_post: RnePost::new(model),
            ne: 0,
            nf: 0,
            efc_margin: DVector::zeros(nefc),
            efc_frictionloss: DVector::zeros(nefc),
            efc_diag_a: DVector::zeros(nefc),
            efc_r: DVector::zeros(nefc),
            efc_d: DVector::zeros(nefc),
            efc_kbip: vec![[0.0; 4]; nefc],
            efc_aref: DVector::zeros(nefc),
            efc_state: vec![EfcState::Satisfied; nefc],
            contact_mu: vec![0.0; model.max_contacts().min(crate::model::INITIAL_CONTACTS)],
            qacc_warmstart: DVector::zeros(nv),
            solver_niter: 0,
            solver_improvement: 0.0,
            solver_gradient: 0.0,
            soft: SoftWork::new(model, nefc),
            x_world_geom: vec![Transform::identity(); model.geoms.len()],
            broadphase: crate::collision::broadphase::BroadphaseWork::new(model),
            contacts: Vec::with_capacity(model.max_contacts().min(crate::model::INITIAL_CONTACTS)),
            contacts_dropped: 0,
            sensordata: DVector::zeros(model.nsensordata),
            sensor_work: crate::sensor::SensorWork::new(model),
            forward_skip: Default::default(),
            ten_length: DVector::zeros(model.tendons.len()),
            ten_velocity: DVector::zeros(model.tendons.len()),
            ten_j: DMatrix::zeros(model.tendons.len(), nv),
            ten_wrapadr: vec![0; model.tendons.len()],
            ten_wrapnum: vec![0; model.tendons.len()],
            wrap_obj: vec![0; nwrap],
            wrap_xpos: vec![crate::spatial::Vec3::zeros(); nwrap],
            sleep: super::sleep::SleepState::new(model),
        }
    }
}

impl Data {
    /// The world pose of mocap body `m` from `mocap_pos` and `mocap_quat` (normalized; a zero or
    /// non-finite quaternion reads as the identity, as MuJoCo normalizes it).
    pub fn mocap_pose(&self, m: usize) -> Transform {
        let [w, x, y, z] = self.mocap_quat[m];
        let norm = (w * w + x * x + y * y + z * z).sqrt();
        let rot = if norm > 0.0 && norm.is_finite() {
            quat_to_matrix(w / norm, x / norm, y / norm, z / norm)
        } else {
            crate::spatial::Mat3::identity()
        };
        Transform::new(rot, self.mocap_pos[m])
    }

    /// The world pose of a frame or geom at `x_body` on `body`, or on mocap body `mocap`.
    #[inline]
    pub(crate) fn attached_pose(&self, body: usize, mocap: Option<usize>, x_body: &Transform) -> Transform {
        match mocap {
            Some(m) => self.mocap_pose(m) * *x_body,
            None => self.x_world_body[body] * *x_body,
        }
    }

    /// Whether row `i` starts a contact's block of rows: the normal row of a frictionless or
    /// elliptic contact, the first edge row of a pyramidal one (a contact's rows are consecutive,
    /// with the same `efc_id` and type). Counting these rows counts the contacts with rows.
    pub fn efc_is_normal(&self, i: usize) -> bool {
        match self.efc_type[i] {
            EfcType::ContactFrictionless => true,
            kind @ (EfcType::ContactElliptic | EfcType::ContactPyramidal) => {
                i == 0 || self.efc_type[i - 1] != kind || self.efc_id[i - 1] != self.efc_id[i]
            }
            _ => false,
        }
    }

    /// The force of row i + k (the k-th row of the block starting at row i) in the last
    /// acceleration-level solve (`efc_warm`, matched by type and element), 0 if it had no such row.
    pub fn efc_previous_force(&self, i: usize, k: usize) -> f64 {
        let key = (self.efc_type[i], self.efc_id[i]);
        self.exact.warm_rows.iter().position(|w| *w == key).map_or(0.0, |j| {
            if j + k < self.exact.warm_rows.len() && self.exact.warm_rows[j + k] == key {
                self.exact.warm[j + k]
            } else {
                0.0
            }
        })
    }

    /// Whether row `i`'s force has a sign in the current solve: a limit or contact row that is
    /// not held closed by `efc_pressing`.
    pub fn efc_signed(&self, i: usize) -> bool {
        self.efc_type[i].is_unilateral() && !self.exact.pressing[i]
    }

    /// Rows in the active set of the last exact solve without friction (compare with `efc_rank`:
    /// fewer independent rows than active ones means redundant constraints).
    pub fn efc_active_rows(&self) -> usize {
        self.exact.active.len()
    }

    /// The number of rows the buffers hold.
    pub fn efc_capacity(&self) -> usize {
        self.efc_j.nrows()
    }

    /// Makes room for `n` rows (at least doubling), keeping the warm start; allocates only when a
    /// problem is larger than any before it.
    pub fn reserve_rows(&mut self, n: usize) {
        // The exact mode's dense matrices (nefc² each) grow where they are formed, with the
        // Delassus matrix: rows written only to measure a violation (a soft-mode run's report)
        // do not allocate them.
        self.reserve_soft_rows(n);
    }

    /// [`reserve_rows`](Self::reserve_rows) without the exact mode's dense matrices: what the soft
    /// mode needs (rows × nv for J, vectors per row).
    pub(crate) fn reserve_soft_rows(&mut self, n: usize) {
        let cap = self.efc_capacity();
        if n <= cap {
            return;
        }
        let new = n.max(2 * cap);
        let nv = self.efc_j.ncols();
        // A zeroed allocation (`vec!` of zeros): the pages that no row is written to are never
        // touched, where `DMatrix::zeros` writes every entry of rows × nv.
        self.efc_j = DMatrix::from_vec(new, nv, vec![0.0; new * nv]);
        self.exact.grow_vectors(new);
        for v in [
            &mut self.efc_pos,
            &mut self.efc_vel,
            &mut self.efc_jdotv,
            &mut self.efc_force,
            &mut self.efc_margin,
            &mut self.efc_frictionloss,
            &mut self.efc_diag_a,
            &mut self.efc_r,
            &mut self.efc_d,
            &mut self.efc_aref,
            &mut self.soft.jar,
            &mut self.soft.jv,
            &mut self.soft.jar_trial,
        ] {
            *v = DVector::zeros(new);
        }
        self.efc_type.resize(new, EfcType::Equality);
        self.efc_id.resize(new, 0);
        self.efc_kbip.resize(new, [0.0; 4]);
        self.efc_state.resize(new, EfcState::Satisfied);
        self.soft.factor_state.resize(new, EfcState::Satisfied);
    }

    /// Whether row `i` is a limit row or a contact's normal row (the rows with a gap φ ≥ 0).
    pub fn efc_is_normal_or_limit(&self, i: usize) -> bool {
        self.efc_type[i] == EfcType::LimitJoint || self.efc_is_normal(i)
    }

    /// Number of rows of the block starting at row `i`: a contact's dimension at its normal row
    /// (2(dim − 1) for a pyramidal contact), 1 for every other row.
    pub fn efc_block_len(&self, i: usize) -> usize {
        let kind = self.efc_type[i];
        if !matches!(kind, EfcType::ContactElliptic | EfcType::ContactPyramidal) {
            return 1;
        }
        // The rows after i up to nefc, read as slices (no bounds check per row).
        let id = self.efc_id[i];
        let end = self.nefc.min(self.efc_type.len()).min(self.efc_id.len()).max(i + 1);
        let (types, ids) = (&self.efc_type[i + 1..end], &self.efc_id[i + 1..end]);
        1 + types.iter().zip(ids).take_while(|&(&t, &d)| t == kind && d == id).count()
    }
}

/// The exact mode's workspace for `nefc` rows: its per-row vectors, and its dense nefc² matrices
/// only for a model in exact mode with constraint rows (a soft model, and the compiler's own
/// scratch `Data`, never pay for them; they grow at their first use if the mode changes).
fn exact_work(model: &Model, nefc: usize, exact_matrices: bool) -> ExactWork {
    let mut work = ExactWork::new(model.nv, 0);
    work.grow_vectors(nefc);
    if exact_matrices
        && matches!(model.plan.solver, crate::constraint::ConstraintSolver::Exact(_))
        && model.plan.has_constraints()
    {
        work.grow_matrices(model.nv, nefc);
    }
    work
}
