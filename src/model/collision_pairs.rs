//! Candidate geom pairs for collision detection, fixed at compile time (MuJoCo documentation,
//! "Computation → Collision detection"; MuJoCo's broad-phase filters and `mj_contactParam`):
//!
//! - dynamic pairs: two colliding geoms on different bodies whose bit masks are compatible,
//!   `(contype₁ & conaffinity₂) || (contype₂ & conaffinity₁)`; never two geoms of one body (fused
//!   links are one body: welded together), never two bodies without degrees of freedom (both
//!   welded to the world), never a parent and its child unless one is the world
//!   (`<flag filterparent>`), never a body pair listed in `<exclude>`;
//! - explicit `<pair>`s, with their own parameters and no filter (a geom pair that is both
//!   explicit and dynamic is taken once, explicitly);
//! - none when `<flag contact="disable">` (or `constraint`);
//! - under `<flag override>`, every pair takes `<option>`'s `o_margin`, `o_solref`, `o_solimp`
//!   and `o_friction` (MuJoCo's `mj_assign*` in engine_core_constraint.c).
//!
//! Each pair carries its combined contact parameters: the geom of higher `priority` gives all of
//! them; at equal priority condim and friction are the larger, solref and solimp the `solmix`
//! mixture (solref the element-wise minimum when either is direct, i.e. negative), margin and gap
//! the sums of the geoms' (MuJoCo 4.0's `getMargin`, `getGap`). The pair's geoms are ordered as MuJoCo orders them for its collision functions (the
//! lower geom type first: plane, hfield, sphere, capsule, ellipsoid, cylinder, box, mesh), so that
//! the normal points from geom 1 to geom 2 as in MuJoCo's `contact.frame`.

use super::spec::{GeomContact, Shape};
use super::Model;

/// A candidate pair with its combined parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct CollisionPair {
    /// Indices in `Model::geoms`, in MuJoCo's order (lower geom type first).
    pub geom: [usize; 2],
    /// 1 (frictionless), 3 (sliding), 4 (+ torsional), 6 (+ rolling).
    pub condim: u32,
    /// MuJoCo's 5-vector: sliding, sliding, torsional, rolling, rolling.
    pub friction: [f64; 5],
    /// `solref` of the normal rows (time constant, damping ratio).
    pub solref: [f64; 2],
    /// `solref` of the friction rows of elliptic cones (`[0, 0]`: use `solref`).
    pub solreffriction: [f64; 2],
    /// `solimp` of the rows (dmin, dmax, width, midpoint, power).
    pub solimp: [f64; 5],
    /// Distance below which a contact has constraint rows (m).
    pub margin: f64,
    /// Distance beyond `margin` within which contacts are reported without rows (m).
    pub gap: f64,
    /// Index in `Model::contact_pairs` for an explicit `<pair>`.
    pub pair: Option<usize>,
    /// The most contacts the pair's collision function makes.
    pub max_contacts: usize,
}

/// MuJoCo's order of geom types in its collision table.
pub fn type_rank(shape: &Shape) -> u8 {
    match shape {
        Shape::Plane { .. } => 0,
        Shape::Hfield { .. } => 1,
        Shape::Sphere { .. } => 2,
        Shape::Capsule { .. } => 3,
        Shape::Ellipsoid { .. } => 4,
        Shape::Cylinder { .. } => 5,
        Shape::Box { .. } => 6,
        Shape::Mesh { .. } => 7,
    }
}

/// The most contacts a pair of these shapes yields (MuJoCo's closed forms and `mj_maxContact`):
/// a height field 50 (`mjMAXCONPAIR`), box against box 8, plane against box, cylinder or mesh hull 4 (MuJoCo 4.0 gives a mesh up to the 4 corners of a hull quadrilateral), plane or box against a capsule
/// and capsule against capsule (parallel axes) 2; the convex pairs (`mjc_Convex`, see `collision::multiccd`) 1 with a sphere or an ellipsoid
/// or when `multiccd` is off, else 5 with a capsule or a cylinder, 4 for boxes and meshes
/// without margin (face clipping pruned to a quadrilateral) and 5 with one; every other pair 1.
fn max_contacts(a: &Shape, b: &Shape, multiccd: bool, has_margin: bool) -> usize {
    use Shape::*;
    match (a, b) {
        (Box { .. }, Box { .. }) => 8,
        (Plane { .. }, Box { .. } | Cylinder { .. } | Mesh { .. }) => 4,
        (Plane { .. }, Capsule { .. })
        | (Capsule { .. }, Box { .. })
        | (Box { .. }, Capsule { .. })
        | (Capsule { .. }, Capsule { .. }) => 2,
        (Hfield { .. }, _) | (_, Hfield { .. }) => crate::collision::hfield::MAX_CONTACTS,
        (Plane { .. }, _) | (_, Plane { .. }) => 1,
        // Closed forms of one contact.
        (Sphere { .. } | Capsule { .. }, Sphere { .. } | Capsule { .. })
        | (Sphere { .. }, Box { .. })
        | (Box { .. }, Sphere { .. }) => 1,
        // The convex solver.
        (Sphere { .. } | Ellipsoid { .. }, _) | (_, Sphere { .. } | Ellipsoid { .. }) => 1,
        _ if !multiccd => 1,
        (Capsule { .. } | Cylinder { .. }, _) | (_, Capsule { .. } | Cylinder { .. }) => 5,
        _ if has_margin => 5,
        _ => 4,
    }
}

/// Whether a collision function exists for the pair (planes and height fields never collide with
/// each other; a height field collides with every other geom, see `collision::hfield_convex`).
fn collidable(a: &Shape, b: &Shape) -> bool {
    let flat = |s: &Shape| matches!(s, Shape::Plane { .. } | Shape::Hfield { .. });
    !(flat(a) && flat(b))
}

/// MuJoCo's `mj_contactParam` for a dynamic pair.
fn combine(g1: &GeomContact, g2: &GeomContact) -> (u32, [f64; 3], [f64; 2], [f64; 5]) {
    if g1.priority != g2.priority {
        let g = if g1.priority > g2.priority { g1 } else { g2 };
        return (g.condim, g.friction, g.solref, g.solimp);
    }
    const MINVAL: f64 = 1e-15;
    let mix = match (g1.solmix >= MINVAL, g2.solmix >= MINVAL) {
        (true, true) => g1.solmix / (g1.solmix + g2.solmix),
        (false, false) => 0.5,
        (false, true) => 0.0,
        (true, false) => 1.0,
    };
    let solref = if g1.solref[0] > 0.0 && g2.solref[0] > 0.0 {
        [0, 1].map(|i| mix * g1.solref[i] + (1.0 - mix) * g2.solref[i])
    } else {
        [0, 1].map(|i| g1.solref[i].min(g2.solref[i]))
    };
    let solimp = [0, 1, 2, 3, 4].map(|i| mix * g1.solimp[i] + (1.0 - mix) * g2.solimp[i]);
    let friction = [0, 1, 2].map(|i| g1.friction[i].max(g2.friction[i]));
    (g1.condim.max(g2.condim), friction, solref, solimp)
}

/// The most candidate collision pairs a model may have (a resource limit: each pair is tested
/// every collision pass, and a file with ten thousand overlapping geoms must not exhaust memory).
pub const MAX_COLLISION_PAIRS: usize = 1_000_000;

/// The candidate pairs of `model` (explicit pairs first, then dynamic pairs in geom order); at
/// most one beyond [`MAX_COLLISION_PAIRS`] (the compile step then refuses the model).
pub fn candidate_pairs(model: &Model) -> Vec<CollisionPair> {
    let flags = &model.options.flags;
    if !flags.contact || !flags.constraint {
        return Vec::new();
    }
    let ordered = |a: usize, b: usize| {
        let (ra, rb) = (type_rank(&model.geoms[a].shape), type_rank(&model.geoms[b].shape));
        if (ra, a) <= (rb, b) {
            [a, b]
        } else {
            [b, a]
        }
    };
    let mut out = Vec::new();
    for (k, p) in model.contact_pairs.iter().enumerate() {
        let geom = ordered(p.geom1, p.geom2);
        let (s1, s2) = (&model.geoms[geom[0]].shape, &model.geoms[geom[1]].shape);
        if !collidable(s1, s2) {
            continue;
        }
        out.push(CollisionPair {
            geom,
            condim: p.condim,
            friction: p.friction,
            solref: p.solref,
            solreffriction: p.solreffriction,
            solimp: p.solimp,
            margin: p.margin,
            gap: p.gap,
            pair: Some(k),
            max_contacts: max_contacts(s1, s2, flags.multiccd, p.margin + p.gap > 0.0),
        });
    }
    let explicit = out.len();
    let has_dofs = |b: usize| b != 0;
    // <exclude> names file bodies: compared with the geoms' own file bodies (MuJoCo's
    // geom_bodyid; a multi-joint body's chain is one body, and a jointless body fused into its
    // parent stays itself — excluding the parent does not exclude it), or, for a model without
    // that table, with their compiled bodies' roots.
    let excluded = |i: usize, j: usize, b1: usize, b2: usize| {
        let file_bodies = (model.links.of_geom.len() == model.geoms.len())
            .then(|| (model.links.of_geom[i], model.links.of_geom[j]));
        model.contact_excludes.iter().any(|e| match file_bodies {
            Some((g1, g2)) => {
                let [e1, e2] = e.mujoco_body;
                (e1, e2) == (g1, g2) || (e1, e2) == (g2, g1)
            }
            None => {
                let (e1, e2) = (model.body_root[e.body1], model.body_root[e.body2]);
                (e1, e2) == (b1, b2) || (e1, e2) == (b2, b1)
            }
        })
    };
    let n = model.geoms.len();
    for i in 0..n {
        let gi = &model.geoms[i];
        if !gi.collision {
            continue;
        }
        for j in i + 1..n {
            let gj = &model.geoms[j];
            if !gj.collision {
                continue;
            }
            // MuJoCo's bodies: the chain of a multi-joint MJCF body is one body.
            let (b1, b2) = (model.body_root[gi.body], model.body_root[gj.body]);
            let parent = |b: usize| model.body_root[model.bodies[b].parent];
            let (c1, c2) = (&gi.contact, &gj.contact);
            let compatible = (c1.contype & c2.conaffinity) != 0 || (c2.contype & c1.conaffinity) != 0;
            let parent_child =
                flags.filterparent && b1 != 0 && b2 != 0 && (parent(b1) == b2 || parent(b2) == b1);
            if b1 == b2
                || !(has_dofs(b1) || has_dofs(b2))
                || !compatible
                || parent_child
                || excluded(i, j, b1, b2)
                || !collidable(&gi.shape, &gj.shape)
            {
                continue;
            }
            let geom = ordered(i, j);
            if out[..explicit].iter().any(|p| p.geom == geom) {
                continue;
            }
            if out.len() > MAX_COLLISION_PAIRS {
                // Resource limit: the compile step refuses the model (one pair over the limit
                // is enough to say so).
                return out;
            }
            let (condim, f, solref, solimp) = combine(c1, c2);
            out.push(CollisionPair {
                geom,
                condim,
                friction: [f[0], f[0], f[1], f[2], f[2]],
                solref,
                solreffriction: [0.0, 0.0],
                solimp,
                margin: c1.margin + c2.margin,
                gap: c1.gap + c2.gap,
                pair: None,
                max_contacts: max_contacts(
                    &model.geoms[geom[0]].shape,
                    &model.geoms[geom[1]].shape,
                    flags.multiccd,
                    c1.margin + c2.margin + c1.gap + c2.gap > 0.0,
                ),
            });
        }
    }
    if flags.override_contacts {
        override_params(model, &mut out);
    }
    out
}

/// `<flag override>` (MuJoCo's `mj_assignMargin`, `mj_assignRef`, `mj_assignImp`,
/// `mj_assignFriction`): every pair takes `o_margin`, `o_solref` (for its friction rows too),
/// `o_solimp` and `o_friction` (each entry at least `mjMINMU`); gap and condim stay the pair's
/// (checked against MuJoCo 4.0: contacts are reported within `o_margin` + gap, with rows within
/// `o_margin`).
fn override_params(model: &Model, pairs: &mut [CollisionPair]) {
    const MINMU: f64 = 1e-5;
    let o = &model.options;
    for p in pairs {
        p.margin = o.o_margin;
        p.solref = o.o_solref;
        p.solreffriction = o.o_solref;
        p.solimp = o.o_solimp;
        p.friction = o.o_friction.map(|mu| mu.max(MINMU));
        let (s1, s2) = (&model.geoms[p.geom[0]].shape, &model.geoms[p.geom[1]].shape);
        p.max_contacts = max_contacts(s1, s2, o.flags.multiccd, p.margin + p.gap > 0.0);
    }
}
