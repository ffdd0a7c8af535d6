//! End-to-end tests of the `lagrange` binary: `info --json` keys, `eval` against the Pinocchio
//! reference data, `simulate` output and CSV, the default run, and input errors.

#[path = "../../tests/common/mod.rs"]
mod common;
mod run;

use common::{rel_err_mat, rel_err_vec, REF_REL};
use nalgebra::DMatrix;
use run::lagrange;
use serde_json::Value;
use std::path::PathBuf;

fn temp_file(name: &str, text: &str) -> PathBuf {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-cli-{}-{name}", std::process::id()));
    std::fs::write(&path, text).unwrap();
    path
}

fn keys(v: &Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().expect("an object").keys().cloned().collect();
    k.sort();
    k
}

#[test]
fn info_json_has_exactly_the_documented_keys() {
    let (ok, out, err) = lagrange(&["info", "models/solo12/solo12.urdf", "--floating", "--json"]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        keys(&v),
        [
            "actuators",
            "bodies",
            "constraints",
            "elements",
            "frames",
            "joints",
            "keyframes",
            "na",
            "nq",
            "nu",
            "nv",
            "options",
            "qpos0",
            "stages",
            "total_mass",
            "warnings"
        ]
    );
    assert_eq!((v["nq"].as_u64(), v["nv"].as_u64()), (Some(19), Some(18)));
    assert_eq!(keys(&v["bodies"][1]), ["com", "inertia", "mass", "name", "parent"]);
    assert_eq!(keys(&v["joints"][0]), ["child", "dofadr", "name", "nq", "nv", "parent", "qposadr", "type"]);
    assert_eq!(v["joints"][0]["name"], "root_joint");
    assert_eq!(v["joints"][0]["type"], "free");
    // The shipped solo12 has its meshes stripped: no collision geometry, no collision stage.
    assert_eq!(v["stages"]["collision"]["status"], "skipped");
    assert_eq!(v["stages"]["joint limits"]["status"], "runs");
    let total: f64 = v["total_mass"].as_f64().unwrap();
    assert!((total - 2.50000279).abs() < 1e-6, "{total}");
}

#[test]
fn info_text_lists_the_plan_and_mimic() {
    let (ok, out, err) = lagrange(&["info", "models/panda/panda.urdf"]);
    assert!(ok, "{err}");
    assert!(out.contains("forward plan (constraint mode: exact; exact is the default for URDF)"), "{out}");
    assert!(out.contains("mimic panda_finger_joint1 (× 1 + 0)"), "{out}");
    assert!(out.contains("1 × equality <mimic>") && out.contains("simulated (exact mode)"), "{out}");
    assert!(out.contains("equality") && out.contains("1 mimic (1 rows)"), "{out}");
}

/// `eval` on the Pinocchio reference states reproduces M, bias, qacc and poses at REF_REL.
#[test]
fn eval_matches_pinocchio_reference_data() {
    let root = run::root();
    let golden: Value = serde_json::from_str(
        &std::fs::read_to_string(root.join("tests/data/pinocchio/solo12.json")).unwrap(),
    )
    .unwrap();
    let states: Vec<Value> = golden["states"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| serde_json::json!({"q": s["q"], "v": s["v"], "tau": s["tau"]}))
        .collect();
    let input = temp_file("states.json", &serde_json::json!({ "states": states }).to_string());
    let (ok, out, err) = lagrange(&[
        "eval",
        "models/solo12/solo12.urdf",
        "--floating",
        "--states",
        input.to_str().unwrap(),
        "--jacobian",
        "FL_FOOT",
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let results = v["results"].as_array().unwrap();
    assert_eq!(results.len(), states.len());
    let vec = |x: &Value| x.as_array().unwrap().iter().map(|e| e.as_f64().unwrap()).collect::<Vec<f64>>();
    let mat = |x: &Value| {
        let rows: Vec<Vec<f64>> = x.as_array().unwrap().iter().map(vec).collect();
        DMatrix::from_fn(rows.len(), rows[0].len(), |r, c| rows[r][c])
    };
    let mut worst = 0.0f64;
    for (r, s) in results.iter().zip(golden["states"].as_array().unwrap()) {
        worst = worst.max(rel_err_mat(&mat(&r["M"]), &mat(&s["M"])));
        worst = worst.max(rel_err_vec(&vec(&r["bias"]), &vec(&s["bias"])));
        worst = worst.max(rel_err_vec(&vec(&r["qacc"]), &vec(&s["qacc"])));
        worst = worst.max(rel_err_vec(&vec(&r["com"]), &vec(&s["com"])));
        let pos = |x: &Value, l: &str| vec(&x["poses"][l]["pos"]);
        worst = worst.max(rel_err_vec(&pos(r, "FL_FOOT"), &pos(s, "FL_FOOT")));
        let jac = mat(&r["jacobians"]["FL_FOOT"]);
        assert_eq!((jac.nrows(), jac.ncols()), (6, 18));
    }
    println!("eval vs Pinocchio (solo12): worst relative error {worst:.2e}");
    assert!(worst <= REF_REL, "{worst}");
}

#[test]
fn eval_rejects_a_state_of_the_wrong_size() {
    let input = temp_file("bad_states.json", r#"{"states": [{"q": [0.0, 1.0], "v": [0, 0, 0, 0, 0, 0]}]}"#);
    let (ok, _, err) = lagrange(&["eval", "models/ur5/ur5.urdf", "--states", input.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("states[0]: 'q' has 2 values, the model needs 6"), "{err}");
    let input = temp_file("malformed_states.json", "{\"states\": [\n{\"q\": [0.0,]}]}");
    let (ok, _, err) = lagrange(&["eval", "models/ur5/ur5.urdf", "--states", input.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("line 2") && err.contains("expected {\"states\""), "{err}");
    // A misspelled field is an error naming it, never silently ignored.
    let input = temp_file(
        "misspelled_states.json",
        r#"{"states": [{"q": [0, 0, 0, 0, 0, 0], "vel": [1, 0, 0, 0, 0, 0]}]}"#,
    );
    let (ok, _, err) = lagrange(&["eval", "models/ur5/ur5.urdf", "--states", input.to_str().unwrap()]);
    assert!(!ok && err.contains("unknown field `vel`"), "{err}");
}

#[test]
fn simulate_prints_a_summary_and_writes_the_csv() {
    let csv = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-cli-{}-traj.csv", std::process::id()));
    let (ok, out, err) = lagrange(&[
        "simulate",
        "models/textbook/double_pendulum.urdf",
        "--duration",
        "0.5",
        "--dt",
        "0.001",
        "--integrator",
        "euler",
        "--q0",
        "2.0,0.5",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    for needle in ["500 steps", "real-time factor", "energy: start", "final state", "shoulder", "elbow"] {
        assert!(out.contains(needle), "missing '{needle}' in {out}");
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time,q:shoulder[0],q:elbow[0],v:shoulder[0],v:elbow[0],energy,constraint_violation"
    );
    assert_eq!(lines.count(), 501);
}

#[test]
fn simulate_rejects_bad_arguments_with_a_fix() {
    let (ok, _, err) = lagrange(&["simulate", "models/ur5/ur5.urdf", "--q0", "1,2"]);
    assert!(!ok);
    assert!(err.contains("--q0: 2 values given, the model needs 6"), "{err}");
    let (ok, _, err) = lagrange(&["simulate", "models/ur5/ur5.urdf", "--dt", "0"]);
    assert!(!ok);
    assert!(err.contains("--dt 0: the step must be a positive"), "{err}");
    // A negative value reaches the check (not clap's "unexpected argument '-0.01'").
    let (ok, _, err) = lagrange(&["simulate", "models/ur5/ur5.urdf", "--dt", "-0.01"]);
    assert!(!ok);
    assert!(err.contains("--dt -0.01: the step must be a positive, finite number of seconds"), "{err}");
    let (ok, _, err) = lagrange(&["simulate", "models/ur5/ur5.urdf", "--duration", "-1"]);
    assert!(!ok);
    assert!(err.contains("--duration -1: give a non-negative"), "{err}");
    let (ok, _, err) = lagrange(&["simulate", "models/textbook/heavy_top.xml", "--rtol", "1e-6"]);
    assert!(!ok);
    assert!(
        err.contains(
            "--rtol/--atol set the error control of the adaptive integrator: add --integrator adaptive"
        ),
        "{err}"
    );
    let (ok, _, err) =
        lagrange(&["simulate", "models/textbook/heavy_top.xml", "--integrator", "adaptive", "--atol", "-1"]);
    assert!(!ok);
    assert!(err.contains("--atol -1: give a positive tolerance, e.g. --atol 1e-8"), "{err}");
}

/// `--integrator adaptive --rtol --atol` runs and reports the adaptive integrator.
#[test]
fn simulate_adaptive_with_tolerances() {
    let (ok, out, err) = lagrange(&[
        "simulate",
        "models/textbook/heavy_top.xml",
        "--integrator",
        "adaptive",
        "--rtol",
        "1e-10",
        "--atol",
        "1e-12",
        "--duration",
        "0.5",
        "--dt",
        "0.01",
        "--v0",
        "1,0.5,20",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["integrator"], "adaptive");
    assert_eq!(v["steps"], 50);
    let drift = v["energy"]["max_abs_drift"].as_f64().unwrap();
    assert!(drift < 1e-8, "energy drift {drift} at rtol 1e-10");
}

#[test]
fn default_run_simulates_the_embedded_model() {
    let (ok, out, err) = lagrange(&[]);
    assert!(ok, "{err}");
    for needle in [
        "embedded default scene",
        "Unitree Go1",
        "forward plan",
        "soft mode",
        "2500 steps",
        "energy: start",
        "base height",
    ] {
        assert!(out.contains(needle), "missing '{needle}' in {out}");
    }
}

#[test]
fn load_errors_reach_the_user_with_file_and_line() {
    let urdf = temp_file("zero_axis.urdf", "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"/>\n<joint name=\"j\" type=\"revolute\">\n<parent link=\"a\"/><child link=\"b\"/><axis xyz=\"0 0 0\"/>\n</joint>\n</robot>\n");
    let (ok, _, err) = lagrange(&["info", urdf.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains(&format!("{}:4", urdf.display()))
            && err.contains("joint 'j'")
            && err.contains("axis is zero"),
        "{err}"
    );
}

#[test]
fn mjcf_info_lists_kept_elements_and_keyframes() {
    let (ok, out, err) = lagrange(&["info", "models/mjcf/unitree_go1/go1.xml", "--json"]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!((v["nq"].as_u64(), v["nv"].as_u64()), (Some(19), Some(18)));
    assert_eq!(v["keyframes"][0]["name"], "home");
    let actuators: Vec<&Value> =
        v["elements"].as_array().unwrap().iter().filter(|e| e["category"] == "actuator").collect();
    assert_eq!(actuators.len(), 12);
    assert!(actuators.iter().all(|a| a["kind"] == "position" && a["status"] == "simulated"));
    assert_eq!(actuators[0]["targets"][0], "FR_hip_joint");
    assert_eq!(v["stages"]["actuation"]["status"], "runs");
    assert_eq!(
        v["stages"]["collision"]["status"], "runs",
        "self-collision pairs between the legs and the trunk"
    );
    assert_eq!(v["options"]["timestep"], 0.002, "MuJoCo's default: go1.xml sets no <option>");
}

#[test]
fn simulate_starts_from_a_keyframe_and_rejects_unknown_ones() {
    let (ok, out, err) = lagrange(&[
        "simulate",
        "models/mjcf/unitree_go1/go1.xml",
        "--keyframe",
        "home",
        "--duration",
        "0.01",
    ]);
    assert!(ok, "{err}");
    // The home pose bends the calves to −1.8 rad; 10 ms of free fall barely moves them.
    assert!(out.contains("FR_calf_joint            q = [-1.80"), "{out}");
    let (ok, _, err) = lagrange(&["simulate", "models/mjcf/unitree_go1/go1.xml", "--keyframe", "crouch"]);
    assert!(!ok);
    assert!(err.contains("--keyframe crouch: the model has no such keyframe (it has: home)"), "{err}");
}

#[test]
fn info_lists_typed_elements_with_what_is_simulated() {
    let (ok, out, err) = lagrange(&["info", "tests/data/elements/elements.xml", "--json"]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let elements = v["elements"].as_array().unwrap();
    let find =
        |name: &str| elements.iter().find(|e| e["name"] == name).unwrap_or_else(|| panic!("no {name}"));
    let c = find("c_body");
    assert_eq!((c["category"].as_str(), c["kind"].as_str()), (Some("equality"), Some("connect")));
    assert_eq!(c["targets"], serde_json::json!(["c", "world"]));
    assert_eq!(c["status"], "simulated (exact mode)");
    assert!(c["source"].as_str().unwrap().ends_with("elements.xml:47"), "{c}");
    assert_eq!(find("t1")["status"], "simulated (equality rows)", "coupled by the tendon equality");
    assert_eq!(find("rope")["status"], "simulated");
    assert_eq!(find("rope")["kind"], "spatial");
    let p = find("p_class");
    assert_eq!((p["kind"].as_str(), p["status"].as_str()), (Some("position"), Some("simulated")));
    assert_eq!(p["targets"], serde_json::json!(["slide"]));
    assert_eq!(find("p0")["targets"], serde_json::json!(["floor", "gc"]));
    assert_eq!(find("x")["kind"], "exclude");
    assert_eq!(
        (find("p0")["status"].as_str(), find("x")["status"].as_str()),
        (Some("simulated (exact mode)"), Some("simulated (exact mode)"))
    );
    // The text lists them grouped by kind and status.
    let (ok, out, _) = lagrange(&["info", "tests/data/elements/elements.xml"]);
    assert!(ok);
    assert!(out.contains("3 × equality <weld>") && out.contains("simulated (exact mode)"), "{out}");
}

#[test]
fn info_json_shows_urdf_mimic_on_the_joint() {
    let (ok, out, err) = lagrange(&["info", "models/panda/panda.urdf", "--json"]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let j = v["joints"].as_array().unwrap().iter().find(|j| j["name"] == "panda_finger_joint2").unwrap();
    assert_eq!(
        j["mimic"],
        serde_json::json!({"joint": "panda_finger_joint1", "multiplier": 1.0, "offset": 0.0, "equality": "mimic:panda_finger_joint2"})
    );
    let e = v["elements"].as_array().unwrap().iter().find(|e| e["kind"] == "mimic").unwrap();
    assert_eq!(e["targets"], serde_json::json!(["panda_finger_joint2", "panda_finger_joint1"]));
}

#[test]
fn disable_switches_off_option_flags_for_both_formats() {
    let (ok, out, err) = lagrange(&["info", "models/ur5/ur5.urdf", "--json", "--disable", "limit"]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["stages"]["joint limits"]["status"], "skipped");
    assert!(v["stages"]["joint limits"]["reason"].as_str().unwrap().contains("flag limit"));
    let (ok, _, err) = lagrange(&["info", "models/ur5/ur5.urdf", "--disable", "limits"]);
    assert!(!ok);
    assert!(err.contains("--disable limits: not a MuJoCo <flag>; use one of"), "{err}");
}

#[test]
fn info_lists_urdf_transmissions_and_effort_limits() {
    let (ok, out, err) = lagrange(&["info", "models/ur5/ur5.urdf", "--json"]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let transmissions: Vec<&Value> =
        v["elements"].as_array().unwrap().iter().filter(|e| e["category"] == "transmission").collect();
    assert_eq!(transmissions.len(), 6);
    assert_eq!(transmissions[0]["name"], "shoulder_pan_trans");
    assert_eq!(transmissions[0]["kind"], "transmission_interface/SimpleTransmission");
    assert_eq!(transmissions[0]["targets"], serde_json::json!(["shoulder_pan_joint", "shoulder_pan_motor"]));
    assert!(transmissions[0]["source"].as_str().unwrap().starts_with("models/ur5/ur5.urdf:"));
    let (ok, out, _) = lagrange(&["info", "models/ur5/ur5.urdf", "--clamp-effort"]);
    assert!(ok);
    assert!(
        out.contains("|torque| ≤ 150 (--clamp-effort)") && out.contains("|torque| ≤ 28 (--clamp-effort)"),
        "{out}"
    );
}

#[test]
fn simulate_warns_when_a_passive_scene_gains_or_loses_energy() {
    // Semi-implicit Euler at 50 ms on a pendulum released at 1.5 rad: energy drifts by 7 %.
    let args = [
        "simulate",
        "models/textbook/simple_pendulum.urdf",
        "--dt",
        "0.05",
        "--duration",
        "10",
        "--q0",
        "1.5",
    ];
    let (ok, out, err) = lagrange(&args);
    assert!(ok, "{err}");
    assert!(
        out.contains("warning: the energy of this passive scene")
            && out.contains("reduce --dt (now 0.05 s) or use --integrator rk4"),
        "{out}"
    );
    // RK4 at 1 ms: no warning; nor for a scene whose limits end impacts inelastically.
    let (_, out, _) =
        lagrange(&["simulate", "models/textbook/simple_pendulum.urdf", "--integrator", "rk4", "--q0", "1.5"]);
    assert!(!out.contains("warning"), "{out}");
    let (_, out, _) = lagrange(&["simulate", "models/ur5/ur5.urdf", "--duration", "2"]);
    assert!(!out.contains("energy of this passive scene"), "{out}");
}

/// MuJoCo's run-time warnings reach the user: `simulate` prints and reports them (a bad control
/// names its actuator), `eval` lists them per state (a singular mass matrix names its joints).
#[test]
fn simulate_and_eval_report_mujocos_run_time_warnings() {
    let (ok, out, err) = lagrange(&[
        "simulate",
        "tests/data/mjcf/warnings/bad_ctrl.xml",
        "--ctrl",
        "nan,0.5",
        "--duration",
        "0.01",
        "--json",
    ]);
    assert!(ok, "{err}");
    let summary: Value = serde_json::from_str(&out).unwrap();
    let warnings = summary["warnings"].as_array().unwrap();
    assert!(warnings.iter().any(|w| w.as_str().unwrap().contains("'m_free'")), "{warnings:?}");
    let states = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-cli-{}-warnings.json", std::process::id()));
    std::fs::write(&states, r#"{"states": [{"q": [0.1, 0.2, 0.3, 0.1, 0.2]}]}"#).unwrap();
    let (ok, out, err) =
        lagrange(&["eval", "tests/data/mjcf/warnings/dup_hinges.xml", "--states", states.to_str().unwrap()]);
    std::fs::remove_file(&states).ok();
    assert!(ok, "{err}");
    let doc: Value = serde_json::from_str(&out).unwrap();
    let w = doc["results"][0]["warnings"][0].as_str().unwrap();
    assert!(w.contains("singular") && w.contains("'a'"), "{w}");
}

/// A full contact buffer is reported with the budget of the mode that ran: `--constraints exact`
/// keeps at most `MAX_CONTACTS` (its Delassus matrix is rows × rows), which the summary's warning
/// quotes, not the soft mode's larger budget of the file's own model.
#[test]
fn simulate_quotes_the_contact_budget_of_the_mode_it_ran() {
    // 140 boxes pressed 1 mm into a plane, four corner contacts each: 560 > 500.
    let mut bodies = String::new();
    for k in 0..140 {
        let (x, y) = ((k % 12) as f64 * 0.2, (k / 12) as f64 * 0.2);
        bodies += &format!(
            "<body pos='{x} {y} 0.039'><freejoint/><geom type='box' size='0.04 0.04 0.04' mass='0.5'/></body>"
        );
    }
    let xml = format!(
        "<mujoco><default><geom condim='1'/></default><worldbody><geom type='plane' size='0 0 1'/>{bodies}</worldbody></mujoco>"
    );
    let path = temp_file("budget.xml", &xml);
    let (ok, out, err) = lagrange(&[
        "simulate",
        path.to_str().unwrap(),
        "--constraints",
        "exact",
        "--duration",
        "0.002",
        "--json",
    ]);
    std::fs::remove_file(&path).ok();
    assert!(ok, "{err}");
    let summary: Value = serde_json::from_str(&out).unwrap();
    // Each collision pass (the start's and the step's) drops the 60 beyond the budget.
    let dropped = summary["contacts_dropped"].as_u64().unwrap();
    let per_pass = 560 - lagrange::model::MAX_CONTACTS as u64;
    assert!(dropped > 0 && dropped.is_multiple_of(per_pass), "{dropped} dropped");
    let warnings = summary["warnings"].as_array().unwrap();
    let full = warnings.iter().filter_map(|w| w.as_str()).find(|w| w.contains("collision pass"));
    let full = full.unwrap_or_else(|| panic!("no contact-full warning: {warnings:?}"));
    assert!(full.contains(&format!("than the {} kept", lagrange::model::MAX_CONTACTS)), "{full}");
    assert!(full.contains("560 found"), "{full}");
}
