//! Resampling a run onto a uniform time grid. Going to a coarser interval first low-passes
//! every column with a zero-phase windowed-sinc filter (Blackman window, pass band to 80 % of
//! the new Nyquist frequency), so that noise above it does not fold back into the band the
//! model is identified in; going finer interpolates linearly.

use super::{DataError, Frame};

/// The value of (t, x) at time `s` by linear interpolation, held at the ends. `cursor` is
/// where the last lookup ended: a sweep of increasing times costs one pass (it restarts from
/// the front when `s` goes back). Shared by resampling and the simulator's input replay.
pub fn interpolate_at(t: &[f64], x: &[f64], s: f64, cursor: &mut usize) -> f64 {
    if s <= t[0] {
        return x[0];
    }
    if s >= t[t.len() - 1] {
        return x[t.len() - 1];
    }
    if t[*cursor] > s {
        *cursor = 0;
    }
    while t[*cursor + 1] < s {
        *cursor += 1;
    }
    let i = *cursor;
    let w = (s - t[i]) / (t[i + 1] - t[i]);
    x[i] + w * (x[i + 1] - x[i])
}

/// (t, x) interpolated at every time of `at`.
fn interpolate(t: &[f64], x: &[f64], at: &[f64]) -> Vec<f64> {
    let mut cursor = 0;
    at.iter().map(|&s| interpolate_at(t, x, s, &mut cursor)).collect()
}

/// Low-pass FIR taps: cut-off `fc` and transition `width`, both in cycles per sample.
fn low_pass(fc: f64, width: f64) -> Vec<f64> {
    let half = (2.75 / width).ceil() as i64; // Blackman: ~5.5 / width taps
    let n = (2 * half + 1) as f64;
    let mut taps: Vec<f64> = (-half..=half)
        .map(|k| {
            let k = k as f64;
            let sinc = if k == 0.0 {
                2.0 * fc
            } else {
                (2.0 * std::f64::consts::PI * fc * k).sin() / (std::f64::consts::PI * k)
            };
            let a = 2.0 * std::f64::consts::PI * (k + half as f64) / (n - 1.0);
            sinc * (0.42 - 0.5 * a.cos() + 0.08 * (2.0 * a).cos())
        })
        .collect();
    let sum: f64 = taps.iter().sum();
    taps.iter_mut().for_each(|t| *t /= sum);
    taps
}

/// Symmetric filtering at the samples `at` of `x` alone (a decimation reads one in so many);
/// the ends are extended by odd reflection (2x₀ − x₋ₖ), which keeps a linear trend undistorted
/// up to the last sample.
fn filter_at(x: &[f64], taps: &[f64], at: impl Iterator<Item = usize>) -> Vec<f64> {
    let n = x.len() as i64;
    let half = (taps.len() / 2) as i64;
    let value = |i: i64| -> f64 {
        if i < 0 {
            2.0 * x[0] - x[(-i).min(n - 1) as usize]
        } else if i >= n {
            2.0 * x[(n - 1) as usize] - x[(2 * (n - 1) - i).max(0) as usize]
        } else {
            x[i as usize]
        }
    };
    // the signal with its reflected ends laid out once: each output is then one dot product
    // over a contiguous window
    let padded: Vec<f64> = (-half..n + half).map(value).collect();
    at.map(|i| taps.iter().zip(&padded[i..i + taps.len()]).map(|(w, v)| w * v).sum()).collect()
}

/// The median spacing of a time column.
pub fn median_step(t: &[f64]) -> f64 {
    let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return 0.0;
    }
    steps.sort_by(f64::total_cmp);
    steps[steps.len() / 2]
}

/// The shortest of the runs' median sample intervals: the step that re-simulates every run
/// once per sample (the recorded inputs are known only at the samples).
pub fn sample_step(frames: &[Frame]) -> f64 {
    frames.iter().map(|f| median_step(f.time())).fold(f64::INFINITY, f64::min)
}

/// Refuses a step in time more than `factor` times the median step (a logging gap or a jump).
pub fn check_gaps(frame: &Frame, factor: f64) -> Result<(), DataError> {
    let t = frame.time();
    let median = median_step(t);
    match (1..t.len()).find(|&i| t[i] - t[i - 1] > factor * median) {
        Some(i) => Err(DataError::TimeGap {
            file: frame.origin().into(),
            row: i + 1,
            column: frame.time_name().into(),
            step: t[i] - t[i - 1],
            median,
        }),
        None => Ok(()),
    }
}

/// The frame on the grid t₀, t₀ + dt, … (anti-aliased when dt is coarser than the data).
pub fn resample(frame: &Frame, dt: f64) -> Result<Frame, DataError> {
    let t = frame.time();
    let span = t[t.len() - 1] - t[0];
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(DataError::Setting(format!(
            "the resampling interval must be a positive number of seconds, not {dt}"
        )));
    }
    // the fine grid of the decimation is never coarser than the run's own median step
    let rows = span / dt.min(median_step(t)) + 1.0;
    crate::budget::check_values(
        rows * frame.names().len() as f64,
        || {
            format!(
                "resampling {} rows over {span} s at {dt} s: {} rows × {} columns",
                t.len(),
                crate::budget::count(rows),
                frame.names().len()
            )
        },
        "choose a coarser --resample",
    )
    .map_err(|size| DataError::TooLarge { file: frame.origin().into(), size })?;
    if dt > span / 2.0 {
        return Err(DataError::TooShort {
            file: frame.origin().into(),
            rows: t.len(),
            needed: 3,
            what: format!("resampling at {dt} s over {span} s (needs 0 < dt ≤ half the run)"),
        });
    }
    let grid = |step: f64| -> Vec<f64> {
        let count = (span / step + 1e-9).floor() as usize + 1;
        (0..count).map(|i| t[0] + i as f64 * step).collect()
    };
    let coarse = grid(dt);
    let h = median_step(t);
    let factor = (dt / h * (1.0 - 1e-9)).ceil() as usize;
    // decimation: a uniform fine grid with dt an exact multiple of its step, one filter for
    // every column, keep every factor-th sample
    let fine = (factor > 1)
        .then(|| (grid(dt / factor as f64), low_pass(0.8 * 0.5 / factor as f64, 0.2 * 0.5 / factor as f64)));
    let mut out = Frame::new(frame.origin(), frame.time_name(), coarse.clone())?;
    for name in &frame.names()[1..] {
        let x = frame.require(name)?;
        let values = match &fine {
            None => interpolate(t, x, &coarse),
            Some((fine_t, taps)) => {
                let fine = interpolate(t, x, fine_t);
                let last = fine.len() - 1;
                filter_at(&fine, taps, (0..coarse.len()).map(|i| (i * factor).min(last)))
            }
        };
        out.push(name, values)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(dt: f64, n: usize, f: impl Fn(f64) -> f64) -> Frame {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let mut fr = Frame::new("run.csv", "t", t.clone()).unwrap();
        fr.push("x", t.iter().map(|&t| f(t)).collect()).unwrap();
        fr
    }

    #[test]
    fn decimation_removes_what_would_alias_and_keeps_the_band() {
        // 50 Hz data: a slow 0.2 Hz signal plus a 9 Hz disturbance; at 10 Hz the 9 Hz would
        // fold to 1 Hz, right into the band of a manoeuvre.
        let slow = |t: f64| (2.0 * std::f64::consts::PI * 0.2 * t).sin();
        let f = frame(0.02, 3000, |t| slow(t) + 0.3 * (2.0 * std::f64::consts::PI * 9.0 * t).sin());
        let r = resample(&f, 0.1).unwrap();
        assert_eq!(r.len(), 600);
        assert!((r.time()[1] - 0.1).abs() < 1e-12);
        let x = r.column("x").unwrap();
        let worst = (50..550).map(|i| (x[i] - slow(r.time()[i])).abs()).fold(0.0, f64::max);
        assert!(worst < 0.01, "decimated signal off by {worst}");
        // plain picking of every 5th sample aliases: the 9 Hz stays at full size
        let picked =
            (50..550).map(|i| (f.column("x").unwrap()[5 * i] - slow(r.time()[i])).abs()).fold(0.0, f64::max);
        assert!(picked > 0.25, "{picked}");
    }

    #[test]
    fn finer_grids_interpolate_and_bad_steps_are_refused() {
        let f = frame(0.1, 11, |t| 3.0 * t - 1.0);
        let r = resample(&f, 0.05).unwrap();
        assert_eq!(r.len(), 21);
        for (t, x) in r.time().iter().zip(r.column("x").unwrap()) {
            assert!((x - (3.0 * t - 1.0)).abs() < 1e-12);
        }
        // a line survives decimation exactly, ends included (odd reflection)
        let d = resample(&frame(0.01, 1001, |t| 2.0 * t + 1.0), 0.05).unwrap();
        for (t, x) in d.time().iter().zip(d.column("x").unwrap()) {
            assert!((x - (2.0 * t + 1.0)).abs() < 1e-9, "{t}: {x}");
        }
        assert!(resample(&f, 0.0).is_err() && resample(&f, f64::NAN).is_err() && resample(&f, 0.8).is_err());
    }

    #[test]
    fn gaps_are_named_by_row() {
        let mut t: Vec<f64> = (0..20).map(|i| i as f64 * 0.05).collect();
        t[12..].iter_mut().for_each(|v| *v += 0.5);
        let f = Frame::new("run.csv", "time", t).unwrap();
        let e = check_gaps(&f, 3.0).unwrap_err().to_string();
        assert!(e.contains("run.csv") && e.contains("row 13") && e.contains("`time`"), "{e}");
        assert!(check_gaps(&frame(0.05, 20, |t| t), 3.0).is_ok());
    }
}
