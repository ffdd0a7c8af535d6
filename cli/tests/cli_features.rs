//! Command-line behaviour of library features: `info` listing what is simulated, `eval` and
//! `simulate` carrying actuator activations, `simulate` and `workprec` selecting the implicit and
//! variational integrators, and `simulate`'s summary counting pyramidal contacts.

mod run;

use lagrange::io::{load, LoadOptions};
use run::lagrange;

const ACTIVATION: &str = "tests/data/mjcf/actuators/activation.xml";
const TRANSMISSIONS: &str = "tests/data/mjcf/actuators/transmissions.xml";

/// Every transmission of the scene is simulated — the body (adhesion) one included since
/// src/forward/adhesion.rs — so nothing is warned about at load and `info` lists each as
/// simulated.
#[test]
fn transmissions_are_simulated_and_listed() {
    let model = load(&run::root().join(TRANSMISSIONS), &LoadOptions::default()).unwrap();
    assert!(!model.warnings.iter().any(|w| w.contains("not simulated")), "{:?}", model.warnings);
    let (ok, out, err) = lagrange(&["info", TRANSMISSIONS, "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let status = |name: &str| {
        v["elements"].as_array().unwrap().iter().find(|e| e["name"] == name).unwrap()["status"].clone()
    };
    for name in ["suction", "crank", "ref_base", "free_parent"] {
        assert_eq!(status(name), "simulated", "{name}");
    }
}

/// `eval` takes `"act"` per state and reports `act_dot`; `simulate` writes act columns and the
/// final act from the keyframe's.
#[test]
fn eval_and_simulate_carry_act() {
    let states = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-act-{}.json", std::process::id()));
    std::fs::write(
        &states,
        r#"{"states": [{"q": [0.1, -0.2, 0.05, 0.3], "ctrl": [1.5, 1, -1, 2, 0.5, 0.3, 0.2, 1, 30],
                         "act": [0.1, 0.2, -0.3, 0.35, -0.5, 0.1, 0.05, 0.4, 1.95]}]}"#,
    )
    .unwrap();
    let (ok, out, err) = lagrange(&["eval", ACTIVATION, "--states", states.to_str().unwrap()]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let act_dot = &v["results"][0]["forward"]["act_dot"];
    assert_eq!(act_dot.as_array().unwrap().len(), 9);
    assert!((act_dot[1].as_f64().unwrap() - 16.0).abs() < 1e-12, "{act_dot}");
    assert!((v["results"][0]["forward"]["actuator_force"][0].as_f64().unwrap() - 0.2).abs() < 1e-15);
    std::fs::write(&states, r#"{"states": [{"q": [0, 0, 0, 0], "act": [1, 2]}]}"#).unwrap();
    let (ok, _, err) = lagrange(&["eval", ACTIVATION, "--states", states.to_str().unwrap()]);
    assert!(!ok && err.contains("states[0]: 'act' has 2 values, the model needs 9"), "{err}");
    let _ = std::fs::remove_file(&states);

    let csv = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-act-{}.csv", std::process::id()));
    let (ok, out, err) = lagrange(&[
        "simulate",
        ACTIVATION,
        "--keyframe",
        "loaded",
        "--duration",
        "0.05",
        "--json",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let _ = std::fs::remove_file(&csv);
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let first: Vec<f64> = text.lines().nth(1).unwrap().split(',').map(|x| x.parse().unwrap()).collect();
    let col = header.iter().position(|h| *h == "act:clamped").expect("an act column per activation");
    assert_eq!(header.iter().filter(|h| h.starts_with("act:")).count(), 9);
    assert_eq!(first[col], 0.35, "the keyframe's act");
    let summary: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(summary["act"][3], 0.4, "integrated and clamped to actrange: {}", summary["act"]);
}

/// The command line: `simulate --integrator variational` and `--integrator implicit` name the
/// integrator in the JSON summary; `workprec --integrators implicit,variational` measures both
/// (order 1 and 2: error ratios per halving of dt near 2 and 4 on the double pendulum).
#[test]
fn command_line_selects_implicit_and_variational() {
    for name in ["variational", "implicit"] {
        let (ok, out, err) = lagrange(&[
            "simulate",
            "models/textbook/double_pendulum.xml",
            "--integrator",
            name,
            "--duration",
            "0.1",
            "--json",
        ]);
        assert!(ok, "{err}");
        assert!(
            out.contains(&format!("\"integrator\": \"{name}\""))
                || out.contains(&format!("\"integrator\":\"{name}\"")),
            "{out}"
        );
    }
    let (ok, out, err) = lagrange(&[
        "workprec",
        "models/textbook/double_pendulum.xml",
        "--integrators",
        "implicit,variational",
        "--dts",
        "4e-3,2e-3",
        "--duration",
        "0.8",
        "--repeats",
        "1",
        "--json",
    ]);
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    for (name, expected) in [("implicit", 2.0), ("variational", 4.0)] {
        let errors: Vec<f64> = json["rows"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r["integrator"] == name)
            .map(|r| r["error"].as_f64().unwrap())
            .collect();
        assert_eq!(errors.len(), 2, "{name}: {out}");
        let ratio = errors[0] / errors[1];
        println!("workprec {name}: error ratio {ratio:.2} per halving");
        assert!((ratio / expected - 1.0).abs() < 0.25, "{name}: ratio {ratio}");
    }
}

/// `simulate`'s summary counts pyramidal contacts (MJCF's default cone), so the drop scene is
/// not a passive scene without contacts.
#[test]
fn simulate_counts_pyramidal_contacts() {
    let (ok, out, err) = lagrange(&["simulate", "models/textbook/drop.xml", "--duration", "3", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    println!("max_contacts {} max_penetration {}", v["max_contacts"], v["max_penetration"]);
    assert!(v["max_contacts"].as_u64().unwrap() >= 5, "ball + 4 box corners: {}", v["max_contacts"]);
    assert!(v["max_penetration"].as_f64().unwrap() > 0.0);
    let (ok, text, _) = lagrange(&["simulate", "models/textbook/drop.xml", "--duration", "3"]);
    assert!(ok && !text.contains("passive scene"), "{text}");
}
