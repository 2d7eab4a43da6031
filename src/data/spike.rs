//! Spikes in a record: one to three samples that leap away from their neighbours and straight
//! back, far beyond the steps beside them and the record's noise. A sampled state cannot do
//! that (its rate is finite) and a command seldom does; a corrupted or misread sample does, and
//! one such sample, differentiated or integrated, buys terms the system does not have.

use super::{DataError, Frame};

/// The widest spike looked for, in samples: a dropout of a few telegrams. Wider excursions
/// that come back are left alone (a pulse a record can follow is the system's).
const WIDEST: usize = 3;
/// How many times the steps beside a spike its leaps in and out must both exceed: a smooth
/// signal's steps are its rate times the sample interval, a spike's are its height.
const BESIDE: f64 = 5.0;
/// How many robust standard deviations of the record's noise a leap must exceed (Gaussian
/// noise leaps that far in one step about once in 10⁷ samples).
const NOISE: f64 = 8.0;
/// The share of the record's span (1st to 99th percentile) a leap must exceed: a record
/// written to three significant figures flickers by a count of 0.1° at 10°, a fine 0.01° below
/// 1°, and a count is not a glitch.
const SPAN: f64 = 0.01;

/// A spike: samples `start..start + width` of a column, `height` off the line through the
/// samples either side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spike {
    /// The first sample (0-based row of the frame).
    pub start: usize,
    /// How many samples, 1 to 3.
    pub width: usize,
    /// The largest distance of its samples from the line through its neighbours.
    pub height: f64,
    /// The larger of the steps beside it.
    pub beside: f64,
}

/// The record's noise as a robust standard deviation: the median absolute deviation of its
/// second differences about 0 (√6 σ for white noise) where they are not 0, and never below its
/// resolution (the smallest step it takes). A quantised signal that mostly holds still (a
/// rudder between its moves) has second differences of 0 and of its flicker by one count:
/// the flicker is its noise, not a spike.
fn noise(x: &[f64]) -> f64 {
    let mut second: Vec<f64> = x.windows(3).map(|w| w[2] - 2.0 * w[1] + w[0]).filter(|e| *e != 0.0).collect();
    let resolution =
        x.windows(2).map(|w| (w[1] - w[0]).abs()).filter(|d| *d > 0.0).fold(f64::INFINITY, f64::min);
    if second.is_empty() {
        return resolution;
    }
    // about 0, not about their median: a signal that flickers mostly one way would have its
    // flicker for a centre
    second.iter_mut().for_each(|e| *e = e.abs());
    let middle = second.len() / 2;
    let (_, median, _) = second.select_nth_unstable_by(middle, f64::total_cmp);
    (1.4826 * *median / 6f64.sqrt()).max(resolution)
}

/// The spikes of one column, in order. A spike needs a sample on either side, so none is
/// found in the first or last sample.
pub fn spikes(x: &[f64]) -> Vec<Spike> {
    let n = x.len();
    if n < 5 {
        return Vec::new();
    }
    // the steps beside alone first: a clean record has no sample that passes them, and its
    // noise and span (two passes and a copy) are not needed
    if search(x, 0.0).is_empty() {
        return Vec::new();
    }
    search(x, (NOISE * noise(x)).max(SPAN * span(x)))
}

/// A record's span from its 1st to its 99th percentile: its range, a glitch or two left out.
pub(super) fn span(x: &[f64]) -> f64 {
    let n = x.len();
    let mut order = x.to_vec();
    let high = *order.select_nth_unstable_by(n * 99 / 100, f64::total_cmp).1;
    let low = *order.select_nth_unstable_by(n / 100, f64::total_cmp).1;
    high - low
}

/// The spikes whose leaps exceed `floor` as well as the steps beside them.
fn search(x: &[f64], floor: f64) -> Vec<Spike> {
    let n = x.len();
    let mut found = Vec::new();
    let step = |i: usize| x[i + 1] - x[i];
    let mut k = 1;
    while k + 1 < n {
        let spike = (1..=WIDEST).filter(|w| k + w < n).find_map(|w| {
            let (enter, leave) = (step(k - 1), step(k + w - 1));
            let leap = enter.abs().min(leave.abs());
            // most samples fail here, before the steps beside are looked at
            if enter * leave >= 0.0 || leap <= floor {
                return None;
            }
            // the steps beside it and, for a wider spike, within it
            let beside = [k.checked_sub(2).map(step), (k + w + 1 < n).then(|| step(k + w))]
                .into_iter()
                .flatten()
                .chain((k..k + w - 1).map(step))
                .fold(0.0, |m: f64, s| m.max(s.abs()));
            let back = (x[k + w] - x[k - 1]).abs();
            let spike = leap > BESIDE * beside && back <= (w + 1) as f64 * leap / BESIDE;
            spike.then(|| {
                let line = |i: usize| x[k - 1] + (x[k + w] - x[k - 1]) * (i + 1 - k) as f64 / (w + 1) as f64;
                let height = (k..k + w).map(|i| (x[i] - line(i)).abs()).fold(0.0, f64::max);
                Spike { start: k, width: w, height, beside }
            })
        });
        match spike {
            Some(s) => {
                found.push(s);
                k += s.width + 1;
            }
            None => k += 1,
        }
    }
    found
}

/// The run with the spikes of `columns` replaced by the line (in time) through the samples
/// either side, with one line to say per column (the rows as its file counts them,
/// [`Frame::row`]); `None` where there is none.
pub fn despiked(frame: &Frame, columns: &[&str]) -> Result<Option<(Frame, Vec<String>)>, DataError> {
    let mut out: Option<Frame> = None;
    let mut notes = Vec::new();
    let t = frame.time();
    for name in columns {
        let Some(column) = frame.column(name) else { continue };
        let found = spikes(column);
        if found.is_empty() {
            continue;
        }
        let mut mended = column.to_vec();
        for s in &found {
            let (a, b) = (s.start - 1, s.start + s.width);
            for i in s.start..b {
                let w = (t[i] - t[a]) / (t[b] - t[a]);
                mended[i] = column[a] + w * (column[b] - column[a]);
            }
        }
        let sig = |x: f64| crate::output::sig(x, 4);
        let place = |s: &Spike| {
            let rows = if s.width == 1 {
                format!("row {}", frame.row(s.start))
            } else {
                format!("rows {}-{}", frame.row(s.start), frame.row(s.start + s.width - 1))
            };
            format!("{} at {rows} (t = {})", sig(s.height), sig(t[s.start]))
        };
        let list: Vec<String> = found.iter().take(3).map(place).collect();
        let more = if found.len() > 3 { format!(" and {} more", found.len() - 3) } else { String::new() };
        let beside = found.iter().map(|s| s.beside).fold(0.0, f64::max);
        notes.push(format!(
            "{}: `{name}` leaps away and straight back by {}{more}, where its steps beside are at most {} and its roughness {}: a glitch in the record, not a motion; replaced by the line through its neighbours (`keep_spikes` keeps it as recorded)",
            frame.origin(),
            list.join(", "),
            sig(beside),
            sig(noise(column))
        ));
        out.get_or_insert_with(|| frame.clone()).overwrite(name, mended)?;
    }
    Ok(out.map(|f| (f, notes)))
}

/// [`despiked`] in every column but the time: a run whose states are not known (a rate's
/// identification without a model).
pub fn despiked_all(frame: &Frame) -> Result<Option<(Frame, Vec<String>)>, DataError> {
    let columns: Vec<&str> = frame.names()[1..].iter().map(String::as_str).collect();
    despiked(frame, &columns)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lorenz_like(n: usize) -> Vec<f64> {
        (0..n).map(|k| 10.0 * (0.05 * k as f64).sin() + 3.0 * (0.013 * k as f64).cos()).collect()
    }

    #[test]
    fn a_glitch_is_found_and_mended() {
        let truth = lorenz_like(400);
        let mut x = truth.clone();
        x[100] += 30.0;
        x[250] -= 4.0;
        x[251] -= 4.1;
        let found = spikes(&x);
        assert_eq!(found.iter().map(|s| (s.start, s.width)).collect::<Vec<_>>(), vec![(100, 1), (250, 2)]);
        assert!((found[0].height - 30.0).abs() < 0.02, "{found:?}");
        let t: Vec<f64> = (0..400).map(|k| 0.01 * k as f64).collect();
        let mut f = Frame::new("run.csv", "t", t).unwrap();
        f.push("x", x).unwrap();
        f.push("u", truth.clone()).unwrap();
        let (g, notes) = despiked(&f, &["x", "u"]).unwrap().unwrap();
        assert_eq!(g.names(), f.names(), "the columns keep their places");
        let mended = g.column("x").unwrap();
        // the line through the neighbours is within the curvature of a smooth signal
        assert!(mended.iter().zip(&truth).all(|(a, b)| (a - b).abs() < 0.03));
        assert!(
            notes.len() == 1
                && notes[0].contains("by 29.99 at row 101 (t = 1.000), 4.101 at rows 251-252 (t = 2.500)"),
            "{notes:?}"
        );
        assert!(despiked(&g, &["x", "u"]).unwrap().is_none());
    }

    #[test]
    fn what_a_record_does_is_not_a_spike() {
        // a step, a ramp's kinks, a triangle's apex, a one-count flicker of a quantised
        // signal, and white noise
        let step: Vec<f64> = (0..50).map(|k| if k < 20 { 0.0 } else { 10.0 }).collect();
        let ramp: Vec<f64> = (0..50).map(|k| (k as f64 - 10.0).clamp(0.0, 20.0)).collect();
        let triangle: Vec<f64> = (0..50).map(|k| 10.0 - (k as f64 - 25.0).abs()).collect();
        let flicker: Vec<f64> = (0..50).map(|k| if k % 7 == 3 { 6.0 } else { 5.0 }).collect();
        // a rudder held between moves, read in 0.1° with a finer count now and then, that
        // flickers by one reading
        let mut held: Vec<f64> = (0..400).map(|k| if k < 200 { 0.0 } else { 10.0 }).collect();
        for k in (10..190).step_by(17) {
            held[k] = 0.1;
        }
        held[300] = 10.1;
        held[320] = 10.01;
        let mut seed = 7u64;
        let noisy: Vec<f64> = (0..20000).map(|_| crate::data::test_noise(&mut seed)).collect();
        for x in [step, ramp, triangle, flicker, held, noisy] {
            assert!(spikes(&x).is_empty(), "{:?}", spikes(&x));
        }
        // a spike in noise is found where it stands out of it
        let mut seed = 3u64;
        let mut noisy: Vec<f64> = (0..2000).map(|_| crate::data::test_noise(&mut seed)).collect();
        noisy[700] += 5.0;
        assert_eq!(spikes(&noisy).iter().map(|s| s.start).collect::<Vec<_>>(), vec![700]);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 256, failure_persistence: None, ..Default::default() })]
        /// A smooth record (three sines of 20 samples a period or more) with or without white
        /// noise has no spike; one sample lifted well beyond its steps, noise and span is
        /// found, exactly there, with its height off the line through its neighbours.
        #[test]
        fn a_lifted_sample_is_found_where_it_is_and_nowhere_else(
            waves in proptest::collection::vec((0.1f64..10.0, 0.001f64..0.05, 0.0f64..6.3), 3),
            noisy in proptest::bool::ANY,
            seed in 0u64..1000,
            at in 5usize..495,
            up in proptest::bool::ANY,
        ) {
            let clean: Vec<f64> = (0..500)
                .map(|k| waves.iter().map(|(a, f, p)| a * (std::f64::consts::TAU * f * k as f64 + p).sin()).sum())
                .collect();
            let span = clean.iter().cloned().fold(f64::MIN, f64::max) - clean.iter().cloned().fold(f64::MAX, f64::min);
            let sigma = if noisy { 0.002 * span } else { 0.0 };
            let mut seed = seed;
            // the sum of twelve uniforms: a normal deviate to 1e-3 in its middle
            let mut x: Vec<f64> = clean
                .iter()
                .map(|c| c + sigma * (0..12).map(|_| crate::data::test_noise(&mut seed)).sum::<f64>())
                .collect();
            proptest::prop_assert!(spikes(&x).is_empty(), "{:?}", spikes(&x));
            let steepest = clean.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max);
            let height = 10.0 * steepest + 20.0 * sigma + 0.03 * span;
            x[at] += if up { height } else { -height };
            let found = spikes(&x);
            proptest::prop_assert_eq!(found.iter().map(|s| (s.start, s.width)).collect::<Vec<_>>(), vec![(at, 1)]);
            let line = (x[at - 1] + x[at + 1]) / 2.0;
            proptest::prop_assert!((found[0].height - (x[at] - line).abs()).abs() < 1e-9);
        }
    }
}
