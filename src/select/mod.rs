//! Term selection: regression back-ends that choose which candidate terms enter an equation
//! and fit their coefficients. Every back-end works on the same sufficient statistics
//! ([`Moments`]) and implements [`Selector`]; [`Backend`] picks one by name for the CLI and
//! model files. A new back-end is one new file and one row in [`Backend`].

#[macro_use]
mod registry;
mod best_subset;
mod efroymson;
#[doc(hidden)]
pub mod gram;
mod moments;
mod rivals;
mod sparse;
pub(crate) mod stepwise;
mod stlsq;
mod subset;

use serde::{Deserialize, Serialize};

pub use best_subset::{BestSubset, Criterion, Sizes};
pub use efroymson::Efroymson;
pub use moments::{gather, gather_halved, in_parallel, Accumulator, Moments, Split};
pub use rivals::{rivals, Rival};
pub use sparse::{Candidate, Equality, LambdaChoice, SparseFit};
pub use stepwise::{StepRule, Stepwise};
pub use stlsq::Stlsq;
pub(crate) use subset::{chi_square_pvalue, sweep};

/// What a back-end is asked to do.
#[derive(Clone, Copy, Debug)]
pub struct Problem<'a> {
    /// Statistics of the candidates (columns 0..p) and the target (column p).
    pub moments: &'a Moments,
    /// Candidate names, aligned with the columns.
    pub names: &'a [String],
    /// Columns that always enter (first, for physical reasons).
    pub forced: &'a [usize],
    /// Columns that never enter.
    pub excluded: &'a [usize],
    /// Fit an intercept b0 (the paper does).
    pub intercept: bool,
}

/// A coefficient with its standard error and t-value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Its standard error.
    pub std_error: f64,
    /// value / std_error.
    pub t: f64,
}

/// A term in a fitted equation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FittedTerm {
    /// The term's canonical text.
    pub term: String,
    /// Its candidate column.
    pub index: usize,
    /// The coefficient.
    pub coefficient: f64,
    /// Standard error of the coefficient.
    pub std_error: f64,
    /// t-value.
    pub t: f64,
}

/// One step of a stepwise regression (Oltmann 1973, App. A, eqs. A2-A14).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Step {
    /// 1-based step number = number of terms in.
    pub step: usize,
    /// The term entered.
    pub term: String,
    /// Its candidate column.
    pub index: usize,
    /// Entered because forced.
    pub forced: bool,
    /// Its sum-of-squares reduction S_i (A2).
    pub reduction: f64,
    /// Its share of the total sum of squares, S_i / D (A3).
    pub proportion: f64,
    /// Cumulative share P_cum (A5) = R².
    pub r2: f64,
    /// Multiple correlation R (A6).
    pub r: f64,
    /// Adjusted multiple correlation R_c.
    pub r_adjusted: f64,
    /// Standard error of estimate s (A7).
    pub standard_error: f64,
    /// Adjusted standard error s_c.
    pub standard_error_adjusted: f64,
    /// F-value (A8); infinite at an exact fit.
    pub f: f64,
    /// Whether this step removed `term` (Efroymson) rather than entering it.
    #[serde(default)]
    pub removed: bool,
    /// The candidate columns in the equation after this step, aligned with `coefficients`.
    pub set: Vec<usize>,
    /// Coefficients of the terms in `set` (A11). [`Selection::terms_at`] pairs them with
    /// names, standard errors and t.
    pub coefficients: Vec<f64>,
    /// Standard errors of those coefficients (A13).
    pub std_errors: Vec<f64>,
    /// Intercept b0 (A12), if fitted.
    pub intercept: Option<Estimate>,
}

/// Why a selection stopped adding terms.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum Stop {
    /// Every allowed candidate is in (or refused).
    AllEntered,
    /// No candidate could enter at all: every one excluded, or refused as constant or
    /// collinear.
    NoCandidate,
    /// The most steps the settings allow (`max_steps`) were taken.
    StepLimit {
        /// The limit.
        steps: usize,
    },
    /// The next term's share of the total fell below the user's constant.
    BelowThreshold {
        /// The term that would have entered next.
        term: String,
        /// Its share.
        proportion: f64,
        /// The constant.
        threshold: f64,
    },
    /// The residual is zero to round-off: later steps would be chosen by round-off.
    ExactFit {
        /// Residual share 1 − R² at the stop.
        residual_share: f64,
    },
    /// No degrees of freedom left for another term.
    NoDegreesOfFreedom,
    /// The back-end finished by its own rule.
    Converged,
    /// A search hit its node or time limit: the result is the best found, not proven best.
    Limit {
        /// Nodes searched.
        nodes: u64,
    },
}

impl std::fmt::Display for Stop {
    /// Why the stepping ended, in words (the chosen step may be an earlier one).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stop::AllEntered => write!(f, "every candidate had entered"),
            Stop::NoCandidate => write!(f, "no candidate could enter: every one was excluded, or refused as constant or collinear"),
            Stop::StepLimit { steps } => write!(f, "the step limit (max_steps = {steps}) was reached"),
            Stop::BelowThreshold { term, proportion, threshold } => write!(
                f,
                "the next term, {term}, would explain {:.3} % of the variance, below the threshold of {:.3} %",
                100.0 * proportion,
                100.0 * threshold
            ),
            Stop::ExactFit { residual_share } => {
                write!(f, "the fit is exact to round-off (1 − R² = {})", round_off_share(*residual_share))
            }
            Stop::NoDegreesOfFreedom => write!(f, "no degrees of freedom were left for another term"),
            Stop::Converged => write!(f, "the back-end's own rule ended it"),
            Stop::Limit { nodes } => write!(f, "the search hit its limit after {nodes} nodes: best found, not proven best"),
        }
    }
}

/// What a back-end returns: the chosen equation plus everything a report needs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Selection {
    /// Back-end name.
    pub backend: String,
    /// Rows used.
    pub rows: usize,
    /// The candidates' names by column.
    pub candidates: Vec<String>,
    /// Every step taken (empty for back-ends without steps).
    pub steps: Vec<Step>,
    /// The chosen step (1-based; 0 if nothing entered).
    pub chosen_step: usize,
    /// The terms of the chosen equation, in order of entry.
    pub terms: Vec<FittedTerm>,
    /// The intercept of the chosen equation.
    pub intercept: Option<Estimate>,
    /// Why stepping stopped.
    pub stop: Stop,
    /// Things the user should know (refused collinear terms, round-off stops, …).
    pub notes: Vec<String>,
}

impl Selection {
    /// A selection reporting step `chosen` (1-based; 0 for none) of `steps`: its terms and
    /// intercept become the equation.
    pub fn from_steps(
        backend: &str,
        rows: usize,
        candidates: &[String],
        steps: Vec<Step>,
        chosen: usize,
        stop: Stop,
        notes: Vec<String>,
    ) -> Selection {
        let intercept = chosen.checked_sub(1).and_then(|c| steps.get(c)).and_then(|s| s.intercept.clone());
        let mut selection = Selection {
            backend: backend.into(),
            rows,
            candidates: candidates.to_vec(),
            steps,
            chosen_step: chosen,
            terms: vec![],
            intercept,
            stop,
            notes,
        };
        selection.terms = selection.terms_at(chosen);
        selection
    }

    /// The chosen step's R² (the share of the target's variance its terms explain); `None`
    /// where no term was chosen.
    pub fn chosen_r2(&self) -> Option<f64> {
        self.chosen_step.checked_sub(1).and_then(|k| self.steps.get(k)).map(|s| s.r2)
    }

    /// The fitted terms after step `k` (1-based).
    pub fn terms_at(&self, k: usize) -> Vec<FittedTerm> {
        let Some(step) = k.checked_sub(1).and_then(|i| self.steps.get(i)) else { return vec![] };
        step.set
            .iter()
            .zip(step.coefficients.iter().zip(&step.std_errors))
            .map(|(&index, (&coefficient, &std_error))| FittedTerm {
                term: self.candidates[index].clone(),
                index,
                coefficient,
                std_error,
                t: coefficient / std_error,
            })
            .collect()
    }
}

/// Why a back-end failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SelectError {
    /// Fewer rows than the fit needs.
    #[error("{rows} rows cannot determine {terms} terms{}", if *.intercept { " and an intercept" } else { "" })]
    TooFewRows {
        /// Rows.
        rows: usize,
        /// Terms asked for.
        terms: usize,
        /// Whether an intercept is fitted too.
        intercept: bool,
    },
    /// The target does not vary.
    #[error("the target has no variance: there is nothing to explain")]
    NoVariance,
    /// A forced term is collinear with those before it.
    #[error("forced term `{term}` is collinear with the terms already in (pivot {pivot:e} ≤ tolerance {tolerance:e})")]
    ForcedCollinear {
        /// The term.
        term: String,
        /// Its pivot (share of its variance not explained by the terms in).
        pivot: f64,
        /// The tolerance.
        tolerance: f64,
    },
    /// Settings out of range.
    #[error("invalid setting: {0}")]
    Config(String),
    /// The QP solver (Clarabel) ended with a status other than Solved.
    #[error("the sparse fit's QP solver stopped with status {status:?}")]
    Solver {
        /// Clarabel's status.
        status: clarabel::solver::SolverStatus,
    },
    /// The sparse fit's constraints admit no coefficients.
    #[error("the sparse fit's constraints conflict: no coefficients satisfy {constraints} together (with the forced terms and the target's scale); drop or loosen one")]
    Infeasible {
        /// The constraints, as a person reads them.
        constraints: String,
    },
    /// Index out of range or names not matching the statistics.
    #[error("problem does not fit together: {0}")]
    Shape(String),
}

impl Problem<'_> {
    /// Checks indices and sizes before any back-end runs.
    pub fn validate(&self) -> Result<(), SelectError> {
        let p = self.moments.regressors();
        if self.names.len() != p {
            return Err(SelectError::Shape(format!("{} names for {p} columns", self.names.len())));
        }
        if let Some(&i) = self.forced.iter().chain(self.excluded).find(|&&i| i >= p) {
            return Err(SelectError::Shape(format!("term index {i} ≥ {p} candidates")));
        }
        if let Some(&i) = self.forced.iter().find(|i| self.excluded.contains(i)) {
            return Err(SelectError::Shape(format!("`{}` is both forced and excluded", self.names[i])));
        }
        let needed = self.forced.len() + usize::from(self.intercept) + 1;
        if self.moments.count() < needed.max(2) {
            return Err(SelectError::TooFewRows {
                rows: self.moments.count(),
                terms: self.forced.len().max(1),
                intercept: self.intercept,
            });
        }
        Ok(())
    }
}

/// A term-selection back-end.
pub trait Selector: Send + Sync {
    /// Stable name used in model files, on the CLI (`--backend stepwise`) and in reports.
    fn name(&self) -> &'static str;
    /// Chooses terms and fits their coefficients.
    fn select(&self, problem: &Problem<'_>) -> Result<Selection, SelectError>;
    /// The same with the statistics of each run (folds) for cross-validation; back-ends that
    /// do not cross-validate ignore them.
    fn select_with_folds(&self, problem: &Problem<'_>, _folds: &[Moments]) -> Result<Selection, SelectError> {
        self.select(problem)
    }
}

/// Leave-one-run-out squared prediction error of the least-squares fit on `set`: each run
/// predicted by the fit on all the others, from sufficient statistics alone.
pub fn cross_validation_error(
    problem: &Problem<'_>,
    folds: &[Moments],
    set: &[usize],
) -> Result<f64, SelectError> {
    Ok(CrossValidation::new(problem, folds)?.error(set))
}

/// Leave-one-run-out cross-validation of many subsets on the same runs: the statistics of
/// all runs but one are formed once per run, and each subset's fit on them is a k × k solve.
pub struct CrossValidation<'a> {
    folds: &'a [Moments],
    /// Per fold, the statistics of the other runs.
    rest: Vec<Moments>,
    intercept: bool,
}

impl<'a> CrossValidation<'a> {
    /// Prepares the folds; at least two are needed.
    pub fn new(problem: &Problem<'_>, folds: &'a [Moments]) -> Result<CrossValidation<'a>, SelectError> {
        if folds.len() < 2 {
            return Err(SelectError::Config(format!(
                "cross-validation needs at least two runs, has {}",
                folds.len()
            )));
        }
        let rest = folds.iter().map(|f| problem.moments.without(f)).collect();
        Ok(CrossValidation { folds, rest, intercept: problem.intercept })
    }

    /// The summed squared error of each run predicted by the least-squares fit on `set` over
    /// the others; ∞ when the set is collinear on some training part (a pivot of its
    /// correlation matrix at most 1e-12, as the sweeps refuse).
    pub fn error(&self, set: &[usize]) -> f64 {
        let k = set.len();
        let mut total = 0.0;
        let mut l = vec![0.0; k * k];
        let mut b = vec![0.0; k];
        for (fold, train) in self.folds.iter().zip(&self.rest) {
            let p = train.regressors();
            let cross =
                |i: usize, j: usize| if self.intercept { train.corrected(i, j) } else { train.raw(i, j) };
            let d: Vec<f64> = set.iter().map(|&j| cross(j, j).max(0.0).sqrt()).collect();
            if d.contains(&0.0) {
                return f64::INFINITY;
            }
            // Cholesky of the correlation matrix R = LLᵀ, then L Lᵀ b' = r_y, b = b'/d
            for c in 0..k {
                for r in c..k {
                    let mut v = cross(set[r], set[c]) / (d[r] * d[c]);
                    for q in 0..c {
                        v -= l[r * k + q] * l[c * k + q];
                    }
                    if r == c {
                        if v.is_nan() || v <= 1e-12 {
                            return f64::INFINITY;
                        }
                        l[c * k + c] = v.sqrt();
                    } else {
                        l[r * k + c] = v / l[c * k + c];
                    }
                }
            }
            for r in 0..k {
                let mut v = cross(set[r], p) / d[r];
                for q in 0..r {
                    v -= l[r * k + q] * b[q];
                }
                b[r] = v / l[r * k + r];
            }
            for r in (0..k).rev() {
                let mut v = b[r];
                for q in r + 1..k {
                    v -= l[q * k + r] * b[q];
                }
                b[r] = v / l[r * k + r];
            }
            let coefficients: Vec<f64> = b.iter().zip(&d).map(|(b, d)| b / d).collect();
            let means = train.means();
            let b0 = if self.intercept {
                means[p] - set.iter().zip(&coefficients).map(|(&j, bj)| bj * means[j]).sum::<f64>()
            } else {
                0.0
            };
            total += fold.squared_error(set, &coefficients, b0);
        }
        total
    }
}

// The registry of back-ends: one line each (variant, settings type, name and aliases). It
// makes `Backend` (a model file's `backend` table, tagged by `method`), `BackendName` (the
// command line's `--backend`) and their names, checks and builders (see `registry.rs`).
back_ends! {
    /// The IBM SSP forward stepwise regression (STPRG) the paper used.
    Stepwise(Stepwise) = "stepwise" | "stprg";
    /// Efroymson's stepwise with F-to-enter and F-to-remove (MATLAB `stepwisefit`).
    Efroymson(Efroymson) = "efroymson";
    /// Exact best subset by branch and bound, size by a criterion.
    BestSubset(BestSubset) = "best-subset";
    /// LASSO path (Clarabel QP) with least-squares refit and constraints.
    Sparse(SparseFit) = "sparse";
    /// Sequentially thresholded least squares (SINDy's STLSQ).
    Stlsq(Stlsq) = "stlsq";
}

impl Default for Backend {
    fn default() -> Self {
        Backend::Stepwise(Stepwise::default())
    }
}

impl Backend {
    /// The back-end an equation of motion takes where none is named (a model file's equation,
    /// a rate on the command line or in Python): sequential thresholding, which a benchmark of
    /// 37 published systems chose (`benches/odes/`); the paper's stepwise regression with its
    /// first F maximum drops true terms once the first explains most of the variance (a
    /// forced Duffing oscillator: its force, coefficient 1, left out at R² 0.80 against 0.82).
    pub fn for_rates() -> Backend {
        Backend::Stlsq(Stlsq::default())
    }

    /// The back-end as a fit that is only simulated needs it (a fold of a choice by
    /// prediction): the same chosen terms, without proving what only a report reads (best
    /// subset's other sizes).
    pub fn for_prediction(&self) -> Backend {
        match self {
            Backend::BestSubset(b) => Backend::BestSubset(BestSubset { sizes: Sizes::Chosen, ..b.clone() }),
            other => other.clone(),
        }
    }
}

/// The unexplained share 1 − R² of an exact fit as one text wherever it is reported: below
/// 1e-15 it is round-off, of either sign, and reads so.
pub(crate) fn round_off_share(share: f64) -> String {
    if share.abs() < 1e-15 {
        "0 to round-off".into()
    } else {
        format!("{share:.1e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_through_the_registry() {
        for name in Backend::NAMES {
            let backend = Backend::by_name(name).unwrap();
            assert_eq!(backend.name(), *name);
            assert_eq!(backend.build().name(), *name);
            // a model file's `method` is the same name
            let table: toml::Value = toml::Value::try_from(&backend).unwrap();
            assert_eq!(table.get("method").and_then(|m| m.as_str()), Some(*name));
        }
    }
}
