//! Sparse fit: the LASSO as a quadratic program solved by Clarabel, on the cross-products in
//! correlation scale (β = standardised coefficients, R the candidates' correlations, r their
//! correlation with the target):
//!
//!   minimise ½ βᵀRβ − rᵀβ + λ Σ wⱼ tⱼ   subject to −tⱼ ≤ βⱼ ≤ tⱼ
//!
//! (bound variables t ≥ |β| rather than the split β = p − n). Over a λ path from λ_max down,
//! each support is refitted by least squares and λ chosen by BIC on the refit; both the
//! shrunk and the refitted coefficients are reported. Being a QP, it takes what the peers'
//! users ask for and rarely get: coefficients fixed to a value, sign constraints, and linear
//! equalities between coefficients. Forced terms carry no penalty. Every solver status but
//! `Solved` is an error.

use serde::{Deserialize, Serialize};

mod constraints;
mod qp;

pub use constraints::{Candidate, Equality};

use super::subset::Scaled;
use super::{Moments, Problem, SelectError, Selection, Selector, Step, Stop};

/// The longest λ path: each λ is a QP, and a path beyond this tells no more.
pub const MAX_PATH: usize = 10_000;

/// How λ is chosen on the path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum LambdaChoice {
    /// BIC of the least-squares refit.
    #[default]
    Bic,
    /// Leave-one-run-out prediction error of the refit (needs two runs or more).
    LeaveOneRunOut,
}

/// Settings.
///
/// | setting | default | meaning |
/// |---|---|---|
/// | `choice` | `bic` | how λ is chosen: `bic` or `leave-one-run-out` |
/// | `path` | 40 | number of λ on the path, log-spaced from λ_max to λ_max·`lambda_ratio` |
/// | `lambda_ratio` | 1e-5 | smallest λ over λ_max |
/// | `lambda` | none | a single λ instead of the path (standardised units) |
/// | `adaptive` | false | weights 1/\|β_ols\| (adaptive LASSO, Zou 2006) |
/// | `fixed` | none | (term, value): coefficient fixed, raw units |
/// | `signs` | none | (term, +1 or −1): coefficient ≥ 0 or ≤ 0 |
/// | `equalities` | none | linear equalities between coefficients |
/// | `support_tolerance` | 1e-6 | \|β\| below this (standardised) is zero |
/// | `active_set` | true | a plain-LASSO λ is first solved from its optimality conditions (active set and signs from the neighbouring λ, updated while they fail; accepted only when all hold, so exact), Clarabel where that fails and for every constrained fit; false: Clarabel at every λ |
/// | `verbose` | false | let Clarabel print its iterations |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SparseFit {
    /// How λ is chosen.
    pub choice: LambdaChoice,
    /// λ values on the path.
    pub path: usize,
    /// λ_min / λ_max.
    pub lambda_ratio: f64,
    /// One λ instead of a path.
    pub lambda: Option<f64>,
    /// Adaptive weights.
    pub adaptive: bool,
    /// Fixed coefficients (term, raw value).
    pub fixed: Vec<(Candidate, f64)>,
    /// Sign constraints (term, ±1).
    pub signs: Vec<(Candidate, f64)>,
    /// Linear equalities.
    pub equalities: Vec<Equality>,
    /// Zero threshold for a standardised coefficient.
    pub support_tolerance: f64,
    /// Solve plain-LASSO λ from their optimality conditions where they can be verified.
    pub active_set: bool,
    /// Solver output.
    pub verbose: bool,
}

impl Default for SparseFit {
    fn default() -> Self {
        SparseFit {
            choice: LambdaChoice::Bic,
            path: 40,
            lambda_ratio: 1e-5,
            lambda: None,
            adaptive: false,
            fixed: vec![],
            signs: vec![],
            equalities: vec![],
            support_tolerance: 1e-6,
            active_set: true,
            verbose: false,
        }
    }
}

impl SparseFit {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), SelectError> {
        if self.path == 0 || self.path > MAX_PATH {
            return Err(SelectError::Config(format!(
                "sparse path = {} : the λ path takes 1 to {MAX_PATH} values (40 is the default; beyond a few hundred, neighbouring λ give the same terms)",
                self.path
            )));
        }
        if !(self.lambda_ratio > 0.0 && self.lambda_ratio < 1.0) {
            return Err(SelectError::Config(format!(
                "sparse lambda_ratio = {}: it must lie strictly between 0 and 1",
                self.lambda_ratio
            )));
        }
        if let Some(l) = self.lambda.filter(|l| !(l.is_finite() && *l >= 0.0)) {
            return Err(SelectError::Config(format!(
                "sparse lambda = {l}: it must be a finite number ≥ 0 (in standardised units, where λ ≥ 1 keeps no term)"
            )));
        }
        if !(self.support_tolerance.is_finite() && self.support_tolerance >= 0.0) {
            return Err(SelectError::Config("sparse support_tolerance must be a finite number ≥ 0".into()));
        }
        if self.signs.iter().any(|s| s.1.abs() != 1.0) {
            return Err(SelectError::Config("sparse signs must be +1 or −1".into()));
        }
        let values = self.fixed.iter().map(|f| f.1).chain(
            self.equalities.iter().flat_map(|e| e.terms.iter().map(|t| t.1).chain(std::iter::once(e.value))),
        );
        if values.into_iter().any(|v| !v.is_finite()) {
            return Err(SelectError::Config("sparse fixed values and equalities must be finite".into()));
        }
        Ok(())
    }

    /// The LASSO solution at one λ, standardised coefficients (one per candidate).
    pub fn lasso(&self, pb: &Problem<'_>, lambda: f64) -> Result<Vec<f64>, SelectError> {
        self.validate()?;
        let c = self.columns(pb)?;
        let sc = Scaled::new(pb)?;
        let w = self.weights(&sc, pb)?;
        let all: Vec<usize> = (0..sc.p).filter(|j| !pb.excluded.contains(j)).collect();
        self.solve(&sc, lambda, &w, &all, &c)
    }
}

impl Selector for SparseFit {
    fn name(&self) -> &'static str {
        "sparse"
    }

    fn select(&self, pb: &Problem<'_>) -> Result<Selection, SelectError> {
        self.path_fit(pb, &[])
    }

    fn select_with_folds(&self, pb: &Problem<'_>, folds: &[Moments]) -> Result<Selection, SelectError> {
        self.path_fit(pb, folds)
    }
}

impl SparseFit {
    fn path_fit(&self, pb: &Problem<'_>, folds: &[Moments]) -> Result<Selection, SelectError> {
        self.validate()?;
        let c = self.columns(pb)?;
        let sc = Scaled::new(pb)?;
        let (p, m) = (sc.p, sc.m);
        let w = self.weights(&sc, pb)?;
        let lambda_max = (0..p)
            .filter(|j| w[*j] > 0.0 && !pb.excluded.contains(j))
            .map(|j| sc.a[j * m + p].abs() / w[j])
            .fold(0.0f64, f64::max)
            .max(1e-12);
        let lambdas: Vec<f64> = match self.lambda {
            Some(l) => vec![l],
            None => (0..self.path)
                .map(|k| lambda_max * self.lambda_ratio.powf(k as f64 / (self.path.max(2) - 1) as f64))
                .collect(),
        };
        let n = sc.n as f64;
        let mut steps: Vec<Step> = Vec::new();
        let mut scores = Vec::new();
        let mut shrunk = Vec::new();
        let mut notes = Vec::new();
        let always = self.always_active(pb, &w, &c);
        let validation = match self.choice {
            LambdaChoice::LeaveOneRunOut => Some(super::CrossValidation::new(pb, folds)?),
            LambdaChoice::Bic => None,
        };
        // Two chains along the path, every other λ each, solved in parallel: each screens and
        // starts from its own previous λ (screening stays exact with the wider gap). The split
        // is fixed, so the result does not depend on the number of threads.
        let chain = |first: usize| {
            let mut previous = (lambda_max, vec![0.0; p]);
            let mut cache = None;
            let mut out = Vec::new();
            for &lambda in lambdas.iter().skip(first).step_by(2) {
                let beta = self.solve_screened(
                    &sc,
                    pb,
                    lambda,
                    (previous.0, &previous.1),
                    &w,
                    &always,
                    &mut cache,
                    &c,
                );
                let failed = beta.is_err();
                if let Ok(b) = &beta {
                    previous = (lambda, b.clone());
                }
                out.push(beta);
                if failed {
                    break;
                }
            }
            out.into_iter()
        };
        let (mut even, mut odd) = rayon::join(|| chain(0), || chain(1));
        for (i, &lambda) in lambdas.iter().enumerate() {
            let next = if i % 2 == 0 { even.next() } else { odd.next() };
            // a chain stops at its first failure, which the loop meets before any later λ
            let Some(beta) = next else { break };
            let beta = beta?;
            let mut support: Vec<usize> = (0..p)
                .filter(|&j| beta[j].abs() > self.support_tolerance || pb.forced.contains(&j))
                .collect();
            support.sort_unstable();
            if support.is_empty() || steps.last().is_some_and(|s| s.set == support) {
                continue;
            }
            if support.len() as f64 >= sc.n_eff {
                notes.push(format!("λ = {lambda:.3e} and below: more terms than rows allow; path ends"));
                break;
            }
            let Ok(a) = sc.swept(&support, 1e-12) else {
                notes.push(format!("λ = {lambda:.3e}: the support is collinear, refit skipped"));
                continue;
            };
            let newest = support
                .iter()
                .copied()
                .find(|j| !steps.last().is_some_and(|s| s.set.contains(j)))
                .unwrap_or(0);
            let mut st = sc.step(&a, &support, pb.names, newest, false, pb.forced.contains(&newest));
            st.step = steps.len() + 1;
            st.reduction = lambda; // the path's λ (standardised units), for the report
            let mut rss = sc.residual_share(&a);
            if !c.is_empty() {
                // the refit keeps the constraints: least squares on the support subject to
                // them (the QP at λ = 0), else a fixed coefficient would come back free
                rss = self.constrained_refit(&sc, &w, &support, &c, &mut st)?;
            }
            let rss = rss.max(1e-13); // exact fits: see best_subset
            let k = support.len() as f64 + if sc.intercept { 1.0 } else { 0.0 };
            scores.push(match self.choice {
                LambdaChoice::Bic => n * (rss * sc.total / n).ln() + k * n.ln(),
                LambdaChoice::LeaveOneRunOut => {
                    validation.as_ref().map_or(f64::INFINITY, |cv| cv.error(&support))
                }
            });
            shrunk.push(beta);
            steps.push(st);
        }
        if steps.is_empty()
            && !notes.iter().any(|n| n.contains("collinear") || n.contains("more terms than rows"))
        {
            return Err(SelectError::Config(format!(
                "no λ of the path keeps a term: the largest λ tried, {:.3e}, is at or above λ_max = {lambda_max:.3e} (standardised units), where every coefficient is zero{}",
                lambdas[0],
                if self.lambda.is_some() { "; give a smaller lambda, or none for the path" } else { "; give path ≥ 2 for a path from λ_max down" }
            )));
        }
        if steps.is_empty() {
            return Err(SelectError::Config(format!(
                "no λ of the path gave a set of terms that can be fitted: every support was collinear{} — leave out candidates that are multiples or sums of others (`termid identify --backend stepwise` lists which)",
                if notes.iter().any(|n| n.contains("more terms than rows")) { " or had more terms than rows" } else { "" }
            )));
        }
        let best = scores
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1).then(a.0.cmp(&b.0)))
            .map_or(0, |x| x.0);
        let chosen = best + 1;
        let shrunk_raw: Vec<String> = steps[best]
            .set
            .iter()
            .map(|&j| format!("{} {:.6e}", pb.names[j], shrunk[best][j] * sc.d[p] / sc.d[j]))
            .collect();
        notes.push(format!(
            "λ = {:.3e} chosen by {} of the least-squares refit; LASSO (shrunk) coefficients there: {}",
            steps[best].reduction,
            match self.choice {
                LambdaChoice::Bic => "BIC",
                LambdaChoice::LeaveOneRunOut => "leave-one-run-out error",
            },
            shrunk_raw.join(", ")
        ));
        Ok(Selection::from_steps(self.name(), sc.n, pb.names, steps, chosen, Stop::Converged, notes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::select::Accumulator;
    use constraints::Columns;

    /// Whenever the optimality conditions give an answer it is the QP's solution, from the
    /// neighbouring λ's solution and from far away (every column starting out); off, or with
    /// constraints, they give none.
    #[test]
    fn closed_form_is_the_qp_solution_or_declines() {
        let (n, p) = (400, 12);
        let mut seed = 5u64;
        let mut next = || crate::data::test_noise(&mut seed);
        let x: Vec<f64> = (0..n * p).map(|_| next()).collect();
        let y: Vec<f64> =
            (0..n).map(|i| 2.0 * x[i] - x[3 * n + i] + 0.5 * x[7 * n + i] + 0.05 * next()).collect();
        let m = Moments::of_columns(&x, &y, None);
        let names: Vec<String> = (0..p).map(|j| format!("x{j}")).collect();
        let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept: true };
        let fit = SparseFit::default();
        let sc = Scaled::new(&pb).unwrap();
        let w = fit.weights(&sc, &pb).unwrap();
        let all: Vec<usize> = (0..p).collect();
        let (mut hits, mut declined) = (0, 0);
        let mut lambda = 0.5;
        let none = Columns::default();
        let mut previous = fit.solve(&sc, lambda, &w, &all, &none).unwrap();
        while lambda > 1e-4 {
            lambda *= 0.8;
            let qp = fit.solve(&sc, lambda, &w, &all, &none).unwrap();
            for start in [previous.clone(), vec![0.0; p]] {
                match fit.closed_form(&sc, &pb, lambda, &start, &w, &none) {
                    Some(b) => {
                        hits += 1;
                        // the objective ½bᵀRb − cᵀb + λ‖b‖₁: the closed form (exact when it answers)
                        // is never worse than the interior-point solution, and agrees with it up to
                        // the QP's accuracy in the coefficients
                        let f = |b: &[f64]| {
                            let mut v = 0.0;
                            for i in 0..p {
                                v -= sc.a[i * sc.m + p] * b[i] - lambda * b[i].abs();
                                for j in 0..p {
                                    v += 0.5 * b[i] * sc.a[i * sc.m + j] * b[j];
                                }
                            }
                            v
                        };
                        assert!(f(&b) <= f(&qp) + 1e-14, "λ {lambda}: {} vs {}", f(&b), f(&qp));
                        for j in 0..p {
                            assert!((b[j] - qp[j]).abs() < 1e-5, "λ {lambda}: {j}: {} vs {}", b[j], qp[j]);
                        }
                    }
                    None => declined += 1,
                }
            }
            previous = qp;
        }
        assert!(hits > 20, "{hits} closed-form solutions, {declined} declined");
        // constraints the closed form does not know, or the setting off: always the QP
        let signed = SparseFit { signs: vec![(3.into(), -1.0)], ..SparseFit::default() };
        let c = signed.columns(&pb).unwrap();
        assert!(signed.closed_form(&sc, &pb, lambda, &previous, &w, &c).is_none());
        let qp_only = SparseFit { active_set: false, ..SparseFit::default() };
        assert!(qp_only.closed_form(&sc, &pb, lambda, &previous, &w, &none).is_none());
        // the whole path either way: the same selection
        for choice in [LambdaChoice::Bic, LambdaChoice::LeaveOneRunOut] {
            let fast = SparseFit { choice, ..SparseFit::default() };
            let slow = SparseFit { choice, active_set: false, ..SparseFit::default() };
            let half = |r: std::ops::Range<usize>| {
                let cols: Vec<&[f64]> = x.chunks_exact(n).map(|c| &c[r.clone()]).collect();
                let mut acc = Accumulator::new(p);
                acc.push_columns(&cols, &y[r], None);
                acc.finish()
            };
            let folds = [half(0..n / 2), half(n / 2..n)];
            let (a, b) =
                (fast.select_with_folds(&pb, &folds).unwrap(), slow.select_with_folds(&pb, &folds).unwrap());
            assert_eq!(a.chosen_step, b.chosen_step);
            let set = |s: &Selection| s.terms.iter().map(|t| (t.index, t.coefficient)).collect::<Vec<_>>();
            for ((i, x), (j, y)) in set(&a).into_iter().zip(set(&b)) {
                assert!(i == j && (x - y).abs() < 1e-9 * x.abs().max(1.0), "{i} {x} / {j} {y}");
            }
            assert_eq!(a.terms.len(), b.terms.len());
        }
    }

    /// Screening changes which QPs are solved, not their answers: at every λ of a path the
    /// screened solution is the one over all columns.
    #[test]
    fn screened_path_equals_the_full_problem() {
        let (n, p) = (300, 40);
        let mut seed = 17u64;
        let mut next = || crate::data::test_noise(&mut seed);
        let mut x = vec![0.0; n * p];
        for v in x.iter_mut() {
            *v = next();
        }
        // correlated columns, as candidate terms are
        for j in 1..p {
            for i in 0..n {
                x[j * n + i] += 0.5 * x[(j - 1) * n + i];
            }
        }
        let y: Vec<f64> =
            (0..n).map(|i| 2.0 * x[i] - x[3 * n + i] + 0.5 * x[10 * n + i] + 0.1 * next()).collect();
        let m = Moments::of_columns(&x, &y, None);
        let names: Vec<String> = (0..p).map(|j| format!("x{j}")).collect();
        let pb = Problem { moments: &m, names: &names, forced: &[7], excluded: &[5], intercept: true };
        for fit in [
            SparseFit::default(),
            SparseFit { adaptive: true, signs: vec![("x3".into(), -1.0)], ..SparseFit::default() },
        ] {
            let sc = Scaled::new(&pb).unwrap();
            let w = fit.weights(&sc, &pb).unwrap();
            let c = fit.columns(&pb).unwrap();
            let always = fit.always_active(&pb, &w, &c);
            let all: Vec<usize> = (0..p).filter(|j| *j != 5).collect();
            let lambda_max = (0..p)
                .filter(|j| w[*j] > 0.0 && *j != 5)
                .map(|j| sc.a[j * sc.m + p].abs() / w[j])
                .fold(0.0, f64::max);
            let mut previous = (lambda_max, vec![0.0; p]);
            let mut cache = None;
            for k in 0..12 {
                let lambda = lambda_max * 1e-4f64.powf(k as f64 / 11.0);
                let screened = fit
                    .solve_screened(&sc, &pb, lambda, (previous.0, &previous.1), &w, &always, &mut cache, &c)
                    .unwrap();
                let full = fit.solve(&sc, lambda, &w, &all, &c).unwrap();
                for j in 0..p {
                    assert!(
                        (screened[j] - full[j]).abs() < 1e-7,
                        "λ = {lambda:e}, x{j}: {} vs {}",
                        screened[j],
                        full[j]
                    );
                }
                assert_eq!(screened[5], 0.0);
                previous = (lambda, screened);
            }
        }
    }
}
