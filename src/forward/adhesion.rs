//! The body (adhesion) transmission: MuJoCo's `mj_transmission`, case `mjTRN_BODY`
//! (engine_core_smooth.c), used by `<adhesion>` and `<general body="...">`.
//!
//! The length is 0. The moment is minus the average, over the contacts of the last collision
//! pass that involve a geom of the body, of the contact normal's row of the contact Jacobian
//!
//!   moment = −(1/n) Σ_c n_cᵀ (J_{b2}(p_c) − J_{b1}(p_c)),
//!
//! (n_c from geom1 towards geom2, p_c the contact point, b1 and b2 the geoms' bodies), so that a
//! positive force pulls the body's geom towards the other. Contacts with constraint rows and
//! contacts in the gap (reported without rows) both count, as in MuJoCo (its `exclude` 0 and 1);
//! MuJoCo's pyramidal-cone average of the pyramid rows equals the normal row. Contacts beyond
//! margin + gap (the exact mode's collision reports a little further) do not count. Without a
//! contact the moment is zero. Checked against MuJoCo 4.0.0 by
//! `validation/mujoco_adhesion_golden.py` (tests/adhesion_mujoco.rs).

use crate::kinematics::for_each_ancestor_dof_at;
use crate::model::{Contact, Model};
use crate::spatial::{Motion, Transform};
use nalgebra::DMatrix;

/// Whether contact `c` counts for the body transmission of body `body`.
fn counts(model: &Model, c: &Contact, body: usize) -> bool {
    let (b1, b2) = (model.geoms[c.geom[0]].body, model.geoms[c.geom[1]].body);
    (b1 == body || b2 == body) && c.dist < c.includemargin + c.gap
}

/// Writes into row `i` of `moment` (zeroed by the caller) the moment of a body transmission on
/// `body` from `contacts`; `x_world_body` and `s_body` hold the kinematics the contacts were
/// found at.
pub(crate) fn body_moment(
    model: &Model,
    contacts: &[Contact],
    x_world_body: &[Transform],
    s_body: &[Motion],
    body: usize,
    moment: &mut DMatrix<f64>,
    i: usize,
) {
    let n = contacts.iter().filter(|c| counts(model, c, body)).count();
    if n == 0 {
        return;
    }
    let scale = -1.0 / n as f64;
    for c in contacts.iter().filter(|c| counts(model, c, body)) {
        let normal = c.frame.row(0).transpose();
        let (b1, b2) = (model.geoms[c.geom[0]].body, model.geoms[c.geom[1]].body);
        for_each_ancestor_dof_at(model, x_world_body, s_body, b2, &c.pos, |k, lin, _| {
            moment[(i, k)] += scale * normal.dot(&lin);
        });
        for_each_ancestor_dof_at(model, x_world_body, s_body, b1, &c.pos, |k, lin, _| {
            moment[(i, k)] -= scale * normal.dot(&lin);
        });
    }
}

/// Why a body transmission on `body` cannot follow MuJoCo: the compiled body merges the geoms
/// of several MJCF bodies (a body welded to its parent), whose contacts MuJoCo tells apart.
pub(crate) fn unsupported_reason(model: &Model, body: usize) -> Option<&'static str> {
    let mut links = model.geoms.iter().filter(|g| g.body == body && g.collision).map(|g| &g.link);
    let first = links.next()?;
    links
        .any(|l| l != first)
        .then_some("a body (adhesion) transmission on a body merged with its welded bodies")
}
