//! A state's record pinned at the end of its range: it rests exactly at its largest (or
//! smallest) value over stretches it enters and leaves moving (a sensor clipped at full scale,
//! an amplifier saturated, a body held against a stop). No equation of the smooth candidates
//! turns a motion into such a plateau, and a fit across it takes the record for the motion
//! (a damped oscillator's position clipped at 80 % of its swing: x³ and u·x² beside the truth):
//! the run is cut around the stretches into runs of its own.

use super::breaks::pieces_of;
use super::{DataError, Frame};

/// Fewest equal samples in a row that make a plateau: two are a turning point's rounding.
const PLATEAU: usize = 3;

/// The steps into and out of a plateau are at least this share of the record's median step:
/// a smooth turning point or a rest approached arrives with a step that shrinks to nothing, a
/// clipped motion at its full rate (at 80 % of its swing, 60 % of its largest step).
const MOVING: f64 = 0.1;

/// The steps into and out of a plateau are at least this many of the smallest step beside it,
/// the record's rounding there (a turning point read to counts rests on the top count over a
/// few samples, arrived at by single counts).
const COUNTS: f64 = 3.0;

/// Rows either side of a plateau whose steps tell the record's rounding there.
const BESIDE: usize = 50;

/// A state pinned at one end of its range: its value and the rows of each stretch.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    /// The state.
    pub column: String,
    /// The value it rests at.
    pub value: f64,
    /// Whether that is its largest value (else its smallest).
    pub top: bool,
    /// The stretches, rows `from..to` of the frame.
    pub stretches: Vec<std::ops::Range<usize>>,
}

/// The states of `frame` pinned at either end of their range, each with every stretch at
/// that value: pinned where one plateau of three samples or more at it within the run is
/// entered and left moving (by a tenth of the record's median step, and three of the smallest
/// steps beside it, its rounding there; a rest at a run's start or end is where the run began
/// or was left, a smooth turning point arrives at a crawl). A column held
/// between samples, or read at a slower sensor's readings (repeated between them), is no
/// motion to pin.
pub fn clips(frame: &Frame, states: &[&str]) -> Vec<Clip> {
    let mut found = Vec::new();
    for &name in states {
        if frame.is_held(name) || frame.readings_of(name).is_some() {
            continue;
        }
        let Some(x) = frame.column(name) else { continue };
        let mut steps: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).filter(|d| *d > 0.0).collect();
        if steps.len() < 20 {
            continue;
        }
        let middle = steps.len() / 2;
        let typical = *steps.select_nth_unstable_by(middle, f64::total_cmp).1;
        let least = MOVING * typical;
        let (lo, hi) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        for (value, top) in [(hi, true), (lo, false)] {
            // every stretch at the value, however short, from row to row
            let mut stretches = Vec::new();
            let mut k = 0;
            while k < x.len() {
                if x[k] != value {
                    k += 1;
                    continue;
                }
                let from = k;
                while k < x.len() && x[k] == value {
                    k += 1;
                }
                stretches.push(from..k);
            }
            // a motion crosses the limit between two samples, so the step onto the plateau
            // may be a sliver of a full one: the step before it tells the pace as well
            let step = |a: usize| x.get(a + 1).zip(x.get(a)).map_or(0.0, |(b, a)| (b - a).abs());
            // a record printed to a few significant figures is rounded the coarser the larger
            // it is, on no one grid: its rounding beside the plateau is the smallest step
            // there, which a smooth turning point rests between (MARIN's heading printed to
            // three figures rests on 25.0° for 120 rows, arrived at by steps of 0.1°)
            let rounding = |r: &std::ops::Range<usize>| {
                let beside = r.start.saturating_sub(BESIDE)..r.start.min(x.len() - 1);
                let after = r.end..(r.end + BESIDE).min(x.len() - 1);
                beside.chain(after).map(step).filter(|d| *d > 0.0).fold(f64::INFINITY, f64::min)
            };
            let pinned = |r: &std::ops::Range<usize>| {
                let least = least.max(COUNTS * rounding(r));
                r.len() >= PLATEAU
                    && r.start >= 2
                    && step(r.start - 1).max(step(r.start - 2)) >= least
                    && r.end + 1 < x.len()
                    && step(r.end - 1).max(step(r.end)) >= least
            };
            // pinned once, the value is the range's end: a noisy record touches it for a sample
            // or two between dips, and a run may start or end there; all of them are cut
            if stretches.iter().any(pinned) {
                found.push(Clip { column: name.to_string(), value, top, stretches });
            }
        }
    }
    found
}

/// The run cut around the stretches where a state rests pinned at an end of its range
/// ([`clips`]) into runs of its own, with what to say; the run itself where none is. A piece
/// under 21 rows is left out (said).
pub fn cut_at_clips(frame: Frame, states: &[&str]) -> Result<(Vec<Frame>, Vec<String>), DataError> {
    let found = clips(&frame, states);
    if found.is_empty() {
        return Ok((vec![frame], Vec::new()));
    }
    let sig = |x: f64| crate::output::sig(x, 3);
    let n = frame.len();
    let mut notes: Vec<String> = found
        .iter()
        .map(|c| {
            let rows: usize = c.stretches.iter().map(|s| s.len()).sum();
            let (short, long) = c
                .stretches
                .iter()
                .fold((usize::MAX, 0), |(a, b), s| (a.min(s.len()), b.max(s.len())));
            let first = &c.stretches[0];
            format!(
                "{}: `{}` rests at its {} value, {}, over {} stretch(es) of {} rows ({} % of the rows; the first rows {}-{}, t = {} s), entered and left moving: a sensor at the end of its range (clipped) or a stop the motion meets, which no rate of the candidates holds; the run is cut around them into runs of its own",
                frame.origin(),
                c.column,
                if c.top { "largest" } else { "smallest" },
                sig(c.value),
                c.stretches.len(),
                if short == long { short.to_string() } else { format!("{short} to {long}") },
                sig(100.0 * rows as f64 / n as f64),
                frame.row(first.start),
                frame.row(first.end - 1),
                sig(frame.time()[first.start]),
            )
        })
        .collect();
    let mut out: Vec<std::ops::Range<usize>> =
        found.iter().flat_map(|c| c.stretches.iter().cloned()).collect();
    out.sort_by_key(|r| r.start);
    let mut spans = Vec::new();
    let mut from = 0;
    for r in out {
        if r.start > from {
            spans.push((from, r.start));
        }
        from = from.max(r.end);
    }
    spans.push((from, n));
    let pieces = pieces_of(&frame, &spans, "its pinned stretches", &mut notes)?;
    Ok((pieces, notes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A damped swing x = e^(−0.05t)·cos 2t, sampled every 0.02 s for 30 s.
    fn swing(t: f64) -> f64 {
        (-0.05 * t).exp() * (2.0 * t).cos()
    }

    fn run(x: impl Fn(f64) -> f64) -> Frame {
        let t: Vec<f64> = (0..1500).map(|k| k as f64 * 0.02).collect();
        let mut f = Frame::new("swing.csv", "t", t.clone()).unwrap();
        f.push("x", t.iter().map(|&t| x(t)).collect()).unwrap();
        f
    }

    /// Clipped at ±0.6, the swing's stretches at either end (over its first ten seconds) are
    /// found and cut out, the pieces between kept as runs; the swing itself, the same
    /// printed to counts of 0.01 or to three significant figures (its turning points resting
    /// on a count for a few samples), and a rest at the run's start before it moves are no
    /// plateau.
    #[test]
    fn a_record_pinned_at_the_end_of_its_range_is_cut_around() {
        let clipped = run(|t| swing(t).clamp(-0.6, 0.6));
        let found = clips(&clipped, &["x"]);
        assert_eq!(found.len(), 2, "{found:?}");
        assert!(found[0].top && found[0].value == 0.6 && !found[1].top && found[1].value == -0.6);
        let (pieces, notes) = cut_at_clips(clipped.clone(), &["x"]).unwrap();
        let pinned: usize = found.iter().flat_map(|c| c.stretches.iter().map(|s| s.len())).sum();
        let kept: usize = pieces.iter().map(|p| p.len()).sum();
        assert!(pieces.len() >= 6 && kept == clipped.len() - pinned, "{} pieces, {kept} rows", pieces.len());
        assert!(notes[0].contains("`x` rests at its largest value, 0.600,"), "{notes:?}");
        assert!(clips(&run(swing), &["x"]).is_empty());
        let counts = run(|t| (swing(t) * 100.0).round() / 100.0);
        assert!(clips(&counts, &["x"]).is_empty(), "{:?}", clips(&counts, &["x"]));
        // printed to three significant figures, as MARIN's records are: rounded the coarser
        // the larger, on no one grid; clipped so, still pinned
        let figures = |v: f64| format!("{v:.2e}").parse::<f64>().unwrap();
        let printed = run(|t| figures(5.0 - 4.5 * swing(t / 4.0)));
        assert!(clips(&printed, &["x"]).is_empty(), "{:?}", clips(&printed, &["x"]));
        let printed = run(|t| figures(swing(t).clamp(-0.6, 0.6)));
        assert_eq!(clips(&printed, &["x"]).len(), 2);
        let rest = run(|t| if t < 5.0 { 0.0 } else { 1.0 - swing(t - 5.0) });
        assert!(clips(&rest, &["x"]).is_empty(), "{:?}", clips(&rest, &["x"]));
    }
}
