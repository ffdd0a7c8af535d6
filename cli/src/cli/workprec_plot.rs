//! The log-log work-precision plot of `lagrange workprec --plot FILE.svg|FILE.png` (plotters):
//! final-time error against CPU seconds, one series per integrator in the order of the rows,
//! points joined along decreasing step size or tolerance, the legend in the lower left (the corner
//! a work-precision plot leaves empty). lagrange's integrators are solid lines
//! with dots; rows of other engines (`--extra-rows`, e.g. `mujoco-rk4`) dashed with triangles.
//! Text is laid out with a TrueType font found on the system (`LAGRANGE_FONT`, else common
//! locations), for SVG and PNG alike.

use super::output_file::OutputFile;
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

/// Where a TrueType font is looked for when `LAGRANGE_FONT` is not set.
const FONT_CANDIDATES: [&str; 8] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
    "/Library/Fonts/Arial.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

enum Format {
    Svg,
    Png,
}

fn format_of(path: &Path) -> Option<Format> {
    match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "svg" => Some(Format::Svg),
        "png" => Some(Format::Png),
        _ => None,
    }
}

/// Rejects a `--plot` file name that is neither `.svg` nor `.png` (before any work is done).
pub fn check_path(path: &Path) -> Result<(), CliError> {
    match format_of(path) {
        Some(_) => Ok(()),
        None => Err(CliError::Usage(format!(
            "--plot {}: give a file name ending in .svg or .png",
            path.display()
        ))),
    }
}

/// Registers a system TrueType font as plotters' "sans-serif" (once).
pub fn register_font() -> Result<(), CliError> {
    use std::sync::OnceLock;
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        let env = std::env::var("LAGRANGE_FONT").ok();
        let candidates: Vec<String> = env
            .iter()
            .cloned()
            .chain(FONT_CANDIDATES.iter().map(|s| s.to_string()))
            .collect();
        for path in &candidates {
            if let Ok(bytes) = std::fs::read(path) {
                let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
                if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok() {
                    return Ok(());
                }
            }
        }
        Err(format!(
            "--plot: no TrueType font for the labels (looked at {}): install one (e.g. Debian's fonts-dejavu-core) or set LAGRANGE_FONT=/path/to/font.ttf",
            candidates.join(", ")
        ))
    })
    .clone()
    .map_err(CliError::Usage)
}

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

/// Draws the work-precision plot of `rows` into `path` (.svg or .png): drawn completely first,
/// then renamed onto `path` ([`OutputFile`]), so a failed plot leaves an earlier one untouched.
pub fn plot(path: &Path, title: &str, rows: &[Row]) -> Result<(), CliError> {
    register_font()?;
    let size = (960, 640);
    let failed = |e: String| CliError::Usage(format!("--plot {}: {e}", path.display()));
    let mut file = OutputFile::create(path)?;
    match format_of(path) {
        Some(Format::Svg) => {
            let mut svg = String::new();
            draw(SVGBackend::with_string(&mut svg, size).into_drawing_area(), title, rows).map_err(failed)?;
            // Generated files say so in their header. (An XML comment may not contain "--".)
            let header =
                format!("<!-- Generated by lagrange workprec: {}. -->\n", title.replace("--", "- -"));
            file.write_all((header + &svg).as_bytes())?;
        }
        // The temporary file keeps the .png extension the encoder goes by.
        Some(Format::Png) => {
            let tmp = file.path().to_path_buf();
            draw(BitMapBackend::new(&tmp, size).into_drawing_area(), title, rows).map_err(failed)?;
        }
        None => return check_path(path),
    }
    file.commit()
}
