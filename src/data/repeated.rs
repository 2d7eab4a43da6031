//! A slower sensor's readings repeated between its updates: a log written ten times as often
//! as a position fix arrives, or sensors of several rates merged and filled forward. Such a
//! column of a moving quantity is a staircase: its rate is zero between readings and a spike
//! at each, and every fit through it is biased (Lorenz with `x` read every 10th row of 1 ms:
//! −0.958 for −1 and two spurious terms). Read at its readings and interpolated between them
//! instead, it is the quantity again.

use super::hold::{gcd, isolated_changes, CLOCK_JUMPS};
use super::{DataError, Frame, Intersample};

/// What shows a column repeated between a slower sensor's readings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Repeats {
    /// The rows from one reading to the next (2 or more).
    pub period: usize,
    /// The first row that is a reading (below `period`).
    pub phase: usize,
    /// The share of readings that differ from the one before.
    pub moving: f64,
}

impl Repeats {
    /// The rows of a column of `len` rows that are readings.
    pub fn readings(&self, len: usize) -> impl Iterator<Item = usize> {
        (self.phase..len).step_by(self.period)
    }
}

/// The share of readings at least that must differ from the last: a moving quantity changes
/// at nearly every reading; a command held by a controller on its clock for several periods
/// at a time changes at a few.
const MOVING: f64 = 0.5;

/// Whether `x` is a slower sensor's readings repeated between its updates: it changes at
/// isolated rows only (no two changing intervals side by side, but for 5 %), those rows keep
/// a clock of two rows or more (nine changes at least, as for a held command), and at half
/// of the clock's ticks or more between its first change and its last it changes. `None`
/// otherwise (a record that moves from row to row, a constant, a command stepped now and
/// then).
pub fn repeated(x: &[f64]) -> Option<Repeats> {
    // the rows where a new reading shows
    let at: Vec<usize> = isolated_changes(x)?.into_iter().map(|i| i + 1).collect();
    if at.len() < CLOCK_JUMPS {
        return None;
    }
    let period = at.windows(2).fold(0, |g, w| gcd(g, w[1] - w[0]));
    if period < 2 {
        return None;
    }
    let ticks = (at[at.len() - 1] - at[0]) / period + 1;
    let moving = at.len() as f64 / ticks as f64;
    (moving >= MOVING).then_some(Repeats { period, phase: at[0] % period, moving })
}

/// Whether a state's record can show what a command does to it: it moves from row to row by
/// itself (neither repeats a slower sensor's readings nor is held between samples).
fn moves_by_itself(m: &[f64]) -> bool {
    repeated(m).is_none() && super::held(m).is_none()
}

/// A change held from its row steps the rate of a state it drives there and only there (a
/// kink in the state); a sensor's reading of a smooth quantity steps nothing, the state's rate
/// turns as smoothly at the change as between. Read in a window of half a period either side
/// (the kink beside a quadratic in the row, or a line in windows of three rows), regressed on
/// the change, at the change and half a period after (a window that holds no change's kink):
/// the kink at the change is held where it is this many times the one between …
const KINK_OVER_BETWEEN: f64 = 4.0;

/// … and this many of its own standard errors.
const KINK_SIGNIFICANT: f64 = 5.0;

/// The least-squares weights over the rows −w … w about a row that give the kink there (the
/// rate's step from it on) beside a polynomial in the row: a quadratic where the window has
/// five rows or more, a line in three (the second difference).
fn kink_weights(w: usize) -> Option<Vec<f64>> {
    let rows = 2 * w + 1;
    let columns = if w >= 2 { 4 } else { 3 };
    let a = nalgebra::DMatrix::from_fn(rows, columns, |i, j| {
        let s = i as f64 - w as f64;
        if j == columns - 1 {
            s.max(0.0)
        } else {
            s.powi(j as i32)
        }
    });
    let inverse = (a.transpose() * &a).try_inverse()?;
    Some((inverse * a.transpose()).row(columns - 1).iter().copied().collect())
}

/// Whether the motion kinks where `x`, repeated on a clock (`r`), changes: the rate of one of
/// the states `motion` (each a recorded column that moves from row to row) steps with `x`'s
/// change at the change's row (by five of its standard errors), and not half a period later
/// (four times less there). Then `x` is a command held from each reading to the next (a
/// controller's, slower than the log, that moves by a little at every tick), not a slower
/// sensor's readings of a smooth quantity. The index in `motion` of the first state that shows
/// it; `None` where none does (a state that does not move, or repeats itself, shows nothing;
/// a kink drowned in the state's noise neither).
pub fn kinks_at_changes(x: &[f64], r: Repeats, motion: &[&[f64]]) -> Option<usize> {
    let (n, w) = (x.len(), r.period / 2);
    // the rows where a change shows, with room for both windows
    let changes: Vec<(usize, f64)> = r
        .readings(n)
        .filter(|&c| c >= w && c + 2 * w < n)
        .map(|c| (c, x[c] - x[c - 1]))
        .filter(|(_, d)| *d != 0.0)
        .collect();
    let squares: f64 = changes.iter().map(|(_, d)| d * d).sum();
    let weights = kink_weights(w)?;
    if changes.len() < CLOCK_JUMPS || squares == 0.0 {
        return None;
    }
    motion.iter().position(|m| {
        if m.len() != n || !moves_by_itself(m) {
            return false;
        }
        let kink = |at: usize| weights.iter().zip(&m[at - w..=at + w]).map(|(w, m)| w * m).sum::<f64>();
        let slope = |offset: usize| changes.iter().map(|&(c, d)| kink(c + offset) * d).sum::<f64>() / squares;
        let (at, between) = (slope(0), slope(w));
        let scatter: f64 = changes.iter().map(|&(c, d)| (kink(c) - at * d).powi(2)).sum::<f64>()
            / (changes.len() - 1) as f64;
        let error = (scatter / squares).sqrt();
        at.abs() > KINK_OVER_BETWEEN * between.abs() && at.abs() > KINK_SIGNIFICANT * error
    })
}

/// Held fits a state's rate better than read at the readings where it leaves at most this
/// share less of the residual sum of squares …
const BETTER_HELD: f64 = 0.005;

/// … by at least this many residual variances (windows of one period each, about
/// independent).
const HELD_SIGNIFICANT: f64 = 25.0;

/// … and by at least this share of the state's squared changes over the windows: where
/// holding the column matters less, a line between its samples costs nothing (a force held
/// on a state it drives: 10⁻⁴ to 10⁻²).
const MATTERS: f64 = 1e-6;

/// The rows the fit reads at most: the start of a long record shows it.
const FIT_ROWS: usize = 20_000;

/// Columns beyond which the fit takes them alone, not their products as well.
const PRODUCTS_UP_TO: usize = 10;

/// Whether a state's rate is fitted better with `x` held from each change to the next than
/// read at its readings (`r`): for each state of `motion`, its change over windows of one
/// period regressed on the integrals over them of a constant, `x` and the columns `others`
/// (the state among them) and, up to ten columns, their products — with `x` as its rows have
/// it held over each interval, and with `x` read at its readings. Held leaves at least 0.5 %
/// less of the residual sum of squares, 25 residual variances less, and a millionth of the
/// state's squared changes less, where it is held: where a noisy record hides the kink of
/// [`kinks_at_changes`], the fit still sees half a period's shift over every period. The
/// index in `motion` of the state held fits best against read, and the share held leaves of
/// what read leaves; `None` where neither is clearly better or the record is too short for
/// the columns.
pub fn fits_better_held(
    t: &[f64],
    x: &[f64],
    r: Repeats,
    motion: &[&[f64]],
    others: &[&[f64]],
) -> Option<(usize, f64)> {
    let n = t.len().min(FIT_ROWS);
    // the cubics of the rows fitted, through the same four readings as over the whole record
    let reach = (n + 2 * r.period + 1).min(t.len());
    let read = between_readings(&t[..reach], &x[..reach], r);
    let windows = Windows { samples: r.period, leaps: &[], unforeseen: false };
    held_or_else(t, x, &read, windows, motion, others)
}

/// Windows of this many samples for [`fits_better_held_than_a_line`]: the integral form's
/// short windows.
const LINE_WINDOW: usize = 8;

/// A column whose own change over the windows the columns leave at least this share of
/// unexplained is one they do not foresee (a command from outside the system).
const UNFORESEEN: f64 = 0.25;

/// A column the columns foresee that is a feedback controller's command ([`STATIC`]) is held
/// only where held gains at least this share of the state's squared changes over the windows:
/// a hold a line misreads shifts the command half an interval, an error of the order of the
/// interval in the state's change (a proportional controller at 10 Hz under 1 % noise:
/// 9.6·10⁻⁴, its line 5 % off both coefficients).
const FORESEEN_MATTERS: f64 = 3e-5;

/// A foreseen column whose change over each window the other columns' terms' changes between
/// the window's ends leave less than this share of unexplained is computed from their values
/// at each sample — a feedback controller's command (a proportional one: 5·10⁻¹⁸) — not
/// integrated from them as a state read as an input is (the ODE benchmark's states read as
/// inputs of another's rate: 1.5·10⁻⁴ at least, Rabinovich-Fabrikant's; Lorenz's 0.26, whose
/// half interval held the terms absorb, 66 % better held by quadratures' errors alone).
const STATIC: f64 = 1e-5;

/// A foreseen column whose step at each sample the other columns' steps there and a sample
/// before and their values (and a constant between the column's leaps) leave less than this
/// share of unexplained, though those columns carry noise ([`NOISY`]), is a digital
/// controller's command with integral action, computed from the noisy samples themselves: a PID
/// controller's u_k − u_{k−1} = K_p Δe_k + K_i h e_k + K_d (Δe_k − Δe_{k−1})/h, e = r − x̃ and
/// r stepped at the leaps. Exact to the digits written (PI and PID controllers at 10 Hz under
/// 1 % noise: 10⁻²¹), where a state read as an input is integrated from the motion, not from
/// its noisy record (a position under its velocity measured with 1 % noise: 10⁻³). Noise-free,
/// a linear system's states meet such a recurrence exactly too: nothing is told.
const EXACT: f64 = 1e-10;

/// The white noise, as a share of a column's spread, from which the columns a command may be
/// computed from count as noisy ([`EXACT`]): a record written to ten digits carries 10⁻¹⁰.
const NOISY: f64 = 1e-5;

/// Whether `x`'s step at each sample of the windows `kept` (of `w` samples) is, to [`EXACT`],
/// a linear function of the other columns' steps at that sample and the one before, their
/// values at it, and a constant over each stretch between the `leaps` (a reference stepped;
/// the two samples from each leap on left out, where a derivative action kicks), some of those
/// columns noisy ([`NOISY`]): a digital controller that sums its error (PI, PID), not static
/// ([`STATIC`]) but computed from the samples alone.
fn integrates_from_samples(x: &[f64], others: &[&[f64]], kept: &[usize], w: usize, leaps: &[usize]) -> bool {
    let rows: Vec<usize> = kept
        .iter()
        .flat_map(|&row| row * w + 1..=(row + 1) * w)
        .filter(|&k| k >= 2 && !leaps.iter().any(|&l| l <= k && k < l + 2))
        .collect();
    // each row's stretch between the leaps
    let stretch: Vec<usize> = rows.iter().map(|&k| leaps.iter().filter(|&&l| l <= k).count()).collect();
    let m = others.len();
    let columns = 3 * m + leaps.len() + 1;
    let noisy = |c: &[f64]| {
        super::NoiseTally::of_values(c, None, 0..c.len(), false, &[])
            .share()
            .is_some_and(|(share, measured)| measured && share >= NOISY)
    };
    if others.is_empty() || rows.len() < 3 * columns || !others.iter().any(|c| noisy(c)) {
        return false;
    }
    let a = nalgebra::DMatrix::from_fn(rows.len(), columns, |i, c| {
        let k = rows[i];
        match c {
            c if c < m => others[c][k] - others[c][k - 1],
            c if c < 2 * m => others[c - m][k - 1] - others[c - m][k - 2],
            c if c < 3 * m => others[c - 2 * m][k],
            c => f64::from(u8::from(stretch[i] == c - 3 * m)),
        }
    });
    let y = nalgebra::DVector::from_fn(rows.len(), |i, _| x[rows[i]] - x[rows[i] - 1]);
    let (a, _) = scaled(a, None);
    let Some(Ok(fit)) = crate::linalg::svd(a.clone()).map(|svd| svd.solve(&y, 1e-12)) else { return false };
    let scale = y.norm_squared();
    scale > 0.0 && (&y - &a * fit).norm_squared() < EXACT * scale
}

/// Whether a state's rate is fitted better with `x` held from each sample to the next than as
/// a line between the samples, as in [`fits_better_held`] over windows of eight samples: a
/// generator's command switched at random samples (a random telegraph, a PRBS of random
/// lengths) steps the rate at the samples, a relay thrown by the motion between them, where
/// a line errs less on average. With `smooth`, the rows of the leaps of a column that moves
/// from sample to sample (a sine put out through a DAC): the windows that hold one (the first
/// row after a leap of `x`, a step of the command, which either reading puts at a sample) are
/// left out, and a column whose own change the columns explain is not compared (a state read as
/// an input) unless it is computed from them at each sample ([`STATIC`]: a feedback
/// controller's command), then held where that gains what a hold's shift would
/// ([`FORESEEN_MATTERS`]).
pub fn fits_better_held_than_a_line(
    t: &[f64],
    x: &[f64],
    motion: &[&[f64]],
    others: &[&[f64]],
    smooth: Option<&[usize]>,
) -> Option<(usize, f64)> {
    let windows =
        Windows { samples: LINE_WINDOW, leaps: smooth.unwrap_or(&[]), unforeseen: smooth.is_some() };
    held_or_else(t, x, x, windows, motion, others)
}

/// A window that holds a jump is misfitted held where its residual exceeds this many times the
/// fit's error of prediction there (the root mean square of the windows without one, grown by
/// how far the window's columns lie from theirs: σ√(1 + h), h its leverage): a jump held a whole interval off its instant
/// errs by the jump times the interval, far beyond a smooth window's quadrature and noise,
/// where a jump at a sample fits held as well as any window.
pub(super) const MISFIT: f64 = 5.0;

/// What a fit held says of the jumps of a record held between samples
/// ([`jumps_off_the_samples`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Jumps {
    /// The windows of eight samples that hold a jump.
    pub windows: usize,
    /// Of those, the ones held misfits ([`MISFIT`]).
    pub off: usize,
    /// Of the misfitted, each lone jump that fits held where it acts over the interval before
    /// the sample that shows it (logged a sample after it acted): that interval's first sample,
    /// to take the new value.
    pub late: Vec<usize>,
}

/// How a fit held meets the jumps of `x` (a record held between samples), for the state of
/// `motion` that shows most ([`Jumps`]): a jump at its sample fits held as well as any window;
/// one between two samples misfits by about the jump times the interval, and one logged a
/// sample after it acted (a command's log late by a sample) fits once it acts an interval
/// earlier. The rate of each state that moves by itself, over windows of eight samples,
/// regressed as in [`fits_better_held_than_a_line`] on the windows without a jump, and the
/// windows with one held against that fit ([`MISFIT`] of its error of prediction at each).
/// `None` where the record is too short for the columns or too few windows are without a jump.
pub fn jumps_off_the_samples(t: &[f64], x: &[f64], motion: &[&[f64]], others: &[&[f64]]) -> Option<Jumps> {
    let n = t.len().min(FIT_ROWS);
    let terms = quadratic_terms(others.len() + 1);
    let w = LINE_WINDOW;
    let kept: Vec<usize> = (0..n.saturating_sub(1) / w).collect();
    if kept.len() < 3 * terms.len()
        || others.iter().any(|c| c.len() < n)
        || motion.iter().any(|m| m.len() < n)
    {
        return None;
    }
    let (held, norms) = scaled(window_design(t, x, x, &kept, w, &terms, others, true), None);
    // each window's jumps (the intervals over which x changes), and the one of a lone jump
    let jumps: Vec<Vec<usize>> =
        kept.iter().map(|&row| (row * w..(row + 1) * w).filter(|&j| x[j + 1] != x[j]).collect()).collect();
    let lone: Vec<Option<usize>> =
        jumps.iter().map(|j| if let [j] = j[..] { Some(j) } else { None }).collect();
    let smooth: Vec<usize> = (0..jumps.len()).filter(|&r| jumps[r].is_empty()).collect();
    if smooth.len() < 3 * terms.len() {
        return None;
    }
    // each lone jump acting an interval earlier
    let mut early = x[..n].to_vec();
    for &j in lone.iter().flatten() {
        early[j] = x[j + 1];
    }
    let (early, _) = scaled(window_design(t, &early, &early, &kept, w, &terms, others, true), Some(&norms));
    let a = held.select_rows(smooth.iter());
    let svd = crate::linalg::svd(a.clone())?;
    // a row's leverage on the smooth windows' fit, xᵀ(AᵀA)⁺x over the directions they determine
    let (v_t, sigma) = (svd.v_t.as_ref()?, &svd.singular_values);
    let determined: Vec<usize> = (0..sigma.len()).filter(|&i| sigma[i] > 1e-12).collect();
    let rank = determined.len();
    let leverage = |design: &nalgebra::DMatrix<f64>, r: usize| -> f64 {
        let row = design.row(r);
        determined.iter().map(|&i| ((v_t.row(i) * row.transpose())[0] / sigma[i]).powi(2)).sum()
    };
    let found = motion.iter().filter(|m| moves_by_itself(m)).filter_map(|m| {
        let change = |row: usize| m[kept[row] * w + w] - m[kept[row] * w];
        let y = nalgebra::DVector::from_fn(smooth.len(), |i, _| change(smooth[i]));
        let fit = svd.solve(&y, 1e-12).ok()?;
        let dof = smooth.len().saturating_sub(rank).max(1) as f64;
        let spread = ((&y - &a * &fit).norm_squared() / dof).sqrt();
        // (rounding: a millionth of the state's changes)
        let floor = 1e-6 * (y.norm_squared() / smooth.len() as f64).sqrt();
        // against the fit's own error of prediction at the window, σ√(1 + h): a window whose
        // columns the smooth ones reach only by extrapolating a few of them (an infusion's
        // terms fitted on six windows with it on, met at its peak) is predicted no better than that
        let misfit = |design: &nalgebra::DMatrix<f64>, r: usize| {
            let residual = (change(r) - (design.row(r) * &fit)[0]).abs();
            let within = MISFIT * spread * (1.0 + leverage(design, r)).sqrt();
            residual > within && residual > floor
        };
        let off: Vec<usize> =
            (0..jumps.len()).filter(|&r| !jumps[r].is_empty() && misfit(&held, r)).collect();
        let late: Vec<usize> = off.iter().filter(|&&r| !misfit(&early, r)).filter_map(|&r| lone[r]).collect();
        Some((off.len(), late))
    });
    let (off, late) = found.max_by_key(|(off, _)| *off)?;
    Some(Jumps { windows: jumps.iter().filter(|j| !j.is_empty()).count(), off, late })
}

/// The terms a held-or-not fit regresses on, over `k` columns: a constant, each column, and
/// (up to [`PRODUCTS_UP_TO`] columns) their products.
fn quadratic_terms(k: usize) -> Vec<(Option<usize>, Option<usize>)> {
    let mut terms: Vec<(Option<usize>, Option<usize>)> = vec![(None, None)];
    terms.extend((0..k).map(|i| (Some(i), None)));
    if k <= PRODUCTS_UP_TO {
        terms.extend((0..k).flat_map(|i| (i..k).map(move |j| (Some(i), Some(j)))));
    }
    terms
}

/// The integrals of `terms` over the windows of `w` samples starting at `kept` (times `w`):
/// column 0 is `x` held from each sample to the next, or as
/// `read` (a line between its samples, or its readings interpolated), the others `others`.
#[allow(clippy::too_many_arguments)]
fn window_design(
    t: &[f64],
    x: &[f64],
    read: &[f64],
    kept: &[usize],
    w: usize,
    terms: &[(Option<usize>, Option<usize>)],
    others: &[&[f64]],
    held: bool,
) -> nalgebra::DMatrix<f64> {
    // column i at row `row`, with x held from row `from`
    let value = |i: usize, row: usize, from: usize| match i {
        0 if held => x[from],
        0 => read[row],
        _ => others[i - 1][row],
    };
    let term = |(a, b): (Option<usize>, Option<usize>), row: usize, from: usize| {
        a.map_or(1.0, |i| value(i, row, from)) * b.map_or(1.0, |j| value(j, row, from))
    };
    nalgebra::DMatrix::from_fn(kept.len(), terms.len(), |row, c| {
        let row = kept[row];
        // the trapezoid over each interval of the window, x held over it where asked
        (row * w..(row + 1) * w)
            .map(|j| 0.5 * (t[j + 1] - t[j]) * (term(terms[c], j, j) + term(terms[c], j + 1, j)))
            .sum()
    })
}

/// `a`'s columns divided by `norms` (their own norms where `None`; a zero column kept), and
/// the norms: a fit's conditioning, the same for every design of one comparison.
fn scaled(mut a: nalgebra::DMatrix<f64>, norms: Option<&[f64]>) -> (nalgebra::DMatrix<f64>, Vec<f64>) {
    let norms: Vec<f64> = match norms {
        Some(n) => n.to_vec(),
        None => a.column_iter().map(|c| c.norm()).collect(),
    };
    for (mut c, norm) in a.column_iter_mut().zip(&norms) {
        if *norm > 0.0 {
            c /= *norm;
        }
    }
    (a, norms)
}

/// The windows a held-or-not comparison fits over.
struct Windows<'a> {
    /// Samples in each.
    samples: usize,
    /// Rows whose windows are left out.
    leaps: &'a [usize],
    /// Ask more of a column the columns foresee ([`UNFORESEEN`], [`FORESEEN_MATTERS`]).
    unforeseen: bool,
}

/// The comparison of [`fits_better_held`] with `x` held against `x` as `read` (over the
/// first [`FIT_ROWS`] rows), in the windows `windows_of` says.
fn held_or_else(
    t: &[f64],
    x: &[f64],
    read: &[f64],
    windows_of: Windows,
    motion: &[&[f64]],
    others: &[&[f64]],
) -> Option<(usize, f64)> {
    let n = t.len().min(FIT_ROWS);
    let terms = quadratic_terms(others.len() + 1);
    let w = windows_of.samples.max(1);
    let kept: Vec<usize> = (0..n.saturating_sub(1) / w)
        .filter(|row| !windows_of.leaps.iter().any(|&l| l > row * w && l <= (row + 1) * w))
        .collect();
    let windows = kept.len();
    if windows < 3 * terms.len()
        || read.len() < n
        || others.iter().any(|c| c.len() < n)
        || motion.iter().any(|m| m.len() < n)
    {
        return None;
    }
    let (held, _) = scaled(window_design(t, x, read, &kept, w, &terms, others, true), None);
    let (read, _) = scaled(window_design(t, x, read, &kept, w, &terms, others, false), None);
    let (held_svd, read_svd) = (crate::linalg::svd(held.clone())?, crate::linalg::svd(read.clone())?);
    let left = |a: &nalgebra::DMatrix<f64>,
                svd: &nalgebra::SVD<f64, nalgebra::Dyn, nalgebra::Dyn>,
                y: &nalgebra::DVector<f64>|
     -> Option<f64> {
        let fit = svd.solve(y, 1e-12).ok()?;
        Some((y - a * fit).norm_squared())
    };
    let dof = (windows - terms.len()) as f64;
    // a column whose own change the columns explain (a state read as an input) is shifted by
    // half an interval held into terms the fit absorbs: held and line fit alike but for their
    // quadratures' errors, which tell nothing of a hold (Lorenz's x under ẏ: 66 % better
    // held); a feedback controller's command is foreseen too, but computed from the columns at
    // each sample ([`STATIC`]), and held or not matters at the order of the interval
    let matters = match windows_of.unforeseen {
        true => {
            let y = nalgebra::DVector::from_fn(windows, |row, _| x[(kept[row] + 1) * w] - x[kept[row] * w]);
            let mean = y.mean();
            let total: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
            if left(&read, &read_svd, &y)? >= UNFORESEEN * total {
                MATTERS
            } else {
                // the column's change over each window against the changes of the other
                // columns' terms (not the constant, not the column's own) between its ends
                let at = |(a, b): (Option<usize>, Option<usize>), row: usize| {
                    a.map_or(1.0, |i| others[i - 1][row]) * b.map_or(1.0, |j| others[j - 1][row])
                };
                let theirs: Vec<_> = terms
                    .iter()
                    .copied()
                    .filter(|&(a, b)| a.is_some_and(|i| i > 0) && b != Some(0))
                    .collect();
                if theirs.is_empty() {
                    return None;
                }
                let (ends, _) = scaled(
                    nalgebra::DMatrix::from_fn(windows, theirs.len(), |row, c| {
                        at(theirs[c], (kept[row] + 1) * w) - at(theirs[c], kept[row] * w)
                    }),
                    None,
                );
                let svd = crate::linalg::svd(ends.clone())?;
                let proportional = left(&ends, &svd, &y)? < STATIC * y.norm_squared();
                match proportional || integrates_from_samples(x, others, &kept, w, windows_of.leaps) {
                    true => FORESEEN_MATTERS,
                    false => return None,
                }
            }
        }
        false => MATTERS,
    };
    // the state that tells most (the one the column drives, where another follows it: `v`
    // under a force, not `x`)
    let telling = motion.iter().enumerate().filter_map(|(i, m)| {
        if !moves_by_itself(m) {
            return None;
        }
        let y = nalgebra::DVector::from_fn(windows, |row, _| m[(kept[row] + 1) * w] - m[kept[row] * w]);
        let (as_held, as_read) = (left(&held, &held_svd, &y)?, left(&read, &read_svd, &y)?);
        // (a state the column does not drive, fitted to its quadrature's error either way,
        // tells nothing: a heading under a rudder read to whole degrees, 6·10⁻¹⁰ better held)
        // (a state that does not move at all, a column of initial values, leaves 0 either way)
        let better = as_read > as_held
            && as_read - as_held >= matters * y.norm_squared()
            && as_held <= (1.0 - BETTER_HELD) * as_read
            && as_read - as_held >= HELD_SIGNIFICANT * as_held / dof;
        better.then_some((i, as_held / as_read))
    });
    telling.min_by(|a, b| a.1.total_cmp(&b.1))
}

/// `x` at its readings (the rows `phase`, `phase + period`, …) and, between them and beyond the
/// first and last, the cubic through the four nearest readings (at their own times `t`): what
/// a sensor read at those instants says of the rows in between, to O(h⁴) of a smooth quantity.
pub fn between_readings(t: &[f64], x: &[f64], r: Repeats) -> Vec<f64> {
    let nodes: Vec<usize> = r.readings(x.len()).collect();
    if nodes.len() < 4 {
        return x.to_vec();
    }
    let (at, read): (Vec<f64>, Vec<f64>) = nodes.iter().map(|&i| (t[i], x[i])).unzip();
    super::resample::cubic_at(&at, &read, t)
}

/// The columns of `frame` named in `columns` that are a slower sensor's readings repeated
/// between its updates ([`repeated`]) read at their readings and interpolated between them
/// ([`between_readings`]), and what to say of each; none where `intersample` is `linear` (the
/// record as its rows have it). A column held between samples (a command:
/// [`Frame::is_held`]) and the columns a frame does not have are passed over.
pub fn read_at_readings(
    frame: &mut Frame,
    columns: &[&str],
    intersample: Intersample,
) -> Result<Vec<String>, DataError> {
    let mut notes = Vec::new();
    if intersample == Intersample::Linear {
        return Ok(notes);
    }
    for name in columns {
        // a command held, or switched between samples, is no slower sensor's readings
        if frame.is_held(name) || frame.switched().iter().any(|s| s == name) {
            continue;
        }
        let Some(column) = frame.column(name) else { continue };
        let Some(r) = repeated(column) else { continue };
        let mended = between_readings(frame.time(), column, r);
        let readings = r.readings(column.len()).count();
        frame.overwrite(name, mended)?;
        frame.read_at(name, r);
        notes.push(format!(
            "{}: `{name}` changes only every {} rows and repeats itself in between ({:.0} % of its {readings} readings differ from the one before): a slower sensor's readings written again until the next (a log kept faster than the sensor reads, or several sensors merged and filled forward), whose rate would read zero between readings and a spike at each; read at its readings and interpolated between them by cubics. Where it is a controller's command held from each reading to the next (whose kink in the motion the noise hides here), say so (identify --intersample held; a model file's `intersample = \"held\"`; Python `intersample=\"held\"`); where it truly changes only at those rows, `linear`",
            frame.origin(),
            r.period,
            100.0 * r.moving,
        ));
    }
    Ok(notes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary command switched at random samples and held: a state it drives (ẏ = u,
    /// integrated exactly) is fitted better held than as a line; a state it does not drive, a
    /// ramp fitted exactly either way, tells nothing (it read 0 / 0, "NaN % less", held).
    #[test]
    fn a_state_fitted_exactly_either_way_tells_nothing() {
        let mut seed = 9u64;
        let mut level = 1.0;
        let u: Vec<f64> = (0..2000)
            .map(|_| {
                if crate::data::test_noise(&mut seed) > 0.3 {
                    level = -level;
                }
                level
            })
            .collect();
        let t: Vec<f64> = (0..2000).map(|k| k as f64 * 0.01).collect();
        let y: Vec<f64> = u
            .iter()
            .scan(0.0, |y, v| {
                let now = *y;
                *y += 0.01 * v;
                Some(now)
            })
            .collect();
        let found = fits_better_held_than_a_line(&t, &u, &[&y], &[&y], None);
        assert!(found.is_some_and(|(i, share)| i == 0 && share < 0.01), "{found:?}");
        assert!(jumps_off_the_samples(&t, &u, &[&y], &[&y]).is_some_and(|j| j.off == 0 && j.windows > 100));
        assert_eq!(fits_better_held_than_a_line(&t, &u, &[&t], &[&t], None), None);
    }

    /// A command held between samples but logged a sample late at some of its jumps (a DC
    /// motor's voltage stepped at 0.6 s and logged at 0.6001 s): held puts each such jump a
    /// whole interval off, and its window misfits, by far more than the windows without a
    /// jump; the jumps at their samples fit.
    #[test]
    fn jumps_between_the_samples_misfit_held() {
        let (n, dt) = (2000, 0.01);
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        // ±1 switched every 100 samples; the jumps at samples 300 and 700 actually an
        // interval early, so the state (ẏ = u − y, exact per interval) turns a sample before
        // the record shows it
        let level = |k: usize| if (k / 100).is_multiple_of(2) { 1.0 } else { -1.0 };
        let u: Vec<f64> = (0..n).map(level).collect();
        let acting = |k: usize| if k == 299 || k == 699 { level(k + 1) } else { level(k) };
        let decay = (-dt).exp();
        let y: Vec<f64> = std::iter::successors(Some((0, 0.0)), |&(k, y)| {
            Some((k + 1, y * decay + (1.0 - decay) * acting(k)))
        })
        .map(|(_, y)| y)
        .take(n)
        .collect();
        let jumps = jumps_off_the_samples(&t, &u, &[&y], &[&y]).unwrap();
        assert_eq!(jumps, Jumps { windows: 19, off: 2, late: vec![299, 699] });
        // switched half an interval early instead (a relay between the samples): neither held
        // at the sample nor an interval early fits
        let halfway: Vec<f64> = std::iter::successors(Some((0, 0.0)), |&(k, y): &(usize, f64)| {
            let half = (-dt / 2.0).exp();
            let y = match k == 299 || k == 699 {
                true => (y * half + (1.0 - half) * level(k)) * half + (1.0 - half) * level(k + 1),
                false => y * decay + (1.0 - decay) * level(k),
            };
            Some((k + 1, y))
        })
        .map(|(_, y)| y)
        .take(n)
        .collect();
        let jumps = jumps_off_the_samples(&t, &u, &[&halfway], &[&halfway]).unwrap();
        assert_eq!(jumps, Jumps { windows: 19, off: 2, late: vec![] });
    }

    /// Infusions held on the samples (on for 10 of every 160, every 0.05 h) into two
    /// compartments (ċ₁ = −0.8c₁ + 0.2c₂ + 0.1u, ċ₂ = 0.5c₁ − 0.2c₂), recorded with noise of
    /// 1 % of each state's spread: the windows without a jump hold the infusion on in only six,
    /// at its start, so the fit meets each switch-off at the peak only by extrapolating its
    /// terms in u; judged against that fit's own error of prediction there, no jump misfits (six
    /// were moved a sample early, each infusion cut by a tenth, and c₁'s rate took 12 terms).
    #[test]
    fn jumps_met_only_by_extrapolating_the_fit_are_not_misfits() {
        let (n, h, fine) = (960, 0.05, 20);
        let u = |k: usize| if k % 160 < 10 { 100.0 } else { 0.0 };
        let rate = |c: [f64; 2], u: f64| [-0.8 * c[0] + 0.2 * c[1] + 0.1 * u, 0.5 * c[0] - 0.2 * c[1]];
        let (mut c, mut states) = ([0.0, 0.0], [Vec::new(), Vec::new()]);
        for k in 0..n {
            states[0].push(c[0]);
            states[1].push(c[1]);
            let dt = h / fine as f64;
            for _ in 0..fine {
                let step = |c: [f64; 2], k: [f64; 2], a: f64| [c[0] + a * k[0], c[1] + a * k[1]];
                let k1 = rate(c, u(k));
                let k2 = rate(step(c, k1, 0.5 * dt), u(k));
                let k3 = rate(step(c, k2, 0.5 * dt), u(k));
                let k4 = rate(step(c, k3, dt), u(k));
                c = [0, 1].map(|i| c[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
            }
        }
        let t: Vec<f64> = (0..n).map(|k| h * k as f64).collect();
        let command: Vec<f64> = (0..n).map(u).collect();
        let mut seed = 3u64;
        let noisy: Vec<Vec<f64>> = states
            .iter()
            .map(|x| {
                let mean = x.iter().sum::<f64>() / n as f64;
                let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
                // (uniform on ±½ has a standard deviation of 1/√12)
                x.iter().map(|v| v + 0.01 * sd * 12f64.sqrt() * crate::data::test_noise(&mut seed)).collect()
            })
            .collect();
        let columns: Vec<&[f64]> = noisy.iter().map(|x| x.as_slice()).collect();
        let jumps = jumps_off_the_samples(&t, &command, &columns, &columns).unwrap();
        assert_eq!(jumps, Jumps { windows: 11, off: 0, late: vec![] });
        let exact: Vec<&[f64]> = states.iter().map(|x| x.as_slice()).collect();
        assert_eq!(jumps_off_the_samples(&t, &command, &exact, &exact).unwrap().off, 0);
    }

    /// A smooth command held from each sample to the next (two sines every 0.05 s) that a
    /// state integrates (ẏ = u, exact under the hold): fitted better held, though it moves at
    /// every sample; the same state under the command acting continuously (y in closed form),
    /// or a state that does not move (0 left over either way: it was held, "NaN % less"): not;
    /// Lorenz's x read as the input of ẏ = 28x − y − xz (sampled every 0.01 s) fits
    /// better held too, but x's own change is foreseen by the columns (ẋ = 10(y − x)), so it
    /// is not compared: its half interval's shift is absorbed by the terms, not a hold.
    #[test]
    fn a_smooth_command_is_compared_where_the_columns_do_not_foresee_it() {
        let h = 0.05;
        let t: Vec<f64> = (0..2000).map(|k| h * k as f64).collect();
        let u: Vec<f64> = t.iter().map(|t| (1.3 * t).sin() + 0.5 * (3.1 * t + 1.0).sin()).collect();
        let held: Vec<f64> = std::iter::successors(Some((0, 0.0)), |&(k, y)| Some((k + 1, y + h * u[k])))
            .map(|(_, y)| y)
            .take(t.len())
            .collect();
        let found = fits_better_held_than_a_line(&t, &u, &[&held], &[&held], Some(&[]));
        assert!(found.is_some_and(|(i, share)| i == 0 && share < 0.01), "{found:?}");
        let line: Vec<f64> =
            t.iter().map(|t| -(1.3 * t).cos() / 1.3 - 0.5 * (3.1 * t + 1.0).cos() / 3.1).collect();
        assert_eq!(fits_better_held_than_a_line(&t, &u, &[&line], &[&line], Some(&[])), None);
        // a state that does not move (a column of initial values) leaves 0 either way: not held
        let still = vec![1.0; t.len()];
        assert_eq!(fits_better_held_than_a_line(&t, &u, &[&still], &[&still], Some(&[])), None);
        let rate =
            |s: [f64; 3]| [10.0 * (s[1] - s[0]), s[0] * (28.0 - s[2]) - s[1], s[0] * s[1] - 8.0 / 3.0 * s[2]];
        let step = |s: [f64; 3], k: [f64; 3], by: f64| [s[0] + by * k[0], s[1] + by * k[1], s[2] + by * k[2]];
        let mut s = [-8.0, 7.0, 27.0];
        let mut lorenz = vec![s];
        for _ in 1..2000 {
            for _ in 0..10 {
                let dt = 0.001;
                let k1 = rate(s);
                let k2 = rate(step(s, k1, dt / 2.0));
                let k3 = rate(step(s, k2, dt / 2.0));
                let k4 = rate(step(s, k3, dt));
                s = std::array::from_fn(|i| s[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
            }
            lorenz.push(s);
        }
        let [x, y, z]: [Vec<f64>; 3] = std::array::from_fn(|i| lorenz.iter().map(|s| s[i]).collect());
        let t: Vec<f64> = (0..2000).map(|k| 0.01 * k as f64).collect();
        assert!(fits_better_held_than_a_line(&t, &x, &[&y], &[&y, &z], None).is_some());
        assert_eq!(fits_better_held_than_a_line(&t, &x, &[&y], &[&y, &z], Some(&[])), None);
    }

    /// A proportional controller at 10 Hz (u = 2(r − x̃), x̃ the state measured with noise of
    /// about 1 % of its spread, r stepped every 60 s) holds its command from each sample to the
    /// next on ẋ = −0.2x + 0.5u: the columns foresee the command's change (it is computed from
    /// them), as they do a state read as an input, but it is their static function (its change
    /// over each window theirs between its ends), and held gains about 10⁻³ of the state's
    /// squared changes (a line put both coefficients 5 % off): held. (Lorenz's x under ẏ,
    /// above, is no static function of y and z: not compared.) So are a PI controller's
    /// (u = 2e + 0.5 Σ e h, e = r − x̃) and a PID's (0.05 Δe/h added), which sum their error at the samples:
    /// a step at each sample is the state's steps there and a sample before, its value, and a
    /// constant between the reference's steps (a line put both coefficients 4 % off, every check
    /// ok); a position read as an input beside its velocity measured with noise is not.
    #[test]
    fn a_feedback_command_held_by_its_controller_is_found() {
        let (h, n): (f64, usize) = (0.1, 3000);
        let levels = [1.0, -0.5, 2.0, 0.0, 1.5];
        let decay = (-0.2 * h).exp();
        let t: Vec<f64> = (0..n).map(|k| h * k as f64).collect();
        for (integral, derivative) in [(0.0, 0.0), (0.5, 0.0), (0.5, 0.05)] {
            let (mut x, mut sum, mut seed, mut last) = (0.0, 0.0, 21u64, None);
            let (mut measured, mut command) = (Vec::new(), Vec::new());
            for k in 0..n {
                let seen = x + 0.028 * crate::data::test_noise(&mut seed);
                let error = levels[(k / 600) % 5] - seen;
                sum += error * h;
                let slope = last.map_or(0.0, |e| (error - e) / h);
                last = Some(error);
                let u = 2.0 * error + integral * sum + derivative * slope;
                measured.push(seen);
                command.push(u);
                // exact over the interval with u held
                x = decay * x + (1.0 - decay) / 0.2 * 0.5 * u;
            }
            let leaps: Vec<usize> = crate::data::breaks(&t, &command).into_iter().map(|b| b.row).collect();
            assert_eq!(leaps.len(), 4, "{leaps:?}");
            let found = fits_better_held_than_a_line(&t, &command, &[&measured], &[&measured], Some(&leaps));
            assert!(
                found.is_some_and(|(i, share)| i == 0 && share < 0.95),
                "{integral} {derivative}: {found:?}"
            );
        }
        let step = std::f64::consts::TAU / 100.0;
        let position: Vec<f64> = (0..n).map(|k| (step * k as f64).sin()).collect();
        let velocity: Vec<f64> = (0..n).map(|k| (step * k as f64).cos()).collect();
        let windows: Vec<usize> = (0..(n - 1) / LINE_WINDOW).collect();
        assert!(!integrates_from_samples(&position, &[&velocity], &windows, LINE_WINDOW, &[]));
        let mut seed = 4u64;
        let read: Vec<f64> =
            velocity.iter().map(|v| v + 0.024 * crate::data::test_noise(&mut seed)).collect();
        assert!(!integrates_from_samples(&position, &[&read], &windows, LINE_WINDOW, &[]));
    }

    /// sin t read every 10th row of 0.01 s and repeated between: found (period 10 from row 3),
    /// and rebuilt to within the cubic's error between readings h = 0.1 s apart (at most
    /// h⁴/24 = 4.2e-6 with sin's fourth derivative, in the first and last intervals; 9/16 of
    /// that between), and within 1e-4 beyond the first and last reading; the readings kept.
    #[test]
    fn a_repeated_sine_is_found_and_rebuilt() {
        let t: Vec<f64> = (0..2000).map(|k| 0.01 * k as f64).collect();
        let x: Vec<f64> = (0..2000).map(|k| (t[if k < 3 { 0 } else { k - (k - 3) % 10 }]).sin()).collect();
        let r = repeated(&x).unwrap();
        assert_eq!((r.period, r.phase), (10, 3));
        assert!(r.moving > 0.99, "{r:?}");
        let rebuilt = between_readings(&t, &x, r);
        let error: Vec<f64> = rebuilt.iter().zip(&t).map(|(v, t)| (v - t.sin()).abs()).collect();
        let worst = |e: &[f64]| e.iter().copied().fold(0.0, f64::max);
        assert!(worst(&error[13..1983]) < 4.2e-6, "{}", worst(&error[13..1983]));
        assert!(worst(&error[23..1973]) < 2.35e-6, "{}", worst(&error[23..1973]));
        assert!(worst(&error) < 1e-4, "{}", worst(&error));
        assert_eq!(rebuilt[13], x[13]);
    }

    /// Not repeated: a record that moves from row to row, a constant, a command stepped every
    /// 50 rows to one of two levels, now and then (few of the clock's ticks change it), a
    /// ramp in counts off any clock, a switch at every row.
    #[test]
    fn motion_commands_and_counts_are_not_repeats() {
        let moving: Vec<f64> = (0..500).map(|k| (0.01 * k as f64).sin()).collect();
        assert_eq!(repeated(&moving), None);
        assert_eq!(repeated(&[2.0; 500]), None);
        let mut seed = 4u64;
        let mut level = 1.0;
        let command: Vec<f64> = (0..5000)
            .map(|k| {
                if k % 50 == 0 && crate::data::test_noise(&mut seed) > 0.3 {
                    level = -level;
                }
                level
            })
            .collect();
        assert!(command.windows(2).filter(|w| w[0] != w[1]).count() >= 9);
        assert_eq!(repeated(&command), None);
        let counts: Vec<f64> = (0..1000).map(|k| (k as f64 / 3.3).floor()).collect();
        assert_eq!(repeated(&counts), None);
        let every: Vec<f64> = (0..100).map(|k| if k % 2 == 0 { 1.0 } else { -1.0 }).collect();
        assert_eq!(repeated(&every), None);
    }

    /// A reading that happens to equal the last (a quantity at rest for one period) is still a
    /// reading: the clock stands, and the cubic goes through it.
    #[test]
    fn an_unchanged_reading_keeps_the_clock() {
        let t: Vec<f64> = (0..400).map(|k| 0.01 * k as f64).collect();
        let reading = |k: usize| ((k / 5) as f64 * 0.05).cos();
        let mut x: Vec<f64> = (0..400).map(reading).collect();
        // the reading at row 100 equal to the one at row 95
        for v in &mut x[100..105] {
            *v = reading(95);
        }
        let r = repeated(&x).unwrap();
        assert_eq!((r.period, r.phase), (5, 0));
        assert_eq!(between_readings(&t, &x, r)[100], reading(95));
    }

    /// ẋ = −x + u recorded every 0.01 s, u a smooth signal on a clock of `period` rows: held
    /// by a controller from each tick to the next (`held`), or read by a slower sensor while
    /// the system feels it smooth; x with uniform noise of `noise` (its size).
    fn driven(period: usize, held: bool, noise: f64) -> (Vec<f64>, Vec<f64>) {
        let (h, fine) = (0.01, 50);
        let u = |t: f64| (0.7 * t).sin() + 0.5 * (1.9 * t + 0.3).sin();
        let reading = |k: usize| u(h * (k - k % period) as f64);
        let (mut x, mut state, mut seed) = (Vec::new(), 0.3, 11u64);
        for k in 0..3000 {
            x.push(state + noise * crate::data::test_noise(&mut seed));
            let dt = h / fine as f64;
            for i in 0..fine {
                let s = h * k as f64 + dt * i as f64;
                let at = |s: f64| if held { reading(k) } else { u(s) };
                let f = |x: f64, s: f64| -x + at(s);
                let k1 = f(state, s);
                let k2 = f(state + 0.5 * dt * k1, s + 0.5 * dt);
                let k3 = f(state + 0.5 * dt * k2, s + 0.5 * dt);
                let k4 = f(state + dt * k3, s + dt);
                state += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            }
        }
        ((0..3000).map(reading).collect(), x)
    }

    /// A command held on a clock of 2, 3, 4 or 10 rows that moves a little at every tick kinks
    /// the state it drives there, clean or with noise of 0.1 % of its size; a slower sensor's
    /// readings of what the system feels smooth do not, nor does a state it does not drive.
    #[test]
    fn a_held_command_kinks_what_it_drives_and_a_sensor_does_not() {
        for period in [2, 3, 4, 10] {
            for noise in [0.0, 1e-3] {
                let (u, x) = driven(period, true, noise);
                let r = repeated(&u).unwrap();
                assert_eq!(r.period, period);
                let other: Vec<f64> = (0..3000).map(|k| (0.002 * k as f64).cos()).collect();
                assert_eq!(kinks_at_changes(&u, r, &[&other, &x]), Some(1), "period {period}, noise {noise}");
                let (u, x) = driven(period, false, noise);
                assert_eq!(kinks_at_changes(&u, r, &[&x, &other]), None, "period {period}, noise {noise}");
            }
        }
    }

    /// With noise of 0.3 % (a period of 4 rows) or 2 % (10 rows) of the state's size, which
    /// hides the kink, the fit still tells: the state's rate is fitted better (by about 10 %)
    /// with the command held than read at its readings, and not with a sensor's readings of
    /// what the system feels smooth.
    #[test]
    fn a_noisy_held_command_fits_better_held_and_a_sensor_does_not() {
        let t: Vec<f64> = (0..3000).map(|k| 0.01 * k as f64).collect();
        for (period, noise) in [(4, 0.003), (10, 0.02)] {
            let (u, x) = driven(period, true, noise);
            let r = repeated(&u).unwrap();
            assert_eq!(kinks_at_changes(&u, r, &[&x]), None, "period {period}");
            let (i, share) = fits_better_held(&t, &u, r, &[&x], &[&x]).unwrap();
            assert!(i == 0 && share < 0.99, "period {period}: {share}");
            let (u, x) = driven(period, false, noise);
            assert_eq!(fits_better_held(&t, &u, r, &[&x], &[&x]), None, "period {period}");
        }
    }

    /// In a frame: the command kinked held (said), so not read at its readings after.
    #[test]
    fn a_command_that_kinks_the_motion_is_held_not_reread() {
        let (u, x) = driven(10, true, 0.0);
        let t: Vec<f64> = (0..3000).map(|k| 0.01 * k as f64).collect();
        let mut f = Frame::new("rig.csv", "t", t).unwrap();
        f.push("x", x).unwrap();
        f.push("u", u.clone()).unwrap();
        let notes = crate::data::mark_held(&mut f, &["u"], &["x", "u"], Intersample::Auto).unwrap();
        assert!(f.is_held("u"));
        assert!(
            notes[0].contains("`u` changes only every 10 rows") && notes[0].contains("the rate of `x` steps"),
            "{}",
            notes[0]
        );
        assert!(read_at_readings(&mut f, &["u", "x"], Intersample::Auto).unwrap().is_empty());
        assert_eq!(f.column("u").unwrap(), &u[..]);
        // without the state it drives, nothing shows it: a sensor's, read at its readings
        let mut g = f.clone();
        g.release("u");
        assert!(crate::data::mark_held(&mut g, &["u"], &[], Intersample::Auto).unwrap().is_empty());
        assert!(!g.is_held("u"));
        // asked to hold, a staircase by small steps is held
        crate::data::mark_held(&mut g, &["u"], &[], Intersample::Held).unwrap();
        assert!(g.is_held("u"));
    }

    /// In a frame: the repeated column re-read and said, a held one and a moving one left.
    #[test]
    fn a_frame_reads_its_repeated_columns_at_their_readings() {
        let t: Vec<f64> = (0..300).map(|k| 0.1 * k as f64).collect();
        let mut f = Frame::new("log.csv", "t", t.clone()).unwrap();
        f.push("x", (0..300).map(|k| t[k - k % 4].sin()).collect()).unwrap();
        f.push("y", t.iter().map(|t| t.cos()).collect()).unwrap();
        f.push("F", (0..300).map(|k| t[k - k % 4].sin()).collect()).unwrap();
        f.hold("F").unwrap();
        let mut g = f.clone();
        assert!(read_at_readings(&mut g, &["x"], Intersample::Linear).unwrap().is_empty());
        assert_eq!(g.column("x"), f.column("x"));
        let notes = read_at_readings(&mut f, &["x", "y", "F", "absent"], Intersample::Auto).unwrap();
        assert_eq!(notes.len(), 1);
        assert!(notes[0].starts_with("log.csv: `x` changes only every 4 rows"), "{}", notes[0]);
        assert!((f.column("x").unwrap()[2] - t[2].sin()).abs() < 1e-3);
        assert_eq!(f.column("y").unwrap()[2], t[2].cos());
        assert_eq!(f.column("F").unwrap()[2], t[0].sin());
    }
}
