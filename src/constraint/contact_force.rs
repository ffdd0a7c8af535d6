//! Reading the contacts of the last `forward`: the force of one contact in its contact frame
//! (MuJoCo's `mj_contactForce`, MuJoCo documentation "Programming → Simulation → Contacts"
//! and `mju_decodePyramid`), and an iterator over all contacts with their geoms, bodies,
//! position, frame, distance and force.
//!
//! A contact's rows are consecutive in the `efc_*` buffers with the contact's index in `efc_id`:
//! - frictionless (condim 1): one normal row, its force the normal force;
//! - elliptic cone (condim 3, 4, 6): the normal row then one row per friction direction, the
//!   forces already in the contact frame;
//! - pyramidal cone (MJCF's default): 2(d − 1) edge rows J_n ± μ_i J_i with forces f⁺_i, f⁻_i ≥ 0;
//!   the contact-frame force is f_n = Σ (f⁺_i + f⁻_i) and f_i = μ_i (f⁺_i − f⁻_i), with μ the
//!   contact's `friction` (the decoding MuJoCo's `mj_contactForce` does).
//!
//! The force is the one geom 1 exerts on geom 2, in the contact frame whose first axis is the
//! normal pointing from geom 1 towards geom 2 (a positive normal force pushes them apart).
//! Contacts without rows (farther than their margin, in the gap) have zero force.

use crate::error::InputError;
use crate::model::{Contact, Data, EfcType, Model};
use crate::spatial::{Mat3, Vec3};

/// The rows of contact `i`: (first row, number of rows, kind), or None when it has none.
fn contact_rows(data: &Data, i: usize) -> Option<(usize, usize, EfcType)> {
    let first = (0..data.nefc).find(|&r| data.efc_type[r].is_contact() && data.efc_id[r] == i)?;
    Some((first, data.efc_block_len(first), data.efc_type[first]))
}

/// The force and torque of contact `i` of the last `forward` in its contact frame (MuJoCo's
/// `mj_contactForce`): [normal, tangent 1, tangent 2, torsional, rolling 1, rolling 2], the
/// entries beyond the contact's dimension zero, all zero when the contact has no rows.
///
/// # Errors
/// [`InputError::Index`] when `i` is not a contact of `data` (`data.contacts.len()` of them).
///
/// # Example
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_str(r#"<mujoco><worldbody><geom type="plane" size="1 1 .1"/>
///     <body pos="0 0 0.1"><freejoint/><geom size="0.1" mass="1"/></body></worldbody></mujoco>"#)?;
/// let mut data = Data::new(&model);
/// for _ in 0..500 {
///     step(&model, &mut data)?; // 1 s: the ball settles on the plane
/// }
/// forward(&model, &mut data);
/// let f = contact_force(&model, &data, 0)?;
/// assert!((f[0] - 9.81).abs() < 1e-3, "{f:?}"); // the normal force carries the ball's weight
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn contact_force(model: &Model, data: &Data, i: usize) -> Result<[f64; 6], InputError> {
    let _ = model;
    let count = data.contacts.len();
    if i >= count {
        return Err(InputError::Index { function: "contact_force", what: "contact", index: i, count });
    }
    let mut out = [0.0; 6];
    let Some((r, len, _)) = contact_rows(data, i) else {
        return Ok(out);
    };
    out = block_force(data, r, len);
    Ok(out)
}

/// The contact-frame force of the contact whose `len` rows start at row `r` (a contact's block:
/// [`Data::efc_is_normal`] at `r`, `len` = [`Data::efc_block_len`]): the decoding of
/// [`contact_force`], without the search for the rows.
pub(crate) fn block_force(data: &Data, r: usize, len: usize) -> [f64; 6] {
    let mut out = [0.0; 6];
    let forces = &data.efc_force.as_slice()[r..r + len];
    match data.efc_type[r] {
        EfcType::ContactPyramidal => {
            let friction = &data.contacts[data.efc_id[r]].friction;
            out[0] = forces.iter().sum();
            for k in 0..len / 2 {
                out[k + 1] = friction[k] * (forces[2 * k] - forces[2 * k + 1]);
            }
        }
        _ => out[..len].copy_from_slice(forces),
    }
    out
}

/// One contact of the last `forward`, as [`contacts`] gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactInfo<'a> {
    /// Index in `data.contacts` (MuJoCo's contact id).
    pub index: usize,
    /// The collision data (MuJoCo's `mjContact`).
    pub contact: &'a Contact,
    /// The geoms' names (empty for unnamed geoms).
    pub geom_names: [&'a str; 2],
    /// The geoms' bodies (indices in `Model::bodies`).
    pub body: [usize; 2],
    /// The bodies' names.
    pub body_names: [&'a str; 2],
    /// Whether the contact has constraint rows (closer than its margin): only then a force.
    pub active: bool,
    /// The force and torque in the contact frame ([`contact_force`]).
    pub force: [f64; 6],
}

impl ContactInfo<'_> {
    /// The contact point (midway between the two surfaces), world frame.
    pub fn pos(&self) -> Vec3 {
        self.contact.pos
    }
    /// The contact frame: rows normal (geom 1 → geom 2), tangent 1, tangent 2, world frame.
    pub fn frame(&self) -> Mat3 {
        self.contact.frame
    }
    /// The signed distance (negative: penetration).
    pub fn dist(&self) -> f64 {
        self.contact.dist
    }
    /// The force geom 1 exerts on geom 2, world frame.
    pub fn force_world(&self) -> Vec3 {
        self.contact.frame.transpose() * Vec3::new(self.force[0], self.force[1], self.force[2])
    }
}

/// Every contact of the last `forward`, in MuJoCo's order, with its geoms, bodies, position,
/// frame, distance and force.
///
/// # Example
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_str(r#"<mujoco><worldbody><geom name="floor" type="plane" size="1 1 .1"/>
///     <body name="ball" pos="0 0 0.1"><freejoint/><geom size="0.1" mass="1"/></body></worldbody></mujoco>"#)?;
/// let mut data = Data::new(&model);
/// forward(&model, &mut data);
/// for c in contacts(&model, &data) {
///     println!("{} on {}: normal force {:.3} N", c.geom_names[0], c.body_names[1], c.force[0]);
/// }
/// assert_eq!(contacts(&model, &data).count(), 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn contacts<'a>(model: &'a Model, data: &'a Data) -> impl Iterator<Item = ContactInfo<'a>> + 'a {
    data.contacts.iter().enumerate().map(move |(index, contact)| {
        let [g1, g2] = contact.geom;
        let body = [model.geoms[g1].body, model.geoms[g2].body];
        let force = contact_force(model, data, index).unwrap_or_default();
        ContactInfo {
            index,
            contact,
            geom_names: [model.geoms[g1].name.as_str(), model.geoms[g2].name.as_str()],
            body,
            body_names: body.map(|b| model.bodies[b].name.as_str()),
            active: contact_rows(data, index).is_some(),
            force,
        }
    })
}
