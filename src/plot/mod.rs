//! Figures as SVG (plotters, no fonts needed): a figure is a column of panels, each with
//! named line or point series. Generic; the core's figures (a run's preparation, runs beside
//! their simulations) are here, the ship plug-in draws its own with the same types. Behind
//! the `plot` feature.

mod comparison;
mod prepared;

pub use comparison::{comparison_figures, diagnosis_figures};
pub use prepared::prepared_figure;

use std::path::Path;

use plotters::prelude::*;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// A solid line.
    Line,
    /// A dashed line (drawn as short segments).
    Dashed,
    /// Markers only.
    Points,
    /// A shaded band between `y` (lower) and `upper`.
    Band,
}

/// One curve.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
    /// Drawing style.
    pub style: Style,
    /// Upper edge of a band (empty for other styles).
    pub upper: Vec<f64>,
}

impl Series {
    /// A solid line.
    pub fn line(name: &str, x: Vec<f64>, y: Vec<f64>) -> Series {
        Series { name: name.into(), x, y, style: Style::Line, upper: vec![] }
    }
    /// A dashed line.
    pub fn dashed(name: &str, x: Vec<f64>, y: Vec<f64>) -> Series {
        Series { name: name.into(), x, y, style: Style::Dashed, upper: vec![] }
    }
    /// Markers.
    pub fn points(name: &str, x: Vec<f64>, y: Vec<f64>) -> Series {
        Series { name: name.into(), x, y, style: Style::Points, upper: vec![] }
    }
    /// A shaded band from `lower` to `upper` (e.g. a 90 % prediction band).
    pub fn band(name: &str, x: Vec<f64>, lower: Vec<f64>, upper: Vec<f64>) -> Series {
        Series { name: name.into(), x, y: lower, style: Style::Band, upper }
    }
}

/// One panel with axes.
#[derive(Clone, Debug, Default)]
pub struct Panel {
    /// Title above the panel.
    pub title: String,
    /// x-axis label with unit.
    pub x_label: String,
    /// y-axis label with unit.
    pub y_label: String,
    /// The curves.
    pub series: Vec<Series>,
    /// Vertical marker lines (e.g. a chosen step), with labels.
    pub markers: Vec<(f64, String)>,
    /// Same scale on both axes (tracks).
    pub equal_axes: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
}

/// A column of panels.
#[derive(Clone, Debug, Default)]
pub struct Figure {
    /// Title of the whole figure.
    pub title: String,
    /// Panels from top to bottom.
    pub panels: Vec<Panel>,
    /// Width in pixels.
    pub width: u32,
    /// Height of one panel in pixels.
    pub panel_height: u32,
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 0, 0),
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
];

fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (-1.0, 1.0) };
    }
    if log {
        return (lo / 1.5, hi * 1.5);
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { lo.abs().max(1.0) * 0.1 };
    (lo - pad, hi + pad)
}

/// Why a figure could not be drawn or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The drawing back-end failed (plotters' message).
    #[error("could not draw the figure: {0}")]
    Draw(String),
    /// Drawn, but not written.
    #[error("{file}: could not draw the figure: {message}")]
    File {
        /// The file.
        file: String,
        /// What went wrong.
        message: String,
    },
}

/// Axis numbers without trailing noise: 0.25, 30, 1e-4.
fn short(v: f64) -> String {
    // tick positions computed as sums carry round-off: 1e-17 is a zero
    if v.abs() < 1e-12 {
        "0".into()
    } else if v.abs() >= 1e-3 && v.abs() < 1e5 {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.1e}")
    }
}

impl Figure {
    /// A figure of the given panels, 760 px wide, 240 px per panel.
    pub fn new(title: &str, panels: Vec<Panel>) -> Figure {
        Figure { title: title.into(), panels, width: 760, panel_height: 240 }
    }

    /// Writes the figure as SVG (atomically: the old file stays until the new one is whole).
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        let file = path.display().to_string();
        let svg =
            self.to_svg().map_err(|e| PlotError::File { file: file.clone(), message: e.to_string() })?;
        crate::output::write_file(path, svg.as_bytes())
            .map_err(|e| PlotError::File { file, message: e.reason() })
    }

    /// The figure as SVG text.
    pub fn to_svg(&self) -> Result<String, PlotError> {
        let err = |e: &dyn std::fmt::Display| PlotError::Draw(e.to_string());
        let title_h = if self.title.is_empty() { 0 } else { 30 };
        let height = title_h + self.panel_height * self.panels.len().max(1) as u32;
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (self.width, height)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| err(&e))?;
            let body = if title_h > 0 {
                let (top, body) = root.split_vertically(title_h);
                top.titled(&self.title, ("sans-serif", 18)).map_err(|e| err(&e))?;
                body
            } else {
                root.clone()
            };
            let areas = body.split_evenly((self.panels.len().max(1), 1));
            for (panel, area) in self.panels.iter().zip(areas) {
                self.draw_panel(panel, &area).map_err(|e| err(&e))?;
            }
            root.present().map_err(|e| err(&e))?;
        }
        Ok(svg)
    }

    fn draw_panel<DB: DrawingBackend>(
        &self,
        panel: &Panel,
        area: &DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (mut x0, mut x1) = range(panel.series.iter().flat_map(|s| s.x.iter().copied()), false);
        let (mut y0, mut y1) =
            range(panel.series.iter().flat_map(|s| s.y.iter().chain(&s.upper).copied()), panel.log_y);
        if panel.equal_axes {
            // the same metres per pixel on both axes: the ranges follow the plotting area's
            // shape (the panel less its caption, label areas and margins below), so a circle
            // is drawn round
            let (w, h) = area.dim_in_pixel();
            let (pw, ph) = ((w as f64 - 60.0 - 16.0).max(10.0), (h as f64 - 34.0 - 16.0 - 22.0).max(10.0));
            let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
            let per_pixel = ((x1 - x0) / pw).max((y1 - y0) / ph);
            (x0, x1) = (cx - per_pixel * pw / 2.0, cx + per_pixel * pw / 2.0);
            (y0, y1) = (cy - per_pixel * ph / 2.0, cy + per_pixel * ph / 2.0);
        }
        let mut builder = ChartBuilder::on(area);
        builder
            .caption(&panel.title, ("sans-serif", 14))
            .margin(8)
            .x_label_area_size(34)
            .y_label_area_size(60);
        if panel.log_y {
            let mut chart = builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?;
            chart
                .configure_mesh()
                .x_desc(&panel.x_label)
                .y_desc(&panel.y_label)
                .y_label_formatter(&|v| format!("{v:.0e}"))
                .draw()?;
            draw_series(&mut chart, panel, y0, y1)?;
        } else {
            let mut chart = builder.build_cartesian_2d(x0..x1, y0..y1)?;
            chart
                .configure_mesh()
                .x_desc(&panel.x_label)
                .y_desc(&panel.y_label)
                .x_label_formatter(&|v| short(*v))
                .y_label_formatter(&|v| short(*v))
                .draw()?;
            draw_series(&mut chart, panel, y0, y1)?;
        }
        Ok(())
    }
}

fn draw_series<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate<From = (f64, f64)>>(
    chart: &mut ChartContext<'a, DB, CT>,
    panel: &Panel,
    y0: f64,
    y1: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    for (x, label) in &panel.markers {
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(*x, y0), (*x, y1)],
            PALETTE[4].stroke_width(1),
        )))?;
        chart.draw_series(std::iter::once(Text::new(
            label.clone(),
            (*x, y1),
            ("sans-serif", 11).into_font(),
        )))?;
    }
    for (k, s) in panel.series.iter().enumerate() {
        let color = PALETTE[k % PALETTE.len()];
        let pts: Vec<(f64, f64)> =
            s.x.iter()
                .zip(&s.y)
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|(x, y)| (*x, *y))
                .collect();
        let anno = match s.style {
            Style::Line => chart.draw_series(LineSeries::new(pts, color.stroke_width(2)))?,
            Style::Dashed => {
                let segments: Vec<Vec<(f64, f64)>> =
                    pts.chunks(2).step_by(2).map(|c| c.to_vec()).filter(|c| c.len() == 2).collect();
                chart.draw_series(
                    segments.into_iter().map(move |seg| PathElement::new(seg, color.stroke_width(2))),
                )?
            }
            Style::Points => {
                chart.draw_series(pts.into_iter().map(move |p| Circle::new(p, 3, color.filled())))?
            }
            Style::Band => {
                // lower edge forward, upper edge back: one closed polygon
                let mut outline: Vec<(f64, f64)> = pts.clone();
                outline.extend(
                    s.x.iter()
                        .zip(&s.upper)
                        .filter(|(x, y)| x.is_finite() && y.is_finite())
                        .map(|(x, y)| (*x, *y))
                        .rev(),
                );
                chart.draw_series(std::iter::once(Polygon::new(outline, color.mix(0.25).filled())))?
            }
        };
        if !s.name.is_empty() {
            anno.label(s.name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2)));
        }
    }
    if panel.series.len() > 1 {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 11))
            .draw()?;
    }
    Ok(())
}
