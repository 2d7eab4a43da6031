//! The LASSO's quadratic program for one λ: Clarabel on the bound-variable form, the
//! optimality conditions' closed form where they give the answer, and strong-rule screening
//! with the KKT check (the columns left out must stay out).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

use super::constraints::Columns;
use super::SparseFit;
use crate::select::subset::Scaled;
use crate::select::{Problem, SelectError};

/// c_j − (R b)_j: column j's correlation with the residual of the standardised coefficients
/// `b` (the LASSO's optimality conditions and the screening rule are about it).
pub(super) fn residual_correlation(sc: &Scaled, b: &[f64], j: usize) -> f64 {
    let (p, m) = (sc.p, sc.m);
    sc.a[j * m + p]
        - b.iter().enumerate().filter(|(_, v)| **v != 0.0).map(|(i, v)| sc.a[j * m + i] * v).sum::<f64>()
}

impl SparseFit {
    /// Columns the QP must always carry: unpenalised (forced) ones and those a fixed value
    /// or an equality names.
    pub(super) fn always_active(&self, pb: &Problem<'_>, w: &[f64], c: &Columns) -> Vec<bool> {
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
    pub(super) fn solve_screened(
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
    pub(super) fn closed_form(
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

    pub(super) fn weights(&self, sc: &Scaled, pb: &Problem<'_>) -> Result<Vec<f64>, SelectError> {
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
    pub(super) fn solve(
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
    pub(super) fn solve_with(
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
        if k == 0 {
            // every column screened out (λ at or beyond λ_max): the solution is zero
            return Ok(vec![0.0; p]);
        }
        // a panic inside the solver (it has had them on degenerate data) is an error here
        let in_solver =
            |e: String| SelectError::Config(format!("the QP solver failed at λ = {lambda:e}: {e}"));
        let reuse = cache
            .as_mut()
            .filter(|(cols, _)| cols == active)
            .is_some_and(|(_, solver)| crate::contain::call(|| solver.update_q(&q).is_ok()).unwrap_or(false));
        if !reuse {
            let solver = crate::contain::call(|| DefaultSolver::new(&P, &q, &A, &b, &cones, settings))
                .map_err(in_solver)?
                .map_err(|e| SelectError::Config(format!("clarabel refused the problem: {e}")))?;
            *cache = Some((active.to_vec(), solver));
        }
        let Some((_, solver)) = cache.as_mut() else { unreachable!("just stored") };
        if let Err(e) = crate::contain::call(|| solver.solve()) {
            // a solver that panicked is not reused
            *cache = None;
            return Err(in_solver(e));
        }
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
