//! Identification of one equation from one or several runs: evaluate the candidate terms on
//! every run (with the run's own parameters, e.g. its `u0`), take the target as a column or
//! the derivative of a state, accumulate the sufficient statistics run by run (the paper's
//! "Komb. Daten" is simply all runs together) and hand them to a back-end.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::data::{DataError, Differentiator, Frame};
use crate::select::{gather, gather_halved, Accumulator, Moments, Problem, SelectError, Selection, Selector};
use crate::term::{Library, Source, Term, TermError, Vocabulary};

/// What the equation explains.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// A column of the data (e.g. measured accelerations `r_dot`).
    Column(String),
    /// The time derivative of a column, computed by the chosen differentiator.
    Derivative(String),
}

impl Target {
    /// Parses `dX/dt` as the derivative of X, anything else as a column name.
    pub fn parse(text: &str) -> Target {
        match text.strip_prefix('d').and_then(|s| s.strip_suffix("/dt")) {
            Some(state) if !state.is_empty() => Target::Derivative(state.to_string()),
            _ => Target::Column(text.to_string()),
        }
    }
}

impl std::fmt::Display for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Target::Column(c) => write!(f, "{c}"),
            Target::Derivative(s) => write!(f, "d{s}/dt"),
        }
    }
}

pub use crate::model::ParamValue;

mod delay;
mod invariant;
mod model;
pub(crate) mod noise;
mod report;
mod statistics;

pub use delay::Lag;

pub use model::{
    coefficients_of, describe_residuals_of, equation_design, fit_equation, fit_equation_design,
    identify_model, say_late_inputs, select_model, IdentifiedModel, ModelIdentification,
};
pub(crate) use model::{store_fit, RunStatistics};
pub use noise::noise_note;
pub use report::{num, sig, FitReport, StepReport, TermReport};
pub use statistics::{
    identify_from_merged, identify_from_moments, merged_by_equation, EquationMoments, Pieces, RunMoments,
};

/// Why identification failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IdentifyError {
    /// In a term.
    #[error(transparent)]
    Term(#[from] TermError),
    /// In the data.
    #[error(transparent)]
    Data(#[from] DataError),
    /// In the regression.
    #[error(transparent)]
    Select(#[from] SelectError),
    /// A term or the target evaluates to NaN or ±∞ on some row.
    #[error(
        "{file}: row {row}: {} `{term}` evaluates to {value} (check {})",
        if *target { "the target" } else { "term" },
        match (*target, value.is_nan()) {
            (true, _) => "the data there",
            (false, true) => "its denominators, roots and logarithms and the data there",
            (false, false) => "its denominators and the data there: a division by zero, or a \
                               power or exponential past the largest number",
        }
    )]
    NonFinite {
        /// The run.
        file: String,
        /// 1-based row.
        row: usize,
        /// The term, or the target where `target`.
        term: String,
        /// Whether it is the target (a column or its derivative), not a term.
        target: bool,
        /// Its value.
        value: f64,
    },
    /// Something the caller asked for does not fit together.
    #[error("{0}")]
    Setup(String),
    /// Any of the above, in a model's equation.
    #[error("identifying `{equation}`: {error}")]
    InEquation {
        /// The equation's name.
        equation: String,
        /// What went wrong (in the message, so not also a source that would print twice).
        error: Box<IdentifyError>,
    },
}

impl IdentifyError {
    /// The error of a piece of a file said of the whole file: its row numbers moved on by
    /// `rows` (see [`DataError::shifted`]).
    pub fn shifted(self, rows: usize) -> IdentifyError {
        match self {
            IdentifyError::Data(e) => IdentifyError::Data(e.shifted(rows)),
            IdentifyError::NonFinite { file, row, term, value, target } => {
                IdentifyError::NonFinite { file, row: row + rows, term, value, target }
            }
            e => e,
        }
    }

    /// The error said of a model's equation.
    pub fn in_equation(self, equation: &str) -> IdentifyError {
        IdentifyError::InEquation { equation: equation.into(), error: Box::new(self) }
    }
}

/// The settings shared by the equations of one identification.
pub struct Identification<'a> {
    /// The names terms may use.
    pub vocabulary: &'a Vocabulary,
    /// Per-run parameters.
    pub parameters: &'a BTreeMap<String, ParamValue>,
    /// Derivative method for `Target::Derivative`.
    pub differentiator: &'a dyn Differentiator,
    /// Fit an intercept.
    pub intercept: bool,
    /// A column of row weights (weighted least squares), if any.
    pub weights: Option<String>,
}

/// A fitted equation with its candidates.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Fit {
    /// What was explained.
    pub target: String,
    /// The candidate terms, canonical text, in column order.
    pub candidates: Vec<String>,
    /// The back-end's result.
    pub selection: Selection,
    /// Covariance of the chosen coefficients (in the order of `selection.terms`),
    /// s²·(X'X)⁻¹ of the least-squares fit on the chosen terms; `None` when it is undefined
    /// (no terms, no residual degrees of freedom, or a singular cross-product matrix).
    #[serde(default)]
    pub covariance: Option<Vec<Vec<f64>>>,
    /// Integrated autocorrelation time of the residuals, in rows (1 for independent rows),
    /// beyond the rows' overlap the statistics count already (a weak form's windows,
    /// [`crate::select::Moments::overlap`]). The covariance assumes it is 1; residuals of a
    /// sampled time series are correlated, and the effective number of rows is
    /// `rows / correlation_time`, so honest standard errors are √τ times the reported ones.
    #[serde(default)]
    pub correlation_time: Option<f64>,
    /// How the residuals grow with the fit's size: their root mean square where |fitted| is
    /// largest (a quarter of the rows) over that where it is smallest; [`Fit::notes`] says
    /// where the largest rows decide the fit.
    #[serde(default)]
    pub residual_growth: Option<f64>,
    /// Each chosen term's closest rival among the candidates left out (how firmly the rows
    /// chose it); [`Fit::notes`] names those within the noise.
    #[serde(default)]
    pub rivals: Vec<crate::select::Rival>,
}

/// An equation's candidate terms compiled for evaluation, with their names: all of a fit that
/// does not depend on the runs. Build it once to fit the same candidates to many sets of runs
/// (repeated timings, resampling); [`Identification::fit`] builds one per call.
#[derive(Clone, Debug)]
pub struct Design {
    candidates: Vec<Term>,
    library: Library,
    names: Vec<String>,
}

impl Design {
    /// Compiles `candidates` with the vocabulary they were parsed with.
    pub fn new(candidates: &[Term], vocabulary: &Vocabulary) -> Result<Design, IdentifyError> {
        Ok(Design {
            candidates: candidates.to_vec(),
            library: Library::compile(candidates, vocabulary)?,
            names: candidates.iter().map(Term::to_string).collect(),
        })
    }

    /// The candidate terms, in column order.
    pub fn candidates(&self) -> &[Term] {
        &self.candidates
    }

    /// Their canonical text.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The columns of `terms` among the candidates; one that is not among them is refused,
    /// called by its `role` (forced, excluded).
    fn columns_of(&self, terms: &[Term], role: &str) -> Result<Vec<usize>, IdentifyError> {
        terms
            .iter()
            .map(|t| {
                self.candidates.iter().position(|c| c == t).ok_or_else(|| {
                    IdentifyError::Setup(format!("{role} term `{t}` is not among the candidates"))
                })
            })
            .collect()
    }
}

/// One run bound to a compiled library (see `Identification::bind`).
struct BoundRun<'a> {
    origin: &'a str,
    /// What `y` is, for messages.
    target: String,
    y: Vec<f64>,
    sources: Vec<Source<'a>>,
    weights: Option<&'a [f64]>,
}

impl BoundRun<'_> {
    /// Evaluates the terms on `rows` and adds them to `acc`; a value that is not finite is
    /// refused with its row and term.
    fn push(
        &self,
        library: &Library,
        terms: &[Term],
        rows: std::ops::Range<usize>,
        acc: &mut Accumulator,
    ) -> Result<(), IdentifyError> {
        self.push_split(library, terms, rows, acc, None)
    }

    /// [`BoundRun::push`], the rows also added to the accumulators of the run's halves where
    /// they cross its middle (`split`).
    fn push_split(
        &self,
        library: &Library,
        terms: &[Term],
        rows: std::ops::Range<usize>,
        acc: &mut Accumulator,
        mut split: Option<crate::select::Split<'_>>,
    ) -> Result<(), IdentifyError> {
        let mut bad: Option<IdentifyError> = None;
        library.for_each_block(&self.sources, rows, |start, columns| {
            if bad.is_some() {
                return;
            }
            let len = columns.first().map_or(0, |c| c.len());
            let rows = start..start + len;
            let y = &self.y[rows.clone()];
            acc.push_columns(columns, y, self.weights.map(|w| &w[rows.clone()]));
            if let Some(split) = split.as_mut() {
                // the block's rows before the middle to the first half, the others to the second
                let cut = split.middle.clamp(start, start + len) - start;
                for (half, part) in [(&mut *split.first, 0..cut), (&mut *split.second, cut..len)] {
                    if !part.is_empty() {
                        let cols: Vec<&[f64]> = columns.iter().map(|c| &c[part.clone()]).collect();
                        let at = start + part.start..start + part.end;
                        half.push_columns(&cols, &self.y[at.clone()], self.weights.map(|w| &w[at]));
                    }
                }
            }
            // the accumulator notices a value that is not finite in passing; find it only then
            if let Some(j) = acc.not_finite() {
                let (values, term) = match columns.get(j) {
                    Some(c) => (*c, terms.get(j).map_or_else(|| format!("{}", j + 1), Term::to_string)),
                    None => (y, self.target.clone()),
                };
                // no such value: the sum overflowed; name the largest
                let i = values.iter().position(|v| !v.is_finite()).unwrap_or_else(|| {
                    (0..values.len())
                        .max_by(|&a, &b| values[a].abs().total_cmp(&values[b].abs()))
                        .unwrap_or(0)
                });
                bad = Some(IdentifyError::NonFinite {
                    file: self.origin.into(),
                    row: start + i + 1,
                    target: columns.get(j).is_none(),
                    term,
                    value: values.get(i).copied().unwrap_or(f64::NAN),
                });
            }
        });
        bad.map_or(Ok(()), Err)
    }
}

/// Row weights, refused where one is negative.
fn checked_weights<'a>(origin: &str, column: &str, w: &'a [f64]) -> Result<&'a [f64], IdentifyError> {
    match w.iter().position(|w| *w < 0.0) {
        Some(i) => Err(IdentifyError::Setup(format!(
            "{origin}: row {}: weight `{column}` = {} is negative",
            i + 1,
            w[i]
        ))),
        None => Ok(w),
    }
}

/// s²·S⁻¹ of the chosen terms, S their (centred when there is an intercept) cross products:
/// the covariance whose diagonal gives the standard errors the back-ends report (eq. A12).
fn covariance_of(moments: &Moments, selection: &Selection) -> Option<Vec<Vec<f64>>> {
    let set: Vec<usize> = selection.terms.iter().map(|t| t.index).collect();
    let k = set.len();
    let intercept = selection.intercept.as_ref().map(|b| b.value);
    let dof = moments.count() as f64 - k as f64 - f64::from(u8::from(intercept.is_some()));
    if k == 0 || dof <= 0.0 {
        return None;
    }
    let coefficients: Vec<f64> = selection.terms.iter().map(|t| t.coefficient).collect();
    let s2 = moments.squared_error(&set, &coefficients, intercept.unwrap_or(0.0)).max(0.0) / dof;
    let cross_product =
        |i: usize, j: usize| if intercept.is_some() { moments.corrected(i, j) } else { moments.raw(i, j) };
    // sweeping every pivot of a positive definite matrix leaves its inverse; a pivot that is
    // not clearly positive means the cross products are singular on this set
    let mut inverse: Vec<f64> = (0..k * k).map(|e| cross_product(set[e / k], set[e % k])).collect();
    for j in 0..k {
        let scale = cross_product(set[j], set[j]).abs();
        if inverse[j * k + j].is_nan() || inverse[j * k + j] <= 1e-14 * scale {
            return None;
        }
        crate::select::sweep(&mut inverse, k, j);
    }
    // the sweep's round-off leaves the inverse symmetric only to ~1e-8 relative on
    // ill-conditioned sets; a covariance is symmetric by definition, so take the mean
    let cov: Vec<Vec<f64>> = (0..k)
        .map(|i| (0..k).map(|j| s2 * 0.5 * (inverse[i * k + j] + inverse[j * k + i])).collect())
        .collect();
    cov.iter().flatten().all(|v| v.is_finite()).then_some(cov)
}

/// The share of a rate's variance (R²) below which its chosen terms are said to explain little.
const EXPLAINED: f64 = 0.5;

/// A note where the chosen terms explain less than [`EXPLAINED`] of the variance of `state`'s
/// rate: for an equation of motion that is noise, or a rate that hangs on what the candidates
/// lack. A pendulum's angle alone (θ̈ = −9.81 sin θ − 0.1 θ̇ recorded as θ only) gives
/// dθ/dt = −0.117θ − 0.078θ² at R² = 0.006, t-values of 3 and every check passed; no
/// equation of θ alone can turn back as θ does.
fn unexplained_note(selection: &crate::select::Selection, state: &str) -> Option<String> {
    let r2 = selection.chosen_r2().unwrap_or(0.0);
    (r2 < EXPLAINED).then(|| {
        format!(
            "the chosen terms explain {} % of the variance of `{state}`'s rate: the rest is noise, or \
             hangs on what the candidates lack — a state not recorded (a motion that turns back, \
             seen in one coordinate, needs its rate as a state too: `--states {state},v=d{state}/dt` \
             estimates it from `{state}`'s record, Python `states=[\"{state}\", \"v=d{state}/dt\"]`), \
             an input, a delay; the re-simulation says which",
            report::sig(100.0 * r2.max(0.0), 2)
        )
    })
}

/// Samples per characteristic period below which a rate's estimate is said to be coarse.
pub(crate) const SAMPLES_PER_PERIOD: f64 = 16.0;

/// A note where the rows sample `state`'s motion coarsely: fewer than [`SAMPLES_PER_PERIOD`]
/// samples in its characteristic period T = 2π·σ(x)/σ(ẋ) (the period of a sinusoid of the
/// same amplitudes; ẋ by central differences, pooled over the runs). Below it the error of
/// quadrature or differencing is no longer small against the motion and enters the fit as
/// spurious terms and biased coefficients: Lorenz's z at 17.7 samples a period keeps its
/// two true terms within 0.02 %, at 12.5 six terms 15 % off, and nothing else in the fit says so.
fn resolution_note(frames: &[Frame], state: &str) -> Option<String> {
    let (samples, period) = samples_per_period(frames, state)?;
    (samples < SAMPLES_PER_PERIOD).then(|| {
        format!(
            "the rows sample `{state}` coarsely: {} samples in its characteristic period (2π·σ/σ of its \
             rate, {} s); below about {SAMPLES_PER_PERIOD} the error of quadrature or differencing \
             enters the fit as spurious terms and biased coefficients: sample faster, or read these as rough",
            report::sig(samples, 3),
            report::sig(period, 3)
        )
    })
}

/// The states of `names` the rows of `frames` sample coarsely ([`resolution_note`]), with their
/// samples per characteristic period.
pub(crate) fn coarsely_sampled(frames: &[Frame], names: &[String]) -> Vec<(String, f64)> {
    names
        .iter()
        .filter_map(|n| samples_per_period(frames, n).map(|(s, _)| (n.clone(), s)))
        .filter(|(_, s)| *s < SAMPLES_PER_PERIOD)
        .collect()
}

/// The samples of `frames` in `state`'s characteristic period T = 2π·σ(x)/σ(ẋ), and T (s);
/// `None` where the runs do not record it or hold too few samples.
fn samples_per_period(frames: &[Frame], state: &str) -> Option<(f64, f64)> {
    let runs: Vec<(&[f64], &[f64])> =
        frames.iter().filter_map(|f| Some((f.column(state)?, f.time()))).collect();
    let values: Vec<f64> = runs.iter().flat_map(|(x, _)| x.iter().copied()).collect();
    // (central difference, half its span) at every inner sample
    let (rates, steps): (Vec<f64>, Vec<f64>) = runs
        .iter()
        .flat_map(|(x, t)| {
            (1..x.len().saturating_sub(1))
                .map(move |k| ((x[k + 1] - x[k - 1]) / (t[k + 1] - t[k - 1]), 0.5 * (t[k + 1] - t[k - 1])))
        })
        .unzip();
    if rates.len() < 2 {
        return None;
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let sd = |v: &[f64]| {
        let m = mean(v);
        (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt()
    };
    let dt = mean(&steps);
    let samples = 2.0 * std::f64::consts::PI * sd(&values) / sd(&rates) / dt;
    samples.is_finite().then_some((samples, samples * dt))
}

/// Said where a rate is estimated at the samples (a point derivative, not the integral form)
/// from runs with a candidate's input held or switched between samples: at each of its jumps
/// the rate jumps too, which differencing and smoothing spread over the samples beside it (a
/// mass-spring-damper driven by a force held for 0.5 s, by a five-point stencil: damping
/// −0.3009 for −0.3, a smoothing spline adds F·x² and F²·x; the integral form integrates the
/// held force piece by piece: exact). A held input is read at its mean about each sample
/// ([`Identification::as_rates_see_it`]), which central differences see exactly.
fn held_rate_note(
    frames: &[Frame],
    library: &Library,
    state: &str,
    method: &dyn Differentiator,
) -> Option<String> {
    let mut held: Vec<&str> = Vec::new();
    let mut jumps = 0;
    for f in frames {
        let marked = f.held().iter().chain(f.switched());
        for h in marked.filter(|h| library.inputs().contains(h)) {
            if let Some(c) = f.column(h) {
                // a held column jumps at each of its changes (a smooth command held: at every
                // sample, where its switches, read as a relay's, were none)
                jumps += match f.is_held(h) {
                    true => c.windows(2).filter(|w| w[1] != w[0]).count(),
                    false => crate::data::switches(f.time(), c).len(),
                };
                if !held.contains(&h.as_str()) {
                    held.push(h);
                }
            }
        }
    }
    (!held.is_empty()).then(|| {
        format!(
            "{} held or switched between samples, {jumps} jumps in all: at each the rate of `{state}` \
             jumps too, and the {} derivative spreads it over the samples beside, which biases the \
             coefficients; the weak form (`--derivative weak`, the default for a rate) and the \
             integral form integrate a held input piece by piece between its jumps and leave out \
             the windows that hold a switch",
            match held.as_slice() {
                [one] => format!("`{one}` is"),
                many =>
                    format!("{} are", many.iter().map(|h| format!("`{h}`")).collect::<Vec<_>>().join(", ")),
            },
            method.name()
        )
    })
}

/// The windows of `w` intervals of a run that hold a switch of an input the `library` reads
/// ([`Frame::switch`]: a relay, a measured input stepped, at an instant between two samples
/// the rows do not tell), as `keep[s]` false for the window from sample `s`, with the inputs
/// and their switches. Left out, the rest are exact whatever the instants; a line across
/// each switch (Simpson's rule over it) biases every coefficient (a mass-spring-damper on a
/// relay switched 66 times in 60 s, sampled every 0.01 s: damping −0.3018 for −0.3). `None`
/// where nothing switches; no `keep` where leaving them out would leave fewer than half the
/// windows (a switch every few samples), which then stay.
fn switched_windows<'a>(frame: &'a Frame, library: &Library, w: usize) -> Option<Switched<'a>> {
    let n = frame.len();
    let inputs: Vec<&str> = frame
        .switched()
        .iter()
        .map(String::as_str)
        .filter(|s| library.inputs().iter().any(|i| i == s))
        .collect();
    let mut at: Vec<usize> = inputs
        .iter()
        .filter_map(|s| frame.column(s))
        .flat_map(|c| crate::data::switches(frame.time(), c))
        .collect();
    if at.is_empty() || n <= w {
        return None;
    }
    at.sort_unstable();
    at.dedup();
    // the window from s holds samples s..=s + w: a switch between rows k − 1 and k if s < k ≤ s + w
    let mut keep = vec![true; n - w];
    for &k in &at {
        keep[k.saturating_sub(w)..k.min(n - w)].iter_mut().for_each(|x| *x = false);
    }
    let kept = keep.iter().filter(|k| **k).count();
    Some(Switched { keep: (2 * kept >= keep.len()).then_some(keep), inputs, switches: at.len() })
}

/// The windows run `frame` takes: `window` as chosen; a default one ([`Window::shrinks`]) the
/// integral form's where the run is too short for four of its windows ([`Window::on_rows`]) or
/// where more than half of them would hold a switch of an input of `library` (they could not
/// all be left out, and a switch taken as a line biases the fit; the integral form's shorter
/// windows leave them out).
///
/// [`Window::shrinks`]: crate::data::Window::shrinks
/// [`Window::on_rows`]: crate::data::Window::on_rows
fn run_window(frame: &Frame, library: &Library, window: crate::data::Window) -> crate::data::Window {
    let on = window.on_rows(frame.len());
    let dense = || switched_windows(frame, library, window.intervals).is_some_and(|s| s.keep.is_none());
    if window.shrinks && on == window && dense() {
        crate::data::Window::fallback()
    } else {
        on
    }
}

/// The windows of a run that hold a switch ([`switched_windows`]).
struct Switched<'a> {
    /// Whether each window is kept; `None` where too many hold a switch to leave them out.
    keep: Option<Vec<bool>>,
    /// The inputs that switch.
    inputs: Vec<&'a str>,
    /// Their switches, counted once where two fall on one interval.
    switches: usize,
}

/// Said where a rate's fit in the integral form left out the windows that hold an input's
/// switch ([`switched_windows`]), or could not (switches too close).
fn switched_note(frames: &[Frame], library: &Library, window: crate::data::Window) -> Option<String> {
    let (mut names, mut switches, mut left, mut all, mut dense) = (Vec::<&str>::new(), 0, 0, 0, 0);
    for f in frames {
        let w = run_window(f, library, window).intervals;
        let Some(Switched { keep, inputs, switches: at }) = switched_windows(f, library, w) else { continue };
        for i in inputs {
            if !names.contains(&i) {
                names.push(i);
            }
        }
        switches += at;
        all += f.len() - w;
        match keep {
            Some(keep) => left += keep.iter().filter(|k| !**k).count(),
            None => dense += 1,
        }
    }
    if names.is_empty() {
        return None;
    }
    let who = names.iter().map(|h| format!("`{h}`")).collect::<Vec<_>>().join(", ");
    let times = if switches == 1 { "once".to_string() } else { format!("{switches} times") };
    Some(if dense == 0 {
        format!(
            "{who} switched between samples {times} in all, at instants the rows do not tell: \
             the {left} windows of the weak or integral form (of {all}) that hold a switch are left out of the fit"
        )
    } else {
        format!(
            "{who} switched between samples {times} in all, too often to leave out the windows \
             of the weak or integral form that hold a switch in {dense} run(s) (more than half of them): taken \
             there as a line across each switch, which biases the coefficients; a shorter window \
             (`--derivative integral:W`, W even) leaves more"
        )
    })
}

/// Variance inflation above which the chosen terms are said to be nearly collinear: their
/// coefficients' standard errors are 100 times what they would be for unrelated terms.
const COLLINEAR_INFLATION: f64 = 1e4;

/// A note where the chosen terms are nearly collinear in these data (a variance inflation
/// VIF_j = C_jj·(C⁻¹)_jj above [`COLLINEAR_INFLATION`]): their coefficients then trade against
/// each other, another choice among them fits about as well, and a back-end's pick among
/// near-equivalent sets says little about the system. The usual cause in a library of
/// products is a variable far from 0 against its spread (a temperature in kelvin, a pressure
/// in pascal, a ship's speed): `z` and `z²`, `x` and `x·z` then move together; the note names
/// such variables among the candidates and the remedy, terms about a reference value.
fn collinearity_note(moments: &Moments, names: &[String], selection: &Selection) -> Option<String> {
    let set: Vec<usize> = selection.terms.iter().map(|t| t.index).collect();
    let k = set.len();
    if k < 2 {
        return None;
    }
    let intercept = selection.intercept.is_some();
    let cross = |i: usize, j: usize| if intercept { moments.corrected(i, j) } else { moments.raw(i, j) };
    let d: Vec<f64> = set.iter().map(|&i| cross(i, i).max(0.0).sqrt()).collect();
    if d.iter().any(|v| v.is_nan() || *v <= 0.0) {
        return None;
    }
    let r = nalgebra::DMatrix::from_fn(k, k, |i, j| cross(set[i], set[j]) / (d[i] * d[j]));
    let inverse = r.try_inverse()?;
    let (worst, inflation) = (0..k).map(|j| (j, inverse[(j, j)])).max_by(|a, b| a.1.total_cmp(&b.1))?;
    if inflation.is_nan() || inflation <= COLLINEAR_INFLATION {
        return None;
    }
    // its partner: the largest partial correlation −R⁻¹_ij / √(R⁻¹_ii R⁻¹_jj)
    let partner = (0..k).filter(|&j| j != worst).max_by(|&a, &b| {
        let partial = |j: usize| (inverse[(worst, j)] / (inverse[(j, j)] * inflation).sqrt()).abs();
        partial(a).total_cmp(&partial(b))
    })?;
    let mut note = format!(
        "`{}` is nearly a combination of the other chosen terms in these data (variance \
         inflation {inflation:.1e}; most with `{}`): their coefficients trade against each other \
         and another choice among the candidates may fit about as well",
        names[set[worst]], names[set[partner]]
    );
    let means = moments.means();
    // (name, |mean| / spread) of the candidates that are a variable alone; the ratio, not the
    // values: in the integral form the columns are a variable's integrals over windows
    let offset: Vec<(&String, f64)> = names
        .iter()
        .enumerate()
        .filter(|(_, n)| crate::term::is_identifier(n))
        .filter_map(|(i, n)| {
            let sd = (moments.corrected(i, i).max(0.0) / moments.weight()).sqrt();
            let ratio = means[i].abs() / sd;
            (sd > 0.0 && ratio > crate::model::OFFSET_SPREADS).then_some((n, ratio))
        })
        .collect();
    if let Some((v, _)) = offset.first() {
        let listed: Vec<String> = offset
            .iter()
            .map(|(n, ratio)| format!("`{n}` (its mean {} times its spread)", report::sig(*ratio, 2)))
            .collect();
        note += &format!(
            ". Far from 0 against their spread: {}; such a variable's powers and products move \
             with the lower terms; written about a reference value c near its mean (`{v} - c`, \
             `x*({v} - c)`) they do not",
            listed.join(", ")
        );
    }
    Some(note)
}

impl Identification<'_> {
    /// The per-run parameter values.
    pub fn run_parameters(&self, frame: &Frame) -> Result<BTreeMap<String, f64>, IdentifyError> {
        self.parameters.iter().map(|(n, v)| Ok((n.clone(), v.resolve(n, frame)?))).collect()
    }

    /// The target values of one run.
    pub fn target(&self, target: &Target, frame: &Frame) -> Result<Vec<f64>, IdentifyError> {
        Ok(match target {
            Target::Column(c) => frame.require(c)?.to_vec(),
            Target::Derivative(s) => {
                let x = frame.require(s)?;
                self.differentiator
                    .differentiate(frame.time(), x)
                    .map_err(|e| e.in_run(frame.origin(), None))?
            }
        })
    }

    /// Sufficient statistics of the compiled candidates against the target on one run.
    pub fn moments(
        &self,
        library: &Library,
        target: &Target,
        frame: &Frame,
    ) -> Result<Moments, IdentifyError> {
        // without the terms at hand, a term that is not finite is named by its column
        Ok(self.moments_of_runs(library, &[], target, std::slice::from_ref(frame))?.remove(0))
    }

    /// The statistics of rows `rows` of one run: a piece of a run read in chunks, the
    /// target's derivative taken on the whole piece (its rows and its neighbours'), only its
    /// own rows counted.
    pub fn moments_of_rows(
        &self,
        library: &Library,
        terms: &[Term],
        target: &Target,
        frame: &Frame,
        rows: std::ops::Range<usize>,
    ) -> Result<Moments, IdentifyError> {
        Ok(self.moments_of_parts(library, terms, target, frame, std::slice::from_ref(&rows))?.remove(0))
    }

    /// [`Identification::moments_of_rows`] of several ranges of a piece's rows, the derivative
    /// (or the weak form's windows) taken once: the halves of a piece, for the check that a
    /// run read in pieces chooses the same terms from each half of it.
    pub fn moments_of_parts(
        &self,
        library: &Library,
        terms: &[Term],
        target: &Target,
        frame: &Frame,
        parts: &[std::ops::Range<usize>],
    ) -> Result<Vec<Moments>, IdentifyError> {
        if let (Some(window), Target::Derivative(_)) = (self.differentiator.window(), target) {
            // a piece of a run takes the run's windows, however short the piece with its context
            let window = crate::data::Window { shrinks: false, ..window };
            return self.integral_moments(library, terms, target, frame, window, parts);
        }
        let frame = self.as_rates_see_it(library, target, frame)?;
        let run = self.bind(library, target, &frame)?;
        let rows: Vec<usize> = parts.iter().map(|p| p.len()).collect();
        gather(library.len(), &rows, |k, part, acc| {
            let offset = parts[k].start;
            run.push(library, terms, part.start + offset..part.end + offset, acc)
        })
    }

    /// The statistics of each run, and of its first and second half (rows `0..n/2`, `n/2..n`;
    /// the windows of the weak or integral form by the row they start on), gathered in
    /// parallel: the run's as [`Identification::moments_of_runs`] gives them, to the bit.
    pub(crate) fn moments_and_halves_of_runs(
        &self,
        library: &Library,
        terms: &[Term],
        target: &Target,
        frames: &[Frame],
    ) -> Result<Vec<(Moments, [Moments; 2])>, IdentifyError> {
        if let (Some(window), Target::Derivative(_)) = (self.differentiator.window(), target) {
            return frames
                .iter()
                .map(|f| {
                    let (n, middle) = (f.len(), f.len() / 2);
                    let mut m = self.integral_moments(
                        library,
                        terms,
                        target,
                        f,
                        window,
                        &[0..n, 0..middle, middle..n],
                    )?;
                    let second = m.pop().unwrap_or_else(|| Moments::new(library.len()));
                    let first = m.pop().unwrap_or_else(|| Moments::new(library.len()));
                    Ok((m.pop().unwrap_or_else(|| Moments::new(library.len())), [first, second]))
                })
                .collect();
        }
        let frames =
            frames.iter().map(|f| self.as_rates_see_it(library, target, f)).collect::<Result<Vec<_>, _>>()?;
        let runs = frames.iter().map(|f| self.bind(library, target, f)).collect::<Result<Vec<_>, _>>()?;
        let rows: Vec<usize> = frames.iter().map(|f| f.len()).collect();
        gather_halved(library.len(), &rows, |k, part, acc, split| {
            runs[k].push_split(library, terms, part, acc, split)
        })
    }

    /// The statistics of each run, gathered in parallel (parts of runs on all threads).
    pub(crate) fn moments_of_runs(
        &self,
        library: &Library,
        terms: &[Term],
        target: &Target,
        frames: &[Frame],
    ) -> Result<Vec<Moments>, IdentifyError> {
        if let (Some(window), Target::Derivative(_)) = (self.differentiator.window(), target) {
            return frames
                .iter()
                .map(|f| {
                    Ok(self
                        .integral_moments(
                            library,
                            terms,
                            target,
                            f,
                            window,
                            std::slice::from_ref(&(0..f.len())),
                        )?
                        .remove(0))
                })
                .collect();
        }
        let frames =
            frames.iter().map(|f| self.as_rates_see_it(library, target, f)).collect::<Result<Vec<_>, _>>()?;
        let runs = frames.iter().map(|f| self.bind(library, target, f)).collect::<Result<Vec<_>, _>>()?;
        let rows: Vec<usize> = frames.iter().map(|f| f.len()).collect();
        gather(library.len(), &rows, |k, part, acc| runs[k].push(library, terms, part, acc))
    }

    /// One run's statistics in the integral form ([`Identification::windows`]), one per part
    /// of its rows: the windows that start on the part's rows (all of a whole run; a piece's
    /// own, its context after it holding their ends; a half's).
    fn integral_moments(
        &self,
        library: &Library,
        terms: &[Term],
        target: &Target,
        frame: &Frame,
        window: crate::data::Window,
        parts: &[std::ops::Range<usize>],
    ) -> Result<Vec<Moments>, IdentifyError> {
        let rows = self.windows(library, target, frame, window)?;
        let Rows { y, columns: integrals, weights, starts: first_rows, window } =
            match rows.window.instrumented {
                true => rows.instrumented(),
                false => rows,
            };
        let part = |own: &std::ops::Range<usize>| {
            // the rows of the windows that start on `own` samples (some left out: a switch inside)
            let starts =
                first_rows.partition_point(|s| *s < own.start)..first_rows.partition_point(|s| *s < own.end);
            let refs: Vec<&[f64]> = integrals.iter().map(|c| &c[starts.clone()]).collect();
            let weights = weights.as_ref().map(|w| w[starts.clone()].to_vec());
            let mut acc = Accumulator::new(library.len());
            acc.push_columns(&refs, &y[starts.clone()], weights.as_deref());
            if let Some(j) = acc.not_finite() {
                // named as a point derivative's row is: the term (or the target) and the row its
                // window starts on (no such value: the sums overflowed; the largest named)
                let values = refs.get(j).copied().unwrap_or(&y[starts.clone()]);
                let i = values.iter().position(|v| !v.is_finite()).unwrap_or_else(|| {
                    (0..values.len())
                        .max_by(|&a, &b| values[a].abs().total_cmp(&values[b].abs()))
                        .unwrap_or(0)
                });
                let term = match (terms.get(j), target) {
                    (Some(t), _) if j < library.len() => t.to_string(),
                    (None, _) if j < library.len() => format!("{}", j + 1),
                    (_, Target::Derivative(s)) => format!("d{s}/dt"),
                    (_, Target::Column(c)) => c.clone(),
                };
                return Err(IdentifyError::NonFinite {
                    file: frame.origin().into(),
                    row: first_rows.get(starts.start + i).map_or(1, |r| r + 1),
                    target: j >= library.len(),
                    term,
                    value: values.get(i).copied().unwrap_or(f64::NAN),
                });
            }
            Ok(acc.finish().with_overlap(crate::data::row_overlap(window)))
        };
        parts.iter().map(part).collect()
    }

    /// The rows of the integral form of one run: the candidates evaluated on every sample,
    /// integrated over each window of `w` intervals, against the target's change over it; with
    /// each window's weight, the mean of its rows' (where the rows are weighted).
    fn windows(
        &self,
        library: &Library,
        target: &Target,
        frame: &Frame,
        window: crate::data::Window,
    ) -> Result<Rows, IdentifyError> {
        let window = run_window(frame, library, window);
        let (n, w) = (frame.len(), window.intervals);
        if n <= w + 1 {
            return Err(IdentifyError::Setup(format!(
                "{}: {n} rows are too few for windows of {w} intervals (--derivative)",
                frame.origin()
            )));
        }
        let run = self.bind(library, target, frame)?;
        let evaluate = |sources: &[crate::term::Source<'_>]| {
            let mut samples = vec![Vec::with_capacity(n); library.len()];
            library.for_each_block(sources, 0..n, |_, block| {
                for (c, b) in samples.iter_mut().zip(block) {
                    c.extend_from_slice(b);
                }
            });
            samples
        };
        let samples = evaluate(&run.sources);
        // inputs held between samples: the candidates also with each held input at the sample
        // before (its value up to the jump), for the windows with a jump inside
        let held: Vec<(&str, &[f64])> = frame
            .held()
            .iter()
            .filter(|h| library.inputs().iter().any(|i| i == *h))
            .filter_map(|h| Some((h.as_str(), frame.column(h)?)))
            .collect();
        let jumps: Vec<bool> = (0..n).map(|k| k > 0 && held.iter().any(|(_, c)| c[k] != c[k - 1])).collect();
        let (y, columns) = if jumps.iter().any(|j| *j) {
            let lagged: Vec<(&str, Vec<f64>)> = held
                .iter()
                .map(|(h, c)| (*h, std::iter::once(c[0]).chain(c[..n - 1].iter().copied()).collect()))
                .collect();
            let params = self.run_parameters(frame)?;
            let column = |name: &str| {
                lagged
                    .iter()
                    .find(|(h, _)| *h == name)
                    .map(|(_, c)| c.as_slice())
                    .or_else(|| frame.column(name))
            };
            let sources = library.bind(&column, &|p| params.get(p).copied())?;
            let before = evaluate(&sources);
            crate::data::integral_rows_held(frame.time(), &run.y, &samples, &before, &jumps, window)
        } else {
            crate::data::integral_rows(frame.time(), &run.y, &samples, window)
        };
        let weights: Option<Vec<f64>> = run
            .weights
            .map(|r| (0..y.len()).map(|k| r[k..=k + w].iter().sum::<f64>() / (w + 1) as f64).collect());
        let Some(Switched { keep: Some(keep), .. }) = switched_windows(frame, library, w) else {
            let starts = (0..y.len()).collect();
            return Ok(Rows { y, columns, weights, starts, window });
        };
        let kept = |v: Vec<f64>| v.into_iter().zip(&keep).filter(|(_, k)| **k).map(|(x, _)| x).collect();
        Ok(Rows {
            starts: (0..y.len()).filter(|&s| keep[s]).collect(),
            y: kept(y),
            columns: columns.into_iter().map(kept).collect(),
            weights: weights.map(kept),
            window,
        })
    }

    /// The run as a rate estimated at its samples sees it: each input held between samples at
    /// the mean of its values before and after the sample, (F[i−1] + F[i]) / 2. A centred
    /// estimate (central differences, a five-point stencil, a smoother) of a state's rate at
    /// a sample averages it over the intervals on both sides, where a held input stood at
    /// F[i−1] and then at F[i]; read at F[i] it is half an interval early (the mass-spring-
    /// damper under a sine held every 0.05 s: damping −0.226 for −0.3 by central differences,
    /// with the mean −0.3000). Exact for a term linear in the input under central differences,
    /// to second order in the interval otherwise. The run itself where nothing is held, where
    /// the target is a column, and for the integral forms (which integrate a held input piece
    /// by piece, [`Identification::windows`]).
    fn as_rates_see_it<'f>(
        &self,
        library: &Library,
        target: &Target,
        frame: &'f Frame,
    ) -> Result<std::borrow::Cow<'f, Frame>, IdentifyError> {
        let held: Vec<&String> = match (target, self.differentiator.window()) {
            (Target::Derivative(_), None) => {
                frame.held().iter().filter(|h| library.inputs().contains(h)).collect()
            }
            _ => Vec::new(),
        };
        if held.is_empty() {
            return Ok(std::borrow::Cow::Borrowed(frame));
        }
        let mut seen = frame.clone();
        for h in held {
            let c = frame.require(h)?;
            let mid = (0..c.len()).map(|i| 0.5 * (c[i.saturating_sub(1)] + c[i])).collect();
            seen.overwrite(h, mid)?;
        }
        Ok(std::borrow::Cow::Owned(seen))
    }

    /// A run made ready for accumulation: its target, its inputs with its own parameters, and
    /// its row weights.
    fn bind<'a>(
        &self,
        library: &Library,
        target: &Target,
        frame: &'a Frame,
    ) -> Result<BoundRun<'a>, IdentifyError> {
        let y = self.target(target, frame)?;
        let params = self.run_parameters(frame)?;
        let sources = library.bind(&|n| frame.column(n), &|n| params.get(n).copied())?;
        let weights = match &self.weights {
            Some(col) => Some(checked_weights(frame.origin(), col, frame.require(col)?)?),
            None => None,
        };
        Ok(BoundRun { origin: frame.origin(), target: target.to_string(), y, sources, weights })
    }

    /// Identifies one equation, `target` explained by the candidates of `design`, from rows
    /// given as borrowed columns of equal length — an embedding's arrays (numpy, Arrow) used
    /// where they lie, with no copy into a [`Frame`]. The rows are one run, not a time series
    /// (no derivative targets, no per-run rules: parameters are values); a value that is not
    /// finite is refused with its row and term as from a frame. `origin` names the rows in
    /// errors.
    #[allow(clippy::too_many_arguments)]
    pub fn fit_columns(
        &self,
        origin: &str,
        columns: &[(&str, &[f64])],
        target: &str,
        design: &Design,
        forced: &[Term],
        excluded: &[Term],
        backend: &dyn Selector,
    ) -> Result<Fit, IdentifyError> {
        let column = |name: &str| columns.iter().find(|(n, _)| *n == name).map(|(_, c)| *c);
        let rows = columns.first().map_or(0, |(_, c)| c.len());
        if let Some((name, c)) = columns.iter().find(|(_, c)| c.len() != rows) {
            return Err(crate::data::DataError::Length {
                file: origin.into(),
                column: (*name).into(),
                expected: rows,
                found: c.len(),
            }
            .into());
        }
        if rows == 0 {
            return Err(crate::data::DataError::Empty { file: origin.into() }.into());
        }
        let require = |name: &str| {
            column(name).ok_or_else(|| crate::data::DataError::MissingColumn {
                file: origin.into(),
                column: name.into(),
                available: columns.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "),
            })
        };
        let y = require(target)?;
        let params = self
            .parameters
            .iter()
            .map(|(n, v)| match v {
                ParamValue::Value(v) => Ok((n.clone(), *v)),
                ParamValue::Rule(r) => Err(IdentifyError::Setup(format!(
                    "parameter `{n}` = `{r}`: a rule per run needs runs; give its value"
                ))),
            })
            .collect::<Result<BTreeMap<_, _>, _>>()?;
        let library = &design.library;
        let sources = library.bind(&column, &|n| params.get(n).copied())?;
        let weights = match &self.weights {
            Some(col) => Some(checked_weights(origin, col, require(col)?)?),
            None => None,
        };
        let run = BoundRun { origin, target: target.to_string(), y: y.to_vec(), sources, weights };
        let (forced, excluded) =
            (design.columns_of(forced, "forced")?, design.columns_of(excluded, "excluded")?);
        let folds =
            gather(library.len(), &[rows], |_, part, acc| run.push(library, design.candidates(), part, acc))?;
        fit_folds(target, design.names(), &forced, &excluded, self.intercept, &folds, backend)
    }

    /// Identifies one equation from all runs together ("Komb. Daten").
    ///
    /// Hald's cement data (Hald 1952), the classic case of stepwise regression: the heat
    /// `y` explained by four ingredients; STPRG enters x4, x1, x2, x3 (Draper & Smith).
    ///
    /// ```
    /// use std::collections::BTreeMap;
    /// use termid::data::{CentralDifference, Frame};
    /// use termid::identify::{Identification, Target};
    /// use termid::select::{StepRule, Stepwise};
    /// use termid::term::{parse_terms, Vocabulary};
    ///
    /// let hald = Frame::read_csv_untimed(std::path::Path::new("tests/data/hald.csv"))?;
    /// let mut vocabulary = Vocabulary::new();
    /// for x in ["x1", "x2", "x3", "x4"] {
    ///     vocabulary.variable(x)?;
    /// }
    /// let candidates = parse_terms(&["x1", "x2", "x3", "x4"], &vocabulary)?;
    /// let how = Identification {
    ///     vocabulary: &vocabulary,
    ///     parameters: &BTreeMap::new(),
    ///     differentiator: &CentralDifference,
    ///     intercept: true,
    ///     weights: None,
    /// };
    /// let backend = Stepwise { step_rule: StepRule::Last, ..Stepwise::default() };
    /// let fit = how.fit(&Target::Column("y".into()), &candidates, &[], &[], &[hald], &backend)?;
    /// let order: Vec<&str> = fit.selection.steps.iter().map(|s| s.term.as_str()).collect();
    /// assert_eq!(order, ["x4", "x1", "x2", "x3"]);
    /// // y = 117.57 − 0.7382 x4 after the first step (Draper & Smith)
    /// assert!((fit.selection.terms_at(1)[0].coefficient + 0.738162).abs() < 1e-5);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn fit(
        &self,
        target: &Target,
        candidates: &[Term],
        forced: &[Term],
        excluded: &[Term],
        frames: &[Frame],
        backend: &dyn Selector,
    ) -> Result<Fit, IdentifyError> {
        // compiling overlaps with the worker's waking (fit_design's second call is cheap)
        wake_a_worker(frames, candidates.len());
        let design = Design::new(candidates, self.vocabulary)?;
        self.fit_design(target, &design, forced, excluded, frames, backend)
    }

    /// The statistics [`Identification::fit_design`] selects from: each run's moments (the
    /// folds) and the `forced` and `excluded` terms' columns of `design`.
    fn folds_of(
        &self,
        target: &Target,
        design: &Design,
        forced: &[Term],
        excluded: &[Term],
        frames: &[Frame],
    ) -> Result<Folds, IdentifyError> {
        wake_a_worker(frames, design.candidates().len());
        if frames.is_empty() {
            return Err(IdentifyError::Setup("no data: give at least one run".into()));
        }
        let (forced, excluded) =
            (design.columns_of(forced, "forced")?, design.columns_of(excluded, "excluded")?);
        // per run, for the back-ends that cross-validate; together they are "Komb. Daten"
        let folds = self.moments_of_runs(&design.library, design.candidates(), target, frames)?;
        Ok(Folds { forced, excluded, folds })
    }

    /// The selection of [`Identification::fit_design`] alone: the back-end on the runs'
    /// statistics, without the notes, rivals and covariance a reader wants (a scan that judges
    /// many fits by their criterion alone: the saturations' scan of K spent half its time on
    /// them).
    pub fn select_design(
        &self,
        target: &Target,
        design: &Design,
        forced: &[Term],
        excluded: &[Term],
        frames: &[Frame],
        backend: &dyn Selector,
    ) -> Result<Selection, IdentifyError> {
        let Folds { forced, excluded, folds } = self.folds_of(target, design, forced, excluded, frames)?;
        Ok(select_folds(design.names(), &forced, &excluded, self.intercept, &folds, backend)?.1)
    }

    /// [`Identification::fit`] with the candidates already compiled.
    pub fn fit_design(
        &self,
        target: &Target,
        design: &Design,
        forced: &[Term],
        excluded: &[Term],
        frames: &[Frame],
        backend: &dyn Selector,
    ) -> Result<Fit, IdentifyError> {
        let candidates = design.candidates();
        let Folds { forced, excluded, folds } = self.folds_of(target, design, forced, excluded, frames)?;
        let mut fit = fit_folds(
            &target.to_string(),
            design.names(),
            &forced,
            &excluded,
            self.intercept,
            &folds,
            backend,
        )?;
        // a law the noise blurs, where no exact one was said
        let mut pooled = Moments::new(design.names().len());
        folds.iter().for_each(|f| pooled.merge(f));
        if invariant::exact_note(&pooled, design.names()).is_none() {
            fit.selection.notes.extend(invariant::within_noise_note(frames, candidates, design.names()));
        }
        if let Target::Derivative(state) = target {
            fit.selection.notes.extend(unexplained_note(&fit.selection, state));
            fit.selection.notes.extend(resolution_note(frames, state));
            match self.differentiator.window() {
                Some(w) => fit.selection.notes.extend(switched_note(frames, &design.library, w)),
                None => fit.selection.notes.extend(held_rate_note(
                    frames,
                    &design.library,
                    state,
                    self.differentiator,
                )),
            }
        }
        Ok(fit)
    }

    /// What the chosen equation's residuals say of the fit, in one more pass over the rows
    /// (the weak or integral form's windows where it is one): their correlation time τ = 1 + 2 Σ ρₖ,
    /// the autocorrelations ρₖ pooled over the runs and summed up to the first lag where they
    /// fall below zero (Geyer's initial positive sequence, simplified; at most 1000 lags;
    /// `None` with row weights or a run too short), and how they grow with the fit's size
    /// ([`Fit::residual_growth`]), set in `fit`.
    pub fn describe_residuals(
        &self,
        target: &Target,
        candidates: &[Term],
        frames: &[Frame],
        fit: &mut Fit,
    ) -> Result<(), IdentifyError> {
        let selection = &fit.selection;
        if selection.terms.is_empty() {
            return Ok(());
        }
        let chosen: Vec<Term> = selection.terms.iter().map(|t| candidates[t.index].clone()).collect();
        let library = Library::compile(&chosen, self.vocabulary)?;
        let b0 = selection.intercept.as_ref().map_or(0.0, |b| b.value);
        let mut residuals: Vec<Vec<f64>> = Vec::new();
        // (|fitted|, residual) of every row
        let mut sized: Vec<(f64, f64)> = Vec::new();
        let window = match target {
            Target::Derivative(_) => self.differentiator.window(),
            Target::Column(_) => None,
        };
        // the statistics count a weak form's overlapping windows already (Moments::overlap):
        // the residuals' correlation is told beyond the overlap of the longest run's windows
        let (mut longest, mut counted) = (0, 1.0);
        for frame in frames {
            // the regression's own rows: the weak or integral form's windows, else the samples (in
            // blocks, as the fit took them: no column of a long run held whole)
            let (y, e, weights) = match window {
                Some(w) => {
                    let Rows { y, columns, weights, window: taken, .. } =
                        self.windows(&library, target, frame, w)?;
                    // (the last of the longest, as before)
                    if frame.len() >= longest {
                        (longest, counted) = (frame.len(), crate::data::row_overlap(taken));
                    }
                    let mut e: Vec<f64> = y.iter().map(|y| y - b0).collect();
                    for (t, column) in selection.terms.iter().zip(&columns) {
                        for (e, x) in e.iter_mut().zip(column) {
                            *e -= t.coefficient * x;
                        }
                    }
                    (y, e, weights)
                }
                None => {
                    let frame = self.as_rates_see_it(&library, target, frame)?;
                    let run = self.bind(&library, target, &frame)?;
                    let mut e: Vec<f64> = run.y.iter().map(|y| y - b0).collect();
                    library.for_each_block(&run.sources, 0..frame.len(), |start, columns| {
                        for (t, column) in selection.terms.iter().zip(columns) {
                            for (e, x) in e[start..].iter_mut().zip(*column) {
                                *e -= t.coefficient * x;
                            }
                        }
                    });
                    (run.y, e, run.weights.map(<[f64]>::to_vec))
                }
            };
            // each row as the fit weighed it
            let scale = |k: usize| weights.as_ref().map_or(1.0, |w| w[k].sqrt());
            sized.extend(e.iter().enumerate().map(|(k, e)| ((y[k] - e).abs(), scale(k) * e)));
            residuals.push(e);
        }
        fit.correlation_time = if self.weights.is_some() {
            None
        } else {
            crate::uncertainty::correlation_time(&residuals).map(|t| (t / counted).max(1.0))
        };
        fit.residual_growth = growth(&mut sized);
        Ok(())
    }
}

/// A run's rows as the regression takes them: the target, each candidate's column, and the
/// rows' weights where they are weighted.
struct Rows {
    y: Vec<f64>,
    columns: Vec<Vec<f64>>,
    weights: Option<Vec<f64>>,
    /// The sample each window starts from (windows holding a switch are left out).
    starts: Vec<usize>,
    /// The windows the run took ([`run_window`]).
    window: crate::data::Window,
}

impl Rows {
    /// The rows whose window has one ending before it starts, each candidate as those windows
    /// predict it ([`crate::data::first_stage`]): what the regression fits where the
    /// candidates are instrumented (the residuals are still the rows' own).
    fn instrumented(self) -> Rows {
        let (has, predicted) =
            crate::data::first_stage(&self.columns, &self.starts, self.window.intervals + 1);
        fn kept<T>(v: Vec<T>, has: &[bool]) -> Vec<T> {
            v.into_iter().zip(has).filter(|(_, h)| **h).map(|(x, _)| x).collect()
        }
        Rows {
            y: kept(self.y, &has),
            columns: predicted,
            weights: self.weights.map(|w| kept(w, &has)),
            starts: kept(self.starts, &has),
            window: self.window,
        }
    }
}

/// How the residuals grow with the fit's size: the root mean square of the residuals in the
/// quarter of rows where |fitted| is largest over that in the quarter where it is smallest,
/// from (|fitted|, residual) pairs; `None` below 40 rows, where the small rows fit exactly, or
/// where the residuals are below [`GROWTH_FLOOR`] of the fitted values.
fn growth(sized: &mut [(f64, f64)]) -> Option<f64> {
    let n = sized.len();
    if n < 40 {
        return None;
    }
    sized.sort_by(|a, b| a.0.total_cmp(&b.0));
    // root mean square of the residuals (or, `fitted`, of the fitted values) over rows
    let rms = |rows: &[(f64, f64)], fitted: bool| {
        let sq: f64 = rows.iter().map(|(f, e)| if fitted { f * f } else { e * e }).sum();
        (sq / rows.len() as f64).sqrt()
    };
    let (small, large) = (rms(&sized[..n / 4], false), rms(&sized[n - n / 4..], false));
    (small > 0.0 && rms(sized, false) > GROWTH_FLOOR * rms(sized, true)).then(|| large / small)
}

/// Residuals below this fraction of the fitted values (root mean square) are not worth
/// weighing: weights move a coefficient by about the residuals' relative size (times the
/// design's conditioning), so below a ten-thousandth nothing a report prints would change.
/// Clean records fit to 1e-5 relative leave just such residuals, and they may grow with the
/// signal all the same (an integrator's relative tolerance: a damped oscillator solved to
/// 1e-11 and differenced centrally read 27 times larger at the peaks).
const GROWTH_FLOOR: f64 = 1e-4;

/// One equation fitted from its runs' statistics: merged for the selection ("Komb. Daten"),
/// each run's kept for the back-ends that cross-validate over runs.
pub(crate) fn fit_folds(
    target: &str,
    names: &[String],
    forced: &[usize],
    excluded: &[usize],
    intercept: bool,
    folds: &[Moments],
    backend: &dyn Selector,
) -> Result<Fit, IdentifyError> {
    let (moments, mut selection) = select_folds(names, forced, excluded, intercept, folds, backend)?;
    let problem = Problem { moments: &moments, names, forced, excluded, intercept };
    let covariance = covariance_of(&moments, &selection);
    if let Some(note) = collinearity_note(&moments, names, &selection) {
        selection.notes.push(note);
    }
    selection.notes.extend(invariant::exact_note(&moments, names));
    let rivals = crate::select::rivals(&problem, &selection);
    // the residual pass for τ is left to the caller (`describe_residuals`): selection itself
    // needs only the sufficient statistics, and is timed against the peers without it
    Ok(Fit {
        target: target.to_string(),
        candidates: names.to_vec(),
        selection,
        covariance,
        correlation_time: None,
        residual_growth: None,
        rivals,
    })
}

/// The runs' statistics an equation is selected from ([`Identification::fit_design`]).
struct Folds {
    /// The forced terms' columns.
    forced: Vec<usize>,
    /// The excluded terms' columns.
    excluded: Vec<usize>,
    /// Each run's moments.
    folds: Vec<Moments>,
}

/// The `folds` merged, and the back-end's selection from them (given the folds, for those that
/// cross-validate).
fn select_folds(
    names: &[String],
    forced: &[usize],
    excluded: &[usize],
    intercept: bool,
    folds: &[Moments],
    backend: &dyn Selector,
) -> Result<(Moments, Selection), IdentifyError> {
    let mut moments = Moments::new(names.len());
    for f in folds {
        moments.merge(f);
    }
    let problem = Problem { moments: &moments, names, forced, excluded, intercept };
    let selection = backend.select_with_folds(&problem, folds)?;
    Ok((moments, selection))
}

/// Wakes a sleeping worker where the rows of `frames` will be gathered in parallel, so that
/// it is looking for work by the time they are (waking it only then cost ~25 µs of a 0.1 ms
/// fit); a second call while it is awake costs a queued empty job.
fn wake_a_worker(frames: &[Frame], p: usize) {
    if crate::select::in_parallel(frames.iter().map(Frame::len).sum(), p) {
        rayon::spawn(|| {});
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Residuals a fixed fraction of the fitted values, on fitted values spread evenly in
    /// log from 1 to 1000: the quarters' root mean squares are 180 apart (by hand), measured
    /// at 1 %, not at 1e-5 (a clean record's integrator tolerance: no weight would change what
    /// is printed), nor below 40 rows.
    #[test]
    fn growth_is_measured_above_the_floor_only() {
        let rows = |relative: f64| -> Vec<(f64, f64)> {
            (0..400)
                .map(|k| {
                    let f = 10f64.powf(3.0 * k as f64 / 399.0);
                    (f, relative * f * if k % 2 == 0 { 1.0 } else { -1.0 })
                })
                .collect()
        };
        let g = growth(&mut rows(0.01)).unwrap();
        assert!((g - 180.15).abs() < 0.01, "{g}");
        assert_eq!(growth(&mut rows(1e-5)), None);
        assert_eq!(growth(&mut rows(0.01)[..39].to_vec()), None);
    }

    #[test]
    fn mean_over_the_first_seconds() {
        let mut f = Frame::new("run", "t", vec![0.0, 1.0, 2.0, 3.0, 4.0]).unwrap();
        f.push("u", vec![2.0, 2.2, 2.4, 1.0, 1.0]).unwrap();
        let v = ParamValue::Rule("mean:u:2".into()).resolve("u0", &f).unwrap();
        assert!((v - 2.2).abs() < 1e-15);
        assert!(ParamValue::Rule("mean:u:-1".into()).check_rule("u0").is_err());
        assert!(ParamValue::Rule("mean:u".into()).check_rule("u0").is_ok());
    }

    /// A relay's switches leave out exactly the windows that hold one (a window from sample s
    /// holds samples s..=s + w); only where the library reads the relay; and none where that
    /// would leave out more than half (a switch every 6 samples with windows of 8), said so.
    #[test]
    fn the_windows_that_hold_a_switch_are_left_out() {
        let n = 100;
        let mut vocab = Vocabulary::new();
        for v in ["t", "x", "F"] {
            vocab.variable(v).unwrap();
        }
        let frame = |switch_every: usize| {
            let mut f = Frame::new("relay.csv", "t", (0..n).map(|k| 0.1 * k as f64).collect()).unwrap();
            f.push("x", (0..n).map(|k| (0.1 * k as f64).sin()).collect()).unwrap();
            f.push(
                "F",
                (0..n).map(|k| if (k / switch_every).is_multiple_of(2) { 1.0 } else { -1.0 }).collect(),
            )
            .unwrap();
            f.switch("F").unwrap();
            f
        };
        let reads =
            Library::compile(&[vocab.parse("x").unwrap(), vocab.parse("F").unwrap()], &vocab).unwrap();
        let sparse = frame(40);
        let s = switched_windows(&sparse, &reads, 8).unwrap();
        let keep = s.keep.unwrap();
        // switches between samples 39/40 and 79/80: windows 32..=39 and 72..=79 hold them
        let left: Vec<usize> = (0..keep.len()).filter(|&k| !keep[k]).collect();
        assert_eq!(left, [(32..40).collect::<Vec<_>>(), (72..80).collect()].concat());
        assert_eq!((s.inputs, s.switches), (vec!["F"], 2));
        let blind = Library::compile(&[vocab.parse("x").unwrap()], &vocab).unwrap();
        assert!(switched_windows(&sparse, &blind, 8).is_none());
        let dense = frame(6);
        assert!(switched_windows(&dense, &reads, 8).unwrap().keep.is_none());
        let said = switched_note(&[dense], &reads, crate::data::Window::fallback()).unwrap();
        assert!(said.contains("too often to leave out") && said.contains("in 1 run(s)"), "{said}");
        let said = switched_note(&[sparse], &reads, crate::data::Window::fallback()).unwrap();
        assert!(
            said.contains("switched between samples 2 times") && said.contains("the 16 windows"),
            "{said}"
        );
    }

    /// ẋ = F with F held between samples: x is exact (a line between samples), and its central
    /// difference at sample i is (F[i−1] + F[i]) / 2, so the force read at that mean is fitted
    /// with coefficient 1 to rounding; read at F[i] (not marked held) it is not.
    #[test]
    fn a_held_input_is_read_as_a_centred_rate_sees_it() {
        let n = 200;
        let mut vocab = Vocabulary::new();
        for v in ["t", "x", "F"] {
            vocab.variable(v).unwrap();
        }
        // (still over the first and last three samples, where the stencils are one-sided)
        let force: Vec<f64> =
            (0..n).map(|k| k.clamp(2, n - 3) as f64).map(|k| (0.3 * k).sin() + 0.2 * (k % 7.0)).collect();
        let x: Vec<f64> = std::iter::once(0.0)
            .chain(force.iter().scan(0.0, |x, f| {
                *x += 0.1 * f;
                Some(*x)
            }))
            .collect();
        let run = |held: bool| {
            let mut f = Frame::new("rig.csv", "t", (0..n).map(|k| 0.1 * k as f64).collect()).unwrap();
            f.push("x", x[..n].to_vec()).unwrap();
            f.push("F", force.clone()).unwrap();
            if held {
                f.hold("F").unwrap();
            }
            f
        };
        let (params, central) = (BTreeMap::new(), crate::data::CentralDifference);
        let id = Identification {
            vocabulary: &vocab,
            parameters: &params,
            differentiator: &central,
            intercept: false,
            weights: None,
        };
        let terms = [vocab.parse("F").unwrap()];
        let coefficient = |held: bool| {
            let fit = id
                .fit(
                    &Target::Derivative("x".into()),
                    &terms,
                    &[],
                    &[],
                    &[run(held)],
                    &crate::select::Stepwise::default(),
                )
                .unwrap();
            fit.selection.terms[0].coefficient
        };
        assert!((coefficient(true) - 1.0).abs() < 1e-12, "{}", coefficient(true));
        assert!((coefficient(false) - 1.0).abs() > 0.01, "{}", coefficient(false));
    }

    /// A term that is not finite on some row is refused with the run, the row and the term,
    /// wherever in the run (and in whichever part of it, when gathered in parallel) it is.
    #[test]
    fn a_term_that_is_not_finite_names_run_row_and_term() {
        let n = 1000;
        let t: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let mut vocab = Vocabulary::new();
        for v in ["t", "x", "y"] {
            vocab.variable(v).unwrap();
        }
        let terms = vec![vocab.parse("x").unwrap(), vocab.parse("y/x").unwrap()];
        let params = BTreeMap::new();
        let central = crate::data::CentralDifference;
        let id = Identification {
            vocabulary: &vocab,
            parameters: &params,
            differentiator: &central,
            intercept: true,
            weights: None,
        };
        for zero_at in [0usize, 3, 700, 999] {
            let x: Vec<f64> = (0..n).map(|i| if i == zero_at { 0.0 } else { 1.0 + i as f64 }).collect();
            let mut f = Frame::new("run7.csv", "t", t.clone()).unwrap();
            f.push("x", x).unwrap();
            f.push("y", t.iter().map(|t| t.sin() + 2.0).collect()).unwrap();
            let err = id
                .fit(&Target::Column("y".into()), &terms, &[], &[], &[f], &crate::select::Stepwise::default())
                .unwrap_err();
            match err {
                IdentifyError::NonFinite { file, row, term, value, target: false } => {
                    assert_eq!((file.as_str(), row, term.as_str()), ("run7.csv", zero_at + 1, "y/x"));
                    assert!(value.is_infinite());
                }
                e => panic!("{e}"),
            }
            // in the weak form, the row the first window holding it starts on
            let weak = crate::data::WeakForm::default();
            let id = Identification {
                vocabulary: &vocab,
                parameters: &params,
                differentiator: &weak,
                intercept: true,
                weights: None,
            };
            let mut f = Frame::new("run7.csv", "t", t.clone()).unwrap();
            f.push("x", (0..n).map(|i| if i == zero_at { 0.0 } else { 1.0 + i as f64 }).collect()).unwrap();
            f.push("y", t.iter().map(|t| t.sin() + 2.0).collect()).unwrap();
            let err = id
                .fit(
                    &Target::Derivative("y".into()),
                    &terms,
                    &[],
                    &[],
                    &[f],
                    &crate::select::Stepwise::default(),
                )
                .unwrap_err();
            match err {
                IdentifyError::NonFinite { file, row, term, target: false, .. } => {
                    assert_eq!((file.as_str(), term.as_str()), ("run7.csv", "y/x"));
                    assert!(row <= zero_at + 1 && row + 32 > zero_at, "{row} for {zero_at}");
                }
                e => panic!("{e}"),
            }
        }
    }

    /// The covariance's diagonal is the standard errors STPRG reports (its own formula, A12),
    /// with and without an intercept; off-diagonals are those of (X'X)⁻¹ from a direct solve.
    #[test]
    fn covariance_matches_the_reported_standard_errors() {
        use crate::select::{StepRule, Stepwise};
        let n = 60;
        let t: Vec<f64> = (0..n).map(f64::from).collect();
        let x1: Vec<f64> = t.iter().map(|t| (0.3 * t).sin() + 0.05 * t).collect();
        let x2: Vec<f64> = t.iter().map(|t| (0.17 * t).cos() * 2.0).collect();
        let y: Vec<f64> = (0..n as usize)
            .map(|i| 1.5 + 2.0 * x1[i] - 0.7 * x2[i] + 0.1 * ((i * 7919) % 13) as f64 / 13.0)
            .collect();
        let mut f = Frame::new("run", "t", t).unwrap();
        f.push("x1", x1.clone()).unwrap();
        f.push("x2", x2.clone()).unwrap();
        f.push("y", y.clone()).unwrap();
        let mut vocab = Vocabulary::new();
        for v in ["t", "x1", "x2", "y"] {
            vocab.variable(v).unwrap();
        }
        let terms = vec![vocab.parse("x1").unwrap(), vocab.parse("x2").unwrap()];
        let stepwise = Stepwise { step_rule: StepRule::Last, ..Stepwise::default() };
        let central = crate::data::CentralDifference;
        for intercept in [true, false] {
            let params = BTreeMap::new();
            let id = Identification {
                vocabulary: &vocab,
                parameters: &params,
                differentiator: &central,
                intercept,
                weights: None,
            };
            let fit = id.fit(&Target::Column("y".into()), &terms, &[], &[], &[f.clone()], &stepwise).unwrap();
            let cov = fit.covariance.as_ref().expect("a covariance");
            for (i, term) in fit.selection.terms.iter().enumerate() {
                let se = cov[i][i].sqrt();
                assert!(
                    (se / term.std_error - 1.0).abs() < 1e-9,
                    "{}: {se} vs {}",
                    term.term,
                    term.std_error
                );
            }
            // off-diagonal: s²(X'X)⁻¹ directly, columns in the order the terms entered
            let cols: Vec<&Vec<f64>> =
                fit.selection.terms.iter().map(|t| if t.term == "x1" { &x1 } else { &x2 }).collect();
            let width = cols.len() + usize::from(intercept);
            let x = nalgebra::DMatrix::from_fn(n as usize, width, |r, c| {
                if intercept && c == 0 {
                    1.0
                } else {
                    cols[c - usize::from(intercept)][r]
                }
            });
            let xtx_inv = (x.transpose() * &x).try_inverse().unwrap();
            let b = &xtx_inv * x.transpose() * nalgebra::DVector::from_vec(y.clone());
            let resid = nalgebra::DVector::from_vec(y.clone()) - &x * &b;
            let s2 = resid.norm_squared() / (n as f64 - width as f64);
            let o = usize::from(intercept);
            assert!(
                (cov[0][1] / (s2 * xtx_inv[(o, o + 1)]) - 1.0).abs() < 1e-8,
                "{} vs {}",
                cov[0][1],
                s2 * xtx_inv[(o, o + 1)]
            );
        }
    }

    #[test]
    fn target_syntax() {
        assert_eq!(Target::parse("dr/dt"), Target::Derivative("r".into()));
        assert_eq!(Target::parse("r_dot"), Target::Column("r_dot".into()));
        assert_eq!(Target::parse("d/dt"), Target::Column("d/dt".into()));
    }
}
