//! MuJoCo 4's `contact` sensor (`mjSENS_CONTACT`, engine_sensor.c): the contacts matching up to
//! two criteria (a site's zone, a body, a subtree or a geom on either side), reduced to `num` slots
//! — the first found, the nearest (`mindist`), the strongest (`maxforce`) or one net wrench
//! (`netforce`) — each slot holding the requested fields: found (the number of matches), force and
//! torque in the contact frame, distance, position, normal, first tangent, and the velocity of
//! geom 2's body relative to geom 1's at the contact point (linear, angular; contact frame,
//! MuJoCo 4.0's `linvel`, `angvel`). The normal points
//! away from the first criterion's object: where the contact lists that object second, the slot's
//! frame is turned half a turn about the tangent-2 axis (normal and tangent negated, the z of force
//! and torque negated, MuJoCo's `copySensorData`).
//!
//! `netforce`: the matched contacts' wrenches (each negated when flipped) summed in world axes
//! about their force-weighted centroid p = Σ |f_i| p_i / Σ |f_i|, τ = Σ (R_iᵀ τ_i + (p_i − p) × R_iᵀ f_i).

use super::objects::point_velocity;
use super::types::{ContactSensorSpec, Sensor, SensorObject, CONTACT_FIELDS};
use crate::constraint::contact_force::contact_force;
use crate::model::{Data, Model};
use crate::spatial::Vec3;

/// The grid of the sorted reductions' criteria, relative to the largest: values closer than one
/// part in 10¹² are ties.
const TIE_DIGITS: f64 = 1e12;

/// Whether the contact side (MuJoCo body `body`, geom `geom`) matches criterion `obj`
/// (MuJoCo's `checkMatch`; a site passed its zone test already).
fn check_match(model: &Model, body: usize, geom: usize, obj: SensorObject) -> bool {
    match obj {
        SensorObject::None | SensorObject::Site(_) => true,
        SensorObject::Geom(g) => g == geom,
        SensorObject::Body(b) => b == body,
        SensorObject::XBody(root) => {
            let mut b = body;
            while b > root {
                b = model.links.parent[b];
            }
            b == root
        }
        _ => false,
    }
}

/// 0: no match; 1: match; −1: match with the normal flipped (MuJoCo's `matchContact`).
/// `inside_site` tells whether the contact point is in the first criterion's site zone.
fn match_contact(
    model: &Model,
    data: &Data,
    c: usize,
    s: &Sensor,
    inside_site: &dyn Fn(usize, &Vec3) -> bool,
) -> i8 {
    let (o1, o2) = (s.object, s.reference);
    if o1 == SensorObject::None && o2 == SensorObject::None {
        return 1;
    }
    let contact = &data.contacts[c];
    if let SensorObject::Site(f) = o1 {
        if !inside_site(f, &contact.pos) {
            return 0;
        }
    }
    let [g1, g2] = contact.geom;
    let (b1, b2) = (model.links.of_geom[g1], model.links.of_geom[g2]);
    let m11 = check_match(model, b1, g1, o1);
    let m12 = check_match(model, b2, g2, o1);
    let m21 = check_match(model, b1, g1, o2);
    let m22 = check_match(model, b2, g2, o2);
    if (!m11 && !m12) || (!m21 && !m22) {
        return 0;
    }
    if o1 != SensorObject::None && o2 != SensorObject::None {
        let regular = m11 && m22;
        let reverse = m12 && m21;
        if reverse && !regular {
            -1
        } else {
            1
        }
    } else if o1 != SensorObject::None {
        if m11 {
            1
        } else {
            -1
        }
    } else if m22 {
        1
    } else {
        -1
    }
}

/// One match: (criterion, contact, flipped).
pub(crate) type Match = (f64, usize, bool);

/// Writes contact sensor `s` into `out` (zeroed first); `matches` is scratch.
pub(crate) fn compute(
    model: &Model,
    data: &Data,
    s: &Sensor,
    spec: &ContactSensorSpec,
    inside_site: &dyn Fn(usize, &Vec3) -> bool,
    matches: &mut Vec<Match>,
    out: &mut [f64],
) {
    out.fill(0.0);
    matches.clear();
    let force = |c: usize| contact_force(model, data, c).unwrap_or_default();
    for c in 0..data.contacts.len() {
        let m = match_contact(model, data, c, s, inside_site);
        if m == 0 {
            continue;
        }
        let criterion = match spec.reduce {
            1 => data.contacts[c].dist,
            2 => {
                let f = force(c);
                -(f[0] * f[0] + f[1] * f[1] + f[2] * f[2])
            }
            _ => 0.0,
        };
        matches.push((criterion, c, m < 0));
    }
    let size: usize = CONTACT_FIELDS
        .iter()
        .enumerate()
        .filter(|(i, _)| spec.dataspec & (1 << i) != 0)
        .map(|(_, f)| f.1)
        .sum();
    let nmatch = matches.len();
    if spec.reduce == 3 {
        // No match: the slot stays zero (MuJoCo 4.0; the frame fields too).
        if nmatch > 0 {
            netforce(model, data, spec, matches, &mut out[..size]);
        }
        return;
    }
    if spec.reduce == 1 || spec.reduce == 2 {
        // Criteria equal to 12 significant digits (of the largest) are ties, kept in contact
        // order — MuJoCo's order for exact ties — so that round-off in the forces of symmetric
        // contacts (a box's four corners) does not reorder them. The criteria are rounded to
        // that grid first, which keeps the order a total one.
        let scale = matches.iter().fold(0.0f64, |m, x| m.max(x.0.abs()));
        if scale > 0.0 && scale.is_finite() {
            for m in matches.iter_mut() {
                m.0 = (m.0 / scale * TIE_DIGITS).round();
            }
        }
        matches.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    }
    for (slot, &(_, c, flip)) in matches.iter().take(spec.num).enumerate() {
        let contact = &data.contacts[c];
        let wrench = force(c);
        let mut k = slot * size;
        let sign = if flip { -1.0 } else { 1.0 };
        for (i, (field, n)) in CONTACT_FIELDS.iter().enumerate() {
            if spec.dataspec & (1 << i) == 0 {
                continue;
            }
            let o = &mut out[k..k + n];
            match *field {
                "found" => o[0] = nmatch as f64,
                "force" => {
                    o.copy_from_slice(&wrench[..3]);
                    o[2] *= sign;
                }
                "torque" => {
                    o.copy_from_slice(&wrench[3..]);
                    o[2] *= sign;
                }
                "dist" => o[0] = contact.dist,
                "pos" => o.copy_from_slice(contact.pos.as_slice()),
                "normal" => o.copy_from_slice((contact.frame.row(0).transpose() * sign).as_slice()),
                "tangent" => o.copy_from_slice((contact.frame.row(1).transpose() * sign).as_slice()),
                field => {
                    // Geom 2's point relative to geom 1's, in the contact frame.
                    let [g1, g2] = contact.geom;
                    let (w1, v1) = point_velocity(data, model.geoms[g1].body, &contact.pos);
                    let (w2, v2) = point_velocity(data, model.geoms[g2].body, &contact.pos);
                    let rel = if field == "linvel" { v2 - v1 } else { w2 - w1 };
                    let mut x = contact.frame * rel;
                    x[2] *= sign;
                    o.copy_from_slice(x.as_slice());
                }
            }
            k += n;
        }
    }
}

/// The `netforce` reduction into slot 0.
fn netforce(model: &Model, data: &Data, spec: &ContactSensorSpec, matches: &[Match], out: &mut [f64]) {
    let mut point = Vec3::zeros();
    let mut total = 0.0;
    let wrenches = |&(_, c, flip): &Match| {
        let mut w = contact_force(model, data, c).unwrap_or_default();
        if flip {
            w.iter_mut().for_each(|x| *x = -*x);
        }
        (c, w)
    };
    for m in matches {
        let (c, w) = wrenches(m);
        let weight = Vec3::new(w[0], w[1], w[2]).norm();
        point += data.contacts[c].pos * weight;
        total += weight;
    }
    point /= f64::max(total, 1e-15);
    let (mut force, mut torque) = (Vec3::zeros(), Vec3::zeros());
    for m in matches {
        let (c, w) = wrenches(m);
        let frame = &data.contacts[c].frame;
        let f = frame.tr_mul(&Vec3::new(w[0], w[1], w[2]));
        let t = frame.tr_mul(&Vec3::new(w[3], w[4], w[5]));
        force += f;
        torque += t + (data.contacts[c].pos - point).cross(&f);
    }
    let mut k = 0;
    for (i, (field, n)) in CONTACT_FIELDS.iter().enumerate() {
        if spec.dataspec & (1 << i) == 0 {
            continue;
        }
        let o = &mut out[k..k + n];
        match *field {
            "found" => o[0] = matches.len() as f64,
            "force" => o.copy_from_slice(force.as_slice()),
            "torque" => o.copy_from_slice(torque.as_slice()),
            "dist" => o[0] = 0.0,
            "pos" => o.copy_from_slice(point.as_slice()),
            "normal" => o[0] = 1.0,
            "tangent" => o[1] = 1.0,
            _ => {}
        }
        k += n;
    }
}
