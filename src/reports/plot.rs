//! PNG plots of the sweep with plotters' bitmap backend. Text needs a font: the embedded
//! one of [`crate::font`], registered before drawing.

use plotters::prelude::*;
use std::path::Path;

/// Plotting failed (the drawing backend's message).
#[derive(Debug, thiserror::Error)]
#[error("cannot draw {path}: {message}")]
pub struct PlotError {
    pub path: String,
    pub message: String,
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// Writes an RGB buffer as PNG, JPEG or WebP (plotters' bitmap backend draws into
/// memory; [`crate::output`] encodes and writes through a temporary file).
fn save(path: &Path, width: u32, height: u32, buf: Vec<u8>) -> Result<(), PlotError> {
    let err = |message: String| PlotError {
        path: path.display().to_string(),
        message,
    };
    let img =
        image::RgbImage::from_raw(width, height, buf).ok_or_else(|| err("buffer size".into()))?;
    crate::output::Output::check(path, crate::output::IMAGE_8BIT, "a plot")
        .and_then(|out| out.write_image(&image::DynamicImage::ImageRgb8(img)))
        .map_err(|e| err(e.to_string()))
}

/// One curve of the render sweep: `(beta, seconds, mean error, p95 error)` per beta,
/// errors relative to the diagonal.
#[derive(Clone, Debug)]
pub struct SweepSeries {
    pub label: String,
    pub points: Vec<(f64, f64, f64, f64)>,
}

/// One curve of the grid sweep: `(beta, median leaves, median microseconds)` per beta,
/// and a sample of single queries `(leaves, microseconds)`.
#[derive(Clone, Debug)]
pub struct GridSeries {
    pub label: String,
    pub per_beta: Vec<(f64, f64, f64)>,
    pub samples: Vec<(f64, f64)>,
}

/// Short tick labels: 3 significant digits, scientific notation outside [0.01, 1e4).
fn tick(v: &f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(0.01..1e4).contains(&a) {
        format!("{v:.0e}")
    } else {
        let decimals = (2 - a.log10().floor() as i32).clamp(0, 4) as usize;
        let t = format!("{v:.decimals$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    }
}

fn range(v: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite() && (!log || *x > 0.0)) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !lo.is_finite() {
        return (if log { 0.1 } else { 0.0 }, 1.0);
    }
    if log {
        (lo / 1.5, hi * 1.5)
    } else {
        let pad = 0.05 * (hi - lo).max(hi.abs() * 0.1).max(1e-12);
        ((lo - pad).min(0.0), hi + pad)
    }
}

fn err<E: std::fmt::Debug>(path: &Path) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError {
        path: path.display().to_string(),
        message: format!("{e:?}"),
    }
}

/// Two panels: render time against beta (log scale), and the isosurface error (percent
/// of the diagonal: mean solid, 95th percentile dashed) against render time.
pub fn sweep_plot(path: &Path, title: &str, series: &[SweepSeries]) -> Result<(), PlotError> {
    crate::font::register();
    let e = err(path);
    let (width, height) = (1400u32, 660u32);
    let mut buf = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(&e)?;
        let root = root
            .titled(title, ("sans-serif", 22).into_font())
            .map_err(&e)?;
        let (plots, legend) = root.split_vertically(height as i32 - 110);
        let (left, right) = plots.split_horizontally(620);
        let all = || series.iter().flat_map(|s| s.points.iter());
        let (t_lo, t_hi) = range(all().map(|p| p.1), true);
        let mut c = ChartBuilder::on(&left)
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(0f64..1f64, (t_lo..t_hi).log_scale())
            .map_err(&e)?;
        c.configure_mesh()
            .x_desc("beta")
            .y_desc("render time (s)")
            .label_style(("sans-serif", 14))
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(WHITE)
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(&e)?;
        for (i, s) in series.iter().enumerate() {
            let col = COLOURS[i % COLOURS.len()];
            c.draw_series(LineSeries::new(
                s.points.iter().map(|p| (p.0, p.1)),
                col.stroke_width(2),
            ))
            .map_err(&e)?
            .label(s.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(2)));
            c.draw_series(
                s.points
                    .iter()
                    .map(|p| Circle::new((p.0, p.1), 4, col.filled())),
            )
            .map_err(&e)?;
        }
        let (x_lo, x_hi) = range(all().map(|p| p.1), true);
        let (_, y_hi) = range(all().flat_map(|p| [100.0 * p.2, 100.0 * p.3]), false);
        let mut c = ChartBuilder::on(&right)
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d((x_lo..x_hi).log_scale(), 0f64..y_hi.max(1e-6))
            .map_err(&e)?;
        c.configure_mesh()
            .x_desc("render time (s)")
            .y_desc("isosurface error (% of diagonal)")
            .label_style(("sans-serif", 14))
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(WHITE)
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(&e)?;
        for (i, s) in series.iter().enumerate() {
            let col = COLOURS[i % COLOURS.len()];
            c.draw_series(LineSeries::new(
                s.points.iter().map(|p| (p.1, 100.0 * p.2)),
                col.stroke_width(2),
            ))
            .map_err(&e)?
            .label(format!("{} mean", s.label))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(2)));
            c.draw_series(LineSeries::new(
                s.points.iter().map(|p| (p.1, 100.0 * p.3)),
                col.stroke_width(1),
            ))
            .map_err(&e)?;
            c.draw_series(
                s.points
                    .iter()
                    .map(|p| Cross::new((p.1, 100.0 * p.3), 4, col.stroke_width(1))),
            )
            .map_err(&e)?;
            c.draw_series(s.points.iter().map(|p| {
                EmptyElement::at((p.1, 100.0 * p.2))
                    + Circle::new((0, 0), 4, col.filled())
                    + Text::new(format!("{}", p.0), (5, -14), ("sans-serif", 11).into_font())
            }))
            .map_err(&e)?;
        }
        // The legend, in a strip under both panels.
        let n = series.len().max(1) as i32;
        let per_row = 3.min(n);
        for (i, s) in series.iter().enumerate() {
            let col = COLOURS[i % COLOURS.len()];
            let (x, y) = (
                30 + (i as i32 % per_row) * 450,
                10 + (i as i32 / per_row) * 24,
            );
            legend
                .draw(&PathElement::new(
                    vec![(x, y + 8), (x + 30, y + 8)],
                    col.stroke_width(3),
                ))
                .map_err(&e)?;
            legend
                .draw(&Text::new(
                    s.label.clone(),
                    (x + 38, y),
                    ("sans-serif", 15).into_font(),
                ))
                .map_err(&e)?;
        }
        let y = 10 + ((n + per_row - 1) / per_row) * 24;
        legend
            .draw(&Text::new(
                "right: thick with dots = mean, thin with crosses = 95th percentile, over the rays that hit in both renders; numbers = beta",
                (30, y),
                ("sans-serif", 14).into_font(),
            ))
            .map_err(&e)?;
        root.present().map_err(&e)?;
    }
    save(path, width, height, buf)
}

/// Time per query against leaves visited (log-log): single queries as faint dots, the
/// median per beta (robust to the odd query preempted by another process) as a line
/// with markers labelled by beta.
pub fn grid_plot(path: &Path, title: &str, series: &[GridSeries]) -> Result<(), PlotError> {
    crate::font::register();
    let e = err(path);
    let (width, height) = (1000u32, 700u32);
    let mut buf = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(&e)?;
        let xs = || {
            series.iter().flat_map(|s| {
                s.samples
                    .iter()
                    .map(|p| p.0)
                    .chain(s.per_beta.iter().map(|p| p.1))
            })
        };
        let ys = || {
            series.iter().flat_map(|s| {
                s.samples
                    .iter()
                    .map(|p| p.1)
                    .chain(s.per_beta.iter().map(|p| p.2))
            })
        };
        let (x_lo, x_hi) = range(xs(), true);
        let (y_lo, y_hi) = range(ys(), true);
        let mut c = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(70)
            .build_cartesian_2d((x_lo..x_hi).log_scale(), (y_lo..y_hi).log_scale())
            .map_err(&e)?;
        c.configure_mesh()
            .x_desc("leaves visited per query")
            .y_desc("time per query (microseconds, one thread)")
            .label_style(("sans-serif", 14))
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(WHITE)
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(&e)?;
        for (i, s) in series.iter().enumerate() {
            let col = COLOURS[i % COLOURS.len()];
            c.draw_series(
                s.samples
                    .iter()
                    .filter(|p| p.0 > 0.0 && p.1 > 0.0)
                    .map(|&p| Circle::new(p, 1, col.mix(0.15).filled())),
            )
            .map_err(&e)?;
        }
        for (i, s) in series.iter().enumerate() {
            let col = COLOURS[i % COLOURS.len()];
            // A dark outline keeps the medians visible over the cloud of the same colour.
            c.draw_series(LineSeries::new(
                s.per_beta.iter().map(|p| (p.1, p.2)),
                BLACK.stroke_width(5),
            ))
            .map_err(&e)?;
            c.draw_series(LineSeries::new(
                s.per_beta.iter().map(|p| (p.1, p.2)),
                col.stroke_width(3),
            ))
            .map_err(&e)?
            .label(s.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(3)));
            c.draw_series(s.per_beta.iter().map(|p| {
                EmptyElement::at((p.1, p.2))
                    + Circle::new((0, 0), 6, BLACK.filled())
                    + Circle::new((0, 0), 4, col.filled())
                    + Text::new(
                        format!("{}", p.0),
                        (-24, -6),
                        ("sans-serif", 12).into_font(),
                    )
            }))
            .map_err(&e)?;
        }
        c.configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(&e)?;
        root.present().map_err(&e)?;
    }
    save(path, width, height, buf)
}
