//! The compiler's actuator length ranges (`model::lengthrange`, `model::lengthrange_sim`) against
//! MuJoCo 4.0's `actuator_lengthrange` (tests/data/mujoco/lengthrange.json, written by
//! validation/mujoco_lengthrange_golden.py): every model of tests/data/mjcf/lengthrange/ — the
//! simulation on limited hinges, sliders, fixed and spatial tendons, `mode="all"`,
//! `useexisting="false"`, `uselimit`, `maxforce`/`timestep` — and MyoSuite's muscle models when the
//! validation venv is present; then 100 steps with the muscles acting at those ranges; and
//! MuJoCo's refusal of a range that does not converge, refused here too.

mod common;

use common::*;
use lagrange::io::{load, LoadOptions};
use lagrange::Data;
use serde_json::Value;

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn lengthranges_match_mujoco() {
    let golden: Value = serde_json::from_str(
        &std::fs::read_to_string(repo_path("tests/data/mujoco/lengthrange.json")).unwrap(),
    )
    .unwrap();
    let venv = repo_path("validation/.venv/lib/python3.11/site-packages");
    let (mut compared, mut refused, mut skipped) = (0, 0, 0);
    for m in golden["models"].as_array().unwrap() {
        let name = m["model"].as_str().unwrap();
        let path = if m["venv"].as_bool() == Some(true) { venv.join(name) } else { repo_path(name) };
        if !path.exists() {
            println!("skipped: {name}: the validation venv (validation/setup_venv.sh) is not installed here");
            skipped += 1;
            continue;
        }
        let loaded = load(&path, &LoadOptions::default());
        if let Some(err) = m["error"].as_str() {
            let e = loaded
                .err()
                .unwrap_or_else(|| panic!("{name}: MuJoCo refuses it ({err}), lagrange loaded it"));
            let text = e.to_string();
            assert!(text.contains("did not converge"), "{name}: {text}");
            println!("{name}: refused as MuJoCo does: {text}");
            refused += 1;
            continue;
        }
        let model = loaded.unwrap_or_else(|e| panic!("{name}: {e}"));
        let ranges = m["actuator_lengthrange"].as_array().unwrap();
        for (i, r) in ranges.iter().enumerate() {
            let want = floats(r);
            let got = model.actuators[i].lengthrange;
            let width = (want[1] - want[0]).abs().max(REL_FLOOR);
            let err = (got[0] - want[0]).abs().max((got[1] - want[1]).abs()) / width;
            println!("{name} actuator {i}: lengthrange {got:?} vs MuJoCo {want:?}: {err:.1e} of the width");
            assert!(err <= LENGTHRANGE_REL, "{name} actuator {i}: {err:.2e} > {LENGTHRANGE_REL:.0e}");
            compared += 1;
        }
        let mut data = Data::new(&model);
        data.ctrl.fill(m["ctrl"].as_f64().unwrap());
        for _ in 0..m["steps"].as_u64().unwrap() {
            lagrange::integrate::step(&model, &mut data).unwrap();
        }
        assert_close_vec(
            &format!("{name} qpos after steps"),
            data.qpos.as_slice(),
            &floats(&m["qpos"]),
            REF_REL,
        );
        assert_close_vec(
            &format!("{name} actuator_force after steps"),
            data.actuator_force.as_slice(),
            &floats(&m["actuator_force"]),
            REF_REL,
        );
    }
    println!("lengthranges: {compared} compared, {refused} refused as MuJoCo does, {skipped} skipped");
    // The 8 ranges of the hand-made scenes always; MyoSuite's 6 more when the venv is there
    // (each skipped model printed above with its reason, and counted).
    assert!(compared >= 8 + 6 - 3 * skipped && refused >= 1, "{compared} compared, {skipped} skipped");
}

/// Hostile options: a simulation too long to run and a negative option are refused with the fix.
#[test]
fn lengthrange_options_out_of_bounds_are_refused() {
    let text = |compiler: &str| {
        format!(
            r#"<mujoco><compiler><lengthrange {compiler}/></compiler><worldbody><body><joint name="j" range="-1 1"/>
               <geom size="0.1"/></body></worldbody><actuator><muscle joint="j"/></actuator></mujoco>"#
        )
    };
    let long = lagrange::Model::from_str(&text(r#"inttotal="1e9""#)).unwrap_err().to_string();
    assert!(
        long.contains("more than 1e6") && long.contains("lower <compiler><lengthrange inttotal>"),
        "{long}"
    );
    let negative = lagrange::Model::from_str(&text(r#"accel="-5""#)).unwrap_err().to_string();
    assert!(negative.contains("accel") && negative.contains("non-negative"), "{negative}");
}
