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

/// The last sample of `t` at or before time `s` (a time within `close` of a sample is on it,
/// [`on_sample`] of the record's own times: a grid k·Δt and a record's times round apart); the
/// first before the record. `cursor` as for [`interpolate_at`]. What a column held between
/// samples ([`super::Frame::hold`]) reads at `s`: shared by reading it back (a dead time) and
/// by the simulator's input replay.
pub fn sample_at(t: &[f64], s: f64, close: f64, cursor: &mut usize) -> usize {
    let n = t.len();
    if t[*cursor] > s + close {
        *cursor = 0;
    }
    while *cursor + 1 < n && t[*cursor + 1] <= s + close {
        *cursor += 1;
    }
    *cursor
}

/// How close to a sample of `t` a time is on it: a millionth of the mean sample interval, or
/// the times' own rounding where they lie far from zero (a logger's Unix time, 1.7·10⁹ s, is
/// read to 2.4·10⁻⁷ s where a millionth of a 50 Hz interval is 2·10⁻⁸ s: a held input's
/// jumps were replayed a sample late).
pub fn on_sample(t: &[f64]) -> f64 {
    (1e-6 * (t[t.len() - 1] - t[0]) / (t.len() - 1).max(1) as f64).max(rounding(t))
}

/// (t, x) interpolated at every time of `at`.
fn interpolate(t: &[f64], x: &[f64], at: &[f64]) -> Vec<f64> {
    let mut cursor = 0;
    at.iter().map(|&s| interpolate_at(t, x, s, &mut cursor)).collect()
}

/// (t, x) at every time of `at` (increasing) by the cubic through the four samples nearest it
/// (the two either side, or the first or last four): Lagrange's, at the samples' own times,
/// exact to O(h⁴) for a smooth record where a line errs by O(h²). Fewer than four samples: a
/// line.
pub fn cubic_at(t: &[f64], x: &[f64], at: &[f64]) -> Vec<f64> {
    if t.len() < 4 {
        return interpolate(t, x, at);
    }
    let mut i = 0;
    at.iter()
        .map(|&s| {
            // the sample at or before s (the first where s comes before it)
            while i + 1 < t.len() && t[i + 1] <= s {
                i += 1;
            }
            let first = i.saturating_sub(1).min(t.len() - 4);
            (first..first + 4)
                .map(|a| {
                    let weight: f64 =
                        (first..first + 4).filter(|&b| b != a).map(|b| (s - t[b]) / (t[a] - t[b])).product();
                    weight * x[a]
                })
                .sum()
        })
        .collect()
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

/// The median spacing of a time column; where the times lie so far from zero that their own
/// rounding is over a billionth of it, the mean of the steps within 1 % of the median (a
/// logger's Unix time, 1.7·10⁹ s, is read to 2.4·10⁻⁷ s: a 50 Hz clock's steps read as
/// 0.01999998 or 0.02000022 s, and a re-simulation's grid k·Δt on the median fell behind the
/// record by 2·10⁻⁸ s a step, its held inputs' jumps a sample late).
pub fn median_step(t: &[f64]) -> f64 {
    let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return 0.0;
    }
    steps.sort_by(f64::total_cmp);
    let median = steps[steps.len() / 2];
    if rounding(t) <= 1e-9 * median.abs() {
        return median;
    }
    let clock: Vec<f64> = steps.into_iter().filter(|d| (d - median).abs() <= 0.01 * median.abs()).collect();
    clock.iter().sum::<f64>() / clock.len() as f64
}

/// How far a time column's values may lie from the numbers written: a few units in the last
/// place of the largest.
fn rounding(t: &[f64]) -> f64 {
    4.0 * f64::EPSILON * t[0].abs().max(t[t.len() - 1].abs())
}

/// The shortest of the runs' median sample intervals: the step that re-simulates every run
/// once per sample (the recorded inputs are known only at the samples).
pub fn sample_step(frames: &[Frame]) -> f64 {
    frames.iter().map(|f| median_step(f.time())).fold(f64::INFINITY, f64::min)
}

/// The step a re-simulation samples a run at: t₁ − t₀, or [`median_step`] where the times'
/// own rounding blurs t₁ − t₀ (times far from zero). `None` for fewer than two samples.
pub fn run_step(t: &[f64]) -> Option<f64> {
    let first = *t.get(1)? - t[0];
    Some(if rounding(t) <= 1e-9 * first.abs() { first } else { median_step(t) })
}

/// Where a run's samples are not where a re-simulation compares them: the first row whose
/// stamp lies more than a tenth of a step off t₀ + k·(t₁ − t₀) (a dropped sample, a clock that
/// drifts from its first step; [`run_step`] for t₁ − t₀), with that stamp and its place.
/// `None` where every one is within it: a re-simulation sampled every t₁ − t₀ meets row k at
/// its k-th sample.
pub fn uneven(t: &[f64]) -> Option<(usize, f64, f64)> {
    let step = run_step(t)?;
    (0..t.len())
        .map(|k| (k, t[k], t[0] + k as f64 * step))
        .find(|(_, at, place)| (at - place).abs() > 0.1 * step)
}

/// The step of a record sampled on a schedule — a pharmacokinetic study's 0.25, 0.5, 1, 2,
/// 4, 8 h, a survey every day then every week — whose median interval is at least 1.5 times
/// its shortest: the shortest itself where every interval is a whole multiple of it (within
/// 2 %: every sample lies on its grid, `true`), else half of it (the schedule's actual times,
/// 0.27 h for 0.25: each sample on a row of its own, `false`).
/// The median step would drop the close samples a fast early phase is read from. `None` for a
/// clock (the median is the shortest, dropouts and jitter aside) and for a grid over 20 times
/// the record's rows (or a million: a log scale, an event log).
fn scheduled_step(t: &[f64]) -> Option<(f64, bool)> {
    let intervals: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let shortest = intervals.iter().copied().fold(f64::INFINITY, f64::min);
    if shortest.is_nan() || shortest <= 0.0 || median_step(t) < 1.5 * shortest {
        return None;
    }
    let whole = intervals.iter().all(|d| (d / shortest - (d / shortest).round()).abs() <= 0.02);
    let step = if whole { shortest } else { 0.5 * shortest };
    let rows = (t[t.len() - 1] - t[0]) / step + 1.0;
    (rows <= (20 * t.len()).min(1_000_000) as f64).then_some((step, whole))
}

/// Intervals that span this ratio (the longest over the shortest) mark a record sampled on a
/// log scale, whose close samples one grid loses.
const LOG_SCALE: f64 = 1000.0;

/// The run on a grid of its median step where its samples are uneven ([`uneven`]), with what
/// to say of it; `None` where they are even.
pub fn evened(frame: &Frame) -> Result<Option<(Frame, String)>, DataError> {
    let Some((row, at, place)) = uneven(frame.time()) else {
        return Ok(None);
    };
    let scheduled = scheduled_step(frame.time());
    let step = scheduled.map_or_else(|| median_step(frame.time()), |(step, _)| step);
    // stamps as a person reads them, not as the binary sums leave them
    let short = |v: f64| (v * 1e9).round() / 1e9;
    let median = short(median_step(frame.time()));
    let onto = match scheduled {
        Some((_, true)) => format!(
            "its shortest step, {} s, on which every sample lies (its intervals are whole multiples of it, as a sampling schedule's are: the median step, {median} s, would lose the close samples; a re-simulation is compared at the samples only)",
            short(step),
        ),
        Some((_, false)) => format!(
            "half its shortest interval, {} s, each sample on a row of its own, a quarter of that interval off at most (the last a step; sampled on a schedule at times of their own: the median step, {median} s, would lose the close samples; a re-simulation is compared at the samples' rows only)",
            short(step),
        ),
        None => format!("its median step, {} s", short(step)),
    };
    let mut note = format!(
        "{}: samples not evenly spaced (row {}: t = {} s where a step of {} s from the first puts it at {} s): resampled onto {onto} (by the cubic through the four nearest samples; a line for a column that steps or leaps), as a re-simulation compares it sample by sample",
        frame.origin(),
        row + 1,
        short(at),
        short(frame.time()[1] - frame.time()[0]),
        short(place),
    );
    // a record sampled on a log scale (stiff kinetics, a relaxation: finely at first, ever
    // more coarsely) loses on one grid what moved between its close samples: said
    let intervals: Vec<f64> = frame.time().windows(2).map(|w| w[1] - w[0]).collect();
    let (shortest, longest) =
        intervals.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), d| (lo.min(*d), hi.max(*d)));
    let lost = intervals.iter().filter(|d| **d < 0.5 * step).count();
    if lost > 0 && shortest > 0.0 && longest >= LOG_SCALE * shortest {
        note += &format!(
            "; {lost} of its {} intervals are shorter than half that step (they run from {} s to {} s: a record sampled on a log scale, as stiff kinetics are): what moved within them is lost, and the even run holds {} rows; such a run is identified in pieces of like spacing (a dataset file's `from` and `to`), each resampled onto its own step",
            intervals.len(),
            crate::output::sig(shortest, 3),
            crate::output::sig(longest, 3),
            ((frame.duration() / step).round() as usize) + 1
        );
    }
    let mut even = resample(frame, step).map_err(|e| {
        DataError::Setting(format!(
            "{}: samples not evenly spaced (row {}), and the run cannot be resampled onto its step: {e}",
            frame.origin(),
            row + 1
        ))
    })?;
    // a record that moves smoothly by the cubic through its four nearest samples (a line's
    // O(h²) error biased Lorenz's damping of y 0.6 % at a jitter of 20 %); one that steps,
    // leaps or changes at every sample stays a line, which does not ring across a jump
    for name in &frame.names()[1..] {
        let x = frame.require(name)?;
        let steps = super::held(x).is_some()
            || super::stepped(x).is_some()
            || super::white(x).is_some()
            || super::repeated(x).is_some()
            || !super::breaks(frame.time(), x).is_empty();
        if !steps {
            let smooth = cubic_at(frame.time(), x, even.time());
            even.set(name, smooth)?;
        }
    }
    // where every sample lies on the grid (a schedule's, a clock's with dropped samples) or
    // has a row of its own (a schedule's own times on a grid of half its shortest interval),
    // the rows between them are the cubic's: a re-simulation is compared at the samples' rows
    // only
    let t0 = even.time()[0];
    // (the grid ends at the last whole step: the last sample is the last row's, a step off
    // at most)
    let reach = match scheduled {
        Some((_, false)) => step * (1.0 + 1e-9),
        _ => (1e-6 * step).max(rounding(frame.time())),
    };
    let mut recorded = vec![false; even.len()];
    let on_grid = frame.time().iter().all(|s| {
        let k = (((s - t0) / step).round() as usize).min(even.len() - 1);
        let hit = (even.time()[k] - s).abs() <= reach && !recorded[k];
        if hit {
            recorded[k] = true;
        }
        hit
    });
    if on_grid {
        even = even.with_recorded(recorded);
    }
    Ok(Some((even, note)))
}

/// Refuses a gap in time ([`super::gaps`]: a step over three times the median, in a record
/// not irregular throughout), where a run cannot be cut ([`super::cut_at_gaps`] cuts one).
pub fn check_gaps(frame: &Frame) -> Result<(), DataError> {
    let t = frame.time();
    let first = match super::gaps(t) {
        super::Gaps::Dropouts(rows) => rows.first().copied(),
        super::Gaps::Irregular { .. } => None,
    };
    match first {
        Some(i) => Err(DataError::TimeGap {
            file: frame.origin().into(),
            row: i + 1,
            column: frame.time_name().into(),
            step: t[i] - t[i - 1],
            median: median_step(t),
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
    let mut out =
        Frame::new(frame.origin(), frame.time_name(), coarse.clone())?.starting_at(frame.row(0) - 1);
    let close = on_sample(t);
    for name in &frame.names()[1..] {
        let x = frame.require(name)?;
        let values = match &fine {
            // a command held between samples is read as held, and one that switches between
            // them as the line across each switch: the filter rang at their jumps (a ±1 force
            // resampled: u² no longer 1, and u³, u²·x chosen)
            _ if frame.is_held(name) => {
                let mut cursor = 0;
                coarse.iter().map(|&s| x[sample_at(t, s, close, &mut cursor)]).collect()
            }
            Some((fine_t, taps)) if !frame.is_switched(name) => {
                let fine = interpolate(t, x, fine_t);
                let last = fine.len() - 1;
                filter_at(&fine, taps, (0..coarse.len()).map(|i| (i * factor).min(last)))
            }
            _ => interpolate(t, x, &coarse),
        };
        match frame.estimated_error(name) {
            Some(error) => out.push_estimated(name, values, error)?,
            None => out.push(name, values)?,
        }
        if frame.is_held(name) {
            out.hold(name)?;
        } else if frame.is_switched(name) {
            out.switch(name)?;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples 0.1 s apart with a jitter of ±20 %: a sine evened by the cubic through its
    /// four nearest samples within 10⁻⁵ (a line would err by 10⁻³), a force held at levels
    /// that step between samples by a line (no overshoot beside a step).
    #[test]
    fn a_jittered_record_is_evened_by_cubics_and_a_stepped_one_by_lines() {
        let mut seed = 4u64;
        let t: Vec<f64> =
            (0..400).map(|k| 0.1 * k as f64 + 0.02 * (crate::data::test_noise(&mut seed) * 2.0)).collect();
        let mut f = Frame::new("jitter.csv", "t", t.clone()).unwrap();
        f.push("x", t.iter().map(|s| s.sin()).collect()).unwrap();
        f.push("F", t.iter().map(|s| if (s / 5.0).floor() as i64 % 2 == 0 { 1.0 } else { -1.0 }).collect())
            .unwrap();
        let (even, note) = evened(&f).unwrap().unwrap();
        assert!(note.contains("cubic"), "{note}");
        let worst = even.time().iter().zip(even.column("x").unwrap()).map(|(s, x)| (x - s.sin()).abs());
        assert!(worst.fold(0.0, f64::max) < 1e-5);
        assert!(even.column("F").unwrap().iter().all(|v| (-1.0..=1.0).contains(v)));
    }

    /// A force held at ±1 between samples, resampled coarser, reads ±1 at every new sample and
    /// stays held (the filter rang at each jump, beyond ±1 and between); a rate estimated
    /// rather than recorded keeps its mark and standard error.
    #[test]
    fn a_held_column_is_resampled_as_held() {
        let t: Vec<f64> = (0..1000).map(|k| k as f64 * 0.01).collect();
        let mut f = Frame::new("held.csv", "t", t.clone()).unwrap();
        f.push("u", t.iter().map(|s| if (s / 2.5).floor() as i64 % 2 == 0 { 1.0 } else { -1.0 }).collect())
            .unwrap();
        f.hold("u").unwrap();
        f.push_estimated("v", t.iter().map(|s| s.cos()).collect(), 0.01).unwrap();
        let coarse = resample(&f, 0.03).unwrap();
        assert!(coarse.column("u").unwrap().iter().all(|&u| u == 1.0 || u == -1.0));
        assert!(coarse.is_held("u"));
        assert_eq!(coarse.estimated_error("v"), Some(0.01));
        f.release("u");
        let filtered = resample(&f, 0.03).unwrap();
        assert!(filtered.column("u").unwrap().iter().any(|&u| u.abs() != 1.0), "a signal is filtered");
    }

    /// A 100 Hz clock stamped in Unix time reads its steps as 0.00999999 or 0.01000023 s (the
    /// stamps' rounding at 1.7·10⁹ s): its step is the clock's, every sample lies on its grid
    /// (the first step's drift left the grid by a tenth of a step within 10 000 rows), and a
    /// time counted from the start k·Δt is on sample k.
    #[test]
    fn unix_time_stamps_keep_their_clock() {
        let t: Vec<f64> =
            (0..30_000).map(|k| format!("{:.2}", 1.7e9 + k as f64 * 0.01).parse().unwrap()).collect();
        assert!((median_step(&t) - 0.01).abs() < 1e-10, "{}", median_step(&t));
        assert!((run_step(&t).unwrap() - 0.01).abs() < 1e-10);
        assert_eq!(uneven(&t), None);
        let from_start: Vec<f64> = t.iter().map(|s| s - t[0]).collect();
        let mut cursor = 0;
        for k in [1, 12_345, 29_999] {
            assert_eq!(sample_at(&from_start, k as f64 * 0.01, on_sample(&t), &mut cursor), k);
        }
        // times near zero keep their first step and a millionth of it
        let near: Vec<f64> = (0..100).map(|k| k as f64 * 0.01).collect();
        assert_eq!(run_step(&near), Some(near[1] - near[0]));
        assert!((on_sample(&near) - 1e-8).abs() < 1e-20);
    }

    /// A dropped sample (a step of two) is found where the first step no longer meets the
    /// row, and the run is put back on its median step; a jitter of a few percent about the
    /// grid is not, a first step that misreads the rate is.
    #[test]
    fn a_dropped_sample_is_found_and_evened() {
        let jitter: Vec<f64> =
            (0..50).map(|k| 0.1 * k as f64 + if k % 3 == 2 { 0.003 } else { 0.0 }).collect();
        assert_eq!(uneven(&jitter), None);
        // a first step 3 % long puts row 4 0.012 s off (row 49 0.15 s): the first step misreads the rate
        let drift: Vec<f64> = (0..50).map(|k| 0.1 * k as f64 + if k == 1 { 0.003 } else { 0.0 }).collect();
        assert_eq!(uneven(&drift).map(|(row, ..)| row), Some(4));
        let dropped: Vec<f64> = (0..50).filter(|k| *k != 7).map(|k| 0.1 * k as f64).collect();
        let (row, at, place) = uneven(&dropped).unwrap();
        assert_eq!(row, 7);
        assert!((at - 0.8).abs() < 1e-12 && (place - 0.7).abs() < 1e-12);
        let mut f = Frame::new("gap.csv", "t", dropped.clone()).unwrap();
        f.push("x", dropped.iter().map(|t| 2.0 * t).collect()).unwrap();
        let (even, note) = evened(&f).unwrap().unwrap();
        assert_eq!(even.len(), 50);
        assert!(uneven(even.time()).is_none());
        // linear between samples: the dropped one's value comes back, compared as none
        assert!((even.column("x").unwrap()[7] - 1.4).abs() < 1e-9);
        assert!(!even.is_sample(7) && (0..50).filter(|k| even.is_sample(*k)).count() == 49);
        assert!(note.contains("gap.csv") && note.contains("row 8"), "{note}");
        assert!(evened(&frame(0.1, 50, |t| t)).unwrap().is_none());
        // three samples (their median step 0.25, too long for the run once), evened onto half
        // the shortest interval; on a schedule of whole steps onto the shortest
        let short = Frame::new("short.csv", "t", vec![0.0, 0.1, 0.35]).unwrap();
        assert_eq!(evened(&short).unwrap().unwrap().0.len(), 8);
        let scheduled = Frame::new("short.csv", "t", vec![0.0, 0.1, 0.3]).unwrap();
        assert_eq!(evened(&scheduled).unwrap().unwrap().0.len(), 4);
        // a dropped sample's intervals span 2: nothing said of a log scale
        assert!(!note.contains("log scale"), "{note}");
    }

    /// A relaxation sampled on a log scale (5 per decade from 1 ms to 100 s, as stiff
    /// kinetics are): one grid of its median step loses the first decades, said with how many
    /// intervals and what to do.
    #[test]
    fn a_record_on_a_log_scale_is_said_to_lose_its_close_samples() {
        let t: Vec<f64> = (0..=25).map(|k| 10f64.powf(-3.0 + k as f64 / 5.0)).collect();
        let mut f = Frame::new("relax.csv", "t", t.clone()).unwrap();
        f.push("x", t.iter().map(|t| (-t).exp()).collect()).unwrap();
        let (_, note) = evened(&f).unwrap().unwrap();
        assert!(note.contains("of its 25 intervals are shorter than half that step"), "{note}");
        assert!(note.contains("a record sampled on a log scale"), "{note}");
        assert!(note.contains("pieces of like spacing"), "{note}");
    }

    /// A pharmacokinetic schedule (0, 0.25, 0.5, 1, 1.5, 2, 3, 4, 6, 8, 12, 16, 24 h): evened
    /// onto its shortest step, where every sample lies (the median step, 1 h, kept 7 of its 13
    /// and lost the absorption); a clock with a dropout, a jittered clock and a log scale keep
    /// their median step.
    #[test]
    fn a_sampling_schedule_is_evened_onto_its_shortest_step() {
        let hours = [0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0];
        let t: Vec<f64> = hours.iter().map(|h| h * 3600.0).collect();
        assert_eq!(scheduled_step(&t), Some((900.0, true)));
        let mut f = Frame::new("pk.csv", "t", t.clone()).unwrap();
        let c = |t: f64| 100.0 * ((-0.15 * t / 3600.0).exp() - (-1.2 * t / 3600.0).exp());
        f.push("C", t.iter().map(|s| c(*s)).collect()).unwrap();
        let (even, note) = evened(&f).unwrap().unwrap();
        assert_eq!(even.len(), 97);
        assert!(note.contains("its shortest step, 900 s, on which every sample lies"), "{note}");
        // the rows between the samples are the cubic's, compared as none
        assert_eq!(even.recorded().unwrap().iter().filter(|r| **r).count(), 13);
        assert!(even.is_sample(0) && !even.is_sample(3) && even.is_sample(4) && even.is_sample(96));
        for (k, s) in t.iter().enumerate() {
            let row = (s / 900.0).round() as usize;
            assert!(
                (even.time()[row] - s).abs() < 1e-9 && (even.column("C").unwrap()[row] - c(*s)).abs() < 1e-9,
                "{k}"
            );
        }
        // the schedule's own times (0.27 h for 0.25, 1.05 for 1 …): half the shortest interval,
        // each sample on a row of its own, the last within a step of the grid's end
        let actual = [0.0, 0.27, 0.52, 1.05, 1.48, 2.03, 3.1, 3.95, 6.05, 8.1, 12.2, 15.9, 24.1];
        let t: Vec<f64> = actual.iter().map(|h| h * 3600.0).collect();
        assert_eq!(
            scheduled_step(&t).map(|(s, whole)| ((s - 450.0).abs() < 1e-9, whole)),
            Some((true, false))
        );
        let mut f = Frame::new("pk.csv", "t", t.clone()).unwrap();
        f.push("C", t.iter().map(|s| c(*s)).collect()).unwrap();
        let (even, note) = evened(&f).unwrap().unwrap();
        assert!(
            note.contains("half its shortest interval, 450 s, each sample on a row of its own"),
            "{note}"
        );
        assert_eq!(even.recorded().unwrap().iter().filter(|r| **r).count(), 13);
        let dropout: Vec<f64> = (0..50).filter(|k| *k != 20).map(|k| k as f64 * 0.1).collect();
        assert_eq!(scheduled_step(&dropout), None);
        let mut seed = 2u64;
        let jitter: Vec<f64> =
            (0..50).map(|k| 0.1 * k as f64 + 0.01 * crate::data::test_noise(&mut seed)).collect();
        assert_eq!(scheduled_step(&jitter), None);
        let log: Vec<f64> = (0..=25).map(|k| 10f64.powf(-3.0 + k as f64 / 5.0)).collect();
        assert_eq!(scheduled_step(&log), None);
    }

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
        let e = check_gaps(&f).unwrap_err().to_string();
        assert!(e.contains("run.csv") && e.contains("row 13") && e.contains("`time`"), "{e}");
        assert!(check_gaps(&frame(0.05, 20, |t| t)).is_ok());
    }
}
