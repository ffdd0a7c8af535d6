//! The viewer's pages in a real browser: Debian's `chromium`, headless, driven by `chromedriver`
//! over its HTTP WebDriver API (std + serde_json). For go1, a URDF arm (models/panda), the drop scene and a
//! mesh gripper (the Franka hand of models/mjcf/franka_emika_panda): the page loads with no console
//! error and nothing fetched from outside the page; the model's pixels (screenshot) lie in the box
//! its geoms project to; two frames of the falling box differ where the box moved; the slider and
//! the play button change the frame; contact arrows appear once the box lands (orange pixels at the
//! contact); the live mode streams frames into the page.
//!
//! The tests need a browser, so they are `#[ignore]`d in `cargo test`; `.ci/run` installs
//! chromium and chromium-driver and runs them with `--include-ignored`. Without chromium each says
//! "skipped: chromium not found" and passes. `LAGRANGE_CHROMIUM`, `LAGRANGE_CHROMEDRIVER` name other
//! binaries. Screenshots go to target/viewer-browser/.

#[path = "../../tests/common/mod.rs"]
mod common;
mod run;

use common::VIEW_BOX_MARGIN_PX;
use run::{lagrange, root};
use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The first of `names` found on PATH (or the environment variable's value).
fn find(env: &str, names: &[&str]) -> Option<PathBuf> {
    if let Ok(p) = std::env::var(env) {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    for dir in std::env::split_paths(&path) {
        for n in names {
            let p = dir.join(n);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    None
}

/// A chromedriver process and one headless chromium session.
struct Browser {
    driver: Child,
    port: u16,
    session: String,
}

impl Browser {
    /// Starts chromedriver and a session, or None (printing why) when chromium is absent.
    fn start() -> Option<Browser> {
        let chromium = find("LAGRANGE_CHROMIUM", &["chromium", "chromium-browser", "google-chrome"]);
        let driver = find("LAGRANGE_CHROMEDRIVER", &["chromedriver"]);
        let (Some(chromium), Some(driver)) = (chromium, driver) else {
            println!("skipped: chromium not found (install chromium and chromium-driver)");
            return None;
        };
        let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
        let child = Command::new(driver)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("chromedriver starts");
        let mut b = Browser { driver: child, port, session: String::new() };
        let t0 = Instant::now();
        while http(port, "GET", "/status", None).is_err() {
            assert!(t0.elapsed() < Duration::from_secs(20), "chromedriver did not answer");
            std::thread::sleep(Duration::from_millis(100));
        }
        let caps = json!({"capabilities": {"alwaysMatch": {
            "goog:chromeOptions": {
                "binary": chromium,
                // Software WebGL (SwiftShader); the network goes nowhere: anything the page tried
                // to load from outside would fail and show in the console and resource list
                // (127.0.0.1, the live server, bypasses the proxy).
                "args": ["--headless=new", "--no-sandbox", "--enable-unsafe-swiftshader", "--use-angle=swiftshader",
                         "--window-size=1200,800", "--force-device-scale-factor=1",
                         "--proxy-server=127.0.0.1:9"]
            },
            "goog:loggingPrefs": {"browser": "ALL"}
        }}});
        let v = http(port, "POST", "/session", Some(&caps)).expect("a session");
        b.session = v["value"]["sessionId"].as_str().expect("a session id").to_string();
        Some(b)
    }

    fn cmd(&self, method: &str, path: &str, body: Option<&Value>) -> Value {
        let v = http(self.port, method, &format!("/session/{}{path}", self.session), body).unwrap();
        assert!(v["value"].get("error").is_none(), "{method} {path}: {v}");
        v["value"].clone()
    }

    fn open(&self, url: &str) {
        self.cmd("POST", "/url", Some(&json!({ "url": url })));
        self.wait("return !!(window.lagrangeViewer && window.lagrangeViewer.ready)", 30);
    }

    fn js(&self, script: &str) -> Value {
        self.cmd("POST", "/execute/sync", Some(&json!({"script": script, "args": []})))
    }

    /// Waits until `script` returns true.
    fn wait(&self, script: &str, seconds: u64) {
        let t0 = Instant::now();
        while self.js(script) != json!(true) {
            assert!(t0.elapsed() < Duration::from_secs(seconds), "timed out waiting for: {script}");
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// Lets the page render what changed (two animation frames).
    fn settle(&self) {
        let r = self.js("return window.lagrangeViewer.renders").as_u64().unwrap();
        std::thread::sleep(Duration::from_millis(150));
        let _ = r;
        self.js("return new Promise(r => requestAnimationFrame(() => requestAnimationFrame(() => r(true))))");
    }

    /// The page's console messages of level SEVERE, and the others (printed).
    fn console_errors(&self) -> Vec<String> {
        let log = self.cmd("POST", "/se/log", Some(&json!({"type": "browser"})));
        let mut errors = Vec::new();
        for e in log.as_array().unwrap() {
            let text = format!("{}: {}", e["level"], e["message"]);
            if e["level"] == "SEVERE" {
                errors.push(text);
            } else {
                println!("console {text}");
            }
        }
        let own = self.js("return window.lagrangeViewer.errors");
        errors.extend(own.as_array().unwrap().iter().map(|e| format!("page error: {e}")));
        errors
    }

    /// The resources the page loaded other than itself and data:/blob: URLs.
    fn external_resources(&self, allowed_prefix: &str) -> Vec<String> {
        let list = self.js("return performance.getEntriesByType('resource').map(e => e.name)");
        list.as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .filter(|u| !(u.starts_with("data:") || u.starts_with("blob:") || u.starts_with(allowed_prefix)))
            .collect()
    }

    fn screenshot(&self, save: &str) -> Image {
        let b64 = self.cmd("GET", "/screenshot", None);
        let bytes = decode_b64(b64.as_str().unwrap());
        let dir = root().join("target/viewer-browser");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(save), &bytes).unwrap();
        Image::from_png(&bytes)
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        if !self.session.is_empty() {
            let _ = http(self.port, "DELETE", &format!("/session/{}", self.session), None);
        }
        let _ = self.driver.kill();
        let _ = self.driver.wait();
    }
}

/// One HTTP/1.1 request to 127.0.0.1:`port`; the JSON body of the response.
fn http(port: u16, method: &str, path: &str, body: Option<&Value>) -> std::io::Result<Value> {
    let mut s = TcpStream::connect(("127.0.0.1", port))?;
    s.set_read_timeout(Some(Duration::from_secs(120)))?;
    let body = body.map(|b| b.to_string()).unwrap_or_default();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )?;
    // chromedriver keeps the connection open: the body is read by its Content-Length.
    let mut reader = BufReader::new(s);
    let mut length = None;
    let mut status = String::new();
    reader.read_line(&mut status)?;
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line)? == 0 || line == "\r\n" {
            break;
        }
        let lower = line.to_ascii_lowercase();
        if let Some(v) = lower.strip_prefix("content-length:") {
            length = v.trim().parse::<usize>().ok();
        }
    }
    let mut payload = Vec::new();
    match length {
        Some(n) => {
            payload.resize(n, 0);
            reader.read_exact(&mut payload)?;
        }
        None => {
            reader.read_to_end(&mut payload)?;
        }
    }
    let text = String::from_utf8_lossy(&payload);
    serde_json::from_str(&text).map_err(|e| std::io::Error::other(format!("{e}: {status} {text}")))
}

fn decode_b64(s: &str) -> Vec<u8> {
    use base64::Engine as _;
    base64::engine::general_purpose::STANDARD.decode(s).unwrap()
}

/// An RGB screenshot.
struct Image {
    width: usize,
    height: usize,
    rgb: Vec<[u8; 3]>,
}

impl Image {
    fn from_png(bytes: &[u8]) -> Image {
        let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().expect("a screenshot's size fits in memory")];
        let info = reader.next_frame(&mut buf).unwrap();
        let channels = info.color_type.samples();
        let rgb = buf[..info.buffer_size()].chunks(channels).map(|c| [c[0], c[1], c[2]]).collect();
        Image { width: info.width as usize, height: info.height as usize, rgb }
    }
    fn at(&self, x: usize, y: usize) -> [u8; 3] {
        self.rgb[y * self.width + x]
    }
}

fn close(a: [u8; 3], b: [u8; 3], tol: i32) -> bool {
    a.iter().zip(b).all(|(x, y)| (i32::from(*x) - i32::from(y)).abs() <= tol)
}

/// A rectangle in page pixels.
#[derive(Debug, Clone, Copy)]
struct Rect {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Rect {
    fn of(v: &Value) -> Rect {
        let f = |k: &str| v[k].as_f64().unwrap();
        Rect { x0: f("x0"), y0: f("y0"), x1: f("x1"), y1: f("y1") }
    }
    fn grow(self, m: f64) -> Rect {
        Rect { x0: self.x0 - m, y0: self.y0 - m, x1: self.x1 + m, y1: self.y1 + m }
    }
    fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }
}

/// The canvas's rectangle in page pixels.
fn canvas_rect(b: &Browser) -> Rect {
    let c = b.js("return window.lagrangeViewer.canvas()");
    let f = |k: &str| c[k].as_f64().unwrap();
    Rect { x0: f("x"), y0: f("y"), x1: f("x") + f("width"), y1: f("y") + f("height") }
}

/// The pixels of the canvas that are not the background: their count and bounding rectangle.
fn foreground(img: &Image, canvas: Rect, background: [u8; 3]) -> (usize, Rect) {
    let mut n = 0;
    let mut r = Rect { x0: f64::INFINITY, y0: f64::INFINITY, x1: f64::NEG_INFINITY, y1: f64::NEG_INFINITY };
    for y in canvas.y0 as usize..(canvas.y1 as usize).min(img.height) {
        for x in canvas.x0 as usize..(canvas.x1 as usize).min(img.width) {
            if !close(img.at(x, y), background, 2) {
                n += 1;
                r = Rect {
                    x0: r.x0.min(x as f64),
                    y0: r.y0.min(y as f64),
                    x1: r.x1.max(x as f64 + 1.0),
                    y1: r.y1.max(y as f64 + 1.0),
                };
            }
        }
    }
    (n, r)
}

fn file_url(p: &Path) -> String {
    format!("file://{}", p.display())
}

fn out_dir() -> PathBuf {
    let d = root().join("target/viewer-browser");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Opens a page of a model at rest, checks console and offline, and that the model's pixels (floor
/// hidden) lie in its projected box and fill a good part of it. Returns the screenshot's name.
fn check_model_page(b: &Browser, page: &Path, name: &str) {
    b.open(&file_url(page));
    let errors = b.console_errors();
    assert!(errors.is_empty(), "{name}: console errors {errors:?}");
    assert_eq!(b.external_resources("file:"), Vec::<String>::new(), "{name}");
    // The screenshot with the floor, for the record (docs/img takes go1's).
    b.settle();
    b.screenshot(&format!("{name}.png"));
    b.js("window.lagrangeViewer.setFloor(false)");
    b.settle();
    let img = b.screenshot(&format!("{name}-nofloor.png"));
    let bg = b.js("return window.lagrangeViewer.background()");
    let bg: Vec<u8> = bg.as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as u8).collect();
    let canvas = canvas_rect(b);
    let projected = Rect::of(&b.js("return window.lagrangeViewer.projectedBox()"));
    let (n, drawn) = foreground(&img, canvas, [bg[0], bg[1], bg[2]]);
    println!("{name}: {n} model pixels in {drawn:?}; projected box {projected:?}");
    assert!(n > 2000, "{name}: only {n} pixels differ from the background");
    let allowed = projected.grow(VIEW_BOX_MARGIN_PX);
    assert!(
        allowed.contains(drawn.x0, drawn.y0) && allowed.contains(drawn.x1, drawn.y1),
        "{name}: pixels drawn in {drawn:?}, outside the projected box {projected:?}"
    );
    // A box projects wider than the shape inside it, but the drawn pixels reach across most of it.
    let (pw, ph) = (projected.x1 - projected.x0, projected.y1 - projected.y0);
    assert!(
        drawn.x1 - drawn.x0 > 0.5 * pw && drawn.y1 - drawn.y0 > 0.5 * ph,
        "{name}: {drawn:?} in {projected:?}"
    );
}

#[test]
#[ignore = "needs chromium and chromedriver (.ci/run installs them)"]
fn go1_urdf_arm_and_mesh_gripper_pages_show_the_model_where_it_projects() {
    let Some(b) = Browser::start() else { return };
    let dir = out_dir();
    for (name, args) in [
        ("go1", vec!["models/mjcf/unitree_go1/scene.xml", "--keyframe", "home"]),
        ("panda-urdf", vec!["models/panda/panda.urdf"]),
        ("panda", vec!["models/mjcf/franka_emika_panda/scene.xml", "--keyframe", "home"]),
    ] {
        let page = dir.join(format!("{name}.html"));
        let mut all = vec!["view"];
        all.extend(args);
        all.extend(["--out", page.to_str().unwrap()]);
        let (ok, _, err) = lagrange(&all);
        assert!(ok, "{name}: {err}");
        check_model_page(&b, &page, name);
    }
    // The gripper's page holds its meshes: the hand and the fingers are triangle meshes.
    let meshes =
        b.js("return JSON.parse(document.getElementById('lagrange-scene').textContent).meshes.length");
    assert!(meshes.as_u64().unwrap() >= 10, "{meshes}");
}

#[test]
#[ignore = "needs chromium and chromedriver (.ci/run installs them)"]
fn drop_trajectory_frames_slider_play_and_contact_arrows() {
    let Some(b) = Browser::start() else { return };
    let page = out_dir().join("drop.html");
    let (ok, _, err) = lagrange(&[
        "simulate",
        "models/textbook/drop.xml",
        "--duration",
        "1.5",
        "--view",
        page.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    b.open(&file_url(&page));
    assert_eq!(b.console_errors(), Vec::<String>::new());
    assert_eq!(b.external_resources("file:"), Vec::<String>::new());
    assert_eq!(b.js("return window.lagrangeViewer.nframes"), json!(91));
    // Two frames of the fall: the pixels that differ lie where the box and the ball were and went.
    b.js("window.lagrangeViewer.setFloor(false); window.lagrangeViewer.setFrame(0)");
    b.settle();
    let a = b.screenshot("drop-0.png");
    let box_a = Rect::of(&b.js("return window.lagrangeViewer.projectedBox()"));
    b.js("window.lagrangeViewer.setFrame(20)");
    b.settle();
    let c = b.screenshot("drop-20.png");
    let box_c = Rect::of(&b.js("return window.lagrangeViewer.projectedBox()"));
    let canvas = canvas_rect(&b);
    let allowed = Rect {
        x0: box_a.x0.min(box_c.x0),
        y0: box_a.y0.min(box_c.y0),
        x1: box_a.x1.max(box_c.x1),
        y1: box_a.y1.max(box_c.y1),
    }
    .grow(VIEW_BOX_MARGIN_PX);
    let mut changed = 0;
    for y in canvas.y0 as usize..canvas.y1 as usize {
        for x in canvas.x0 as usize..canvas.x1 as usize {
            if !close(a.at(x, y), c.at(x, y), 2) {
                changed += 1;
                assert!(allowed.contains(x as f64, y as f64), "pixel ({x}, {y}) changed outside {allowed:?}");
            }
        }
    }
    println!("frames 0 and 20 differ in {changed} pixels, all within {allowed:?}");
    assert!(changed > 500, "{changed}");
    // The slider: one key press moves one frame.
    b.js("window.lagrangeViewer.setFloor(true); window.lagrangeViewer.setFrame(0)");
    let slider = b.cmd("POST", "/element", Some(&json!({"using": "css selector", "value": "#time-slider"})));
    let id = slider.as_object().unwrap().values().next().unwrap().as_str().unwrap().to_string();
    b.cmd("POST", &format!("/element/{id}/click"), Some(&json!({})));
    b.cmd("POST", &format!("/element/{id}/value"), Some(&json!({"text": "\u{E014}\u{E014}\u{E014}"})));
    let after_click = b.js("return window.lagrangeViewer.frame").as_u64().unwrap();
    assert!(after_click > 3, "the slider's click and three right-arrow keys left frame {after_click}");
    b.cmd("POST", &format!("/element/{id}/value"), Some(&json!({"text": "\u{E012}"})));
    assert_eq!(b.js("return window.lagrangeViewer.frame").as_u64().unwrap(), after_click - 1);
    // The play button (found by its label) advances the frames.
    b.js("window.lagrangeViewer.setFrame(0)");
    let play = b.cmd(
        "POST",
        "/element",
        Some(&json!({"using": "css selector", "value": "button[aria-label='Play']"})),
    );
    let pid = play.as_object().unwrap().values().next().unwrap().as_str().unwrap().to_string();
    b.cmd("POST", &format!("/element/{pid}/click"), Some(&json!({})));
    b.wait("return window.lagrangeViewer.frame >= 10", 20);
    assert_eq!(b.js("return document.getElementById('play').textContent"), json!("Pause"));
    b.cmd("POST", &format!("/element/{pid}/click"), Some(&json!({})));
    assert_eq!(b.js("return window.lagrangeViewer.playing"), json!(false));
    // No contact in the air; arrows once landed, orange pixels at the contact points.
    b.js("window.lagrangeViewer.setFrame(0)");
    b.settle();
    assert_eq!(b.js("return window.lagrangeViewer.arrows"), json!(0));
    let before = b.screenshot("drop-air.png");
    b.js("window.lagrangeViewer.setFrame(90)");
    b.settle();
    let arrows = b.js("return window.lagrangeViewer.arrows").as_u64().unwrap();
    assert!(arrows >= 2, "{arrows} arrows once both bodies rest on the floor");
    let landed = b.screenshot("drop-landed.png");
    let orange = |img: &Image| {
        let mut n = 0;
        for y in canvas.y0 as usize..canvas.y1 as usize {
            for x in canvas.x0 as usize..canvas.x1 as usize {
                let [r, g, bl] = img.at(x, y);
                if r > 200 && (60..=150).contains(&g) && bl < 60 {
                    n += 1;
                }
            }
        }
        n
    };
    let (o0, o1) = (orange(&before), orange(&landed));
    println!("orange arrow pixels: {o0} in the air, {o1} landed");
    assert!(o0 == 0 && o1 > 50, "orange pixels {o0} → {o1}");
    assert_eq!(b.console_errors(), Vec::<String>::new());
}

#[test]
#[ignore = "needs chromium and chromedriver (.ci/run installs them)"]
fn live_mode_streams_frames_into_the_page() {
    let Some(b) = Browser::start() else { return };
    let mut child = Command::new(env!("CARGO_BIN_EXE_lagrange"))
        .args(["view", "models/textbook/drop.xml", "--live", "--port", "0", "--duration", "3"])
        .current_dir(root())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    stdout.read_line(&mut line).unwrap();
    let url = line.split_whitespace().find(|w| w.starts_with("http://127.0.0.1:")).expect(&line).to_string();
    b.open(&url);
    b.wait("return window.lagrangeViewer.ended", 30);
    let received = b.js("return window.lagrangeViewer.received").as_u64().unwrap();
    let frame = b.js("return window.lagrangeViewer.frame").as_u64().unwrap();
    println!("live: {received} frames received, showing frame {frame}");
    // 3 s at 60 frames per second: 181 frames, the first in the page, 180 streamed; the page
    // follows the last.
    assert_eq!(received, 180);
    assert_eq!(b.js("return window.lagrangeViewer.nframes"), json!(181));
    assert_eq!(frame, 180);
    assert!(b.js("return window.lagrangeViewer.arrows").as_u64().unwrap() >= 2);
    assert_eq!(b.console_errors(), Vec::<String>::new());
    let origin = url.trim_end_matches('/');
    assert_eq!(b.external_resources(origin), Vec::<String>::new());
    let status = child.wait().unwrap();
    assert!(status.success());
}
