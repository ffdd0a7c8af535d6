//! The `touch` sensor (MuJoCo's engine_sensor.c, `mjSENS_TOUCH`; MuJoCo documentation "XML
//! Reference → sensor → touch"): the sum of the normal forces of the contacts on the site's body
//! whose normal ray, cast from the contact point into that body, meets the site's zone.
//!
//! All the touch sensors of a model are formed in one pass over the contacts' constraint rows
//! ([`touch_all`]): each contact's normal force is decoded once
//! ([`block_force`](crate::constraint::contact_force::block_force)) and offered to the sensors
//! on its two bodies (listed per body, [`TouchSites`]), instead of each sensor searching every contact's rows. The forces are
//! summed per sensor in the contacts' order, as the per-sensor definition ([`touch`]) does, so
//! that both give the same bits; the pass falls back to [`touch`] when the rows are not in the
//! contacts' order.

use super::types::{Sensor, SensorObject, SensorType};
use crate::collision::ray::ray_meets_primitive;
use crate::constraint::contact_force::{block_force, contact_force};
use crate::model::{Contact, Data, Model};

/// MuJoCo's `mjMINVAL`.
const MINVAL: f64 = 1e-15;

/// A computed touch sensor on a site (one without a shape reads zero).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct TouchSite {
    /// Its address in `sensordata`.
    adr: usize,
    /// Its site frame.
    frame: usize,
    /// The MuJoCo body carrying the site (`Model::links`).
    body: usize,
}

/// The computed touch sensors of a model on sites (the ones [`touch_all`] writes), grouped by
/// MuJoCo body.
#[derive(Clone, Debug, Default)]
pub(crate) struct TouchSites {
    /// The sensors, by body (in sensor order within a body).
    sites: Vec<TouchSite>,
    /// Body b's sensors are `sites[start[b]..start[b + 1]]`.
    start: Vec<usize>,
}

impl TouchSites {
    /// The touch sensors of `model`.
    pub(crate) fn new(model: &Model) -> Self {
        let mut sites: Vec<TouchSite> = model
            .sensors
            .iter()
            .filter(|s| s.is_computed() && s.kind == SensorType::Touch)
            .filter_map(|s| match s.object {
                SensorObject::Site(f) => {
                    Some(TouchSite { adr: s.adr, frame: f, body: model.links.of_frame[f] })
                }
                _ => None,
            })
            .collect();
        sites.sort_by_key(|t| t.body);
        let nbody = model.links.len();
        let start = (0..=nbody).map(|b| sites.partition_point(|t| t.body < b)).collect();
        TouchSites { sites, start }
    }

    /// The sensors on MuJoCo body `b`.
    fn on(&self, b: usize) -> &[TouchSite] {
        match (self.start.get(b), self.start.get(b + 1)) {
            (Some(&lo), Some(&hi)) => &self.sites[lo..hi],
            _ => &[],
        }
    }
}

/// Whether `s` is written by [`touch_all`] (a touch sensor on a site).
pub(crate) fn is_touch_site(s: &Sensor) -> bool {
    s.kind == SensorType::Touch && matches!(s.object, SensorObject::Site(_))
}

/// Whether the contact's normal ray, cast from the contact point into the touch sensor `t`'s
/// body, meets its site's zone. `bodies` are the contact's geoms' bodies, one of them the
/// sensor's.
fn meets(model: &Model, data: &Data, t: &TouchSite, contact: &Contact, bodies: [usize; 2]) -> bool {
    let Some(shape) = model.frames[t.frame].site else { return false };
    // The normal's direction, pointing into the sensor's body.
    let mut ray = contact.frame.row(0).transpose();
    ray /= ray.norm().max(MINVAL);
    if t.body == bodies[1] {
        ray = -ray;
    }
    ray_meets_primitive(&data.x_world_frame[t.frame], &shape, &contact.pos, &ray)
}

/// The touch sensor `t` alone: every contact on its body, in the contacts' order.
fn touch_one(model: &Model, data: &Data, t: &TouchSite) -> f64 {
    let mut total = 0.0;
    for (c, contact) in data.contacts.iter().enumerate() {
        let bodies = contact.geom.map(|g| model.links.of_geom[g]);
        if t.body != bodies[0] && t.body != bodies[1] {
            continue;
        }
        let normal_force = contact_force(model, data, c).map_or(0.0, |w| w[0]);
        if normal_force <= 0.0 {
            continue;
        }
        if meets(model, data, t, contact, bodies) {
            total += normal_force;
        }
    }
    total
}

/// Every touch sensor of `touch` into `sensordata`, after a `forward` (its contacts and
/// constraint forces) and with the site frames at the state.
pub(crate) fn touch_all(model: &Model, data: &Data, touch: &TouchSites, sensordata: &mut [f64]) {
    if touch.sites.is_empty() {
        return;
    }
    for t in &touch.sites {
        sensordata[t.adr] = 0.0;
    }
    // One pass over the contacts' blocks of rows, in row order: the contacts' order while their
    // indices increase.
    let mut last: Option<usize> = None;
    let mut r = 0;
    while r < data.nefc {
        if !data.efc_type[r].is_contact() {
            r += 1;
            continue;
        }
        let len = data.efc_block_len(r);
        let c = data.efc_id[r];
        if last.is_some_and(|l| c <= l) {
            // Rows out of the contacts' order: each sensor on its own, in the contacts' order.
            for t in &touch.sites {
                sensordata[t.adr] = touch_one(model, data, t);
            }
            return;
        }
        last = Some(c);
        if let Some(contact) = data.contacts.get(c) {
            let bodies = contact.geom.map(|g| model.links.of_geom[g]);
            let mut normal_force = None;
            // The sensors of geom 1's body, then of geom 2's (once for a contact within a body).
            let second = if bodies[1] == bodies[0] { &[][..] } else { touch.on(bodies[1]) };
            for t in touch.on(bodies[0]).iter().chain(second) {
                let f = *normal_force.get_or_insert_with(|| block_force(data, r, len)[0]);
                if f <= 0.0 {
                    break;
                }
                if meets(model, data, t, contact, bodies) {
                    sensordata[t.adr] += f;
                }
            }
        }
        r += len;
    }
}
