//! The collision layer (docs/architecture.md, "Layers"): for the candidate pairs fixed at compile time
//! (`Model::collision_pairs`, see [`crate::model::collision_pairs`]) the contacts at the current
//! body poses, written into `Data::contacts` in MuJoCo's form (`mjContact`: position midway
//! between the surfaces, frame with the normal first pointing from geom 1 to geom 2, signed
//! distance, the pair's combined friction, condim, solref and solimp; MuJoCo documentation,
//! "Computation → Collision detection").
//!
//! On scenes with many candidate pairs a sweep and prune over the geoms' bounding cubes picks the
//! pairs that may touch ([`broadphase`], MuJoCo's `mj_broadphase`); on the others the pairs between
//! the same two bodies are skipped together when the bodies' bounding spheres are apart
//! ([`PairRun`], MuJoCo's body-level broad phase); a bounding-sphere test then
//! rejects far pairs (MuJoCo's `mj_filterSphere`), and an oriented-bounding-box test the pairs of
//! convex geoms whose boxes are apart ([`obb`], MuJoCo's `mj_collideOBB`; docs/constraints.md,
//! "Collision"); the narrow phase
//! is closed form for planes ([`plane`], meshes on planes [`plane_mesh`]), spheres and capsules, spheres against cylinders
//! ([`sphere_cylinder`]), and boxes against spheres,
//! capsules ([`box_primitive`]) and boxes ([`box_box`]) with MuJoCo's multi-point manifolds, and
//! GJK/EPA on support maps for the other convex pairs ([`convex`]). Meshes collide by their
//! convex hulls, whose support points are found by hill climbing on the hull's edges
//! ([`hull_support`], as MuJoCo's mesh graph); height fields collide with every convex geom by GJK/EPA on
//! MuJoCo's prisms, in the field's frame ([`hfield`], [`hfield_convex`]).
//!
//! `collide` reports the contacts closer than the pair's margin + gap plus `reach`: MuJoCo's rule
//! with `reach` = 0 (contacts in the gap are reported without rows: rows exist below the margin,
//! the contact's `includemargin`); the exact mode asks a little further ([`EXACT_REACH`]) so that a contact lifted
//! off by round-off or within a step is still known (its rows exist only while touching, or while
//! the step's rows are frozen).
//!
//! The geometric queries of the sensors live here too: ray casting against geoms and sites
//! ([`ray()`], MuJoCo's `mj_ray`), the distance between two geoms ([`geom_distance()`], MuJoCo's
//! `mj_geomDistance`, through the same narrow phase) and whether a point is inside a site
//! ([`inside_site()`], MuJoCo's `mju_insideGeom`). They consider every geom, visual ones included,
//! reading the triangles and hulls of mesh geoms on first use ([`GeomMesh`]).

pub mod box_box;
pub mod box_primitive;
pub mod broadphase;
pub mod capsule;
mod ccd;
pub mod convex;
mod epa_face;
mod frame;
pub mod geom_distance;
mod gjk;
pub mod hfield;
pub mod hfield_convex;
pub mod hull_support;
pub mod inside;
pub mod mesh;
pub mod mesh_graph;
pub mod multiccd;
pub mod obb;
pub mod plane;
pub mod plane_mesh;
pub mod polygon_clip;
pub mod ray;
pub mod sphere_cylinder;

pub use convex::{ConvexShape, Ellipsoid};
pub use frame::contact_frame;
pub use geom_distance::{geom_distance, GeomDistance};
pub use inside::inside_site;
pub use mesh::GeomMesh;
pub use ray::{ray, ray_site, RayFilter, RayHit};

use crate::model::spec::Shape;
use crate::model::{Contact, Data, Model};
use crate::spatial::{Transform, Vec3};
use convex::PairPoint;
use plane::PlanePoint;
use plane_mesh::PlaneHull;
use std::sync::Arc;

/// How much farther than MuJoCo's margin the exact mode detects contacts (m).
pub const EXACT_REACH: f64 = 1e-3;

/// Per geom: its support-map shape (None for planes, height fields and non-colliding geoms) and
/// bounding-sphere radius. Built once per model.
#[derive(Clone, Debug, Default)]
pub struct CollisionModel {
    /// Per geom, its support-map shape (`None` for planes, height fields and non-colliding meshes).
    pub shapes: Vec<Option<ConvexShape>>,
    /// Per geom, its bounding-sphere radius about the geom origin (m; infinite for planes and
    /// height fields).
    pub rbound: Vec<f64>,
    /// Per candidate pair (`Model::collision_pairs` order), what the bounding-sphere test needs,
    /// packed: the two geoms, the pair's margin + gap plus both bounding radii (geom 2's alone
    /// against a plane), and whether geom 1 is a plane.
    pub broad: Vec<BroadPair>,
    /// Per geom, a colliding mesh's hull prepared for plane contacts ([`plane_mesh`]; geoms of one
    /// hull share it).
    pub plane_hulls: Vec<Option<Arc<PlaneHull>>>,
    /// The sweep and prune over the geoms' boxes ([`broadphase`]).
    pub sweep: broadphase::Broadphase,
    /// Per geom, its bounding box in its own frame for the [`obb`] test (None for planes, height
    /// fields and meshes without a hull); a mesh's along MuJoCo's axes of it (`geom_aabb`'s).
    pub local_box: Vec<Option<obb::LocalBox>>,
    /// Per mesh geom whose principal axes are not its geom frame's: its box along the geom
    /// frame's axes, a second test after `local_box`'s (None elsewhere).
    pub file_box: Vec<Option<obb::LocalBox>>,
    /// The geoms posed by each collision pass (those with a support-map shape or that collide),
    /// ascending.
    pub posed: Vec<u32>,
    /// The candidate pairs in runs of consecutive pairs between the same two parts, each with
    /// the parts' bounding spheres ([`PairRun`]), in `Model::collision_pairs` order.
    pub runs: Vec<PairRun>,
}

/// Consecutive candidate pairs (`Model::collision_pairs[start..end]`) between the same two
/// rigid parts — two bodies (a geom's body with its mocap frame, if any), or a plane and a body —
/// and a bounding sphere of each part's geoms in the run: a collision pass that finds the spheres
/// apart skips every pair of the run, each of whose own bounding-sphere tests would fail (the
/// body-level broad phase of MuJoCo's `mj_collision`, on spheres).
#[derive(Clone, Copy, Debug)]
pub struct PairRun {
    /// The first pair of the run (index in `Model::collision_pairs`).
    pub start: u32,
    /// One past the last pair of the run.
    pub end: u32,
    /// A geom of each part (the plane first for a plane's run), whose origin centres the part's
    /// sphere.
    pub anchor: [u32; 2],
    /// The largest margin + gap of the run's pairs plus both spheres' radii (the body's alone
    /// against a plane), widened by a relative 1e-9 so that rounding never drops a pair its own
    /// test would keep (m); infinite when a part is unbounded (a height field) or both are one.
    pub reach: f64,
    /// Whether the first part is a plane.
    pub plane: bool,
}

impl PairRun {
    /// Whether the two parts' spheres are farther apart than the run's reach plus `reach` at
    /// the geoms' world poses `x` (a plane: the body's sphere above the plane).
    #[inline]
    pub fn apart(&self, x: &[Transform], reach: f64) -> bool {
        let (x1, x2) = (&x[self.anchor[0] as usize], &x[self.anchor[1] as usize]);
        spheres_apart(x1, x2, self.plane, self.reach + reach)
    }

    /// The runs of `model`'s candidate pairs, with the geoms' bounding radii `rbound`.
    fn of(model: &Model, rbound: &[f64]) -> Vec<PairRun> {
        // A geom's part: an unbounded geom (plane, height field) is its own part.
        #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
        enum Part {
            Body(usize, Option<usize>),
            Unbounded(usize),
        }
        let part = |g: usize| {
            let geom = &model.geoms[g];
            if rbound[g].is_finite() {
                Part::Body(geom.body, geom.mocap)
            } else {
                Part::Unbounded(g)
            }
        };
        let key = |i: usize| {
            let [g1, g2] = model.collision_pairs[i].geom;
            let (p1, p2) = (part(g1), part(g2));
            if p1 <= p2 {
                (p1, p2)
            } else {
                (p2, p1)
            }
        };
        let mut runs = Vec::new();
        let n = model.collision_pairs.len();
        let mut start = 0;
        while start < n {
            let k = key(start);
            let mut end = start + 1;
            while end < n && key(end) == k {
                end += 1;
            }
            let pairs = &model.collision_pairs[start..end];
            let margin = pairs.iter().map(|p| p.margin + p.gap).fold(0.0, f64::max);
            // Each side's geoms in the run, the first its anchor.
            let side = |p: Part| -> (usize, f64) {
                let geoms = pairs.iter().flat_map(|q| q.geom).filter(|&g| part(g) == p);
                let anchor = geoms.clone().next().unwrap_or(0);
                let at = model.geoms[anchor].x_body_geom.pos;
                let radius = geoms
                    .map(|g| (model.geoms[g].x_body_geom.pos - at).norm() + rbound[g])
                    .fold(0.0, f64::max);
                (anchor, radius)
            };
            let run = match k {
                (Part::Body(..), Part::Unbounded(g))
                    if matches!(model.geoms[g].shape, Shape::Plane { .. }) =>
                {
                    let (a, r) = side(k.0);
                    PairRun { start: 0, end: 0, anchor: [g as u32, a as u32], reach: margin + r, plane: true }
                }
                (p1 @ Part::Body(..), p2 @ Part::Body(..)) if p1 != p2 => {
                    let ((a1, r1), (a2, r2)) = (side(p1), side(p2));
                    PairRun {
                        start: 0,
                        end: 0,
                        anchor: [a1 as u32, a2 as u32],
                        reach: margin + r1 + r2,
                        plane: false,
                    }
                }
                _ => {
                    let [g1, g2] = pairs[0].geom;
                    PairRun {
                        start: 0,
                        end: 0,
                        anchor: [g1 as u32, g2 as u32],
                        reach: f64::INFINITY,
                        plane: false,
                    }
                }
            };
            runs.push(PairRun {
                start: start as u32,
                end: end as u32,
                reach: run.reach * (1.0 + 1e-9),
                ..run
            });
            start = end;
        }
        runs
    }
}

/// The bounding-sphere test of one candidate pair (see [`CollisionModel::broad`]).
#[derive(Clone, Copy, Debug)]
pub struct BroadPair {
    /// The pair's geoms (indices in `Model::geoms`).
    pub geom: [u32; 2],
    /// Margin + gap plus both bounding radii (geom 2's alone against a plane) (m): the distance
    /// between the geom origins (against a plane, geom 2's height above it) beyond which the pair
    /// cannot touch.
    pub reach: f64,
    /// Whether geom 1 is a plane.
    pub plane: bool,
}

impl CollisionModel {
    /// The shapes, bounding radii and broad-phase data of `model`'s geoms and candidate pairs.
    pub fn new(model: &Model) -> Self {
        let mut shapes = Vec::with_capacity(model.geoms.len());
        let mut plane_hulls: Vec<Option<Arc<PlaneHull>>> = Vec::with_capacity(model.geoms.len());
        let mut built: Vec<(*const mesh_graph::MeshGraph, Option<Arc<PlaneHull>>)> = Vec::new();
        let mut rbound = Vec::with_capacity(model.geoms.len());
        for g in &model.geoms {
            let (shape, r) = match &g.shape {
                Shape::Mesh { .. } => match &g.hull_graph {
                    Some(h) => {
                        let r = h.vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
                        (Some(ConvexShape::Hull(Box::new(hull_support::HullSupport::new(h.clone())))), r)
                    }
                    None => (None, 0.0),
                },
                Shape::Plane { .. } | Shape::Hfield { .. } => (None, f64::INFINITY),
                primitive => match ConvexShape::of_primitive(primitive) {
                    Some((s, r)) => (Some(s), r),
                    None => (None, 0.0),
                },
            };
            shapes.push(shape);
            rbound.push(r);
            plane_hulls.push(g.hull_graph.as_ref().and_then(|h| {
                let key = Arc::as_ptr(h);
                if let Some((_, p)) = built.iter().find(|(k, _)| *k == key) {
                    return p.clone();
                }
                let p = PlaneHull::new(h).map(Arc::new);
                built.push((key, p.clone()));
                p
            }));
        }
        let broad = model
            .collision_pairs
            .iter()
            .map(|p| {
                let [g1, g2] = p.geom;
                let plane = matches!(model.geoms[g1].shape, Shape::Plane { .. });
                let radii = if plane { rbound[g2] } else { rbound[g1] + rbound[g2] };
                BroadPair { geom: [g1 as u32, g2 as u32], reach: p.margin + p.gap + radii, plane }
            })
            .collect();
        let sweep = broadphase::Broadphase::new(model, &rbound);
        let local_box: Vec<Option<obb::LocalBox>> = model
            .geoms
            .iter()
            .map(|g| obb::LocalBox::of(&g.shape, g.hull(), g.hull_graph.as_ref().map(|h| &h.box_frame)))
            .collect();
        // A mesh's box along its geom frame's axes too, where those differ from its principal
        // axes: a part modelled along its own axes (a robot link) is hugged better by those.
        let file_box = model
            .geoms
            .iter()
            .zip(&local_box)
            .map(|(g, b): (_, &Option<obb::LocalBox>)| {
                b.as_ref().and_then(|b| b.axes).and_then(|_| obb::LocalBox::of(&g.shape, g.hull(), None))
            })
            .collect();
        let posed = (0..model.geoms.len())
            .filter(|&g| shapes[g].is_some() || model.geoms[g].collision)
            .map(|g| g as u32)
            .collect();
        let runs = PairRun::of(model, &rbound);
        Self { shapes, rbound, broad, plane_hulls, sweep, local_box, file_box, posed, runs }
    }
}

/// The contacts of every candidate pair at the current body poses (`x_world_body`), closer than
/// the pair's margin + gap plus `reach`, into `data.contacts` (cleared first; no allocation once the
/// buffers have held as many contacts: a pass that finds more than every earlier one grows them).
pub fn collide(model: &Model, cm: &CollisionModel, data: &mut Data, reach: f64) {
    data.contacts.clear();
    // Sleeping islands: with every tree asleep no pair passes the sleep filter.
    if data.sleep.all_asleep(model) {
        data.sleep.pairs_tested = 0;
        return;
    }
    let budget = model.contact_budget();
    let dropped_before = data.contacts_dropped;
    // World poses of the colliding geoms, once per pass (MuJoCo's geom_xpos, geom_xmat).
    for &g in &cm.posed {
        let geom = &model.geoms[g as usize];
        data.x_world_geom[g as usize] = data.attached_pose(geom.body, geom.mocap, &geom.x_body_geom);
    }
    // The geoms' world boxes are formed when a pair first needs them (`world_boxes`).
    data.broadphase.pass += 1;
    // Sweep and prune narrows the candidate pairs first when there are many (same pairs, same
    // order as the full loop: see [`broadphase`]).
    if cm.sweep.sweep {
        cm.sweep.candidates(&data.x_world_geom, &mut data.broadphase, reach);
    }
    // Taken out while contacts are written, put back after (no allocation).
    let swept = std::mem::take(&mut data.broadphase.pairs);
    let asleep = data.sleep.any_asleep();
    let mut tested = 0;
    if cm.sweep.sweep {
        for &idx in &swept {
            tested += test_pair(model, cm, data, idx as usize, reach, budget, asleep) as usize;
        }
    } else {
        // Runs of pairs between the same two parts: skipped together when the parts' bounding
        // spheres are apart (a run of one pair goes straight to its own test).
        for run in &cm.runs {
            if run.end - run.start > 1 && run.apart(&data.x_world_geom, reach) {
                continue;
            }
            for idx in run.start as usize..run.end as usize {
                tested += test_pair(model, cm, data, idx, reach, budget, asleep) as usize;
            }
        }
    }
    data.broadphase.pairs = swept;
    data.sleep.pairs_tested = tested;
    if data.contacts_dropped > dropped_before {
        let found = data.contacts.len() + (data.contacts_dropped - dropped_before) as usize;
        data.warnings.contacts_full(found, data.time);
    }
    // One regularized-cone μ per contact (`contact_mu`): grown with the contact buffer when this
    // pass found more contacts than any before.
    if data.contact_mu.len() < data.contacts.len() {
        data.contact_mu.resize(data.contacts.len(), 0.0);
    }
}

/// Whether two bounding spheres centred at the origins of `x1` and `x2` are farther apart than
/// `within` (the radii, margin and gap summed), or, with `plane`, whether `x2`'s origin is more
/// than `within` above the plane of `x1` (its local z = 0): the test of one pair and of a run of
/// pairs alike.
#[inline(always)]
fn spheres_apart(x1: &Transform, x2: &Transform, plane: bool, within: f64) -> bool {
    let d = x2.pos - x1.pos;
    if plane {
        x1.rot.column(2).dot(&d) > within
    } else {
        d.norm_squared() > within * within
    }
}

/// Candidate pair `idx` through the sleep filter and the bounding-sphere test (a plane: the other
/// geom's sphere against the plane), then [`narrow_pair`]; whether it passed the sleep filter.
#[inline(always)]
fn test_pair(
    model: &Model,
    cm: &CollisionModel,
    data: &mut Data,
    idx: usize,
    reach: f64,
    budget: usize,
    asleep: bool,
) -> bool {
    let b = &cm.broad[idx];
    // Sleeping islands: no pair of two sleeping trees or of a sleeping tree and the world (a
    // pair touching at the last pass is still taken as touching when tested again).
    if asleep && data.sleep.pair_skipped(model, [b.geom[0] as usize, b.geom[1] as usize]) {
        let bw = &mut data.broadphase;
        if bw.touched[idx] + 1 == bw.pass {
            bw.touched[idx] = bw.pass;
        }
        return false;
    }
    let (x1, x2) = (&data.x_world_geom[b.geom[0] as usize], &data.x_world_geom[b.geom[1] as usize]);
    if !spheres_apart(x1, x2, b.plane, b.reach + reach) {
        narrow_pair(model, cm, data, idx, reach, budget);
    }
    true
}

/// Candidate pair `idx`, whose bounding spheres overlap: the oriented-bounding-box test ([`obb`]),
/// then its narrow phase, its contacts pushed onto `data.contacts` (at most the pair's
/// `max_contacts`, none past `budget`: those are counted in `contacts_dropped`); a pair that
/// found contacts is stamped touching for the next pass.
#[inline(always)]
fn narrow_pair(model: &Model, cm: &CollisionModel, data: &mut Data, idx: usize, reach: f64, budget: usize) {
    let pair = &model.collision_pairs[idx];
    let [g1, g2] = pair.geom;
    let within = pair.margin + pair.gap + reach;
    if let (Some(l1), Some(l2)) = (&cm.local_box[g1], &cm.local_box[g2]) {
        let (bw, xg) = (&mut data.broadphase, &data.x_world_geom);
        bw.form_box(g1, l1, &xg[g1]);
        bw.form_box(g2, l2, &xg[g2]);
        if bw.boxes[g1].apart(&bw.boxes[g2], within) {
            return;
        }
        // Then the geom frames' boxes where a mesh has one (any box that separates the pair
        // proves it apart).
        let (f1, f2) = (&cm.file_box[g1], &cm.file_box[g2]);
        if f1.is_some() || f2.is_some() {
            let b1 = match f1 {
                Some(f) => bw.form_file_box(g1, f, &xg[g1]),
                None => bw.boxes[g1],
            };
            let b2 = match f2 {
                Some(f) => bw.form_file_box(g2, f, &xg[g2]),
                None => bw.boxes[g2],
            };
            if b1.apart(&b2, within) {
                return;
            }
        }
    }
    let before = data.contacts.len();
    narrow_phase(model, cm, data, idx, within, budget);
    if data.contacts.len() > before {
        data.broadphase.touched[idx] = data.broadphase.pass;
    }
}

/// The narrow phase of candidate pair `idx` (see [`narrow_pair`]), contacts closer than `within`.
#[inline(never)]
fn narrow_phase(model: &Model, cm: &CollisionModel, data: &mut Data, idx: usize, within: f64, budget: usize) {
    let pair = &model.collision_pairs[idx];
    let [g1, g2] = pair.geom;
    let (geom1, geom2) = (&model.geoms[g1], &model.geoms[g2]);
    let (x1, x2) = (data.x_world_geom[g1], data.x_world_geom[g2]);
    let start = data.contacts.len();
    let mut push = |p1: Vec3, p2: Vec3, normal: Vec3, dist: f64, hint: Option<Vec3>, feature: u32| {
        if data.contacts.len() - start >= pair.max_contacts {
            return;
        }
        if data.contacts.len() >= budget {
            data.contacts_dropped += 1;
            return;
        }
        data.contacts.push(Contact {
            geom: pair.geom,
            pos: (p1 + p2) * 0.5,
            frame: contact_frame(&normal, hint.as_ref()),
            dist,
            includemargin: pair.margin,
            gap: pair.gap,
            condim: pair.condim,
            friction: pair.friction,
            solref: pair.solref,
            solreffriction: pair.solreffriction,
            solimp: pair.solimp,
            pair: pair.pair,
            feature,
        });
    };
    // Height fields against every convex geom: MuJoCo's prisms by GJK/EPA ([`hfield_convex`]).
    if let Shape::Hfield { field, .. } = &geom1.shape {
        if let Some(s2) = &cm.shapes[g2] {
            let mut out = |p: hfield::HfieldPoint| push(p.pos, p.pos, p.normal, p.dist, None, 0);
            hfield_convex::convex(&x1, field, s2, &x2, pair.margin, &model.options, &mut out);
        }
        return;
    }
    if let Shape::Plane { .. } = geom1.shape {
        let n = x1.rot.column(2).into_owned();
        let mut out = |p: PlanePoint| push(p.surface - n * p.dist, p.surface, n, p.dist, p.hint, p.feature);
        match &geom2.shape {
            Shape::Sphere { radius } => plane::sphere(&x1, &x2.pos, *radius, within, &mut out),
            Shape::Capsule { radius, length } => {
                plane::capsule(&x1, &x2, *radius, 0.5 * length, within, &mut out)
            }
            Shape::Box { size } => plane::cuboid(&x1, &x2, &(size / 2.0), within, &mut out),
            Shape::Cylinder { radius, length } => {
                plane::cylinder(&x1, &x2, *radius, 0.5 * length, within, &mut out)
            }
            Shape::Ellipsoid { radii } => plane::ellipsoid(&x1, &x2, radii, within, &mut out),
            Shape::Mesh { .. } => {
                if let Some(h) = &cm.plane_hulls[g2] {
                    plane_mesh::plane_mesh(&x1, &x2, h, within, &mut out)
                }
            }
            Shape::Plane { .. } | Shape::Hfield { .. } => {}
        }
        return;
    }
    // Boxes against spheres, capsules and boxes, spheres against cylinders: MuJoCo's closed
    // forms (geom 1 the lower type; a pair given the other way round is swapped and its normal
    // turned back).
    let mut emit = |p: PairPoint, feature: u32, swap: bool| match swap {
        false => push(p.p1, p.p2, p.normal, p.dist, None, feature),
        true => push(p.p2, p.p1, -p.normal, p.dist, None, feature),
    };
    let boxed = match (&geom1.shape, &geom2.shape) {
        (Shape::Sphere { radius }, Shape::Box { size }) | (Shape::Box { size }, Shape::Sphere { radius }) => {
            let (xs, xb, swap) =
                if let Shape::Box { .. } = geom2.shape { (x1, x2, false) } else { (x2, x1, true) };
            let mut out = |p, f| emit(p, f, swap);
            box_primitive::sphere_box(&xs.pos, *radius, &xb, &(size / 2.0), within, 0, &mut out);
            true
        }
        (Shape::Capsule { radius, length }, Shape::Box { size })
        | (Shape::Box { size }, Shape::Capsule { radius, length }) => {
            let (xc, xb, swap) =
                if let Shape::Box { .. } = geom2.shape { (x1, x2, false) } else { (x2, x1, true) };
            let mut out = |p, f| emit(p, f, swap);
            box_primitive::capsule_box(&xc, *radius, 0.5 * length, &xb, &(size / 2.0), within, &mut out);
            true
        }
        (Shape::Sphere { radius }, Shape::Cylinder { radius: rc, length })
        | (Shape::Cylinder { radius: rc, length }, Shape::Sphere { radius }) => {
            let (xs, xc, swap) =
                if let Shape::Cylinder { .. } = geom2.shape { (x1, x2, false) } else { (x2, x1, true) };
            let z = xs.rot.column(2).into_owned();
            if let Some(p) =
                sphere_cylinder::sphere_cylinder(&xs.pos, &z, *radius, &xc, *rc, 0.5 * length, within)
            {
                emit(p, 0, swap);
            }
            true
        }
        (Shape::Box { size: s1 }, Shape::Box { size: s2 }) => {
            box_box::box_box(&x1, &(s1 / 2.0), &x2, &(s2 / 2.0), within, &mut |p, f| emit(p, f, false));
            true
        }
        // Spheres and capsules: MuJoCo's sphere–sphere tests of segment points ([`capsule`]).
        (Shape::Sphere { radius: r1 }, Shape::Sphere { radius: r2 }) => {
            if let Some(p) = capsule::sphere_sphere_pair(&x1, *r1, &x2, *r2, within) {
                emit(p, 0, false);
            }
            true
        }
        (Shape::Sphere { radius }, Shape::Capsule { radius: rc, length })
        | (Shape::Capsule { radius: rc, length }, Shape::Sphere { radius }) => {
            let (xs, xc, swap) =
                if let Shape::Capsule { .. } = geom2.shape { (x1, x2, false) } else { (x2, x1, true) };
            if let Some(p) = capsule::sphere_capsule(&xs, *radius, &xc, *rc, 0.5 * length, within) {
                emit(p, 0, swap);
            }
            true
        }
        (Shape::Capsule { radius: r1, length: l1 }, Shape::Capsule { radius: r2, length: l2 }) => {
            let mut k = 0;
            capsule::capsule_capsule(&x1, *r1, 0.5 * l1, &x2, *r2, 0.5 * l2, within, &mut |p| {
                emit(p, k, false);
                k += 1;
            });
            true
        }
        _ => false,
    };
    if boxed {
        return;
    }
    let point = match (&cm.shapes[g1], &cm.shapes[g2]) {
        (Some(s1), Some(s2)) => {
            let bw = &mut data.broadphase;
            let touching = bw.touched[idx] + 1 == bw.pass;
            convex::mujoco_pair_warm(&x1, s1, &x2, s2, within, &model.options, touching, &mut bw.warm[idx])
        }
        _ => None,
    };
    if let Some((p, face)) = point {
        if let (true, Some(s1), Some(s2)) = (pair.max_contacts > 1, &cm.shapes[g1], &cm.shapes[g2]) {
            // Feature ids: the order of the points (distinct within the pair).
            let mut k = 0;
            let mut out = |q: PairPoint| {
                push(q.p1, q.p2, q.normal, q.dist, None, k);
                k += 1;
            };
            multiccd::convex_contacts(&x1, s1, &x2, s2, p, face.as_ref(), pair.margin + pair.gap, &mut out);
            return;
        }
        push(p.p1, p.p2, p.normal, p.dist, None, 0);
    }
}
