//! Forward sensitivities of a re-simulation with respect to the model's coefficients. The
//! right-hand side is linear in its coefficients, ẋ_i = Σ_j θ_j φ_j(x, u) over the terms of
//! equation i, so S = ∂x/∂θ obeys Ṡ = A(x, u) S + B(x, u), with A = ∂f/∂x and B_ij =
//! φ_j(x, u) where term j belongs to the equation of state i. Integrated beside the state by
//! the same RK4 step, S gives the whole Jacobian of the output error in one pass per run,
//! instead of one re-simulation per coefficient (and two for central differences). A named
//! parameter p of the model file (inside derived variables or equations, nonlinear in p) adds
//! a column whose B is ∂f/∂p: the grey-box case. A and ∂f/∂p come exactly, by forward-mode
//! derivatives through the compiled right-hand side, in one pass. A run's initial state
//! x_i(0) adds a column with B = 0 and S(0) = e_i in that run alone. A derived variable
//! y = g(x, u; p) compared with its record (a propeller's thrust) adds residuals whose
//! Jacobian rows are ∂g/∂x S + ∂g/∂p, from the same forward-mode pass at each sample.

use std::collections::BTreeMap;

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::fit::WithOutputs;
use super::{DiagnoseError, Runs};
use crate::model::Model;
use crate::sim::{Controller, Integrator, Replay, RightHandSide, SimError, System};
use crate::term::Term;

/// What an output-error fit may change: a term's coefficient (additively) or a named
/// parameter of the model file.
#[derive(Clone, Debug, PartialEq)]
pub enum Free {
    /// The coefficient of `term` in `equation`.
    Term(String, Term),
    /// A parameter by name (one value for every run).
    Parameter(String),
    /// A parameter's value in a group of runs alone (a source's nuisance: one basin's rudder
    /// indicator zero); the runs carry it among their own parameters.
    Group {
        /// The parameter.
        name: String,
        /// The runs (indices) it holds for.
        runs: Vec<usize>,
    },
    /// The initial value of a state (by index in the system) in one run (by index): a
    /// nuisance of output error, since a noisy first sample would otherwise bias the rest.
    Initial {
        /// The run.
        run: usize,
        /// The state's index.
        state: usize,
    },
}

impl Free {
    /// How an error names it.
    pub fn label(&self) -> String {
        match self {
            Free::Term(equation, term) => format!("`{term}` of {equation}"),
            Free::Parameter(name) => format!("`{name}`"),
            Free::Group { name, runs } => format!("`{name}` of runs {runs:?}"),
            Free::Initial { run, state } => format!("the initial value of state {state} in run {run}"),
        }
    }
}

/// The output error linearised at a model: the scaled residuals of every run (as
/// [`Runs::residuals`] orders them) and the normal equations' JᵀJ and Jᵀr, J the residuals'
/// Jacobian with respect to additive changes of the coefficients. J itself, a row per
/// residual, is never assembled: each run's part is reduced where it is made.
pub(super) struct Linearised {
    /// The scaled residuals.
    pub residuals: Vec<f64>,
    /// JᵀJ.
    pub jtj: DMatrix<f64>,
    /// Jᵀr.
    pub jtr: DVector<f64>,
}

/// Linearises the output error of `model` on `runs` in `entries`.
pub(super) fn linearise(runs: &Runs, model: &Model, entries: &[Free]) -> Result<Linearised, DiagnoseError> {
    let k = entries.len();
    let mut residuals = Vec::with_capacity(runs.residual_count());
    let mut jtj = DMatrix::<f64>::zeros(k, k);
    let mut jtr = DVector::<f64>::zeros(k);
    let parts = per_run_jacobians(runs, model, entries, |res, jt, active| {
        let a = gram_of_rows(&jt);
        let g = &jt * DVector::from_column_slice(&res);
        (res, a, g, active.to_vec())
    })?;
    for (r, a, g, active) in parts {
        residuals.extend(r);
        for (q, &j) in active.iter().enumerate() {
            for (p, &i) in active.iter().enumerate() {
                jtj[(i, j)] += a[(p, q)];
            }
            jtr[j] += g[q];
        }
    }
    // a slope that is not finite would make every step NaN and the fit stop saying only that
    // no step lowers the error: name what it is the slope with respect to
    let infinite: Vec<String> = entries
        .iter()
        .enumerate()
        .filter(|(j, _)| !(jtj[(*j, *j)].is_finite() && jtr[*j].is_finite()))
        .map(|(_, e)| e.label())
        .collect();
    if !infinite.is_empty() && residuals.iter().all(|r| r.is_finite()) {
        return Err(DiagnoseError::Refinement(super::fit::EstimateError::SlopeNotFinite(
            infinite.join(", "),
        )));
    }
    Ok(Linearised { residuals, jtj, jtr })
}

/// A linearisation's failure as an output-error fit reports it: a slope that is not finite as
/// it is (it names the free values), any other (the re-simulation left its bounds) as the fit
/// diverging `at`.
pub(super) fn fit_failure(e: DiagnoseError, at: &'static str) -> DiagnoseError {
    match e {
        slope @ DiagnoseError::Refinement(super::fit::EstimateError::SlopeNotFinite(_)) => slope,
        _ => DiagnoseError::Refinement(super::fit::EstimateError::Diverges(at)),
    }
}

/// A Aᵀ of a k × n column-major matrix (JᵀJ from Jᵀ): one blocked product straight from its
/// storage, no transposed copy. (Computing only the blocks on and below the diagonal saved
/// nothing measurable at k = 64: the smaller products pack less efficiently.)
fn gram_of_rows(a: &DMatrix<f64>) -> DMatrix<f64> {
    let (k, n) = a.shape();
    let mut c = DMatrix::zeros(k, k);
    if k == 0 || n == 0 {
        return c;
    }
    // SAFETY: `a` holds k·n values with row stride 1 and column stride k, its transpose is the
    // same storage read with the strides swapped, and `c` is a distinct k × k column-major
    // matrix
    unsafe {
        matrixmultiply::dgemm(
            k,
            n,
            k,
            1.0,
            a.as_ptr(),
            1,
            k as isize,
            a.as_ptr(),
            k as isize,
            1,
            0.0,
            c.as_mut_ptr(),
            1,
            k as isize,
        );
    }
    c
}

/// The residuals of every run and their Jacobian, assembled (for tests and small problems).
#[cfg(test)]
fn residuals_and_jacobian(
    runs: &Runs,
    model: &Model,
    entries: &[Free],
) -> Result<(Vec<f64>, DMatrix<f64>), DiagnoseError> {
    let parts =
        per_run_jacobians(runs, model, entries, |res, jt, active| (res, jt.transpose(), active.to_vec()))?;
    let rows: usize = parts.iter().map(|p| p.0.len()).sum();
    let mut residuals = Vec::with_capacity(rows);
    let mut jacobian = DMatrix::zeros(rows, entries.len());
    let mut at = 0;
    for (r, j, active) in parts {
        for (q, &column) in active.iter().enumerate() {
            jacobian.view_mut((at, column), (r.len(), 1)).copy_from(&j.column(q));
        }
        at += r.len();
        residuals.extend(r);
    }
    Ok((residuals, jacobian))
}

/// Each run's scaled residuals and their Jacobian, transposed (columns × residuals, column-
/// major: a residual's derivatives lie side by side, as S holds them), handed to `reduce` in the
/// thread that made them with the entries its rows stand for; the runs in parallel. A run's
/// Jacobian has no rows for the entries that cannot move it (another run's initial state, a
/// group it is not in): their sensitivities are zero throughout, and with every run's initial
/// states free they would otherwise be most of S and of JᵀJ.
fn per_run_jacobians<T: Send>(
    runs: &Runs,
    model: &Model,
    entries: &[Free],
    reduce: impl Fn(Vec<f64>, DMatrix<f64>, &[usize]) -> T + Sync,
) -> Result<Vec<T>, DiagnoseError> {
    // the system's states in its order (the model's)
    let states: Vec<String> = model.states()?.into_iter().map(|(name, _, _)| name).collect();
    // the term columns: (column, owning state) and their regressors
    let mut term_columns = Vec::new();
    let mut terms = Vec::new();
    let mut parameters = Vec::new();
    let values = model.parameter_values();
    let unknown = |name: &str| DiagnoseError::Setup(format!("`{name}` is not a parameter of {}", model.path));
    for (j, entry) in entries.iter().enumerate() {
        match entry {
            Free::Term(eq, term) => {
                let state = model.equation(eq).map(|e| e.state.clone()).unwrap_or_default();
                let i = states
                    .iter()
                    .position(|s| *s == state)
                    .ok_or_else(|| DiagnoseError::Setup(format!("no state for `{eq}`")))?;
                term_columns.push((j, i));
                terms.push(term.clone());
            }
            Free::Parameter(name) => {
                if !values.contains_key(name) {
                    return Err(unknown(name));
                }
                if runs.params.iter().any(|p| p.contains_key(name)) {
                    return Err(DiagnoseError::Setup(format!(
                        "`{name}` is set per run (`per_run`): it cannot be one free parameter"
                    )));
                }
                parameters.push((j, name.clone()));
            }
            Free::Group { name, runs: group } => {
                if !values.contains_key(name) {
                    return Err(unknown(name));
                }
                if let Some(r) =
                    group.iter().find(|r| !runs.params.get(**r).is_some_and(|p| p.contains_key(name)))
                {
                    return Err(DiagnoseError::Setup(format!("run {r} carries no value of `{name}`")));
                }
            }
            Free::Initial { state, .. } if *state >= states.len() => {
                return Err(DiagnoseError::Setup(format!("no state {state} in {}", model.path)));
            }
            Free::Initial { .. } => {}
        }
    }
    // the model's states, inputs and parameters; after ẋ the compared derived variables and
    // the terms φ_j (for the matrix B), from one evaluation: compiled apart, every φ_j was
    // computed twice per stage, as they are the very sub-expressions ẋ is made of
    let outputs = runs.outputs.iter().map(|o| o.term.clone()).chain(terms).collect();
    let system =
        System::new(&WithOutputs { model, rates: true, outputs }, &BTreeMap::new(), runs.intercepts)?;
    (0..runs.frames.len())
        .into_par_iter()
        .map(|r| {
            let system = system.with_parameters(&runs.params[r])?;
            // the entries that move this run, in the order of `entries`; S's columns are theirs
            let active: Vec<usize> = entries
                .iter()
                .enumerate()
                .filter(|(_, e)| match e {
                    Free::Group { runs: group, .. } => group.contains(&r),
                    Free::Initial { run, .. } => *run == r,
                    Free::Term(..) | Free::Parameter(_) => true,
                })
                .map(|(j, _)| j)
                .collect();
            let mut local = vec![usize::MAX; entries.len()];
            for (q, &j) in active.iter().enumerate() {
                local[j] = q;
            }
            let terms: Vec<(usize, usize)> = term_columns.iter().map(|&(j, i)| (local[j], i)).collect();
            // the free parameters of this run: every run's and those of its groups
            let grouped = active.iter().filter_map(|&j| match &entries[j] {
                Free::Group { name, .. } => Some((local[j], name.clone())),
                _ => None,
            });
            let free: Vec<(usize, String)> =
                parameters.iter().map(|(j, name)| (local[*j], name.clone())).chain(grouped).collect();
            let initial: Vec<(usize, usize)> = active
                .iter()
                .filter_map(|&j| match entries[j] {
                    Free::Initial { state, .. } => Some((local[j], state)),
                    _ => None,
                })
                .collect();
            let k = active.len();
            let outputs = runs.outputs.len();
            let frame = &runs.frames[r];
            let observed = runs.outputs.iter().any(|o| frame.column(&o.name).is_some());
            let columns =
                Columns { terms: &terms, parameters: &free, initial: &initial, outputs, observed, k };
            // the residuals state by state and then derived variable by derived variable, as
            // `Runs::residuals` orders them: (first row, index in x or y, scale, measured)
            let mut blocks = Vec::with_capacity(runs.states.len());
            let mut observed = Vec::with_capacity(outputs);
            let mut rows = 0;
            for ((i, name), sc) in runs.states.iter().zip(&runs.scale) {
                let meas = frame.column(name).unwrap_or(&[]);
                blocks.push((rows, *i, *sc, meas));
                rows += meas.len();
            }
            for (q, o) in runs.outputs.iter().enumerate() {
                let meas = frame.column(&o.name).unwrap_or(&[]);
                observed.push((rows, q, o.scale, meas));
                rows += meas.len();
            }
            // a sample the simulation does not reach stays NaN
            let mut res = vec![f64::NAN; rows];
            let mut jt = DMatrix::from_element(k, rows, f64::NAN);
            integrate(&system, &columns, runs, r, &mut |t, x, s, y, sy| {
                // a state's value and row of S, or a derived variable's and its sensitivities
                let blocks = blocks.iter().map(|b| (b, x, s)).chain(observed.iter().map(|b| (b, y, sy)));
                for (&(first, i, sc, meas), values, slopes) in blocks {
                    if let Some(m) = meas.get(t) {
                        // a row between a schedule's samples is compared as none
                        let sample = frame.is_sample(t);
                        res[first + t] = if sample { (values[i] - m) / sc } else { 0.0 };
                        let inverse = if sample { 1.0 / sc } else { 0.0 };
                        let column = &mut jt.as_mut_slice()[(first + t) * k..(first + t + 1) * k];
                        for (out, v) in column.iter_mut().zip(&slopes[i * k..(i + 1) * k]) {
                            *out = v * inverse;
                        }
                    }
                }
            })?;
            Ok(reduce(res, jt, &active))
        })
        .collect()
}

/// The columns of S of one run by kind.
struct Columns<'a> {
    /// (column, the state whose equation holds the term), the terms in the order of the
    /// system's outputs after the states'.
    terms: &'a [(usize, usize)],
    /// (column, name) of the free parameters.
    parameters: &'a [(usize, String)],
    /// (column, state) of this run's free initial values.
    initial: &'a [(usize, usize)],
    /// How many derived variables are compared (the system's outputs after ẋ, before the
    /// terms).
    outputs: usize,
    /// Whether the run records any of them (else they are not evaluated along it).
    observed: bool,
    /// All columns.
    k: usize,
}

/// Run `r` of `runs` with its sensitivities: the state and S (row-major, n × K), the compared
/// derived variables y and theirs (row-major, outputs × K) at every sample of the run, handed
/// to `sample` with the sample's index. `system` yields ẋ, then y, then the terms' values
/// ([`WithOutputs`]).
fn integrate(
    system: &System,
    columns: &Columns<'_>,
    runs: &Runs,
    r: usize,
    sample: &mut impl FnMut(usize, &[f64], &[f64], &[f64], &[f64]),
) -> Result<(), DiagnoseError> {
    let Columns { terms: term_columns, parameters, initial, outputs, observed, k } = *columns;
    let settings = &runs.settings[r];
    let n = system.dim();
    // S's rows that matter: the compared states' and those the right-hand side reads (through
    // them the others'); a state nothing reads and nobody compares (a ship's x0, y0) feeds
    // nothing back, so its row is not integrated (it keeps its start in the output)
    let rows: Vec<usize> =
        (0..n).filter(|&i| system.reads_state(i) || runs.states.iter().any(|(c, _)| *c == i)).collect();
    if settings.integrator != Integrator::Rk4 {
        return Err(DiagnoseError::Setup("forward sensitivities integrate with RK4".into()));
    }
    let m = system.inputs.len();
    let (steps, every) = settings.check(n)?;
    let dt = settings.dt;
    let mut recorded = Replay::new(&runs.frames[r], &system.inputs)?;
    // inputs that act late reach the system that much later, as in the simulator
    let mut late;
    let replay: &mut dyn Controller = if system.delays.is_empty() && system.lags.is_empty() {
        &mut recorded
    } else {
        late = crate::sim::Delayed::new(&mut recorded, &system.delays, &system.lags);
        &mut late
    };
    let mut ws = system.workspace();
    // ∂f/∂x_c is zero for a state the right-hand side does not read
    let read: Vec<usize> = (0..n).filter(|&c| system.reads_state(c)).collect();
    let names: Vec<String> = parameters.iter().map(|(_, name)| name.clone()).collect();
    let mut tangents = system.partials(&read, &names)?;
    let d = tangents.directions();
    let mut partials = vec![0.0; n * d];
    // ẋ, the derived variables and then the terms φ_j
    let mut values = vec![0.0; n + outputs + term_columns.len()];
    // the same for y = g(x, u) at the samples, in buffers of its own (where the run records y)
    let mut buffers_y = (observed && outputs > 0)
        .then(|| (system.workspace(), tangents.clone(), values.clone(), vec![0.0; (n + outputs) * d]));
    // (ẋ, Ṡ) at (x, S, u)
    let mut rate = |x: &[f64], s: &[f64], u: &[f64], dx: &mut [f64], ds: &mut [f64]| {
        // the partials of ẋ alone (`partials` holds n rows)
        system.derivatives_and_partials(x, u, &mut ws, &mut tangents, &mut values, &mut partials);
        let (rates, rest) = values.split_at(n);
        let terms = &rest[outputs..];
        dx.copy_from_slice(rates);
        // only the integrated rows are read (the others stay zero)
        for &i in &rows {
            ds[i * k..(i + 1) * k].fill(0.0);
        }
        for (&(j, i), phi_j) in term_columns.iter().zip(terms) {
            ds[i * k + j] = *phi_j;
        }
        for &i in &rows {
            let p = &partials[i * d..(i + 1) * d];
            // ∂f/∂p
            for (q, (j, _)) in parameters.iter().enumerate() {
                ds[i * k + j] = p[read.len() + q];
            }
            // A S, by the columns of A (whole rows of S: slices the compiler vectorises)
            let row = &mut ds[i * k..(i + 1) * k];
            for (q, &c) in read.iter().enumerate() {
                let a = p[q];
                if a != 0.0 {
                    for (d, s) in row.iter_mut().zip(&s[c * k..(c + 1) * k]) {
                        *d += a * s;
                    }
                }
            }
        }
    };
    // y = g(x, u) and its sensitivities ∂g/∂x S + ∂g/∂p at a sample, by their own workspace
    let mut sy = vec![0.0; outputs * k];
    let mut observe = |x: &[f64], s: &[f64], u: &[f64], sy: &mut [f64]| -> Vec<f64> {
        let Some((ws_y, tangents_y, values_y, partials_y)) = buffers_y.as_mut() else {
            return Vec::new();
        };
        system.derivatives_and_partials(x, u, ws_y, tangents_y, values_y, partials_y);
        for q in 0..outputs {
            let p = &partials_y[(n + q) * d..(n + q + 1) * d];
            let row = &mut sy[q * k..(q + 1) * k];
            row.fill(0.0);
            for (c, &state) in read.iter().enumerate() {
                if p[c] != 0.0 {
                    for (out, v) in row.iter_mut().zip(&s[state * k..(state + 1) * k]) {
                        *out += p[c] * v;
                    }
                }
            }
            // ∂g/∂p, after the states' directions
            for (a, (j, _)) in parameters.iter().enumerate() {
                row[*j] += p[read.len() + a];
            }
        }
        values_y[n..n + outputs].to_vec()
    };
    let mut x = runs.x0[r].clone();
    let mut s = vec![0.0; n * k];
    for &(j, i) in initial {
        s[i * k + j] = 1.0;
    }
    let (mut u_now, mut u_next, mut u_mid) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let mut u_before = vec![0.0; m];
    replay.input(0.0, &x, &mut u_now);
    let y = observe(&x, &s, &u_now, &mut sy);
    sample(0, &x, &s, &y, &sy);
    let (mut kx, mut ks) = (vec![vec![0.0; n]; 4], vec![vec![0.0; n * k]; 4]);
    let (mut tx, mut ts) = (vec![0.0; n], vec![0.0; n * k]);
    for step in 1..=steps {
        let t1 = step as f64 * dt;
        replay.input(t1, &x, &mut u_next);
        // as the simulator: a held input that jumps at t1 keeps its value before over the step
        let u_end: &[f64] = if replay.before(t1, &mut u_before) { &u_before } else { &u_next };
        for j in 0..m {
            u_mid[j] = 0.5 * (u_now[j] + u_end[j]);
        }
        rate(&x, &s, &u_now, &mut kx[0], &mut ks[0]);
        for (stage, (w, u)) in [(0.5, &u_mid[..]), (0.5, &u_mid[..]), (1.0, u_end)].into_iter().enumerate() {
            for i in 0..n {
                tx[i] = x[i] + w * dt * kx[stage][i];
            }
            for &i in &rows {
                let span = i * k..(i + 1) * k;
                for ((t, s), d) in ts[span.clone()].iter_mut().zip(&s[span.clone()]).zip(&ks[stage][span]) {
                    *t = s + w * dt * d;
                }
            }
            let (kx_next, ks_next) = (&mut kx[stage + 1], &mut ks[stage + 1]);
            rate(&tx, &ts, u, kx_next, ks_next);
        }
        for i in 0..n {
            x[i] += dt / 6.0 * (kx[0][i] + 2.0 * kx[1][i] + 2.0 * kx[2][i] + kx[3][i]);
        }
        for &i in &rows {
            let span = i * k..(i + 1) * k;
            let (k0, k1, k2, k3) =
                (&ks[0][span.clone()], &ks[1][span.clone()], &ks[2][span.clone()], &ks[3][span.clone()]);
            for (q, s) in s[span].iter_mut().enumerate() {
                *s += dt / 6.0 * (k0[q] + 2.0 * k1[q] + 2.0 * k2[q] + k3[q]);
            }
        }
        if let Some((i, v)) = x.iter().enumerate().find(|(i, v)| {
            let (lo, hi) = system.bounds[*i];
            !(**v >= lo && **v <= hi)
        }) {
            return Err(SimError::Diverged {
                t: t1,
                state: system.states[i].clone(),
                value: *v,
                why: "outside its bounds or not finite (sensitivity pass)".into(),
                snapshot: String::new(),
            }
            .into());
        }
        std::mem::swap(&mut u_now, &mut u_next);
        if step % every == 0 {
            let y = observe(&x, &s, &u_now, &mut sy);
            sample(step / every, &x, &s, &y, &sy);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Frame;
    use crate::diagnose::Hypothesis;

    /// A Aᵀ from A's storage equals nalgebra's product.
    #[test]
    fn the_gram_matrix_of_rows_is_the_whole_product() {
        for (k, n) in [(1, 3), (7, 5), (37, 50), (64, 9)] {
            let a = DMatrix::from_fn(k, n, |i, j| ((i * 31 + j * 17) % 13) as f64 - 6.0 + 0.1 * i as f64);
            let c = gram_of_rows(&a);
            let full = &a * a.transpose();
            assert!((&c - &full).amax() <= 1e-12 * full.amax(), "{k} × {n}");
        }
    }

    /// A slope that is infinite where the motion passes (√x from x = 0) is refused naming the
    /// free value, not left to stop the fit as a step that lowers nothing.
    #[test]
    fn an_infinite_slope_is_named() {
        let model = crate::diagnose::fixtures::lag("sqrt(x)", -0.1);
        let t: Vec<f64> = (0..=100).map(|i| i as f64 * 0.05).collect();
        let mut f = Frame::new("run", "t", t.clone()).unwrap();
        f.push("x", t.clone()).unwrap();
        f.push("u", vec![1.0; t.len()]).unwrap();
        let runs = Runs::new(&model, &[f], 0.05, Integrator::Rk4).unwrap();
        let entries = vec![Free::Term("x_dot".into(), model.vocabulary.parse("u").unwrap())];
        let Err(e) = linearise(&runs, &model, &entries) else { panic!("a finite slope from √x at 0") };
        let message = e.to_string();
        assert!(message.contains("no finite slope with respect to `u` of x_dot"), "{message}");
        // the same with a smooth term is linearised as before
        assert!(linearise(&runs, &crate::diagnose::fixtures::lag("x", -0.1), &entries).is_ok());
    }

    /// With several runs, a run's initial state moves that run alone: its column is zero on the
    /// other runs' rows and equals central differences on its own, and the normal equations
    /// gathered run by run (each over the entries that move it) are JᵀJ and Jᵀr of the whole J.
    #[test]
    fn an_initial_state_moves_its_own_run_alone() {
        let model = Model::parse(DUFFING, "duffing.toml").unwrap();
        let frame = |phase: f64| forced(121, phase);
        let runs = Runs::new(&model, &[frame(0.0), frame(1.0), frame(2.0)], 0.05, Integrator::Rk4).unwrap();
        let entries = vec![
            Free::Initial { run: 1, state: 0 },
            Free::Term("w_dot".to_string(), model.vocabulary.parse("x^3").unwrap()),
            Free::Initial { run: 0, state: 1 },
            Free::Initial { run: 2, state: 0 },
        ];
        let (r0, jac) = residuals_and_jacobian(&runs, &model, &entries).unwrap();
        let rows: Vec<usize> = runs.frames.iter().map(|f| 2 * f.len()).collect();
        let first = |run: usize| rows[..run].iter().sum::<usize>();
        for (j, (run, state)) in [(0, (1, 0)), (2, (0, 1)), (3, (2, 0))] {
            let shifted = |h: f64| {
                let mut moved = runs.clone();
                moved.x0[run][state] += h;
                moved.residuals(&moved.simulate(&model, &[], &[]).unwrap())
            };
            let h = 1e-6;
            let (up, down) = (shifted(h), shifted(-h));
            for row in 0..r0.len() {
                let mine = (first(run)..first(run) + rows[run]).contains(&row);
                assert!(mine || jac[(row, j)] == 0.0, "entry {j} moves row {row} of another run");
            }
            central(&jac, j, (&up, &down), h, 1e-6);
        }
        let lin = linearise(&runs, &model, &entries).unwrap();
        let r = DVector::from_column_slice(&r0);
        let (jtj, jtr) = (jac.transpose() * &jac, jac.transpose() * r);
        assert!((&lin.jtj - &jtj).amax() <= 1e-12 * jtj.amax(), "{} vs {}", lin.jtj, jtj);
        assert!((&lin.jtr - &jtr).amax() <= 1e-12 * jtr.amax(), "{} vs {}", lin.jtr, jtr);
    }

    /// Column `j` of the Jacobian `jac` equals the central differences of the residuals
    /// moved by ±`h` (`up`, `down`), each row within `tolerance` × (1 + |difference|).
    fn central(jac: &DMatrix<f64>, j: usize, (up, down): (&[f64], &[f64]), h: f64, tolerance: f64) {
        for (row, (p, m)) in up.iter().zip(down).enumerate() {
            let fd = (p - m) / (2.0 * h);
            assert!(
                (jac[(row, j)] - fd).abs() < tolerance * (1.0 + fd.abs()),
                "row {row}, {j}: {} vs {fd}",
                jac[(row, j)]
            );
        }
    }

    /// A run of a forced oscillator's states x, w and its force F, `samples` of 0.05 s from
    /// the phase `phase`.
    fn forced(samples: usize, phase: f64) -> Frame {
        let t: Vec<f64> = (0..samples).map(|i| i as f64 * 0.05).collect();
        let mut f = Frame::new("run", "t", t.clone()).unwrap();
        f.push("x", t.iter().map(|t| 0.5 * (0.8 * t + phase).cos()).collect()).unwrap();
        f.push("w", t.iter().map(|t| -0.4 * (0.8 * t + phase).sin()).collect()).unwrap();
        f.push("F", t.iter().map(|t| 0.7 * (0.9 * t + phase).sin()).collect()).unwrap();
        f
    }

    /// [`forced`] from phase 0 with a record of the spring's `load` beside it.
    fn loaded(samples: usize) -> Frame {
        let mut f = forced(samples, 0.0);
        let load = f.time().iter().map(|t| 0.3 * (0.9 * t).cos()).collect();
        f.push("load", load).unwrap();
        f
    }

    const DUFFING: &str = r#"
[model]
name = "duffing"
[[states]]
name = "x"
[[states]]
name = "w"
[[inputs]]
name = "F"
[equations.x_dot]
state = "x"
identify = false
coefficients = { "w" = 1.0 }
[equations.w_dot]
state = "w"
candidates = ["x", "w", "x^3", "F"]
coefficients = { "x" = -1.0, "w" = -0.1, "x^3" = -0.2, "F" = 1.0 }
"#;

    /// The forward sensitivities equal central differences of re-simulations, on a nonlinear
    /// model with an input (a forced Duffing oscillator).
    #[test]
    fn sensitivities_equal_finite_differences() {
        let model = Model::parse(DUFFING, "duffing.toml").unwrap();
        let runs = Runs::new(&model, &[forced(201, 0.0)], 0.05, Integrator::Rk4).unwrap();
        let entries: Vec<Free> = ["x", "w", "x^3", "F"]
            .iter()
            .map(|t| Free::Term("w_dot".to_string(), model.vocabulary.parse(t).unwrap()))
            .collect();
        let (r0, jac) = residuals_and_jacobian(&runs, &model, &entries).unwrap();
        assert_eq!(r0, runs.residuals(&runs.simulate(&model, &[], &[]).unwrap()));
        let h = Hypothesis {
            name: "fd".into(),
            effect: crate::diagnose::Effect::Terms {
                terms: entries
                    .iter()
                    .map(|f| match f {
                        Free::Term(e, t) => (e.clone(), t.to_string()),
                        _ => unreachable!("only terms here"),
                    })
                    .collect(),
            },
        };
        for j in 0..entries.len() {
            let step = 1e-5;
            let mut up = vec![0.0; entries.len()];
            up[j] = step;
            let mut down = vec![0.0; entries.len()];
            down[j] = -step;
            let sim = |theta: &[f64]| {
                let m = super::super::fit::apply(&model, &h, theta).unwrap();
                runs.residuals(&runs.simulate(&m, &[], &[]).unwrap())
            };
            central(&jac, j, (&sim(&up), &sim(&down)), step, 1e-5);
        }
    }

    /// A spring whose stiffness `k` is a parameter, and a derived `load` that also reads `d`,
    /// a parameter of nothing else.
    const SPRING: &str = r#"
[model]
name = "forced spring"
[[states]]
name = "x"
[[states]]
name = "w"
[[inputs]]
name = "F"
[parameters.k]
value = 1.0
free = true
[parameters.d]
value = 0.3
free = true
[[derived]]
name = "spring"
definition = "k*x + 0.2*x^3"
[[derived]]
name = "load"
definition = "spring*F + d*w^2"
[equations.x_dot]
state = "x"
identify = false
coefficients = { "w" = 1.0 }
[equations.w_dot]
state = "w"
candidates = ["spring", "w", "F"]
coefficients = { "spring" = -1.0, "w" = -0.1, "F" = 1.0 }
"#;

    /// A compared derived variable's residuals are those of the re-simulation, and its
    /// sensitivities (∂g/∂x S + ∂g/∂p) equal central differences, with respect to a parameter
    /// of the motion and the output, one of the output alone, a term and an initial state.
    #[test]
    fn a_derived_variables_sensitivities_equal_finite_differences() {
        let model = Model::parse(SPRING, "spring.toml").unwrap();
        let f = loaded(161);
        let t = f.time().to_vec();
        let names: Vec<String> = ["x", "w", "load"].iter().map(|s| s.to_string()).collect();
        let runs = Runs::new(&model, &[f], 0.05, Integrator::Rk4).unwrap().comparing(&model, &names).unwrap();
        assert_eq!(runs.observed(), ["load"]);
        let entries = vec![
            Free::Parameter("k".into()),
            Free::Parameter("d".into()),
            Free::Term("w_dot".into(), model.vocabulary.parse("w").unwrap()),
            Free::Initial { run: 0, state: 0 },
        ];
        let (r0, jac) = residuals_and_jacobian(&runs, &model, &entries).unwrap();
        let residuals = |m: &Model, runs: &Runs| runs.residuals(&runs.simulate(m, &[], &[]).unwrap());
        assert_eq!(r0.len(), 3 * t.len());
        assert_eq!(r0, residuals(&model, &runs));
        let h = 1e-6;
        let moved = |j: usize, by: f64| -> Vec<f64> {
            let mut m = model.clone();
            let mut runs = runs.clone();
            match j {
                0 => {
                    m.set_parameter("k", 1.0 + by);
                }
                1 => {
                    m.set_parameter("d", 0.3 + by);
                }
                2 => m.set_coefficients(
                    "w_dot",
                    model
                        .equation("w_dot")
                        .unwrap()
                        .coefficients
                        .iter()
                        .map(|(t, v, se)| (t.clone(), if t.to_string() == "w" { v + by } else { *v }, *se))
                        .collect(),
                    None,
                ),
                _ => runs.x0[0][0] += by,
            }
            residuals(&m, &runs)
        };
        for j in 0..entries.len() {
            central(&jac, j, (&moved(j, h), &moved(j, -h)), h, 1e-5);
        }
        // `d` moves the load alone, and does move it
        let states = 2 * t.len();
        assert!((0..states).all(|row| jac[(row, 1)] == 0.0));
        assert!((states..r0.len()).any(|row| jac[(row, 1)].abs() > 1e-3));
    }

    /// A state or derived variable that some runs record and others do not (one basin logs
    /// a propeller's thrust and a rate, another neither) is compared in those that do: the
    /// others hold the fit to what they record, with no residual, slope or gap of the rest
    /// (the unrecorded rate, which the motion reads, starts where it is steady), and the
    /// sensitivities, with respect to that start too, still equal central differences.
    #[test]
    fn states_and_derived_variables_are_compared_in_the_runs_that_record_them() {
        let model = Model::parse(SPRING, "spring.toml").unwrap();
        let with = loaded(161);
        let other = forced(121, 0.7);
        let mut without = Frame::new("other", "t", other.time().to_vec()).unwrap();
        for name in ["x", "F"] {
            without.push(name, other.column(name).unwrap().to_vec()).unwrap();
        }
        let names: Vec<String> = ["x", "w", "load"].iter().map(|s| s.to_string()).collect();
        let runs = Runs::new(&model, &[with, without], 0.05, Integrator::Rk4)
            .unwrap()
            .comparing(&model, &names)
            .unwrap();
        let partly: Vec<(String, usize, usize)> =
            runs.partly_recorded().into_iter().map(|p| (p.name, p.runs, p.of)).collect();
        assert_eq!(partly, [("w".to_string(), 1, 2), ("load".to_string(), 1, 2)]);
        assert_eq!(runs.hidden, [vec![], vec![1]]);
        let sims = runs.simulate(&model, &[], &[]).unwrap();
        let r = runs.residuals(&sims);
        assert_eq!((r.len(), runs.residual_count()), (3 * 161 + 121, 3 * 161 + 121));
        let lengths: Vec<usize> = runs.series(&r).iter().map(Vec::len).collect();
        assert_eq!(lengths, [161, 161, 161, 121, 0, 0]);
        let gap = runs.gap(&sims);
        let compared = |run: usize| gap.runs[run].1.iter().map(|(n, _, _)| n.clone()).collect::<Vec<_>>();
        assert_eq!((compared(0), compared(1)), (names.clone(), names[..1].to_vec()));
        // `d` moves the load alone: slopes in the first run's load rows, none in the second run
        let entries = vec![
            Free::Parameter("k".into()),
            Free::Parameter("d".into()),
            Free::Initial { run: 1, state: 1 },
        ];
        let (r0, jac) = residuals_and_jacobian(&runs, &model, &entries).unwrap();
        assert_eq!(r0, r);
        let h = 1e-6;
        for j in 0..entries.len() {
            let moved = |by: f64| {
                let (mut m, mut runs) = (model.clone(), runs.clone());
                match j {
                    0 => assert!(m.set_parameter("k", 1.0 + by)),
                    1 => assert!(m.set_parameter("d", 0.3 + by)),
                    _ => runs.x0[1][1] += by,
                }
                runs.residuals(&runs.simulate(&m, &[], &[]).unwrap())
            };
            central(&jac, j, (&moved(h), &moved(-h)), h, 1e-5);
        }
        assert!((2 * 161..3 * 161).any(|row| jac[(row, 1)].abs() > 1e-3));
        assert!((3 * 161..r0.len()).all(|row| jac[(row, 1)] == 0.0));
        // the unrecorded rate's start moves the other run's displacement
        assert!((3 * 161..r0.len()).any(|row| jac[(row, 2)].abs() > 1e-3));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 64, ..Default::default() })]

        /// Whatever each run records of the compared quantities (the displacement in one, the
        /// rate and the load in another, any mix, so long as one run records each), the
        /// residuals, their count, their series and the Jacobian's rows agree, and a run
        /// counts what it records alone.
        #[test]
        fn residuals_series_and_slopes_agree_whatever_each_run_records(
            records in proptest::collection::vec((proptest::bool::ANY, proptest::bool::ANY, proptest::bool::ANY), 1..4),
        ) {
            let model = Model::parse(SPRING, "spring.toml").unwrap();
            let frames: Vec<Frame> = records
                .iter()
                .enumerate()
                .map(|(k, &(x, w, load))| {
                    let full = loaded(41 + 10 * k);
                    let mut f = Frame::new(&format!("run{k}"), "t", full.time().to_vec()).unwrap();
                    for (name, kept) in [("x", x), ("w", w), ("load", load), ("F", true)] {
                        if kept {
                            f.push(name, full.column(name).unwrap().to_vec()).unwrap();
                        }
                    }
                    f
                })
                .collect();
            let recorded = |q: usize| records.iter().any(|r| [r.0, r.1, r.2][q]);
            let names: Vec<String> =
                ["x", "w", "load"].iter().enumerate().filter(|(q, _)| recorded(*q)).map(|(_, n)| n.to_string()).collect();
            let runs = match Runs::new(&model, &frames, 0.05, Integrator::Rk4).and_then(|r| r.comparing(&model, &names)) {
                Ok(runs) => runs,
                // no state recorded anywhere (the load alone): refused, as it must be
                Err(e) => {
                    proptest::prop_assert!(!recorded(0) && !recorded(1), "{e}");
                    return Ok(());
                }
            };
            let sims = runs.simulate(&model, &[], &[]).unwrap();
            let r = runs.residuals(&sims);
            let expected: usize = frames
                .iter()
                .map(|f| names.iter().filter(|n| f.column(n).is_some()).count() * f.len())
                .sum();
            proptest::prop_assert_eq!((r.len(), runs.residual_count()), (expected, expected));
            proptest::prop_assert_eq!(runs.series(&r).iter().map(Vec::len).sum::<usize>(), expected);
            let entries = vec![Free::Parameter("k".into()), Free::Parameter("d".into())];
            let (r0, jac) = residuals_and_jacobian(&runs, &model, &entries).unwrap();
            proptest::prop_assert_eq!((r0.len(), jac.nrows()), (expected, expected));
            proptest::prop_assert_eq!(r0, r);
        }
    }

    /// The coarsest step that resolves the runs resolves the compared derived variables too: a
    /// load that follows a fast force the motion smooths out holds the step finer than the
    /// states alone would.
    #[test]
    fn the_coarsest_step_resolves_the_derived_variables_too() {
        let model = Model::parse(SPRING, "spring.toml").unwrap();
        let t: Vec<f64> = (0..400).map(|i| i as f64 * 0.05).collect();
        let mut f = Frame::new("run", "t", t.clone()).unwrap();
        f.push("x", t.iter().map(|t| 0.5 * (0.8 * t).cos()).collect()).unwrap();
        f.push("w", t.iter().map(|t| -0.4 * (0.8 * t).sin()).collect()).unwrap();
        f.push("F", t.iter().map(|t| 0.7 * (0.9 * t).sin() + 0.3 * (30.0 * t).sin()).collect()).unwrap();
        f.push("load", vec![0.0; t.len()]).unwrap();
        let names = |n: &[&str]| n.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let factor = |compared: &[&str]| {
            let runs = Runs::new(&model, std::slice::from_ref(&f), 0.05, Integrator::Rk4)
                .unwrap()
                .comparing(&model, &names(compared))
                .unwrap();
            let fine = runs.simulate(&model, &[], &[]).unwrap();
            runs.coarsest(&model, &fine, 0.05, 8).0
        };
        let (states, with_load) = (factor(&["x", "w"]), factor(&["x", "w", "load"]));
        assert!(with_load < states, "with the load {with_load}, the states alone {states}");
    }

    /// A name that is neither a state nor a derived variable, or a derived variable without a
    /// column, is refused, saying which.
    #[test]
    fn a_derived_variable_without_its_record_is_refused() {
        let model = Model::parse(SPRING, "spring.toml").unwrap();
        let t: Vec<f64> = (0..=40).map(|i| i as f64 * 0.05).collect();
        let mut f = Frame::new("run", "t", t.clone()).unwrap();
        for name in ["x", "w", "F"] {
            f.push(name, vec![0.1; t.len()]).unwrap();
        }
        let runs = Runs::new(&model, &[f], 0.05, Integrator::Rk4).unwrap();
        let compare = |names: &[&str]| {
            let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
            runs.clone().comparing(&model, &names).err().map(|e| e.to_string()).unwrap_or_default()
        };
        assert!(
            compare(&["x", "load"]).contains("no run has a column `load`"),
            "{}",
            compare(&["x", "load"])
        );
        assert!(
            compare(&["x", "torque"]).contains("its derived variables spring, load"),
            "{}",
            compare(&["x", "torque"])
        );
        assert!(compare(&["spring"]).contains("compare at least one state"), "{}", compare(&["spring"]));
        assert!(compare(&["x", ""]).contains("an empty name"), "{}", compare(&["x", ""]));
        // a name given twice is compared once
        let mut f = runs.frames[0].clone();
        f.push("load", vec![0.2; f.len()]).unwrap();
        let twice: Vec<String> = ["x", "load", "load", "x"].iter().map(|s| s.to_string()).collect();
        let once = Runs::new(&model, &[f], 0.05, Integrator::Rk4).unwrap().comparing(&model, &twice).unwrap();
        assert_eq!((once.observed(), once.compared().len()), (vec!["load".to_string()], 1));
    }
}
