//! Figures as SVG (plotters, no fonts needed): a figure is a column of panels, each with
//! named line or point series. Generic; the core's figures (a run's preparation, runs beside
//! their simulations) are here, the ship plug-in draws its own with the same types. Behind
//! the `plot` feature.

mod comparison;
mod prepared;

pub use comparison::{comparison_figures, diagnosis_figures, LABELS};
pub use prepared::prepared_figure;

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// A solid line.
    Line,
    /// A dashed line (drawn as short segments).
    Dashed,
    /// Markers only.
    Points,
    /// Larger open rings (a reference, e.g. the true values, that markers drawn over it
    /// leave visible).
    Rings,
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
    /// The palette colour, where it is not the series' place in its panel (a residual in
    /// the colour of the simulation it belongs to).
    pub color: Option<usize>,
}

impl Series {
    /// The same series in palette colour `k`.
    pub fn colored(mut self, k: usize) -> Series {
        self.color = Some(k);
        self
    }
    /// A solid line.
    pub fn line(name: &str, x: Vec<f64>, y: Vec<f64>) -> Series {
        Series { name: name.into(), x, y, style: Style::Line, upper: vec![], color: None }
    }
    /// A dashed line.
    pub fn dashed(name: &str, x: Vec<f64>, y: Vec<f64>) -> Series {
        Series { name: name.into(), x, y, style: Style::Dashed, upper: vec![], color: None }
    }
    /// Markers.
    pub fn points(name: &str, x: Vec<f64>, y: Vec<f64>) -> Series {
        Series { name: name.into(), x, y, style: Style::Points, upper: vec![], color: None }
    }
    /// Open rings.
    pub fn rings(name: &str, x: Vec<f64>, y: Vec<f64>) -> Series {
        Series { name: name.into(), x, y, style: Style::Rings, upper: vec![], color: None }
    }
    /// A shaded band from `lower` to `upper` (e.g. a 90 % prediction band).
    pub fn band(name: &str, x: Vec<f64>, lower: Vec<f64>, upper: Vec<f64>) -> Series {
        Series { name: name.into(), x, y: lower, style: Style::Band, upper, color: None }
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
    /// Both axes labelled at every whole unit where the range allows (a track in ship
    /// lengths: a tick per length, as in the paper's track plots).
    pub unit_ticks: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Height in pixels where it differs from the figure's `panel_height` (a track in a
    /// one-column figure, drawn near square).
    pub height: Option<u32>,
}

/// Panels in rows of `columns` (one column unless set).
#[derive(Clone, Debug, Default)]
pub struct Figure {
    /// Title of the whole figure.
    pub title: String,
    /// Panels row by row, left to right, top to bottom.
    pub panels: Vec<Panel>,
    /// Width in pixels.
    pub width: u32,
    /// Height of one row of panels in pixels.
    pub panel_height: u32,
    /// Panels side by side in a row.
    pub columns: usize,
    /// One legend for the whole figure, under its title, in place of each panel's own (panels
    /// that show the same series: a run's states beside their simulations).
    pub shared_legend: bool,
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

/// An axis label: `name [unit]`, or the bare name where there is no unit.
pub fn labelled(name: &str, unit: &str) -> String {
    if unit.is_empty() {
        name.to_string()
    } else {
        format!("{name} [{unit}]")
    }
}

/// Whether the label of the marker at `x` goes left of its line: where another marker's line
/// would cross it on the right (11 px text, 5.5 px a character; `per_px`: x units a pixel).
fn label_left(panel: &Panel, x: f64, label: &str, per_px: f64) -> bool {
    let width = (5.5 * label.chars().count() as f64 + 4.0) * per_px;
    panel.markers.iter().any(|(other, _)| *other > x && *other <= x + width)
}

/// The colour the `k`-th series of `panel` is drawn in: its own or the palette's; a solid line
/// (the reference: measured, true) under dashed ones is drawn wide (see [`draw_series`]) and
/// mixed half with white, so that it shows beside the dashes that run along it.
fn paint(panel: &Panel, k: usize) -> RGBColor {
    let s = &panel.series[k];
    let c = PALETTE[s.color.unwrap_or(k) % PALETTE.len()];
    let under = panel.series.iter().any(|s| style_is(s.style, Style::Dashed));
    if under && style_is(s.style, Style::Line) {
        let mix = |v: u8| (f64::from(v) * 0.5 + 255.0 * 0.5).round() as u8;
        RGBColor(mix(c.0), mix(c.1), mix(c.2))
    } else {
        c
    }
}

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

/// The legend's size in pixels as plotters lays it out for `panel` (11 px text, about 5 px a
/// character, a 30 px glyph column, 10 px margins), 5 px from the plotting area's edge, and
/// a few pixels more: its own estimate of a text's width is not ours (Greek letters).
fn legend_px(panel: &Panel) -> (f64, f64) {
    let named = panel.series.iter().filter(|s| !s.name.is_empty());
    let (rows, chars) = named.fold((0usize, 0usize), |(n, c), s| (n + 1, c.max(s.name.chars().count())));
    (5.5 * chars as f64 + 65.0, 14.0 * rows as f64 + 30.0)
}

/// The plotting area's size in pixels in a panel of `(w, h)`: less the label areas (60 px
/// left, 34 px below), the margins (8 px each side) and the caption.
fn plot_px((w, h): (u32, u32)) -> (f64, f64) {
    ((w as f64 - 60.0 - 16.0).max(10.0), (h as f64 - 34.0 - 16.0 - 22.0).max(10.0))
}

/// The corner of the plotting area where the legend covers the fewest data points, and how
/// many it covers, in the order upper right, upper left, lower right, lower left on ties.
/// `px` is the plotting area's size in pixels, which sizes the legend's box in data units.
fn legend_corner(
    panel: &Panel,
    x: (f64, f64),
    y: (f64, f64),
    px: (f64, f64),
) -> (SeriesLabelPosition, usize) {
    // on a logarithmic axis the box is a share of the decades
    let scale = |v: f64| if panel.log_y { v.max(1e-300).log10() } else { v };
    let y = (scale(y.0), scale(y.1));
    let (lw, lh) = legend_px(panel);
    let (w, h) = ((x.1 - x.0) * (lw / px.0).min(1.0), (y.1 - y.0) * (lh / px.1).min(1.0));
    let corners = [
        (SeriesLabelPosition::UpperRight, x.1 - w, y.1 - h),
        (SeriesLabelPosition::UpperLeft, x.0, y.1 - h),
        (SeriesLabelPosition::LowerRight, x.1 - w, y.0),
        (SeriesLabelPosition::LowerLeft, x.0, y.0),
    ];
    // a marker is a line over the whole height, and its label (11 px text, 5.5 px a
    // character) to the right of it near the top, a line lower for each marker before it
    let per_px = (x.1 - x.0) / px.0;
    let marks: Vec<(f64, f64)> = panel
        .markers
        .iter()
        .enumerate()
        .flat_map(|(k, (mx, label))| {
            let line = (0..=20).map(move |i| (*mx, y.0 + (y.1 - y.0) * f64::from(i) / 20.0));
            let at = y.1 - 0.08 * k as f64 * (y.1 - y.0);
            let sign = if label_left(panel, *mx, label, per_px) { -1.0 } else { 1.0 };
            let text = (0..label.chars().count()).map(move |c| (*mx + sign * 5.5 * c as f64 * per_px, at));
            line.chain(text)
        })
        .collect();
    // the points of every line and band edge, and four between each two (a line from one
    // point outside the box to the next can cross it)
    let edge = |s: &Series, ys: &[f64]| -> Vec<(f64, f64)> {
        let p: Vec<(f64, f64)> = s.x.iter().zip(ys).map(|(a, b)| (*a, scale(*b))).collect();
        let between = !matches!(s.style, Style::Points | Style::Rings);
        let mut out = p.clone();
        if between {
            for pair in p.windows(2) {
                let ((a, b), (c, d)) = (pair[0], pair[1]);
                out.extend((1..5).map(|i| {
                    let f = f64::from(i) / 5.0;
                    (a + f * (c - a), b + f * (d - b))
                }));
            }
        }
        out
    };
    let points: Vec<(f64, f64)> = panel
        .series
        .iter()
        .flat_map(|s| edge(s, &s.y).into_iter().chain(edge(s, &s.upper)))
        .chain(marks)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .collect();
    let inside = |cx: f64, cy: f64| {
        points.iter().filter(|(px, py)| *px >= cx && *px <= cx + w && *py >= cy && *py <= cy + h).count()
    };
    corners
        .into_iter()
        .map(|(p, cx, cy)| (p, inside(cx, cy)))
        .min_by_key(|(_, n)| *n)
        .unwrap_or((SeriesLabelPosition::UpperRight, 0))
}

/// Whether a panel draws a legend of its own.
fn has_legend(panel: &Panel) -> bool {
    panel.series.len() > 1 && panel.series.iter().any(|s| !s.name.is_empty())
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
        Figure {
            title: title.into(),
            panels,
            width: 760,
            panel_height: 240,
            columns: 1,
            shared_legend: false,
        }
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
        let legend_h = if self.shared_legend { 24 } else { 0 };
        // a panel may have its own height (a track); a grid's row takes its tallest panel's
        let columns = self.columns.max(1);
        let heights: Vec<u32> = self
            .panels
            .chunks(columns)
            .map(|row| {
                row.iter().map(|p| p.height.unwrap_or(self.panel_height)).max().unwrap_or(self.panel_height)
            })
            .collect();
        let height = title_h + legend_h + heights.iter().sum::<u32>().max(self.panel_height);
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
            let body = if legend_h > 0 {
                let (row, body) = body.split_vertically(legend_h);
                legend_row(&self.panels, &row).map_err(|e| err(&e))?;
                body
            } else {
                body
            };
            let mut rest = body;
            let mut areas = Vec::new();
            for h in &heights {
                let (row, below) = rest.split_vertically(*h);
                areas.extend(if columns > 1 { row.split_evenly((1, columns)) } else { vec![row] });
                rest = below;
            }
            let shared = self.shared_x();
            for ((panel, area), x) in self.panels.iter().zip(areas).zip(shared) {
                self.draw_panel(panel, &area, x).map_err(|e| err(&e))?;
            }
            root.present().map_err(|e| err(&e))?;
        }
        Ok(svg)
    }

    /// Each panel's x range where it shares one with other panels: panels over the same x
    /// axis (the same label: time, in a figure of stacked panels) are drawn over the range of
    /// all of them, so that one instant stands at one place in every panel. Tracks (equal
    /// axes) keep their own.
    fn shared_x(&self) -> Vec<Option<(f64, f64)>> {
        let over = |p: &Panel| !p.equal_axes && !p.x_label.is_empty();
        self.panels
            .iter()
            .map(|p| {
                let same: Vec<&Panel> =
                    self.panels.iter().filter(|q| over(q) && q.x_label == p.x_label).collect();
                (over(p) && same.len() > 1).then(|| {
                    range(same.iter().flat_map(|q| q.series.iter().flat_map(|s| s.x.iter().copied())), false)
                })
            })
            .collect()
    }

    fn draw_panel<DB: DrawingBackend>(
        &self,
        panel: &Panel,
        area: &DrawingArea<DB, plotters::coord::Shift>,
        shared_x: Option<(f64, f64)>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (mut x0, mut x1) =
            shared_x.unwrap_or_else(|| range(panel.series.iter().flat_map(|s| s.x.iter().copied()), false));
        let (mut y0, mut y1) =
            range(panel.series.iter().flat_map(|s| s.y.iter().chain(&s.upper).copied()), panel.log_y);
        let px = plot_px(area.dim_in_pixel());
        // the same metres per pixel on both axes: the ranges follow the plotting area's shape,
        // so a circle is drawn round
        let equal = |(x0, x1): (f64, f64), (y0, y1): (f64, f64)| {
            let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
            let per_pixel = ((x1 - x0) / px.0).max((y1 - y0) / px.1);
            (
                (cx - per_pixel * px.0 / 2.0, cx + per_pixel * px.0 / 2.0),
                (cy - per_pixel * px.1 / 2.0, cy + per_pixel * px.1 / 2.0),
            )
        };
        let data_y = (y0, y1);
        if panel.equal_axes {
            ((x0, x1), (y0, y1)) = equal((x0, x1), (y0, y1));
        }
        let own_legend = has_legend(panel) && !self.shared_legend;
        let mut corner = if own_legend {
            legend_corner(panel, (x0, x1), (y0, y1), px)
        } else {
            (SeriesLabelPosition::UpperRight, 0)
        };
        if own_legend && corner.1 > 0 && panel.equal_axes {
            // a track under the legend in every corner: room above the data, both axes at
            // the same scale still
            let (_, lh) = legend_px(panel);
            let high = ((lh + 4.0) / px.1).min(0.5);
            let (lo, hi) = data_y;
            let x = range(panel.series.iter().flat_map(|s| s.x.iter().copied()), false);
            // the fit centres the data: where the width sets the scale, only part of the
            // room added lands above them, so add more until the legend is clear
            for more in [1.0, 2.0, 4.0] {
                ((x0, x1), (y0, y1)) = equal(x, (lo, hi + more * (hi - lo) * high / (1.0 - high)));
                corner = legend_corner(panel, (x0, x1), (y0, y1), px);
                if corner.1 == 0 {
                    break;
                }
            }
        }
        if own_legend && corner.1 > 0 && !panel.equal_axes {
            // every corner has data under the legend: room beside the data (a tall legend of
            // many entries) or above them (a wide one), whichever takes less of the panel,
            // so that it covers none; above them where the x axis is shared with other panels
            let (lw, lh) = legend_px(panel);
            let (wide, high) = ((lw + 4.0) / px.0, (lh + 4.0) / px.1);
            if wide < high && wide < 0.5 && !panel.log_y && shared_x.is_none() {
                x1 = x0 + (x1 - x0) / (1.0 - wide);
            } else {
                let room = 1.0 / (1.0 - high).max(1.0 / 3.0);
                if panel.log_y {
                    y1 = y0 * (y1 / y0).powf(room);
                } else {
                    y1 = y0 + (y1 - y0) * room;
                }
            }
            corner = legend_corner(panel, (x0, x1), (y0, y1), px);
        }
        let legend = own_legend.then_some(corner.0);
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
            draw_series(&mut chart, panel, legend, y0, y1, (x1 - x0) / px.0)?;
        } else {
            let mut chart = builder.build_cartesian_2d(x0..x1, y0..y1)?;
            // steps and alternatives are counted: their axis is labelled at whole numbers only
            let counted = integer_axis(panel);
            // plotters labels at the finest of 1, 2, 5 × 10ᵏ that gives at most this many
            // labels: one more than the whole units in the range gives a label per unit, as
            // many as fit at 40 px apart across and 25 px up
            let per_unit = |lo: f64, hi: f64, fit: f64| {
                if panel.unit_ticks {
                    ((hi - lo).floor() + 1.0).min(fit).max(2.0) as usize
                } else {
                    10
                }
            };
            chart
                .configure_mesh()
                .x_labels(per_unit(x0, x1, px.0 / 40.0))
                .y_labels(per_unit(y0, y1, px.1 / 25.0))
                .x_desc(&panel.x_label)
                .y_desc(&panel.y_label)
                .x_label_formatter(&|v| if counted { whole(*v) } else { short(*v) })
                .y_label_formatter(&|v| short(*v))
                .draw()?;
            draw_series(&mut chart, panel, legend, y0, y1, (x1 - x0) / px.0)?;
        }
        Ok(())
    }
}

/// A legend entry's picture, 18 px wide from `at`: one element type for every style
/// (plotters needs one), its parts shown or not: a line, dashes, a marker, a ring or a band.
/// A macro, not a function: plotters takes legend pictures as elements of a type free of the
/// drawing back-end, which a generic function cannot name.
macro_rules! glyph {
    ($at:expr, $style:expr, $color:expr) => {{
        let (style, color): (Style, RGBColor) = ($style, $color);
        let show = |yes: bool| if yes { 1.0 } else { 0.0 };
        let (line, dashes, marker, ring, band) = (
            show(style_is(style, Style::Line)),
            show(matches!(style, Style::Line | Style::Dashed)),
            show(style_is(style, Style::Points)),
            show(style_is(style, Style::Rings)),
            show(style_is(style, Style::Band)),
        );
        EmptyElement::at($at)
            + Rectangle::new([(0, -5), (18, 5)], color.mix(0.25 * band).filled())
            + PathElement::new(vec![(0, 0), (7, 0)], color.mix(dashes).stroke_width(2))
            + PathElement::new(vec![(7, 0), (11, 0)], color.mix(line).stroke_width(2))
            + PathElement::new(vec![(11, 0), (18, 0)], color.mix(dashes).stroke_width(2))
            + Circle::new((9, 0), 3, color.mix(marker).filled())
            + Circle::new((9, 0), 5, color.mix(ring).stroke_width(2))
    }};
}

/// The figure's legend in one row under its title (a shared legend): every named series
/// once, by name, in its colour and style as its first panel draws it.
fn legend_row<DB: DrawingBackend>(
    panels: &[Panel],
    area: &DrawingArea<DB, plotters::coord::Shift>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let mut seen: Vec<(String, Style, RGBColor)> = Vec::new();
    for panel in panels {
        for (k, s) in panel.series.iter().enumerate() {
            if !s.name.is_empty() && !seen.iter().any(|(n, _, _)| *n == s.name) {
                seen.push((s.name.clone(), s.style, paint(panel, k)));
            }
        }
    }
    // each entry: its picture, 6 px, its text (5 px a character at 11 px), 18 px to the next
    let widths: Vec<i32> = seen.iter().map(|(n, _, _)| 18 + 6 + 5 * n.chars().count() as i32 + 18).collect();
    let (w, h) = area.dim_in_pixel();
    let mut x = ((w as i32 - widths.iter().sum::<i32>()) / 2).max(4);
    let y = h as i32 / 2;
    for ((name, style, color), width) in seen.iter().zip(&widths) {
        area.draw(&glyph!((x, y), *style, *color))?;
        area.draw(&Text::new(
            name.clone(),
            (x + 24, y),
            TextStyle::from(("sans-serif", 11).into_font()).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        x += width;
    }
    Ok(())
}

fn draw_series<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate<From = (f64, f64)>>(
    chart: &mut ChartContext<'a, DB, CT>,
    panel: &Panel,
    legend: Option<SeriesLabelPosition>,
    y0: f64,
    y1: f64,
    per_px: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    for (k, (x, label)) in panel.markers.iter().enumerate() {
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(*x, y0), (*x, y1)],
            PALETTE[4].stroke_width(1),
        )))?;
        // each label a line lower than the one before, so that two close markers' labels
        // do not print over each other; to the left of its line where another marker's line
        // would cross it on the right
        let share = 0.08 * k as f64;
        let at = if panel.log_y { y1 * (y0 / y1).powf(share) } else { y1 - share * (y1 - y0) };
        let side = if label_left(panel, *x, label, per_px) { HPos::Right } else { HPos::Left };
        chart.draw_series(std::iter::once(Text::new(
            label.clone(),
            (*x, at),
            TextStyle::from(("sans-serif", 11).into_font()).pos(Pos::new(side, VPos::Top)),
        )))?;
    }
    let under = panel.series.iter().any(|s| style_is(s.style, Style::Dashed));
    for (k, s) in panel.series.iter().enumerate() {
        let color = paint(panel, k);
        let pts: Vec<(f64, f64)> =
            s.x.iter()
                .zip(&s.y)
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|(x, y)| (*x, *y))
                .collect();
        let anno = match s.style {
            Style::Line if under => chart.draw_series(LineSeries::new(pts, color.stroke_width(5)))?,
            Style::Line => chart.draw_series(LineSeries::new(pts, color.stroke_width(2)))?,
            // dashes measured in pixels, whatever the sampling
            Style::Dashed => chart.draw_series(DashedLineSeries::new(pts, 7, 4, color.stroke_width(2)))?,
            Style::Points => {
                chart.draw_series(pts.into_iter().map(move |p| Circle::new(p, 3, color.filled())))?
            }
            Style::Rings => {
                chart.draw_series(pts.into_iter().map(move |p| Circle::new(p, 6, color.stroke_width(2))))?
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
            let style = s.style;
            anno.label(s.name.clone()).legend(move |at| glyph!(at, style, color));
        }
    }
    if let Some(position) = legend {
        chart
            .configure_series_labels()
            .position(position)
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
        assert!(matches!(
            legend_corner(&panel, (0.0, 19.0), (0.0, 10.5), (684.0, 168.0)).0,
            SeriesLabelPosition::LowerLeft
        ));
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
