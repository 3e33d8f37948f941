//! Line charts as PNG and SVG with a bundled font (DejaVu Sans, see `assets/`), so no
//! system fonts are needed.

use crate::error::{internal, CliError};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Register the bundled font as `sans-serif` (once per process).
pub fn register_font() -> Result<(), CliError> {
    static ONCE: Once = Once::new();
    let mut result = Ok(());
    ONCE.call_once(|| {
        result = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
            .map_err(|_| internal("the bundled font could not be loaded"));
    });
    result
}

/// One line. `NaN` y values break the line (no estimate there). An empty name keeps it
/// out of the legend.
pub struct Series {
    /// Legend label.
    pub name: String,
    /// `(x, y)` points.
    pub points: Vec<(f64, f64)>,
    /// Colour.
    pub color: RGBColor,
    /// Line width, px.
    pub width: u32,
}

/// One set of axes.
pub struct Panel {
    /// Title above the axes.
    pub title: String,
    /// Y-axis label with units.
    pub y_label: String,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The lines.
    pub series: Vec<Series>,
}

impl Panel {
    /// The relative Frobenius error on a log axis, untitled.
    pub fn total_error(series: Vec<Series>) -> Self {
        Self {
            title: String::new(),
            y_label: "‖J_est − J‖_F / ‖J‖_F".into(),
            log_y: true,
            series,
        }
    }
}

/// A palette that stays readable in print.
pub const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(0, 0, 0),
];

/// Write `stem.png` and `stem.svg`: panels stacked vertically, sharing the x label.
pub fn figure(stem: &Path, title: &str, x_label: &str, panels: &[Panel]) -> Result<(), CliError> {
    let height = 120 + 300 * panels.len() as u32;
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    {
        let root = BitMapBackend::new(&png, (960, height)).into_drawing_area();
        draw(&root, title, x_label, panels)
            .map_err(|e| internal(format!("{}: {e}", png.display())))?;
        root.present()
            .map_err(|e| internal(format!("{}: {e}", png.display())))?;
    }
    {
        let root = SVGBackend::new(&svg, (960, height)).into_drawing_area();
        draw(&root, title, x_label, panels)
            .map_err(|e| internal(format!("{}: {e}", svg.display())))?;
        root.present()
            .map_err(|e| internal(format!("{}: {e}", svg.display())))?;
    }
    Ok(())
}

fn x_range(panels: &[Panel]) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for s in panels.iter().flat_map(|p| &p.series) {
        for &(x, _) in &s.points {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    }
    if lo.is_finite() && hi > lo {
        (lo, hi)
    } else {
        (0.0, 1.0)
    }
}

fn y_range(p: &Panel) -> (f64, f64) {
    let ys = p
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|q| q.1))
        .filter(|y| y.is_finite() && (!p.log_y || *y > 0.0));
    let (mut lo, mut hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
        (a.min(y), b.max(y))
    });
    if !lo.is_finite() {
        return if p.log_y { (1e-6, 1.0) } else { (-1.0, 1.0) };
    }
    if p.log_y {
        lo = (lo / 2.0).max(hi * 1e-12);
        hi *= 2.0;
    } else {
        let m = 0.05 * (hi - lo).max(1e-12);
        lo -= m;
        hi += m;
    }
    (lo, hi)
}

type DrawResult<E> = Result<(), DrawingAreaErrorKind<E>>;

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    x_label: &str,
    panels: &[Panel],
) -> DrawResult<DB::ErrorType> {
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 26))?;
    let areas = root.split_evenly((panels.len(), 1));
    let (x0, x1) = x_range(panels);
    for (idx, (area, p)) in areas.iter().zip(panels).enumerate() {
        let (y0, y1) = y_range(p);
        let mut b = ChartBuilder::on(area);
        b.caption(&p.title, ("sans-serif", 20))
            .margin(12)
            .margin_right(36)
            .x_label_area_size(45)
            .y_label_area_size(80);
        if p.log_y {
            let mut chart = b.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .y_desc(&p.y_label)
                .x_label_formatter(&|v| format!("{v:.0}"))
                .y_label_formatter(&|v| format!("{v:.0e}"))
                .label_style(("sans-serif", 15))
                .draw()?;
            lines(&mut chart, p, true, idx == 0)?;
        } else {
            let mut chart = b.build_cartesian_2d(x0..x1, y0..y1)?;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .y_desc(&p.y_label)
                .x_label_formatter(&|v| format!("{v:.0}"))
                .label_style(("sans-serif", 15))
                .draw()?;
            lines(&mut chart, p, false, idx == 0)?;
        }
    }
    Ok(())
}

/// Draw a panel's series (the first one last, on top, and thicker) and, on the first
/// panel, the legend.
fn lines<'a, DB, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    p: &Panel,
    log: bool,
    legend: bool,
) -> DrawResult<DB::ErrorType>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    // Drawn in reverse, so the first (main) series ends up on top.
    for s in p.series.iter().rev() {
        let width = s.width;
        for (i, seg) in segments(&s.points, log).into_iter().enumerate() {
            // Two-point paths: the bitmap backend draws thick polylines with unlimited
            // miter joins, which turn sharp zig-zags of noisy data into long spikes.
            let style = s.color.stroke_width(width);
            let pieces: Vec<PathElement<(f64, f64)>> = if seg.len() == 1 {
                vec![PathElement::new(vec![seg[0], seg[0]], style)]
            } else {
                seg.windows(2)
                    .map(|w| PathElement::new(vec![w[0], w[1]], style))
                    .collect()
            };
            let series = chart.draw_series(pieces)?;
            if i == 0 && legend && !s.name.is_empty() {
                let c = s.color;
                series.label(&s.name).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(3))
                });
            }
        }
    }
    if legend {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
    }
    Ok(())
}

/// Split points into runs of drawable values (finite, and positive on a log axis).
fn segments(points: &[(f64, f64)], log: bool) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for &(x, y) in points {
        if y.is_finite() && (!log || y > 0.0) {
            cur.push((x, y));
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}
