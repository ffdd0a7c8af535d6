//! What the actuation stage ([`actuation`](super::actuation)) needs to know about each actuator
//! that does not change from one evaluation to the next, worked out once per model (part of the
//! [`Plan`](super::Plan), docs/architecture.md "Layers"): whether the actuator is simulated
//! ([`unsimulated_reason`](crate::model::actuator::unsimulated_reason)), where its activation
//! is, which dofs its moment row can reach ([`moment_span`](super::transmission::moment_span)),
//! and whether its transmission is a joint transmission on a hinge or slide joint — MuJoCo's
//! commonest actuator, whose length is gear₀ · q and whose moment row is gear₀ at one dof
//! ([`transmission`](super::transmission)'s table), which the stage then forms directly.
//! Beside them: whether any simulated transmission needs body poses, and whether any tendon or
//! joint has an `actuatorfrcrange`. The parameters (gear, gains, ranges) are read from the model
//! at every evaluation; only the structure is kept here.

use super::transmission::{moment_span, needs_poses};
use crate::model::actuator::{unsimulated_reason, Actuator, Transmission};
use crate::model::{JointKind, Model};

/// One actuator's entry in the [`ActuatorLayout`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ActuatorEntry {
    /// Whether the actuation stage simulates it (no [`unsimulated_reason`]).
    pub simulated: bool,
    /// Its activation's index in `act` (None without activation dynamics).
    pub act: Option<usize>,
    /// The first dof of its moment span (the dofs its moment row can be nonzero at).
    pub span_start: usize,
    /// One past the last dof of its moment span.
    pub span_end: usize,
    /// For a joint (or joint-in-parent) transmission on a hinge or slide joint: the joint's
    /// `qpos` address and its dof.
    pub one_dof: Option<(usize, usize)>,
}

impl ActuatorEntry {
    /// The entry of actuator `a` of `model`, whose activation (if any) is at `act_adr`.
    pub fn of(model: &Model, a: &Actuator, act_adr: usize) -> Self {
        let span = moment_span(model, a);
        let one_dof = match a.transmission {
            Transmission::Joint(j) | Transmission::JointInParent(j) => {
                let joint = &model.joints[j];
                matches!(joint.kind, JointKind::Revolute { .. } | JointKind::Prismatic { .. })
                    .then_some((joint.qpos_adr, joint.dof_adr))
            }
            _ => None,
        };
        Self {
            simulated: unsimulated_reason(model, a).is_none(),
            act: (a.actnum() == 1).then_some(act_adr),
            span_start: span.start,
            span_end: span.end,
            one_dof,
        }
    }

    /// The dofs its moment row can be nonzero at.
    pub fn span(&self) -> std::ops::Range<usize> {
        self.span_start..self.span_end
    }
}

/// The actuators' per-model layout for the actuation stage.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ActuatorLayout {
    /// One entry per actuator, in the model's order.
    pub entries: Vec<ActuatorEntry>,
    /// Whether a simulated actuator's transmission needs body and site poses.
    pub needs_poses: bool,
    /// Whether a tendon has an `actuatorfrcrange` (the stage's tendon force scaling).
    pub tendon_force_range: bool,
    /// The joints with an `actuatorfrcrange`, in the model's order.
    pub force_range_joints: Vec<usize>,
}

impl ActuatorLayout {
    /// The layout of `model`'s actuators.
    pub fn new(model: &Model) -> Self {
        let mut act_adr = 0;
        let entries = model
            .actuators
            .iter()
            .map(|a| {
                let entry = ActuatorEntry::of(model, a, act_adr);
                act_adr += a.actnum();
                entry
            })
            .collect::<Vec<_>>();
        let needs_poses = model.actuators.iter().zip(&entries).any(|(a, e)| e.simulated && needs_poses(a));
        Self {
            entries,
            needs_poses,
            tendon_force_range: model.tendons.iter().any(|t| t.actuator_force_range.is_some()),
            force_range_joints: (0..model.joints.len())
                .filter(|&j| model.joints[j].actuator_force_range.is_some())
                .collect(),
        }
    }

    /// Whether the layout was made for `model`'s actuators (one entry each); the stage works
    /// each entry out as it goes otherwise (a model whose plan is not built yet).
    pub fn fits(&self, model: &Model) -> bool {
        self.entries.len() == model.actuators.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_follow_the_transmissions() {
        let model = Model::from_str(
            r#"<mujoco><worldbody>
              <body><joint name="h" type="hinge"/><geom size="0.1"/>
                <body><joint name="s" type="slide"/><geom size="0.1"/>
                  <body><joint name="b" type="ball"/><geom size="0.1"/><site name="t"/></body>
                </body>
              </body>
            </worldbody>
            <actuator>
              <motor joint="h" gear="2"/>
              <position joint="s" kp="10"/>
              <general joint="b" dyntype="integrator"/>
              <motor site="t"/>
              <general joint="h" dyntype="user"/>
            </actuator></mujoco>"#,
        )
        .unwrap();
        let layout = &model.plan.actuators;
        assert!(layout.fits(&model));
        assert_eq!(*layout, ActuatorLayout::new(&model));
        let e = &layout.entries;
        let (h, s, b) = (&model.joints[0], &model.joints[1], &model.joints[2]);
        assert_eq!(e[0].one_dof, Some((h.qpos_adr, h.dof_adr)));
        assert_eq!(e[1].one_dof, Some((s.qpos_adr, s.dof_adr)));
        assert_eq!((e[2].one_dof, e[2].act, e[2].span()), (None, Some(0), b.dof_adr..b.dof_adr + 3));
        assert_eq!((e[3].one_dof, e[3].span()), (None, 0..model.nv));
        assert!(e[..4].iter().all(|e| e.simulated));
        assert_eq!((e[4].simulated, e[4].act), (false, Some(1)));
        assert!(layout.needs_poses);
        assert!(!layout.tendon_force_range && layout.force_range_joints.is_empty());
    }
}
