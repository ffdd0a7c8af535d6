//! Sensors (`Data::sensordata`) against MuJoCo 4.0's `sensordata`: on the scenes of
//! tests/data/mjcf/sensors/ at the states of validation/mujoco_sensor_golden.py (random states,
//! the puck pressed into the floor), after `forward` — every sensor MuJoCo has is either computed
//! and compared (relative to the largest value of the sensors of its type at that state, over an
//! absolute floor of `SENSOR_ABS_FLOOR`: a force sensor reading zero as the difference of two 30 N
//! wrenches compares at the scale of the scene's forces) or listed as not computed with a reason; and after `step`, which leaves
//! the sensors of the state the step started from, as `mj_step` does. The reference data is
//! checked against the live MuJoCo in `.ci/run`; `validation/crossval_sensors` compares more
//! scenes and corpus models live.

mod common;

use common::{MaxErr, REF_REL, SENSOR_ABS_FLOOR};
use lagrange::prelude::*;
use serde_json::Value;

/// max |a − b| / scale over a sensor's values.
fn sensor_err(a: &[f64], b: &[f64], scale: f64) -> f64 {
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale
}

fn vec(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// Compares every sensor of `expected` with `data`; returns the labels of those not computed.
fn compare(model: &Model, data: &Data, expected: &Value, check: &mut MaxErr, at: &str) -> Vec<String> {
    let mut skipped = Vec::new();
    // The scale of each sensor type at this state: its largest reference value.
    let mut scale = std::collections::HashMap::new();
    for (label, values) in expected.as_object().unwrap() {
        if let Some(s) = model.sensor(label) {
            let m = vec(values).iter().fold(SENSOR_ABS_FLOOR, |m, x| m.max(x.abs()));
            let e = scale.entry(s.kind).or_insert(SENSOR_ABS_FLOOR);
            *e = f64::max(*e, m);
        }
    }
    for (label, values) in expected.as_object().unwrap() {
        let sensor = model.sensor(label).unwrap_or_else(|| panic!("{at}: lagrange has no sensor '{label}'"));
        if let Some(why) = &sensor.not_computed {
            skipped.push(format!("{label} ({why})"));
            continue;
        }
        let got = data.sensor(model, label).unwrap();
        check.add(sensor_err(got, &vec(values), scale[&sensor.kind]), || {
            format!("{at}, sensor {label}: {got:?} vs {values}")
        });
    }
    skipped
}

fn scenes() -> Vec<(Model, Value)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir("tests/data/mujoco_sensors").unwrap() {
        let golden: Value =
            serde_json::from_str(&std::fs::read_to_string(entry.unwrap().path()).unwrap()).unwrap();
        let model = Model::from_file(golden["model"].as_str().unwrap()).unwrap();
        out.push((model, golden));
    }
    assert!(!out.is_empty());
    out
}

#[test]
fn sensors_after_forward_equal_mujoco() {
    let mut check = MaxErr::new("sensordata after forward vs MuJoCo mj_forward", REF_REL);
    for (model, golden) in scenes() {
        let mut data = Data::new(&model);
        let mut skipped = Vec::new();
        for (i, s) in golden["forward"].as_array().unwrap().iter().enumerate() {
            data.qpos.copy_from_slice(&vec(&s["q"]));
            data.qvel.copy_from_slice(&vec(&s["v"]));
            data.ctrl.copy_from_slice(&vec(&s["ctrl"]));
            data.time = s["time"].as_f64().unwrap();
            forward(&model, &mut data);
            assert_eq!(
                data.contacts.len() as u64,
                s["ncon"].as_u64().unwrap(),
                "{}: contacts at state {i}",
                model.name
            );
            skipped = compare(&model, &data, &s["sensors"], &mut check, &format!("{} state {i}", model.name));
        }
        println!("{}: {} sensors, not computed: {skipped:?}", model.name, model.sensors.len());
    }
    common::report_and_assert(&[&check]);
}

#[test]
fn step_leaves_the_sensors_of_the_state_it_started_from() {
    let mut check = MaxErr::new("sensordata after step vs MuJoCo mj_step", REF_REL);
    for (model, golden) in scenes() {
        let mut data = Data::new(&model);
        let first = &golden["forward"][0];
        data.qpos.copy_from_slice(&vec(&first["q"]));
        data.qvel.copy_from_slice(&vec(&first["v"]));
        data.ctrl.copy_from_slice(&vec(&first["ctrl"]));
        data.time = first["time"].as_f64().unwrap();
        for (k, s) in golden["steps"].as_array().unwrap().iter().enumerate() {
            // Stepwise: each step starts from MuJoCo's state.
            data.qpos.copy_from_slice(&vec(&s["before"]["q"]));
            data.qvel.copy_from_slice(&vec(&s["before"]["v"]));
            data.time = s["before"]["time"].as_f64().unwrap();
            step(&model, &mut data).unwrap();
            compare(&model, &data, &s["sensors"], &mut check, &format!("{} step {}", model.name, k + 1));
        }
    }
    common::report_and_assert(&[&check]);
}

#[test]
fn a_model_without_sensors_has_no_sensordata_and_a_disabled_flag_computes_none() {
    let model = Model::from_file("models/textbook/double_pendulum.xml").unwrap();
    assert_eq!((model.sensors.len(), model.nsensordata, Data::new(&model).sensordata.len()), (0, 0, 0));
    assert!(!model.plan.sensor_needs.any);
    let text = std::fs::read_to_string("tests/data/mjcf/sensors/kinematic.xml")
        .unwrap()
        .replace("<worldbody>", "<option><flag sensor=\"disable\"/></option><worldbody>");
    let model = Model::from_str(&text).unwrap();
    let mut data = Data::new(&model);
    data.qpos[0] = 0.4;
    forward(&model, &mut data);
    assert!(model.nsensordata > 0 && data.sensordata.iter().all(|&x| x == 0.0));
}

#[test]
fn sensor_lookup_errors_name_the_known_sensors() {
    let model = Model::from_file("tests/data/mjcf/sensors/kinematic.xml").unwrap();
    let data = Data::new(&model);
    let err = data.sensor(&model, "elbo_vel").unwrap_err().to_string();
    assert!(err.contains("elbo_vel") && err.contains("elbow_vel"), "{err}");
    assert_eq!(data.sensor(&model, "jointpos#0").unwrap().len(), 1, "unnamed sensors by TYPE#ID");
}
