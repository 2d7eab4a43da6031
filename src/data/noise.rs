//! How much white noise a record carries: the spread of its fourth differences, in which a
//! motion sampled finely leaves almost nothing and white noise of σ leaves a spread of √70 σ.
//! Where the motion shows through (a coarse record) the noise cannot be told from it; noise
//! correlated over more than a few samples shows less than it is.

use super::Frame;

/// Σ C(4, k)² = C(8, 4): the variance of the fourth difference of white noise of unit variance.
const FOURTH: f64 = 70.0;

/// Σ C(3, k)² = C(6, 3): the same for the third difference.
const THIRD: f64 = 20.0;

/// The fourth differences' noise over the third's below which the motion is taken to show
/// through: white noise gives 1 from both, a motion sampled k times a period leaves the
/// fourth difference (2π/k) times the third's.
const WHITE: f64 = 0.8;

/// The noise over two samples over that over one from which the noise is taken to be
/// correlated from sample to sample: white noise reads alike over both, a motion leaking into
/// the two-sample reading raised it by up to 1.18 (FitzHugh-Nagumo at 1 %), noise filtered to
/// a correlation of 0.5 from sample to sample by about 1.3.
const CORRELATED: f64 = 1.2;

/// The white noise on a record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// Its standard deviation, in the record's unit; where not `measured`, at most this.
    pub sd: f64,
    /// Whether the differences are white: where the motion shows through them (a record too
    /// coarse: its third differences spread more than white noise would give beside its
    /// fourth), `sd` bounds the noise from above and does not measure it.
    pub measured: bool,
    /// Whether it reads more over two samples than over one: noise correlated from sample to
    /// sample, of which `sd` is a lower bound.
    pub correlated: bool,
}

/// The white noise on `x`: its fourth differences' median absolute value (robust to a few
/// glitches) scaled to σ, over one sample, and over two where that reads a fifth more and
/// the motion does not show through it either. Noise correlated from sample to sample (a filtered
/// sensor's) shows less over one sample than it is; over two, more of it (on the ODE
/// benchmark's 37 systems, noise of 5 % of the spread filtered to a correlation of 0.8 from
/// sample to sample reads 1.7-1.9 % over one sample, 2.4-2.7 % over both; white noise of 1 %
/// reads 0.99-1.06 % either way). `None` for a record under 20 samples or one not
/// finite. A held or quantised record whose differences are mostly 0 gives 0.
pub fn white_noise(x: &[f64]) -> Option<Noise> {
    white_noise_beside(x, &[])
}

/// [`white_noise`] of a record whose motion kinks where inputs held from each sample to the
/// next (`stepped`: a controller's command, a generator's excitation, a telegraph) step:
/// what their values explain of its differences (a linear regression on the values each
/// difference spans) is motion, not noise. ẋ = −x + 2u with u white and held read "at
/// least 12 %" of a record that had none.
pub fn white_noise_beside(x: &[f64], stepped: &[&[f64]]) -> Option<Noise> {
    white_noise_of(x, None, stepped)
}

/// [`white_noise_beside`] of a record sampled at `times` (or evenly, `None`): unevenly spaced
/// samples (a logger's jitter) are differenced by the polynomials through their neighbours at
/// their own times, which leave a smooth motion nothing as even differences do (read as if
/// even, a jitter of a fifth of the step made the Lotka-Volterra cycle's motion read 0.1 % of
/// its span as noise it did not have).
fn white_noise_of(x: &[f64], times: Option<&[f64]>, stepped: &[&[f64]]) -> Option<Noise> {
    if x.len() < 20 || x.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let one = over(x, times, 1, stepped);
    if !one.measured || x.len() < 4 * 2 + 20 {
        return Some(one);
    }
    let two = over(x, times, 2, stepped);
    if two.sd > MOTION * one.sd {
        // the motion's own fourth difference, not noise: it bounds the noise from above
        return Some(Noise { measured: false, ..one });
    }
    // (a margin, so that white noise keeps its one-sample reading, not the larger of two
    // readings that scatter alike, nor one the motion raised)
    Some(if two.measured && two.sd > CORRELATED * one.sd { Noise { correlated: true, ..two } } else { one })
}

/// The noise over two samples over that over one beyond which the reading is the motion's:
/// a motion's fourth difference grows sixteen-fold from one sample to two, noise correlated
/// 0.8 from sample to sample about 1.4-fold. A lynx population sampled yearly (ten samples a
/// cycle, its peaks sharp enough that its fourth differences pass for white over one sample)
/// read "at least 53 %" noise of a record that had none.
const MOTION: f64 = 4.0;

/// The noise read off the differences of `x` (sampled at `times`, or evenly) over `lag`
/// samples, less what the `stepped` inputs' values explain of them.
fn over(x: &[f64], times: Option<&[f64]>, lag: usize, stepped: &[&[f64]]) -> Noise {
    let (third, fourth) = match times {
        Some(t) => timed_differences(x, t, lag),
        None => {
            let third: Vec<f64> = (0..x.len() - 3 * lag)
                .map(|k| x[k + 3 * lag] - 3.0 * x[k + 2 * lag] + 3.0 * x[k + lag] - x[k])
                .collect();
            let fourth: Vec<f64> = (0..third.len() - lag).map(|k| third[k + lag] - third[k]).collect();
            (third, fourth)
        }
    };
    let (third, fourth) = match stepped {
        [] => (third, fourth),
        _ => (
            explained(&third, stepped, 3 * lag).map_or(third, |r| r.residuals),
            explained(&fourth, stepped, 4 * lag).map_or(fourth, |r| r.residuals),
        ),
    };
    let (s3, s4) = (robust_sd(third) / THIRD.sqrt(), robust_sd(fourth) / FOURTH.sqrt());
    Noise { sd: s4, measured: s4 >= WHITE * s3, correlated: false }
}

/// The third and fourth differences over `lag` samples of `x` sampled at `times`, unevenly:
/// each sample less the polynomial through the samples before it (the third: a quadratic
/// through three) or about it (the fourth: a cubic through the two each side) at its time,
/// scaled so that white noise spreads it as it spreads the even differences (by √20 and √70
/// over the root of one plus the polynomial's squared weights). At even steps they are the
/// even differences: the cubic through x₋₂, x₋₁, x₁, x₂ is (−x₋₂ + 4x₋₁ + 4x₁ − x₂)/6 at 0.
fn timed_differences(x: &[f64], t: &[f64], lag: usize) -> (Vec<f64>, Vec<f64>) {
    // sample `at` less the polynomial through the samples `through` at its time, scaled
    let left = |at: usize, through: &[usize], scale: f64| -> f64 {
        let mut predicted = 0.0;
        let mut squares = 1.0;
        for &i in through {
            let w: f64 =
                through.iter().filter(|&&j| j != i).map(|&j| (t[at] - t[j]) / (t[i] - t[j])).product();
            predicted += w * x[i];
            squares += w * w;
        }
        let r = (x[at] - predicted) * scale / squares.sqrt();
        // (a frame's times increase, so the weights are finite; should two samples share
        // a time, their difference tells nothing)
        if r.is_finite() {
            r
        } else {
            0.0
        }
    };
    let third: Vec<f64> = (0..x.len().saturating_sub(3 * lag))
        .map(|k| left(k + 3 * lag, &[k, k + lag, k + 2 * lag], THIRD.sqrt()))
        .collect();
    let fourth: Vec<f64> = (0..x.len().saturating_sub(4 * lag))
        .map(|k| left(k + 2 * lag, &[k, k + lag, k + 3 * lag, k + 4 * lag], FOURTH.sqrt()))
        .collect();
    (third, fourth)
}

/// The white noise that `x`'s fourth differences over `lag` samples read, whatever the motion
/// (`over`'s reading alone): how it grows with the lag tells a stationary noise from a path of
/// independent steps. `None` for a record under 20 samples beyond the differences' reach.
pub(crate) fn fourth_differences_over(x: &[f64], lag: usize) -> Option<f64> {
    (x.len() >= 4 * lag + 20).then(|| over(x, None, lag, &[]).sd)
}

/// A difference series regressed on the values of inputs that each of its terms spans.
struct Explained {
    /// What is left of the differences.
    residuals: Vec<f64>,
    /// The regression's F statistic (explained over residual variance per degree of freedom).
    f: f64,
}

/// `d` (d[k] a difference of a record over samples k ..= k + span) regressed on the values
/// `u[k ..= k + span]` of each input in `inputs` (and a constant): a state driven by inputs
/// held from each sample to the next changes its rate at each of their steps, so its
/// differences are a fixed combination of the input values they span, give or take the
/// state's own slower terms. `None` where the rows do not determine the regression.
fn explained(d: &[f64], inputs: &[&[f64]], span: usize) -> Option<Explained> {
    let p = 1 + inputs.len() * (span + 1);
    let n = d.len().min(inputs.iter().map(|u| u.len().saturating_sub(span)).min()?);
    if n <= 2 * p {
        return None;
    }
    let row = |k: usize| {
        std::iter::once(1.0).chain(inputs.iter().flat_map(move |u| u[k..=k + span].iter().copied()))
    };
    let mut a = nalgebra::DMatrix::<f64>::zeros(p, p);
    let mut b = nalgebra::DVector::<f64>::zeros(p);
    for (k, dk) in d[..n].iter().enumerate() {
        let r = nalgebra::DVector::from_iterator(p, row(k));
        b.axpy(*dk, &r, 1.0);
        a.ger(1.0, &r, &r, 1.0);
    }
    let beta = a.cholesky()?.solve(&b);
    let residuals: Vec<f64> =
        (0..n).map(|k| d[k] - row(k).zip(beta.iter()).map(|(r, b)| r * b).sum::<f64>()).collect();
    let mean = d[..n].iter().sum::<f64>() / n as f64;
    let total: f64 = d[..n].iter().map(|v| (v - mean).powi(2)).sum();
    let left: f64 = residuals.iter().map(|r| r * r).sum();
    let f = ((total - left).max(0.0) / (p - 1) as f64) / (left / (n - p) as f64).max(f64::MIN_POSITIVE);
    Some(Explained { residuals, f })
}

/// The F statistic beyond which a record is taken to follow an input's steps: the kinks of a
/// state it drives stand far above what chance gives (F ≈ 1), noise on a value held steady
/// drives nothing.
const FOLLOWS: f64 = 30.0;

/// Whether some record of `frame` other than `name` (a column held from each sample to the
/// next, `u`) and not held itself follows its steps: its fourth differences regress on the
/// values they span.
fn followed(frame: &Frame, name: &str, u: &[f64]) -> bool {
    frame.names().iter().skip(1).filter(|c| *c != name && !frame.is_held(c)).any(|c| {
        frame.column(c).is_some_and(|x| {
            let fourth: Vec<f64> = (0..x.len().saturating_sub(4))
                .map(|k| x[k + 4] - 4.0 * x[k + 3] + 6.0 * x[k + 2] - 4.0 * x[k + 1] + x[k])
                .collect();
            explained(&fourth, &[u], 4).is_some_and(|e| e.f > FOLLOWS)
        })
    })
}

/// The step of the grid a record's values sit on, where the record is read so coarsely that
/// it moves one step at a time (a motion printed with few digits, an encoder's counts): its
/// rounding is then noise of step/√12 that the differences do not see (they are mostly 0, or
/// a staircase). `None` where the values move by other amounts, or by single steps over fewer
/// than ten levels (a command switched between levels is no rounding).
pub fn quantum(x: &[f64]) -> Option<f64> {
    grid(x).filter(|g| g.staircase).map(|g| g.step)
}

/// The grid a record's values sit on: every step between samples a whole number of the
/// smallest, over ten levels at least.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Grid {
    /// The smallest step, the grid's.
    step: f64,
    /// Whether 80 % of the steps are single ones: a staircase, whose differences misread its
    /// rounding (a sine printed to a tenth of its amplitude reads 1.8 times its rounding's σ).
    staircase: bool,
    /// Whether it rests on a level over a tenth of its intervals at least: where it moves
    /// slowly its rounding holds it, which its differences do not see. A motion that only
    /// happens to sit on a grid (a triangle wave whose steps are three of its corners') never
    /// rests.
    rests: bool,
}

/// The share of a record's intervals over which it rests on a level from which its rounding
/// shows ([`Grid::rests`]).
const RESTS: f64 = 0.1;

/// The grid `x` sits on ([`Grid`]); `None` where its values move by other amounts, by fewer
/// than 20 steps, or over fewer than ten levels (a command switched between levels is no
/// rounding).
fn grid(x: &[f64]) -> Option<Grid> {
    let steps: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).filter(|d| *d > 0.0).collect();
    if steps.len() < 20 || steps.iter().any(|d| !d.is_finite()) {
        return None;
    }
    let rests = (x.len() - 1 - steps.len()) as f64 >= RESTS * (x.len() - 1) as f64;
    let q = steps.iter().copied().fold(f64::INFINITY, f64::min);
    let mut single = 0;
    for d in &steps {
        let n = (d / q).round();
        // decimal digits read as binary numbers leave a relative error of ~1e-15 of the values
        if (d / q - n).abs() > 1e-6 * n.max(1.0) {
            return None;
        }
        single += usize::from(n == 1.0);
    }
    let (low, high) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
    ((high - low) / q >= 9.0).then_some(Grid {
        step: q,
        staircase: single as f64 >= 0.8 * steps.len() as f64,
        rests,
    })
}

/// A variable's white noise and spread gathered over records read whole or in pieces and
/// merged in any grouping: what the identification's noise note and check compare (a plain
/// value, written with an equation's statistics).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NoiseTally {
    /// Σ σ² × rows over the records whose noise was measured ([`white_noise`]).
    pub noise: f64,
    /// The rows of those records.
    pub noise_rows: usize,
    /// The rows of those whose noise read correlated ([`Noise::correlated`]).
    #[serde(default)]
    pub correlated_rows: usize,
    /// The rows of those not recorded but estimated (a rate from another state's record,
    /// [`Frame::estimated_error`]): their noise is the estimate's standard error.
    #[serde(default)]
    pub estimated_rows: usize,
    /// Σ σ² × rows over the records whose noise was only bounded ([`Noise::measured`]: the
    /// motion shows through).
    pub bound: f64,
    /// The rows of those records.
    pub bound_rows: usize,
    /// All rows seen.
    pub rows: usize,
    /// The mean of the rows seen.
    pub mean: f64,
    /// Their sum of squared deviations from `mean` (Welford).
    pub m2: f64,
}

/// The share of the rows whose noise was measured from which the tally measures it: a short
/// run or a few coarse ones among long fine ones do not turn a measurement into a bound.
const MEASURED_ROWS: f64 = 0.9;

impl NoiseTally {
    /// The tally of column `name` over the `own` rows of `frame`, a run or a piece of one with
    /// its neighbours' rows around (its fourth differences read across them); `None` where
    /// the frame has no such column. A column held or switched between samples (a command:
    /// [`Frame::held`]) is not taken for a motion rounded to its levels.
    ///
    /// Inputs held from each sample to the next (a command, a generator's excitation stepped
    /// at every sample, [`super::white`], or switched at random ones) kink the records they
    /// drive at each step, which is motion: what their values explain of a record's
    /// differences is not counted as its noise. Such an input that a record follows is its
    /// generator's exact values, without noise; one that none follows is measured (one
    /// stepped at every sample is then the noise of a value held steady).
    ///
    /// A slower sensor's readings, read at them and interpolated between
    /// ([`Frame::readings_of`]), carry the readings' noise, which the cubics between them hide
    /// (a swing read every tenth row with noise of 1 % read 5·10⁻¹⁴ %): it is read at the
    /// readings (without the held inputs' steps, which act between them).
    pub fn of(frame: &Frame, name: &str, own: std::ops::Range<usize>) -> Option<NoiseTally> {
        let x = frame.column(name)?;
        if let Some(error) = frame.estimated_error(name) {
            // a rate estimated from another record: the smoother's error, smooth itself, is
            // what a regressor made of it carries
            let spread = Self::spread(x.get(own).unwrap_or_default());
            let rows = spread.rows;
            return Some(NoiseTally {
                noise: error * error * rows as f64,
                noise_rows: rows,
                estimated_rows: rows,
                ..spread
            });
        }
        if let Some(r) = frame.readings_of(name) {
            let at: Vec<usize> = r.readings(x.len()).collect();
            let read: Vec<f64> = at.iter().map(|&k| x[k]).collect();
            return Some(Self::of_values(&read, None, among(&at, own), true, &[]));
        }
        // (a column stepped at every sample that no record follows is a value's noise, and may
        // be rounded)
        let command =
            frame.held().iter().chain(frame.switched()).any(|c| c == name) && super::white(x).is_none();
        let stepped: Vec<(&String, &[f64])> =
            frame.held().iter().filter_map(|c| frame.column(c).map(|u| (c, u))).collect();
        if stepped.iter().any(|(c, u)| *c == name && followed(frame, name, u)) {
            let spread = Self::spread(x.get(own).unwrap_or_default());
            return Some(NoiseTally { noise_rows: spread.rows, ..spread });
        }
        let others: Vec<&[f64]> = stepped.iter().filter(|(c, _)| *c != name).map(|(_, u)| *u).collect();
        if frame.recorded().is_some() {
            // resampled onto a finer grid (a logger's jitter): the cubics' rows between the
            // samples are smooth (noise of 3 % of the spread read 0.09 %), so it is read at
            // the samples, at their own times
            let at: Vec<usize> = (0..x.len()).filter(|&k| frame.is_sample(k)).collect();
            let pick = |v: &[f64]| -> Vec<f64> { at.iter().map(|&k| v[k]).collect() };
            let others: Vec<Vec<f64>> = others.iter().map(|u| pick(u)).collect();
            let others: Vec<&[f64]> = others.iter().map(Vec::as_slice).collect();
            let times = pick(frame.time());
            return Some(Self::of_values(&pick(x), Some(&times), among(&at, own), !command, &others));
        }
        Some(Self::of_values(x, None, own, !command, &others))
    }

    /// The tally of the `own` rows of `x` (sampled at `times`, or evenly), its rounding counted
    /// where `rounded` allows, less what the held inputs `stepped` explain
    /// ([`white_noise_beside`]).
    pub(crate) fn of_values(
        x: &[f64],
        times: Option<&[f64]>,
        own: std::ops::Range<usize>,
        rounded: bool,
        stepped: &[&[f64]],
    ) -> NoiseTally {
        let rows = x.get(own).unwrap_or_default();
        let mut tally = NoiseTally::default();
        // a record too short for fourth differences still spreads the variable; one read on a
        // grid carries its rounding's noise at least, which its differences misread: a
        // staircase's (a sine printed to a tenth of its amplitude reads 1.8 times its
        // rounding's σ), and one that rests on a level over stretches where it moves slowly
        // (an encoder's counts of a decaying swing, its steps of up to four counts: most of
        // its fourth differences 0, the noise read 0)
        let rounding = |g: Grid| Noise { sd: g.step / 12f64.sqrt(), measured: true, correlated: false };
        let found = match grid(x).filter(|_| rounded) {
            Some(g) if g.staircase => Some(rounding(g)),
            Some(g) if g.rests => Some(
                white_noise_of(x, times, stepped).filter(|w| w.sd >= rounding(g).sd).unwrap_or(rounding(g)),
            ),
            _ => white_noise_of(x, times, stepped),
        };
        if let Some(found) = found {
            let (sum, count) = if found.measured {
                (&mut tally.noise, &mut tally.noise_rows)
            } else {
                (&mut tally.bound, &mut tally.bound_rows)
            };
            *sum = found.sd * found.sd * rows.len() as f64;
            *count = rows.len();
            if found.measured && found.correlated {
                tally.correlated_rows = rows.len();
            }
        }
        let spread = Self::spread(rows);
        NoiseTally { rows: spread.rows, mean: spread.mean, m2: spread.m2, ..tally }
    }

    /// The tally of `rows` with no noise found: their count, mean and squared deviations
    /// (Welford).
    fn spread(rows: &[f64]) -> NoiseTally {
        let mut tally = NoiseTally::default();
        for &v in rows {
            tally.rows += 1;
            let d = v - tally.mean;
            tally.mean += d / tally.rows as f64;
            tally.m2 += d * (v - tally.mean);
        }
        tally
    }

    /// The tallies as one ([`NoiseTally::merge`] in turn).
    pub fn pooled(tallies: impl IntoIterator<Item = NoiseTally>) -> NoiseTally {
        tallies.into_iter().fold(NoiseTally::default(), |mut all, t| {
            all.merge(&t);
            all
        })
    }

    /// Both tallies as one (Chan's update of the mean and the squared deviations: records
    /// about different levels spread the variable too).
    pub fn merge(&mut self, other: &NoiseTally) {
        // (counts read from a file may be anything)
        let rows = self.rows.saturating_add(other.rows);
        if rows > 0 {
            let d = other.mean - self.mean;
            let (a, b) = (self.rows as f64, other.rows as f64);
            self.m2 += other.m2 + d * d * a * b / rows as f64;
            self.mean += d * b / rows as f64;
        }
        self.rows = rows;
        self.noise += other.noise;
        self.noise_rows = self.noise_rows.saturating_add(other.noise_rows);
        self.correlated_rows = self.correlated_rows.saturating_add(other.correlated_rows);
        self.estimated_rows = self.estimated_rows.saturating_add(other.estimated_rows);
        self.bound += other.bound;
        self.bound_rows = self.bound_rows.saturating_add(other.bound_rows);
    }

    /// The noise's standard deviation over the spread of all rows, and whether it was
    /// measured: from the records whose noise was measured where they hold 90 % of the rows
    /// whose noise was found, else from all of them as a bound (`false`). `None` where no
    /// record was long enough to tell or nothing varies.
    pub fn share(&self) -> Option<(f64, bool)> {
        let spread = (self.m2 / self.rows.max(1) as f64).sqrt();
        let found = self.noise_rows as f64 + self.bound_rows as f64;
        if found == 0.0 || !(spread > 0.0 && spread.is_finite()) {
            return None;
        }
        Some(if self.noise_rows as f64 >= MEASURED_ROWS * found {
            ((self.noise / self.noise_rows as f64).sqrt() / spread, true)
        } else {
            (((self.noise + self.bound) / found).sqrt() / spread, false)
        })
    }

    /// The noise's standard deviation as [`NoiseTally::share`] reads it (measured, or a bound).
    pub fn sd(&self) -> Option<f64> {
        let spread = (self.m2 / self.rows.max(1) as f64).sqrt();
        self.share().map(|(share, _)| share * spread)
    }

    /// Whether the noise measured read correlated from sample to sample in most of its rows:
    /// the share is then a lower bound.
    pub fn correlated(&self) -> bool {
        self.correlated_rows as f64 > 0.5 * self.noise_rows as f64
    }

    /// Whether the noise measured is mostly an estimate's standard error (a rate estimated
    /// from another record), not a record's noise.
    pub fn estimated(&self) -> bool {
        self.estimated_rows as f64 > 0.5 * self.noise_rows as f64
    }

    /// Whether rows could have given it: counts that fit, sums not negative, numbers finite.
    pub fn is_consistent(&self) -> bool {
        self.noise_rows.checked_add(self.bound_rows).is_some_and(|n| n <= self.rows)
            && self.correlated_rows <= self.noise_rows
            && self.estimated_rows <= self.noise_rows
            && [self.noise, self.bound, self.m2].iter().all(|v| v.is_finite() && *v >= 0.0)
            && self.mean.is_finite()
    }
}

/// The places in `at` (rows, increasing) of the rows `own`: a run's own rows among the
/// readings or samples a record is read at.
fn among(at: &[usize], own: std::ops::Range<usize>) -> std::ops::Range<usize> {
    let first = at.partition_point(|&k| k < own.start);
    first..first + at[first..].partition_point(|&k| k < own.end)
}

/// 1.4826 times the median absolute value: the standard deviation of Gaussian values about 0.
fn robust_sd(mut values: Vec<f64>) -> f64 {
    values.iter_mut().for_each(|v| *v = v.abs());
    let middle = values.len() / 2;
    let (_, median, _) = values.select_nth_unstable_by(middle, f64::total_cmp);
    1.4826 * *median
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sine sampled 100 times a period with Gaussian noise of 0.05 (Box-Muller on a fixed
    /// sequence): σ found within 5 %; without the noise, at most 10⁻³ of it, unmeasured (the
    /// motion shows through); sampled 6 times a period, unmeasured.
    #[test]
    fn white_noise_is_told_from_a_fine_motion_and_not_claimed_on_a_coarse_one() {
        let mut state = 12345u64;
        let mut uniform = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let gauss: Vec<f64> = (0..20_000)
            .map(|_| (-2.0 * uniform().ln()).sqrt() * (2.0 * std::f64::consts::PI * uniform()).cos())
            .collect();
        let sine = |k: usize, per: f64| (2.0 * std::f64::consts::PI * k as f64 / per).sin();
        let noisy: Vec<f64> = gauss.iter().enumerate().map(|(k, e)| sine(k, 100.0) + 0.05 * e).collect();
        let found = white_noise(&noisy).unwrap();
        assert!(found.measured && (found.sd / 0.05 - 1.0).abs() < 0.05, "{found:?}");
        let clean: Vec<f64> = (0..20_000).map(|k| sine(k, 100.0)).collect();
        let found = white_noise(&clean).unwrap();
        assert!(!found.measured && found.sd < 5e-5, "{found:?}");
        let coarse: Vec<f64> = (0..20_000).map(|k| sine(k, 6.0)).collect();
        assert!(!white_noise(&coarse).unwrap().measured);
        // the same noise filtered to a correlation of 0.8 from sample to sample (a first-order
        // filter, its variance kept): over one sample it reads 0.36 of σ, over two half of it
        let mut filtered = 0.0;
        let correlated: Vec<f64> = gauss
            .iter()
            .enumerate()
            .map(|(k, e)| {
                filtered = 0.8 * filtered + 0.6 * e;
                sine(k, 100.0) + 0.05 * filtered
            })
            .collect();
        let found = white_noise(&correlated).unwrap();
        assert!(found.measured && found.correlated && (0.45..0.6).contains(&(found.sd / 0.05)), "{found:?}");
        assert!(!white_noise(&noisy).unwrap().correlated);
        assert!((over(&correlated, None, 1, &[]).sd / 0.05 - 0.36).abs() < 0.03);
        assert_eq!(white_noise(&[1.0; 100]), Some(Noise { sd: 0.0, measured: true, correlated: false }));
        // the sine printed to a tenth of its amplitude moves a step at a time: its rounding
        // is noise of 0.1/√12 the differences read as 0; a command switched between three
        // levels, or steps of more than one, are no rounding
        let printed: Vec<f64> = clean.iter().map(|v| (v * 10.0).round() / 10.0).collect();
        assert!((quantum(&printed).unwrap() - 0.1).abs() < 1e-12);
        let tally = NoiseTally::of_values(&printed, None, 0..printed.len(), true, &[]);
        let (share, measured) = tally.share().unwrap();
        let sd = share * std::f64::consts::FRAC_1_SQRT_2;
        assert!(
            measured && (sd / (0.1 / 12f64.sqrt()) - 1.0).abs() < 0.05,
            "{sd} {:?}",
            white_noise(&printed)
        );
        assert_eq!(quantum(&(0..300).map(|k| ((k / 20) % 3) as f64).collect::<Vec<_>>()), None);
        assert_eq!(
            quantum(&(0..300).map(|k| (k / 10) as f64 * 2.5 + (k % 2) as f64 * 0.4).collect::<Vec<_>>()),
            None
        );
        assert_eq!(quantum(&noisy), None);
        // an encoder's counts of a decaying swing (0.01 a count, up to four counts a sample):
        // no staircase, and most of its fourth differences 0 where it swings slowly; its
        // rounding is its noise. The noisy sine printed to a thousandth is on a grid too, its
        // noise its own.
        let counts: Vec<f64> = (0..1500)
            .map(|k| {
                let t = k as f64 * 0.02;
                ((-0.2 * t).exp() * (2.0 * t).cos() * 100.0).round() / 100.0
            })
            .collect();
        assert_eq!(quantum(&counts), None);
        assert!(white_noise(&counts).unwrap().sd < 0.1 * 0.01 / 12f64.sqrt());
        let tally = NoiseTally::of_values(&counts, None, 0..counts.len(), true, &[]);
        assert!((tally.sd().unwrap() / (0.01 / 12f64.sqrt()) - 1.0).abs() < 1e-9, "{tally:?}");
        let printed: Vec<f64> = noisy.iter().map(|v| (v * 1000.0).round() / 1000.0).collect();
        let tally = NoiseTally::of_values(&printed, None, 0..printed.len(), true, &[]);
        assert!((tally.sd().unwrap() / 0.05 - 1.0).abs() < 0.05, "{tally:?}");
        assert_eq!(white_noise(&[1.0; 10]), None);
        // a lynx population of Lotka-Volterra (ẋ = 0.55x − 0.028xy, ẏ = 0.024xy − 0.8y) read
        // yearly for 60 years, ten samples a cycle: its peaks are sharp enough that its fourth
        // differences pass for white over one sample, and read 7 times more over two: the
        // motion, no noise ("at least 53 %" of a record that had none)
        let (mut x, mut y) = (30.0f64, 4.0f64);
        let rate = |x: f64, y: f64| (0.55 * x - 0.028 * x * y, 0.024 * x * y - 0.8 * y);
        let lynx: Vec<f64> = (0..61)
            .map(|_| {
                let now = y;
                for _ in 0..1000 {
                    let h = 1e-3;
                    let (a, b) = rate(x, y);
                    let (c, d) = rate(x + 0.5 * h * a, y + 0.5 * h * b);
                    let (e, f) = rate(x + 0.5 * h * c, y + 0.5 * h * d);
                    let (g, i) = rate(x + h * e, y + h * f);
                    x += h / 6.0 * (a + 2.0 * c + 2.0 * e + g);
                    y += h / 6.0 * (b + 2.0 * d + 2.0 * f + i);
                }
                now
            })
            .collect();
        assert!(
            over(&lynx, None, 1, &[]).measured
                && over(&lynx, None, 2, &[]).sd > MOTION * over(&lynx, None, 1, &[]).sd
        );
        let found = white_noise(&lynx).unwrap();
        assert!(!found.measured && !found.correlated, "{found:?}");
    }

    /// A sine sampled at times jittered by up to a fifth of the step (a logger's clock): read
    /// at those times, its motion leaves nothing and noise of 1 % of its amplitude reads 1 %
    /// within 10 %; read as if even, the motion alone reads as noise. Evened onto a finer grid
    /// (the recipe's preparation), the frame's noise is read at its samples: the cubics' rows
    /// between them are smooth.
    #[test]
    fn jittered_samples_are_read_at_their_own_times() {
        let mut seed = 11u64;
        let n = 4000;
        let t: Vec<f64> =
            (0..n).map(|k| 0.05 * (k as f64 + 0.4 * crate::data::test_noise(&mut seed))).collect();
        let clean: Vec<f64> = t.iter().map(|t| (0.9 * t).sin()).collect();
        let timed = white_noise_of(&clean, Some(&t), &[]).unwrap();
        assert!(timed.sd < 1e-6, "{timed:?}");
        assert!(white_noise(&clean).unwrap().sd > 1e-3, "{:?}", white_noise(&clean));
        let noisy: Vec<f64> =
            clean.iter().map(|x| x + 0.01 * 12f64.sqrt() * crate::data::test_noise(&mut seed)).collect();
        let read = white_noise_of(&noisy, Some(&t), &[]).unwrap();
        assert!(read.measured && (read.sd / 0.01 - 1.0).abs() < 0.1, "{read:?}");
        // (uniform noise reads 5 % high by the median, as the same noise on the sine at even
        // steps does)
        let at_even: Vec<f64> = (0..n).map(|k| noisy[k] - clean[k] + (0.045 * k as f64).sin()).collect();
        assert!((read.sd / white_noise(&at_even).unwrap().sd - 1.0).abs() < 0.01, "{read:?}");
        // at even steps the timed differences are the even ones
        let even: Vec<f64> = (0..n).map(|k| 0.05 * k as f64).collect();
        let (third, fourth) = timed_differences(&noisy, &even, 1);
        assert!((third[7] - (noisy[10] - 3.0 * noisy[9] + 3.0 * noisy[8] - noisy[7])).abs() < 1e-12);
        let d4 = noisy[7] - 4.0 * noisy[8] + 6.0 * noisy[9] - 4.0 * noisy[10] + noisy[11];
        assert!((fourth[7] - d4).abs() < 1e-12, "{} {d4}", fourth[7]);
        let mut frame = Frame::new("logger.csv", "t", t).unwrap();
        frame.push("x", noisy).unwrap();
        let (fine, _) = super::super::resample::evened(&frame).unwrap().unwrap();
        assert!(fine.len() > 2 * n);
        // (a sample's row holds the cubic through its four nearest at the grid's time, a
        // quarter of a row off at most, which smooths its noise a little: 0.94 % read; its
        // rows read as one record, 0.03 % at most)
        let sd = NoiseTally::of(&fine, "x", 0..fine.len()).unwrap().sd().unwrap();
        assert!((sd / 0.01 - 1.0).abs() < 0.1, "{sd}");
        assert!(white_noise(fine.column("x").unwrap()).unwrap().sd < 0.001);
    }

    /// ẋ = −x + 2u under u white and held from each sample to the next (exact steps): the
    /// state kinks at every step, which read as noise of 12 % of its spread; less what u's
    /// values explain of its differences, nothing, and 1 % where it carries 1 %. The input,
    /// which the state follows, is its generator's exact values; noise on a value held
    /// steady (no record follows it) is measured as before.
    #[test]
    fn a_state_driven_by_steps_at_every_sample_is_no_noise() {
        let mut seed = 5u64;
        let n = 3000;
        let u: Vec<f64> = (0..n).map(|_| crate::data::test_noise(&mut seed)).collect();
        let a = (-0.01f64).exp();
        let mut x = vec![0.0; n];
        for k in 0..n - 1 {
            x[k + 1] = a * x[k] + 2.0 * (1.0 - a) * u[k];
        }
        let sd = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            (v.iter().map(|y| (y - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
        };
        assert!(white_noise(&x).unwrap().sd > 0.05 * sd(&x));
        assert!(white_noise_beside(&x, &[&u]).unwrap().sd < 1e-4 * sd(&x));
        let e: Vec<f64> =
            (0..n).map(|_| 0.01 * sd(&x) * 12f64.sqrt() * crate::data::test_noise(&mut seed)).collect();
        let noisy: Vec<f64> = x.iter().zip(&e).map(|(x, e)| x + e).collect();
        let read = white_noise_beside(&noisy, &[&u]).unwrap().sd / sd(&x);
        assert!((read - 0.01).abs() < 0.001, "{read}");
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
        let mut frame = Frame::new("run.csv", "t", t).unwrap();
        frame.push("x", noisy).unwrap();
        frame.push("u", u.clone()).unwrap();
        frame.push("w", (0..n).map(|_| 2.0 + 0.2 * crate::data::test_noise(&mut seed)).collect()).unwrap();
        frame.hold("u").unwrap();
        frame.hold("w").unwrap();
        let share = |name: &str| NoiseTally::of(&frame, name, 0..n).unwrap().share().unwrap().0;
        assert!((share("x") - 0.01).abs() < 0.001, "{}", share("x"));
        assert_eq!(share("u"), 0.0);
        // `w`, stepped alike, drives nothing: noise about 2, measured (a uniform's own reading)
        assert!(share("w") > 0.9, "{}", share("w"));
    }

    /// A swing read every tenth row with noise of 1 % of its spread and written again until
    /// the next reading: read at its readings and interpolated by cubics, the rows are smooth
    /// (its noise read 5·10⁻¹⁴ %, so the closeness check allowed a thousandth of the span and
    /// flagged the exact equations); its noise is read at the readings, in a piece cut from
    /// the run too.
    #[test]
    fn a_slower_sensor_s_noise_is_read_at_its_readings() {
        let n = 3000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
        let swing: Vec<f64> = t.iter().map(|t| (2.0 * t).sin() + 0.5 * (0.7 * t).cos()).collect();
        let sd = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            (v.iter().map(|y| (y - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
        };
        let mut seed = 3u64;
        let e = 0.01 * sd(&swing) * 12f64.sqrt();
        let read: Vec<f64> = swing.iter().map(|x| x + e * crate::data::test_noise(&mut seed)).collect();
        let repeated: Vec<f64> = (0..n).map(|k| read[k / 10 * 10]).collect();
        let mut frame = Frame::new("run.csv", "t", t).unwrap();
        frame.push("x", repeated).unwrap();
        crate::data::read_at_readings(&mut frame, &["x"], crate::data::Intersample::Auto).unwrap();
        assert!(white_noise(frame.column("x").unwrap()).unwrap().sd < 1e-3 * 0.01 * sd(&swing));
        let share = NoiseTally::of(&frame, "x", 0..n).unwrap().share().unwrap().0;
        assert!((share - 0.01).abs() < 0.0015, "{share}");
        let piece = frame.slice(1003..2507);
        assert_eq!(piece.readings_of("x").unwrap().phase, 7);
        let share = NoiseTally::of(&piece, "x", 0..piece.len()).unwrap().share().unwrap().0;
        assert!((share - 0.01).abs() < 0.002, "{share}");
    }

    /// A noisy record tallied in pieces (each read across its neighbours' rows, as a run read
    /// in pieces is) and merged gives the whole record's spread to round-off and its noise
    /// within 5 % (a piece of 1 000 rows reads it within a few per cent); a piece too short
    /// to measure adds its spread alone.
    #[test]
    fn a_tally_in_pieces_is_the_tally_of_the_whole() {
        let mut state = 7u64;
        let mut uniform = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let x: Vec<f64> =
            (0..10_000).map(|k| 3.0 * (k as f64 * 0.01).sin() + 5.0 + 0.1 * uniform()).collect();
        let whole = NoiseTally::of_values(&x, None, 0..x.len(), true, &[]);
        let mut pieces = NoiseTally::default();
        for start in (0..x.len()).step_by(1000) {
            let (from, to) = (start.saturating_sub(6), (start + 1006).min(x.len()));
            pieces.merge(&NoiseTally::of_values(
                &x[from..to],
                None,
                start - from..start - from + 1000.min(x.len() - start),
                true,
                &[],
            ));
        }
        assert_eq!(pieces.rows, whole.rows);
        assert!((pieces.mean / whole.mean - 1.0).abs() < 1e-12 && (pieces.m2 / whole.m2 - 1.0).abs() < 1e-12);
        let (a, b) = (whole.share().unwrap(), pieces.share().unwrap());
        assert!(a.1 && b.1 && (a.0 / b.0 - 1.0).abs() < 0.05, "{a:?} {b:?}");
        let mut short = whole.clone();
        short.merge(&NoiseTally::of_values(&[100.0; 5], None, 0..5, true, &[]));
        assert_eq!(
            (short.noise, short.noise_rows, short.rows),
            (whole.noise, whole.noise_rows, whole.rows + 5)
        );
        assert!(short.m2 > whole.m2 && short.is_consistent());
    }
}
