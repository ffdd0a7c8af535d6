//! Sleeping islands, what a step does (docs/constraints.md, "Sleeping islands"; MuJoCo 4.0
//! documentation, "Simulation → Sleeping islands", and its engine_sleep.c for the semantics):
//! with `<flag sleep>` (soft mode), a tree whose largest dof speed (`dof_length · |v|`) stays
//! below `sleep_tolerance` counts up in `tree_asleep`; when every tree of its constraint island
//! is ready, the island sleeps as the step advances — its velocities are zeroed and from then on
//! it is not collided with static geoms or other sleeping trees (so it has no rows), and its
//! dofs are not integrated (its poses stay). It wakes, all of its island together, when an
//! awake tree or a mocap body touches it, when an active equality joins it to an awake tree, or
//! when the user changes its `qpos`, sets a nonzero `qvel`, `qfrc_applied` or `xfrc_applied`.
//! Nothing here allocates.

use crate::constraint::ConstraintMode;
use crate::model::sleep::{AWAKE, NO_TREE};
use crate::model::{Data, EfcType, EqualityKind, Model};

/// Whether `model` sleeps: `<flag sleep>` in soft mode (the exact mode never does).
pub(crate) fn enabled(model: &Model) -> bool {
    model.options.flags.sleep && model.plan.mode() == ConstraintMode::Soft
}

/// Wakes tree `t` and every tree of its sleeping cycle to `val` (an awake tree only takes `val`
/// when that is more awake); returns the trees woken (MuJoCo's `mj_wakeIsland`).
fn wake_island(tree_asleep: &mut [i32], t: usize, val: i32) -> usize {
    if tree_asleep[t] < 0 {
        tree_asleep[t] = tree_asleep[t].min(val);
        return 0;
    }
    let (mut current, mut n) = (t, 0);
    loop {
        let next = tree_asleep[current];
        tree_asleep[current] = val;
        n += 1;
        // A broken cycle (never written so) ends here rather than looping.
        if next < 0 || next as usize >= tree_asleep.len() || n >= tree_asleep.len() {
            break;
        }
        current = next as usize;
        if current == t {
            break;
        }
    }
    n
}

/// Whether bytes of `x` are all zero (MuJoCo compares bytewise: −0.0 wakes).
fn zero_bits(x: &[f64]) -> bool {
    x.iter().all(|v| v.to_bits() == 0)
}

/// At the start of an evaluation (MuJoCo's `mj_wake` in `mj_kinematics`): the sleeping trees the
/// user changed — `q` not as they fell asleep, a nonzero `v`, `qfrc_applied` or `xfrc_applied` —
/// wake with their islands. Without the flag every sleeping tree wakes. Returns the trees woken.
pub(crate) fn wake_perturbed(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> usize {
    let s = &mut data.sleep;
    if !s.any_asleep() {
        return 0;
    }
    if !enabled(model) {
        let n = s.nasleep();
        s.tree_asleep.fill(AWAKE);
        s.update();
        s.woken += n as u64;
        return n;
    }
    let sm = &model.sleep;
    let mut woken = 0;
    // xfrc_applied of a sleeping tree's bodies.
    for (l, w) in data.xfrc_applied.iter().enumerate() {
        let t = sm.link_tree.get(l).copied().unwrap_or(NO_TREE);
        if t != NO_TREE && !s.tree_awake[t] && s.tree_asleep[t] >= 0 && !zero_bits(w) {
            woken += wake_island(&mut s.tree_asleep, t, AWAKE);
        }
    }
    for t in 0..sm.ntree() {
        if s.tree_asleep[t] < 0 {
            continue;
        }
        let dofs = sm.tree_dof[t]..sm.tree_dof[t + 1];
        let moved = model.joints[sm.tree_joint[t]..sm.tree_joint[t + 1]].iter().any(|j| {
            let r = j.qpos_adr..j.qpos_adr + j.kind.nq();
            q[r.clone()].iter().zip(&s.qpos_asleep[r]).any(|(a, b)| a.to_bits() != b.to_bits())
        });
        let pushed = !zero_bits(&v[dofs.clone()]) || !zero_bits(&data.qfrc_applied.as_slice()[dofs]);
        if moved || pushed || !sm.policy[t].may_sleep() {
            woken += wake_island(&mut s.tree_asleep, t, AWAKE);
        }
    }
    if woken > 0 {
        s.update();
        s.woken += woken as u64;
    }
    woken
}

/// The tree of compiled body `b` and whether it is a mocap body's geom (static but awake).
fn geom_tree(model: &Model, g: usize) -> (usize, bool) {
    let geom = &model.geoms[g];
    (model.sleep.body_tree[geom.body], geom.mocap.is_some())
}

/// After collision (MuJoCo's `mj_wakeCollision`): a sleeping tree touching an awake tree or a
/// mocap body wakes with its island (to the awake tree's count). Returns the trees woken; the
/// caller collides again, for the contacts of the woken trees with the world and each other.
pub(crate) fn wake_touched(model: &Model, data: &mut Data) -> usize {
    let s = &mut data.sleep;
    if !s.any_asleep() || !enabled(model) {
        return 0;
    }
    let mut woken = 0;
    for c in &data.contacts {
        let ((t1, m1), (t2, m2)) = (geom_tree(model, c.geom[0]), geom_tree(model, c.geom[1]));
        if t1 == NO_TREE || t2 == NO_TREE {
            let (t, mocap) = if t1 == NO_TREE { (t2, m1) } else { (t1, m2) };
            if t != NO_TREE && mocap && !s.tree_awake[t] {
                woken += wake_island(&mut s.tree_asleep, t, AWAKE);
            }
            continue;
        }
        let (a1, a2) = (s.tree_awake[t1], s.tree_awake[t2]);
        if a1 != a2 {
            let (sleeping, awake) = if a1 { (t2, t1) } else { (t1, t2) };
            let val = s.tree_asleep[awake];
            woken += wake_island(&mut s.tree_asleep, sleeping, val);
        }
    }
    if woken > 0 {
        s.update();
        s.woken += woken as u64;
    }
    woken
}

/// After collision (MuJoCo's `mj_wakeEquality`): an active connect, weld, joint or mimic
/// equality between a sleeping tree and an awake one (or a mocap body) wakes the sleeping
/// island; between two sleeping trees of different islands it wakes both.
pub(crate) fn wake_joined(model: &Model, data: &mut Data) -> usize {
    let s = &mut data.sleep;
    if !s.any_asleep() || !enabled(model) {
        return 0;
    }
    let sm = &model.sleep;
    // (tree, awake-static): a frame's or a joint's body.
    let of_frame = |f: usize| {
        let fr = &model.frames[f];
        (sm.body_tree[fr.body], fr.mocap.is_some())
    };
    let of_joint = |j: usize| (sm.body_tree[model.joints[j].body], false);
    let mut woken = 0;
    for (e, eq) in model.equalities.iter().enumerate() {
        if !data.eq_active.get(e).copied().unwrap_or(eq.active) {
            continue;
        }
        let ((t1, m1), (t2, m2)) = match eq.kind {
            EqualityKind::Connect { frame1, frame2, .. } | EqualityKind::Weld { frame1, frame2, .. } => {
                (of_frame(frame1), of_frame(frame2))
            }
            EqualityKind::Joint { joint1, joint2, .. } => {
                (of_joint(joint1), joint2.map_or((NO_TREE, false), of_joint))
            }
            EqualityKind::Mimic { joint, leader, .. } => (of_joint(joint), of_joint(leader)),
            _ => continue,
        };
        let asleep = |t: usize, s: &crate::model::sleep::SleepState| t != NO_TREE && !s.tree_awake[t];
        let (z1, z2) = (asleep(t1, s), asleep(t2, s));
        if !z1 && !z2 || t1 == t2 {
            continue;
        }
        // A static (not mocap) side leaves the sleeping tree asleep.
        if (t1 == NO_TREE && !m1) || (t2 == NO_TREE && !m2) {
            continue;
        }
        if z1 && z2 {
            if cycle_min(&s.tree_asleep, t1) != cycle_min(&s.tree_asleep, t2) {
                woken += wake_island(&mut s.tree_asleep, t1, AWAKE);
                woken += wake_island(&mut s.tree_asleep, t2, AWAKE);
            }
            continue;
        }
        woken += wake_island(&mut s.tree_asleep, if z1 { t1 } else { t2 }, AWAKE);
    }
    if woken > 0 {
        s.update();
        s.woken += woken as u64;
    }
    woken
}

/// The smallest tree of the sleeping cycle through `t` (MuJoCo's `mj_sleepCycle`).
fn cycle_min(tree_asleep: &[i32], t: usize) -> usize {
    let (mut current, mut smallest) = (t, t);
    for _ in 0..tree_asleep.len() {
        let next = tree_asleep[current];
        if next < 0 {
            break;
        }
        current = next as usize;
        smallest = smallest.min(current);
        if current == t {
            break;
        }
    }
    smallest
}

/// Union–find root of tree `t`.
fn root(parent: &mut [usize], mut t: usize) -> usize {
    while parent[t] != t {
        parent[t] = parent[parent[t]];
        t = parent[t];
    }
    t
}

/// As the step advances (MuJoCo's `mj_sleep` in `mj_advance`), after the evaluation at the
/// step's start (`q`, `v`, its rows in `data`): each awake tree that may sleep — its policy,
/// no applied force, every `dof_length · |v|` below `sleep_tolerance` — counts one step towards
/// sleeping (others go back to fully awake); every island (the trees the rows join) whose trees
/// are all ready sleeps: its trees form a cycle in `tree_asleep`, their `v` and `qacc` are
/// zeroed and `q` recorded. Returns the trees put to sleep.
pub(crate) fn sleep_islands(model: &Model, data: &mut Data, q: &[f64], v: &mut [f64]) -> usize {
    if !enabled(model) {
        return 0;
    }
    let sm = &model.sleep;
    let n = sm.ntree();
    let tol = model.options.sleep_tolerance;
    let mut ready = false;
    {
        let s = &mut data.sleep;
        for t in 0..n {
            if s.tree_asleep[t] >= 0 {
                continue;
            }
            let dofs = sm.tree_dof[t]..sm.tree_dof[t + 1];
            let mut can = sm.policy[t].may_sleep() && zero_bits(&data.qfrc_applied.as_slice()[dofs.clone()]);
            if can {
                can = v[dofs.clone()].iter().zip(&sm.dof_length[dofs]).all(|(x, l)| l * x.abs() < tol);
            }
            if can {
                if s.tree_asleep[t] < -1 {
                    s.tree_asleep[t] += 1;
                }
            } else {
                s.tree_asleep[t] = AWAKE;
            }
            ready |= s.tree_asleep[t] == -1;
        }
        // xfrc_applied on a tree's body keeps it awake.
        for (l, w) in data.xfrc_applied.iter().enumerate() {
            let t = sm.link_tree.get(l).copied().unwrap_or(NO_TREE);
            if t != NO_TREE && s.tree_asleep[t] < 0 && !zero_bits(w) {
                s.tree_asleep[t] = AWAKE;
            }
        }
    }
    if !ready {
        return 0;
    }
    // Islands: the awake trees the rows join.
    let Data { sleep: s, efc_type, efc_id, efc_j, contacts, nefc, qacc, .. } = data;
    let data_qacc = qacc.as_mut_slice();
    for t in 0..n {
        s.parent[t] = t;
    }
    for r in 0..*nefc {
        let mut first = NO_TREE;
        let mut join = |t: usize, s: &mut crate::model::sleep::SleepState| {
            if t == NO_TREE || !s.tree_awake[t] {
                return;
            }
            if first == NO_TREE {
                first = t;
            } else {
                let (a, b) = (root(&mut s.parent, first), root(&mut s.parent, t));
                if a != b {
                    s.parent[a.max(b)] = a.min(b);
                }
            }
        };
        match efc_type[r] {
            EfcType::ContactFrictionless | EfcType::ContactElliptic | EfcType::ContactPyramidal => {
                let c = &contacts[efc_id[r]];
                join(geom_tree(model, c.geom[0]).0, s);
                join(geom_tree(model, c.geom[1]).0, s);
            }
            _ => {
                let mut k = 0;
                while k < model.nv {
                    if efc_j[(r, k)] != 0.0 {
                        let t = sm.dof_tree[k];
                        join(t, s);
                        k = sm.tree_dof[t + 1];
                    } else {
                        k += 1;
                    }
                }
            }
        }
    }
    // An island sleeps when all of its trees are ready: each tree's root, the roots blocked.
    for t in 0..n {
        let r = root(&mut s.parent, t);
        s.parent[t] = r;
        s.first[t] = NO_TREE;
        s.last[t] = NO_TREE;
    }
    for t in 0..n {
        s.blocked[t] = false;
    }
    for t in 0..n {
        if s.tree_awake[t] && s.tree_asleep[t] != -1 {
            s.blocked[s.parent[t]] = true;
        }
    }
    // The ready islands' trees, in ascending order, linked into cycles.
    let mut slept = 0;
    for t in 0..n {
        let r = s.parent[t];
        if !s.tree_awake[t] || s.blocked[r] {
            continue;
        }
        if s.last[r] == NO_TREE {
            s.first[r] = t;
        } else {
            s.tree_asleep[s.last[r]] = t as i32;
        }
        s.last[r] = t;
        let dofs = sm.tree_dof[t]..sm.tree_dof[t + 1];
        v[dofs.clone()].fill(0.0);
        data_qacc[dofs].fill(0.0);
        for j in &model.joints[sm.tree_joint[t]..sm.tree_joint[t + 1]] {
            let r = j.qpos_adr..j.qpos_adr + j.kind.nq();
            s.qpos_asleep[r.clone()].copy_from_slice(&q[r]);
        }
        slept += 1;
    }
    for r in 0..n {
        if s.last[r] != NO_TREE {
            s.tree_asleep[s.last[r]] = s.first[r] as i32;
        }
    }
    if slept > 0 {
        s.update();
        s.slept += slept as u64;
    }
    slept
}

/// After the velocities are advanced: the sleeping trees' velocities stay zero.
pub(crate) fn hold_velocities(model: &Model, data: &Data, v: &mut [f64]) {
    let (s, sm) = (&data.sleep, &model.sleep);
    if !s.any_asleep() {
        return;
    }
    for t in 0..sm.ntree() {
        if !s.tree_awake[t] {
            v[sm.tree_dof[t]..sm.tree_dof[t + 1]].fill(0.0);
        }
    }
}

/// `q ⊕ h v` for the awake trees only (a sleeping tree's `q` keeps its bits).
pub(crate) fn integrate_awake(model: &Model, data: &Data, q: &mut [f64], v: &[f64], h: f64) {
    let (s, sm) = (&data.sleep, &model.sleep);
    if !s.any_asleep() {
        crate::model::integrate_configuration_unchecked(model, q, v, h);
        return;
    }
    for t in 0..sm.ntree() {
        if !s.tree_awake[t] {
            continue;
        }
        for j in &model.joints[sm.tree_joint[t]..sm.tree_joint[t + 1]] {
            let (qa, va) = (j.qpos_adr, j.dof_adr);
            j.kind.integrate(&mut q[qa..qa + j.kind.nq()], &v[va..va + j.kind.nv()], h);
        }
    }
}

/// The sleeping trees' accelerations are zero (they do not move) — after an evaluation.
pub(crate) fn zero_sleeping_acceleration(model: &Model, data: &mut Data) {
    let sm = &model.sleep;
    if !data.sleep.any_asleep() {
        return;
    }
    for t in 0..sm.ntree() {
        if !data.sleep.tree_awake[t] {
            data.qacc.as_mut_slice()[sm.tree_dof[t]..sm.tree_dof[t + 1]].fill(0.0);
        }
    }
}
