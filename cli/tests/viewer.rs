//! `lagrange view`, `simulate --view`, `simulate --plot` and `view --live` without a browser: the
//! page is self-contained (nothing from the network), carries the model's geoms and meshes once
//! and the poses per frame (equal to lagrange's own forward kinematics to f32 rounding), the
//! trajectory path recomputes the same contacts as the simulation, go1's 10 s page stays small,
//! the plot is written, and the live server streams frames over server-sent events and exits.
//! The same pages in a real browser: `viewer_browser.rs`.

#[path = "../../tests/common/mod.rs"]
mod common;
mod run;

use base64::Engine as _;
use common::VIEW_F32_REL;
use lagrange::io::{load, LoadOptions};
use run::{lagrange, root};
use serde_json::Value;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::PathBuf;

fn temp(name: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-viewer-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The JSON in `<script id="ID" type="application/json">` of a page.
fn script_json(page: &str, id: &str) -> Value {
    let open = format!("<script id=\"{id}\" type=\"application/json\">");
    let start = page.find(&open).unwrap_or_else(|| panic!("no {id}")) + open.len();
    let end = start + page[start..].find("</script>").unwrap();
    serde_json::from_str(&page[start..end]).unwrap()
}

fn f32s(b64: &Value) -> Vec<f32> {
    let bytes = base64::engine::general_purpose::STANDARD.decode(b64.as_str().unwrap()).unwrap();
    bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// Whether the page loads anything from outside itself: an external script, style sheet, image,
/// font or frame, a fetch, an import, a CSS url().
fn external_references(page: &str) -> Vec<String> {
    let lower = page.to_ascii_lowercase();
    let patterns = [
        "src=\"http",
        "src='http",
        "src=http",
        "href=\"http",
        "href='http",
        "href=http",
        "url(http",
        "url(\"http",
        "url('http",
        "fetch(\"http",
        "fetch('http",
        "fetch(`http",
        "import(\"http",
        "from\"http",
        "from \"http",
        "from 'http",
        "<script src",
        "<link rel=\"stylesheet",
        "@import",
    ];
    patterns.iter().filter(|p| lower.contains(*p)).map(|p| p.to_string()).collect()
}

#[test]
fn view_writes_a_self_contained_page_of_the_model_at_a_keyframe() {
    let out = temp("go1.html");
    let (ok, stdout, err) = lagrange(&[
        "view",
        "models/mjcf/unitree_go1/scene.xml",
        "--keyframe",
        "home",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(stdout.contains("viewer written to") && stdout.contains("1 frame"), "{stdout}");
    let page = std::fs::read_to_string(&out).unwrap();
    assert_eq!(external_references(&page), Vec::<String>::new());
    assert!(page.contains("var THREE="), "three.js is inlined");
    let scene = script_json(&page, "lagrange-scene");
    let frames = script_json(&page, "lagrange-frames");
    let model = load(&root().join("models/mjcf/unitree_go1/scene.xml"), &LoadOptions::default()).unwrap();
    // Every geom is in the scene (go1 has no height field); meshes once each.
    let geoms = scene["geoms"].as_array().unwrap();
    assert_eq!(geoms.len(), model.geoms.len());
    let mesh_files: std::collections::BTreeSet<_> =
        model.geoms.iter().filter_map(|g| g.mesh.as_ref().map(|m| m.source().to_string())).collect();
    assert_eq!(scene["meshes"].as_array().unwrap().len(), mesh_files.len());
    // The one frame's poses are the keyframe's forward kinematics.
    assert_eq!(frames["n"], 1);
    let poses = f32s(&frames["poses"]);
    let nslot = scene["nslot"].as_u64().unwrap() as usize;
    assert_eq!(poses.len(), 7 * nslot);
    let mut data = lagrange::Data::new(&model);
    lagrange::model::reset::reset_keyframe(&model, &mut data, "home").unwrap();
    lagrange::forward::forward(&model, &mut data);
    let mut worst = 0.0f64;
    for (b, x) in data.x_world_body.iter().enumerate() {
        let p = &poses[7 * b..7 * b + 7];
        let q = x.quat_wxyz();
        for (a, e) in p.iter().zip([x.pos.x, x.pos.y, x.pos.z, q[1], q[2], q[3], q[0]]) {
            worst = worst.max((f64::from(*a) - e).abs() / e.abs().max(1.0));
        }
    }
    assert!(worst <= VIEW_F32_REL, "poses differ from forward kinematics by {worst:.3e}");
    // Joint values of the frame: the keyframe's qpos.
    let qpos = f32s(&frames["qpos"]);
    for (a, e) in qpos.iter().zip(data.qpos.iter()) {
        assert!((f64::from(*a) - e).abs() <= VIEW_F32_REL * e.abs().max(1.0));
    }
}

#[test]
fn meshes_are_written_once_with_their_vertices_and_triangles() {
    let out = temp("panda.html");
    let (ok, _, err) =
        lagrange(&["view", "models/mjcf/franka_emika_panda/scene.xml", "--out", out.to_str().unwrap()]);
    assert!(ok, "{err}");
    let scene = script_json(&std::fs::read_to_string(&out).unwrap(), "lagrange-scene");
    let model =
        load(&root().join("models/mjcf/franka_emika_panda/scene.xml"), &LoadOptions::default()).unwrap();
    let meshes = scene["meshes"].as_array().unwrap();
    let geoms = scene["geoms"].as_array().unwrap();
    let mut checked = std::collections::BTreeSet::new();
    for (g, v) in model.geoms.iter().zip(geoms) {
        let Some(m) = &g.mesh else { continue };
        let id = v["mesh"].as_u64().unwrap() as usize;
        let t = m.triangles().unwrap();
        let vertices = f32s(&meshes[id]["vertices"]);
        assert_eq!(vertices.len(), 3 * t.vertices.len());
        for (a, e) in vertices.chunks(3).zip(&t.vertices) {
            for k in 0..3 {
                assert!((f64::from(a[k]) - e[k]).abs() <= VIEW_F32_REL * e[k].abs().max(0.01));
            }
        }
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(meshes[id]["indices"].as_str().unwrap())
            .unwrap();
        assert_eq!(bytes.len(), 4 * 3 * t.triangles.len());
        checked.insert(id);
    }
    // Each file once: 11 collision meshes and the finger's visual mesh.
    assert_eq!(checked.len(), meshes.len());
    assert!(meshes.len() >= 10, "{} meshes", meshes.len());
}

#[test]
fn simulate_view_and_view_trajectory_give_the_same_frames_and_contacts() {
    let (csv, page_sim, page_traj, plot) =
        (temp("drop.csv"), temp("drop-sim.html"), temp("drop-traj.html"), temp("drop.svg"));
    let (ok, stdout, err) = lagrange(&[
        "simulate",
        "models/textbook/drop.xml",
        "--duration",
        "1.5",
        "--out",
        csv.to_str().unwrap(),
        "--view",
        page_sim.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(stdout.contains("viewer written to") && stdout.contains("plot written to"), "{stdout}");
    let (ok, _, err) = lagrange(&[
        "view",
        "models/textbook/drop.xml",
        "--trajectory",
        csv.to_str().unwrap(),
        "--out",
        page_traj.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let a = script_json(&std::fs::read_to_string(&page_sim).unwrap(), "lagrange-frames");
    let b = script_json(&std::fs::read_to_string(&page_traj).unwrap(), "lagrange-frames");
    // 1.5 s at 60 frames per second: frames 0..=90, at the steps nearest to n/60 s.
    assert_eq!(a["n"], 91);
    assert_eq!(a["time"], b["time"]);
    let t = a["time"].as_array().unwrap();
    for (n, t) in t.iter().enumerate() {
        assert!((t.as_f64().unwrap() - n as f64 / 60.0).abs() <= 0.0005 + 1e-12, "frame {n} at {t}");
    }
    // The CSV keeps every number to round trip: the recomputed states are the simulation's.
    for key in ["poses", "qpos", "contacts", "contact_start"] {
        assert_eq!(a[key], b[key], "{key}");
    }
    // No contact in the air at t = 0; the landed box and ball rest on the floor at the end,
    // their contact forces carrying the 2 kg of the two bodies.
    let start: Vec<usize> =
        a["contact_start"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as usize).collect();
    assert_eq!(start[1] - start[0], 0);
    let contacts = f32s(&a["contacts"]);
    let last = &contacts[6 * start[90]..6 * start[91]];
    assert!(last.len() >= 12, "{} contacts at the end", last.len() / 6);
    let fz: f64 = last.chunks(6).map(|c| f64::from(c[5])).sum();
    assert!((fz - 2.0 * 9.81).abs() < 0.01 * 2.0 * 9.81, "vertical contact force {fz} N, weight 19.62 N");
    // The plot has its four panels.
    let svg = std::fs::read_to_string(&plot).unwrap();
    for label in ["joint position", "energy (J)", "max |φ|", "touching contacts", "ball z", "box z"] {
        assert!(svg.contains(label), "the plot lacks {label}");
    }
}

#[test]
fn a_ten_second_go1_page_at_60_fps_stays_well_under_20_mb() {
    let page = temp("go1-10s.html");
    let (ok, stdout, err) = lagrange(&[
        "simulate",
        "models/mjcf/unitree_go1/scene.xml",
        "--keyframe",
        "home",
        "--duration",
        "10",
        "--view",
        page.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let bytes = std::fs::metadata(&page).unwrap().len();
    let frames = script_json(&std::fs::read_to_string(&page).unwrap(), "lagrange-frames");
    assert_eq!(frames["n"], 601, "{stdout}");
    println!("go1, 10 s at 60 fps: {:.2} MB", bytes as f64 / 1e6);
    assert!(bytes < 5_000_000, "{bytes} bytes");
}

#[test]
fn view_refuses_another_models_trajectory_and_a_bad_fps() {
    let csv = temp("pendulum.csv");
    let (ok, _, err) = lagrange(&[
        "simulate",
        "models/textbook/double_pendulum.xml",
        "--duration",
        "0.01",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, _, err) = lagrange(&[
        "view",
        "models/textbook/drop.xml",
        "--trajectory",
        csv.to_str().unwrap(),
        "--out",
        temp("x.html").to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(err.contains("the model has nq = 14"), "{err}");
    let (ok, _, err) =
        lagrange(&["simulate", "models/textbook/drop.xml", "--view", "x.html", "--view-fps", "0"]);
    assert!(!ok);
    assert!(err.contains("--view-fps 0"), "{err}");
    let (ok, _, err) = lagrange(&["simulate", "models/textbook/drop.xml", "--plot", "x.pdf"]);
    assert!(!ok);
    assert!(err.contains(".svg or .png"), "{err}");
    // A trajectory with a NaN (an edited file) is refused, never drawn.
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut fields: Vec<String> = lines[2].split(',').map(str::to_string).collect();
    fields[1] = "NaN".into();
    lines[2] = fields.join(",");
    let edited = temp("pendulum-nan.csv");
    std::fs::write(&edited, lines.join("\n") + "\n").unwrap();
    let page = temp("pendulum-nan.html");
    let (ok, _, err) = lagrange(&[
        "view",
        "models/textbook/double_pendulum.xml",
        "--trajectory",
        edited.to_str().unwrap(),
        "--out",
        page.to_str().unwrap(),
    ]);
    assert!(!ok, "a NaN state was drawn");
    assert!(err.contains("row 3, column 2") && err.contains("not a finite number"), "{err}");
    assert!(!page.exists());
}

/// GET `path` from the live server; the raw response.
fn get(addr: &str, path: &str, until: impl Fn(&str) -> bool) -> String {
    let mut s = std::net::TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(std::time::Duration::from_secs(20))).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut out = Vec::new();
    let mut buf = [0u8; 65536];
    loop {
        match s.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => out.extend_from_slice(&buf[..n]),
        }
        if until(&String::from_utf8_lossy(&out)) {
            break;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[test]
fn live_mode_serves_the_page_and_streams_frames_then_exits() {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_lagrange"))
        .args(["view", "models/textbook/drop.xml", "--live", "--port", "0", "--duration", "1.5"])
        .current_dir(root())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    stdout.read_line(&mut line).unwrap();
    let url = line.split_whitespace().find(|w| w.starts_with("http://127.0.0.1:")).expect(&line).to_string();
    let addr = url.trim_start_matches("http://").trim_end_matches('/').to_string();
    let page = get(&addr, "/", |_| false);
    assert!(page.starts_with("HTTP/1.1 200 OK"), "{}", &page[..page.len().min(200)]);
    assert!(page.contains("\"live\":true"));
    assert_eq!(external_references(&page), Vec::<String>::new());
    assert!(get(&addr, "/nothing", |_| false).starts_with("HTTP/1.1 404"));
    let events = get(&addr, "/events", |s| s.contains("event: end"));
    let n = events.matches("event: frame").count();
    // 1.5 s at 60 frames per second: the page holds frame 0, the stream the 90 after it, each a
    // JSON object with its poses.
    assert_eq!(script_json(&page, "lagrange-frames")["n"], 1);
    assert_eq!(n, 90, "{} frames streamed", n);
    let first = events.split("data: ").nth(1).unwrap().lines().next().unwrap();
    let frame: Value = serde_json::from_str(first).unwrap();
    assert_eq!(frame["poses"].as_array().unwrap().len(), 7 * 3);
    let status = child.wait().unwrap();
    let mut rest = String::new();
    stdout.read_to_string(&mut rest).unwrap();
    assert!(status.success(), "{rest}");
    assert!(rest.contains("the live run ended at t = 1.500 s"), "{rest}");
}

#[cfg(unix)]
#[test]
fn live_mode_without_duration_ends_cleanly_on_ctrl_c() {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_lagrange"))
        .args(["view", "models/textbook/drop.xml", "--live", "--port", "0"])
        .current_dir(root())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    stdout.read_line(&mut line).unwrap();
    assert!(line.contains("until Ctrl-C"), "{line}");
    std::thread::sleep(std::time::Duration::from_millis(500));
    // SIGINT, as Ctrl-C in a terminal sends it (to this child only, by its id).
    let pid = i32::try_from(child.id()).unwrap();
    assert_eq!(unsafe { libc::kill(pid, libc::SIGINT) }, 0);
    let status = child.wait().unwrap();
    let mut rest = String::new();
    stdout.read_to_string(&mut rest).unwrap();
    assert!(status.success(), "{status:?}: {rest}");
    assert!(rest.contains("the live run interrupted at t = "), "{rest}");
}
