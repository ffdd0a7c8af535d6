//! Memory discipline (docs/architecture.md, "Errors"): once `Data` exists, the kinematics and dynamics
//! kernels and the integrators perform zero heap allocations. A counting global allocator counts
//! the allocations this thread makes while the kernels run.

use lagrange::constraint::ConstraintMode;
use lagrange::dynamics::{
    aba, bias_forces, crba, factorize_mass_matrix, interaction_wrench, object_acceleration,
    rne_post_constraint, rnea, solve_mass_matrix,
};
use lagrange::forward::forward;
use lagrange::integrate::IntegratorKind;
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::{forward_kinematics, forward_velocities, frame_jacobian, ReferenceFrame};
use lagrange::Data;
use nalgebra::{DMatrix, DVector};
use std::path::Path;

mod alloc_counter;
use alloc_counter::allocations;

#[test]
fn kernels_and_integrators_do_not_allocate() {
    // The counter must see allocations at all, or a zero below would prove nothing.
    assert!(allocations(|| drop(std::hint::black_box(vec![1u8; 16]))) >= 1);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (file, floating) in [
        ("models/ur5/ur5.urdf", false),
        ("models/solo12/solo12.urdf", true),
        // Constrained: a mimic row, and a loop with redundant rows (the minimum-norm path).
        ("models/panda/panda.urdf", false),
        ("models/textbook/four_bar.xml", false),
        ("tests/data/mjcf/constraints/connect_free_sites.xml", false),
        // Actuators: activation dynamics (act in the state), site, ball and free transmissions.
        ("tests/data/mjcf/actuators/activation.xml", false),
        ("tests/data/mjcf/actuators/transmissions.xml", false),
        // Fluid forces (the inertia-box model) in the passive stage.
        ("tests/data/mjcf/fluid/inertia_box.xml", false),
    ] {
        let model = load(&root.join(file), &LoadOptions { floating, ..Default::default() }).unwrap();
        let mut data = Data::new(&model);
        let mut q = model.neutral();
        for (k, x) in q.iter_mut().enumerate() {
            if model
                .joints
                .iter()
                .all(|j| !(j.qpos_adr..j.qpos_adr + j.kind.nq()).contains(&k) || j.kind.nq() == 1)
            {
                *x += 0.1 * k as f64;
            }
        }
        let v: Vec<f64> = (0..model.nv).map(|k| 0.3 - 0.05 * k as f64).collect();
        let tau: Vec<f64> = (0..model.nv).map(|k| 0.2 * k as f64).collect();
        let mut jac = DMatrix::zeros(6, model.nv);
        let mut x = DVector::from_vec(tau.clone());
        let frame = model.frames.len() - 1;
        let kernels = allocations(|| {
            forward_kinematics(&model, &mut data, &q).unwrap();
            forward_velocities(&model, &mut data, &v).unwrap();
            frame_jacobian(&model, &data, frame, ReferenceFrame::LocalWorldAligned, &mut jac).unwrap();
            rnea(&model, &mut data, &q, &v, &tau).unwrap();
            bias_forces(&model, &mut data, &q, &v).unwrap();
            crba(&model, &mut data, &q).unwrap();
            factorize_mass_matrix(&model, &mut data);
            solve_mass_matrix(&model, &data, &mut x).unwrap();
            aba(&model, &mut data, &q, &v, &tau).unwrap();
        });
        assert_eq!(kernels, 0, "{file}: kernels allocated {kernels} times");
        // The staged pipeline with the model's constraint rows (projection included in the steps).
        let mut model = model;
        model.set_constraint_mode(ConstraintMode::Exact);
        let mut data = Data::new(&model);
        data.qfrc_applied.copy_from_slice(&tau);
        data.ctrl.fill(0.5);
        data.act.fill(0.1);
        data.qpos.copy_from_slice(&q);
        data.qvel.copy_from_slice(&v);
        forward(&model, &mut data);
        let forwards = allocations(|| forward(&model, &mut data));
        assert_eq!(forwards, 0, "{file}: forward allocated {forwards} times");
        for kind in [
            IntegratorKind::Euler,
            IntegratorKind::Rk4,
            IntegratorKind::Adaptive,
            IntegratorKind::ImplicitFast,
            IntegratorKind::Implicit,
            IntegratorKind::Variational,
        ] {
            let mut integrator = kind.build(&model);
            data.qpos.copy_from_slice(&q);
            data.qvel.copy_from_slice(&v);
            let steps = allocations(|| {
                for _ in 0..10 {
                    integrator.step(&model, &mut data, 1e-3);
                }
            });
            assert_eq!(steps, 0, "{file}: {kind:?} steps allocated {steps} times");
        }
        println!("{file}: 0 allocations in FK, velocities, Jacobian, RNEA, bias, CRBA, LTDL, solve, ABA, Euler, RK4, adaptive, implicitfast, implicit, variational");
    }
}

/// Contact scenes: the collision pass, the contact rows, the Gauss–Seidel Coulomb solve, the frozen
/// rows of a step and the projections allocate nothing either (a box resting on an incline with
/// four sticking corners; go1 standing on its floor from its home keyframe; convex meshes resting
/// on a table box and on each other, the multi-point contacts of box–mesh and mesh–mesh pairs).
#[test]
fn contact_scenes_do_not_allocate() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (file, keyframe) in [
        ("models/textbook/incline_box.xml", None),
        ("models/mjcf/unitree_go1/scene.xml", Some("home")),
        ("validation/scenes/mesh_pile.xml", None),
    ] {
        let model = load(&root.join(file), &LoadOptions::default()).unwrap();
        let _data = Data::new(&model);
        let q = match keyframe {
            Some(k) => model.keyframes[model.keyframe_id(k).unwrap()].qpos.clone().unwrap(),
            None => model.qpos0.clone(),
        };
        let v = vec![0.0; model.nv];
        for mode in [ConstraintMode::Exact, ConstraintMode::Soft] {
            let mut model = model.clone();
            model.set_constraint_mode(mode);
            let mut data = Data::new(&model);
            // Warm up: the warm-start record of the first solve is the only growth (in soft mode,
            // a few steps first, so that the bodies sink into their contacts and the rows exist).
            data.qpos.copy_from_slice(&q);
            data.qvel.copy_from_slice(&v);
            let mut warm = IntegratorKind::Euler.build(&model);
            for _ in 0..20 {
                warm.step(&model, &mut data, 1e-3);
            }
            let (qs, vs) = (data.qpos.as_slice().to_vec(), data.qvel.as_slice().to_vec());
            forward(&model, &mut data);
            let forwards = allocations(|| forward(&model, &mut data));
            assert_eq!(forwards, 0, "{file} {mode:?}: forward allocated {forwards} times");
            // MuJoCo's rnePostConstraint (contact forces in cfrc_ext) and the sensors' accessors.
            let post = allocations(|| {
                rne_post_constraint(&model, &mut data).unwrap();
                let p = data.x_world_body[1].pos;
                std::hint::black_box(object_acceleration(&model, &data, 1, &p).unwrap());
                std::hint::black_box(interaction_wrench(&model, &data, 1, &p).unwrap());
            });
            assert_eq!(post, 0, "{file} {mode:?}: rne_post_constraint allocated {post} times");
            for kind in [IntegratorKind::Euler, IntegratorKind::Rk4] {
                let mut integrator = kind.build(&model);
                data.qpos.copy_from_slice(&qs);
                data.qvel.copy_from_slice(&vs);
                let steps = allocations(|| {
                    for _ in 0..50 {
                        integrator.step(&model, &mut data, 1e-3);
                    }
                });
                assert_eq!(steps, 0, "{file} {mode:?}: {kind:?} steps allocated {steps} times");
            }
            let touching = data.contacts.iter().filter(|c| c.dist <= 1e-9).count();
            println!(
                "{file} {mode:?}: 0 allocations in forward, rne_post_constraint, Euler and RK4 with {touching} touching contacts, {} rows",
                data.nefc
            );
            assert!(touching > 0 && data.nefc > 0, "{file} {mode:?}: the scene should be in contact");
        }
    }
}

#[test]
fn geometric_queries_do_not_allocate() {
    // Rays against every geom type (meshes read on the first ray), site rays and point tests, and
    // geom distances of every pair, closed forms, GJK and EPA: no allocation once the meshes are
    // read.
    use lagrange::collision::{geom_distance, inside_site, ray, ray_site, RayFilter};
    use lagrange::spatial::Vec3;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = std::fs::read_to_string(root.join("tests/data/mujoco_geomq/distance.json")).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&scene).unwrap();
    let meshdir = root.join("tests/data/mujoco_geomq/meshes");
    let mjcf = doc["mjcf"].as_str().unwrap().replace("@MESHDIR@", meshdir.to_str().unwrap());
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-no-alloc-geomq-{}.xml", std::process::id()));
    std::fs::write(
        &path,
        mjcf.replace("</worldbody>", r#"<site name="zone" type="box" size="0.1 0.2 0.3"/></worldbody>"#),
    )
    .unwrap();
    let model = load(&path, &LoadOptions::default()).unwrap();
    let _ = std::fs::remove_file(&path);
    let mut data = Data::new(&model);
    let qpos: Vec<f64> =
        doc["states"][40]["qpos"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    forward_kinematics(&model, &mut data, &qpos).unwrap();
    let site = model.site_id("zone").unwrap();
    let queries = |data: &Data| {
        let mut sum = 0.0;
        for k in 0..20 {
            let p = Vec3::new(0.3 * (k as f64).sin(), 0.2 * (k as f64).cos(), 1.0);
            let v = Vec3::new(-0.1 * p.x, -0.1 * p.y, -1.0);
            sum += ray(&model, data, p, v, &RayFilter::default()).unwrap().map_or(0.0, |h| h.dist);
            sum += ray_site(&model, data, site, p, v).unwrap().map_or(0.0, |h| h.0);
            sum += inside_site(&model, data, site, p * 0.1).unwrap() as u8 as f64;
        }
        for g1 in 0..model.geoms.len() {
            for g2 in 0..model.geoms.len() {
                sum += geom_distance(&model, data, g1, g2, 1.0).unwrap().dist;
            }
        }
        sum
    };
    std::hint::black_box(queries(&data));
    let n = allocations(|| {
        std::hint::black_box(queries(&data));
    });
    assert_eq!(n, 0, "geometric queries allocated {n} times");
}

#[test]
fn sleeping_islands_do_not_allocate() {
    // drop.xml: bodies fall asleep, a falling sphere wakes one (contact wake, a second collision
    // pass), both fall asleep again — all within the counted steps, after a warm-up run (and a
    // reset) that grew the buffers to the scene's largest contact count.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let model = load(&root.join("tests/data/mjcf/sleep/drop.xml"), &LoadOptions::default()).unwrap();
    let mut data = Data::new(&model);
    for _ in 0..500 {
        lagrange::prelude::step(&model, &mut data).unwrap();
    }
    lagrange::prelude::reset(&model, &mut data).unwrap();
    let (mut slept, mut woken) = (0, 0);
    let steps = allocations(|| {
        for _ in 0..500 {
            lagrange::prelude::step(&model, &mut data).unwrap();
        }
        slept = data.sleep.slept;
        woken = data.sleep.woken;
    });
    assert!(slept >= 6 && woken >= 1, "{slept} trees fell asleep, {woken} woke");
    assert_eq!(steps, 0, "sleeping, waking and stepping allocated {steps} times");
}
