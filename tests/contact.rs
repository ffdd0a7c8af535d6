//! Frictional contact in exact mode against the closed forms of docs/physics.md §2.5 (a cylinder rolling or
//! sliding down an incline, the critical friction coefficient), statics of a box on an incline,
//! inelastic impacts of dropped bodies, and the go1 quadruped settling on its floor.

mod common;

use common::{rel_err, CONTACT_REL, ENERGY_GAIN_REL, PENETRATION_AT_REST};
use lagrange::constraint::ConstraintMode;
use lagrange::forward::forward;
use lagrange::io::{load, LoadOptions};
use lagrange::sim::{SimOptions, Simulation};
use lagrange::spatial::Vec3;
use lagrange::{Data, Model};
use std::path::{Path, PathBuf};
use std::sync::Arc;

const G: f64 = 9.81;

/// A textbook model with every `friction="0.5 0 0"` replaced by μ (a copy in the temp directory).
fn with_friction(file: &str, mu: f64) -> Model {
    let text = std::fs::read_to_string(Path::new("models/textbook").join(file)).unwrap();
    let text = text.replace(r#"friction="0.5 0 0""#, &format!(r#"friction="{mu} 0 0""#));
    let path: PathBuf = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-{}-{mu}-{file}", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let model = load(&path, &LoadOptions::default()).unwrap();
    let _ = std::fs::remove_file(&path);
    model
}

/// `forward` at the model's `qpos0` at rest in exact mode. The Gauss–Seidel solve converges
/// linearly, slowly right at the stick/slip threshold: the tests allow it 10 000 sweeps.
fn forward_at_rest(model: &Model) -> Data {
    let mut model = common::with_mode(model.clone(), ConstraintMode::Exact);
    model.plan.solver.exact_mut().unwrap().settings.max_iterations = 10_000;
    let mut data = Data::new(&model);
    forward(&model, &mut data);
    data
}

/// The incline of `incline_*.xml`: normal n and downhill direction d for the angle θ.
fn incline(theta_deg: f64) -> (Vec3, Vec3, f64) {
    let t = theta_deg.to_radians();
    (Vec3::new(t.sin(), 0.0, t.cos()), Vec3::new(t.cos(), 0.0, -t.sin()), t)
}

/// Linear acceleration of the free body's origin (world) and its angular acceleration (world).
fn free_accelerations(model: &Model, data: &Data) -> (Vec3, Vec3) {
    let q = &model.qpos0;
    let rot = lagrange::spatial::quat_to_matrix(q[3], q[4], q[5], q[6]);
    let a = Vec3::new(data.qacc[0], data.qacc[1], data.qacc[2]);
    let alpha_body = Vec3::new(data.qacc[3], data.qacc[4], data.qacc[5]);
    (a, rot * alpha_body)
}

/// Notes §2.5: above the critical μ_c = tan θ / 3 the cylinder rolls, ẍ = ⅔ g sin θ, with its
/// angular acceleration ẍ / a about its axis; below, it slides with ẍ = g (sin θ − μ cos θ) and
/// α̈ = (m g a / I) μ cos θ. Both to 1e-8 at the contact's first instant (one `forward`), and on
/// either side of the threshold itself.
#[test]
fn cylinder_on_an_incline_rolls_or_slides_as_the_notes_say() {
    let (n, d, theta) = incline(30.0);
    let (radius, mass) = (0.1, 2.0);
    let inertia = 0.5 * mass * radius * radius;
    let mu_c = theta.tan() / 3.0;
    let axis = Vec3::new(0.0, 1.0, 0.0); // rolling downhill (+x): v = a ω × n turns about +y
    for (mu, rolls) in [(0.5, true), (mu_c * 1.001, true), (mu_c * 0.999, false), (0.1, false)] {
        let model = with_friction("incline_cylinder.xml", mu);
        let data = forward_at_rest(&model);
        let (a, alpha) = free_accelerations(&model, &data);
        let (want_a, want_alpha) = if rolls {
            let x = 2.0 / 3.0 * G * theta.sin();
            (x, x / radius)
        } else {
            (G * (theta.sin() - mu * theta.cos()), mass * G * radius / inertia * mu * theta.cos())
        };
        let contacts = (0..data.nefc).filter(|&i| data.efc_is_normal(i)).count();
        println!(
            "μ = {mu:.5} (μ_c = {mu_c:.5}): ẍ = {:.12} (want {want_a:.12}), α̈ = {:.10} (want {want_alpha:.10}), a·n = {:e}, {contacts} contacts, {} iterations",
            a.dot(&d),
            alpha.dot(&axis),
            a.dot(&n),
            data.efc_iterations
        );
        assert!(contacts >= 1);
        assert!(rel_err(a.dot(&d), want_a) <= CONTACT_REL, "ẍ = {} vs {want_a}", a.dot(&d));
        assert!(rel_err(alpha.dot(&axis), want_alpha) <= CONTACT_REL, "α̈ = {}", alpha.dot(&axis));
        assert!(a.dot(&n).abs() <= CONTACT_REL * G, "off the plane: a·n = {}", a.dot(&n));
        assert!(data.efc_converged, "residual {:e}", data.efc_residual);
    }
}

/// A box on a 20° incline: with μ = 0.5 > tan θ it stays at rest (q̈ = 0) and its contact normal
/// forces sum to m g cos θ; with μ = 0.2 it slides without turning, ẍ = g (sin θ − μ cos θ).
#[test]
fn box_on_an_incline_sticks_or_slides() {
    let (n, d, theta) = incline(20.0);
    let mass = 1.0;
    let model = with_friction("incline_box.xml", 0.5);
    let data = forward_at_rest(&model);
    let normal: f64 =
        (0..data.nefc).filter(|&i| data.efc_is_normal(i)).map(|i| data.efc_force[i]).sum::<f64>();
    let contacts = (0..data.nefc).filter(|&i| data.efc_is_normal(i)).count();
    println!(
        "μ = 0.5: |q̈| = {:e}, Σ λ_n = {normal:.12} (m g cos θ = {:.12}), {contacts} contacts, {} iterations",
        data.qacc.amax(),
        mass * G * theta.cos(),
        data.efc_iterations
    );
    assert_eq!(contacts, 4, "four corners touch");
    assert!(data.qacc.amax() <= CONTACT_REL * G, "at rest: q̈ = {}", data.qacc);
    assert!(rel_err(normal, mass * G * theta.cos()) <= CONTACT_REL);
    assert!(data.efc_converged);

    let mu = 0.2;
    let model = with_friction("incline_box.xml", mu);
    let data = forward_at_rest(&model);
    let (a, alpha) = free_accelerations(&model, &data);
    let want = G * (theta.sin() - mu * theta.cos());
    println!(
        "μ = 0.2: ẍ = {:.12} (want {want:.12}), |α̈| = {:e}, a·n = {:e}",
        a.dot(&d),
        alpha.norm(),
        a.dot(&n)
    );
    assert!(rel_err(a.dot(&d), want) <= CONTACT_REL);
    assert!(alpha.norm() <= CONTACT_REL * G && a.dot(&n).abs() <= CONTACT_REL * G);
}

/// Total energy of the simulation's state.
fn energy(sim: &mut Simulation) -> f64 {
    let (t, v) = sim.energies();
    t + v
}

/// A sphere and a tilted box dropped from 1 m: the impacts are inelastic, both come to rest on the
/// floor, penetration after settling stays below 1e-6 m, and after the first impact the energy
/// never increases (RK4, 1 ms, exact mode).
#[test]
fn dropped_bodies_come_to_rest_without_sinking_or_gaining_energy() {
    let model = Arc::new(load(Path::new("models/textbook/drop.xml"), &LoadOptions::default()).unwrap());
    let options = common::exact_rk4(1e-3);
    let mut sim = Simulation::new(model.clone(), &options);
    let e0 = energy(&mut sim);
    let (mut impacted, mut e_prev, mut rise, mut depth_settled) = (false, e0, 0.0f64, 0.0f64);
    for step in 0..3000 {
        sim.step().unwrap();
        let e = energy(&mut sim);
        if impacted {
            rise = rise.max(e - e_prev);
        }
        impacted |= (0..sim.data.nefc).any(|i| sim.data.efc_is_normal(i));
        e_prev = e;
        if step >= 2000 {
            for i in 0..sim.data.nefc {
                if sim.data.efc_is_normal(i) {
                    depth_settled = depth_settled.max(-sim.data.efc_pos[i]);
                }
            }
        }
    }
    let v = sim.data.qvel.amax();
    let (ball_z, box_z) = (sim.data.qpos[2], sim.data.qpos[9]);
    println!(
        "after 3 s: ball z {ball_z:.9}, box z {box_z:.9}, max |v| {v:e}, penetration after settling {depth_settled:e} m, largest energy rise in a step after the impact {rise:e} J"
    );
    assert!(impacted);
    assert!(v <= 1e-6, "at rest: max |v| = {v}");
    assert!((ball_z - 0.1).abs() <= PENETRATION_AT_REST, "ball rests on the floor: z = {ball_z}");
    assert!((box_z - 0.1).abs() <= PENETRATION_AT_REST, "box rests on a face: z = {box_z}");
    assert!(depth_settled <= PENETRATION_AT_REST);
    assert!(rise <= ENERGY_GAIN_REL * e0.abs(), "energy rose by {rise:e} J after the impact");
    assert!(sim.data.efc_unconverged == 0, "{} unconverged solves", sim.data.efc_unconverged);
}

/// go1 from its home keyframe without control collapses onto its floor and settles: its base
/// stays above 0.05 m and no foot sinks below the plane (exact mode, RK4 at 1 ms, 2 s).
#[test]
fn go1_settles_on_its_floor() {
    let path = Path::new("models/mjcf/unitree_go1/scene.xml");
    let model = Arc::new(load(path, &LoadOptions::default()).unwrap());
    let options = common::exact_rk4(1e-3);
    let mut sim = Simulation::new(model.clone(), &options);
    let key = model.keyframe_id("home").unwrap();
    let home = model.keyframes[key].qpos.clone().unwrap();
    sim.set_state(&home, &vec![0.0; model.nv]).unwrap();
    let feet: Vec<usize> = ["FR", "FL", "RR", "RL"]
        .iter()
        .map(|f| model.geoms.iter().position(|g| g.name == *f).unwrap())
        .collect();
    let (mut lowest_base, mut lowest_foot, mut max_contacts) = (f64::MAX, f64::MAX, 0);
    for _ in 0..2000 {
        sim.step().unwrap();
        lowest_base = lowest_base.min(sim.data.qpos[2]);
        sim.kinematics();
        for &f in &feet {
            let g = &model.geoms[f];
            let centre = (sim.data.x_world_body[g.body] * g.x_body_geom).pos;
            lowest_foot = lowest_foot.min(centre.z - 0.023);
        }
        max_contacts = max_contacts.max((0..sim.data.nefc).filter(|&i| sim.data.efc_is_normal(i)).count());
    }
    println!(
        "go1 after 2 s: base z {:.4} (lowest {lowest_base:.4}), lowest foot bottom {lowest_foot:e} m, up to {max_contacts} contacts, max |v| {:e}",
        sim.data.qpos[2],
        sim.data.qvel.amax()
    );
    assert!(lowest_base >= 0.05, "base sank to {lowest_base}");
    assert!(lowest_foot >= -PENETRATION_AT_REST, "a foot sank {lowest_foot} m below the floor");
    assert!(max_contacts >= 4);
}

/// The exact contact rows only exist while touching: a body in the air has none, and `forward`
/// then takes the ABA path (no rows, qacc = qacc_smooth).
#[test]
fn no_rows_in_the_air() {
    let model = load(Path::new("models/textbook/drop.xml"), &LoadOptions::default()).unwrap();
    let data = forward_at_rest(&model);
    assert_eq!((data.nefc, data.contacts.len()), (0, 0));
    assert_eq!(data.qacc, data.qacc_smooth);
}

/// go1 from its home keyframe holding its keyframe controls (position actuators) stands on its
/// floor in exact mode: after 2 s its base is still near the keyframe's height (MuJoCo's soft
/// contacts settle it at 0.265 m; rigid contacts do not sink) and no foot is below the floor.
#[test]
fn go1_stands_on_its_actuators() {
    let model =
        Arc::new(load(Path::new("models/mjcf/unitree_go1/scene.xml"), &LoadOptions::default()).unwrap());
    let options = SimOptions { constraints: Some(ConstraintMode::Exact), ..Default::default() };
    let mut sim = Simulation::new(model.clone(), &options);
    let key = &model.keyframes[model.keyframe_id("home").unwrap()];
    sim.set_state(key.qpos.as_ref().unwrap(), &vec![0.0; model.nv]).unwrap();
    sim.ctrl_mut().copy_from_slice(key.ctrl.as_ref().unwrap());
    let steps = (2.0 / sim.timestep).round() as usize;
    let mut lowest = f64::MAX;
    for _ in 0..steps {
        sim.step().unwrap();
        lowest = lowest.min(sim.data.qpos[2]);
    }
    let contacts = (0..sim.data.nefc).filter(|&i| sim.data.efc_is_normal(i)).count();
    println!(
        "go1 standing, {} steps of {} s ({}): base z {:.4} (lowest {lowest:.4}), {contacts} contacts, max |v| {:e}",
        steps,
        sim.timestep,
        sim.integrator(),
        sim.data.qpos[2],
        sim.data.qvel.amax()
    );
    assert!(sim.data.qpos[2] > 0.25 && sim.data.qpos[2] < 0.30, "base z {}", sim.data.qpos[2]);
    assert!(lowest > 0.2, "it should never fall: lowest base z {lowest}");
    assert_eq!(contacts, 4, "standing on its four feet");
}
