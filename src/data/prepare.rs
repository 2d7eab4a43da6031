//! Preparing a measured run for identification: resample (anti-aliased) to a chosen
//! interval, then for each named signal its rate by the chosen method, added as `<name>_dot`,
//! and, where the method smooths, the smoothed signal in place of the raw one so that the
//! regressors are as clean as the targets.

use super::derivative::Differentiator;
use super::resample::resample;
use super::{cut_at_breaks, cut_at_clips, mark_held_acting, read_at_readings, DataError, Frame, Intersample};

/// The runs of one rate, `state`'s, as its fit reads them: every other of `columns` an input
/// that may be held between samples ([`super::mark_held`]; one of `late` judged as it acts, that many
/// seconds late, one of `lags` by its record alone: [`mark_held_acting`]), any of them (the state too) a slower
/// sensor's readings, read at them ([`read_at_readings`]), and a run cut where the state leaps
/// and stays (records joined in one file: [`cut_at_breaks`]; another column's leap alone is a
/// step of an input) and around where it rests pinned at an end of its range (a sensor
/// clipped: [`cut_at_clips`]). With what was done, a sentence each.
pub fn runs_of_rate(
    frames: Vec<Frame>,
    state: &str,
    columns: &[&str],
    late: &[(&str, f64)],
    lags: &[(&str, f64)],
    intersample: Intersample,
) -> Result<(Vec<Frame>, Vec<String>), DataError> {
    let inputs: Vec<&str> = columns.iter().copied().filter(|n| *n != state).collect();
    let (mut runs, mut notes) = (Vec::new(), Vec::new());
    for mut frame in frames {
        notes.extend(mark_held_acting(&mut frame, &inputs, late, lags, columns, intersample)?);
        notes.extend(read_at_readings(&mut frame, columns, intersample)?);
        let (cut, said) = cut_at_breaks(frame, &[state], &inputs)?;
        notes.extend(said);
        for piece in cut {
            let (pieces, said) = cut_at_clips(piece, &[state])?;
            notes.extend(said);
            runs.extend(pieces);
        }
    }
    Ok((runs, notes))
}

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
        let short = Frame::new("short.csv", "t", vec![0.0, 1.0, 2.0]).unwrap();
        let mut short2 = short.clone();
        short2.push("u", vec![0.0; 3]).unwrap();
        let how = Preparation { resample: None, method: &spline, signals: vec!["u".into()], smooth: false };
        let e = prepare(&short2, &how).unwrap_err().to_string();
        assert!(e.contains("short.csv") && e.contains("`u`"), "{e}");
    }

    /// A rate's runs are cut around where its state rests pinned at the end of its range, as
    /// a model's are: a swing clipped at ±0.6 by its sensor.
    #[test]
    fn a_rate_s_runs_are_cut_around_a_pinned_state() {
        let t: Vec<f64> = (0..1500).map(|k| k as f64 * 0.02).collect();
        let mut f = Frame::new("swing.csv", "t", t.clone()).unwrap();
        f.push("x", t.iter().map(|t| ((-0.05 * t).exp() * (2.0 * t).cos()).clamp(-0.6, 0.6)).collect())
            .unwrap();
        f.push("u", t.iter().map(|t| (0.3 * t).sin()).collect()).unwrap();
        let (runs, notes) = runs_of_rate(vec![f], "x", &["x", "u"], &[], &[], Intersample::Auto).unwrap();
        assert!(
            runs.len() > 1 && notes.iter().any(|n| n.contains("`x` rests at its largest value")),
            "{notes:?}"
        );
    }
}
