//! The figure of a run's preparation for identification: raw and prepared signals, and the
//! rates beside the raw record's central differences.

use super::{labelled, Figure, Panel, Series};
use crate::data::{CentralDifference, Differentiator, Frame};

/// Raw and prepared signals over time, two panels per signal (its value, and its rate beside
/// the central differences of the raw record, which show the noise the method took out);
/// `scale` gives a display factor and unit per signal (e.g. rad → deg).
pub fn prepared_figure(
    raw: &Frame,
    prepared: &Frame,
    signals: &[String],
    scale: &dyn Fn(&str) -> (f64, String),
) -> Figure {
    let mut panels = Vec::new();
    let mut every_rate = true;
    let times = |f: &Frame| f.time().to_vec();
    for name in signals {
        let (k, unit) = scale(name);
        let line = |v: &[f64]| v.iter().map(|v| v * k).collect::<Vec<_>>();
        let (Some(r), Some(p)) = (raw.column(name), prepared.column(name)) else { continue };
        panels.push(Panel {
            title: name.clone(),
            x_label: format!("{} [s]", raw.time_name()),
            y_label: labelled(name, &unit),
            series: vec![
                Series::points("raw", times(raw), line(r)),
                Series::line("prepared", times(prepared), line(p)),
            ],
            ..Panel::default()
        });
        let Some(d) = prepared.column(&format!("{name}_dot")) else {
            every_rate = false;
            continue;
        };
        // the axis is the prepared rate's (three times its range): differences of a noisy
        // record reach far beyond it and would flatten the rate to a line
        let rate = line(d);
        let (lo, hi) = rate
            .iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(*v), b.max(*v)));
        let span = if hi > lo { hi - lo } else { lo.abs().max(1e-12) };
        let (bottom, top) = (lo - span, hi + span);
        let mut series = Vec::new();
        let mut beyond = 0;
        if let Ok(cd) = CentralDifference.differentiate(raw.time(), r) {
            let (t, v): (Vec<f64>, Vec<f64>) = times(raw)
                .into_iter()
                .zip(line(&cd))
                .filter(|(_, v)| {
                    let inside = *v >= bottom && *v <= top;
                    beyond += usize::from(!inside);
                    inside
                })
                .unzip();
            series.push(Series::points("central differences of raw", t, v));
        }
        series.push(Series::line("prepared rate", times(prepared), rate));
        let clipped =
            if beyond > 0 { format!(" ({beyond} raw differences beyond the axis)") } else { String::new() };
        panels.push(Panel {
            title: format!("d{name}/dt{clipped}"),
            x_label: format!("{} [s]", raw.time_name()),
            y_label: labelled(&format!("d{name}/dt"), &per_second(&unit)),
            series,
            ..Panel::default()
        });
    }
    // a signal a row, its value beside its rate, where every signal has its rate
    let mut fig = Figure::new(&format!("{}: raw and prepared signals", raw.origin()), panels);
    if every_rate {
        fig.columns = 2;
        fig.width = 1100;
        fig.panel_height = 220;
    }
    fig.shared_legend = true;
    fig
}

/// A rate's unit: m/s → m/s², ° → °/s, nothing → 1/s.
fn per_second(unit: &str) -> String {
    match unit {
        "" => "1/s".into(),
        u if u.ends_with("/s") => format!("{u}²"),
        u => format!("{u}/s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{prepare, Preparation, SmoothingSpline};

    #[test]
    fn two_panels_per_signal() {
        let t: Vec<f64> = (0..400).map(|i| i as f64 * 0.01).collect();
        let mut f = Frame::new("run.csv", "t", t.clone()).unwrap();
        f.push("u", t.iter().map(|t| t * t).collect()).unwrap();
        let spline = SmoothingSpline { alpha: Some(1.0) };
        let how =
            Preparation { resample: Some(0.02), method: &spline, signals: vec!["u".into()], smooth: true };
        let p = prepare(&f, &how).unwrap();
        let fig = prepared_figure(&f, &p, &how.signals, &|_| (1.0, "m/s".into()));
        assert_eq!(fig.panels.len(), 2);
        assert_eq!(fig.panels[1].title, "du/dt");
        assert!(fig.to_svg().unwrap().contains("</svg>"));
    }
}
