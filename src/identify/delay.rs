//! Whether an input acts on the target later than it is recorded (a dead time): the
//! candidates fitted all together with the input read d seconds earlier, for d on a grid up to
//! a tenth of the shortest run. Where some d leaves far less of the target unexplained than
//! none, the fit without it is biased (a mass-spring-damper whose force acts 0.2 s late: gain
//! 1.71 for 2 and three spurious terms) and is said, with the delay that explains it, or the
//! first-order lag (an actuator's) that explains it better over the same rows.

use nalgebra::{DMatrix, DVector};

use super::{Identification, IdentifyError, Target};
use crate::data::{delayed, lagged, Frame};
use crate::select::Moments;
use crate::term::{Library, Term};

/// An input found to act late.
#[derive(Clone, Debug, PartialEq)]
pub struct Lag {
    /// The column.
    pub column: String,
    /// How much later it acts, s (0 where a first-order lag explains it and no dead time does).
    pub seconds: f64,
    /// The residual sum of squares of all candidates with it delayed so, over that without
    /// (where no dead time is found, `seconds` 0: through its first-order lag).
    pub share: f64,
    /// The longest delay tried, s.
    pub longest: f64,
    /// The time constant of a first-order lag (an actuator's, s) that explains the rate better
    /// than the dead time does, over the same rows, where one does: a lag of 0.5 s read as
    /// 0.45 s late left stand-in terms (u·x², u²·x, x³) beside it.
    pub first_order: Option<f64>,
}

/// A delay is said where it leaves at most this share of the residual sum of squares of none:
/// noise and a slightly wrong library move it by a few per cent; a missed dead time of a few
/// samples leaves most of the residual.
const SHARE: f64 = 0.5;

/// A fit that leaves at most this share of the target's sum of squares (its residuals'
/// RMS a ten-thousandth of the target's spread: a clean record's rounding and derivative
/// error) is not scanned: whatever is left is too small to bias a coefficient visibly, and
/// its shape (smooth, so correlated) would be taken for a delay's.
const NEGLIGIBLE: f64 = 1e-8;

/// A delay is said only where it explains more than this share of the target's sum of
/// squares (what is left without it, RMS a thousandth of the target's spread, biases no
/// coefficient by more than about that): below it, a near-constant combination of the
/// candidates (a fast state that follows another and the input) leaves rounding and quadrature
/// error that the input read one sample off takes up, a valley of the scan that is no delay.
const GAIN: f64 = 1e-6;

/// A first-order lag found where no dead time is (a hidden state of its own, which may stand
/// in for another the records lack) is said only where it leaves at most this share of the
/// residual of the input as recorded: a mass-spring recorded by its position alone had its
/// missing velocity's part halved by a lag of 0.96 s (0.49 left); an actuator's lag of 2 s
/// left 3·10⁻⁸ noise-free, 0.006 at noise of 1 % of span.
const LAG_SHARE: f64 = 0.1;

/// … and only where it explains more than this share of the target's sum of squares (what is
/// left without it, RMS a hundredth of the target's spread): a rudder turned at its rate
/// between samples 0.1 s apart, its corners cut by the line between them, left 1.3·10⁻⁶ of the
/// heading's rate, 88 % of which a lag of one sample took up, and the fit through it chose
/// two spurious terms.
const LAG_GAIN: f64 = 1e-4;

/// How many rows a rate's residuals must be correlated over for the scan: a square wave acting
/// 0.5 s late, its misfit in bursts after each of its jumps, left 1.46 (the scan asked for 1.5
/// and the delay went unsaid); white residuals read 1.0-1.04.
const CORRELATED: f64 = 1.2;

/// The rows a scan reads at most (about 20 passes over them): a delay shows in any stretch
/// of the record it acts in, and 200 000 rows of Lorenz took 0.9 s to scan whole.
const ROWS: usize = 20_000;

/// Delays tried on the coarse grid, in samples; the best is then refined sample by sample
/// between its neighbours on the grid.
const GRID: [usize; 17] = [0, 1, 2, 3, 4, 6, 8, 11, 16, 22, 32, 45, 64, 90, 128, 181, 256];

impl Identification<'_> {
    /// The columns of `columns` the candidates use that act on `target` later than recorded:
    /// for each, over the runs' first 20 000 rows in all (each run its share), the residual
    /// sum of squares of all `candidates` together over the same rows
    /// (each run from a tenth of the shortest run's length on) with the column read d earlier,
    /// d from 0 to 256 samples (0, 1, 2, 3, 4, 6, 8, 11, … each about √2 times the last) up to
    /// a tenth of the shortest run, refined to the sample between the best one's neighbours;
    /// found where the best d leaves at most half the residual sum of squares of none.
    pub fn scan_delays(
        &self,
        target: &Target,
        candidates: &[Term],
        frames: &[Frame],
        columns: &[String],
    ) -> Result<Vec<Lag>, IdentifyError> {
        let library = Library::compile(candidates, self.vocabulary)?;
        // a long record scanned by its start: each run its share of [`ROWS`]
        let total: usize = frames.iter().map(Frame::len).sum();
        let frames: Vec<Frame> = frames
            .iter()
            .map(|f| match total > ROWS {
                true => f.slice(0..(f.len() * ROWS).div_ceil(total).max(200).min(f.len())),
                false => f.clone(),
            })
            .collect();
        let frames = frames.as_slice();
        let step = frames.iter().map(|f| crate::data::median_step(f.time())).fold(f64::INFINITY, f64::min);
        let shortest = frames.iter().map(Frame::duration).fold(f64::INFINITY, f64::min);
        let longest = 0.1 * shortest;
        if !(step > 0.0 && longest >= step) {
            return Ok(Vec::new());
        }
        let mut out = Vec::new();
        let rss_of = |runs: &[Frame]| -> Result<(f64, f64), IdentifyError> {
            let mut m = Moments::new(library.len());
            for part in self.moments_of_runs(&library, candidates, target, runs)? {
                m.merge(&part);
            }
            Ok(full_rss(&m, self.intercept))
        };
        for column in columns.iter().filter(|c| library.inputs().contains(c)) {
            let rss = |samples: usize| -> Result<(f64, f64), IdentifyError> {
                let runs = frames
                    .iter()
                    .map(|f| delayed(f, column, samples as f64 * step, longest))
                    .collect::<Result<Vec<_>, _>>()?;
                rss_of(&runs)
            };
            let (none, total) = rss(0)?;
            if none <= NEGLIGIBLE * total {
                continue;
            }
            let rss = |samples: usize| -> Result<f64, IdentifyError> {
                Ok(if samples == 0 { none } else { rss(samples)?.0 })
            };
            let grid: Vec<usize> = GRID.iter().copied().filter(|&k| k as f64 * step <= longest).collect();
            let tried: Vec<(usize, f64)> =
                grid.iter().map(|&k| Ok((k, rss(k)?))).collect::<Result<_, IdentifyError>>()?;
            let best = (0..tried.len()).min_by(|&a, &b| tried[a].1.total_cmp(&tried[b].1)).unwrap_or(0);
            if best == 0 || tried[best].1 > SHARE * none || none - tried[best].1 <= GAIN * total {
                // no dead time; a first-order lag of some length may still explain it (one of
                // 2 s behind a mass-spring reads as no dead time at all: its input is not
                // only late but smoothed)
                if let Some((t, share)) = first_order(&rss_of, frames, column, 0.0, step, shortest)? {
                    out.push(Lag {
                        column: column.clone(),
                        seconds: 0.0,
                        share,
                        longest,
                        first_order: Some(t),
                    });
                }
                continue;
            }
            let (k, r) = valley(&rss, tried, best, 0)?;
            let seconds = k as f64 * step;
            let first_order = first_order(&rss_of, frames, column, seconds, step, shortest)?.map(|(t, _)| t);
            out.push(Lag { column: column.clone(), seconds, share: r / none, longest, first_order });
        }
        Ok(out)
    }
}

/// The residual sum of squares of a rate over some runs, and the rate's own sum of squares.
type Residuals<'a> = dyn Fn(&[Frame]) -> Result<(f64, f64), IdentifyError> + 'a;

/// The time constant of a first-order lag of `column` that explains the rate better than its
/// dead time of `seconds` (0: none found) does, over the same rows, with the share of the
/// residual sum of squares it leaves of that of the column as recorded there, where one does
/// (`rss_of` the runs: the residual sum of squares and the target's): time constants of 1 to
/// 256 samples (each about √2 times the last) up to twice the dead time (a lag of T reads as a
/// dead time a little short of T: 0.5 s as 0.45 s), or without one up to a tenth of the
/// `shortest` run, refined to the sample between the best one's neighbours, all over the rows
/// from five of the longest tried on ([`crate::data::SETTLED`]: where a lag's start at rest
/// has died away); found where the best leaves less than the dead time, and at most half of
/// the residual of the column as recorded there, explaining more than 10⁻⁶ of the target;
/// without a dead time, at most a tenth, explaining more than 10⁻⁴ ([`LAG_SHARE`], [`LAG_GAIN`]).
/// None where those rows are fewer than half the shortest run's.
fn first_order(
    rss_of: &Residuals<'_>,
    frames: &[Frame],
    column: &str,
    seconds: f64,
    step: f64,
    shortest: f64,
) -> Result<Option<(f64, f64)>, IdentifyError> {
    let top = if seconds > 0.0 { 2.0 * seconds + step } else { 0.1 * shortest };
    let from = crate::data::SETTLED * top;
    if from > 0.5 * shortest * (1.0 + 1e-9) {
        return Ok(None);
    }
    let read_late = |delay: f64| -> Result<(f64, f64), IdentifyError> {
        let runs = frames.iter().map(|f| delayed(f, column, delay, from)).collect::<Result<Vec<_>, _>>()?;
        rss_of(&runs)
    };
    let (none, total) = read_late(0.0)?;
    let dead = if seconds > 0.0 { read_late(seconds)?.0 } else { none };
    // read between its samples as a lag's input is (a smooth command through an actuator of
    // 0.5 s was taken as held by the rates' fit, and a held reading's half sample put the lag a
    // sample short)
    let read: Vec<Frame> = frames
        .iter()
        .map(|f| {
            let mut f = f.clone();
            let auto = crate::data::Intersample::Auto;
            match f.column(column).is_some_and(|c| crate::data::held_through_lag(c, auto)) {
                true => f.hold(column)?,
                false => f.release(column),
            }
            Ok(f)
        })
        .collect::<Result<_, crate::data::DataError>>()?;
    let rss = |samples: usize| -> Result<f64, IdentifyError> {
        let runs = read
            .iter()
            .map(|f| lagged(f, &[(column, samples as f64 * step)], from))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(rss_of(&runs)?.0)
    };
    let grid: Vec<usize> = GRID.iter().copied().filter(|&k| k >= 1 && k as f64 * step <= top).collect();
    let tried: Vec<(usize, f64)> =
        grid.iter().map(|&k| Ok((k, rss(k)?))).collect::<Result<_, IdentifyError>>()?;
    let Some(best) = (0..tried.len()).min_by(|&a, &b| tried[a].1.total_cmp(&tried[b].1)) else {
        return Ok(None);
    };
    let (k, r) = valley(&rss, tried, best, 1)?;
    let found = match seconds > 0.0 {
        true => r < dead && r <= SHARE * none && none - r > GAIN * total,
        false => r <= LAG_SHARE * none && none - r > LAG_GAIN * total,
    };
    Ok(found.then_some((k as f64 * step, r / none)))
}

/// The bottom of a scan's valley: `tried` (samples, residual) on a grid, its best at index
/// `best`, searched sample by sample between the best one's neighbours on the grid (ternary
/// search; from `least` where the best is the first), by `rss`; the best of all tried.
fn valley(
    rss: &dyn Fn(usize) -> Result<f64, IdentifyError>,
    mut tried: Vec<(usize, f64)>,
    best: usize,
    least: usize,
) -> Result<(usize, f64), IdentifyError> {
    let (mut lo, mut hi) = (
        best.checked_sub(1).map_or(least, |b| tried[b].0),
        tried.get(best + 1).map_or(tried[best].0, |t| t.0),
    );
    while hi - lo > 2 {
        let (a, b) = (lo + (hi - lo) / 3, hi - (hi - lo) / 3);
        let (ra, rb) = (rss(a)?, rss(b)?);
        tried.extend([(a, ra), (b, rb)]);
        if ra <= rb {
            hi = b;
        } else {
            lo = a;
        }
    }
    for k in lo..=hi {
        if !tried.iter().any(|t| t.0 == k) {
            let r = rss(k)?;
            tried.push((k, r));
        }
    }
    Ok(tried.iter().copied().min_by(|a, b| a.1.total_cmp(&b.1)).unwrap_or(tried[best]))
}

impl Lag {
    /// What the lag means for the fit of `target`, and `remedy`: how to fit it.
    pub fn note(&self, target: &Target, remedy: &str) -> String {
        let s = crate::output::sig(self.seconds, 3);
        if let (Some(t), true) = (self.first_order, self.seconds == 0.0) {
            return format!(
                "`{}` acts on {target} through a first-order lag of about {} s (an actuator's, \
                 a valve's): read through it, the candidates all together leave {} % of the \
                 residual sum of squares they leave without (time constants up to {} s tried; \
                 no dead time explains it), so the coefficients above are biased; {remedy}",
                self.column,
                crate::output::sig(t, 3),
                crate::output::sig(100.0 * self.share, 2),
                crate::output::sig(self.longest, 3),
            );
        }
        let lag = match self.first_order {
            Some(t) => format!(
                "; a first-order lag of {} s (an actuator's) explains it better still, over the same rows",
                crate::output::sig(t, 3)
            ),
            None => String::new(),
        };
        format!(
            "`{}` acts on {target} about {s} s later than the rows have it (a dead time, or a lag \
             of about that): read {s} s earlier, the candidates all together leave {} % of the \
             residual sum of squares they leave without (delays of 0 to {} s tried){lag}, so the \
             coefficients above are biased; {remedy}",
            self.column,
            crate::output::sig(100.0 * self.share, 2),
            crate::output::sig(self.longest, 3),
        )
    }

    /// How plain runs fit it: `--delay` (or `--lag`, for a first-order lag) on the command
    /// line, `delays=` (`lags=`) in Python.
    pub fn plain_remedy(&self) -> String {
        let (flag, python, seconds) = match self.first_order {
            Some(t) => ("--lag", "lags", t),
            None => ("--delay", "delays", self.seconds),
        };
        let s = crate::output::sig(seconds, 3);
        format!("fit it so with {flag} {}={s} (Python `{python}={{\"{}\": {s}}}`)", self.column, self.column)
    }
}

impl Identification<'_> {
    /// [`Identification::scan_delays`] where the fit of a rate left its residuals correlated
    /// over more than 1.2 rows (a missed dead time leaves them smooth; white
    /// residuals have nothing to find, and the scan's 20 fits cost five times a small system's
    /// identification), each lag found said in the fit's notes with its `remedy`; the lags said.
    pub fn say_delays(
        &self,
        target: &Target,
        candidates: &[Term],
        frames: &[Frame],
        columns: &[String],
        fit: &mut super::Fit,
        remedy: &dyn Fn(&Lag) -> String,
    ) -> Result<Vec<Lag>, IdentifyError> {
        if !matches!(target, Target::Derivative(_)) || !fit.correlation_time.is_some_and(|t| t > CORRELATED) {
            return Ok(Vec::new());
        }
        // a fit that leaves nothing to explain has no delay to find: the scan's own measure,
        // every candidate at once, passes over their collinear directions and may leave more
        // (a six-mass chain's exact four terms left 4·10⁻¹⁴ of the rate, its 120 cubic
        // candidates together more than 10⁻⁸, and the input read a sample early took up 82 %
        // of that: a dead time said of a record that had none, its re-identification 100 s)
        if fit.selection.chosen_r2().is_some_and(|r2| 1.0 - r2 <= NEGLIGIBLE) {
            return Ok(Vec::new());
        }
        let late = self.scan_delays(target, candidates, frames, columns)?;
        for lag in &late {
            fit.selection.notes.push(lag.note(target, &remedy(lag)));
        }
        Ok(late)
    }
}

/// The residual sum of squares of the target on every regressor of `m` together (about the
/// means where `intercept`), by a pseudo-inverse that passes over collinear directions and
/// regressors that do not vary (the constant about its mean), beside the target's own sum of
/// squares (which it is where the decomposition does not converge).
fn full_rss(m: &Moments, intercept: bool) -> (f64, f64) {
    let p = m.regressors();
    let product = |i: usize, j: usize| if intercept { m.corrected(i, j) } else { m.raw(i, j) };
    let yy = product(p, p);
    // scaled to unit diagonal, so that the tolerance means the same for every column
    let used: Vec<usize> = (0..p).filter(|&i| product(i, i) > 0.0 && product(i, i).is_finite()).collect();
    if used.is_empty() || !yy.is_finite() {
        return (yy, yy);
    }
    let scale: Vec<f64> = used.iter().map(|&i| product(i, i).sqrt()).collect();
    let k = used.len();
    let a = DMatrix::from_fn(k, k, |r, c| product(used[r], used[c]) / (scale[r] * scale[c]));
    let b = DVector::from_fn(k, |r, _| product(used[r], p) / scale[r]);
    let Some(svd) = a.try_svd(true, true, 1e-15, 10_000) else { return (yy, yy) };
    let Ok(pinv) = svd.pseudo_inverse(1e-12) else { return (yy, yy) };
    ((yy - b.dot(&(pinv * &b))).max(0.0), yy)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = 2x + 3z exactly: nothing left; y on x alone leaves 9 Σ z² (x and z unrelated).
    #[test]
    fn full_rss_is_what_least_squares_leaves() {
        let x: Vec<f64> = (0..50).map(|k| (0.3 * k as f64).sin()).collect();
        let z: Vec<f64> = (0..50).map(|k| (0.7 * k as f64).cos()).collect();
        let y: Vec<f64> = x.iter().zip(&z).map(|(x, z)| 2.0 * x + 3.0 * z).collect();
        let mut both = crate::select::Accumulator::new(2);
        both.push_columns(&[&x, &z], &y, None);
        // nothing left but rounding, relative to Σy²
        let (left, total) = full_rss(&both.finish(), false);
        assert!(left < 1e-14 * total, "{left} of {total}");
        // about the means, the constant does not vary: passed over, not divided by zero
        let ones = vec![1.0; 50];
        let mut with_one = crate::select::Accumulator::new(3);
        with_one.push_columns(&[&x, &z, &ones], &y, None);
        let (left, total) = full_rss(&with_one.finish(), true);
        assert!(left < 1e-14 * total, "{left} of {total}");
        let mut one = crate::select::Accumulator::new(1);
        one.push_columns(&[&x], &y, None);
        let (left, total) = full_rss(&one.finish(), false);
        // what x cannot take of 3z: 9 (Σz² − (Σxz)²/Σx²)
        let (sxx, sxz, szz): (f64, f64, f64) = (
            x.iter().map(|v| v * v).sum(),
            x.iter().zip(&z).map(|(a, b)| a * b).sum(),
            z.iter().map(|v| v * v).sum(),
        );
        let want = 9.0 * (szz - sxz * sxz / sxx);
        assert!((left - want).abs() < 1e-9 * want, "{left} vs {want}");
        let yy: f64 = y.iter().map(|v| v * v).sum();
        assert!((total - yy).abs() < 1e-12 * yy);
    }
}
