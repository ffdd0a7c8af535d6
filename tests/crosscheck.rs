//! Algorithms checked against each other (docs/architecture.md, "Truth"): ABA against the mass matrix, RNEA
//! against ABA, CRBA against RNEA columns, Jacobians against propagated velocities and against
//! finite differences of forward kinematics, the energy balance dE/dt = τ·v, momentum, and a free
//! rigid body against Euler's equations. On random trees covering every joint type and on the four
//! shipped robots. Tolerances come from `common`.
//!
//! Run with `cargo test --release --test crosscheck -- --nocapture` to see the one-line summaries.

mod common;

use common::*;
use lagrange::dynamics::{
    aba, bias_forces, center_of_mass, crba, factorize_mass_matrix, kinetic_energy, potential_energy, rnea,
    solve_mass_matrix, spatial_momentum,
};
use lagrange::io::compile;
use lagrange::kinematics::{
    forward_kinematics, forward_velocities, frame_jacobian, frame_velocity, ReferenceFrame,
};
use lagrange::model::spec::{InertialSpec, JointSpec, JointType, LinkSpec, ModelSpec};
use lagrange::model::{difference_configuration, integrate_configuration};
use lagrange::model::{JointKind, SourceLoc};
use lagrange::spatial::{quat_to_matrix, Force, Mat3, Motion, Transform, Vec3};
use lagrange::{Data, Model};
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use std::collections::BTreeMap;

/// Random states per model and check.
const STATES: usize = 4;
/// Random states per model for the (costlier) finite-difference check.
const FD_STATES: usize = 2;

const REFERENCE_FRAMES: [ReferenceFrame; 3] =
    [ReferenceFrame::Local, ReferenceFrame::LocalWorldAligned, ReferenceFrame::World];

fn trees() -> Vec<(String, Model)> {
    random_trees().into_iter().map(|(name, _, model)| (name, model)).collect()
}

fn dvec(x: &[f64]) -> DVector<f64> {
    DVector::from_column_slice(x)
}

fn stack(lin: &Vec3, ang: &Vec3) -> [f64; 6] {
    [lin.x, lin.y, lin.z, ang.x, ang.y, ang.z]
}

/// Rotation vector of a rotation matrix (the SO(3) logarithm), accurate for small angles: the sine
/// comes from the skew part and the angle from atan2, never from acos of the trace.
fn log_so3(r: &Mat3) -> Vec3 {
    let s = Vec3::new(r[(2, 1)] - r[(1, 2)], r[(0, 2)] - r[(2, 0)], r[(1, 0)] - r[(0, 1)]) * 0.5;
    let sin = s.norm();
    let cos = 0.5 * (r.trace() - 1.0);
    let angle = sin.atan2(cos);
    if sin < 1e-300 {
        s
    } else {
        s * (angle / sin)
    }
}

/// The index of a frame attached to body `b` (every body keeps the frame of its own link).
fn frame_of_body(model: &Model, b: usize) -> usize {
    model.frames.iter().position(|f| f.body == b).expect("every body has a frame")
}

/// A copy of the model without gravity (body accelerations from its RNEA are the true ones).
fn without_gravity(model: &Model) -> Model {
    let mut m = model.clone();
    m.gravity = Vec3::zeros();
    m
}

// ------------------------------------------------------------------------------------------------
// Coverage of the random trees
// ------------------------------------------------------------------------------------------------

#[test]
fn random_trees_cover_every_joint_type() {
    let mut count: BTreeMap<String, usize> = BTreeMap::new();
    let (mut armature, mut free_inner, mut fixed_root, mut fused_massive, mut fused_massless) =
        (0, 0, 0, 0, 0);
    let mut bodies = 0;
    for (_, spec, model) in random_trees() {
        bodies = bodies.max(model.nbody() - 1);
        for (i, l) in spec.links.iter().enumerate() {
            *count.entry(format!("{:?}", l.joint.jtype)).or_default() += 1;
            if l.joint.armature > 0.0 {
                armature += 1;
            }
            if i > 0 && l.joint.jtype == JointType::Floating {
                free_inner += 1;
            }
            if i == 0 && l.joint.jtype == JointType::Fixed {
                fixed_root += 1;
            }
            if l.joint.jtype == JointType::Fixed {
                if l.inertial.is_some() {
                    fused_massive += 1;
                } else {
                    fused_massless += 1;
                }
            }
        }
        // Every link stays addressable as a frame.
        assert_eq!(model.frames.len(), spec.links.len());
    }
    println!(
        "random trees: {} trees, up to {bodies} bodies; joints {count:?}; armature>0: {armature}; \
         free below the root: {free_inner}; fixed roots: {fixed_root}; fused fixed links with mass: \
         {fused_massive}, massless: {fused_massless}",
        TREE_SIZES.len()
    );
    for t in ALL_JOINT_TYPES {
        assert!(
            count.get(&format!("{t:?}")).copied().unwrap_or(0) >= 2,
            "joint type {t:?} under-represented"
        );
    }
    assert!(armature >= 5 && free_inner >= 1 && fixed_root >= 1 && fused_massive >= 1 && fused_massless >= 1);
    assert!(TREE_SIZES.len() >= 20 && bodies >= 28);
}

// ------------------------------------------------------------------------------------------------
// 1. ABA = M⁻¹(τ − c)
// ------------------------------------------------------------------------------------------------

fn check_aba_against_mass_matrix(models: &[(String, Model)], seed: u64) {
    let mut e_sparse = MaxErr::new("ABA vs sparse LtDL solve M^-1 (tau - c)", ALGO_REL);
    let mut e_chol = MaxErr::new("ABA vs dense Cholesky solve", ALGO_REL);
    let mut e_lu = MaxErr::new("sparse LtDL solve vs dense LU solve", ALGO_REL);
    let mut max_cond: f64 = 0.0;
    for (name, model) in models {
        let mut data = Data::new(model);
        let mut r = rng(seed);
        for s in 0..STATES {
            let (q, v, tau) = (random_q(model, &mut r), random_v(model, &mut r), random_tau(model, &mut r));
            let qacc = aba(model, &mut data, &q, &v, &tau).unwrap().clone();
            let c = bias_forces(model, &mut data, &q, &v).unwrap().clone();
            let rhs = dvec(&tau) - c;
            crba(model, &mut data, &q).unwrap();
            factorize_mass_matrix(model, &mut data);
            let mut x_sparse = rhs.clone();
            solve_mass_matrix(model, &data, &mut x_sparse).unwrap();
            let m = data.mass_matrix.clone();
            let eig = m.clone().symmetric_eigenvalues();
            max_cond = max_cond.max(eig.max() / eig.min());
            let x_chol = m.clone().cholesky().expect("M must be positive definite").solve(&rhs);
            let x_lu = m.lu().solve(&rhs).expect("M must be invertible");
            let at = || format!("{name}, state {s}");
            e_sparse.add(rel_err_vec(qacc.as_slice(), x_sparse.as_slice()), at);
            e_chol.add(rel_err_vec(qacc.as_slice(), x_chol.as_slice()), at);
            e_lu.add(rel_err_vec(x_sparse.as_slice(), x_lu.as_slice()), at);
        }
    }
    println!("(largest cond(M) seen: {max_cond:.3e})");
    report_and_assert(&[&e_sparse, &e_chol, &e_lu]);
}

#[test]
fn aba_equals_mass_matrix_solve_random_trees() {
    check_aba_against_mass_matrix(&trees(), 11);
}

#[test]
fn aba_equals_mass_matrix_solve_robots() {
    check_aba_against_mass_matrix(&robots(), 12);
}

// ------------------------------------------------------------------------------------------------
// 2. RNEA(q, v, ABA(q, v, τ)) = τ
// ------------------------------------------------------------------------------------------------

fn check_rnea_inverts_aba(models: &[(String, Model)], seed: u64) {
    let mut e = MaxErr::new("RNEA(q, v, ABA(q, v, tau)) vs tau", ALGO_REL);
    for (name, model) in models {
        let mut data = Data::new(model);
        let mut r = rng(seed);
        for s in 0..STATES {
            let (q, v, tau) = (random_q(model, &mut r), random_v(model, &mut r), random_tau(model, &mut r));
            let qacc = aba(model, &mut data, &q, &v, &tau).unwrap().clone();
            let tau2 = rnea(model, &mut data, &q, &v, qacc.as_slice()).unwrap();
            e.add(rel_err_vec(tau2.as_slice(), &tau), || format!("{name}, state {s}"));
        }
    }
    report_and_assert(&[&e]);
}

#[test]
fn rnea_inverts_aba_random_trees() {
    check_rnea_inverts_aba(&trees(), 21);
}

#[test]
fn rnea_inverts_aba_robots() {
    check_rnea_inverts_aba(&robots(), 22);
}

// ------------------------------------------------------------------------------------------------
// 3. M symmetric positive definite; M eₖ = RNEA(q, 0, eₖ) − RNEA(q, 0, 0)
// ------------------------------------------------------------------------------------------------

fn check_mass_matrix(models: &[(String, Model)], seed: u64) {
    let mut e_sym = MaxErr::new("CRBA: M vs M^T", ALGO_REL);
    let mut e_cols = MaxErr::new("CRBA vs columns RNEA(q,0,e_k) - RNEA(q,0,0)", ALGO_REL);
    let mut e_pd = MaxErr::new("CRBA: Cholesky of M fails (0 = succeeds)", 0.0);
    for (name, model) in models {
        let mut data = Data::new(model);
        let mut r = rng(seed);
        let nv = model.nv;
        for s in 0..STATES {
            let q = random_q(model, &mut r);
            let m = crba(model, &mut data, &q).unwrap().clone();
            let at = || format!("{name}, state {s}");
            e_sym.add(rel_err_mat(&m, &m.transpose()), at);
            e_pd.add(if m.clone().cholesky().is_some() { 0.0 } else { 1.0 }, at);
            let zero = vec![0.0; nv];
            let g = rnea(model, &mut data, &q, &zero, &zero).unwrap().clone();
            let mut m_cols = DMatrix::zeros(nv, nv);
            let mut e_k = vec![0.0; nv];
            for k in 0..nv {
                e_k[k] = 1.0;
                let col = rnea(model, &mut data, &q, &zero, &e_k).unwrap() - &g;
                m_cols.set_column(k, &col);
                e_k[k] = 0.0;
            }
            e_cols.add(rel_err_mat(&m, &m_cols), at);
        }
    }
    report_and_assert(&[&e_sym, &e_pd, &e_cols]);
}

#[test]
fn mass_matrix_spd_and_equals_rnea_columns_random_trees() {
    check_mass_matrix(&trees(), 31);
}

#[test]
fn mass_matrix_spd_and_equals_rnea_columns_robots() {
    check_mass_matrix(&robots(), 32);
}

// ------------------------------------------------------------------------------------------------
// 4a. J(q) v = frame velocity, every frame, every reference frame
// ------------------------------------------------------------------------------------------------

fn check_jacobian_times_v(models: &[(String, Model)], seed: u64) {
    let mut errs: Vec<MaxErr> = REFERENCE_FRAMES
        .iter()
        .map(|rf| MaxErr::new(&format!("J v vs frame_velocity, {rf:?}"), ALGO_REL))
        .collect();
    for (name, model) in models {
        let mut data = Data::new(model);
        let mut jac = DMatrix::zeros(6, model.nv);
        let mut r = rng(seed);
        for s in 0..STATES {
            let (q, v) = (random_q(model, &mut r), random_v(model, &mut r));
            forward_kinematics(model, &mut data, &q).unwrap();
            forward_velocities(model, &mut data, &v).unwrap();
            let v_vec = dvec(&v);
            for (f, frame) in model.frames.iter().enumerate() {
                for (rf, e) in REFERENCE_FRAMES.iter().zip(errs.iter_mut()) {
                    frame_jacobian(model, &data, f, *rf, &mut jac).unwrap();
                    let jv = &jac * &v_vec;
                    let (lin, ang) = frame_velocity(model, &data, f, *rf).unwrap();
                    e.add(rel_err_vec(jv.as_slice(), &stack(&lin, &ang)), || {
                        format!("{name}, state {s}, frame {}", frame.name)
                    });
                }
            }
        }
    }
    report_and_assert(&errs.iter().collect::<Vec<_>>());
}

#[test]
fn jacobian_times_v_equals_frame_velocity_random_trees() {
    check_jacobian_times_v(&trees(), 41);
}

#[test]
fn jacobian_times_v_equals_frame_velocity_robots() {
    check_jacobian_times_v(&robots(), 42);
}

// ------------------------------------------------------------------------------------------------
// 4b. Jacobians against finite differences of forward kinematics on the manifold
// ------------------------------------------------------------------------------------------------

/// Central differences with step `h` along every unit tangent, for every frame: (ṗ, ω_world,
/// ω_local) per frame and degree of freedom.
fn central_differences(model: &Model, data: &mut Data, q: &[f64], h: f64) -> Vec<Vec<[Vec3; 3]>> {
    let nf = model.frames.len();
    let mut out = vec![vec![[Vec3::zeros(); 3]; model.nv]; nf];
    let mut e_k = vec![0.0; model.nv];
    for k in 0..model.nv {
        e_k[k] = 1.0;
        let mut q_plus = q.to_vec();
        integrate_configuration(model, &mut q_plus, &e_k, h).unwrap();
        let mut q_minus = q.to_vec();
        integrate_configuration(model, &mut q_minus, &e_k, -h).unwrap();
        e_k[k] = 0.0;
        forward_kinematics(model, data, &q_plus).unwrap();
        let plus = data.x_world_frame.clone();
        forward_kinematics(model, data, &q_minus).unwrap();
        for f in 0..nf {
            let (xp, xm) = (&plus[f], &data.x_world_frame[f]);
            let p_dot = (xp.pos - xm.pos) / (2.0 * h);
            let w_world = log_so3(&(xp.rot * xm.rot.transpose())) / (2.0 * h);
            let w_local = log_so3(&(xm.rot.transpose() * xp.rot)) / (2.0 * h);
            out[f][k] = [p_dot, w_world, w_local];
        }
    }
    out
}

fn check_jacobian_finite_differences(models: &[(String, Model)], seed: u64) {
    let mut errs: Vec<MaxErr> = REFERENCE_FRAMES
        .iter()
        .map(|rf| MaxErr::new(&format!("Jacobian vs Richardson central FD of FK, {rf:?}"), FD_REL))
        .collect();
    for (name, model) in models {
        let mut data = Data::new(model);
        let mut jac = DMatrix::zeros(6, model.nv);
        let mut r = rng(seed);
        for s in 0..FD_STATES {
            let q = random_q(model, &mut r);
            let d_h = central_differences(model, &mut data, &q, FD_STEP);
            let d_h2 = central_differences(model, &mut data, &q, FD_STEP / 2.0);
            forward_kinematics(model, &mut data, &q).unwrap();
            for (f, frame) in model.frames.iter().enumerate() {
                let x = data.x_world_frame[f];
                // Richardson: (4 D(h/2) − D(h)) / 3, per column.
                let mut fd =
                    [DMatrix::zeros(6, model.nv), DMatrix::zeros(6, model.nv), DMatrix::zeros(6, model.nv)];
                for k in 0..model.nv {
                    let ex = |i: usize| (d_h2[f][k][i] * 4.0 - d_h[f][k][i]) / 3.0;
                    let (p_dot, w_world, w_local) = (ex(0), ex(1), ex(2));
                    let cols = [
                        stack(&x.rot.tr_mul(&p_dot), &w_local),            // Local
                        stack(&p_dot, &w_world),                           // LocalWorldAligned
                        stack(&(p_dot - w_world.cross(&x.pos)), &w_world), // World
                    ];
                    for (m, col) in fd.iter_mut().zip(cols) {
                        m.column_mut(k).copy_from_slice(&col);
                    }
                }
                for ((rf, e), fd_m) in REFERENCE_FRAMES.iter().zip(errs.iter_mut()).zip(&fd) {
                    frame_jacobian(model, &data, f, *rf, &mut jac).unwrap();
                    let (err, (row, col)) = rel_err_mat_at(&jac, fd_m);
                    e.add(err, || format!("{name}, state {s}, frame {}, ({row}, {col})", frame.name));
                }
            }
        }
    }
    report_and_assert(&errs.iter().collect::<Vec<_>>());
}

#[test]
fn jacobian_matches_finite_differences_random_trees() {
    check_jacobian_finite_differences(&trees(), 43);
}

#[test]
fn jacobian_matches_finite_differences_robots() {
    check_jacobian_finite_differences(&robots(), 44);
}

// ------------------------------------------------------------------------------------------------
// 5. Energy: d(T + V)/dt = τ·v without passive forces; T = ½ vᵀ M v; V = −m g·c
// ------------------------------------------------------------------------------------------------

fn check_energy(models: &[(String, Model)], seed: u64) {
    let mut e_rate = MaxErr::new("d(T+V)/dt vs tau.v (rel. to sum |terms|)", ALGO_REL);
    let mut e_kin = MaxErr::new("kinetic_energy vs 1/2 v^T M v", ALGO_REL);
    let mut e_pot = MaxErr::new("potential_energy vs -m_total g.com", ALGO_REL);
    for (name, model) in models {
        let model0 = without_gravity(model);
        let mut data = Data::new(model);
        let mut data0 = Data::new(&model0);
        let mut r = rng(seed);
        let moving_mass: f64 = model.bodies[1..].iter().map(|b| b.mass()).sum();
        for s in 0..STATES {
            let (q, v, tau) = (random_q(model, &mut r), random_v(model, &mut r), random_tau(model, &mut r));
            let at = || format!("{name}, state {s}");
            let qacc = aba(model, &mut data, &q, &v, &tau).unwrap().clone();
            // True (gravity-free) body accelerations at q̈.
            rnea(&model0, &mut data0, &q, &v, qacc.as_slice()).unwrap();
            forward_kinematics(&model0, &mut data0, &q).unwrap();
            let mut terms = Vec::new();
            for b in 1..model.nbody() {
                let inertia = &model.bodies[b].inertia;
                let (v_b, a_b) = (&data0.v_body[b], &data0.a_body[b]);
                // dT_b/dt = v_b · (I_b a_b) (I_b constant in body coordinates, v ×* I v ⟂ v).
                terms.push(v_b.dot(&inertia.mul_motion(a_b)));
                // dV_b/dt = −m_b g · ċ_b, ċ_b = R_b (v_lin + ω × c_b).
                let c_dot = data0.x_world_body[b].rot * (v_b.lin + v_b.ang.cross(&inertia.com()));
                terms.push(-inertia.mass * model.gravity.dot(&c_dot));
            }
            for k in 0..model.nv {
                terms.push(model.dof_armature[k] * v[k] * qacc[k]);
            }
            let power: Vec<f64> = tau.iter().zip(&v).map(|(t, w)| t * w).collect();
            let scale: f64 =
                terms.iter().map(|t| t.abs()).sum::<f64>().max(power.iter().map(|p| p.abs()).sum::<f64>());
            let diff = terms.iter().sum::<f64>() - power.iter().sum::<f64>();
            e_rate.add(diff.abs() / scale.max(REL_FLOOR), at);

            let t = kinetic_energy(model, &mut data, &q, &v).unwrap();
            let m = crba(model, &mut data, &q).unwrap();
            let v_vec = dvec(&v);
            let t_m = 0.5 * v_vec.dot(&(m * &v_vec));
            e_kin.add(rel_err(t, t_m), at);

            forward_kinematics(model, &mut data, &q).unwrap();
            let pot = potential_energy(model, &data);
            let com = center_of_mass(model, &data);
            e_pot.add(rel_err(pot, -moving_mass * model.gravity.dot(&com)), at);
        }
    }
    report_and_assert(&[&e_rate, &e_kin, &e_pot]);
}

#[test]
fn energy_balance_random_trees() {
    check_energy(&trees(), 51);
}

#[test]
fn energy_balance_robots() {
    check_energy(&robots(), 52);
}

// ------------------------------------------------------------------------------------------------
// 6. Momentum
// ------------------------------------------------------------------------------------------------

/// Whether the whole tree hangs from the world by one free joint (so that gravity is the only
/// external wrench when that joint's generalized force is zero).
fn single_free_root(model: &Model) -> bool {
    model.joints.first().is_some_and(|j| j.kind == JointKind::Free)
        && model.joints.iter().filter(|j| j.parent == 0).count() == 1
}

fn check_momentum(models: &[(String, Model)], seed: u64) {
    let mut e_lin = MaxErr::new("spatial_momentum lin vs sum m_b cdot_b (Jacobians)", ALGO_REL);
    let mut e_ang = MaxErr::new("spatial_momentum ang vs sum (c x m cdot + R Ic R^T w)", ALGO_REL);
    let mut e_com = MaxErr::new("com velocity vs Richardson FD of center_of_mass", FD_REL);
    let mut e_rate = MaxErr::new("free root, tau_root=0: dh/dt vs gravity wrench", ALGO_REL);
    let mut free_models = 0;
    for (name, model) in models {
        let mut data = Data::new(model);
        let mut data0 = Data::new(model);
        let mut jac = DMatrix::zeros(6, model.nv);
        let mut r = rng(seed);
        let moving_mass: f64 = model.bodies[1..].iter().map(|b| b.mass()).sum();
        for s in 0..STATES {
            let (q, v, mut tau) =
                (random_q(model, &mut r), random_v(model, &mut r), random_tau(model, &mut r));
            let at = || format!("{name}, state {s}");
            forward_kinematics(model, &mut data, &q).unwrap();
            forward_velocities(model, &mut data, &v).unwrap();
            let h = spatial_momentum(model, &data);
            // Independent construction: point velocities of the centres of mass from the
            // world-aligned Jacobians, angular momentum about the world origin.
            let v_vec = dvec(&v);
            let (mut lin, mut ang) = (Vec3::zeros(), Vec3::zeros());
            for b in 1..model.nbody() {
                let body = &model.bodies[b];
                let f = frame_of_body(model, b);
                frame_jacobian(model, &data, f, ReferenceFrame::LocalWorldAligned, &mut jac).unwrap();
                let jv = &jac * &v_vec;
                let (p_dot, w) = (Vec3::new(jv[0], jv[1], jv[2]), Vec3::new(jv[3], jv[4], jv[5]));
                let x = &data.x_world_body[b];
                let c = x.act_point(&body.com());
                let c_dot = p_dot + w.cross(&(c - data.x_world_frame[f].pos));
                lin += c_dot * body.mass();
                ang += c.cross(&c_dot) * body.mass() + x.rot * body.inertia_com() * x.rot.tr_mul(&w);
            }
            let scale_h = [h.lin, h.ang, lin, ang].iter().map(|x| x.amax()).fold(0.0, f64::max);
            e_lin.add((h.lin - lin).amax() / scale_h.max(REL_FLOOR), at);
            e_ang.add((h.ang - ang).amax() / scale_h.max(REL_FLOOR), at);
            // ċ_com = h_lin / m against finite differences of the centre of mass along v.
            if moving_mass > 0.0 {
                let com_at = |data: &mut Data, t: f64| {
                    let mut qt = q.clone();
                    integrate_configuration(model, &mut qt, &v, t).unwrap();
                    forward_kinematics(model, data, &qt).unwrap();
                    center_of_mass(model, data)
                };
                let mut central = |hh: f64| (com_at(&mut data, hh) - com_at(&mut data, -hh)) / (2.0 * hh);
                let fd = (central(FD_STEP / 2.0) * 4.0 - central(FD_STEP)) / 3.0;
                let v_com = h.lin / moving_mass;
                e_com.add(rel_err_vec(v_com.as_slice(), fd.as_slice()), at);
            }
            // dh/dt = gravity wrench when the tree floats freely and its root is not pushed.
            // Armature on the root joint would be an external reaction (MuJoCo's armature is a
            // rotor inertia whose reaction goes nowhere), so it is removed for this check; inner
            // joints' armature only changes internal forces and stays.
            if single_free_root(model) {
                if s == 0 {
                    free_models += 1;
                }
                tau[..6].fill(0.0);
                let mut model_r = model.clone();
                model_r.dof_armature[..6].fill(0.0);
                model_r.joints[0].armature = 0.0;
                let model_r0 = without_gravity(&model_r);
                let qacc = aba(&model_r, &mut data, &q, &v, &tau).unwrap().clone();
                rnea(&model_r0, &mut data0, &q, &v, qacc.as_slice()).unwrap();
                forward_kinematics(&model_r0, &mut data0, &q).unwrap();
                let mut rate = Force::zero();
                let mut wrench = Force::zero();
                for b in 1..model.nbody() {
                    let inertia = &model.bodies[b].inertia;
                    let (v_b, a_b) = (&data0.v_body[b], &data0.a_body[b]);
                    let f_b = inertia.mul_motion(a_b) + v_b.cross_force(&inertia.mul_motion(v_b));
                    rate += data0.x_world_body[b].act_force(&f_b);
                    let c = data0.x_world_body[b].act_point(&inertia.com());
                    let weight = model.gravity * inertia.mass;
                    wrench += Force::new(c.cross(&weight), weight);
                }
                e_rate.add(rel_err_vec(&stack(&rate.lin, &rate.ang), &stack(&wrench.lin, &wrench.ang)), at);
            }
        }
    }
    println!("({free_models} models float on a single free root: momentum-rate check applied)");
    let mut checks = vec![&e_lin, &e_ang, &e_com];
    if free_models > 0 {
        checks.push(&e_rate);
    }
    report_and_assert(&checks);
}

#[test]
fn momentum_random_trees() {
    check_momentum(&trees(), 61);
}

#[test]
fn momentum_robots() {
    check_momentum(&robots(), 62);
}

// ------------------------------------------------------------------------------------------------
// 7. A free rigid body: Euler's equations and the MuJoCo-convention origin acceleration
// ------------------------------------------------------------------------------------------------

/// One free body with its centre of mass `com` off the body origin and a general inertia tensor.
fn free_body(com: Vec3, i_com_principal: Vec3, r_principal: Mat3, gravity: Vec3) -> Model {
    let joint = JointSpec::new("free", JointType::Floating, SourceLoc::default());
    let inertial = InertialSpec {
        mass: 2.5,
        x_link_inertial: Transform::new(r_principal, com),
        inertia: Mat3::from_diagonal(&i_com_principal),
        loc: SourceLoc::default(),
    };
    let link = LinkSpec {
        name: "body".into(),
        loc: SourceLoc::default(),
        parent: None,
        joint,
        inertial: Some(inertial),
        inertia_from_geoms: false,
        geoms: Vec::new(),
        kind: lagrange::model::FrameKind::Link,
        frames: Vec::new(),
        mocap: false,
    };
    compile(&ModelSpec {
        name: "free_body".into(),
        source: None,
        gravity,
        links: vec![link],
        ..Default::default()
    })
    .unwrap()
}

#[test]
fn free_body_follows_euler_equations() {
    let mut r = rng(71);
    let mut e_ang = MaxErr::new("free body, g=0: omega_dot vs I^-1 (-w x I w) (body frame)", ALGO_REL);
    let mut e_lin = MaxErr::new("free body, g=0: origin accel vs -R (wdot x c + w x (w x c))", ALGO_REL);
    let mut e_all = MaxErr::new("free body, any g: qacc vs [g - R(..); I^-1 (-w x I w)]", ALGO_REL);
    let mut e_rnea = MaxErr::new("free body: RNEA at the Euler accelerations vs 0", ALGO_REL);
    for case in 0..8 {
        let com = random_vec3(&mut r, 0.3);
        // Clearly distinct principal moments (a near-spherical body has a tiny gyroscopic torque
        // and says little about Euler's equations): (b + c, a + c, a + b) with a < b < c.
        let a = r.random_range(0.01..0.03);
        let b = r.random_range(0.05..0.08);
        let c = r.random_range(0.12..0.20);
        let principal = Vec3::new(b + c, a + c, a + b);
        let r_principal = random_rotation(&mut r);
        // Half the cases without gravity (pure Euler), half with: then the centre of mass falls
        // with g and the rotation is unchanged.
        let gravity = if case % 2 == 0 { Vec3::zeros() } else { random_unit(&mut r) * 9.81 };
        let model = free_body(com, principal, r_principal, gravity);
        assert_eq!((model.nq, model.nv), (7, 6));
        let mut data = Data::new(&model);
        for s in 0..4 {
            let q = random_q(&model, &mut r);
            let v = random_v(&model, &mut r);
            let qacc = aba(&model, &mut data, &q, &v, &[0.0; 6]).unwrap().clone();
            // Expected, by hand. Inertia about the centre of mass in body axes:
            let i_c = r_principal * Mat3::from_diagonal(&principal) * r_principal.transpose();
            let w = Vec3::new(v[3], v[4], v[5]);
            // Euler: I ω̇ + ω × I ω = 0 (no torque about the centre of mass).
            let w_dot = i_c.try_inverse().unwrap() * (-w.cross(&(i_c * w)));
            // The centre of mass x_c = p + R c accelerates with g; the origin p = x_c − R c, so
            // p̈ = g − R (ω̇ × c + ω × (ω × c)) (Ṙ = R [ω]×, body-frame ω).
            let rot = quat_to_matrix(q[3], q[4], q[5], q[6]);
            let p_ddot = gravity - rot * (w_dot.cross(&com) + w.cross(&w.cross(&com)));
            let expected = stack(&p_ddot, &w_dot);
            let at = || format!("case {case}, state {s}");
            if gravity == Vec3::zeros() {
                e_ang.add(rel_err_vec(&qacc.as_slice()[3..6], w_dot.as_slice()), at);
                e_lin.add(rel_err_vec(&qacc.as_slice()[0..3], p_ddot.as_slice()), at);
            }
            e_all.add(rel_err_vec(qacc.as_slice(), &expected), at);
            let tau = rnea(&model, &mut data, &q, &v, &expected).unwrap();
            // Scale: the inertial forces m p̈ and I ω̇ the RNEA balances.
            let scale = (p_ddot.amax() * 2.5).max((i_c * w_dot).amax()).max(REL_FLOOR);
            e_rnea.add(tau.amax() / scale, at);
        }
    }
    report_and_assert(&[&e_ang, &e_lin, &e_all, &e_rnea]);
}

/// The free joint's velocity convention, checked on kinematics alone: q̇ of the position is the
/// world-frame velocity of the body origin, and the angular part is body-frame (MuJoCo).
#[test]
fn free_joint_velocity_convention() {
    let mut r = rng(72);
    let model =
        free_body(Vec3::new(0.1, -0.2, 0.05), Vec3::new(0.03, 0.04, 0.05), Mat3::identity(), Vec3::zeros());
    let mut data = Data::new(&model);
    let mut e = MaxErr::new("free joint: frame velocity (LWA) vs [v_world; R w_body]", ALGO_REL);
    for s in 0..4 {
        let q = random_q(&model, &mut r);
        let v = random_v(&model, &mut r);
        forward_kinematics(&model, &mut data, &q).unwrap();
        forward_velocities(&model, &mut data, &v).unwrap();
        let (lin, ang) = frame_velocity(&model, &data, 0, ReferenceFrame::LocalWorldAligned).unwrap();
        let rot = quat_to_matrix(q[3], q[4], q[5], q[6]);
        let w_world = rot * Vec3::new(v[3], v[4], v[5]);
        e.add(rel_err_vec(&stack(&lin, &ang), &stack(&Vec3::new(v[0], v[1], v[2]), &w_world)), || {
            format!("state {s}")
        });
        // And the body velocity itself (body coordinates) is [R^T v_world; w] in motion form.
        let vb: Motion = data.v_body[1];
        let expected = Motion::new(Vec3::new(v[3], v[4], v[5]), rot.tr_mul(&Vec3::new(v[0], v[1], v[2])));
        e.add(rel_err_vec(&stack(&vb.lin, &vb.ang), &stack(&expected.lin, &expected.ang)), || {
            format!("state {s}, v_body")
        });
    }
    report_and_assert(&[&e]);
}

// ------------------------------------------------------------------------------------------------
// Configuration space: difference_configuration inverts integrate_configuration
// ------------------------------------------------------------------------------------------------

fn check_integrate_difference(models: &[(String, Model)], seed: u64) {
    // Steps keep every rotation below π (|ω| ≤ 2√3, so |ω dt| ≤ 1.74 at dt = 0.5), where the
    // difference (the shortest rotation) is unique, and large enough that the increment is not
    // swamped by the round-off of q itself (relative error ≈ ε |q| / |v dt|).
    let mut e = MaxErr::new("difference(q, q + v dt) vs v dt", ALGO_REL);
    for (name, model) in models {
        let mut r = rng(seed);
        for s in 0..STATES {
            let (q0, v) = (random_q(model, &mut r), random_v(model, &mut r));
            for dt in [0.5, 1e-2] {
                let mut q1 = q0.clone();
                integrate_configuration(model, &mut q1, &v, dt).unwrap();
                let mut d = vec![0.0; model.nv];
                difference_configuration(model, &q0, &q1, &mut d).unwrap();
                let v_dt: Vec<f64> = v.iter().map(|x| x * dt).collect();
                e.add(rel_err_vec(&d, &v_dt), || format!("{name}, state {s}, dt {dt}"));
            }
        }
    }
    report_and_assert(&[&e]);
}

#[test]
fn difference_inverts_integrate_random_trees() {
    check_integrate_difference(&trees(), 81);
}

#[test]
fn difference_inverts_integrate_robots() {
    check_integrate_difference(&robots(), 82);
}
