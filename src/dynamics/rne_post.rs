//! The quantities MuJoCo's acceleration-stage sensors read, after a `forward`: MuJoCo's
//! `mj_rnePostConstraint` (engine_core_smooth.c) — per MuJoCo body its spatial acceleration
//! `cacc` with the gravity offset, the external wrench `cfrc_ext` and the interaction wrench with
//! its parent `cfrc_int` — and `mj_objectAcceleration` (engine_core_util.c) on top of them.
//!
//! **Bodies.** MuJoCo's bodies are lagrange's link frames ([`Links`](crate::model::Links)): a
//! body welded to its parent is its own MuJoCo body although lagrange fuses it into a compiled
//! body, and a body with several joints is one MuJoCo body (the last compiled body of its chain).
//! Each MuJoCo body `b` moves with the compiled body `frames[links.frame[b]].body` and has its own
//! mass properties `frames[links.frame[b]].inertia`; the subtree sums run over `links.parent`.
//!
//! **Convention** (MuJoCo's): every spatial vector is in world axes about the point
//! `subtree_com[rootid[b]]`, the centre of mass of the subtree of the body's root (the child of
//! the world it hangs from). A motion is [angular; linear], the linear part the velocity or
//! acceleration of the body point passing through that point; a force is [torque about that
//! point; force]. The accessors move them to any point.
//!
//! **What is computed** (spatial algebra of RBDA ch. 2, as `crate::spatial`):
//! - `cvel`, `cacc`: the compiled body's velocity and acceleration at `qacc` (RNEA's forward
//!   pass, RBDA Table 5.1), the world accelerating at −gravity (zero with
//!   `<flag gravity="disable">`), so that `cacc` of a body at rest under gravity is (0, −g);
//! - `cfrc_ext`: the wrenches the world exerts on the body besides its joint —
//!   `xfrc_applied` (at the body's centre of mass), the contact forces of contacts with rows
//!   (geom 1's body receives −f, geom 2's +f, at the contact point), and the forces of connect and
//!   weld equality rows (body 1 +λ at its anchor, body 2 −λ at its). A weld's torque is the one
//!   its rotation rows exert, `J_rotᵀ λ`: with MuJoCo's quaternion rows (soft mode)
//!   `s · Eᵀ λ_rot`, E the map ω ↦ ½ imag(q_B⁻¹ (0, ω) q_A) and s the torquescale; with the
//!   exact mode's rows s (ω_A − ω_B), `s · λ_rot`. This is what MuJoCo 4.0.0 sums (checked by
//!   experiment: its 2026-08 source snapshot still adds λ_rot itself). Joint, tendon and mimic
//!   equalities, limits and friction loss act through joints: they are in no body's `cfrc_ext`;
//! - `cfrc_int`: the inertial wrench of the body's subtree, I a + v ×* I v summed over the
//!   subtree, minus the subtree's external wrenches: the wrench the parent exerts on the body
//!   through its joint (or weld). As in MuJoCo, the world's entry is the plain sum of its
//!   children's, each about its own root's point, read about `subtree_com` of the world.
//!
//! `mj_objectAcceleration` moves `cacc` to a point and adds ω × v (the classical acceleration of
//! the point, minus gravity). MuJoCo 4.0.0 does so for every body, the world and bodies welded to
//! it included (they read (0, −g)); its 2026-08 source snapshot returned zero there (checked by
//! experiment on the live MuJoCo).
//!
//! The buffers live in `Data` ([`RnePost`]), sized by `Data::new`; nothing allocates.

use crate::constraint::soft::rows::{conj, weld_quats, weld_rotation_map};
use crate::constraint::{ConstraintMode, RowGeometry};
use crate::error::{check, InputError};
use crate::kinematics::{body_poses, forward_velocities_unchecked};
use crate::model::{Data, EfcType, EqualityKind, JointKind, Model};
use crate::spatial::{Force, Motion, RigidInertia, Transform, Vec3};

/// MuJoCo's `mjMINVAL`: a subtree lighter than this has its centre of mass at the body's own.
const MIN_MASS: f64 = 1e-15;

/// The work and results of [`rne_post_constraint`], per MuJoCo body (MuJoCo's buffer names) and
/// per compiled body. Spatial vectors in world axes about `subtree_com[rootid[b]]`.
#[derive(Clone, Debug, Default)]
pub(crate) struct RnePost {
    /// MuJoCo's `body_rootid`: the child of the world each body hangs from (0 for the world).
    pub(crate) rootid: Vec<usize>,
    /// Each MuJoCo body's own mass properties in its compiled body's coordinates (constant; a
    /// mocap body's are formed at its pose instead).
    inertia_body: Vec<RigidInertia>,
    /// Each MuJoCo body's centre of mass in its compiled body's coordinates (constant).
    com_body: Vec<Vec3>,
    /// The MuJoCo bodies whose `cvel` and `cacc` the sensor stage forms: those its computed
    /// accelerometers and frame accelerations read, and the mocap bodies (`cfrc_int` reads
    /// theirs).
    sensed: Vec<bool>,
    /// The MuJoCo bodies whose `cfrc_int` the sensor stage forms: the subtrees of the bodies its
    /// computed force and torque sensors read (a body's `cfrc_int` carries its whole subtree).
    wrench_sensed: Vec<bool>,
    /// Per compiled body, whether the sensor stage forms its acceleration: the compiled bodies of
    /// the [`sensed`](Self::sensed) and [`wrench_sensed`](Self::wrench_sensed) MuJoCo bodies and
    /// their ancestors (an acceleration is formed from its parent's).
    accelerated: Vec<bool>,
    /// Each body's centre of mass, world (MuJoCo's `xipos`).
    pub(crate) xipos: Vec<Vec3>,
    /// The mass of each body's subtree (MuJoCo's `body_subtreemass`).
    pub(crate) subtree_mass: Vec<f64>,
    /// The centre of mass of each body's subtree, world (MuJoCo's `subtree_com`).
    pub(crate) subtree_com: Vec<Vec3>,
    /// Spatial velocity of each body (MuJoCo's `cvel`).
    pub(crate) cvel: Vec<Motion>,
    /// Spatial acceleration with the gravity offset (MuJoCo's `cacc`).
    pub(crate) cacc: Vec<Motion>,
    /// External wrench (MuJoCo's `cfrc_ext`).
    pub(crate) cfrc_ext: Vec<Force>,
    /// Interaction wrench with the parent (MuJoCo's `cfrc_int`).
    pub(crate) cfrc_int: Vec<Force>,
    /// Per compiled body: spatial acceleration with the gravity offset, body coordinates.
    a_body: Vec<Motion>,
}

impl RnePost {
    /// Buffers for `model` (its MuJoCo bodies and compiled bodies).
    pub(crate) fn new(model: &Model) -> Self {
        let parent = &model.links.parent;
        let mut rootid = vec![0; parent.len()];
        for b in 1..parent.len() {
            rootid[b] = if parent[b] == 0 { b } else { rootid[parent[b]] };
        }
        let n = parent.len();
        let frames = || model.links.frame.iter().map(|&f| &model.frames[f]);
        let (sensed, wrench_sensed) = (sensed_bodies(model), wrench_sensed_bodies(model));
        let accelerated = accelerated_bodies(model, &sensed, &wrench_sensed);
        Self {
            rootid,
            inertia_body: frames().map(|f| f.inertia.transformed(&f.x_body_frame)).collect(),
            com_body: frames().map(|f| f.x_body_frame.act_point(&f.inertia.com())).collect(),
            sensed,
            wrench_sensed,
            accelerated,
            xipos: vec![Vec3::zeros(); n],
            subtree_mass: vec![0.0; n],
            subtree_com: vec![Vec3::zeros(); n],
            cvel: vec![Motion::zero(); n],
            cacc: vec![Motion::zero(); n],
            cfrc_ext: vec![Force::zero(); n],
            cfrc_int: vec![Force::zero(); n],
            a_body: vec![Motion::zero(); model.nbody()],
        }
    }
}

/// Per MuJoCo body, whether the sensor stage forms its `cvel` and `cacc` ([`RnePost::sensed`]).
fn sensed_bodies(model: &Model) -> Vec<bool> {
    use crate::sensor::{SensorObject, SensorType};
    let links = &model.links;
    let mut sensed: Vec<bool> = links.frame.iter().map(|&f| model.frames[f].mocap.is_some()).collect();
    for s in model.sensors.iter().filter(|s| s.is_computed()) {
        if !matches!(s.kind, SensorType::Accelerometer | SensorType::FrameLinAcc | SensorType::FrameAngAcc) {
            continue;
        }
        let b = match s.object {
            SensorObject::Body(b) | SensorObject::XBody(b) => Some(b),
            SensorObject::Site(f) => links.of_frame.get(f).copied(),
            SensorObject::Geom(g) => links.of_geom.get(g).copied(),
            _ => None,
        };
        if let Some(flag) = b.and_then(|b| sensed.get_mut(b)) {
            *flag = true;
        }
    }
    sensed
}

/// Per MuJoCo body, whether the sensor stage forms its `cfrc_int` ([`RnePost::wrench_sensed`]):
/// the bodies of the sites of the computed force and torque sensors and their descendants (MuJoCo
/// numbers a parent before its children).
fn wrench_sensed_bodies(model: &Model) -> Vec<bool> {
    use crate::sensor::{SensorObject, SensorType};
    let links = &model.links;
    let mut sensed = vec![false; links.len()];
    for s in model.sensors.iter().filter(|s| s.is_computed()) {
        if let (SensorType::Force | SensorType::Torque, SensorObject::Site(f)) = (s.kind, s.object) {
            if let Some(flag) = links.of_frame.get(f).and_then(|&b| sensed.get_mut(b)) {
                *flag = true;
            }
        }
    }
    for b in 1..links.len() {
        if sensed[links.parent[b]] {
            sensed[b] = true;
        }
    }
    sensed
}

/// Per compiled body, whether the sensor stage forms its acceleration ([`RnePost::accelerated`]):
/// those of the MuJoCo bodies in `sensed` or `wrench_sensed`, and their ancestors (a compiled
/// body's parent comes before it).
fn accelerated_bodies(model: &Model, sensed: &[bool], wrench_sensed: &[bool]) -> Vec<bool> {
    let mut accelerated = vec![false; model.nbody()];
    for (b, &f) in model.links.frame.iter().enumerate() {
        if sensed[b] || wrench_sensed[b] {
            accelerated[model.frames[f].body] = true;
        }
    }
    for b in (1..model.nbody()).rev() {
        if accelerated[b] {
            accelerated[model.bodies[b].parent] = true;
        }
    }
    accelerated
}

/// MuJoCo's `mj_rnePostConstraint` at the state in `data` (`qpos`, `qvel`) with the outputs of
/// the last [`forward`](crate::forward::forward) there (`qacc`, the contacts and constraint
/// forces `efc_force`): every MuJoCo body's `cacc`, `cfrc_ext` and `cfrc_int` (module
/// documentation), read by [`body_acceleration`], [`object_acceleration`],
/// [`interaction_wrench`] and [`external_wrench`]. Also forms the body poses at `qpos`
/// (`x_world_body`) and the body velocities at `qvel` (`v_body`). Allocates nothing.
///
/// # Errors
/// [`InputError::Length`] when `data` was made for another model or a state or input buffer
/// (`qpos`, `qvel`, `qacc`, `xfrc_applied`, …) has the wrong length.
///
/// # Example
/// ```
/// use lagrange::dynamics::{interaction_wrench, rne_post_constraint};
/// use lagrange::prelude::*;
/// let model = Model::from_str(r#"<mujoco><worldbody><body name="a" pos="0 0 1">
///     <joint type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.02" mass="2"/>
///     </body></worldbody></mujoco>"#)?;
/// let mut data = Data::new(&model);
/// forward(&model, &mut data); // hanging at rest
/// rne_post_constraint(&model, &mut data)?;
/// let (force, _torque) = interaction_wrench(&model, &data, 1, &[0.0, 0.0, 1.0].into())?;
/// assert!((force.z - 2.0 * 9.81).abs() < 1e-12); // the hinge carries the weight
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn rne_post_constraint(model: &Model, data: &mut Data) -> Result<(), InputError> {
    const F: &str = "rne_post_constraint";
    check::data(F, model, data)?;
    data.check_sizes(model, F)?;
    InputError::check_len(F, "data.qacc", data.qacc.len(), model.nv, "nv")?;
    let nbody = model.links.len();
    InputError::check_len(F, "data.xfrc_applied", data.xfrc_applied.len(), nbody, "MuJoCo bodies")?;
    InputError::check_len(F, "data (MuJoCo bodies)", data.rne_post.cacc.len(), nbody, "MuJoCo bodies")?;
    let nmocap = model.mocap_pose0.len();
    InputError::check_len(F, "data.mocap_pos", data.mocap_pos.len(), nmocap, "mocap bodies")?;
    InputError::check_len(F, "data.mocap_quat", data.mocap_quat.len(), nmocap, "mocap bodies")?;
    data.poses_stamp.clear();
    data.velocity_stamp.clear();
    let q = std::mem::take(&mut data.qpos);
    let v = std::mem::take(&mut data.qvel);
    body_poses(model, data, q.as_slice());
    forward_velocities_unchecked(model, data, v.as_slice());
    rne_post_constraint_at(model, data, q.as_slice(), v.as_slice(), true, false, None);
    data.qpos = q;
    data.qvel = v;
    Ok(())
}

/// [`rne_post_constraint`] at configuration `q` and velocity `v` (the state of the `forward_at`
/// that left `qacc` and the constraint forces in `data`), without the argument checks, with the
/// body velocities `v_body` already at `v` ([`forward_velocities`](crate::kinematics::forward_velocities)
/// after the poses at `q`: the sensor stage forms them once for all its sensors). Without
/// `wrenches` (the sensor stage when no force or torque sensor reads them) `cfrc_ext` and
/// `cfrc_int` are left zero and only the accelerations are formed. With `sensed_only` (the
/// sensor stage) `cvel` and `cacc` are formed only for the bodies the model's acceleration sensors
/// read (and mocap bodies), zero for the others, and `cfrc_int` only for the subtrees its force and
/// torque sensors read, zero for the other bodies (the world's too, unless a sensor reads it). `centres`, when the caller has them at `q`
/// (the sensor stage's subtree sensors), are each MuJoCo body's centre of mass, its subtree's mass
/// and centre of mass (`xipos`, `body_subtreemass`, `subtree_com`), used instead of forming them
/// again.
pub(crate) fn rne_post_constraint_at(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    wrenches: bool,
    sensed_only: bool,
    centres: Option<(&[Vec3], &[f64], &[Vec3])>,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `rne_post_avx2` requires.
        unsafe { rne_post_avx2(model, data, q, v, wrenches, sensed_only, centres) };
        return;
    }
    rne_post_kernel(model, data, q, v, wrenches, sensed_only, centres);
}

/// [`rne_post_kernel`] compiled for AVX2: the same products and sums (Rust fuses no
/// multiply–add unasked), so the same bits, in fewer instructions (three-operand VEX forms).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn rne_post_avx2(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    wrenches: bool,
    sensed_only: bool,
    centres: Option<(&[Vec3], &[f64], &[Vec3])>,
) {
    rne_post_kernel(model, data, q, v, wrenches, sensed_only, centres);
}

#[inline(always)]
fn rne_post_kernel(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    wrenches: bool,
    sensed_only: bool,
    centres: Option<(&[Vec3], &[f64], &[Vec3])>,
) {
    let mut w = std::mem::take(&mut data.rne_post);
    body_poses(model, data, q);
    compiled_motions(model, data, &mut w, v, sensed_only);
    // The caller's centres when they follow this file's rule (the world's own mass zero).
    let world_massless = model.links.frame.first().is_none_or(|&f| model.frames[f].inertia.mass == 0.0);
    match centres {
        Some((xipos, mass, com))
            if world_massless
                && xipos.len() == w.xipos.len()
                && mass.len() == w.subtree_mass.len()
                && com.len() == w.subtree_com.len() =>
        {
            w.xipos.copy_from_slice(xipos);
            w.subtree_mass.copy_from_slice(mass);
            w.subtree_com.copy_from_slice(com);
        }
        _ => com_frames(model, data, &mut w),
    }
    link_motions(model, data, &mut w, sensed_only);
    if wrenches {
        external_wrenches(model, data, &mut w);
        interaction_wrenches(model, data, &mut w, sensed_only);
    } else {
        w.cfrc_ext.fill(Force::zero());
        w.cfrc_int.fill(Force::zero());
    }
    data.rne_post = w;
}

/// Acceleration of every compiled body in its own coordinates at (`v`, `qacc`), the world
/// accelerating at −gravity (RNEA's forward pass, RBDA Table 5.1), with the velocities `v_body`
/// at `v` (the same pass's, `forward_velocities`). Needs `body_poses`. With `sensed_only`, only
/// of the [`RnePost::accelerated`] bodies (the others' are left as they were: nothing reads them).
#[inline(always)]
fn compiled_motions(model: &Model, data: &Data, w: &mut RnePost, v: &[f64], sensed_only: bool) {
    w.a_body[0] = Motion::new(Vec3::zeros(), -model.gravity);
    for b in 1..model.nbody() {
        if sensed_only && !w.accelerated[b] {
            continue;
        }
        let j = model.joint_of(b);
        let x = &data.x_parent_body[b];
        let p = model.bodies[b].parent;
        let v_b = &data.v_body[b];
        if matches!(j.kind, JointKind::Revolute { .. }) {
            // A hinge's column is (axis, 0): its joint velocity (axis q̇, 0) and acceleration
            // (axis q̈, 0) have no linear part, and the products with those zeros are left out
            // (the same bits up to the signs of zeros).
            let k = j.dof_adr;
            let axis = data.s_body[k].ang;
            let w_joint = axis * v[k];
            let mut a = x.inv_act_motion(&w.a_body[p]);
            a.ang += axis * data.qacc[k];
            a.ang += v_b.ang.cross(&w_joint);
            a.lin += v_b.lin.cross(&w_joint);
            w.a_body[b] = a;
            continue;
        }
        let mut v_joint = Motion::zero();
        let mut a_joint = Motion::zero();
        for k in j.dof_adr..j.dof_adr + j.kind.nv() {
            v_joint += data.s_body[k] * v[k];
            a_joint += data.s_body[k] * data.qacc[k];
        }
        a_joint += j.kind.bias_motion(&v_joint);
        w.a_body[b] = x.inv_act_motion(&w.a_body[p]) + a_joint + v_b.cross_motion(&v_joint);
    }
}

/// Each MuJoCo body's centre of mass, and its subtree's mass and centre of mass (MuJoCo's
/// `xipos`, `body_subtreemass`, `subtree_com`; `mj_comPos`). The world's own mass is zero, as in
/// MuJoCo.
#[inline(always)]
fn com_frames(model: &Model, data: &Data, w: &mut RnePost) {
    let links = &model.links;
    for b in 0..links.len() {
        let frame = &model.frames[links.frame[b]];
        let mass = if b == 0 { 0.0 } else { frame.inertia.mass };
        w.xipos[b] = match frame.mocap {
            None => data.x_world_body[frame.body].act_point(&w.com_body[b]),
            Some(m) => (data.mocap_pose(m) * frame.x_body_frame).act_point(&frame.inertia.com()),
        };
        w.subtree_mass[b] = mass;
        w.subtree_com[b] = w.xipos[b] * mass;
    }
    for b in (1..links.len()).rev() {
        let p = links.parent[b];
        let (m, moment) = (w.subtree_mass[b], w.subtree_com[b]);
        w.subtree_mass[p] += m;
        w.subtree_com[p] += moment;
    }
    for b in 0..links.len() {
        w.subtree_com[b] =
            if w.subtree_mass[b] < MIN_MASS { w.xipos[b] } else { w.subtree_com[b] / w.subtree_mass[b] };
    }
}

/// `cvel` and `cacc` of every MuJoCo body (with `sensed_only`, of the [`RnePost::sensed`] ones;
/// zero for the others): its compiled body's, in world axes about the body's point
/// `subtree_com[rootid]`. Bodies on the world (static and mocap bodies) have the world's: zero
/// velocity and the acceleration (0, −g).
#[inline(always)]
fn link_motions(model: &Model, data: &Data, w: &mut RnePost, sensed_only: bool) {
    let links = &model.links;
    for b in 0..links.len() {
        if sensed_only && !w.sensed[b] {
            w.cvel[b] = Motion::zero();
            w.cacc[b] = Motion::zero();
            continue;
        }
        let cb = model.frames[links.frame[b]].body;
        let x = &data.x_world_body[cb];
        let offset = w.subtree_com[w.rootid[b]] - x.pos;
        let to_point = |m: &Motion| {
            let ang = x.rot * m.ang;
            Motion::new(ang, x.rot * m.lin + ang.cross(&offset))
        };
        w.cvel[b] = to_point(&data.v_body[cb]);
        w.cacc[b] = to_point(&w.a_body[cb]);
    }
}

/// The wrench (`torque`, `force`) applied at world point `p_from`, as a spatial force about
/// `p_to` (world axes): (torque + (p_from − p_to) × force, force).
fn wrench_about(torque: &Vec3, force: &Vec3, p_from: &Vec3, p_to: &Vec3) -> Force {
    Force::new(torque + (p_from - p_to).cross(force), *force)
}

/// Adds to body `b`'s `cfrc_ext` (unless it is the world) the wrench (torque, force) applied at
/// world point `p`, with `sign`.
fn add_ext(w: &mut RnePost, b: usize, sign: f64, torque: &Vec3, force: &Vec3, p: &Vec3) {
    if b == 0 {
        return;
    }
    let f = wrench_about(torque, force, p, &w.subtree_com[w.rootid[b]]);
    w.cfrc_ext[b] += f * sign;
}

/// `cfrc_ext`: `xfrc_applied`, contact forces and connect/weld forces (module documentation).
#[inline(always)]
fn external_wrenches(model: &Model, data: &Data, w: &mut RnePost) {
    w.cfrc_ext.fill(Force::zero());
    for b in 1..model.links.len() {
        let x = &data.xfrc_applied[b];
        if x.iter().any(|&c| c != 0.0) {
            let (force, torque) = (Vec3::new(x[0], x[1], x[2]), Vec3::new(x[3], x[4], x[5]));
            let p = w.xipos[b];
            add_ext(w, b, 1.0, &torque, &force, &p);
        }
    }
    let mut r = 0;
    while r < data.nefc {
        let kind = data.efc_type[r];
        if kind.is_contact() {
            let len = data.efc_block_len(r);
            add_contact(model, data, w, r, len);
            r += len;
        } else if kind == EfcType::Equality {
            let id = data.efc_id[r];
            let n = model.equalities.get(id).map_or(1, |e| e.kind.nrow());
            if r + n <= data.nefc {
                add_equality(model, data, w, id, r, n);
            }
            r += n;
        } else {
            r += 1;
        }
    }
}

/// Contact `data.efc_id[r]` (rows r..r + len): −f on geom 1's body, +f on geom 2's, at the
/// contact point (MuJoCo's `mj_contactForce` in world axes).
fn add_contact(model: &Model, data: &Data, w: &mut RnePost, r: usize, len: usize) {
    let Some(contact) = data.contacts.get(data.efc_id[r]) else {
        return;
    };
    let frc = crate::constraint::contact_force::block_force(data, r, len);
    let frame_t = contact.frame.transpose();
    let force = frame_t * Vec3::new(frc[0], frc[1], frc[2]);
    let torque = frame_t * Vec3::new(frc[3], frc[4], frc[5]);
    let [g1, g2] = contact.geom;
    add_ext(w, model.links.of_geom[g1], -1.0, &torque, &force, &contact.pos);
    add_ext(w, model.links.of_geom[g2], 1.0, &torque, &force, &contact.pos);
}

/// Equality `id` with its `n` rows from row r: a connect's force λ, a weld's force and torque,
/// +at body 1's anchor and − at body 2's; other equalities act through joints (nothing here).
fn add_equality(model: &Model, data: &Data, w: &mut RnePost, id: usize, r: usize, n: usize) {
    let (frame1, frame2) = match model.equalities.get(id).map(|e| &e.kind) {
        Some(EqualityKind::Connect { frame1, frame2, .. } | EqualityKind::Weld { frame1, frame2, .. }) => {
            (*frame1, *frame2)
        }
        _ => return,
    };
    let equalities = &model.plan.constraints.equalities;
    let Some(e) =
        equalities.get(id).filter(|e| e.id == id).or_else(|| equalities.iter().find(|e| e.id == id))
    else {
        return;
    };
    let lambda =
        |k: usize| Vec3::new(data.efc_force[r + k], data.efc_force[r + k + 1], data.efc_force[r + k + 2]);
    let force = lambda(0);
    let (a, p_a, b, p_b, torque) = match &e.geometry {
        RowGeometry::Points { a, r_a, b, r_b } => (*a, *r_a, *b, *r_b, Vec3::zeros()),
        RowGeometry::Frames { a, x_a, b, x_b, torquescale } => {
            let torque = if n == 6 {
                match model.plan.mode() {
                    // MuJoCo's rows: J_rot = s E (J_ω,A − J_ω,B).
                    ConstraintMode::Soft => {
                        let (qa, qb) = weld_quats(data, e, *a, x_a, *b, x_b);
                        weld_rotation_map(&qa, &conj(&qb)).tr_mul(&lambda(3)) * *torquescale
                    }
                    // The exact mode's rows: J_rot = s (J_ω,A − J_ω,B).
                    ConstraintMode::Exact => lambda(3) * *torquescale,
                }
            } else {
                Vec3::zeros()
            };
            (*a, x_a.pos, *b, x_b.pos, torque)
        }
        RowGeometry::Scalar { .. } => return,
    };
    let p_a = e.side_pose(data, 0, a).act_point(&p_a);
    let p_b = e.side_pose(data, 1, b).act_point(&p_b);
    add_ext(w, model.links.of_frame[frame1], 1.0, &torque, &force, &p_a);
    add_ext(w, model.links.of_frame[frame2], -1.0, &torque, &force, &p_b);
}

/// `cfrc_int`: each body's inertial wrench I a + v ×* I v (its own inertia) minus `cfrc_ext`,
/// summed over the subtree (leaves to root, MuJoCo's order; the world's entry sums its
/// children's about their own points, as MuJoCo's does). The inertial wrench is formed in the
/// compiled body's coordinates, where the body's inertia is constant, and moved to world axes
/// about the body's point (one force transform instead of an inertia transform per body); a mocap
/// body's, in world axes at its pose. With `sensed_only`, only of the
/// [`RnePost::wrench_sensed`] bodies, zero for the others: a sensed body's subtree is sensed, so
/// its sum is the same.
#[inline(always)]
fn interaction_wrenches(model: &Model, data: &Data, w: &mut RnePost, sensed_only: bool) {
    let links = &model.links;
    w.cfrc_int[0] = Force::zero();
    for b in 1..links.len() {
        if sensed_only && !w.wrench_sensed[b] {
            w.cfrc_int[b] = Force::zero();
            continue;
        }
        let frame = &model.frames[links.frame[b]];
        let point = w.subtree_com[w.rootid[b]];
        let f_body = match frame.mocap {
            None => {
                let (cb, inertia) = (frame.body, &w.inertia_body[b]);
                let (v, a) = (&data.v_body[cb], &w.a_body[cb]);
                let f = inertia.mul_motion(a) + v.cross_force(&inertia.mul_motion(v));
                let x = &data.x_world_body[cb];
                Transform::new(x.rot, x.pos - point).act_force(&f)
            }
            Some(m) => {
                let x = data.mocap_pose(m) * frame.x_body_frame;
                let inertia = frame.inertia.transformed(&Transform::new(x.rot, x.pos - point));
                let (v, a) = (&w.cvel[b], &w.cacc[b]);
                inertia.mul_motion(a) + v.cross_force(&inertia.mul_motion(v))
            }
        };
        w.cfrc_int[b] = f_body - w.cfrc_ext[b];
    }
    for b in (1..links.len()).rev() {
        let p = links.parent[b];
        if sensed_only && !w.wrench_sensed[p] {
            continue;
        }
        let f = w.cfrc_int[b];
        w.cfrc_int[p] += f;
    }
}

/// The checks of the accessors: `data` made for `model`, `b` a MuJoCo body.
fn check_body(function: &'static str, model: &Model, data: &Data, b: usize) -> Result<(), InputError> {
    check::data(function, model, data)?;
    let count = model.links.len();
    if b >= count || data.rne_post.cacc.len() != count {
        return Err(InputError::Index { function, what: "body", index: b, count });
    }
    Ok(())
}

/// A motion of body b about its point, moved to world point `p_world`: (angular, linear).
fn motion_at(w: &RnePost, b: usize, m: &Motion, p_world: &Vec3) -> (Vec3, Vec3) {
    let offset = p_world - w.subtree_com[w.rootid[b]];
    (m.ang, m.lin + m.ang.cross(&offset))
}

/// A wrench of body b about its point, moved to world point `p_world`: (force, torque about
/// `p_world`).
fn wrench_at(w: &RnePost, b: usize, f: &Force, p_world: &Vec3) -> (Vec3, Vec3) {
    let offset = w.subtree_com[w.rootid[b]] - p_world;
    (f.lin, f.ang + offset.cross(&f.lin))
}

/// MuJoCo body `b`'s spatial acceleration with the gravity offset (MuJoCo's `cacc`) at world
/// point `p_world`, world axes: (angular, linear), the linear part the acceleration of the body
/// point at `p_world` in the spatial sense (without the ω × v of a classical acceleration; see
/// [`object_acceleration`]). From the last [`rne_post_constraint`].
///
/// # Errors
/// [`InputError::Index`] when `b` is not a MuJoCo body of the model (`model.links.len()` of
/// them); [`InputError::Length`] when `data` was made for another model.
pub fn body_acceleration(
    model: &Model,
    data: &Data,
    b: usize,
    p_world: &Vec3,
) -> Result<(Vec3, Vec3), InputError> {
    check_body("body_acceleration", model, data, b)?;
    Ok(body_acceleration_unchecked(data, b, p_world))
}

/// [`body_acceleration`] without the checks.
pub(crate) fn body_acceleration_unchecked(data: &Data, b: usize, p_world: &Vec3) -> (Vec3, Vec3) {
    let w = &data.rne_post;
    motion_at(w, b, &w.cacc[b], p_world)
}

/// MuJoCo's `mj_objectAcceleration` in world axes for a point rigidly attached to MuJoCo body
/// `b` at world position `p_world`: (angular, linear) with linear = the point's classical
/// acceleration minus gravity, `cacc` moved to the point plus MuJoCo's correction ω × v. What an
/// accelerometer at the point measures is `R_siteᵀ · linear` (MuJoCo's accelerometer);
/// framelinacc and frameangacc read linear and angular. A body without degrees of freedom (the
/// world, a body welded to it, a mocap body) reads the world's (0, −g), as MuJoCo 4.0.0 does
/// (checked: its 2026-08 source snapshot still returned zero there). From the last
/// [`rne_post_constraint`].
///
/// # Errors
/// As [`body_acceleration`].
pub fn object_acceleration(
    model: &Model,
    data: &Data,
    b: usize,
    p_world: &Vec3,
) -> Result<(Vec3, Vec3), InputError> {
    check_body("object_acceleration", model, data, b)?;
    Ok(object_acceleration_unchecked(data, b, p_world))
}

/// [`object_acceleration`] without the checks.
pub(crate) fn object_acceleration_unchecked(data: &Data, b: usize, p_world: &Vec3) -> (Vec3, Vec3) {
    let w = &data.rne_post;
    let (alpha, a) = motion_at(w, b, &w.cacc[b], p_world);
    let (omega, v) = motion_at(w, b, &w.cvel[b], p_world);
    (alpha, a + omega.cross(&v))
}

/// MuJoCo's `cfrc_int` of body `b` — the wrench its parent exerts on it through its joint or
/// weld, which carries the body's subtree — about world point `p_world`, world axes: (force,
/// torque about `p_world`). Force and torque sensors at a site read it in the site's axes. For
/// the world (b = 0), MuJoCo's sum of its children's. From the last [`rne_post_constraint`].
///
/// # Errors
/// As [`body_acceleration`].
pub fn interaction_wrench(
    model: &Model,
    data: &Data,
    b: usize,
    p_world: &Vec3,
) -> Result<(Vec3, Vec3), InputError> {
    check_body("interaction_wrench", model, data, b)?;
    Ok(interaction_wrench_unchecked(data, b, p_world))
}

/// [`interaction_wrench`] without the checks.
pub(crate) fn interaction_wrench_unchecked(data: &Data, b: usize, p_world: &Vec3) -> (Vec3, Vec3) {
    let w = &data.rne_post;
    wrench_at(w, b, &w.cfrc_int[b], p_world)
}

/// MuJoCo's `cfrc_ext` of body `b` — applied wrench, contact and connect/weld forces on it —
/// about world point `p_world`, world axes: (force, torque about `p_world`). From the last
/// [`rne_post_constraint`].
///
/// # Errors
/// As [`body_acceleration`].
pub fn external_wrench(
    model: &Model,
    data: &Data,
    b: usize,
    p_world: &Vec3,
) -> Result<(Vec3, Vec3), InputError> {
    check_body("external_wrench", model, data, b)?;
    let w = &data.rne_post;
    Ok(wrench_at(w, b, &w.cfrc_ext[b], p_world))
}
