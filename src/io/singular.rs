//! The compile step's last check: whether the joint-space mass matrix M(qpos0) is positive
//! definite, so that forward dynamics is defined (massless moving links, duplicated
//! joints). A singular M is a warning naming the joints, not an error: Pinocchio loads massless
//! leaf links and MuJoCo loads duplicated joints, and a model either reference loads must load
//! (kinematics, inverse dynamics and M itself are fine); forward dynamics at such a state is not
//! finite, and a simulation stops at its first step with an error naming the joint.
//!
//! M is factorized as Lᵀ D L along the tree (RBDA §6.3, [`crate::dynamics::factorize_mass_matrix`]);
//! a pivot `D_k` that vanishes relative to `M_kk` means dof k's motion moves nothing the other dofs
//! do not already move. Two cases get their own message:
//! - `M_kk` ≈ 0: the joint carries no mass or inertia about its axis (a massless moving leaf link,
//!   URDF `<mass value="0"/>` or no `<inertial>`): MuJoCo refuses such a model ("mass and inertia of
//!   moving bodies must be larger than mjMINVAL"), Pinocchio loads it and computes infinite
//!   accelerations;
//! - otherwise the joint repeats joints further out in the tree (two identical slide joints on one
//!   body, coincident hinge axes): the joints are named.
//!
//! A massless link whose descendants give its joint inertia passes (Pinocchio simulates it; M is
//! regular).

use crate::dynamics::{crba_unchecked, factorize_mass_matrix};
use crate::io::LinkWord;
use crate::model::{Data, Model, SourceLoc, NO_DOF};

/// `M_kk` at or below this (kg·m² or kg) is no inertia at all (MuJoCo's `mjMINVAL`).
const MINVAL: f64 = 1e-15;
/// A pivot `D_k ≤ PIVOT_REL · M_kk` is singular to round-off.
const PIVOT_REL: f64 = 1e-12;

/// The warning for a model whose mass matrix at `qpos0` is singular, if it is; `joint_locs[j]` is
/// where joint j is written, `word` what a link is called in the file.
pub fn check_mass_matrix(model: &Model, joint_locs: &[SourceLoc], word: LinkWord) -> Option<String> {
    if model.nv == 0 {
        return None;
    }
    let mut data = Data::new(model);
    crba_unchecked(model, &mut data, &model.qpos0);
    let m = data.mass_matrix.clone();
    factorize_mass_matrix(model, &mut data);
    let nv = model.nv;
    let joint_of = |d: usize| model.joints.iter().position(|j| d >= j.dof_adr && d < j.dof_adr + j.kind.nv());
    // Leaves first, the factorization's order: the first vanishing pivot is the culprit (a zero
    // pivot makes every ancestor's NaN).
    for k in (0..nv).rev() {
        let (m_kk, d_k) = (m[(k, k)], data.mass_factor[(k, k)]);
        if m_kk.is_finite() && d_k > PIVOT_REL * m_kk && m_kk > MINVAL {
            continue;
        }
        let Some(j) = joint_of(k) else { continue };
        let joint = &model.joints[j];
        let loc = joint_locs.get(j).cloned().unwrap_or_default();
        // An MJCF body with several joints compiles to bodies named "body/joint": name the body.
        let body = model.bodies[joint.body].name.split('/').next().unwrap_or_default();
        let detail = if m_kk.is_nan() || m_kk <= MINVAL {
            format!(
                "joint '{}' moves nothing: {word} '{body}' and the {word}s it carries have no mass or inertia about the joint's motion (M[{k},{k}] = {m_kk:e}), so its acceleration is undefined and a simulation stops at its first step (MuJoCo refuses such a model: \"mass and inertia of moving bodies must be larger than mjMINVAL\"); give the {word} mass and inertia (URDF <inertial>, MJCF <inertial> or a geom), make the joint fixed, or add armature",
                joint.name
            )
        } else {
            // The dofs further out in the tree coupled to dof k: their joints repeat its motion.
            let others: Vec<String> = (k + 1..nv)
                .filter(|&i| is_ancestor(model, k, i) && m[(k, i)].abs() > PIVOT_REL * m_kk)
                .filter_map(|i| joint_of(i).map(|j| format!("'{}'", model.joints[j].name)))
                .fold(Vec::new(), |mut v, n| {
                    if !v.contains(&n) {
                        v.push(n);
                    }
                    v
                });
            format!(
                "joint '{}' (on {word} '{body}') repeats the motion of joint(s) {}: the mass matrix at qpos0 is singular (pivot {d_k:e} of M[{k},{k}] = {m_kk:e}), so accelerations are not finite and a simulation stops at its first step; remove the duplicate joint or change its axis",
                joint.name,
                others.join(", ")
            )
        };
        return Some(format!("{loc}: <joint>: {detail}"));
    }
    None
}

/// Whether dof `a` is on the path from dof `d` to the root.
fn is_ancestor(model: &Model, a: usize, mut d: usize) -> bool {
    while d != NO_DOF {
        if d == a {
            return true;
        }
        d = model.dof_parent[d];
    }
    false
}
