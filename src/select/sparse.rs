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

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use serde::{Deserialize, Serialize};

use super::subset::Scaled;
use super::{Moments, Problem, SelectError, Selection, Selector, Step, Stop};

/// A candidate named in a constraint: its term as model files write it (`"u*δ"`, matched
/// against the candidates' canonical texts; a model file's are canonicalised when it is read)
/// or its 0-based column among the candidates.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Candidate {
    /// Column index.
    Column(usize),
    /// Term text.
    Term(String),
}

impl std::fmt::Display for Candidate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Candidate::Column(j) => write!(f, "column {j}"),
            Candidate::Term(t) => write!(f, "`{t}`"),
        }
    }
}

impl From<usize> for Candidate {
    fn from(j: usize) -> Candidate {
        Candidate::Column(j)
    }
}

impl From<&str> for Candidate {
    fn from(t: &str) -> Candidate {
        Candidate::Term(t.into())
    }
}

impl Candidate {
    /// The column it names among `names`, or an error that lists them.
    pub fn column(&self, names: &[String]) -> Result<usize, SelectError> {
        let found = match self {
            Candidate::Column(j) => Some(*j).filter(|j| *j < names.len()),
            Candidate::Term(t) => names.iter().position(|n| n == t),
        };
        found.ok_or_else(|| {
            SelectError::Config(format!(
                "a sparse constraint names {self}, which is not a candidate (candidates: {})",
                names.join(", ")
            ))
        })
    }
}

/// A linear equality between coefficients: Σ factor × b(term) = value (raw units).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Equality {
    /// (candidate, factor).
    pub terms: Vec<(Candidate, f64)>,
    /// Right-hand side.
    pub value: f64,
}

/// The constraints with every candidate resolved to its column (checked against the problem).
#[derive(Clone, Debug, Default)]
struct Columns {
    fixed: Vec<(usize, f64)>,
    signs: Vec<(usize, f64)>,
    equalities: Vec<(Vec<(usize, f64)>, f64)>,
    /// The constraints as a person reads them (`x3 = 1, x3 ≤ 0`), for the error when they conflict.
    text: String,
}

impl Columns {
    fn is_empty(&self) -> bool {
        self.fixed.is_empty() && self.signs.is_empty() && self.equalities.is_empty()
    }
}

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

/// c_j − (R b)_j: column j's correlation with the residual of the standardised coefficients
/// `b` (the LASSO's optimality conditions and the screening rule are about it).
fn residual_correlation(sc: &Scaled, b: &[f64], j: usize) -> f64 {
    let (p, m) = (sc.p, sc.m);
    sc.a[j * m + p]
        - b.iter().enumerate().filter(|(_, v)| **v != 0.0).map(|(i, v)| sc.a[j * m + i] * v).sum::<f64>()
}

impl SparseFit {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), SelectError> {
        if self.path == 0 || !(self.lambda_ratio > 0.0 && self.lambda_ratio < 1.0) {
            return Err(SelectError::Config("sparse path must be ≥ 1 and 0 < lambda_ratio < 1".into()));
        }
        if self.lambda.is_some_and(|l| l.is_nan() || l < 0.0) || self.signs.iter().any(|s| s.1.abs() != 1.0) {
            return Err(SelectError::Config("sparse lambda must be ≥ 0 and signs ±1".into()));
        }
        let values = self.fixed.iter().map(|f| f.1).chain(
            self.equalities.iter().flat_map(|e| e.terms.iter().map(|t| t.1).chain(std::iter::once(e.value))),
        );
        if values.into_iter().any(|v| !v.is_finite()) {
            return Err(SelectError::Config("sparse fixed values and equalities must be finite".into()));
        }
        Ok(())
    }

    /// The constraints on the problem's columns: every named candidate must be one, and a
    /// candidate may be fixed or signed once.
    fn columns(&self, pb: &Problem<'_>) -> Result<Columns, SelectError> {
        let col = |c: &Candidate| c.column(pb.names);
        let pairs = |list: &[(Candidate, f64)], what: &str| -> Result<Vec<(usize, f64)>, SelectError> {
            let mut out: Vec<(usize, f64)> = Vec::new();
            for (c, v) in list {
                let j = col(c)?;
                if out.iter().any(|(i, _)| *i == j) {
                    return Err(SelectError::Config(format!(
                        "sparse `{what}` names `{}` twice",
                        pb.names[j]
                    )));
                }
                out.push((j, *v));
            }
            Ok(out)
        };
        let mut equalities = Vec::new();
        for e in &self.equalities {
            let terms =
                e.terms.iter().map(|(c, f)| Ok((col(c)?, *f))).collect::<Result<Vec<_>, SelectError>>()?;
            equalities.push((terms, e.value));
        }
        let (fixed, signs) = (pairs(&self.fixed, "fixed")?, pairs(&self.signs, "signs")?);
        let name = |j: usize| pb.names[j].as_str();
        let text = fixed
            .iter()
            .map(|&(j, v)| format!("{} = {v}", name(j)))
            .chain(signs.iter().map(|&(j, s)| format!("{} {} 0", name(j), if s > 0.0 { "≥" } else { "≤" })))
            .chain(equalities.iter().map(|(terms, v)| {
                let lhs: Vec<String> = terms.iter().map(|&(j, f)| format!("{f}·{}", name(j))).collect();
                format!("{} = {v}", lhs.join(" + "))
            }))
            .collect::<Vec<_>>()
            .join(", ");
        let columns = Columns { fixed, signs, equalities, text };
        for &j in columns
            .fixed
            .iter()
            .map(|(j, _)| j)
            .chain(columns.equalities.iter().flat_map(|e| e.0.iter().map(|(j, _)| j)))
        {
            if pb.excluded.contains(&j) {
                return Err(SelectError::Config(format!(
                    "sparse constraint on `{}`, which is excluded",
                    pb.names[j]
                )));
            }
        }
        Ok(columns)
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

    /// Columns the QP must always carry: unpenalised (forced) ones and those a fixed value
    /// or an equality names.
    fn always_active(&self, pb: &Problem<'_>, w: &[f64], c: &Columns) -> Vec<bool> {
        let mut keep: Vec<bool> = w.iter().map(|w| *w == 0.0).collect();
        for &(j, _) in &c.fixed {
            keep[j] = true;
        }
        for e in &c.equalities {
            for &(j, _) in &e.0 {
                keep[j] = true;
            }
        }
        for &j in pb.excluded {
            keep[j] = false;
        }
        keep
    }

    /// The LASSO at λ with screening (Tibshirani et al. 2012): the sequential strong rule
    /// leaves out the columns whose correlation with the previous residual is below
    /// 2λ − λ_prev; the QP is solved on the rest, and any left-out column that violates the
    /// optimality condition |c_j − (R b)_j| ≤ λ w_j is put back and the QP solved again.
    /// Exact, and on long candidate lists far smaller QPs.
    #[allow(clippy::too_many_arguments)]
    fn solve_screened(
        &self,
        sc: &Scaled,
        pb: &Problem<'_>,
        lambda: f64,
        previous: (f64, &[f64]),
        w: &[f64],
        always: &[bool],
        cache: &mut Option<(Vec<usize>, DefaultSolver<f64>)>,
        c: &Columns,
    ) -> Result<Vec<f64>, SelectError> {
        let p = sc.p;
        let correlation = |b: &[f64], j: usize| residual_correlation(sc, b, j);
        let (lambda_prev, b_prev) = previous;
        if let Some(beta) = self.closed_form(sc, pb, lambda, b_prev, w, c) {
            return Ok(beta);
        }
        let candidates: Vec<usize> = (0..p).filter(|j| !pb.excluded.contains(j)).collect();
        let mut active: Vec<usize> = candidates
            .iter()
            .copied()
            .filter(|&j| {
                // an interior-point solution is never exactly zero: below the support
                // tolerance a coefficient counts as out (the optimality check below keeps this exact)
                always[j]
                    || b_prev[j].abs() > self.support_tolerance
                    || correlation(b_prev, j).abs() >= w[j] * (2.0 * lambda - lambda_prev)
            })
            .collect();
        loop {
            let beta = self.solve_with(sc, lambda, w, &active, cache, c)?;
            let violators: Vec<usize> = candidates
                .iter()
                .copied()
                .filter(|j| {
                    !active.contains(j)
                        && correlation(&beta, *j).abs() > lambda * w[*j] * (1.0 + 1e-8) + 1e-12
                })
                .collect();
            if violators.is_empty() {
                return Ok(beta);
            }
            active.extend(violators);
            active.sort_unstable();
        }
    }

    /// The plain LASSO at λ by its optimality conditions, starting from the active set and
    /// signs of the neighbouring λ's solution `b_prev` (along a fine path they mostly stay):
    /// b_S = R_SS⁻¹ (c_S − λ w_S∘s_S) in closed form is the solution exactly when its signs
    /// hold and every other column satisfies |c_j − (R b)_j| ≤ λ w_j. Where either fails, the
    /// set is updated (columns that violate the condition enter with the sign of their
    /// correlation, coefficients that would change sign leave) and tried again, at most once
    /// per column. `None` if no set passes (the QP decides), with `active_set` off, or with
    /// fixed values, signs or equalities, which the closed form does not know.
    fn closed_form(
        &self,
        sc: &Scaled,
        pb: &Problem<'_>,
        lambda: f64,
        b_prev: &[f64],
        w: &[f64],
        c: &Columns,
    ) -> Option<Vec<f64>> {
        if !(self.active_set && c.is_empty()) {
            return None;
        }
        let (p, m) = (sc.p, sc.m);
        let open: Vec<bool> = (0..p).map(|j| !pb.excluded.contains(&j)).collect();
        // sign of each penalised coefficient in the set (0: out); unpenalised ones are always in
        let mut sign: Vec<f64> =
            (0..p)
                .map(|j| {
                    if open[j] && b_prev[j].abs() > self.support_tolerance {
                        b_prev[j].signum()
                    } else {
                        0.0
                    }
                })
                .collect();
        let in_set = |j: usize, sign: &[f64]| open[j] && (w[j] == 0.0 || sign[j] != 0.0);
        // each update moves at least one column in or out: as many as there are columns
        for _ in 0..=p {
            let set: Vec<usize> = (0..p).filter(|&j| in_set(j, &sign)).collect();
            if set.is_empty() {
                return None;
            }
            let k = set.len();
            let r = nalgebra::DMatrix::from_fn(k, k, |a, b| sc.a[set[a] * m + set[b]]);
            let rhs = nalgebra::DVector::from_fn(k, |a, _| {
                let j = set[a];
                sc.a[j * m + p] - lambda * w[j] * sign[j]
            });
            let b_set = r.cholesky()?.solve(&rhs);
            let mut beta = vec![0.0; p];
            for (a, &j) in set.iter().enumerate() {
                beta[j] = b_set[a];
            }
            let mut changed = false;
            for &j in &set {
                if w[j] > 0.0 && beta[j] * sign[j] <= 0.0 {
                    sign[j] = 0.0;
                    changed = true;
                }
            }
            for j in (0..p).filter(|&j| open[j] && !set.contains(&j)) {
                let c = residual_correlation(sc, &beta, j);
                if c.abs() > lambda * w[j] {
                    sign[j] = c.signum();
                    changed = true;
                }
            }
            if !changed {
                return Some(beta);
            }
        }
        None
    }

    fn weights(&self, sc: &Scaled, pb: &Problem<'_>) -> Result<Vec<f64>, SelectError> {
        let mut w = vec![1.0; sc.p];
        if self.adaptive {
            let all: Vec<usize> = (0..sc.p).filter(|j| !pb.excluded.contains(j)).collect();
            let a = sc.swept(&all, 1e-12).map_err(|j| {
                SelectError::Config(format!(
                    "adaptive weights need a full least-squares fit; `{}` is collinear",
                    pb.names[j]
                ))
            })?;
            // weights 1/|β_ols|, capped at 1e6 × the smallest: on exact data the zero terms'
            // β_ols is round-off, and weights of 1e12 wreck the QP's scaling
            let beta: Vec<f64> = all.iter().map(|&j| a[j * sc.m + sc.p].abs()).collect();
            let floor = beta.iter().fold(0.0f64, |m, b| m.max(*b)) * 1e-6;
            for (&j, b) in all.iter().zip(&beta) {
                w[j] = 1.0 / b.max(floor).max(1e-300);
            }
        }
        for &j in pb.forced {
            w[j] = 0.0;
        }
        Ok(w)
    }

    /// The LASSO QP on the columns `active` (the others held at zero): variables b and the
    /// bounds t ≥ |b| of the active columns; standardised coefficients, one per candidate.
    fn solve(
        &self,
        sc: &Scaled,
        lambda: f64,
        w: &[f64],
        active: &[usize],
        c: &Columns,
    ) -> Result<Vec<f64>, SelectError> {
        self.solve_with(sc, lambda, w, active, &mut None, c)
    }

    /// [`SparseFit::solve`], reusing the solver of the previous λ when it had the same
    /// columns: only q depends on λ, so its data are updated in place and the setup
    /// (equilibration, symbolic factorisation, allocation) is skipped.
    #[allow(non_snake_case)]
    fn solve_with(
        &self,
        sc: &Scaled,
        lambda: f64,
        w: &[f64],
        active: &[usize],
        cache: &mut Option<(Vec<usize>, DefaultSolver<f64>)>,
        c: &Columns,
    ) -> Result<Vec<f64>, SelectError> {
        let (p, m) = (sc.p, sc.m);
        let k = active.len();
        let n = 2 * k;
        let mut pos = vec![usize::MAX; p];
        for (a, &j) in active.iter().enumerate() {
            pos[j] = a;
        }
        let at = |j: usize| -> Result<usize, SelectError> {
            pos.get(j).copied().filter(|a| *a != usize::MAX).ok_or_else(|| {
                SelectError::Shape(format!("constraint names column {j} of {p}, which is not in the problem"))
            })
        };
        // P = blkdiag(R, 0), upper triangle, column by column
        let (mut colptr, mut rowval, mut nzval) = (vec![0usize], vec![], vec![]);
        for c in 0..n {
            if c < k {
                for i in 0..=c {
                    rowval.push(i);
                    nzval.push(sc.a[active[i] * m + active[c]]);
                }
            }
            colptr.push(rowval.len());
        }
        let P = CscMatrix::new(n, n, colptr, rowval, nzval);
        let mut q = vec![0.0; n];
        for (a, &j) in active.iter().enumerate() {
            q[a] = -sc.a[j * m + p];
            q[k + a] = lambda * w[j];
        }
        // constraint rows (dense, then to CSC): equalities first (zero cone), then inequalities
        let to_std = |j: usize| sc.d[j] / sc.d[p]; // β = b·d_j/d_y
        let mut eq_rows: Vec<(Vec<(usize, f64)>, f64)> = Vec::new();
        for &(j, v) in &c.fixed {
            eq_rows.push((vec![(at(j)?, 1.0)], v * to_std(j)));
        }
        for (terms, value) in &c.equalities {
            // Σ f·b = v with b = β·d_y/d_j
            let entries = terms
                .iter()
                .map(|&(j, f)| Ok((at(j)?, f / to_std(j))))
                .collect::<Result<_, SelectError>>()?;
            eq_rows.push((entries, *value));
        }
        let mut ineq_rows: Vec<Vec<(usize, f64)>> = Vec::new();
        for (a, &j) in active.iter().enumerate() {
            if w[j] == 0.0 {
                // no penalty (forced): t_j would be a free direction of zero cost, which
                // interior-point methods see as (almost) dual infeasible
                eq_rows.push((vec![(k + a, 1.0)], 0.0));
                continue;
            }
            ineq_rows.push(vec![(a, 1.0), (k + a, -1.0)]);
            ineq_rows.push(vec![(a, -1.0), (k + a, -1.0)]);
        }
        for &(j, sgn) in &c.signs {
            // a column left out is zero, which every sign allows
            if let Ok(a) = at(j) {
                ineq_rows.push(vec![(a, -sgn)]);
            }
        }
        let rows: Vec<(Vec<(usize, f64)>, f64)> =
            eq_rows.iter().cloned().chain(ineq_rows.into_iter().map(|r| (r, 0.0))).collect();
        let mrows = rows.len();
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for (r, (entries, _)) in rows.iter().enumerate() {
            for &(c, v) in entries {
                if c >= n {
                    return Err(SelectError::Shape(format!("constraint names column {c} of {p}")));
                }
                cols[c].push((r, v));
            }
        }
        let (mut colptr, mut rowval, mut nzval) = (vec![0usize], vec![], vec![]);
        for c in &cols {
            for &(r, v) in c {
                rowval.push(r);
                nzval.push(v);
            }
            colptr.push(rowval.len());
        }
        let A = CscMatrix::new(mrows, n, colptr, rowval, nzval);
        let b: Vec<f64> = rows.iter().map(|r| r.1).collect();
        let mut cones = Vec::new();
        if !eq_rows.is_empty() {
            cones.push(SupportedConeT::ZeroConeT(eq_rows.len()));
        }
        if mrows > eq_rows.len() {
            cones.push(SupportedConeT::NonnegativeConeT(mrows - eq_rows.len()));
        }
        let settings = DefaultSettings {
            verbose: self.verbose,
            tol_gap_abs: 1e-12,
            tol_gap_rel: 1e-12,
            tol_feas: 1e-12,
            // data updates along the path need the problem as given
            presolve_enable: false,
            input_sparse_dropzeros: false,
            ..DefaultSettings::default()
        };
        let reuse = cache
            .as_mut()
            .filter(|(cols, _)| cols == active)
            .is_some_and(|(_, solver)| solver.update_q(&q).is_ok());
        if !reuse {
            let solver = DefaultSolver::new(&P, &q, &A, &b, &cones, settings)
                .map_err(|e| SelectError::Config(format!("clarabel refused the problem: {e}")))?;
            *cache = Some((active.to_vec(), solver));
        }
        let Some((_, solver)) = cache.as_mut() else { unreachable!("just stored") };
        solver.solve();
        match solver.solution.status {
            SolverStatus::Solved => {
                let mut beta = vec![0.0; p];
                for (a, &j) in active.iter().enumerate() {
                    beta[j] = solver.solution.x[a];
                }
                Ok(beta)
            }
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                Err(SelectError::Infeasible { constraints: c.text.clone() })
            }
            status => Err(SelectError::Solver { status }),
        }
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
    /// Least squares on `support` under the constraints, written into the step: its
    /// coefficients, intercept and fit; a fixed coefficient's standard error is 0 (it is not
    /// estimated), the others keep the unconstrained fit's. Returns the residual share 1 − R².
    fn constrained_refit(
        &self,
        sc: &Scaled,
        w: &[f64],
        support: &[usize],
        c: &Columns,
        st: &mut Step,
    ) -> Result<f64, SelectError> {
        let (p, m) = (sc.p, sc.m);
        let beta = self.solve(sc, 0.0, w, support, c)?;
        // 1 − R² = 1 − 2 rᵀβ + βᵀRβ in correlation scale
        let mut rss = 1.0;
        for &i in support {
            rss -= 2.0 * sc.a[i * m + p] * beta[i];
            for &j in support {
                rss += beta[i] * sc.a[i * m + j] * beta[j];
            }
        }
        let rss = rss.max(0.0);
        st.coefficients = support.iter().map(|&j| beta[j] * sc.d[p] / sc.d[j]).collect();
        for (k, &j) in support.iter().enumerate() {
            if c.fixed.iter().any(|(f, _)| *f == j) {
                st.std_errors[k] = 0.0;
            }
        }
        if let Some(b0) = st.intercept.as_mut() {
            let means = &sc.means;
            b0.value =
                means[p] - support.iter().zip(&st.coefficients).map(|(&j, b)| b * means[j]).sum::<f64>();
            b0.t = b0.value / b0.std_error;
        }
        let r2 = 1.0 - rss;
        let dof = sc.n_eff - support.len() as f64;
        st.r2 = r2;
        st.r = r2.max(0.0).sqrt();
        st.standard_error = (rss * sc.total / dof.max(1.0)).sqrt();
        st.f = if rss > 0.0 { r2 / support.len() as f64 / (rss / dof.max(1.0)) } else { f64::INFINITY };
        Ok(rss)
    }

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
