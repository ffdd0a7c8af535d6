//! The viewer's page: one self-contained HTML document with three.js (the bundle vendored in
//! `cli/assets/three/`, see its README), the viewer script and style (`cli/assets/viewer.*`) and
//! the scene and frames as JSON, all inline: opening it needs no network.

use serde_json::{json, Value};

/// three.js (npm `three`, bundled with OrbitControls into one script defining `THREE`; MIT).
pub const THREE_JS: &str = include_str!("../../../assets/three/three.bundle.min.js");
/// The viewer's own script.
pub const VIEWER_JS: &str = include_str!("../../../assets/viewer.js");
/// The viewer's style sheet.
pub const VIEWER_CSS: &str = include_str!("../../../assets/viewer.css");

/// JSON that can sit inside a `<script>` element: `</` and `<!--` cannot end or comment it.
fn script_json(v: &Value) -> String {
    v.to_string().replace("</", "<\\/").replace("<!--", "<\\u0021--")
}

/// Text escaped for HTML element content.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// The page for `scene` (from [`super::scene::scene_json`]) and `frames`
/// ([`super::scene::Frames::to_json`]); `live`: the page reads more frames from its server's
/// `events` stream.
pub fn page(scene: &Value, frames: &Value, live: bool) -> String {
    let title = scene["model"].as_str().unwrap_or("model");
    let config = json!({ "live": live });
    format!(
        r#"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="lagrange {version}">
<link rel="icon" href="data:,">
<title>{title} — lagrange viewer</title>
<style>
{css}
</style>
</head>
<body>
<div id="view"></div>
<div id="controls">
<button id="play" type="button" aria-label="Play">Play</button>
<input id="time-slider" type="range" min="0" max="0" step="1" value="0" aria-label="Time">
<label>speed <select id="speed" aria-label="Speed">
<option value="0.1">0.1×</option><option value="0.25">0.25×</option><option value="0.5">0.5×</option>
<option value="1" selected>1×</option><option value="2">2×</option><option value="4">4×</option>
</select></label>
<span id="time"></span>
</div>
<div id="panel">
<h1 id="title"></h1>
<div id="source"></div>
<div id="status"></div>
<h2>Show</h2>
<label><input id="show-contacts" type="checkbox" checked> contact points and forces</label>
<label><input id="show-frames" type="checkbox"> link frames</label>
<label><input id="show-sites" type="checkbox"> sites</label>
<label><input id="show-hidden" type="checkbox"> hidden geoms (collision, groups 3–5)</label>
<label><input id="show-floor" type="checkbox" checked> floor</label>
<h2>Joints (qpos)</h2>
<table id="joints"></table>
</div>
<script id="lagrange-scene" type="application/json">{scene_json}</script>
<script id="lagrange-frames" type="application/json">{frames_json}</script>
<script id="lagrange-config" type="application/json">{config_json}</script>
<script>
{three}
</script>
<script>
{viewer}
</script>
</body>
</html>
"#,
        version = env!("CARGO_PKG_VERSION"),
        title = escape(title),
        css = VIEWER_CSS,
        scene_json = script_json(scene),
        frames_json = script_json(frames),
        config_json = script_json(&config),
        three = THREE_JS,
        viewer = VIEWER_JS,
    )
}
