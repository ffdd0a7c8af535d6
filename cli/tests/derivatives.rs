//! `eval --derivatives`: the `"derivatives"` block of each state (shapes, the library's numbers),
//! `--derivatives smooth` without the transition, `hybrid` as `all`, and the refusal with
//! `--kernels-only`.

mod run;

use lagrange::derivatives::{aba_derivatives, DerivativesWork};
use lagrange::io::{load, LoadOptions};
use lagrange::Data;
use run::lagrange;

const ACTIVATION: &str = "tests/data/mjcf/actuators/activation.xml";

fn shape(m: &serde_json::Value) -> (usize, usize) {
    let rows = m.as_array().unwrap();
    (rows.len(), rows.first().map_or(0, |r| r.as_array().unwrap().len()))
}

#[test]
fn eval_adds_derivatives() {
    let model = load(&run::root().join(ACTIVATION), &LoadOptions::default()).unwrap();
    let (nv, na, nu) = (model.nv, model.na(), model.actuators.len());
    let states = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-deriv-{}.json", std::process::id()));
    std::fs::write(
        &states,
        r#"{"states": [{"q": [0.1, -0.2, 0.05, 0.3], "v": [0.3, -0.1, 0.2, 0.05], "tau": [0.1, 0, 0, -0.2],
                         "ctrl": [1.5, 1, -1, 2, 0.5, 0.3, 0.2, 1, 30],
                         "act": [0.1, 0.2, -0.3, 0.35, -0.5, 0.1, 0.05, 0.4, 1.95]}]}"#,
    )
    .unwrap();
    let (ok, out, err) =
        lagrange(&["eval", ACTIVATION, "--states", states.to_str().unwrap(), "--derivatives"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let d = &v["results"][0]["derivatives"];
    assert_eq!(shape(&d["rnea"]["dtau_dq"]), (nv, nv));
    assert_eq!(shape(&d["smooth"]["dqacc_dv"]), (nv, nv));
    assert_eq!(shape(&d["transition"]["A"]), (2 * nv + na, 2 * nv + na));
    assert_eq!(shape(&d["transition"]["B"]), (2 * nv + na, nu));
    // The printed ABA derivatives are the library's at (q, v, tau).
    let mut data = Data::new(&model);
    let mut work = DerivativesWork::new(&model);
    let (q, vel, tau) = ([0.1, -0.2, 0.05, 0.3], [0.3, -0.1, 0.2, 0.05], [0.1, 0.0, 0.0, -0.2]);
    aba_derivatives(&model, &mut data, &mut work, &q, &vel, &tau).unwrap();
    for i in 0..nv {
        for j in 0..nv {
            assert_eq!(d["aba"]["dqacc_dq"][i][j].as_f64().unwrap(), work.dqacc_dq[(i, j)], "({i}, {j})");
        }
    }

    let (ok, out, err) =
        lagrange(&["eval", ACTIVATION, "--states", states.to_str().unwrap(), "--derivatives", "smooth"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v["results"][0]["derivatives"].get("transition").is_none());
    assert!(v["results"][0]["derivatives"].get("smooth").is_some());

    // `hybrid`: the same Jacobians (this model has activations: every column is differenced).
    let (ok, out, err) =
        lagrange(&["eval", ACTIVATION, "--states", states.to_str().unwrap(), "--derivatives", "hybrid"]);
    assert!(ok, "{err}");
    let h: serde_json::Value = serde_json::from_str(&out).unwrap();
    let (a, b) = (&d["transition"]["A"], &h["results"][0]["derivatives"]["transition"]["A"]);
    for i in 0..2 * nv + na {
        for j in 0..2 * nv + na {
            let (x, y) = (a[i][j].as_f64().unwrap(), b[i][j].as_f64().unwrap());
            assert!((x - y).abs() <= 1e-6 * (1.0 + x.abs()), "hybrid A ({i}, {j}): {y} vs {x}");
        }
    }

    let (ok, _, err) = lagrange(&[
        "eval",
        ACTIVATION,
        "--states",
        states.to_str().unwrap(),
        "--derivatives",
        "--kernels-only",
    ]);
    assert!(!ok && err.contains("--derivatives needs the forward pipeline"), "{err}");
    let _ = std::fs::remove_file(&states);
}
