//! `lagrange.Contact`: one contact of the last collision pass (MuJoCo's `mjContact`) with its
//! force in the contact frame (MuJoCo's `mj_contactForce`).

use crate::error;
use lagrange::{Data, Model};
use pyo3::prelude::*;

/// One contact: the geoms (`geom1`, `geom2`) and their bodies (MuJoCo's body ids), the midpoint
/// `pos`, the `frame` (3 × 3, rows: the normal from geom1 towards geom2, tangent1, tangent2),
/// the signed distance `dist` (negative: penetration), `condim`, `friction`, whether it has
/// constraint rows (`active`) and `force`: normal, tangent1, tangent2, then torsional and rolling
/// torques, in the contact frame, as `lagrange.contact_force`.
#[pyclass(name = "Contact", module = "lagrange", frozen, get_all)]
pub struct PyContact {
    /// Index of the first geom (MuJoCo's geom1).
    pub geom1: usize,
    /// Index of the second geom.
    pub geom2: usize,
    /// MuJoCo body id of geom1's body.
    pub body1: usize,
    /// MuJoCo body id of geom2's body.
    pub body2: usize,
    /// Midpoint between the surfaces (world frame).
    pub pos: [f64; 3],
    /// Rows: normal, tangent1, tangent2 (world frame).
    pub frame: [[f64; 3]; 3],
    /// Signed distance (m).
    pub dist: f64,
    /// Contact dimension (1, 3, 4 or 6).
    pub condim: u32,
    /// Friction: tangent1, tangent2, torsional, rolling1, rolling2.
    pub friction: [f64; 5],
    /// Whether the contact has constraint rows (within its margin).
    pub active: bool,
    /// Force and torque in the contact frame (6 numbers, as mj_contactForce).
    pub force: [f64; 6],
}

impl PyContact {
    /// Contact `i` of `data`.
    pub fn of(model: &Model, data: &Data, i: usize) -> PyResult<Self> {
        let c = &data.contacts[i];
        let f = &c.frame;
        let force = lagrange::prelude::contact_force(model, data, i).map_err(error::input)?;
        Ok(PyContact {
            geom1: c.geom[0],
            geom2: c.geom[1],
            body1: model.links.of_geom[c.geom[0]],
            body2: model.links.of_geom[c.geom[1]],
            pos: [c.pos.x, c.pos.y, c.pos.z],
            frame: [0, 1, 2].map(|r| [f[(r, 0)], f[(r, 1)], f[(r, 2)]]),
            dist: c.dist,
            condim: c.condim,
            friction: c.friction,
            active: lagrange::prelude::contacts(model, data).nth(i).is_some_and(|info| info.active),
            force,
        })
    }
}

#[pymethods]
impl PyContact {
    fn __repr__(&self) -> String {
        format!(
            "lagrange.Contact(geom1={}, geom2={}, dist={:.3e}, force={:?})",
            self.geom1, self.geom2, self.dist, self.force
        )
    }
}
