//! The life cycle of the limit and contact rows within one step of the exact mode: which rows
//! exist at each stage, and which friction keeps its sticking law (`docs/architecture.md`,
//! "The row life cycle").
//!
//! Outside a step a row exists by distance: a joint within its limit's activation distance, a
//! contact closer than [`CONTACT_ACTIVE_DISTANCE`](super::CONTACT_ACTIVE_DISTANCE). Within a
//! step that rule alone is wrong twice over:
//! - A multi-stage stepper (RK4, the adaptive method) evaluates `forward` at configurations the
//!   step will not end at. A contact that a stage lifts off by round-off or by the integrator's
//!   error would lose its row in that stage and the stages would solve different problems: the
//!   step is no longer the method it claims to be. So after the first stage the rows are
//!   **frozen**: every row the step started with exists in the later stages whatever its
//!   distance, and no row counts as separating.
//! - Friction that was at rest when the rows were frozen (slip at most
//!   [`SLIP_VELOCITY`](crate::model::SLIP_VELOCITY)) keeps its sticking law in the later stages:
//!   a stage's velocity carries the integrator's O(h²) slip, which is no slip.
//! - The drift correction after the last stage freezes the rows still pressing, and adds every
//!   row the position projection corrects, so that a sustained contact stays closed through the
//!   projection (a corner pushed out of the floor stays a row even where a Gauss–Newton step
//!   overshoots) and the velocity projection that follows sees it too.
//!
//! The steppers call [`Data::freeze_rows`] after their first stage and [`Data::thaw_rows`] at
//! the end of the step; [`RowLifecycle`] holds what is frozen, and the row builders ask it
//! ([`Data::contact_is_frozen`], [`RowLifecycle::keeps_limit`], [`Data::efc_frozen_at_rest`]).
//! The soft mode has no life cycle: its rows follow MuJoCo's activation rules at every stage.

use crate::model::{Contact, Data, EfcType, Model, SLIP_VELOCITY};

/// What is frozen within a step (see the module documentation).
#[derive(Clone, Debug)]
pub(crate) struct RowLifecycle {
    /// Whether rows are frozen (between `freeze_rows` and `thaw_rows`).
    frozen: bool,
    /// The limited joints (index in `Model::joints`) with a row when frozen.
    limits: Vec<usize>,
    /// The contacts (geom pair and feature, see `Contact::feature`) with a row when frozen.
    contacts: Vec<([usize; 2], u32)>,
    /// Of the frozen rows, the contacts and friction-loss dofs that were at rest when frozen.
    sticking: Vec<([usize; 2], u32)>,
    sticking_dofs: Vec<usize>,
}

impl RowLifecycle {
    /// Room for every limited joint and every contact `model` can report (no allocation later).
    pub fn new(model: &Model) -> Self {
        Self {
            frozen: false,
            limits: Vec::with_capacity(model.joints.len()),
            contacts: Vec::with_capacity(model.max_contacts().min(crate::model::INITIAL_CONTACTS)),
            sticking: Vec::with_capacity(model.max_contacts().min(crate::model::INITIAL_CONTACTS)),
            sticking_dofs: Vec::with_capacity(model.nv),
        }
    }

    /// Whether rows are frozen.
    pub fn is_frozen(&self) -> bool {
        self.frozen
    }

    /// Whether the limit of joint `joint` keeps its row while rows are frozen.
    pub fn keeps_limit(&self, joint: usize) -> bool {
        self.frozen && self.limits.contains(&joint)
    }
}

impl Data {
    /// Freezes the current limit and contact rows (with `pressing_only`, those whose force is
    /// positive): until [`thaw_rows`](Self::thaw_rows) they keep a row whatever their distance,
    /// and the friction at rest keeps its sticking law (the module documentation of
    /// `constraint::row_lifecycle` says why).
    pub fn freeze_rows(&mut self, pressing_only: bool) {
        let life = &mut self.lifecycle;
        life.limits.clear();
        life.contacts.clear();
        life.sticking.clear();
        life.sticking_dofs.clear();
        self.add_frozen_rows(pressing_only);
        let mut i = 0;
        while i < self.nefc {
            let len = self.efc_block_len(i);
            let slip = (i + 1..i + len).map(|k| self.efc_vel[k].abs()).fold(0.0, f64::max);
            let life = &mut self.lifecycle;
            match self.efc_type[i] {
                EfcType::FrictionDof if self.efc_vel[i].abs() <= SLIP_VELOCITY => {
                    life.sticking_dofs.push(self.efc_id[i])
                }
                EfcType::ContactElliptic if slip <= SLIP_VELOCITY => {
                    let c = &self.contacts[self.efc_id[i]];
                    if life.sticking.len() < life.sticking.capacity() {
                        life.sticking.push((c.geom, c.feature));
                    }
                }
                _ => {}
            }
            i += len;
        }
    }

    /// Whether the friction of row block `i` (a contact's normal row or a friction-loss row) keeps
    /// its sticking law because rows are frozen and it was at rest when frozen.
    pub fn efc_frozen_at_rest(&self, i: usize) -> bool {
        let life = &self.lifecycle;
        life.frozen
            && match self.efc_type[i] {
                EfcType::FrictionDof => life.sticking_dofs.contains(&self.efc_id[i]),
                EfcType::ContactElliptic => {
                    let c = &self.contacts[self.efc_id[i]];
                    life.sticking.contains(&(c.geom, c.feature))
                }
                _ => false,
            }
    }

    /// Adds the current limit and contact rows (with `pressing_only`, those whose force is
    /// positive) to the frozen ones and freezes: the position projection keeps every row it
    /// corrects until it lands on φ = 0, so the velocity projection that follows sees it too.
    pub fn add_frozen_rows(&mut self, pressing_only: bool) {
        for i in 0..self.nefc {
            if pressing_only && self.efc_force[i] <= 0.0 {
                continue;
            }
            let normal = self.efc_is_normal(i);
            let life = &mut self.lifecycle;
            match self.efc_type[i] {
                EfcType::LimitJoint if !life.limits.contains(&self.efc_id[i]) => {
                    life.limits.push(self.efc_id[i])
                }
                EfcType::ContactFrictionless | EfcType::ContactElliptic if normal => {
                    let c = &self.contacts[self.efc_id[i]];
                    let key = (c.geom, c.feature);
                    if !life.contacts.contains(&key) && life.contacts.len() < life.contacts.capacity() {
                        life.contacts.push(key);
                    }
                }
                _ => {}
            }
        }
        self.lifecycle.frozen = true;
    }

    /// Whether contact `c` keeps a row while rows are frozen.
    pub fn contact_is_frozen(&self, c: &Contact) -> bool {
        self.lifecycle.frozen && self.lifecycle.contacts.contains(&(c.geom, c.feature))
    }

    /// Whether rows are frozen (within a step, between [`freeze_rows`](Self::freeze_rows) and
    /// [`thaw_rows`](Self::thaw_rows)).
    pub fn rows_frozen(&self) -> bool {
        self.lifecycle.is_frozen()
    }

    /// Ends the frozen stages of a step: rows are again chosen by distance.
    pub fn thaw_rows(&mut self) {
        self.lifecycle.frozen = false;
    }
}
