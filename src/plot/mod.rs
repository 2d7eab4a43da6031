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
fn style_is(a: Style, b: Style) -> bool {
    std::mem::discriminant(&a) == std::mem::discriminant(&b)
}

/// Whether every x value of the panel is a whole number (steps, alternatives) over a short
/// range, so that its axis is labelled at whole numbers only.
fn integer_axis(panel: &Panel) -> bool {
    let mut xs = panel.series.iter().flat_map(|s| s.x.iter()).filter(|x| x.is_finite()).peekable();
    xs.peek().is_some() && xs.all(|x| x.fract() == 0.0 && x.abs() < 1e6)
}

/// A tick of a counted axis: the whole number, no label between two.
fn whole(v: f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("{}", v.round() as i64)
    } else {
        String::new()
    }
}

/// The corner of the plotting area where the legend covers the fewest data points (a box of
/// a third of the width and `rows` legend lines high in each corner), in the order upper
/// right, upper left, lower right, lower left on ties.
fn legend_corner(panel: &Panel, x: (f64, f64), y: (f64, f64), rows: usize) -> SeriesLabelPosition {
    // on a logarithmic axis the box is a share of the decades
    let scale = |v: f64| if panel.log_y { v.max(1e-300).log10() } else { v };
    let y = (scale(y.0), scale(y.1));
    let (w, h) = ((x.1 - x.0) / 3.0, (y.1 - y.0) * (0.1 * rows as f64 + 0.08).min(0.6));
    let corners = [
        (SeriesLabelPosition::UpperRight, x.1 - w, y.1 - h),
        (SeriesLabelPosition::UpperLeft, x.0, y.1 - h),
        (SeriesLabelPosition::LowerRight, x.1 - w, y.0),
        (SeriesLabelPosition::LowerLeft, x.0, y.0),
    ];
    let inside = |cx: f64, cy: f64| {
        panel
            .series
            .iter()
            .flat_map(|s| s.x.iter().zip(s.y.iter().chain(s.upper.iter())))
            .map(|(px, py)| (*px, scale(*py)))
            .filter(|(px, py)| *px >= cx && *px <= cx + w && *py >= cy && *py <= cy + h)
            .count()
    };
    corners
        .into_iter()
        .min_by_key(|(_, cx, cy)| inside(*cx, *cy))
        .map_or(SeriesLabelPosition::UpperRight, |(p, _, _)| p)
}

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
            let counted = integer_axis(panel);
            chart
                .configure_mesh()
                .x_desc(&panel.x_label)
                .y_desc(&panel.y_label)
                .x_label_formatter(&|v| if counted { whole(*v) } else { short(*v) })
                .y_label_formatter(&|v| format!("{v:.0e}"))
                .draw()?;
            draw_series(&mut chart, panel, x0..x1, y0, y1)?;
        } else {
            let mut chart = builder.build_cartesian_2d(x0..x1, y0..y1)?;
            // steps and alternatives are counted: their axis is labelled at whole numbers only
            let counted = integer_axis(panel);
            chart
                .configure_mesh()
                .x_desc(&panel.x_label)
                .y_desc(&panel.y_label)
                .x_label_formatter(&|v| if counted { whole(*v) } else { short(*v) })
                .y_label_formatter(&|v| short(*v))
                .draw()?;
            draw_series(&mut chart, panel, x0..x1, y0, y1)?;
        }
        Ok(())
    }
}

fn draw_series<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate<From = (f64, f64)>>(
    chart: &mut ChartContext<'a, DB, CT>,
    panel: &Panel,
    x_range: std::ops::Range<f64>,
    y0: f64,
    y1: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    for (k, (x, label)) in panel.markers.iter().enumerate() {
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(*x, y0), (*x, y1)],
            PALETTE[4].stroke_width(1),
        )))?;
        // each label a line lower than the one before, so that two close markers' labels
        // do not print over each other
        let share = 0.08 * k as f64;
        let at = if panel.log_y { y1 * (y0 / y1).powf(share) } else { y1 - share * (y1 - y0) };
        chart.draw_series(std::iter::once(Text::new(
            label.clone(),
            (*x, at),
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
            // one element type for every entry (plotters needs one), its parts shown or not:
            // a line, dashes, a marker or a shaded band, as the series is drawn
            let show = |yes: bool| if yes { 1.0 } else { 0.0 };
            let (line, dashes, marker, band) = (
                show(style_is(s.style, Style::Line)),
                show(matches!(s.style, Style::Line | Style::Dashed)),
                show(style_is(s.style, Style::Points)),
                show(style_is(s.style, Style::Band)),
            );
            anno.label(s.name.clone()).legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + Rectangle::new([(0, -5), (18, 5)], color.mix(0.25 * band).filled())
                    + PathElement::new(vec![(0, 0), (7, 0)], color.mix(dashes).stroke_width(2))
                    + PathElement::new(vec![(7, 0), (11, 0)], color.mix(line).stroke_width(2))
                    + PathElement::new(vec![(11, 0), (18, 0)], color.mix(dashes).stroke_width(2))
                    + Circle::new((9, 0), 3, color.mix(marker).filled())
            });
        }
    }
    let named = panel.series.iter().filter(|s| !s.name.is_empty()).count();
    if panel.series.len() > 1 && named > 0 {
        chart
            .configure_series_labels()
            .position(legend_corner(panel, (x_range.start, x_range.end), (y0, y1), named))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 11))
            .draw()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steps_panel() -> Panel {
        let x: Vec<f64> = (1..=18).map(f64::from).collect();
        // the data fill the top of the panel and its right half: the lower left is free
        let high: Vec<f64> = x.iter().map(|s| 10.0 - 0.1 * s).collect();
        let right: Vec<f64> = x.iter().map(|s| if *s > 9.0 { 1.0 } else { 9.5 }).collect();
        Panel {
            title: "steps".into(),
            x_label: "step".into(),
            y_label: "F".into(),
            series: vec![Series::line("a", x.clone(), high), Series::points("b", x, right)],
            markers: vec![(12.0, "chosen 12".into()), (13.0, "chosen 13".into())],
            ..Panel::default()
        }
    }

    /// Read off the SVG as a person would: a counted axis is labelled 2, 4, … (not 2.0, 2.5),
    /// the legend goes where the data are not, two close markers' labels stand apart.
    #[test]
    fn counted_axes_legend_off_the_data_labels_apart() {
        let panel = steps_panel();
        assert!(integer_axis(&panel));
        assert_eq!((whole(4.0), whole(4.5)), ("4".to_string(), String::new()));
        assert!(matches!(legend_corner(&panel, (0.0, 19.0), (0.0, 10.5), 2), SeriesLabelPosition::LowerLeft));
        let svg = Figure::new("t", vec![panel]).to_svg().unwrap();
        let texts: Vec<&str> = svg
            .split("<text")
            .skip(1)
            .filter_map(|t| Some(t.split('>').nth(1)?.split('<').next()?.trim()))
            .collect();
        assert!(texts.contains(&"4") && !texts.iter().any(|t| *t == "4.0" || *t == "2.5"), "{texts:?}");
        let y_of = |label: &str| -> f64 {
            let at = svg.find(label).unwrap();
            let tag = &svg[svg[..at].rfind("<text").unwrap()..at];
            let y = tag.split(" y=\"").nth(1).unwrap().split('"').next().unwrap();
            y.parse().unwrap()
        };
        assert!((y_of("chosen 13") - y_of("chosen 12")).abs() >= 10.0, "marker labels overlap");
        let mut times = steps_panel();
        times.series[0].x[0] = 0.5;
        assert!(!integer_axis(&times));
    }
}
