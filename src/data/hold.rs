//! Inputs held between samples (a zero-order hold: a digital controller's command, a force
//! stepped by a test rig, a mode switch). Such an input is constant from each sample to the
//! next and jumps at the samples; taken as a line between samples instead, it shifts every
//! jump half an interval early and biases every coefficient near it (a mass-spring-damper
//! driven by a force held for 0.5 s: damping −0.288 for −0.3).

use serde::{Deserialize, Serialize};

use super::repeated::{
    fits_better_held, fits_better_held_than_a_line, jumps_off_the_samples, kinks_at_changes, repeated, MISFIT,
};
use super::{DataError, Frame};

/// How a run's inputs behave between their samples (MATLAB's `InterSample`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Intersample {
    /// Held where the record shows a controller's command ([`held`], [`Hold::on_a_clock`]), a
    /// generator's stepped each sample ([`white`]), or the states' rates show a smooth command
    /// held by a DAC, else a line between samples; a column
    /// that repeats a slower sensor's readings between them is read at its readings.
    #[default]
    #[cfg_attr(
        feature = "cli",
        value(
            help = "Held where the record or the states' rates show a command held by a controller, a generator or a DAC; else a line"
        )
    )]
    Auto,
    /// A line between samples, whatever the record shows (a column that repeats a slower
    /// sensor's readings between them is taken as its rows have it too).
    #[cfg_attr(feature = "cli", value(help = "A line between samples, whatever the record shows"))]
    Linear,
    /// Held from each sample to the next, every input that changes: one that stays put
    /// between isolated jumps ([`held`]), on a clock or not, steps to random levels at random
    /// samples ([`stepped`]), changes at every sample unforeseen by the last ([`white`]), or
    /// moves smoothly from sample to sample (a sine put out through a DAC; MATLAB's
    /// `InterSample = 'zoh'`).
    #[cfg_attr(
        feature = "cli",
        value(help = "Every input that changes held from each sample to the next (a zero-order hold)")
    )]
    Held,
}

/// What shows a record held between its samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hold {
    /// Samples at which it jumps.
    pub jumps: usize,
    /// The share of intervals over which it does not change at all.
    pub flat: f64,
    /// The median jump, in units of the record's span.
    pub jump: f64,
    /// The greatest common divisor of the samples between its jumps: a controller's period
    /// in samples where it is 2 or more (the jumps on its clock).
    pub period: usize,
}

impl Hold {
    /// Whether the jumps keep to a clock of two or more samples (nine jumps at least): then
    /// they are a digital controller's, on the samples, and the record is held between them.
    /// A record that jumps at isolated samples off any clock (a relay switched
    /// by the motion, a rudder thrown at once when the heading passes its check) may jump
    /// anywhere between two samples: a line between them is the better guess (its error
    /// averages out over the jumps, the hold's is half an interval late on average).
    pub fn on_a_clock(&self) -> bool {
        self.period >= 2 && self.jumps >= CLOCK_JUMPS
    }
}

/// Jumps needed to believe a clock: intervals between random jumps share a divisor of 2 or
/// more by chance with odds of Σ p^−(jumps − 1) over the primes p, 0.4 % with 9 jumps.
pub(super) const CLOCK_JUMPS: usize = 9;

/// Jumps with a changing interval beside them, at most this share: a held record changes at
/// isolated samples; a moving one (a rudder turning at its rate, even printed to three digits
/// and so flat between its counts) changes on consecutive intervals.
const SIDE_BY_SIDE: f64 = 0.05;

/// The median jump at least this share of the record's span: a slowly moving quantity
/// rounded to its counts also changes at isolated samples, but by one count of many.
const SPAN: f64 = 0.05;

/// The median jump at least this share of the record's largest value: a steady quantity
/// printed to three significant figures flickers by one count, which is its whole span
/// (MARIN's propeller rate, 0.1 at 76 rpm), but 0.1-1 % of its value.
const SIZE: f64 = 0.01;

/// Whether `x` is held between its samples: it jumps at isolated samples (no two changing
/// intervals side by side, but for 5 % of its jumps) by a fair share of its span (5 %) and of
/// its size (1 % of its largest value), and stays put in between. `None` for a record that
/// moves, never changes, or has under 20 intervals. A record that jumps at every sample
/// (a random binary signal switched each sample) is not found here: [`white`] finds it.
pub fn held(x: &[f64]) -> Option<Hold> {
    sized(x, isolated_changes(x)?)
}

/// Whether `x` is stepped between many levels at random samples and held in between (an
/// APRBS: a new random level with some odds at each sample, so now and then on consecutive
/// samples): it stays put over a third of its intervals or more (one switched at every other
/// sample on average correlates by a half from sample to sample, not [`white`]) and jumps by
/// a fair share of its span and size (as [`held`]), its changes side by side or not, but those
/// side by side turning back as often as not (a third of them keep their direction between
/// random levels; a motion read to coarse counts keeps it from count to count). Whether the
/// states' rates are stepped by it too is for [`mark_held`]'s fit of them to tell. `None`
/// as for [`held`].
pub fn stepped(x: &[f64]) -> Option<Hold> {
    if x.len() < 21 {
        return None;
    }
    let at: Vec<usize> = (0..x.len() - 1).filter(|&i| x[i + 1] != x[i]).collect();
    (!at.is_empty() && 3 * at.len() <= 2 * (x.len() - 1)).then_some(())?;
    // changes side by side keeping their direction: a third of them between random levels,
    // nearly all where a motion passes count after count (one pair more allowed where few)
    let side_by_side = at.windows(2).filter(|w| w[1] == w[0] + 1);
    let (pairs, kept) = side_by_side.fold((0, 0), |(n, k), w| {
        let (a, b) = (x[w[0] + 1] - x[w[0]], x[w[1] + 1] - x[w[1]]);
        (n + 1, k + usize::from(a.signum() == b.signum()))
    });
    (2 * kept <= pairs + 2).then_some(())?;
    sized(x, at)
}

/// What shows `x` held between its changes `at` (the intervals over which it changes): its
/// median jump a fair share of its span and of its size; `None` where not.
fn sized(x: &[f64], at: Vec<usize>) -> Option<Hold> {
    let (low, high) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
    let size = low.abs().max(high.abs());
    let mut jumps: Vec<f64> = at.iter().map(|&i| (x[i + 1] - x[i]).abs()).collect();
    let middle = jumps.len() / 2;
    let median = *jumps.select_nth_unstable_by(middle, f64::total_cmp).1;
    if median < SPAN * (high - low) || median < SIZE * size {
        return None;
    }
    let period = at.windows(2).fold(0, |g, w| gcd(g, w[1] - w[0]));
    Some(Hold {
        jumps: at.len(),
        flat: 1.0 - at.len() as f64 / (x.len() - 1) as f64,
        jump: median / (high - low),
        period,
    })
}

/// Whether `x` changes only at its samples, as far as its record shows: held between jumps at
/// isolated samples ([`held`]), stepped between random levels ([`stepped`]), or changed at every
/// sample by as much as its spread ([`white`]); not a record that moves from sample to sample.
pub fn staircase(x: &[f64]) -> bool {
    held(x).is_some() || stepped(x).is_some() || white(x).is_some()
}

/// Lag-one autocorrelations within this of 0 read as white: a record that changes at every
/// sample by as much as its spread, each change unforeseen by the last (a random excitation
/// stepped each sample). A motion sampled at its rate correlates near 1; a sine needs fewer
/// than 6 samples a period to fall under 0.5, and under −0.5 (3 a period) it is left alone.
const WHITE: f64 = 0.5;

/// Whether `x` changes at every sample by as much as its spread, uncorrelated from one sample
/// to the next (its lag-one autocorrelation within ±0.5, changing over a third of its
/// intervals or more: a random binary signal changes over half; 20 intervals at least), by 1 % of its size or more (a steady value printed to three figures flickers by a count): a random
/// excitation a digital generator steps each sample (white noise, a binary signal switched
/// at random each sample), or the noise of a value held steady. No interpolation between the
/// samples can follow it; a generator holds each value to the next sample. Its lag-one
/// autocorrelation where it is so.
pub fn white(x: &[f64]) -> Option<f64> {
    if x.len() < 21 {
        return None;
    }
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let variance: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
    let lagged: f64 = x.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum();
    let rho = lagged / variance;
    let size = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let spread = (variance / x.len() as f64).sqrt();
    // (a spike now and then is uncorrelated too, but stays put in between)
    let changing = x.windows(2).filter(|w| w[1] != w[0]).count();
    (spread >= SIZE * size && variance.is_finite() && rho.abs() < WHITE && 3 * changing >= x.len() - 1)
        .then_some(rho)
}

/// The intervals over which `x` changes (interval i from sample i to i + 1), where it changes
/// at isolated samples: no two changing intervals side by side but for 5 % of them, or any
/// where it takes at most four values and stays put over half its intervals or more (a
/// binary signal switched twice in a row; one switched at every sample is not held). `None`
/// for a record that moves from sample to sample, never changes, or has under 20 intervals.
pub(super) fn isolated_changes(x: &[f64]) -> Option<Vec<usize>> {
    if x.len() < 21 {
        return None;
    }
    let changes: Vec<bool> = x.windows(2).map(|w| w[1] != w[0]).collect();
    let at: Vec<usize> = (0..changes.len()).filter(|&i| changes[i]).collect();
    if at.is_empty() {
        return None;
    }
    let beside = at
        .iter()
        .filter(|&&i| (i > 0 && changes[i - 1]) || changes.get(i + 1).copied().unwrap_or(false))
        .count();
    let mostly_flat = 2 * at.len() <= changes.len();
    (beside as f64 <= SIDE_BY_SIDE * at.len() as f64 || (mostly_flat && few_levels(x))).then_some(at)
}

/// Levels a record switched between may take at most and still change on consecutive
/// intervals: a binary or ternary signal (a random telegraph, on and off) switched twice in a
/// row is a command, while a motion read to counts passes through many of them.
const FEW_LEVELS: usize = 4;

/// Whether `x` takes at most [`FEW_LEVELS`] values.
fn few_levels(x: &[f64]) -> bool {
    let mut levels: Vec<f64> = Vec::with_capacity(FEW_LEVELS + 1);
    for v in x {
        if !levels.contains(v) {
            if levels.len() == FEW_LEVELS {
                return false;
            }
            levels.push(*v);
        }
    }
    true
}

/// Columns by name.
type Named<'f> = Vec<(String, &'f [f64])>;

/// The recorded columns a held-or-not test of column `name` reads: the states of `motion`
/// (by name) and every column of `motion` and `columns`, each but `name` and those held.
fn beside<'f>(
    frame: &'f Frame,
    name: &str,
    motion: &[&str],
    columns: &[&str],
) -> (Named<'f>, Vec<&'f [f64]>) {
    let recorded = |names: &[&str]| -> Named<'f> {
        names
            .iter()
            .filter(|m| **m != name && !frame.is_held(m))
            .filter_map(|m| frame.column(m).map(|c| (m.to_string(), c)))
            .collect()
    };
    let mut all: Vec<&str> = motion.to_vec();
    all.extend(columns.iter().filter(|c| !motion.contains(c)));
    (recorded(motion), recorded(&all).into_iter().map(|(_, c)| c).collect())
}

/// Holds column `name` of `frame` where it repeats itself on a clock slower than the rows and
/// a recorded state of `motion` (not `name` itself) kinks where it changes, or the states'
/// rates fit clearly better with it held than read at its readings (over `name`, `motion`
/// and `columns`), and says so.
fn commanded(
    frame: &mut Frame,
    name: &str,
    motion: &[&str],
    columns: &[&str],
) -> Result<Option<String>, DataError> {
    let Some(column) = frame.column(name) else { return Ok(None) };
    let Some(r) = repeated(column) else { return Ok(None) };
    let (states, others) = beside(frame, name, motion, columns);
    let slices: Vec<&[f64]> = states.iter().map(|(_, c)| *c).collect();
    let how = format!(
        "{}: `{name}` changes only every {} rows, by a little at {:.0} % of them",
        frame.origin(),
        r.period,
        100.0 * r.moving
    );
    let why = if let Some(i) = kinks_at_changes(column, r, &slices) {
        format!("the rate of `{}` steps where it changes", states[i].0)
    } else {
        let Some((i, share)) = fits_better_held(frame.time(), column, r, &slices, &others) else {
            return Ok(None);
        };
        format!(
            "the rate of `{}` is fitted better with it held from each change to the next than read at its readings ({:.1} % less left over, by a quadratic in the columns over windows of one period)",
            states[i].0,
            100.0 * (1.0 - share)
        )
    };
    let note = format!(
        "{how}, and {why}: a controller's command slower than the log, held from each change to the next (a zero-order hold), not a slower sensor's readings of a smooth quantity; taken as held. Where it is a sensor's readings after all, give it interpolated between them (identify --intersample linear, a model file's `intersample = \"linear\"` or Python's `intersample=\"linear\"` would take its staircase as its rows have it)"
    );
    frame.hold(name)?;
    Ok(Some(note))
}

/// Holds column `name` of `frame` (a record that jumps at isolated samples on no clock) where
/// a recorded state of `motion` (not `name`) has its rate fitted clearly better with it held
/// from each sample to the next than as a line between them ([`held_fit`]): a generator's
/// command switched at random samples, not a relay thrown between them; and says so, after
/// `how` it jumps (on no clock).
fn held_on_the_samples(
    frame: &mut Frame,
    name: &str,
    motion: &[&str],
    columns: &[&str],
    how: &str,
) -> Result<Option<String>, DataError> {
    let Some((state, share)) = held_fit(frame, name, motion, columns, false) else { return Ok(None) };
    frame.hold(name)?;
    Ok(Some(format!(
        "{how}, but the rate of `{state}` is fitted better with it held from each sample to the next than as a line between them ({:.1} % less left over, by a quadratic in the columns over windows of eight samples): a generator's command switched at random samples (a random telegraph, a PRBS, an APRBS), not a relay thrown between them; taken as held. Where it switches between the samples, say so (identify --intersample linear; a model file's `intersample = \"linear\"`; Python `intersample=\"linear\"`)",
        100.0 * (1.0 - share)
    )))
}

/// Jumps held misfits at least this share of (`1/OFF_THE_SAMPLES`) make a column switched
/// between samples rather than held: a few in many bias the fit little, where leaving out
/// every window that holds a jump would cost many.
const OFF_THE_SAMPLES: f64 = 20.0;

/// Where held misfits the windows that hold some jumps of column `name` of `frame`
/// ([`jumps_off_the_samples`]): each such jump that fits once it acts an interval earlier (a
/// command logged a sample after it acted) moved to the sample before and the column held,
/// where every misfitted jump does; else, where at least one in [`OFF_THE_SAMPLES`] misfits,
/// the column switched between samples (jumps between two samples, which held would put a
/// whole interval off and bias every coefficient near them: a DC motor's di/dt 1.2 % high with
/// two of nine steps a sample late). What was done, said after `how` it jumps; `None` where
/// held fits (or the record cannot tell), nothing done.
fn off_the_samples(
    frame: &mut Frame,
    name: &str,
    motion: &[&str],
    columns: &[&str],
    how: &str,
) -> Result<Option<String>, DataError> {
    let Some(column) = frame.column(name) else { return Ok(None) };
    let (states, others) = beside(frame, name, motion, columns);
    let slices: Vec<&[f64]> = states.iter().map(|(_, c)| *c).collect();
    let Some(jumps) = jumps_off_the_samples(frame.time(), column, &slices, &others) else { return Ok(None) };
    let misfit = format!(
        "held misfits a state's rate at {} of the {} windows of eight samples that hold a jump (by over {MISFIT} times the others' spread)",
        jumps.off, jumps.windows
    );
    if jumps.off > 0 && jumps.late.len() == jumps.off {
        let mut moved = column.to_vec();
        let t = frame.time();
        let at: Vec<String> = jumps.late.iter().map(|&j| format!("{}", t[j])).collect();
        for &j in &jumps.late {
            moved[j] = column[j + 1];
        }
        frame.overwrite(name, moved)?;
        frame.hold(name)?;
        return Ok(Some(format!(
            "{how}; {misfit}, and fits them where they act an interval before the sample that shows them: a command logged a sample after it acted; those {} jumps moved to the sample before (at t = {}), and the column taken as held from each sample to the next (a zero-order hold). Where they are a relay's between the samples, say so (identify --intersample linear; a model file's `intersample = \"linear\"`; Python `intersample=\"linear\"`)",
            at.len(),
            at.join(", ")
        )));
    }
    if jumps.off == 0 || OFF_THE_SAMPLES * (jumps.off as f64) < jumps.windows as f64 {
        return Ok(None);
    }
    frame.switch(name)?;
    Ok(Some(format!(
        "{how}; {misfit}: those jumps fall between two samples (a relay, a command switched between them), which held would put a whole interval off and bias every coefficient near them; so a rate's fit leaves out the windows of the weak or integral form that hold a jump (a replay takes it as a line between the samples). Where every jump is at a sample, say so (identify --intersample held; a model file's `intersample = \"held\"`; Python `intersample=\"held\"`)"
    )))
}

/// Holds column `name` of `frame` (a record that moves from sample to sample) where a recorded
/// state of `motion` has its rate fitted clearly better with it held from each sample to the
/// next than as a line between them ([`held_fit`]): a smooth command a controller or a signal
/// generator puts out through a zero-order hold (a sine or a chirp through a DAC, MATLAB's
/// default `InterSample = 'zoh'`), whose line between samples runs half an interval early and
/// biases the damping it drives (a mass-spring-damper under a held sine at 20 Hz: −0.332v +
/// 0.034v³ for −0.3v); and says so.
fn held_though_smooth(
    frame: &mut Frame,
    name: &str,
    motion: &[&str],
    columns: &[&str],
) -> Result<Option<String>, DataError> {
    let Some(column) = frame.column(name) else { return Ok(None) };
    let changing = column.windows(2).filter(|w| w[1] != w[0]).count();
    if 2 * changing <= column.len().saturating_sub(1) {
        return Ok(None);
    }
    let Some((state, share)) = held_fit(frame, name, motion, columns, true) else { return Ok(None) };
    frame.hold(name)?;
    Ok(Some(format!(
        "{}: `{name}` moves from sample to sample, but the rate of `{state}` is fitted better with it held from each sample to the next than as a line between them ({:.1} % less left over, by a quadratic in the columns over windows of eight samples): a command put out through a zero-order hold (a controller's, a signal generator's through a DAC), which a line between the samples would run half an interval early; taken as held. Where it is a measured quantity that moves between the samples, say so (identify --intersample linear; a model file's `intersample = \"linear\"`; Python `intersample=\"linear\"`)",
        frame.origin(),
        100.0 * (1.0 - share)
    )))
}

/// The recorded state of `motion` (not `name`) whose rate is fitted clearly better with column
/// `name` of `frame` held from each sample to the next than as a line between them, and how
/// ([`fits_better_held_than_a_line`], over `motion` and `columns`; `smooth`: a record that
/// moves from sample to sample, the windows that hold a leap of it left out, compared only
/// where the columns do not foresee it). `None` where no state's is.
fn held_fit(
    frame: &Frame,
    name: &str,
    motion: &[&str],
    columns: &[&str],
    smooth: bool,
) -> Option<(String, f64)> {
    let column = frame.column(name)?;
    let leaps: Option<Vec<usize>> =
        smooth.then(|| super::breaks(frame.time(), column).into_iter().map(|b| b.row).collect());
    let (states, others) = beside(frame, name, motion, columns);
    let slices: Vec<&[f64]> = states.iter().map(|(_, c)| *c).collect();
    let (i, share) = fits_better_held_than_a_line(frame.time(), column, &slices, &others, leaps.as_deref())?;
    Some((states[i].0.clone(), share))
}

/// How column `name` of `frame` stays put between samples and jumps at them (`h`).
fn stays_put(frame: &Frame, name: &str, h: Hold) -> String {
    format!(
        "{}: `{name}` stays put between samples ({:.0} % of intervals) and jumps at {} samples (by {:.0} % of its span, median)",
        frame.origin(),
        100.0 * h.flat,
        h.jumps,
        100.0 * h.jump
    )
}

/// The rows at which a record switched between samples ([`Frame::switch`]) has switched: the
/// row after each jump. A record that stays put between jumps ([`held`]) switches at every
/// change; one that moves (a measured input stepped, with its noise) at its breaks
/// ([`super::breaks`]).
pub fn switches(t: &[f64], x: &[f64]) -> Vec<usize> {
    match isolated_changes(x) {
        Some(at) => at.into_iter().map(|i| i + 1).collect(),
        None => super::breaks(t, x).into_iter().map(|b| b.row).collect(),
    }
}

pub(super) fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Marks the columns of `frame` named in `columns` that are held between samples, as
/// `intersample` says, and says what `auto` found and why: held where a column jumps at
/// isolated samples on a clock, a line (said) where it jumps off any; held too where it
/// changes by a little at every tick of a clock slower than the rows and the recorded states
/// `motion` kink there ([`crate::data::kinks_at_changes`]) or their rates fit clearly better
/// with it held ([`crate::data::fits_better_held`]): a controller's command, not a slower
/// sensor's readings; and held where it steps to random levels at random samples ([`stepped`],
/// an APRBS) and a state's rate fits clearly better so than with a line between its samples,
/// or where it moves from sample to sample, its change not foreseen by the columns, and a
/// state's rate fits clearly better so (a smooth command through a
/// DAC). The columns a frame does not have are passed over.
pub fn mark_held(
    frame: &mut Frame,
    columns: &[&str],
    motion: &[&str],
    intersample: Intersample,
) -> Result<Vec<String>, DataError> {
    mark_held_among(frame, columns, columns, motion, intersample)
}

/// [`mark_held`] of the columns `marked` alone, each judged beside every other of `columns`.
pub(super) fn mark_held_among(
    frame: &mut Frame,
    marked: &[&str],
    columns: &[&str],
    motion: &[&str],
    intersample: Intersample,
) -> Result<Vec<String>, DataError> {
    let mut notes = Vec::new();
    for name in marked {
        let Some(column) = frame.column(name) else { continue };
        match intersample {
            Intersample::Linear => frame.release(name),
            Intersample::Held => {
                // asked: a staircase on a clock or off it, stepped every sample, or a smooth
                // command through a DAC alike
                if column.windows(2).any(|w| w[1] != w[0]) {
                    frame.hold(name)?;
                }
            }
            Intersample::Auto => {
                if let Some(rho) = white(column) {
                    frame.hold(name)?;
                    notes.push(format!(
                        "{}: `{name}` changes at every sample by as much as its spread, each change \
                         unforeseen by the last (its correlation from one sample to the next {rho:.2}): a random \
                         excitation a generator steps each sample, or the noise of a value held steady; no line \
                         between the samples can follow it, so it is taken as held from each sample to the next \
                         (a zero-order hold); where it is a motion sampled too coarsely, sample faster or say so \
                         (identify --intersample linear; a model file's `intersample = \"linear\"`; Python \
                         `intersample=\"linear\"`)",
                        frame.origin()
                    ));
                    continue;
                }
                let Some(h) = held(column) else {
                    let steps = stepped(column);
                    if let Some(note) = commanded(frame, name, motion, columns)? {
                        notes.push(note);
                    } else if let Some(h) = steps {
                        // changes side by side: held where the rates say so, else a line (a
                        // motion read to coarse counts is no relay to leave out windows for)
                        let how = stays_put(frame, name, h);
                        let unclocked = format!("{how}, on no clock");
                        if let Some(note) = off_the_samples(frame, name, motion, columns, &how)? {
                            notes.push(note);
                        } else if let Some(note) =
                            held_on_the_samples(frame, name, motion, columns, &unclocked)?
                        {
                            notes.push(note);
                        }
                    } else if let Some(note) = held_though_smooth(frame, name, motion, columns)? {
                        notes.push(note);
                    }
                    continue;
                };
                let how = stays_put(frame, name, h);
                // a command, on a clock or not, may act a sample before its log shows it
                let clock = match h.on_a_clock() {
                    true => format!("{how}, every one on a clock of {} samples", h.period),
                    false => format!("{how}, on no clock"),
                };
                if let Some(note) = off_the_samples(frame, name, motion, columns, &clock)? {
                    notes.push(note);
                    continue;
                }
                if h.on_a_clock() {
                    frame.hold(name)?;
                    notes.push(format!(
                        "{clock}: a controller's command, taken as held from each sample to the next (a zero-order hold), not as a line between them; where it moves between its samples, say so (identify --intersample linear; a model file's `intersample = \"linear\"`; Python `intersample=\"linear\"`)"
                    ));
                } else if let Some(note) = held_on_the_samples(frame, name, motion, columns, &clock)? {
                    notes.push(note);
                } else {
                    frame.switch(name)?;
                    notes.push(format!(
                        "{clock}: it may jump anywhere between two samples (a relay, a switch thrown by the motion), so a rate's fit leaves out the windows of the weak or integral form that hold a jump (a point derivative and a replay take it as a line between the samples, which halves the error of a jump's time on average); where it is a command held from each sample to the next, say so (identify --intersample held; a model file's `intersample = \"held\"`; Python `intersample=\"held\"`)"
                    ));
                }
            }
        }
    }
    Ok(notes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A generator's excitation stepped at every sample (uniform noise, a random binary
    /// signal) is white; a motion sampled at its rate, a sine of 2.5 samples a period (its
    /// samples alternate), a steady value flickering by a count of its print, a constant:
    /// not.
    #[test]
    fn an_excitation_stepped_at_every_sample_is_white() {
        let mut seed = 11u64;
        let noise: Vec<f64> = (0..500).map(|_| crate::data::test_noise(&mut seed)).collect();
        assert!(white(&noise).is_some_and(|rho| rho.abs() < 0.1));
        let binary: Vec<f64> = noise.iter().map(|v| 5.0 + v.signum()).collect();
        assert!(white(&binary).is_some());
        let sine = |per: f64| -> Vec<f64> {
            (0..500).map(|k| (std::f64::consts::TAU * k as f64 / per).sin()).collect()
        };
        assert_eq!(white(&sine(100.0)), None);
        assert_eq!(white(&sine(2.5)), None);
        let flicker: Vec<f64> = noise.iter().map(|v| if *v > 0.0 { 76.1 } else { 76.0 }).collect();
        assert_eq!(white(&flicker), None);
        assert_eq!(white(&[2.0; 500]), None);
        assert_eq!(white(&noise[..20]), None);
        let spike: Vec<f64> = (0..500).map(|k| if k == 300 { 1.0 } else { 0.0 }).collect();
        assert_eq!(white(&spike), None);
    }

    /// An APRBS (a new random level with odds of one in five at each sample, so at times on
    /// consecutive samples) is stepped, not held at isolated samples; a rudder turned at
    /// 1.5 counts a sample between ±10 counts and standing in between (its changes side by
    /// side keep their direction) and a binary signal switched at every sample (no sample
    /// where it stays put) are not.
    #[test]
    fn random_levels_at_random_samples_are_stepped() {
        let mut seed = 5u64;
        let mut level = 0.0;
        let aprbs: Vec<f64> = (0..2000)
            .map(|_| {
                if crate::data::test_noise(&mut seed) > 0.3 {
                    level = 2.0 * crate::data::test_noise(&mut seed);
                }
                level
            })
            .collect();
        assert_eq!(held(&aprbs), None);
        let h = stepped(&aprbs).unwrap();
        assert!(h.flat > 0.7 && h.flat < 0.9 && h.period == 1, "{h:?}");
        let rudder: Vec<f64> = (0..2000)
            .map(|k| {
                let phase = (k % 200) as f64;
                let swing = (1.5 * phase).min(20.0);
                if k % 400 < 200 {
                    (10.0 - swing).round()
                } else {
                    (-10.0 + swing).round()
                }
            })
            .collect();
        assert_eq!(stepped(&rudder), None);
        let alternating: Vec<f64> = (0..2000).map(|k| (k % 2) as f64).collect();
        assert_eq!(stepped(&alternating), None);
    }

    /// A force held for 50 samples at a time, at random levels: held; the same force moving
    /// as a line between the levels over 5 samples: not.
    #[test]
    fn steps_are_held_and_ramps_are_not() {
        let mut seed = 3u64;
        let levels: Vec<f64> = (0..40).map(|_| 4.0 * crate::data::test_noise(&mut seed)).collect();
        let steps: Vec<f64> = (0..2000).map(|k| levels[k / 50]).collect();
        let h = held(&steps).unwrap();
        assert_eq!(h.jumps, 39);
        assert!((h.flat - (1.0 - 39.0 / 1999.0)).abs() < 1e-12);
        let ramps: Vec<f64> = (0..2000)
            .map(|k| {
                let (j, r) = (k / 50, k % 50);
                if j == 0 || r >= 5 {
                    levels[j]
                } else {
                    levels[j - 1] + (levels[j] - levels[j - 1]) * r as f64 / 5.0
                }
            })
            .collect();
        assert_eq!(held(&ramps), None);
    }

    /// A binary signal ±1 switched now and then (the classic identification input), and a
    /// single step: held. A switch at every sample cannot be told from a motion: not.
    #[test]
    fn binary_signals_and_a_step_are_held() {
        let mut seed = 5u64;
        let (mut prbs, mut level) = (Vec::new(), 1.0);
        while prbs.len() < 500 {
            // held for 2 to 15 samples
            let hold = 2 + ((crate::data::test_noise(&mut seed) + 0.5) * 14.0) as usize;
            prbs.extend(std::iter::repeat_n(level, hold));
            level = -level;
        }
        let switches = prbs.windows(2).filter(|w| w[0] != w[1]).count();
        let h = held(&prbs).unwrap();
        assert_eq!(h.jumps, switches);
        assert_eq!(h.jump, 1.0);
        let step: Vec<f64> = (0..100).map(|k| if k < 30 { 0.0 } else { 2.0 }).collect();
        assert_eq!(held(&step).map(|h| h.jumps), Some(1));
        let every: Vec<f64> = (0..100).map(|k| if k % 2 == 0 { 1.0 } else { -1.0 }).collect();
        assert_eq!(held(&every), None);
    }

    /// Quantised records that are not held: a slow ramp in counts (isolated changes of one
    /// count of many), a steady rate printed to three figures (76.0 / 76.1 / 75.9: its whole
    /// span, 0.1 % of its value), a rudder turned at its rate and printed to 0.1° (changes
    /// side by side), a constant.
    #[test]
    fn counts_and_printed_digits_are_not_held() {
        let ramp: Vec<f64> = (0..1000).map(|k| (k as f64 / 3.3).floor()).collect();
        assert_eq!(held(&ramp), None);
        let mut seed = 8u64;
        let rate: Vec<f64> = (0..1000)
            .map(|_| {
                let n = crate::data::test_noise(&mut seed);
                76.0 + if n > 0.4 {
                    0.1
                } else if n < -0.4 {
                    -0.1
                } else {
                    0.0
                }
            })
            .collect();
        let flicker = held(&rate);
        assert_eq!(flicker, None);
        let rudder: Vec<f64> = (0..1000)
            .map(|k| {
                let t = 0.05 * k as f64;
                (10.0f64.min(2.3 * t) * 10.0).round() / 10.0
            })
            .collect();
        assert_eq!(held(&rudder), None);
        assert_eq!(held(&[1.5; 100]), None);
        assert_eq!(held(&[0.0, 1.0, 1.0]), None);
    }

    /// Marking: a command on a clock of 10 samples held, said; a switch at irregular samples
    /// (a relay) left a line, said; a moving column neither. `linear` marks none, `held` both
    /// switching columns, clock or not, and never the moving one.
    #[test]
    fn marks_as_asked() {
        let t: Vec<f64> = (0..100).map(|k| 0.1 * k as f64).collect();
        let mut f = Frame::new("rig.csv", "t", t.clone()).unwrap();
        f.push("F", (0..100).map(|k| if (k / 10) % 2 == 0 { 1.0 } else { -1.0 }).collect()).unwrap();
        let switches = [7, 19, 30, 48, 61, 77, 83, 95];
        f.push(
            "G",
            (0..100)
                .map(|k| if switches.iter().filter(|&&s| k >= s).count() % 2 == 0 { 0.0 } else { 5.0 })
                .collect(),
        )
        .unwrap();
        f.push("x", t.iter().map(|t| t.sin()).collect()).unwrap();
        let mut g = f.clone();
        let notes = mark_held(&mut f, &["F", "G", "x", "absent"], &["x"], Intersample::Auto).unwrap();
        assert!(f.is_held("F") && !f.is_held("G") && !f.is_held("x"));
        assert_eq!(notes.len(), 2);
        assert!(
            notes[0].contains("rig.csv: `F` stays put") && notes[0].contains("jumps at 9 samples"),
            "{}",
            notes[0]
        );
        assert!(
            notes[0].contains("on a clock of 10 samples") && notes[0].contains("taken as held"),
            "{}",
            notes[0]
        );
        assert!(
            notes[1].contains("`G`")
                && notes[1].contains("on no clock")
                && notes[1].contains("--intersample held"),
            "{}",
            notes[1]
        );
        let mut linear = f.clone();
        assert!(mark_held(&mut linear, &["F"], &[], Intersample::Linear).unwrap().is_empty());
        assert!(!linear.is_held("F"));
        mark_held(&mut g, &["F", "G", "x"], &[], Intersample::Held).unwrap();
        assert!(g.is_held("F") && g.is_held("G") && g.is_held("x"));
    }

    /// The clock: jumps every 50 samples from sample 37 keep a period of 50; six jumps do not
    /// show one, and intervals of 3, 4 and 5 samples share none.
    #[test]
    fn a_clock_is_the_jumps_common_divisor() {
        let levels = [0.0, 3.0, -1.0, 2.0, -2.0, 1.0, 4.0, -3.0, 0.5, 2.5, -0.5, 1.5, -2.5];
        let clocked: Vec<f64> = (0..600).map(|k| levels[(k + 13) / 50]).collect();
        let h = held(&clocked).unwrap();
        assert_eq!((h.period, h.jumps), (50, 12));
        assert!(h.on_a_clock());
        assert!(!held(&clocked[..300]).unwrap().on_a_clock(), "6 jumps");
        let mut at = 0;
        let irregular: Vec<f64> = (0..200)
            .map(|k| {
                if [10, 13, 17, 22, 25, 29, 34, 37, 41, 46, 49].contains(&k) {
                    at += 1;
                }
                levels[at]
            })
            .collect();
        let h = held(&irregular).unwrap();
        assert_eq!((h.period, h.jumps), (1, 11));
        assert!(!h.on_a_clock());
    }
}
