//! Sleeping islands, the tables (docs/constraints.md, "Sleeping islands"; MuJoCo 4.0
//! documentation, "Computation → Sleeping islands" and "Simulation → Sleeping islands"):
//! MuJoCo's kinematic trees over lagrange's compiled bodies, each tree's sleep policy (the file's
//! `<body sleep>` or the compiler's automatic one), each dof's length (`dof_length`, which turns
//! a rotational speed into a length per time), and the sleep state a [`Data`](super::Data) holds
//! (`tree_asleep` with MuJoCo's encoding). What a step does with them is `forward::sleep`.

use super::actuator::Transmission;
use super::{JointKind, Model};

/// MuJoCo's `mjMINAWAKE`: the steps a tree must stay below the tolerance before it may sleep.
pub const MIN_AWAKE: i32 = 10;

/// `tree_asleep` of a fully awake tree, −(1 + `MIN_AWAKE`); −1 is "ready to sleep".
pub const AWAKE: i32 = -(1 + MIN_AWAKE);

/// No tree: a body or dof of the world (static).
pub const NO_TREE: usize = usize::MAX;

/// The sleep policy of a kinematic tree (MuJoCo's `mjtSleepPolicy`, MJCF `<body sleep>` on the
/// tree's root body).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SleepPolicy {
    /// `auto` (the default): the compiler decides ([`SleepPolicy::AutoNever`] or
    /// [`SleepPolicy::AutoAllowed`]).
    #[default]
    Auto,
    /// The compiler's choice: never sleeps (an actuator moves the tree, or a tendon with
    /// stiffness or damping joins it to another tree).
    AutoNever,
    /// The compiler's choice: may sleep.
    AutoAllowed,
    /// `never`: the file forbids sleeping.
    Never,
    /// `allowed`: the file allows sleeping.
    Allowed,
    /// `init`: the tree starts asleep (after `Data::new` and `reset`, with `<flag sleep>`).
    Init,
}

impl SleepPolicy {
    /// The MJCF keyword (`auto`, `never`, `allowed`, `init`) as a policy.
    pub fn from_mjcf(word: &str) -> Option<Self> {
        Some(match word {
            "auto" => SleepPolicy::Auto,
            "never" => SleepPolicy::Never,
            "allowed" => SleepPolicy::Allowed,
            "init" => SleepPolicy::Init,
            _ => return None,
        })
    }

    /// Whether a tree with this policy may fall asleep.
    pub fn may_sleep(self) -> bool {
        !matches!(self, SleepPolicy::Never | SleepPolicy::AutoNever)
    }
}

/// MuJoCo's trees and what sleeping reads of them, fixed when the model is compiled.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SleepModel {
    /// Tree t's dofs are `tree_dof[t]..tree_dof[t + 1]` (MuJoCo's `tree_dofadr`, `tree_dofnum`).
    pub tree_dof: Vec<usize>,
    /// Tree t's joints are `tree_joint[t]..tree_joint[t + 1]` (indices in `Model::joints`).
    pub tree_joint: Vec<usize>,
    /// Each dof's tree (MuJoCo's `dof_treeid`).
    pub dof_tree: Vec<usize>,
    /// Each compiled body's tree ([`NO_TREE`] for the world).
    pub body_tree: Vec<usize>,
    /// Each MuJoCo body's tree (MuJoCo's `body_treeid`, [`NO_TREE`] for static bodies).
    pub link_tree: Vec<usize>,
    /// Each tree's policy, resolved (never [`SleepPolicy::Auto`]; MuJoCo's `tree_sleep_policy`).
    pub policy: Vec<SleepPolicy>,
    /// Each dof's length (m; MuJoCo's `dof_length`): 1 for a translation, for a rotation the size
    /// of its body at `qpos0` (the largest distance from its centre of mass to a joint anchor, or
    /// to a geom's bounding sphere), so that `dof_length · |v|` is a speed.
    pub dof_length: Vec<f64>,
    /// The name of each tree's root body (messages).
    pub root_name: Vec<String>,
    /// Whether a geom is on a mocap body (awake whatever the trees do).
    pub mocap_geoms: bool,
}

impl SleepModel {
    /// Number of trees (MuJoCo's `ntree`).
    pub fn ntree(&self) -> usize {
        self.policy.len()
    }

    /// The tables of `model` (compiled, its plan built), with the policies the file gives
    /// (`user`: compiled root body, policy). `ten_j` is the tendons' Jacobian at `qpos0` and
    /// `x_world_body` the compiled bodies' poses there.
    ///
    /// # Errors
    /// The compiled body and the message when a policy cannot hold: a policy on a body that is
    /// not the root of a tree, or `allowed`/`init` on a tree a tendon with stiffness or damping
    /// (or spanning more than two trees) joins to others.
    pub(crate) fn new(
        model: &Model,
        user: &[(usize, SleepPolicy)],
        ten_j: &nalgebra::DMatrix<f64>,
        x_world_body: &[crate::spatial::Transform],
    ) -> Result<Self, (usize, String)> {
        let nv = model.nv;
        let (mut tree_dof, mut dof_tree) = (Vec::new(), vec![NO_TREE; nv]);
        for k in 0..nv {
            if model.dof_tree_start[k] == k {
                tree_dof.push(k);
            }
            dof_tree[k] = tree_dof.len() - 1;
        }
        let ntree = tree_dof.len();
        tree_dof.push(nv);
        let mut body_tree = vec![NO_TREE; model.bodies.len()];
        let mut tree_joint = vec![model.joints.len(); ntree + 1];
        for (j, joint) in model.joints.iter().enumerate().rev() {
            let t = dof_tree[joint.dof_adr];
            body_tree[joint.body] = t;
            tree_joint[t] = j;
        }
        // The first frame of each compiled body is its own (frames are made in link order).
        let mut body_link = vec![usize::MAX; model.bodies.len()];
        for (f, frame) in model.frames.iter().enumerate() {
            if body_link[frame.body] == usize::MAX && f < model.links.of_frame.len() {
                body_link[frame.body] = model.links.of_frame[f];
            }
        }
        body_link[0] = 0;
        let link_tree: Vec<usize> = (0..model.links.len())
            .map(|l| {
                let f = model.links.frame[l];
                model.frames.get(f).map_or(NO_TREE, |fr| body_tree[fr.body])
            })
            .collect();
        let mut root_name = vec![String::new(); ntree];
        let mut policy = vec![SleepPolicy::Auto; ntree];
        for (b, body) in model.bodies.iter().enumerate().skip(1) {
            let t = body_tree[b];
            if root_name[t].is_empty() {
                root_name[t] = body.name.clone();
            }
        }
        for &(b, p) in user {
            let t = body_tree.get(b).copied().unwrap_or(NO_TREE);
            let is_root = t != NO_TREE && model.bodies[b].parent == 0;
            if !is_root {
                return Err((b, "sleep policy only allowed for movable root bodies (a body with joints whose parent is the world or a static body), as in MuJoCo".to_string()));
            }
            policy[t] = p;
        }
        // The compiler's automatic policy (MuJoCo's mj_setConst): actuated trees never sleep.
        let never = |t: usize, policy: &mut Vec<SleepPolicy>| {
            if t != NO_TREE && policy[t] == SleepPolicy::Auto {
                policy[t] = SleepPolicy::AutoNever;
            }
        };
        let tendon_trees = |i: usize| -> Vec<usize> {
            let mut ts: Vec<usize> = (0..nv).filter(|&k| ten_j[(i, k)] != 0.0).map(|k| dof_tree[k]).collect();
            ts.dedup();
            ts.sort_unstable();
            ts.dedup();
            ts
        };
        for a in &model.actuators {
            match &a.transmission {
                Transmission::Joint(j) | Transmission::JointInParent(j) => {
                    never(body_tree[model.joints[*j].body], &mut policy)
                }
                Transmission::Site { site, .. } => never(body_tree[model.frames[*site].body], &mut policy),
                Transmission::SliderCrank { cranksite, .. } => {
                    never(body_tree[model.frames[*cranksite].body], &mut policy)
                }
                Transmission::Body(b) => never(body_tree[*b], &mut policy),
                Transmission::Tendon(i) => {
                    for t in tendon_trees(*i) {
                        never(t, &mut policy);
                    }
                }
            }
        }
        for (i, tendon) in model.tendons.iter().enumerate() {
            let ts = tendon_trees(i);
            let actuated =
                model.actuators.iter().any(|a| matches!(a.transmission, Transmission::Tendon(k) if k == i));
            if ts.len() < 2
                || (ts.len() == 2 && tendon.stiffness == 0.0 && tendon.damping == 0.0 && !actuated)
            {
                continue;
            }
            for t in ts {
                match policy[t] {
                    SleepPolicy::Auto => policy[t] = SleepPolicy::AutoNever,
                    SleepPolicy::Allowed | SleepPolicy::Init => {
                        let root = (1..model.bodies.len()).find(|&b| body_tree[b] == t).unwrap_or(0);
                        return Err((root, format!("tree of '{}' is joined by tendon '{}' (with stiffness or damping, or spanning more than two trees) to other trees: it cannot sleep; remove sleep=\"allowed\"/\"init\"", root_name[t], tendon.name)));
                    }
                    _ => {}
                }
            }
        }
        for p in &mut policy {
            if *p == SleepPolicy::Auto {
                *p = SleepPolicy::AutoAllowed;
            }
        }
        let dof_length = dof_lengths(model, &body_link, x_world_body);
        let mocap_geoms = model.geoms.iter().any(|g| g.mocap.is_some());
        Ok(Self {
            tree_dof,
            tree_joint,
            dof_tree,
            body_tree,
            link_tree,
            policy,
            dof_length,
            root_name,
            mocap_geoms,
        })
    }
}

/// MuJoCo's `dof_length` (mj_setConst): each MuJoCo body's size at `qpos0` — the largest
/// distance from its centre of mass to the anchor of a joint of it or of a child, and to the far
/// side of a geom's bounding sphere, at least 1e-5 — for the rotational dofs, 1 for the others.
fn dof_lengths(model: &Model, body_link: &[usize], x_world_body: &[crate::spatial::Transform]) -> Vec<f64> {
    let nlink = model.links.len();
    // Centre of mass of each MuJoCo body in the world.
    let com: Vec<crate::spatial::Vec3> = (0..nlink)
        .map(|l| {
            let frame = &model.frames[model.links.frame[l]];
            let x = x_world_body[frame.body] * frame.x_body_frame;
            let local = if frame.inertia.mass > 0.0 {
                frame.inertia.h / frame.inertia.mass
            } else {
                crate::spatial::Vec3::zeros()
            };
            x.act_point(&local)
        })
        .collect();
    let mut size = vec![0.0f64; nlink];
    for j in &model.joints {
        let anchor = x_world_body[j.body].pos;
        let mut l = body_link[j.body];
        if l == usize::MAX {
            continue;
        }
        size[l] = size[l].max((com[l] - anchor).norm());
        l = model.links.parent[l];
        size[l] = size[l].max((com[l] - anchor).norm());
    }
    if let Some(first) = size.first_mut() {
        *first = 0.0;
    }
    let rbound = &model.plan.constraints.collision.rbound;
    for (g, geom) in model.geoms.iter().enumerate() {
        let l = model.links.of_geom.get(g).copied().unwrap_or(0);
        let r = rbound.get(g).copied().unwrap_or(0.0);
        if l == 0 || !(r > 0.0 && r.is_finite()) {
            continue;
        }
        let pos = (x_world_body[geom.body] * geom.x_body_geom).pos;
        size[l] = size[l].max(r + (com[l] - pos).norm());
    }
    for s in size.iter_mut().skip(1) {
        *s = s.max(1e-5);
    }
    let mut out = vec![1.0; model.nv];
    for j in &model.joints {
        let l = body_link[j.body];
        let s = if l == usize::MAX { 1.0 } else { size[l] };
        let a = j.dof_adr;
        match j.kind {
            JointKind::Revolute { .. } => out[a] = s,
            JointKind::Ball => out[a..a + 3].fill(s),
            JointKind::Free => out[a + 3..a + 6].fill(s),
            JointKind::Planar { .. } => out[a + 2] = s,
            JointKind::Prismatic { .. } => {}
        }
    }
    out
}

/// The sleep state of one simulation (MuJoCo's `tree_asleep` and what it derives), in
/// [`Data::sleep`](super::Data::sleep).
#[derive(Clone, Debug, Default)]
pub struct SleepState {
    /// Per tree, MuJoCo's `tree_asleep`: negative when awake (from −(1 + `MIN_AWAKE`) counting
    /// up, one per step at rest, to −1 "ready to sleep"), else asleep, the index of the next
    /// tree of its island (the sleeping trees of an island form a cycle).
    pub tree_asleep: Vec<i32>,
    /// Per tree, whether it is awake (MuJoCo's `tree_awake`).
    pub tree_awake: Vec<bool>,
    /// Number of awake trees (MuJoCo's `ntree_awake`).
    pub ntree_awake: usize,
    /// The candidate geom pairs the last collision pass tested (after the sleep filter; the
    /// pairs of a run skipped at the body level, `collision::PairRun`, are not counted).
    pub pairs_tested: usize,
    /// Trees put to sleep and trees woken since `Data::new` or the last `reset`.
    pub slept: u64,
    /// Trees woken (by contact, a user change, an equality) since `Data::new` or `reset`.
    pub woken: u64,
    /// qpos as each tree fell asleep (only the sleeping trees' entries are read): a user change
    /// wakes the tree.
    pub(crate) qpos_asleep: Vec<f64>,
    /// Island discovery over trees: union–find parents, whether an island (by its root) has a
    /// tree not ready to sleep, and each island's first and last tree while its cycle is linked.
    pub(crate) parent: Vec<usize>,
    pub(crate) blocked: Vec<bool>,
    pub(crate) first: Vec<usize>,
    pub(crate) last: Vec<usize>,
}

impl SleepState {
    /// The state of `model` with every tree awake (buffers sized once).
    pub fn new(model: &Model) -> Self {
        let n = model.sleep.ntree();
        let mut s = Self {
            tree_asleep: vec![AWAKE; n],
            tree_awake: vec![true; n],
            ntree_awake: n,
            pairs_tested: 0,
            slept: 0,
            woken: 0,
            qpos_asleep: model.qpos0.clone(),
            parent: (0..n).collect(),
            blocked: vec![false; n],
            first: vec![NO_TREE; n],
            last: vec![NO_TREE; n],
        };
        s.reset(model);
        s
    }

    /// Every tree awake — except, with `<flag sleep>`, the trees of policy `init`, each asleep
    /// (its own cycle) at `qpos0`. MuJoCo groups `init` trees by the islands of a first
    /// evaluation; here each is its own island (a touching awake tree wakes it all the same).
    pub fn reset(&mut self, model: &Model) {
        self.tree_asleep.fill(AWAKE);
        self.qpos_asleep.copy_from_slice(&model.qpos0);
        self.slept = 0;
        self.woken = 0;
        self.pairs_tested = 0;
        if model.options.flags.sleep {
            for (t, p) in model.sleep.policy.iter().enumerate() {
                if *p == SleepPolicy::Init {
                    self.tree_asleep[t] = t as i32;
                }
            }
        }
        self.update();
    }

    /// Copies the state of `other` (same model) into `self` without allocating (the transition
    /// Jacobians' nudged steps start from the nominal's sleep state).
    pub fn copy_from(&mut self, other: &SleepState) {
        self.tree_asleep.copy_from_slice(&other.tree_asleep);
        self.qpos_asleep.copy_from_slice(&other.qpos_asleep);
        self.slept = other.slept;
        self.woken = other.woken;
        self.pairs_tested = other.pairs_tested;
        self.update();
    }

    /// `tree_awake` and `ntree_awake` from `tree_asleep` (MuJoCo's `mj_updateSleep`).
    pub fn update(&mut self) {
        let mut n = 0;
        for (awake, &asleep) in self.tree_awake.iter_mut().zip(&self.tree_asleep) {
            *awake = asleep < 0;
            n += usize::from(*awake);
        }
        self.ntree_awake = n;
    }

    /// Whether any tree is asleep.
    pub fn any_asleep(&self) -> bool {
        self.ntree_awake < self.tree_awake.len()
    }

    /// Number of trees asleep.
    pub fn nasleep(&self) -> usize {
        self.tree_awake.len() - self.ntree_awake
    }

    /// Whether the collision pass skips geoms `geom` of `model` (MuJoCo's `filterBodyPair`): both
    /// on sleeping trees, or one on a sleeping tree and the other static (the world, not a mocap
    /// body, which counts as awake).
    pub fn pair_skipped(&self, model: &Model, geom: [usize; 2]) -> bool {
        let side = |g: usize| {
            let geom = &model.geoms[g];
            let t = model.sleep.body_tree[geom.body];
            let asleep = t != NO_TREE && !self.tree_awake[t];
            let fixed = t == NO_TREE && geom.mocap.is_none();
            (asleep, fixed)
        };
        let ((z1, s1), (z2, s2)) = (side(geom[0]), side(geom[1]));
        (z1 && (z2 || s2)) || (z2 && s1)
    }

    /// Whether every tree of `model` sleeps and no mocap geom could touch one: nothing moves, no
    /// pair can touch (the collision pass and the smooth dynamics are skipped).
    pub fn all_asleep(&self, model: &Model) -> bool {
        self.ntree_awake == 0 && !self.tree_awake.is_empty() && !model.sleep.mocap_geoms
    }

    /// Whether equality `e` of `model` has rows: active, and not joining only sleeping trees and
    /// static bodies (MuJoCo leaves those rows out; a mocap body counts as awake).
    pub fn equality_has_rows(&self, model: &Model, e: usize, active: bool) -> bool {
        if !active || self.ntree_awake == self.tree_awake.len() {
            return active;
        }
        use super::EqualityKind;
        // (asleep, awake) of a compiled body, its mocap index when it is a mocap body's frame.
        let side = |body: usize, mocap: bool| {
            let t = model.sleep.body_tree[body];
            if t == NO_TREE {
                (false, mocap)
            } else {
                (!self.tree_awake[t], self.tree_awake[t])
            }
        };
        let frame = |f: usize| side(model.frames[f].body, model.frames[f].mocap.is_some());
        let joint = |j: usize| side(model.joints[j].body, false);
        let ((z1, a1), (z2, a2)) = match model.equalities[e].kind {
            EqualityKind::Connect { frame1, frame2, .. } | EqualityKind::Weld { frame1, frame2, .. } => {
                (frame(frame1), frame(frame2))
            }
            EqualityKind::Joint { joint1, joint2, .. } => {
                (joint(joint1), joint2.map_or((false, false), joint))
            }
            EqualityKind::Mimic { joint: j, leader, .. } => (joint(j), joint(leader)),
            _ => return true,
        };
        a1 || a2 || !(z1 || z2)
    }

    /// Whether dof `k` of `model` is on a sleeping tree.
    pub fn dof_asleep(&self, model: &Model, k: usize) -> bool {
        self.ntree_awake < self.tree_awake.len() && !self.tree_awake[model.sleep.dof_tree[k]]
    }

    /// Whether compiled body `b` (of `model`) is on a sleeping tree (the world never is).
    pub fn body_asleep(&self, model: &Model, b: usize) -> bool {
        let t = model.sleep.body_tree[b];
        t != NO_TREE && !self.tree_awake[t]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn policies_read_from_mjcf_keywords() {
        assert_eq!(SleepPolicy::from_mjcf("init"), Some(SleepPolicy::Init));
        assert_eq!(SleepPolicy::from_mjcf("never"), Some(SleepPolicy::Never));
        assert_eq!(SleepPolicy::from_mjcf("sometimes"), None);
        assert!(!SleepPolicy::AutoNever.may_sleep());
        assert!(SleepPolicy::Init.may_sleep());
    }
}
