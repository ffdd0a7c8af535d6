//! The contact-rich scenes of the stability tests, as MJCF text (validation/bench_contact_rich.py's
//! scenes, deterministic).

/// Euler, 2 ms, Newton, pyramidal cones (MuJoCo's defaults, written out).
pub const OPTION: &str = "<option timestep='0.002' integrator='Euler' solver='Newton' cone='pyramidal'/>";

/// n unit boxes of 0.1 m stacked on a floor, 0.1 mm apart (validation/bench_contact_rich.py's stack).
pub fn stack(n: usize) -> String {
    let bodies: String = (0..n)
        .map(|k| {
            format!(
                "<body pos='0 0 {:.6}'><freejoint/><geom type='box' size='0.05 0.05 0.05' mass='1'/></body>",
                0.05 + 0.1 * k as f64 + 1e-4 * k as f64
            )
        })
        .collect();
    format!("<mujoco>{OPTION}<worldbody><geom type='plane' size='0 0 1'/>{bodies}</worldbody></mujoco>")
}

/// A box of 1 kg under a box of `ratio` kg on a floor (validation/bench_contact_rich.py's scene).
pub fn mass_ratio(ratio: f64) -> String {
    format!(
        "<mujoco>{OPTION}<worldbody><geom type='plane' size='0 0 1'/>\
         <body pos='0 0 0.05'><freejoint/><geom type='box' size='0.05 0.05 0.05' mass='1'/></body>\
         <body pos='0 0 0.1501'><freejoint/><geom type='box' size='0.1 0.1 0.05' mass='{ratio}'/></body>\
         </worldbody></mujoco>"
    )
}

/// `n` primitives (spheres, capsules, boxes) dropped into a walled bin from a grid, a pile about
/// three deep (validation/bench_contact_rich.py's bin; `jitter` moves each body by a few mm off the
/// grid, a fixed pattern instead of that script's random one).
pub fn bin(n: usize, jitter: bool) -> String {
    let side = ((n as f64 / 3.0).sqrt().ceil() as usize).max(2);
    let half = 0.06 * side as f64;
    let walls: String = [
        (half + 0.01, 0.0, 0.01, half),
        (-half - 0.01, 0.0, 0.01, half),
        (0.0, half + 0.01, half, 0.01),
        (0.0, -half - 0.01, half, 0.01),
    ]
    .iter()
    .map(|(x, y, sx, sy)| format!("<geom type='box' pos='{x} {y} 0.3' size='{sx} {sy} 0.3'/>"))
    .collect();
    let geoms = [
        "<geom type='sphere' size='0.04'/>",
        "<geom type='capsule' size='0.025 0.03'/>",
        "<geom type='box' size='0.035 0.035 0.035'/>",
    ];
    let bodies: String = (0..n)
        .map(|k| {
            let (i, j, layer) = (k % side, (k / side) % side, k / (side * side));
            let (dx, dy) =
                if jitter { (0.003 * (k % 4) as f64, -0.002 * (k % 3) as f64) } else { (0.0, 0.0) };
            let x = -half + 0.06 + 0.12 * i as f64 + dx;
            let y = -half + 0.06 + 0.12 * j as f64 + dy;
            let z = 0.06 + 0.12 * layer as f64;
            format!("<body pos='{x} {y} {z}' euler='{} 0 0'><freejoint/>{}</body>", 17 * k, geoms[k % 3])
        })
        .collect();
    format!(
        "<mujoco>{OPTION}<worldbody><geom type='plane' size='0 0 1'/>{walls}{bodies}</worldbody></mujoco>"
    )
}
