//! The library's surface as a user meets it: `Model::from_file`/`from_str` telling URDF from
//! MJCF by content, `Data` holding the whole state, `reset`/`reset_keyframe`, `step` with the
//! model's integrator against `Simulation`, frames by name, and the typed errors of wrong names
//! and of data made for another model (never a panic).

mod common;

use lagrange::prelude::*;
use std::sync::Arc;

const GO1: &str = "models/mjcf/unitree_go1/scene.xml";

#[test]
fn from_file_and_from_str_tell_the_format_by_content() {
    let urdf = std::fs::read_to_string("models/ur5/ur5.urdf").unwrap();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-api-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A URDF under a name without the extension still loads as URDF (exact mode, its default).
    let path = dir.join("robot.description");
    std::fs::write(&path, &urdf).unwrap();
    let model = Model::from_file(&path).unwrap();
    assert_eq!((model.nq, model.plan.mode()), (6, ConstraintMode::Exact));
    let model = Model::from_str(&urdf).unwrap();
    assert_eq!(model.nv, 6);
    let mjcf = Model::from_str(
        r#"<?xml version="1.0"?><!-- a comment --><mujoco><worldbody>
        <geom type="plane" size="1 1 .1"/><body><freejoint/><geom size="0.1"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    assert_eq!((mjcf.nq, mjcf.plan.mode()), (7, ConstraintMode::Soft));
    let err = Model::from_str("<sdf version='1.6'/>").unwrap_err();
    assert!(err.to_string().contains("unsupported model format"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `step` runs the model's own integrator and timestep: it equals a `Simulation` with the
/// model's options, bit for bit (go1 from its keyframe, servo controls held, 100 steps).
#[test]
fn step_equals_the_simulation_of_the_models_options() {
    let model = Model::from_file(GO1).unwrap();
    let mut data = Data::new(&model);
    reset_keyframe(&model, &mut data, "home").unwrap();
    let mut sim = Simulation::new(Arc::new(model.clone()), &SimOptions::default());
    sim.set_state(data.qpos.as_slice(), data.qvel.as_slice()).unwrap();
    sim.ctrl_mut().copy_from_slice(data.ctrl.as_slice());
    for _ in 0..100 {
        step(&model, &mut data).unwrap();
        sim.step().unwrap();
    }
    assert_eq!(data.qpos, sim.data.qpos);
    assert_eq!(data.qvel, sim.data.qvel);
    assert!((data.time - 0.2).abs() < 1e-12, "{}", data.time);
}

#[test]
fn reset_and_keyframes_set_the_whole_state() {
    let model = Model::from_file(GO1).unwrap();
    let mut data = Data::new(&model);
    assert_eq!(data.qpos.as_slice(), model.qpos0.as_slice(), "Data::new starts at qpos0");
    reset_keyframe(&model, &mut data, "home").unwrap();
    let key = &model.keyframes[model.keyframe_id("home").unwrap()];
    assert_eq!(data.qpos.as_slice(), key.qpos.as_deref().unwrap());
    assert_eq!(data.ctrl.as_slice(), key.ctrl.as_deref().unwrap());
    for _ in 0..10 {
        step(&model, &mut data).unwrap();
    }
    data.qfrc_applied[0] = 1.0;
    reset(&model, &mut data).unwrap();
    assert_eq!(data.time, 0.0);
    assert_eq!(data.qpos.as_slice(), model.qpos0.as_slice());
    assert!(data.qvel.iter().chain(data.ctrl.iter()).chain(data.qfrc_applied.iter()).all(|&x| x == 0.0));
    let err = reset_keyframe(&model, &mut data, "sitting").unwrap_err();
    println!("{err}");
    assert!(matches!(err, InputError::Name { .. }) && err.to_string().contains("'home'"), "{err}");
}

/// Data made for another model is refused with the size that differs, by every call that
/// takes both (never an index out of bounds).
#[test]
fn data_of_another_model_is_a_typed_error() {
    let go1 = Model::from_file(GO1).unwrap();
    let ur5 = Model::from_file("models/ur5/ur5.urdf").unwrap();
    let mut data = Data::new(&ur5);
    let err = step(&go1, &mut data).unwrap_err();
    println!("{err}");
    assert!(err.to_string().contains("step: data.qpos has 6 values, the model needs 19 (nq)"), "{err}");
    assert!(matches!(reset(&go1, &mut data), Err(InputError::Length { .. })));
    assert!(matches!(frames::pose(&go1, &mut data, "trunk"), Err(InputError::Length { .. })));
}

#[test]
fn frames_by_name() {
    let model = Model::from_file(GO1).unwrap();
    let mut data = Data::new(&model);
    reset_keyframe(&model, &mut data, "home").unwrap();
    let trunk = frames::pose(&model, &mut data, "trunk").unwrap();
    assert!((trunk.pos.z - data.qpos[2]).abs() < 1e-15, "the free joint's position is the trunk's");
    // A site (MJCF's foot sites) and a body by name; a linear velocity of the base shows at the foot.
    data.qvel[0] = 0.5;
    let (lin, _) = frames::velocity(&model, &mut data, "FR").unwrap();
    assert!((lin.x - 0.5).abs() < 1e-12, "{lin:?}");
    let mut jac = nalgebra::DMatrix::zeros(6, model.nv);
    frames::jacobian(&model, &mut data, "FR", &mut jac).unwrap();
    assert!(((&jac * &data.qvel).fixed_rows::<3>(0) - lin).amax() < 1e-12);
    let err = frames::pose(&model, &mut data, "tail").unwrap_err();
    assert!(err.to_string().contains("no body, link or site named 'tail'"), "{err}");
    let mut small = nalgebra::DMatrix::zeros(6, 3);
    assert!(matches!(frames::jacobian(&model, &mut data, "FR", &mut small), Err(InputError::Length { .. })));
}

/// Every public kernel that takes slices refuses a wrong length with `InputError::Length`
/// naming the function, the argument and the size it needs (Pinocchio's argument checks),
/// before touching anything.
#[test]
fn every_kernel_refuses_wrong_lengths() {
    use lagrange::dynamics::*;
    use lagrange::forward::actuation;
    use lagrange::kinematics::*;
    use lagrange::model::{dexp_inv_configuration, difference_configuration, integrate_configuration};
    let model = Model::from_file("models/panda/panda.urdf").unwrap();
    let mut data = Data::new(&model);
    let (nq, nv) = (model.nq, model.nv);
    let (q, v) = (model.qpos0.clone(), vec![0.0; nv]);
    let (q_short, v_long) = (vec![0.0; nq - 1], vec![0.0; nv + 1]);
    let length = |r: Result<(), InputError>, function: &str, argument: &str, size: &str| {
        let err = r.expect_err(function);
        println!("{err}");
        match &err {
            InputError::Length { function: f, argument: a, size: s, .. } => {
                assert_eq!((*f, *a, *s), (function, argument, size), "{err}")
            }
            other => panic!("{function}: {other:?}"),
        }
    };
    length(aba(&model, &mut data, &q_short, &v, &v).map(|_| ()), "aba", "q", "nq");
    length(aba(&model, &mut data, &q, &v_long, &v).map(|_| ()), "aba", "v", "nv");
    length(aba(&model, &mut data, &q, &v, &v_long).map(|_| ()), "aba", "tau", "nv");
    length(rnea(&model, &mut data, &q, &v, &v_long).map(|_| ()), "rnea", "qacc", "nv");
    length(bias_forces(&model, &mut data, &q_short, &v).map(|_| ()), "bias_forces", "q", "nq");
    length(gravity_forces(&model, &mut data, &q_short).map(|_| ()), "gravity_forces", "q", "nq");
    length(crba(&model, &mut data, &q_short).map(|_| ()), "crba", "q", "nq");
    length(crba_upper(&model, &mut data, &q_short).map(|_| ()), "crba_upper", "q", "nq");
    length(kinetic_energy(&model, &mut data, &q, &v_long).map(|_| ()), "kinetic_energy", "v", "nv");
    let mut x = nalgebra::DVector::zeros(nv + 1);
    length(solve_mass_matrix(&model, &data, &mut x), "solve_mass_matrix", "x", "nv");
    length(solve_with_factor(&model, &data.mass_factor, &mut v_long.clone()), "solve_with_factor", "x", "nv");
    length(forward_kinematics(&model, &mut data, &q_short), "forward_kinematics", "q", "nq");
    length(forward_velocities(&model, &mut data, &v_long), "forward_velocities", "v", "nv");
    length(bias_accelerations(&model, &mut data, &v_long), "bias_accelerations", "v", "nv");
    let mut jac = nalgebra::DMatrix::zeros(6, nv - 1);
    length(
        frame_jacobian(&model, &data, 0, ReferenceFrame::Local, &mut jac),
        "frame_jacobian",
        "jac (columns)",
        "nv",
    );
    assert!(matches!(
        frame_velocity(&model, &data, model.frames.len(), ReferenceFrame::Local),
        Err(InputError::Index { what: "frame", .. })
    ));
    length(
        integrate_configuration(&model, &mut q_short.clone(), &v, 1.0),
        "integrate_configuration",
        "q",
        "nq",
    );
    length(
        integrate_configuration(&model, &mut q.clone(), &v_long, 1.0),
        "integrate_configuration",
        "v",
        "nv",
    );
    length(
        difference_configuration(&model, &q, &q_short, &mut v.clone()),
        "difference_configuration",
        "q1",
        "nq",
    );
    length(
        dexp_inv_configuration(&model, &v, &v, &mut v_long.clone()),
        "dexp_inv_configuration",
        "out",
        "nv",
    );
    length(model.spring_energy(&q_short).map(|_| ()), "Model::spring_energy", "q", "nq");
    // The constraint rows, the actuation stage and the variational integrator's terms.
    let rows = &model.plan.constraints;
    length(rows.positions(&model, &mut data, &q_short, true), "ConstraintModel::positions", "q", "nq");
    length(rows.evaluate(&model, &mut data, &q, &v_long), "ConstraintModel::evaluate", "v", "nv");
    length(rows.collide(&model, &mut data, &q_short).map(|_| ()), "ConstraintModel::collide", "q", "nq");
    length(actuation(&model, &mut data, &q_short, &v, &[]), "actuation", "q", "nq");
    length(
        lagrange::constraint::project_velocities(
            &model,
            &mut data,
            &mut v_long.clone(),
            1e-3,
            Default::default(),
        )
        .map(|_| ()),
        "project_velocities",
        "v",
        "nv",
    );
    let mut terms = lagrange::integrate::LagrangianTerms::new(&model);
    length(terms.compute(&model, &mut data, &q, &v_long), "LagrangianTerms::compute", "xi", "nv");
    length(
        terms.recompute_velocity_terms(&model, &v_long),
        "LagrangianTerms::recompute_velocity_terms",
        "xi",
        "nv",
    );
    length(
        lagrange::constraint::ball_angle_axis(&[1.0, 0.0, 0.0]).map(|_| ()),
        "ball_angle_axis",
        "quat",
        "4",
    );
    let limit =
        (0..model.joints.len()).find_map(|j| lagrange::constraint::LimitRow::of_joint(&model, j)).unwrap();
    length(limit.active(&q_short).map(|_| ()), "LimitRow::active", "q", "nq");
    length(limit.jdotv(&q, &v_long).map(|_| ()), "LimitRow::jdotv", "v", "nv");
    assert!(lagrange::constraint::LimitRow::of_joint(&model, 99).is_none(), "no joint 99: no row, no panic");
    // Data made for another model.
    let ur5 = Model::from_file("models/ur5/ur5.urdf").unwrap();
    let mut other = Data::new(&ur5);
    length(aba(&model, &mut other, &q, &v, &v).map(|_| ()), "aba", "data (bodies)", "nbody");
    // The message says what to give.
    let err = aba(&model, &mut data, &q_short, &v, &v).unwrap_err();
    assert_eq!(err.to_string(), format!("aba: q has {} values, the model needs {nq} (nq)", nq - 1));
}

/// A zero or vanishing quaternion in the state reads as the identity, as MuJoCo normalizes it
/// (free and ball joints): finite accelerations equal to those at the identity, and a step that
/// stays finite — never NaN in an output; each such read is a warning naming the joint.
#[test]
fn a_zero_quaternion_is_the_identity() {
    let model = Model::from_str(
        r#"<mujoco><worldbody><body pos="0 0 1"><freejoint/><geom type="box" size="0.1 0.2 0.3"/>
           <body pos="0.2 0 0"><joint type="ball"/><geom size="0.05" pos="0.1 0 0"/></body></body>
           </worldbody></mujoco>"#,
    )
    .unwrap();
    let mut data = Data::new(&model);
    data.qvel.copy_from_slice(&[0.1, 0.2, 0.3, 0.5, -0.4, 0.3, 1.0, 0.0, -1.0]);
    forward(&model, &mut data);
    let at_identity = data.qacc.clone();
    assert_eq!(data.warnings.zero_quat.number, 0, "unit quaternions raise nothing");
    for tiny in [0.0, 1e-300] {
        data.qpos.as_mut_slice()[3..7].copy_from_slice(&[tiny, 0.0, 0.0, 0.0]);
        data.qpos.as_mut_slice()[7..11].copy_from_slice(&[0.0, tiny, 0.0, tiny]);
        forward(&model, &mut data);
        assert_eq!(data.qacc, at_identity, "quaternions of norm {tiny}");
    }
    // Two forwards, two zero quaternions each; the ball joint (index 1) is the last.
    assert_eq!((data.warnings.zero_quat.number, data.warnings.zero_quat.last_info), (4, 1));
    step(&model, &mut data).unwrap();
    assert!(data.qpos.iter().chain(data.qvel.iter()).all(|x| x.is_finite()), "{:?}", data.qpos);
    let message = data.warnings.messages(&model).join("\n");
    assert!(message.contains("zero quaternion") && message.contains("joint"), "{message}");
}
