//! Breaks in a state's record: a leap at one sample that stays, far beyond the steps beside it
//! (two records joined in one file, a sensor re-zeroed, a knock). No motion whose rate is
//! finite crosses one; taken as a motion, every rate and integral across it is wrong and so is
//! every fit (Lorenz, two runs in one file: ten terms where two are). A run is cut where a
//! state breaks into runs of its own, also where it leaps again and again moving between (a
//! bouncing ball); an input that leaps alone is a step of the input. So is a run cut at a gap
//! in its time (a logger's dropout).

use super::{DataError, Frame};

/// A break: the state leaps by `leap` from row `row − 1` to row `row` and goes on from there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Break {
    /// The first row after the leap (0-based row of the frame).
    pub row: usize,
    /// The leap.
    pub leap: f64,
}

/// Rows per break at least: a record that leaps more often is a staircase of its own (a
/// counter, a state read off a coarse scale), not records joined.
const ROWS_PER_BREAK: usize = 1000;

/// The shortest piece kept as a run, in rows: fewer hold no rate worth fitting.
const SHORTEST: usize = 21;

/// How many times a break's step must be off its neighbours' mean more than any step two
/// or three samples away is off theirs (a smooth record's steps change smoothly; a break's
/// flanks are off by half as much, the other way).
const BESIDE: f64 = 5.0;
/// The share of a break's own excess each step beside it must be off the other way at least
/// (a leap's are off by half; a kink's are off by as much on one side and none on the other).
const FLANK: f64 = 0.25;
/// How many robust standard deviations of the steps' roughness it must exceed (Gaussian
/// noise that far about once in 10⁷ samples).
const NOISE: f64 = 8.0;
/// The share of the record's span (1st to 99th percentile) it must exceed: a count of a
/// record printed to a few figures is no break.
const SPAN: f64 = 0.01;

/// The breaks of one record `x` at times `t`: where its slope from one sample to the next is
/// off the mean of the slopes either side (which a smooth record's is by a third difference,
/// and noise by about 1.2 σ/Δt), both slopes beside it off the other way by a quarter of
/// that or more (by half for a leap; a kink, a motion starting at its rate between two
/// samples, is off as much on one side or not at all), far beyond the slopes two and three samples away and the
/// record's roughness so measured, and the leap (that excess times the interval) beyond its
/// resolution (the smallest step it takes) and 1 % of its span. A glitch (away and straight
/// back) is no break: its two steps are off alike. None in the first or last three steps.
pub fn breaks(t: &[f64], x: &[f64]) -> Vec<Break> {
    let n = x.len().min(t.len());
    if n < 9 {
        return Vec::new();
    }
    let steps: Vec<f64> = x[..n].windows(2).map(|w| w[1] - w[0]).collect();
    // per second, so that a longer interval (a dropped sample) is no leap
    let slopes: Vec<f64> = steps.iter().zip(t.windows(2)).map(|(s, w)| s / (w[1] - w[0])).collect();
    // off[k]: slope k off the mean of slopes k − 1 and k + 1 (off[0] and the last unused)
    let mut off = vec![0.0; steps.len()];
    for k in 1..steps.len() - 1 {
        off[k] = slopes[k] - 0.5 * (slopes[k - 1] + slopes[k + 1]);
    }
    let candidates: Vec<usize> = (3..steps.len().saturating_sub(3))
        .filter(|&k| {
            let around = [k - 3, k - 2, k + 2, k + 3].iter().fold(0.0, |m: f64, &j| m.max(off[j].abs()));
            // a leap's flanks are off by half as much the other way, both; a kink's (a rudder
            // starting to turn at its rate) are off by as much, or nothing on one side
            let flank = |j: usize| -off[j] * off[k].signum() >= FLANK * off[k].abs();
            off[k].abs() > BESIDE * around && flank(k - 1) && flank(k + 1)
        })
        .collect();
    if candidates.is_empty() {
        return Vec::new();
    }
    // the roughness and span only where something stood out (most records: nowhere)
    let mut rough: Vec<f64> = off[1..steps.len() - 1].iter().map(|r| r.abs()).collect();
    let middle = rough.len() / 2;
    let sigma = 1.4826 * *rough.select_nth_unstable_by(middle, f64::total_cmp).1;
    // a record printed to a few figures steps by its counts: its resolution is its noise
    let resolution = steps.iter().map(|s| s.abs()).filter(|s| *s > 0.0).fold(f64::INFINITY, f64::min);
    let span = super::spike::span(&x[..n]);
    // the leap in the record's units: the slope's excess over its interval
    let leap = |k: usize| off[k] * (t[k + 1] - t[k]);
    candidates
        .into_iter()
        .filter(|&k| off[k].abs() > NOISE * sigma && leap(k).abs() > (NOISE * resolution).max(SPAN * span))
        .map(|k| Break { row: k + 1, leap: leap(k) })
        .collect()
}

/// The breaks of the `columns` of `frame` that cut it, as (row, column, leap) in row order,
/// and what to say of the columns that leap too often to be records joined (more than one
/// row in a thousand and more than three: a staircase of its own, a counter or a coarse
/// scale), which cut nothing. Only records that move from sample to sample are looked at: a
/// command stepped at isolated samples ([`super::held`], a step test's force) or marked held
/// ([`Frame::is_held`]) jumps by design.
pub fn moving_breaks<'a>(frame: &Frame, columns: &[&'a str]) -> Leaps<'a> {
    let n = frame.len();
    let (mut found, mut notes, mut resets) = (Vec::new(), Vec::new(), Vec::new());
    // a command held or switched for one or two samples and back (a telegraph's pulse) moves
    // the states it drives by a step that stays: no break there (one stepped at every sample,
    // white, pulses everywhere, and its states' steps are all alike rough: none stands out)
    let pulses: Vec<usize> = frame
        .held()
        .iter()
        .chain(frame.switched())
        .filter_map(|c| frame.column(c))
        .filter(|x| super::white(x).is_none())
        .flat_map(|x| {
            (1..x.len().saturating_sub(1)).filter(move |&i| {
                x[i] != x[i - 1] && (x[i + 1] != x[i] || x.get(i + 2).is_some_and(|v| *v != x[i]))
            })
        })
        .collect();
    let by_a_command = |row: usize| pulses.iter().any(|&j| j.abs_diff(row) <= 2);
    for name in columns {
        let Some(column) = moving(frame, name) else { continue };
        let mut b = breaks(frame.time(), column);
        b.retain(|b| !by_a_command(b.row));
        if b.len() > 3 && b.len() * ROWS_PER_BREAK > n && moves_between(column, &b) {
            // a motion reset again and again (a ball's bounces, a relay's resets): the
            // rates hold between the leaps, none across them
            notes.push(format!(
                "{}: `{name}` leaps at {} rows and stays (the first from row {} to row {}, t = {} s), moving between its leaps as much as it leaps: a motion reset at each (an impact, a bounce, a dose, a reset), whose rule no rate holds; the run is cut at each into runs of their own: the equations found hold between the leaps, not across them",
                frame.origin(),
                b.len(),
                frame.row(b[0].row - 1),
                frame.row(b[0].row),
                crate::output::sig(frame.time()[b[0].row], 3)
            ));
            resets.push(*name);
        } else if b.len() > 3 && b.len() * ROWS_PER_BREAK > n {
            notes.push(format!(
                "{}: `{name}` leaps at {} rows and stays (from row {}), far beyond its steps beside: too often for records joined in one file; taken as recorded, its rate spikes there",
                frame.origin(),
                b.len(),
                frame.row(b[0].row)
            ));
            continue;
        }
        found.extend(b.iter().map(|b| (b.row, *name, b.leap)));
    }
    found.sort_by_key(|f| f.0);
    Leaps { found, notes, resets }
}

/// What [`moving_breaks`] finds.
#[derive(Clone, Debug, Default)]
pub struct Leaps<'a> {
    /// Where the columns break, as (row, column, leap) in row order: each cuts the run.
    pub found: Vec<(usize, &'a str, f64)>,
    /// What to say of the columns that leap too often to be records joined.
    pub notes: Vec<String>,
    /// Of those, the columns that move between their leaps as much as they leap (a motion
    /// reset at each: a bounce), whose leaps are in `found`, said once in `notes`.
    pub resets: Vec<&'a str>,
}

/// Whether a record moves between its leaps by a quarter of its typical leap or more, over a
/// run's rows at least ([`SHORTEST`]), in most pieces between them (a ball's speed between
/// bounces): not holding still between them as a staircase does (a state read off a coarse
/// scale, a counter), nor leaping every few rows as a rough record may, whose pieces would
/// hold no run.
fn moves_between(x: &[f64], breaks: &[Break]) -> bool {
    let mut leaps: Vec<f64> = breaks.iter().map(|b| b.leap.abs()).collect();
    let middle = leaps.len() / 2;
    let typical = *leaps.select_nth_unstable_by(middle, f64::total_cmp).1;
    let moved = breaks
        .windows(2)
        .filter(|w| {
            let piece = &x[w[0].row..w[1].row];
            let (lo, hi) =
                piece.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
            w[1].row - w[0].row >= SHORTEST && hi - lo >= 0.25 * typical
        })
        .count();
    2 * moved > breaks.len() - 1
}

/// Column `name` of `frame` where it records a motion that may break: not a command stepped
/// at isolated samples ([`super::held`]) nor one marked held ([`Frame::is_held`]), which jump
/// by design.
fn moving<'f>(frame: &'f Frame, name: &str) -> Option<&'f [f64]> {
    let column = frame.column(name)?;
    (!frame.is_held(name) && super::held(column).is_none()).then_some(column)
}

/// The run cut where a recorded state leaps at one sample and stays ([`moving_breaks`] of
/// `states` and `inputs`) into runs of their own (each named by its origin and its rows in it:
/// "run.csv [rows 1001-2000]"), with what to say; the run itself where none breaks. A piece
/// under 21 rows is left out (said). An input that leaps where no state does is a step of the
/// input (a command switched on top of its motion, a measured force stepped with its noise):
/// the system went on through it, so it cuts nothing and is said (were it a sensor re-zeroed,
/// the rows after it are off by the leap); it is marked switched ([`Frame::switch`]), so that a
/// rate's fit leaves out the windows that hold its leaps.
pub fn cut_at_breaks(
    mut frame: Frame,
    states: &[&str],
    inputs: &[&str],
) -> Result<(Vec<Frame>, Vec<String>), DataError> {
    let sig = |x: f64| crate::output::sig(x, 3);
    let Leaps { mut found, mut notes, resets } = moving_breaks(&frame, states);
    let mut cuts: Vec<usize> = found.iter().map(|f| f.0).collect();
    cuts.dedup();
    // an input's leaps, however many (they cut nothing: no staircase rule)
    for input in inputs.iter().filter(|i| !states.contains(i)) {
        let Some(column) = moving(&frame, input) else { continue };
        found.extend(breaks(frame.time(), column).iter().map(|b| (b.row, *input, b.leap)));
    }
    // said in the frame's order of columns
    let position = |c: &str| frame.names().iter().position(|n| n == c);
    found.sort_by_key(|f| (f.0, position(f.1)));
    // an input's leaps where no state leaps: one note per input
    for input in inputs.iter().filter(|i| !states.contains(i)) {
        let steps: Vec<&(usize, &str, f64)> =
            found.iter().filter(|f| f.1 == *input && !cuts.contains(&f.0)).collect();
        let Some(first) = steps.first() else { continue };
        let still = match states {
            [one] => format!("`{one}` does not leap"),
            _ => "no state leaps".to_string(),
        };
        let at = if steps.len() == 1 {
            format!(
                "by {} from row {} to row {} (t = {} s)",
                sig(first.2),
                frame.row(first.0 - 1),
                frame.row(first.0),
                sig(frame.time()[first.0])
            )
        } else {
            let rows: Vec<String> = steps.iter().take(4).map(|s| frame.row(s.0).to_string()).collect();
            format!(
                "at {} rows ({}{}; the first by {} at t = {} s)",
                steps.len(),
                rows.join(", "),
                if steps.len() > 4 { ", …" } else { "" },
                sig(first.2),
                sig(frame.time()[first.0])
            )
        };
        notes.push(format!(
            "{}: `{input}` leaps {at} and stays, where {still} with it: a step of the input (a command switched), not cut there; a rate's fit leaves out the windows of the weak or integral form that hold a leap (a replay, as `estimate` and `validate` make, takes it as a line between the two samples: when between them it stepped is not recorded); were it a sensor re-zeroed, the rows after it would be off by the leap",
            frame.origin()
        ));
        frame.switch(input)?;
    }
    if cuts.is_empty() {
        return Ok((vec![frame], notes));
    }
    let t = frame.time();
    for &row in &cuts {
        let leaps: Vec<String> = found
            .iter()
            .filter(|f| f.0 == row && !resets.contains(&f.1))
            .map(|(_, name, leap)| format!("`{name}` (by {})", sig(*leap)))
            .collect();
        // a reset's leaps are said once, for its column
        if leaps.is_empty() {
            continue;
        }
        let (verb, whose) = if leaps.len() == 1 { ("leaps", "its") } else { ("leap", "their") };
        notes.push(format!(
            "{}: {} {verb} from row {} to row {} (t = {} s), far beyond {whose} steps beside, and {} there: no motion crosses that in one sample (two records joined in one file, a sensor re-zeroed, a knock); the run is cut there into runs of its own",
            frame.origin(),
            leaps.join(", "),
            frame.row(row - 1),
            frame.row(row),
            sig(t[row]),
            if leaps.len() == 1 { "stays" } else { "stay" },
        ));
    }
    let pieces = into_pieces(&frame, &cuts, 0, "breaks", &mut notes)?;
    Ok((pieces, notes))
}

/// `frame` cut before each row of `cuts` into runs of their own, each named by its origin and
/// its rows in it, `margin` rows left out beside each cut; a piece under 21 rows left out,
/// said in `notes` as between `what`.
fn into_pieces(
    frame: &Frame,
    cuts: &[usize],
    margin: usize,
    what: &str,
    notes: &mut Vec<String>,
) -> Result<Vec<Frame>, DataError> {
    let n = frame.len();
    let bounds: Vec<usize> =
        std::iter::once(0).chain(cuts.iter().copied()).chain(std::iter::once(n)).collect();
    let spans: Vec<(usize, usize)> = bounds
        .windows(2)
        .enumerate()
        .map(|(k, w)| {
            // the margin only beside a cut, not at the run's own ends
            let a = if k == 0 { w[0] } else { w[0] + margin };
            let b = if k + 2 == bounds.len() { w[1] } else { w[1].saturating_sub(margin) };
            (a, b)
        })
        .collect();
    pieces_of(frame, &spans, what, notes)
}

/// The rows `spans` (from, to) of `frame` as runs of their own, each named by its origin and
/// its rows in it; a piece under 21 rows left out, said in `notes` as between `what`.
pub(super) fn pieces_of(
    frame: &Frame,
    spans: &[(usize, usize)],
    what: &str,
    notes: &mut Vec<String>,
) -> Result<Vec<Frame>, DataError> {
    let (mut pieces, mut short) = (Vec::new(), Vec::new());
    let mut longest = 0;
    for &(a, b) in spans {
        let rows = b.saturating_sub(a);
        longest = longest.max(rows);
        if rows < SHORTEST {
            short.push((a, rows));
            continue;
        }
        let mut piece = frame.slice(a..b);
        // a piece of a piece is named by its rows in the file alone
        let file = frame.origin().split(" [rows ").next().unwrap_or_default();
        piece.origin = format!("{file} [rows {}-{}]", frame.row(a), frame.row(b - 1));
        pieces.push(piece);
    }
    match short.as_slice() {
        [] => {}
        [(a, rows)] => notes.push(format!(
            "{} [rows {}-{}]: {rows} row(s) between {what}, too few for a run: left out",
            frame.origin(),
            frame.row(*a),
            frame.row(*a) + rows - 1
        )),
        many => {
            let some: Vec<String> = many
                .iter()
                .take(3)
                .map(|(a, rows)| format!("{}-{}", frame.row(*a), frame.row(*a) + rows - 1))
                .collect();
            notes.push(format!(
                "{}: {} pieces between {what} under {SHORTEST} rows each, too few for a run: left out (rows {}{}; {} rows in all)",
                frame.origin(),
                many.len(),
                some.join(", "),
                if many.len() > 3 { ", …" } else { "" },
                many.iter().map(|s| s.1).sum::<usize>()
            ))
        }
    }
    if pieces.is_empty() {
        return Err(DataError::TooShort {
            file: frame.origin().into(),
            rows: longest,
            needed: SHORTEST,
            what: format!("a run between its {what} (the longest piece's rows)"),
        });
    }
    Ok(pieces)
}

/// An interval over this many times the median is a gap in the record (a dropout).
const GAP: f64 = 3.0;

/// Gaps in more than this share of the intervals make a log irregular (asynchronous, sampled
/// on events), not a clock with dropouts.
const IRREGULAR: f64 = 0.05;

/// Gaps in at least this share of the intervals make a log irregular however few they are.
const IRREGULAR_FEW: f64 = 0.2;

/// What a record's time says of its gaps ([`gaps`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Gaps {
    /// A clock with dropouts: the rows after intervals over three times the median (none: a
    /// record without gaps).
    Dropouts(Vec<usize>),
    /// A log irregular throughout (asynchronous, sampled on events), whose spacing is its own.
    Irregular {
        /// The share of its intervals over three times the median.
        share: f64,
        /// The longest interval, in the time's units.
        longest: f64,
    },
}

/// The gaps of a record's time `t`: intervals over three times the median are dropouts,
/// unless they are over 5 % of the intervals and more than three, or a fifth of them at least
/// (an irregular log: a dozen samples at 0.25, 0.5, 1, 2, 4 … 24 h, as a pharmacokinetic
/// study takes them, is no clock with three dropouts).
pub fn gaps(t: &[f64]) -> Gaps {
    let median = super::median_step(t);
    let rows: Vec<usize> = (1..t.len()).filter(|&i| t[i] - t[i - 1] > GAP * median).collect();
    let share = rows.len() as f64 / (t.len() - 1) as f64;
    if (rows.len() > 3 && share > IRREGULAR) || share >= IRREGULAR_FEW {
        let longest = t.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        return Gaps::Irregular { share, longest };
    }
    Gaps::Dropouts(rows)
}

/// The run cut at the gaps in its time ([`gaps`]: a logger's dropouts, where the record
/// stops and goes on later) into runs of their own, `margin` rows left out beside each gap (rows
/// a difference across the gap has spoiled), with what to say; an integral or a derivative
/// across a gap would take the motion in it as a line. A log whose spacing is irregular
/// throughout is taken as it is (said).
pub fn cut_at_gaps(frame: Frame, margin: usize) -> Result<(Vec<Frame>, Vec<String>), DataError> {
    let t = frame.time();
    let sig = |x: f64| crate::output::sig(x, 3);
    let median = super::median_step(t);
    let cuts = match gaps(t) {
        Gaps::Dropouts(cuts) if cuts.is_empty() => return Ok((vec![frame], Vec::new())),
        Gaps::Dropouts(cuts) => cuts,
        Gaps::Irregular { share, longest } => {
            let note = format!(
                "{}: `{}` steps irregularly ({:.0} % of its intervals over {GAP} times its median, {} s; the longest {} s): a log sampled on events, not a clock with dropouts: not cut at its long intervals",
                frame.origin(),
                frame.time_name(),
                100.0 * share,
                sig(median),
                sig(longest)
            );
            return Ok((vec![frame], vec![note]));
        }
    };
    let step = |i: usize| sig(t[i] - t[i - 1]);
    let at = match cuts.as_slice() {
        [one] => format!(
            "by {} s from row {} to row {} (t = {} s)",
            step(*one),
            frame.row(one - 1),
            frame.row(*one),
            sig(t[*one])
        ),
        many => {
            let rows: Vec<String> = many.iter().take(4).map(|r| frame.row(*r).to_string()).collect();
            let longest = many.iter().map(|&i| t[i] - t[i - 1]).fold(0.0, f64::max);
            format!(
                "at {} rows ({}{}; the longest {} s)",
                many.len(),
                rows.join(", "),
                if many.len() > 4 { ", …" } else { "" },
                sig(longest)
            )
        }
    };
    let mut notes = vec![format!(
        "{}: `{}` jumps {at}, where its usual step is {} s: a gap in the record (a logger's dropout); the run is cut there into runs of its own{}",
        frame.origin(),
        frame.time_name(),
        sig(median),
        if margin > 0 { format!(", {margin} rows beside each gap left out") } else { String::new() }
    )];
    let pieces = into_pieces(&frame, &cuts, margin, "gaps", &mut notes)?;
    Ok((pieces, notes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` samples 0.1 s apart.
    fn clock(n: usize) -> Vec<f64> {
        (0..n).map(|k| 0.1 * k as f64).collect()
    }

    /// A smooth record that jumps by 5 at row 300 and goes on from the new level: one break,
    /// at row 300, by 5 (and the steps there are the motion's).
    #[test]
    fn a_leap_that_stays_is_a_break() {
        let x: Vec<f64> =
            (0..600).map(|k| (0.02 * k as f64).sin() + if k >= 300 { 5.0 } else { 0.0 }).collect();
        let b = breaks(&clock(x.len()), &x);
        assert_eq!(b.len(), 1, "{b:?}");
        assert_eq!(b[0].row, 300);
        assert!((b[0].leap - 5.0).abs() < 0.03, "{b:?}");
        let smooth: Vec<f64> = (0..600).map(|k| (0.02 * k as f64).sin()).collect();
        assert!(breaks(&clock(smooth.len()), &smooth).is_empty());
        // a sample dropped from a record that moves fast (a step 4 % of its span): the
        // interval is twice as long, the slope across it the motion's
        let fast: Vec<f64> = (0..600).map(|k| (0.3 * k as f64).sin()).collect();
        let (mut t, mut dropped) = (clock(600), fast.clone());
        t.remove(300);
        dropped.remove(300);
        assert!(breaks(&t, &dropped).is_empty(), "{:?}", breaks(&t, &dropped));
    }

    /// Not breaks: a glitch (away and straight back), counts of a slow ramp, noise, a steady
    /// rate printed to three figures (76.0, 76.1, 75.9: MARIN's propeller).
    #[test]
    fn glitches_counts_and_noise_are_not_breaks() {
        let mut glitch: Vec<f64> = (0..600).map(|k| (0.02 * k as f64).sin()).collect();
        glitch[200] += 3.0;
        assert!(breaks(&clock(glitch.len()), &glitch).is_empty());
        let counts: Vec<f64> = (0..1000).map(|k| (k as f64 / 7.3).floor()).collect();
        assert!(breaks(&clock(counts.len()), &counts).is_empty());
        let mut seed = 9u64;
        let noisy: Vec<f64> =
            (0..5000).map(|k| (0.01 * k as f64).sin() + 0.05 * crate::data::test_noise(&mut seed)).collect();
        assert!(breaks(&clock(noisy.len()), &noisy).is_empty());
        let flicker: Vec<f64> = (0..2000)
            .map(|_| {
                let n = crate::data::test_noise(&mut seed);
                76.0 + if n > 0.45 {
                    0.1
                } else if n < -0.45 {
                    -0.1
                } else {
                    0.0
                }
            })
            .collect();
        assert!(breaks(&clock(flicker.len()), &flicker).is_empty());
    }

    /// Not breaks: a rudder turned at its rate from one angle to the next, 1.5° a sample,
    /// starting and stopping between samples and standing in between (its kinks are off
    /// alike on both sides, or on one side only), noise-free; a leap on its way still is.
    #[test]
    fn a_rudder_turned_at_its_rate_is_no_break() {
        let rate = 15.0;
        let angle = |t: f64| {
            // from 10° to −10° starting at 5.23 s, back at 20.57 s, and so on every 15.34 s
            let cycle = (t - 5.23).rem_euclid(30.68);
            let turned = |since: f64| (rate * since).min(20.0);
            if t < 5.23 {
                10.0
            } else if cycle < 15.34 {
                10.0 - turned(cycle)
            } else {
                -10.0 + turned(cycle - 15.34)
            }
        };
        let t = clock(3000);
        let rudder: Vec<f64> = t.iter().map(|&s| angle(s)).collect();
        assert!(breaks(&t, &rudder).is_empty(), "{:?}", breaks(&t, &rudder));
        let mut knocked = rudder;
        knocked[1200..].iter_mut().for_each(|d| *d += 2.0);
        assert_eq!(breaks(&t, &knocked).iter().map(|b| b.row).collect::<Vec<_>>(), [1200]);
    }

    /// Two records in one frame: cut into two runs named by their rows (the file's, for a
    /// piece of it), said once with both states that leap; a piece of 10 rows at the end left
    /// out, said; a column that is not a state (a command stepped) cuts nothing.
    #[test]
    fn joined_records_are_cut_into_runs() {
        let t: Vec<f64> = (0..610).map(|k| 0.1 * k as f64).collect();
        let mut f = Frame::new("joined.csv", "t", t.clone()).unwrap();
        let level = |k: usize| match k {
            0..300 => 0.0,
            300..600 => 4.0,
            _ => -3.0,
        };
        f.push("x", (0..610).map(|k| (0.2 * t[k]).sin() + level(k)).collect()).unwrap();
        f.push("y", (0..610).map(|k| (0.2 * t[k]).cos() - level(k)).collect()).unwrap();
        f.push("F", (0..610).map(|k| if k % 100 < 50 { 1.0 } else { -1.0 }).collect()).unwrap();
        let (runs, notes) = cut_at_breaks(f.clone(), &["x", "y"], &["F"]).unwrap();
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0].origin(), "joined.csv [rows 1-300]");
        assert_eq!((runs[1].origin(), runs[1].len()), ("joined.csv [rows 301-600]", 300));
        assert_eq!(runs[1].time()[0], t[300]);
        assert_eq!(notes.len(), 3, "{notes:?}");
        assert!(
            notes[0].contains("`x` (by 4.00), `y` (by -4.00) leap from row 300 to row 301 (t = 30.0 s)"),
            "{}",
            notes[0]
        );
        assert!(notes[2].contains("[rows 601-610]: 10 row(s) between breaks"), "{}", notes[2]);
        // a piece of the file (rows 201-610, as a gap or a trimmed window leaves it) names the
        // file's rows, not its own
        let (runs, notes) = cut_at_breaks(f.slice(200..610), &["x", "y"], &["F"]).unwrap();
        assert_eq!(runs[1].origin(), "joined.csv [rows 301-600]");
        assert!(notes[0].contains("leap from row 300 to row 301"), "{}", notes[0]);
        let (pieces, _) = cut_at_breaks(runs[1].clone(), &["x", "y"], &["F"]).unwrap();
        assert_eq!(pieces[0].origin(), "joined.csv [rows 301-600]");
        let (whole, said) = cut_at_breaks(f.clone(), &[], &["F"]).unwrap();
        assert_eq!((whole.len(), said.len()), (1, 0));
        // a held input stepped at every sample beside (white) hides no break; a telegraph's
        // pulse of one sample at the break does
        let mut seed = 2u64;
        let mut white = f.clone();
        white.push("W", (0..610).map(|_| crate::data::test_noise(&mut seed)).collect()).unwrap();
        white.hold("W").unwrap();
        assert_eq!(cut_at_breaks(white, &["x", "y"], &["F", "W"]).unwrap().0.len(), 2);
        let mut pulsed = f;
        pulsed.push("P", (0..610).map(|k| if k == 300 { 1.0 } else { 0.0 }).collect()).unwrap();
        pulsed.hold("P").unwrap();
        let (runs, notes) = cut_at_breaks(pulsed, &["x", "y"], &["F", "P"]).unwrap();
        assert_eq!(runs.len(), 1, "{notes:?}");
    }

    /// A measured input that moves (with its noise) and steps twice while the state goes on
    /// smoothly: a step of the input, not records joined: not cut, said once with its rows,
    /// and marked switched (a fit leaves out the windows that hold its steps). Where the state
    /// leaps at the same row, the run is cut as before.
    #[test]
    fn an_input_that_steps_alone_cuts_nothing() {
        let t: Vec<f64> = (0..600).map(|k| 0.1 * k as f64).collect();
        let mut seed = 4u64;
        let level = |k: usize| match k {
            0..200 => 0.0,
            200..400 => 3.0,
            _ => 1.0,
        };
        let force: Vec<f64> =
            (0..600).map(|k| level(k) + 0.01 * crate::data::test_noise(&mut seed)).collect();
        let mut f = Frame::new("rig.csv", "t", t.clone()).unwrap();
        f.push("x", t.iter().map(|t| (0.2 * t).sin()).collect()).unwrap();
        f.push("F", force).unwrap();
        let (runs, notes) = cut_at_breaks(f.clone(), &["x"], &["F"]).unwrap();
        assert_eq!(runs.len(), 1);
        assert!(runs[0].is_switched("F") && !runs[0].is_switched("x"));
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].contains("`F` leaps at 2 rows (201, 401; the first by 3.0")
                && notes[0].contains("`x` does not leap"),
            "{}",
            notes[0]
        );
        assert_eq!(crate::data::switches(&t, runs[0].column("F").unwrap()), vec![200, 400]);
        let mut joined = f;
        joined
            .overwrite("x", t.iter().enumerate().map(|(k, t)| (0.2 * t).sin() + level(k)).collect())
            .unwrap();
        let (runs, notes) = cut_at_breaks(joined, &["x"], &["F"]).unwrap();
        assert_eq!(runs.len(), 3, "{notes:?}");
        assert!(notes[0].contains("`x` (by 3.00), `F` (by 3.0"), "{}", notes[0]);
    }

    /// A clock of 0.1 s with two dropouts (0.5 s and 1.2 s): cut into three runs named by
    /// their rows, said once; with a margin of 2, two rows beside each gap left out (not at
    /// the run's ends). A log sampled on events (exponential intervals) is not cut, said; a
    /// clock without dropouts, nothing said. Pieces too short are said together.
    #[test]
    fn a_run_is_cut_at_its_gaps() {
        let mut t = clock(300);
        t[100..].iter_mut().for_each(|v| *v += 0.4);
        t[200..].iter_mut().for_each(|v| *v += 1.1);
        let run = |t: Vec<f64>| {
            let mut f = Frame::new("log.csv", "t", t.clone()).unwrap();
            f.push("x", t.iter().map(|t| t.sin()).collect()).unwrap();
            f
        };
        let (runs, notes) = cut_at_gaps(run(t.clone()), 0).unwrap();
        let names: Vec<&str> = runs.iter().map(Frame::origin).collect();
        assert_eq!(names, ["log.csv [rows 1-100]", "log.csv [rows 101-200]", "log.csv [rows 201-300]"]);
        assert_eq!(notes.len(), 1);
        assert!(notes[0].contains("`t` jumps at 2 rows (101, 201; the longest 1.20 s)"), "{}", notes[0]);
        let (runs, _) = cut_at_gaps(run(t.clone()), 2).unwrap();
        assert_eq!(runs.iter().map(Frame::len).collect::<Vec<_>>(), [98, 96, 98]);
        assert_eq!(runs[1].time()[0], t[102]);
        let mut seed = 12u64;
        let mut at = 0.0;
        let events: Vec<f64> = (0..500)
            .map(|_| {
                at += -0.1 * (crate::data::test_noise(&mut seed) + 0.5 + 1e-3).ln();
                at
            })
            .collect();
        let (runs, notes) = cut_at_gaps(run(events), 0).unwrap();
        assert_eq!(runs.len(), 1);
        assert!(
            notes[0].contains("steps irregularly") && notes[0].contains("sampled on events"),
            "{notes:?}"
        );
        assert_eq!(cut_at_gaps(run(clock(300)), 0).unwrap().1.len(), 0);
        let mut t = clock(300);
        for k in [50, 60, 70, 80] {
            t[k..].iter_mut().for_each(|v| *v += 1.0);
        }
        let (runs, notes) = cut_at_gaps(run(t), 0).unwrap();
        assert_eq!(runs.len(), 2);
        assert!(
            notes[1].contains("3 pieces between gaps under 21 rows each")
                && notes[1].contains("30 rows in all"),
            "{notes:?}"
        );
        // a dozen samples at 0.25, 0.5, 1 … 24 h (a pharmacokinetic study's): three intervals of
        // eleven over three times the median, an irregular log, not a clock with three dropouts
        // (it was cut into pieces of at most 9 rows and refused)
        let dozen = vec![0.0, 0.25, 0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0];
        assert!(matches!(gaps(&dozen), Gaps::Irregular { .. }));
        let (runs, notes) = cut_at_gaps(run(dozen), 0).unwrap();
        assert_eq!(runs[0].len(), 12);
        assert!(notes[0].contains("27 % of its intervals") && notes[0].contains("not cut"), "{notes:?}");
        // one dropout in a dozen clock samples is still a dropout
        let mut t = clock(12);
        t[6..].iter_mut().for_each(|v| *v += 1.0);
        assert!(matches!(gaps(&t), Gaps::Dropouts(rows) if rows == [6]));
    }

    /// A ball dropped from 2 m bouncing back at 0.8 of its speed (g = 9.81 m/s², flights of
    /// 2·0.8ᵏ·v₁/g): its speed leaps at each bounce and moves between them as much: cut at each
    /// into flights of their own, said once; its height only kinks, and cuts nothing.
    #[test]
    fn a_bouncing_motion_is_cut_at_each_bounce() {
        let g = 9.81;
        let v1 = (2.0 * g * 2.0f64).sqrt();
        let first = v1 / g;
        // the bounce times and the speed leaving each
        let mut bounces = vec![(first, 0.8 * v1)];
        while bounces.len() < 8 {
            let (t, v) = *bounces.last().unwrap();
            bounces.push((t + 2.0 * v / g, 0.8 * v));
        }
        let t: Vec<f64> = (0..480).map(|k| 0.01 * k as f64).collect();
        let (h, v): (Vec<f64>, Vec<f64>) = t
            .iter()
            .map(|&t| match bounces.iter().rev().find(|b| b.0 <= t) {
                Some(&(tb, vb)) => (vb * (t - tb) - 0.5 * g * (t - tb).powi(2), vb - g * (t - tb)),
                None => (2.0 - 0.5 * g * t * t, -g * t),
            })
            .unzip();
        let mut f = Frame::new("ball.csv", "t", t.clone()).unwrap();
        f.push("h", h).unwrap();
        f.push("v", v).unwrap();
        let (runs, notes) = cut_at_breaks(f, &["h", "v"], &[]).unwrap();
        // bounces at 0.639, 1.66, 2.48, 3.13, 3.65, 4.07, 4.41 and 4.68 s: the drop and seven
        // flights, the last 12 rows too few for a run
        assert_eq!(runs.len(), 8, "{notes:?}");
        for (run, b) in runs.iter().skip(1).zip(&bounces) {
            // each flight starts at the first sample after its bounce
            assert!(run.time()[0] >= b.0 && run.time()[0] - b.0 < 0.01 + 1e-9, "{} {}", run.time()[0], b.0);
        }
        assert_eq!(notes.len(), 2, "{notes:?}");
        assert!(
            notes[0].contains("`v` leaps at 8 rows") && notes[0].contains("a motion reset at each"),
            "{notes:?}"
        );
        assert!(notes[1].contains("12 row(s) between breaks"), "{notes:?}");
    }

    /// A staircase (a state read off a coarse scale every 40 rows) leaps too often to be
    /// records joined: cut nowhere, said.
    #[test]
    fn a_staircase_is_not_cut() {
        let t: Vec<f64> = (0..4000).map(|k| 0.01 * k as f64).collect();
        let mut f = Frame::new("scale.csv", "t", t).unwrap();
        f.push("x", (0..4000).map(|k| (k / 40) as f64 + 0.001 * (0.01 * k as f64).sin()).collect()).unwrap();
        let (runs, notes) = cut_at_breaks(f, &["x"], &[]).unwrap();
        assert_eq!(runs.len(), 1);
        assert!(notes[0].contains("too often for records joined"), "{notes:?}");
    }
}
