//! The sensors that ask a geometric question (MuJoCo's engine_sensor.c, through
//! [`crate::collision`]'s ray casting, zone tests and geom distances):
//!
//! - `rangefinder` on a site (position stage): the distance along the site's z axis to the nearest
//!   geom not on the site's body (−1 when nothing is hit), with the `data` fields dist, dir,
//!   origin, point, normal and depth;
//! - `insidesite`: 1 when the object's origin is inside the site's zone;
//! - `distance`, `normal`, `fromto`: the smallest signed distance between two geoms (or the geoms
//!   of two bodies), capped at the sensor's `cutoff`, the unit normal along the from–to segment and
//!   the segment itself (MuJoCo's `mj_geomDistance`).

use super::objects::object_pose;
use super::types::{Sensor, SensorObject, SensorType, RAY_FIELDS};
use super::SensorWork;
use crate::collision::geom_distance::geom_distance_unchecked;
use crate::collision::inside::inside_primitive;
use crate::collision::ray::{ray_unchecked, RayFilter};
use crate::model::{Data, Model};
use crate::spatial::Vec3;

/// MuJoCo's `mjMINVAL`.
const MINVAL: f64 = 1e-15;

/// Whether the world point `p` is inside site frame `f`'s zone (false for a site without a
/// primitive shape).
pub(crate) fn inside_site_zone(model: &Model, data: &Data, f: usize, p: &Vec3) -> bool {
    model.frames[f].site.is_some_and(|shape| inside_primitive(&data.x_world_frame[f], &shape, p))
}

/// The site rangefinder of frame `f` into `out` (its `data` fields in MuJoCo's order).
fn rangefinder(model: &Model, data: &Data, s: &Sensor, f: usize, out: &mut [f64]) {
    let x = &data.x_world_frame[f];
    let origin = x.pos;
    let dir = x.rot.column(2).into_owned();
    let filter =
        RayFilter { geomgroup: None, include_static: true, body_exclude: Some(model.links.of_frame[f]) };
    let hit = ray_unchecked(model, data, &origin, &dir, &filter);
    let dist = hit.map_or(-1.0, |h| h.dist);
    let zero = Vec3::zeros();
    let mut k = 0;
    for (i, (field, n)) in RAY_FIELDS.iter().enumerate() {
        if s.ray_dataspec & (1 << i) == 0 {
            continue;
        }
        let o = &mut out[k..k + n];
        match *field {
            "dist" => o[0] = dist,
            "dir" => o.copy_from_slice(if hit.is_some() { dir.as_slice() } else { zero.as_slice() }),
            "origin" => o.copy_from_slice(origin.as_slice()),
            "point" => o.copy_from_slice(hit.map_or(zero, |h| origin + dir * h.dist).as_slice()),
            "normal" => o.copy_from_slice(hit.map_or(zero, |h| h.normal).as_slice()),
            _ => o[0] = hit.map_or(-1.0, |h| h.dist),
        }
        k += n;
    }
}

/// The geoms of a geom-distance sensor's side: one geom, or every geom of a MuJoCo body.
fn geoms_of(model: &Model, obj: SensorObject) -> impl Iterator<Item = usize> + '_ {
    (0..model.geoms.len()).filter(move |&g| match obj {
        SensorObject::Geom(one) => g == one,
        SensorObject::Body(b) => model.links.of_geom[g] == b,
        _ => false,
    })
}

/// Writes the geometric sensor `s` into `out`.
pub(crate) fn compute(model: &Model, data: &Data, work: &SensorWork, s: &Sensor, out: &mut [f64]) {
    match (s.kind, s.object) {
        (SensorType::Rangefinder, SensorObject::Site(f)) => rangefinder(model, data, s, f, out),
        (SensorType::InsideSite, obj) => {
            let SensorObject::Site(site) = s.reference else { return };
            let mut p = object_pose(model, data, obj).pos;
            // A massless body carrying mass below it (a flex parent): its subtree's centre of mass.
            if let SensorObject::Body(b) = obj {
                if b > 0
                    && model.frames[model.links.frame[b]].inertia.mass < MINVAL
                    && work.subtree.mass[b] >= MINVAL
                {
                    p = work.subtree.com[b];
                }
            }
            out[0] = if inside_site_zone(model, data, site, &p) { 1.0 } else { 0.0 };
        }
        (SensorType::GeomDist | SensorType::GeomNormal | SensorType::GeomFromTo, obj) => {
            let mut dist = s.cutoff;
            let mut fromto = [Vec3::zeros(); 2];
            for g1 in geoms_of(model, obj) {
                for g2 in geoms_of(model, s.reference) {
                    let d = geom_distance_unchecked(model, data, g1, g2, s.cutoff);
                    if d.dist < dist {
                        dist = d.dist;
                        fromto = d.fromto.unwrap_or([Vec3::zeros(); 2]);
                    }
                }
            }
            match s.kind {
                SensorType::GeomDist => out[0] = dist,
                SensorType::GeomNormal => {
                    let n = fromto[1] - fromto[0];
                    let n = if n == Vec3::zeros() { n } else { n / n.norm() };
                    out[..3].copy_from_slice(n.as_slice());
                }
                _ => {
                    out[..3].copy_from_slice(fromto[0].as_slice());
                    out[3..6].copy_from_slice(fromto[1].as_slice());
                }
            }
        }
        _ => {}
    }
}
