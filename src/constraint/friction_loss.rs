//! Dry friction of joints (`frictionloss`) as bounded rows (MuJoCo documentation, "Computation →
//! Constraint model → Friction loss"; MuJoCo's `mjCNSTR_FRICTION_DOF`): one row per degree of
//! freedom of a joint with friction loss f > 0, J = e_dof, always present. Its force obeys
//! Coulomb's law on the dof: |λ| ≤ f, and λ = −f sign(q̇) while the dof moves; at rest the row
//! sticks (row acceleration 0) as long as the force needed stays within ±f. A ball or free joint's
//! friction loss acts on each of its dofs, as in MuJoCo.

use crate::model::{Data, EfcType, Model};

/// One dof with friction loss.
#[derive(Clone, Debug, PartialEq)]
pub struct FrictionRow {
    /// Index in `Model::joints`.
    pub joint: usize,
    /// Index of the dof in `qvel`.
    pub dof: usize,
    /// The bound f on |λ| (N or N·m).
    pub loss: f64,
}

impl FrictionRow {
    /// The friction rows of every joint of `model` with a positive friction loss.
    pub fn of_model(model: &Model) -> Vec<Self> {
        let mut rows = Vec::new();
        for (joint, j) in model.joints.iter().enumerate() {
            if j.friction > 0.0 {
                for dof in j.dof_adr..j.dof_adr + j.kind.nv() {
                    rows.push(Self { joint, dof, loss: j.friction });
                }
            }
        }
        rows
    }

    /// Writes the row into `efc_*` row `r` (`efc_id` is the dof, as MuJoCo's).
    pub(crate) fn write_row(&self, data: &mut Data, r: usize) {
        data.efc_id[r] = self.dof;
        data.efc_type[r] = EfcType::FrictionDof;
        // Row r of J cleared through its storage (every nrows-th entry): no index
        // checks per entry.
        let stride = data.efc_j.nrows();
        for x in data.efc_j.as_mut_slice()[r..].iter_mut().step_by(stride) {
            *x = 0.0;
        }
        data.efc_j[(r, self.dof)] = 1.0;
        data.efc_pos[r] = 0.0;
    }
}
