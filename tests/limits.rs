//! Joint limits in exact mode: unilateral rows (Signorini complementarity at the acceleration
//! level, inelastic impacts at the velocity level), checked on a robot and against statics.

mod common;

use common::{rel_err, CONSTRAINT_REL, LIMIT_EXCURSION};
use lagrange::constraint::ConstraintMode;
use lagrange::integrate::IntegratorKind;
use lagrange::io::{load, load_urdf_str, LoadOptions};
use lagrange::model::EfcType;
use lagrange::sim::{SimOptions, Simulation};
use lagrange::{Data, Model};
use std::path::Path;
use std::sync::Arc;

/// An arm of mass m with its centre of mass l along x from a hinge about y, limited to [−1, 0]:
/// gravity turns it towards +q, into the upper bound at q = 0 (horizontal).
fn arm() -> Model {
    let urdf = r#"<robot name="arm">
  <link name="base"/>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="0" effort="10" velocity="10"/></joint>
  <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.05"/></inertial></link>
</robot>"#;
    load_urdf_str(urdf, Path::new("arm.urdf"), &LoadOptions::default()).unwrap()
}

/// Resting on its limit, the hinge carries the gravity torque m g l as the limit's multiplier and
/// the arm does not accelerate; moving away from the bound, the limit exerts no force.
#[test]
fn hinge_at_its_limit_carries_the_gravity_torque() {
    let model = arm();
    let model = common::with_mode(model, ConstraintMode::Exact);
    let mut data = Data::new(&model);
    let (m, g, l) = (2.0, 9.81, 0.5);
    common::forward_at(&model, &mut data, &[0.0], &[0.0]);
    assert_eq!((data.nefc, data.efc_type[0]), (1, EfcType::LimitJoint));
    let err = rel_err(data.efc_force[0], m * g * l);
    println!("limit multiplier {} vs m g l = {}: rel err {err:.1e}", data.efc_force[0], m * g * l);
    assert!(err <= CONSTRAINT_REL, "λ = {}", data.efc_force[0]);
    assert!(data.qacc[0].abs() <= 1e-12, "q̈ = {}", data.qacc[0]);
    // Separating (v < 0 leaves the upper bound): no force, the free acceleration.
    common::forward_at(&model, &mut data, &[0.0], &[-1.0]);
    assert_eq!(data.efc_force[0], 0.0);
    assert!(rel_err(data.qacc[0], data.qacc_smooth[0]) <= CONSTRAINT_REL && data.qacc[0] > 0.0);
    // Inside the range no row exists, and forward is ABA's.
    common::forward_at(&model, &mut data, &[-0.5], &[0.0]);
    assert_eq!(data.nefc, 0);
}

/// Released from the bound's far side, the arm swings into its limit: the impact stops it
/// (restitution 0), it never passes the bound, and the energy never increases.
#[test]
fn impact_on_a_limit_is_inelastic() {
    let model = Arc::new(arm());
    let options =
        SimOptions { integrator: Some(IntegratorKind::Rk4), timestep: Some(1e-3), ..Default::default() };
    let mut sim = Simulation::new(model, &options);
    sim.set_state(&[-1.0], &[0.0]).unwrap();
    let (t0, v0) = sim.energies();
    let e0 = t0 + v0;
    let (mut worst, mut e_max, mut hit) = (0.0f64, f64::MIN, false);
    for _ in 0..3000 {
        sim.step().unwrap();
        worst = worst.max(sim.data.qpos[0]);
        hit |= sim.data.qpos[0] >= -1e-9;
        let (t, v) = sim.energies();
        e_max = e_max.max(t + v - e0);
    }
    println!("arm into its limit: max q {worst:e}, max E − E0 {e_max:.2e} J, final v {:e}", sim.data.qvel[0]);
    assert!(hit, "the arm should reach its bound");
    assert!(worst <= LIMIT_EXCURSION, "passed the bound by {worst:e}");
    assert!(e_max <= 1e-9, "energy increased by {e_max:e}");
    assert!(sim.data.qvel[0].abs() <= 1e-9, "at rest on the bound: v = {}", sim.data.qvel[0]);
}

/// The UR5 released under gravity stays within its joint limits
/// for 10 s, with the limits reached.
#[test]
fn ur5_stays_within_its_joint_limits() {
    let model = Arc::new(load(Path::new("models/ur5/ur5.urdf"), &LoadOptions::default()).unwrap());
    let options =
        SimOptions { integrator: Some(IntegratorKind::Rk4), timestep: Some(1e-3), ..Default::default() };
    let mut sim = Simulation::new(model.clone(), &options);
    sim.set_state(&[0.0, -1.2, 1.0, -0.6, 1.5, 0.0], &[0.0; 6]).unwrap();
    let (mut excursion, mut at_limit) = (0.0f64, 0usize);
    for _ in 0..10_000 {
        sim.step().unwrap();
        let mut touching = false;
        for j in &model.joints {
            if let Some([lo, hi]) = j.limits {
                let q = sim.data.qpos[j.qpos_adr];
                excursion = excursion.max(lo - q).max(q - hi);
                touching |= q <= lo || q >= hi;
            }
        }
        at_limit += usize::from(touching);
    }
    println!("UR5 10 s: max excursion beyond a limit {excursion:.2e} rad, {at_limit} steps at a limit");
    assert!(excursion <= LIMIT_EXCURSION, "{excursion:e}");
    assert!(at_limit > 0, "the released UR5 reaches its elbow limit");
}
