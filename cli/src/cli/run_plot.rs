//! The figure of `lagrange simulate --plot FILE.svg|FILE.png` (plotters, as the work-precision
//! plot): four panels over simulated time — the joint positions (each hinge and slide joint, and
//! the height of each free joint's body), the total energy, the position constraint violation
//! (max |φ|, penetration included) and the number of touching contacts (normal rows of the step's
//! constraint solve). At most about [`MAX_POINTS`] samples per line. Written by
//! [`plot_file`](super::plot_file) (embedded font, SVG or PNG).

use super::plot_file::{self, Figure};
use super::CliError;
use lagrange::model::JointKind;
use lagrange::Model;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Samples kept per line (every k-th step of a longer run).
pub const MAX_POINTS: u64 = 4000;

pub use plot_file::check_path;

/// The sampled time series of a run.
pub struct Series {
    every: u64,
    /// (joint name, qpos index) of each plotted coordinate.
    coords: Vec<(String, usize)>,
    time: Vec<f64>,
    /// One line per coordinate.
    q: Vec<Vec<f64>>,
    energy: Vec<f64>,
    violation: Vec<f64>,
    contacts: Vec<f64>,
}

impl Series {
    /// Empty series for a run of `steps` steps of `model`.
    pub fn new(model: &Model, steps: u64) -> Self {
        let mut coords = Vec::new();
        for j in &model.joints {
            match j.kind {
                JointKind::Free => coords.push((format!("{} z", j.name), j.qpos_adr + 2)),
                _ if j.kind.nq() == 1 => coords.push((j.name.clone(), j.qpos_adr)),
                _ => {}
            }
        }
        let n = coords.len();
        Self {
            every: steps.div_ceil(MAX_POINTS).max(1),
            coords,
            time: Vec::new(),
            q: vec![Vec::new(); n],
            energy: Vec::new(),
            violation: Vec::new(),
            contacts: Vec::new(),
        }
    }

    /// Keeps the state after step `k` if it is a sampled one.
    pub fn push(&mut self, k: u64, time: f64, qpos: &[f64], energy: f64, violation: f64, contacts: usize) {
        if !k.is_multiple_of(self.every) {
            return;
        }
        self.time.push(time);
        for ((_, i), line) in self.coords.iter().zip(self.q.iter_mut()) {
            line.push(qpos[*i]);
        }
        self.energy.push(energy);
        self.violation.push(violation);
        self.contacts.push(contacts as f64);
    }
}

/// Lines in a colour-blind-friendly order (Tableau 10).
const PALETTE: [(u8, u8, u8); 10] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];

/// The padded range of the finite values of `lines` (a unit around a constant).
fn range<'a>(lines: impl Iterator<Item = &'a Vec<f64>>) -> (f64, f64) {
    let (lo, hi) = lines
        .flatten()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.5 * lo.abs().max(1e-9) };
    (lo - pad, hi + pad)
}

/// An axis label: plain below 1e4 and above 1e-3 (to 4 significant digits), else scientific.
fn label(y: f64) -> String {
    if y == 0.0 || (1e-3..1e4).contains(&y.abs()) {
        let text = format!("{y:.4}");
        let text = text.trim_end_matches('0').trim_end_matches('.');
        if text == "-0" {
            "0".into()
        } else {
            text.into()
        }
    } else {
        format!("{y:.2e}")
    }
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    time: &[f64],
    y_desc: &str,
    lines: &[(&str, &Vec<f64>)],
    legend: bool,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let t1 = time.last().copied().unwrap_or(1.0).max(time.first().copied().unwrap_or(0.0) + 1e-9);
    let t0 = time.first().copied().unwrap_or(0.0);
    let (y0, y1) = range(lines.iter().map(|(_, v)| *v));
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(t0..t1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc(y_desc)
        .y_label_formatter(&|y| label(*y))
        .label_style(("sans-serif", 12))
        .draw()
        .map_err(err)?;
    for (i, (name, values)) in lines.iter().enumerate() {
        let (r, g, b) = PALETTE[i % PALETTE.len()];
        let style = RGBColor(r, g, b).stroke_width(2);
        let points = time.iter().copied().zip(values.iter().copied()).filter(|(_, y)| y.is_finite());
        let anno = chart.draw_series(LineSeries::new(points, style)).map_err(err)?;
        if legend {
            anno.label(*name).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
        }
    }
    if legend && !lines.is_empty() {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(("sans-serif", 11))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, title: &str, s: &Series) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let root = root.titled(title, ("sans-serif", 18)).map_err(|e| e.to_string())?;
    let areas = root.split_evenly((4, 1));
    // Legends name at most 12 joints (more lines are drawn, unnamed).
    let joints: Vec<(&str, &Vec<f64>)> = s.coords.iter().map(|(n, _)| n.as_str()).zip(s.q.iter()).collect();
    panel(&areas[0], &s.time, "joint position (rad, m)", &joints, joints.len() <= 12)?;
    panel(&areas[1], &s.time, "energy (J)", &[("energy", &s.energy)], false)?;
    panel(&areas[2], &s.time, "max |φ| (m, rad)", &[("violation", &s.violation)], false)?;
    panel(&areas[3], &s.time, "touching contacts", &[("contacts", &s.contacts)], false)?;
    root.present().map_err(|e| e.to_string())
}

/// The figure: a title and the four panels of a run.
struct RunFigure<'a> {
    title: String,
    series: &'a Series,
}

impl Figure for RunFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        draw(root, &self.title, self.series)
    }
}

/// Draws the figure of `series` into `path` (.svg or .png), replacing it only when complete
/// ([`plot_file::write`]: embedded font).
pub fn plot(path: &Path, model: &Model, series: &Series) -> Result<(), CliError> {
    let title = format!("lagrange simulate {}", model.name);
    plot_file::write(path, (960, 1200), &title, &RunFigure { title: title.clone(), series })
}
