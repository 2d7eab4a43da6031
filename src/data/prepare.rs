//! Preparing a measured run for identification: resample (anti-aliased) to a chosen
//! interval, then for each named signal its rate by the chosen method, added as `<name>_dot`,
//! and, where the method smooths, the smoothed signal in place of the raw one so that the
//! regressors are as clean as the targets.

use super::derivative::Differentiator;
use super::resample::resample;
use super::{DataError, Frame};
use crate::plot::{Figure, Panel, Series};

/// What to do to each run.
pub struct Preparation<'a> {
    /// Resample to this interval first (s), if given.
    pub resample: Option<f64>,
    /// How rates (and smoothed signals) are estimated.
    pub method: &'a dyn Differentiator,
    /// The signals to differentiate (e.g. the states with equations).
    pub signals: Vec<String>,
    /// Replace each signal by the method's smoothed estimate.
    pub smooth: bool,
}

/// The prepared run.
pub fn prepare(frame: &Frame, how: &Preparation) -> Result<Frame, DataError> {
    let mut out = match how.resample {
        Some(dt) => resample(frame, dt)?,
        None => frame.clone(),
    };
    for name in &how.signals {
        let x = out.require(name)?.to_vec();
        let s = how.method.smooth(out.time(), &x).map_err(|e| e.in_run(frame.origin(), Some(name)))?;
        if how.smooth {
            out.set(name, s.value)?;
        }
        out.set(&format!("{name}_dot"), s.rate)?;
    }
    Ok(out)
}

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
    let times = |f: &Frame| f.time().to_vec();
    for name in signals {
        let (k, unit) = scale(name);
        let line = |v: &[f64]| v.iter().map(|v| v * k).collect::<Vec<_>>();
        let (Some(r), Some(p)) = (raw.column(name), prepared.column(name)) else { continue };
        panels.push(Panel {
            title: name.clone(),
            x_label: format!("{} [s]", raw.time_name()),
            y_label: format!("{name} [{unit}]"),
            series: vec![
                Series::points("raw", times(raw), line(r)),
                Series::line("prepared", times(prepared), line(p)),
            ],
            ..Panel::default()
        });
        let Some(d) = prepared.column(&format!("{name}_dot")) else { continue };
        let mut series = Vec::new();
        if let Ok(cd) = super::CentralDifference.differentiate(raw.time(), r) {
            series.push(Series::points("central differences of raw", times(raw), line(&cd)));
        }
        series.push(Series::line("prepared rate", times(prepared), line(d)));
        panels.push(Panel {
            title: format!("d{name}/dt"),
            x_label: format!("{} [s]", raw.time_name()),
            y_label: format!("d{name}/dt [{unit}/s]"),
            series,
            ..Panel::default()
        });
    }
    Figure::new(&format!("{}: raw and prepared signals", raw.origin()), panels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::SmoothingSpline;

    #[test]
    fn adds_rates_and_smooths_in_place() {
        let t: Vec<f64> = (0..400).map(|i| i as f64 * 0.01).collect();
        let mut f = Frame::new("run.csv", "t", t.clone()).unwrap();
        f.push("u", t.iter().map(|t| t * t).collect()).unwrap();
        let spline = SmoothingSpline { alpha: Some(1.0) };
        let how =
            Preparation { resample: Some(0.02), method: &spline, signals: vec!["u".into()], smooth: true };
        let p = prepare(&f, &how).unwrap();
        assert_eq!(p.len(), 200);
        let (u, du) = (p.column("u").unwrap(), p.column("u_dot").unwrap());
        for i in 5..195 {
            let t = p.time()[i];
            assert!((u[i] - t * t).abs() < 1e-3 && (du[i] - 2.0 * t).abs() < 1e-2, "{t}: {} {}", u[i], du[i]);
        }
        let fig = prepared_figure(&f, &p, &how.signals, &|_| (1.0, "m/s".into()));
        assert_eq!(fig.panels.len(), 2);
        let short = Frame::new("short.csv", "t", vec![0.0, 1.0, 2.0]).unwrap();
        let mut short2 = short.clone();
        short2.push("u", vec![0.0; 3]).unwrap();
        let how = Preparation { resample: None, method: &spline, signals: vec!["u".into()], smooth: false };
        let e = prepare(&short2, &how).unwrap_err().to_string();
        assert!(e.contains("short.csv") && e.contains("`u`"), "{e}");
    }
}
