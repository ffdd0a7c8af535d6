//! Run-time warnings kept in [`Data`]: MuJoCo's `d->warning` counters (`mjWARN_INERTIA`,
//! `mjWARN_BADCTRL`; engine_forward.c, engine_core_smooth.c) for the conditions that lagrange,
//! like MuJoCo 4.0, corrects and carries on from instead of failing.
//!
//! Each kind counts how many times it was raised since the [`Data`] was made (or the counters
//! were cleared by [`Warnings::clear`]) and keeps the index of the last element it concerned
//! (MuJoCo's `lastinfo`). [`Warnings::messages`] words them, naming the joints or actuators.

use super::{Data, Model};

/// MuJoCo's `mjMINVAL`: the smallest pivot of the mass matrix's LᵀDL factor; a smaller (or
/// negative) one is raised to it with an [`Warnings::inertia`] warning.
pub const MIN_PIVOT: f64 = 1e-15;

/// MuJoCo's `mjMAXVAL`: a control (after its `ctrlrange` clamp) larger in magnitude, or NaN, is
/// bad (`mju_isBad`): every control is then taken as zero, with a [`Warnings::bad_ctrl`] warning.
pub const MAX_CTRL: f64 = 1e10;

/// One kind of warning: how many times it was raised and the index it last concerned.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WarningStat {
    /// Times raised (MuJoCo's `number`).
    pub number: u64,
    /// The element it last concerned (MuJoCo's `lastinfo`): a dof or an actuator index.
    pub last_info: usize,
}

impl WarningStat {
    fn raise(&mut self, info: usize) {
        self.number += 1;
        self.last_info = info;
    }
}

/// The run-time warnings of one [`Data`].
#[derive(Clone, Debug, Default)]
pub struct Warnings {
    /// `mjWARN_INERTIA`: the mass matrix was singular (or not positive) at the state: a pivot of
    /// its factor was below [`MIN_PIVOT`] and was raised to it, as MuJoCo 4.0 does, so the
    /// accelerations are MuJoCo's regularized ones (zero along the lost direction when no force
    /// acts on it, very large when one does). `last_info`: the first dof raised in the
    /// factorization's order (the highest index), as MuJoCo reports it.
    pub inertia: WarningStat,
    /// Per dof, whether its pivot was raised at the latest factorization (the joints a message
    /// names).
    pub inertia_dofs: Vec<bool>,
    /// `mjWARN_BADCTRL`: a control was NaN, ±∞ or beyond ±[`MAX_CTRL`] after its range clamp;
    /// all controls were taken as zero for that evaluation (`data.ctrl` itself is left as set).
    /// `last_info`: the first bad actuator.
    pub bad_ctrl: WarningStat,
    /// A free or ball joint's quaternion in `qpos` was zero (or shorter than 1e-15) at a
    /// `forward` or the start of a `step`: it reads as the identity, as MuJoCo's `mju_normalize4`
    /// makes it (MuJoCo itself does not warn). `last_info`: the joint (index in `Model::joints`).
    pub zero_quat: WarningStat,
    /// MuJoCo's `mjWARN_CONTACTFULL`: a collision pass found more contacts than
    /// [`Model::contact_budget`] keeps and dropped the rest (MuJoCo drops them when its arena is
    /// full). `last_info`: the contacts that pass found, kept and dropped.
    pub contact_full: WarningStat,
    /// The simulation time of the last pass that raised [`Self::contact_full`].
    pub contact_full_time: f64,
}

impl Warnings {
    /// No warning, for a model with `nv` dofs.
    pub fn new(nv: usize) -> Self {
        Warnings { inertia_dofs: vec![false; nv], ..Default::default() }
    }

    /// Whether any warning was raised.
    pub fn any(&self) -> bool {
        self.inertia.number > 0
            || self.bad_ctrl.number > 0
            || self.zero_quat.number > 0
            || self.contact_full.number > 0
    }

    /// Resets every counter (MuJoCo's `mj_resetData` does).
    pub fn clear(&mut self) {
        self.inertia = WarningStat::default();
        self.bad_ctrl = WarningStat::default();
        self.zero_quat = WarningStat::default();
        self.contact_full = WarningStat::default();
        self.contact_full_time = 0.0;
        self.inertia_dofs.fill(false);
    }

    /// Records the pivot of dof `k` raised to [`MIN_PIVOT`] (called during the factorization).
    pub(crate) fn pivot_raised(&mut self, k: usize) {
        self.inertia_dofs[k] = true;
    }

    /// Counts the free and ball joints whose quaternion in `q` is zero (they read as the identity).
    pub(crate) fn check_quaternions(&mut self, model: &Model, q: &[f64]) {
        for (j, joint) in model.joints.iter().enumerate() {
            let off = match joint.kind {
                super::JointKind::Free => 3,
                super::JointKind::Ball => 0,
                _ => continue,
            };
            let a = joint.qpos_adr + off;
            let n2: f64 = q[a..a + 4].iter().map(|x| x * x).sum();
            if n2.sqrt() < 1e-15 {
                self.zero_quat.raise(j);
            }
        }
    }

    /// Records a bad control at actuator `i`.
    pub(crate) fn bad_control(&mut self, i: usize) {
        self.bad_ctrl.raise(i);
    }

    /// Counts a collision pass at `time` that found `found` contacts, more than it keeps.
    pub(crate) fn contacts_full(&mut self, found: usize, time: f64) {
        self.contact_full.raise(found);
        self.contact_full_time = time;
    }

    /// Counts one singular factorization (after its pivots were recorded); `first`: the first
    /// dof raised in the factorization's order (last to first), MuJoCo's `lastinfo`.
    pub(crate) fn singular_factor(&mut self, first: usize) {
        self.inertia.raise(first);
    }

    /// The warnings raised, worded for a user, naming the joints and the actuator: one line per
    /// kind raised (empty when none was).
    pub fn messages(&self, model: &Model) -> Vec<String> {
        let mut out = Vec::new();
        if self.inertia.number > 0 {
            let mut joints: Vec<&str> = Vec::new();
            for (k, _) in self.inertia_dofs.iter().enumerate().filter(|(_, &raised)| raised) {
                let name = model.joint_of(model.dof_body[k]).name.as_str();
                if !joints.contains(&name) {
                    joints.push(name);
                }
            }
            out.push(format!(
                "the mass matrix was singular {} time(s) (last at the joint(s) {}): a pivot of its \
                 factor below {MIN_PIVOT:e} was raised to it, as MuJoCo does (mjWARN_INERTIA); \
                 the accelerations along the lost direction are regularized, not physical: check \
                 for duplicated joints or bodies without mass or inertia",
                self.inertia.number,
                joints.iter().map(|n| format!("'{n}'")).collect::<Vec<_>>().join(", ")
            ));
        }
        if self.bad_ctrl.number > 0 {
            let i = self.bad_ctrl.last_info;
            let name = model.actuators.get(i).map(|a| a.name.as_str()).unwrap_or("");
            out.push(format!(
                "a control was NaN, infinite or beyond ±{MAX_CTRL:e} {} time(s) (last at the \
                 actuator '{name}', index {i}): all controls were taken as zero, as MuJoCo does \
                 (mjWARN_BADCTRL)",
                self.bad_ctrl.number
            ));
        }
        if self.zero_quat.number > 0 {
            let j = self.zero_quat.last_info;
            let name = model.joints.get(j).map(|j| j.name.as_str()).unwrap_or("");
            out.push(format!(
                "a zero quaternion in qpos {} time(s) (last at the joint '{name}'): it was read as the \
                 identity, as MuJoCo's mju_normalize4 does; set a unit quaternion [1, 0, 0, 0] for \
                 the joint's orientation",
                self.zero_quat.number
            ));
        }
        if self.contact_full.number > 0 {
            out.push(format!(
                "{} collision pass(es) found more contacts than the {} kept (last at t = {} s: {} \
                 found), as MuJoCo's mjWARN_CONTACTFULL: the rest were dropped, so bodies may sink \
                 into each other; exclude pairs that need not touch (<contact><exclude>, \
                 contype/conaffinity), raise the budget (--max-contacts, Options::max_contacts; \
                 memory grows with it){}",
                self.contact_full.number,
                model.contact_budget(),
                self.contact_full_time,
                self.contact_full.last_info,
                if model.dense_contact_rows() {
                    ", or use the soft mode's Newton or CG solver without no-slip, which keeps more"
                } else {
                    ""
                }
            ));
        }
        out
    }
}

/// The warnings of `data`, worded ([`Warnings::messages`]).
pub fn warning_messages(model: &Model, data: &Data) -> Vec<String> {
    data.warnings.messages(model)
}
