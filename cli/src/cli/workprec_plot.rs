//! The log-log work-precision plot of `lagrange workprec --plot FILE.svg|FILE.png` (plotters):
//! final-time error against CPU seconds, one series per integrator in the order of the rows,
//! points joined along decreasing step size or tolerance, the legend in the lower left (the corner
//! a work-precision plot leaves empty). lagrange's integrators are solid lines
//! with dots; rows of other engines (`--extra-rows`, e.g. `mujoco-rk4`) dashed with triangles.
//! Written by [`plot_file`](super::plot_file) (embedded font, SVG or PNG).

use super::plot_file::{self, Figure};
use super::workprec::Row;
use super::CliError;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Lines of the same family in a colour-blind-friendly order (Tableau 10).
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

pub use plot_file::check_path;

/// One series: the rows of one integrator, in order of decreasing dt or rtol.
struct Series<'a> {
    name: &'a str,
    points: Vec<(f64, f64)>,
    extra: bool,
}

fn series(rows: &[Row]) -> Vec<Series<'_>> {
    let mut out: Vec<(Series, Vec<&Row>)> = Vec::new();
    for r in rows {
        match out.iter_mut().find(|(s, _)| s.name == r.integrator) {
            Some((_, v)) => v.push(r),
            None => out.push((
                Series {
                    name: &r.integrator,
                    points: Vec::new(),
                    extra: !["euler", "rk4", "implicitfast", "implicit", "variational", "adaptive"]
                        .contains(&r.integrator.as_str()),
                },
                vec![r],
            )),
        }
    }
    out.into_iter()
        .map(|(mut s, mut v)| {
            let key = |r: &Row| r.dt.or(r.rtol).unwrap_or(0.0);
            v.sort_by(|a, b| key(b).total_cmp(&key(a)));
            // A log scale shows positive values only (an error of exactly 0 is left out).
            s.points = v
                .iter()
                .filter(|r| r.error > 0.0 && r.cpu_s > 0.0 && r.error.is_finite() && r.cpu_s.is_finite())
                .map(|r| (r.cpu_s, r.error))
                .collect();
            s
        })
        .collect()
}

/// The padded log range of `values` (a decade around a single value).
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
    if !lo.is_finite() {
        return (1e-6, 1.0);
    }
    (lo / 2.0, hi * 2.0)
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, title: &str, rows: &[Row]) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let all = series(rows);
    let (x0, x1) = log_range(all.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let (y0, y1) = log_range(all.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("CPU time of the run (s)")
        .y_desc("final-time error (max-norm: q on the manifold, v)")
        .x_label_formatter(&|x| format!("{x:.0e}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    for (i, s) in all.iter().enumerate() {
        let (r, g, b) = PALETTE[i % PALETTE.len()];
        let color = RGBColor(r, g, b);
        let style = color.stroke_width(2);
        let anno = if s.extra {
            chart.draw_series(DashedLineSeries::new(s.points.iter().copied(), 8, 5, style)).map_err(err)?
        } else {
            chart.draw_series(LineSeries::new(s.points.iter().copied(), style)).map_err(err)?
        };
        anno.label(s.name).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        if s.extra {
            chart
                .draw_series(s.points.iter().map(|&p| TriangleMarker::new(p, 6, color.filled())))
                .map_err(err)?;
        } else {
            chart.draw_series(s.points.iter().map(|&p| Circle::new(p, 4, color.filled()))).map_err(err)?;
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)
}

/// The work-precision figure of a report's rows.
struct WorkPrecision<'a> {
    title: &'a str,
    rows: &'a [Row],
}

impl Figure for WorkPrecision<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        draw(root, self.title, self.rows)
    }
}

/// Draws the work-precision plot of `rows` into `path` (.svg or .png).
pub fn plot(path: &Path, title: &str, rows: &[Row]) -> Result<(), CliError> {
    plot_file::write(path, (960, 640), &format!("lagrange workprec: {title}"), &WorkPrecision { title, rows })
}
