//! End-to-end tests of `lagrange workprec` (docs/cli.md, "workprec"): the JSON has exactly the
//! documented keys, the errors on the double pendulum fall with the step size at each method's
//! order (RK4 4, semi-implicit Euler 1) and with the adaptive method's tolerance, the plot files
//! are written, saved and extra rows are merged, the reference dump holds the trajectory, and bad
//! input is refused naming the flag. No timing is asserted.

#[path = "../../tests/common/mod.rs"]
mod common;
mod run;

use common::{INTEGRATOR_ORDER_BAND, WORKPREC_SLOPE_TOL};
use run::lagrange;
use serde_json::Value;
use std::path::PathBuf;

const MODEL: &str = "models/textbook/double_pendulum.xml";

fn temp_path(name: &str) -> PathBuf {
    std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-workprec-{}-{name}", std::process::id()))
}

fn keys(v: &Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().expect("an object").keys().cloned().collect();
    k.sort();
    k
}

/// The rows of one integrator as (dt or rtol, error), largest parameter first.
fn series(report: &Value, integrator: &str, param: &str) -> Vec<(f64, f64)> {
    let mut s: Vec<(f64, f64)> = report["rows"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["integrator"] == integrator)
        .map(|r| (r[param].as_f64().unwrap(), r["error"].as_f64().unwrap()))
        .collect();
    s.sort_by(|a, b| b.0.total_cmp(&a.0));
    s
}

/// Least-squares slope of log(error) against log(dt).
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (xs, ys): (Vec<f64>, Vec<f64>) = points.iter().map(|(h, e)| (h.ln(), e.ln())).unzip();
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// Checks the observed order of a fixed-step method: every halving of dt shrinks the error by
/// 2^order within `INTEGRATOR_ORDER_BAND`, and the fitted slope is the order.
fn check_order(report: &Value, integrator: &str, order: i32) {
    let s = series(report, integrator, "dt");
    assert_eq!(s.len(), 4, "{integrator}: {s:?}");
    let expected = 2f64.powi(order);
    for w in s.windows(2) {
        let ratio = w[0].1 / w[1].1;
        println!("{integrator}: dt {} → {}: error ratio {ratio:.2}", w[0].0, w[1].0);
        assert!(
            ratio >= expected / INTEGRATOR_ORDER_BAND && ratio <= expected * INTEGRATOR_ORDER_BAND,
            "{integrator}: error ratio {ratio} per halving (rows {s:?}), expected {expected}"
        );
    }
    let p = slope(&s);
    println!("{integrator}: fitted order {p:.3}");
    assert!((p - f64::from(order)).abs() <= WORKPREC_SLOPE_TOL, "{integrator}: slope {p}, rows {s:?}");
}

#[test]
fn workprec_json_has_the_schema_and_the_orders_of_the_methods() {
    let dump = temp_path("reference.json");
    let (ok, out, err) = lagrange(&[
        "workprec",
        MODEL,
        "--json",
        "--integrators",
        "euler,rk4,adaptive",
        "--dts",
        "8e-3,4e-3,2e-3,1e-3",
        "--rtols",
        "1e-5,1e-7,1e-9",
        "--duration",
        "2",
        "--repeats",
        "1",
        "--dump-reference",
        dump.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}"));
    assert_eq!(keys(&v), ["duration", "model", "reference", "rows"]);
    assert_eq!(v["model"], MODEL);
    assert_eq!(v["duration"], 2.0);
    assert_eq!(v["reference"], serde_json::json!({"integrator": "adaptive", "rtol": 1e-13}));
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4 + 4 + 3);
    for r in rows {
        assert_eq!(
            keys(r),
            ["cpu_s", "dt", "energy_error", "error", "error_l2", "integrator", "rtol", "steps"]
        );
        let adaptive = r["integrator"] == "adaptive";
        assert_eq!(r["dt"].is_null(), adaptive, "{r}");
        assert_eq!(r["rtol"].is_null(), !adaptive, "{r}");
        for key in ["error", "error_l2", "energy_error", "cpu_s"] {
            let x = r[key].as_f64().unwrap_or_else(|| panic!("{key} in {r}"));
            assert!(x.is_finite() && x >= 0.0, "{key} in {r}");
        }
        if !adaptive {
            let dt = r["dt"].as_f64().unwrap();
            assert_eq!(r["steps"].as_u64().unwrap(), (2.0 / dt).round() as u64, "{r}");
        }
    }
    check_order(&v, "rk4", 4);
    check_order(&v, "euler", 1);
    // The adaptive method: the error falls as the tolerance does.
    let adaptive = series(&v, "adaptive", "rtol");
    assert_eq!(adaptive.len(), 3);
    for w in adaptive.windows(2) {
        assert!(w[1].1 < w[0].1, "adaptive errors do not fall with rtol: {adaptive:?}");
    }

    // The reference dump: the run's settings and the trajectory at every coarsest step.
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&dump).unwrap()).unwrap();
    std::fs::remove_file(&dump).ok();
    assert_eq!(r["sample_dt"], 8e-3);
    assert_eq!(r["dts"], serde_json::json!([8e-3, 4e-3, 2e-3, 1e-3]));
    assert_eq!(r["q0"], serde_json::json!([1.0, 0.5]), "keyframe 'swing' is the model's first");
    let samples = &r["samples"];
    assert_eq!(samples["time"].as_array().unwrap().len(), 251);
    assert_eq!(samples["q"].as_array().unwrap().len(), 251);
    assert_eq!(samples["q"][0], r["q0"]);
    assert_eq!(r["joints"][1]["name"], "elbow");
    assert_eq!(r["reference"]["rtol"], 1e-13);
}

#[test]
fn workprec_text_says_how_it_measures() {
    let (ok, out, err) = lagrange(&["workprec", MODEL, "--duration", "0.4", "--repeats", "1"]);
    assert!(ok, "{err}");
    for needle in [
        "reference: adaptive Dormand–Prince 5(4) at rtol 1e-13",
        "keyframe 'swing'",
        "error_l2: RMS over the 50 sample times (every 0.008 s, the coarsest dt)",
        "min of 1 repeats",
        "it takes the same steps as euler",
    ] {
        assert!(out.contains(needle), "missing '{needle}' in {out}");
    }
    // Default step sizes: the model's timestep 0.002 s × 4 … 1/8; default rtols 1e-4 … 1e-10.
    for integrator in ["euler", "rk4", "implicitfast"] {
        assert_eq!(out.lines().filter(|l| l.starts_with(integrator)).count(), 6, "{integrator}: {out}");
    }
    assert_eq!(out.lines().filter(|l| l.starts_with("adaptive ")).count(), 4, "{out}");
}

#[test]
fn workprec_plots_svg_and_png_and_merges_extra_rows() {
    let saved = temp_path("saved.json");
    let svg = temp_path("plot.svg");
    let png = temp_path("plot.png");
    let args = ["workprec", MODEL, "--dts", "8e-3,4e-3", "--rtols", "1e-6", "--duration", "0.8"];
    let (ok, out, err) =
        lagrange(&[&args[..], &["--repeats", "1", "--json", "--plot", svg.to_str().unwrap()]].concat());
    assert!(ok, "{err}");
    std::fs::write(&saved, &out).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("<svg") && text.contains("rk4") && text.contains("CPU time"), "{text}");

    // Rows of another engine, in the same format, overlaid on a saved run.
    let extra = temp_path("extra.json");
    let mut other: Value = serde_json::from_str(&out).unwrap();
    for r in other["rows"].as_array_mut().unwrap() {
        r["integrator"] = Value::from(format!("other-{}", r["integrator"].as_str().unwrap()));
    }
    std::fs::write(&extra, other.to_string()).unwrap();
    let (ok, merged, err) = lagrange(&[
        "workprec",
        "--from-json",
        saved.to_str().unwrap(),
        "--extra-rows",
        extra.to_str().unwrap(),
        "--json",
        "--plot",
        png.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let merged: Value = serde_json::from_str(&merged).unwrap();
    let n = other["rows"].as_array().unwrap().len();
    assert_eq!(merged["rows"].as_array().unwrap().len(), 2 * n);
    assert_eq!(merged["rows"][n]["integrator"], "other-euler");
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.len() > 1000 && bytes.starts_with(b"\x89PNG"), "{} bytes", bytes.len());
    let (ok, table, err) = lagrange(&[
        "workprec",
        "--from-json",
        saved.to_str().unwrap(),
        "--extra-rows",
        extra.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(table.contains("other-rk4") && table.contains("error_l2: RMS"), "{table}");
    for f in [saved, svg, png, extra] {
        std::fs::remove_file(f).ok();
    }
}

#[test]
fn workprec_refuses_bad_input_naming_the_flag() {
    let cases: [(&[&str], &str); 8] = [
        (&["--dts", "-1e-3"], "--dts: -1e-3 is not a positive finite step size"),
        (&["--dts", "1e-2,x"], "--dts: 'x' is not a number"),
        (&["--dts", "1e-2,3e-3"], "--dts: 0.003 does not divide the coarsest step 0.01"),
        (
            &["--integrators", "rk4,leapfrog"],
            "--integrators: unknown integrator 'leapfrog'; known: euler, rk4, implicitfast, implicit, variational, adaptive",
        ),
        (&["--rtols", "0"], "--rtols: 0 is not a positive finite relative tolerance"),
        (&["--duration", "1.001"], "--duration 1.001 is not a whole number of the coarsest step 0.008"),
        (&["--plot", "out.pdf"], "--plot out.pdf: give a file name ending in .svg or .png"),
        (&["--keyframe", "upright"], "--keyframe upright: the model has no such keyframe (it has: swing)"),
    ];
    for (args, message) in cases {
        let (ok, _, err) = lagrange(&[&["workprec", MODEL][..], args].concat());
        assert!(!ok, "{args:?} was accepted");
        assert!(err.contains(message), "{args:?}: expected '{message}' in: {err}");
    }
    let (ok, _, err) = lagrange(&["workprec", MODEL, "--repeats", "0"]);
    assert!(!ok && err.contains("--repeats 0"), "{err}");
    let missing = temp_path("missing.json");
    let (ok, _, err) = lagrange(&["workprec", "--from-json", missing.to_str().unwrap()]);
    assert!(!ok && err.contains("missing.json"), "{err}");
}
