//! `simulate`'s inputs and trajectory CSV: names that need quoting, the ctrl and actuator_force
//! columns, time-varying controls (`--ctrl-file`, linear and hold) and applied joint torques
//! (`--tau-file`, which drives a URDF robot), and the errors of a bad input file.

#[path = "../../tests/common/mod.rs"]
mod common;
mod run;

use common::REF_REL;
use run::lagrange;
use std::path::PathBuf;

fn temp_file(name: &str, text: &str) -> PathBuf {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-inputs-{}-{name}", std::process::id()));
    std::fs::write(&path, text).unwrap();
    path
}

/// The CSV as records (header first), read back by the csv crate.
fn read_csv(path: &PathBuf) -> Vec<Vec<String>> {
    let mut reader = csv::ReaderBuilder::new().has_headers(false).from_path(path).unwrap();
    reader.records().map(|r| r.unwrap().iter().map(str::to_string).collect()).collect()
}

fn column(rows: &[Vec<String>], name: &str) -> Vec<f64> {
    let k =
        rows[0].iter().position(|c| c == name).unwrap_or_else(|| panic!("no column {name} in {:?}", rows[0]));
    rows[1..].iter().map(|r| r[k].parse().unwrap()).collect()
}

/// A hinge with a motor (force = ctrl) and no gravity: q̈ = ctrl / I.
const MOTOR: &str = r#"<mujoco model="motor">
  <option gravity="0 0 0" timestep="0.01"/>
  <worldbody>
    <body name="arm">
      <joint name="hinge" type="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 1 0 0" size="0.05" mass="1"/>
    </body>
  </worldbody>
  <actuator><motor name="drive" joint="hinge"/></actuator>
</mujoco>"#;

#[test]
fn a_joint_name_with_a_comma_is_quoted_and_every_row_has_the_header_s_fields() {
    let urdf = r#"<robot name="r">
  <link name="base"/>
  <link name="leg"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="hip,left" type="continuous"><parent link="base"/><child link="leg"/><axis xyz="0 1 0"/></joint>
</robot>"#;
    let model = temp_file("comma.urdf", urdf);
    let out = temp_file("comma.csv", "");
    let (ok, _, err) = lagrange(&[
        "simulate",
        model.to_str().unwrap(),
        "--duration",
        "0.01",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let rows = read_csv(&out);
    assert_eq!(rows[0], ["time", "q:hip,left[0]", "v:hip,left[0]", "energy", "constraint_violation"]);
    assert!(rows.iter().all(|r| r.len() == rows[0].len()), "{rows:?}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("time,\"q:hip,left[0]\",\"v:hip,left[0]\","), "{text}");
}

#[test]
fn ctrl_file_is_interpolated_linearly_or_held_and_forces_are_in_the_csv() {
    let model = temp_file("motor.xml", MOTOR);
    let ctrl = temp_file("ctrl.csv", "time,drive\n0,0\n0.1,1\n0.2,1\n");
    for (interp, at_0_05) in [("linear", 0.5), ("hold", 0.0)] {
        let out = temp_file(&format!("motor-{interp}.csv"), "");
        let (ok, _, err) = lagrange(&[
            "simulate",
            model.to_str().unwrap(),
            "--duration",
            "0.3",
            "--ctrl-file",
            ctrl.to_str().unwrap(),
            "--input-interp",
            interp,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        let rows = read_csv(&out);
        let (time, ctrl, force) =
            (column(&rows, "time"), column(&rows, "ctrl:drive"), column(&rows, "actuator_force:drive"));
        assert_eq!(time.len(), 31);
        // Row k: the control applied from t_k on, and the motor's force at that state (gain 1).
        let k = time.iter().position(|t| (t - 0.05).abs() < 1e-12).unwrap();
        assert!((ctrl[k] - at_0_05).abs() < 1e-12, "{interp}: ctrl(0.05) = {}", ctrl[k]);
        for (c, f) in ctrl.iter().zip(&force) {
            assert_eq!(c, f, "{interp}: a motor's force is its control");
        }
        // After the last row the last value is held.
        assert_eq!(*ctrl.last().unwrap(), 1.0);
    }
}

#[test]
fn tau_file_drives_a_urdf_robot() {
    // The gravity torque at q = 0.7, from `eval`, applied through --tau-file holds the
    // pendulum still: q stays at 0.7 while without it the pendulum falls.
    let states = temp_file("states.json", r#"{"states": [{"q": [0.7], "v": [0.0]}]}"#);
    let (ok, out, err) = lagrange(&[
        "eval",
        "models/textbook/simple_pendulum.urdf",
        "--states",
        states.to_str().unwrap(),
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let gravity = v["results"][0]["bias"][0].as_f64().unwrap();
    let tau = temp_file("tau.csv", &format!("time,hinge\n0,{gravity:?}\n"));
    let run = |extra: &[&str]| {
        let out = temp_file(&format!("pendulum-{}.csv", extra.len()), "");
        let args = [
            &["simulate", "models/textbook/simple_pendulum.urdf", "--q0", "0.7", "--duration", "0.5"][..],
            extra,
            &["--out", out.to_str().unwrap()],
        ]
        .concat();
        let (ok, _, err) = lagrange(&args);
        assert!(ok, "{err}");
        column(&read_csv(&out), "q:hinge[0]")
    };
    let held = run(&["--tau-file", tau.to_str().unwrap()]);
    let worst = held.iter().map(|q| (q - 0.7).abs()).fold(0.0, f64::max);
    assert!(worst < REF_REL, "held pendulum moved by {worst:e}");
    let free = run(&[]);
    assert!((free.last().unwrap() - 0.7).abs() > 0.1, "{free:?}");
}

#[test]
fn bad_input_files_are_refused_with_the_line_and_the_fix() {
    let model = temp_file("motor-errors.xml", MOTOR);
    let cases: [(&str, &str, &str, &[&str]); 7] = [
        ("--ctrl-file", "unknown.csv", "time,gripper\n0,1\n", &["column 'gripper'", "the model's: drive"]),
        ("--ctrl-file", "order.csv", "time,drive\n0,1\n0,2\n", &["line 3", "times must increase"]),
        ("--ctrl-file", "nan.csv", "time,drive\n0,nan\n", &["line 2", "column 'drive'", "not finite"]),
        ("--ctrl-file", "text.csv", "time,drive\n0,abc\n", &["line 2", "'abc' is not a number"]),
        ("--ctrl-file", "header.csv", "t,drive\n0,1\n", &["first column is 't'", "time,NAME"]),
        ("--ctrl-file", "empty.csv", "time,drive\n", &["no rows"]),
        ("--tau-file", "dof.csv", "time,hinge[1]\n0,1\n", &["column 'hinge[1]'", "1 dofs", "out of range"]),
    ];
    for (option, name, text, needles) in cases {
        let file = temp_file(name, text);
        let (ok, _, err) = lagrange(&[
            "simulate",
            model.to_str().unwrap(),
            "--duration",
            "0.1",
            option,
            file.to_str().unwrap(),
        ]);
        assert!(!ok, "{name} accepted");
        for needle in needles {
            assert!(err.contains(needle), "{name}: missing '{needle}' in {err}");
        }
        assert!(err.contains(option), "{name}: the message names {option}: {err}");
    }
}

#[test]
fn a_non_finite_actuator_force_stops_the_run_instead_of_reaching_the_csv() {
    // A position servo (kp 1e12) at a finite hinge angle of 1e300 rad: its force kp·(ctrl − q)
    // overflows to −inf while the state, and its energy, are finite.
    let servo = MOTOR.replace(
        "<motor name=\"drive\" joint=\"hinge\"/>",
        "<position name=\"drive\" joint=\"hinge\" kp=\"1e12\"/>",
    );
    let model = temp_file("overflow.xml", &servo);
    let out = temp_file("overflow.csv", "");
    std::fs::remove_file(&out).unwrap();
    let (ok, _, err) = lagrange(&[
        "simulate",
        model.to_str().unwrap(),
        "--duration",
        "0.1",
        "--q0",
        "1e300",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok, "an infinite actuator force was written");
    assert!(err.contains("actuator_force of 'drive' is -inf") && err.contains("step 0"), "{err}");
    assert!(!out.exists(), "the CSV target is not written by a stopped run");
    let partial = std::fs::read_to_string(out.with_extension("partial.csv")).unwrap_or_default();
    assert!(!partial.contains("inf") && !partial.to_lowercase().contains("nan"), "{partial}");
}
