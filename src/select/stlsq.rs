//! Sequentially thresholded least squares (STLSQ; Brunton, Proctor & Kutz 2016, the default
//! optimiser of SINDy): fit every allowed candidate, drop those whose standardised coefficient
//! is below a threshold, refit on the rest, until the support settles. Coefficients are
//! compared in correlation scale (β_j·d_j/d_y), so no threshold depends on the candidates'
//! units. Without a fixed `threshold` the whole path of thresholds is walked and the support
//! with the smallest Bayesian information criterion kept: a fixed threshold drops every small
//! true term (a Rössler constant, a light damping) and keeps large spurious ones. Where the
//! candidates are many for the rows, forward selection by the same criterion can do better
//! than every support of the path, and is taken where it does by far.
//! The reported fit is ordinary least squares on the final support, entered in order of
//! decreasing |β| so the step table shows what each term adds.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::subset::{sweep, Scaled};
use super::{Problem, SelectError, Selection, Selector, Step, Stop};

/// Settings.
///
/// | setting | default | meaning |
/// |---|---|---|
/// | `threshold` | none: the path, by BIC | a term whose standardised coefficient is below this leaves |
/// | `floor` | 0.01 | without `threshold`: the path's lowest threshold (a term smaller than this never enters) |
/// | `alpha` | 0 | ridge penalty in correlation scale (0: plain least squares) |
/// | `max_iterations` | 20 | refits before giving up on a settled support |
/// | `pivot_tolerance` | 1e-10 | a collinear term is left out of the final fit |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Stlsq {
    /// Threshold on |standardised coefficient|; `None`: every threshold of the path, the
    /// support of least BIC kept.
    pub threshold: Option<f64>,
    /// The lowest threshold of the path: below a hundredth of the target's scale lie the
    /// errors of quadrature and differentiation, which spurious terms would fit (on the ODE
    /// benchmark, benches/odes: 0.003 and 0.03 each recover fewer systems than 0.01).
    pub floor: f64,
    /// Ridge penalty (correlation scale).
    pub alpha: f64,
    /// Most refits.
    pub max_iterations: usize,
    /// Refusal threshold for a term's pivot (correlation scale).
    pub pivot_tolerance: f64,
}

impl Default for Stlsq {
    fn default() -> Self {
        Stlsq { threshold: None, floor: 0.01, alpha: 0.0, max_iterations: 20, pivot_tolerance: 1e-10 }
    }
}

/// How much lower forward selection's BIC must be for its support to replace the path's.
const FORWARD_MARGIN: f64 = 10.0;

impl Stlsq {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), SelectError> {
        let finite_non_negative = |v: f64| v >= 0.0 && v.is_finite();
        if !self.threshold.is_none_or(finite_non_negative) || !finite_non_negative(self.alpha) {
            return Err(SelectError::Config(format!(
                "stlsq needs a finite threshold ≥ 0 and alpha ≥ 0, has {:?} and {}",
                self.threshold, self.alpha
            )));
        }
        if !(self.floor > 0.0 && self.floor.is_finite()) {
            return Err(SelectError::Config(format!("stlsq needs a finite floor > 0, has {}", self.floor)));
        }
        if self.max_iterations == 0 {
            return Err(SelectError::Config("stlsq max_iterations must be ≥ 1".into()));
        }
        Ok(())
    }

    /// Standardised (ridge) least-squares coefficients on `set`, in its order; `None` where
    /// the system is singular.
    fn solve(&self, sc: &Scaled, set: &[usize]) -> Option<Vec<f64>> {
        let (p, m) = (sc.p, sc.m);
        let k = set.len();
        let r =
            DMatrix::from_fn(k, k, |i, j| sc.a[set[i] * m + set[j]] + if i == j { self.alpha } else { 0.0 });
        let c = DVector::from_fn(k, |i, _| sc.a[set[i] * m + p]);
        let beta = r.clone().cholesky().map(|ch| ch.solve(&c)).or_else(|| r.lu().solve(&c))?;
        beta.iter().all(|b| b.is_finite()).then(|| beta.iter().copied().collect())
    }

    /// Whether candidate `j`, at `pivot` after those swept before it, is collinear with them
    /// (and so left out); a forced one that is cannot be fitted and is refused.
    fn collinear(&self, pb: &Problem<'_>, j: usize, pivot: f64) -> Result<bool, SelectError> {
        if !(pivot.is_nan() || pivot <= self.pivot_tolerance) {
            return Ok(false);
        }
        if pb.forced.contains(&j) {
            return Err(SelectError::ForcedCollinear {
                term: pb.names[j].clone(),
                pivot,
                tolerance: self.pivot_tolerance,
            });
        }
        Ok(true)
    }

    /// `set` without the candidates that are linear combinations of those before them (the
    /// forced ones first, then in the candidates' order), each left out with a note. Without
    /// this a near-collinear group (a constant, z and z² where z lies far from 0) makes the
    /// full fit's coefficients huge and opposite: the threshold path then drops the true terms
    /// with them and ends with nothing, and no support of it can be swept to be scored.
    /// Subsets of what is left sweep in order, so every support of the path can be scored.
    fn independent(
        &self,
        sc: &Scaled,
        pb: &Problem<'_>,
        set: Vec<usize>,
        notes: &mut Vec<String>,
    ) -> Result<Vec<usize>, SelectError> {
        let m = sc.m;
        let (forced, free): (Vec<usize>, Vec<usize>) = set.into_iter().partition(|j| pb.forced.contains(j));
        let mut a = sc.a.clone();
        let (mut kept, mut out) = (Vec::new(), Vec::new());
        for j in forced.into_iter().chain(free) {
            let pivot = a[j * m + j];
            if self.collinear(pb, j, pivot)? {
                // rounding leaves an exact combination a share of -1e-30: none, said as 0
                out.push((j, pivot.max(0.0)));
                continue;
            }
            sweep(&mut a, m, j);
            kept.push(j);
        }
        // one note for them all: a large library on a short run leaves out dozens (Lorenz-96's
        // cubic one, 24 for each of ten equations, a note each)
        match out.as_slice() {
            [] => {}
            [(j, pivot)] => notes.push(format!(
                "`{}` left out of the candidates: collinear with those before it (its share of \
                 variance not explained by them {pivot:.1e}, below pivot_tolerance {:.0e})",
                pb.names[*j], self.pivot_tolerance
            )),
            _ => {
                let names: Vec<String> = out.iter().map(|(j, _)| format!("`{}`", pb.names[*j])).collect();
                let (low, high) = out
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), (_, p)| (l.min(*p), h.max(*p)));
                notes.push(format!(
                    "{} ({}) left out of the candidates: collinear with those before them (their shares of \
                     variance not explained by them {low:.1e} to {high:.1e}, below pivot_tolerance {:.0e})",
                    names.join(", "),
                    out.len(),
                    self.pivot_tolerance
                ));
            }
        }
        // kept in the order checked: every subsequence sweeps in it with pivots no smaller
        Ok(kept)
    }

    /// STLSQ at one threshold from the support `set`: the support it settles on.
    fn settle(
        &self,
        sc: &Scaled,
        pb: &Problem<'_>,
        mut set: Vec<usize>,
        threshold: f64,
        notes: &mut Vec<String>,
    ) -> Vec<usize> {
        for _ in 0..self.max_iterations {
            let Some(beta) = self.solve(sc, &set) else {
                notes.push("the least-squares system is singular on the candidates: add `alpha` (ridge) or exclude collinear candidates".into());
                return set;
            };
            let keep: Vec<usize> = set
                .iter()
                .zip(&beta)
                .filter(|(j, b)| pb.forced.contains(j) || b.abs() >= threshold)
                .map(|(j, _)| *j)
                .collect();
            if keep.len() == set.len() {
                return set;
            }
            set = keep;
        }
        notes.push(format!(
            "the support had not settled after {} refits (max_iterations)",
            self.max_iterations
        ));
        set
    }

    /// Every support of the threshold path (thresholds rising geometrically from `floor` to
    /// the largest standardised coefficient, each STLSQ started from the last one's support),
    /// and of these the one of least BIC = n·ln(RSS/n) + k·ln(n) (Schwarz 1978): consistent,
    /// so it keeps a small true term the data hold and drops what only fits their noise.
    /// Residual shares below 10⁻¹³ are round-off and count as equal.
    fn path(&self, sc: &Scaled, pb: &Problem<'_>, set: Vec<usize>, notes: &mut Vec<String>) -> Vec<usize> {
        const STEPS: usize = 60;
        let low = self.floor;
        let top =
            self.solve(sc, &set).map_or(1.0, |b| b.iter().fold(0.0f64, |m, v| m.max(v.abs()))).max(2.0 * low);
        let ratio = (top / low).powf(1.0 / (STEPS - 1) as f64);
        let mut best: Option<(f64, Vec<usize>)> = None;
        let mut current = set;
        let mut seen: Vec<Vec<usize>> = Vec::new();
        let mut path_notes = Vec::new();
        let mut too_many = false;
        for i in 0..STEPS {
            let threshold = low * ratio.powi(i as i32);
            current = self.settle(sc, pb, current, threshold, &mut path_notes);
            if seen.contains(&current) {
                continue;
            }
            seen.push(current.clone());
            // more terms than the rows' independent evidence determines: no BIC to compare
            // (the weak form's overlapping windows leave fewer such rows than candidates)
            if sc.n_eff - (current.len() as f64) < 1.0 {
                if !too_many {
                    path_notes.push(format!(
                        "supports of more than {} terms skipped: {:.0} rows of independent evidence cannot determine them",
                        (sc.n_eff - 1.0).max(0.0).floor(),
                        sc.n_eff
                    ));
                    too_many = true;
                }
                continue;
            }
            let Some(bic) = self.bic(sc, &current) else { continue };
            if best.as_ref().is_none_or(|(b, _)| bic < *b) {
                best = Some((bic, current.clone()));
            }
            if current.iter().all(|j| pb.forced.contains(j)) {
                break;
            }
        }
        path_notes.dedup();
        notes.extend(path_notes);
        best.map(|(_, s)| s).unwrap_or_default()
    }

    /// The BIC n·ln(RSS/n) + k·ln(n) of the support `set` up to a constant (as the path
    /// scores it); `None` where it does not sweep or holds more terms than the rows determine.
    fn bic(&self, sc: &Scaled, set: &[usize]) -> Option<f64> {
        let n = sc.n_eff.max(2.0);
        if sc.n_eff - (set.len() as f64) < 1.0 {
            return None;
        }
        let a = sc.swept(set, self.pivot_tolerance).ok()?;
        Some(n * sc.residual_share(&a).max(1e-13).ln() + set.len() as f64 * n.ln())
    }

    /// Forward selection by the BIC from the forced terms over the candidates `allowed`: the
    /// candidate that lowers the residual most (of those whose standardised coefficient would
    /// be at least the floor) enters while it lowers the BIC; then STLSQ at the floor from
    /// what entered. Not distorted by an ill-conditioned full fit, where the threshold path is
    /// (see [`Stlsq::prune`]).
    fn forward(
        &self,
        sc: &Scaled,
        pb: &Problem<'_>,
        allowed: &[usize],
        notes: &mut Vec<String>,
    ) -> Vec<usize> {
        let (p, m) = (sc.p, sc.m);
        let n = sc.n_eff.max(2.0);
        let forced: Vec<usize> = allowed.iter().copied().filter(|j| pb.forced.contains(j)).collect();
        let Ok(mut a) = sc.swept(&forced, self.pivot_tolerance) else { return forced };
        let mut set = forced;
        while sc.n_eff - ((set.len() + 1) as f64) >= 1.0 {
            let share = sc.residual_share(&a).max(1e-13);
            // entering j lowers the residual share by a_jy² / a_jj (its pivot after the set),
            // with the standardised coefficient a_jy / a_jj: below the floor it is not taken, as
            // the path never takes it (noise-free, the quadrature's error is fitted so)
            let strongest = allowed
                .iter()
                .copied()
                .filter(|j| !set.contains(j) && a[j * m + j] > self.pivot_tolerance)
                .filter(|j| (a[j * m + p] / a[j * m + j]).abs() >= self.floor)
                .map(|j| (j, a[j * m + p].powi(2) / a[j * m + j]))
                .filter(|(_, fall)| fall.is_finite())
                .max_by(|x, y| x.1.total_cmp(&y.1));
            let Some((j, fall)) = strongest else { break };
            if n * ((share - fall).max(1e-13) / share).ln() + n.ln() >= 0.0 {
                break;
            }
            sweep(&mut a, m, j);
            set.push(j);
        }
        // a term that entered early for one that came later may end below the floor
        self.settle(sc, pb, set, self.floor, notes)
    }

    /// `set` less the terms whose removal lowers the BIC, the one that raises the residual
    /// least first (backward elimination). The path drops a term only below a threshold, so
    /// where the candidates are many for the rows (the full fit ill-conditioned, its true
    /// coefficients distorted) none of its supports may be the true one, and the least BIC
    /// of them keeps dozens of spurious terms over it: Lorenz-96 with ten states at 1 % noise
    /// from its quadratic library (66 candidates, 105 rows of independent evidence) kept 56
    /// terms for four in ẋ₁, where forward stepwise regression found the four.
    fn prune(
        &self,
        sc: &Scaled,
        pb: &Problem<'_>,
        mut set: Vec<usize>,
        notes: &mut Vec<String>,
    ) -> Vec<usize> {
        let (p, m) = (sc.p, sc.m);
        let n = sc.n_eff.max(2.0);
        let Ok(mut a) = sc.swept(&set, self.pivot_tolerance) else { return set };
        let mut dropped = Vec::new();
        loop {
            let share = sc.residual_share(&a).max(1e-13);
            // removing j raises the residual share by β_j² / (R⁻¹)_jj
            let weakest = set
                .iter()
                .enumerate()
                .filter(|(_, j)| !pb.forced.contains(j))
                .map(|(i, &j)| (i, j, a[j * m + p].powi(2) / a[j * m + j]))
                .filter(|(.., rise)| rise.is_finite())
                .min_by(|x, y| x.2.total_cmp(&y.2));
            let Some((i, j, rise)) = weakest else { break };
            // BIC = n·ln(share) + k·ln(n): removal lowers it when n·ln(after/share) < ln(n)
            if n * ((share + rise).max(1e-13) / share).ln() >= n.ln() {
                break;
            }
            sweep(&mut a, m, j);
            set.remove(i);
            dropped.push(format!("`{}`", pb.names[j]));
        }
        if !dropped.is_empty() {
            notes.push(format!(
                "{} left out after the threshold path: each removal lowered the Bayesian information criterion",
                dropped.join(", ")
            ));
        }
        set
    }
}

impl Selector for Stlsq {
    fn name(&self) -> &'static str {
        "stlsq"
    }

    fn select(&self, pb: &Problem<'_>) -> Result<Selection, SelectError> {
        self.validate()?;
        let sc = Scaled::new(pb)?;
        let (p, m) = (sc.p, sc.m);
        let mut notes = Vec::new();
        // columns without variance carry no information (and would make R singular)
        let set: Vec<usize> = (0..p)
            .filter(|j| !pb.excluded.contains(j) && (sc.d[*j] > 0.0 || pb.forced.contains(j)))
            .collect();
        let set = self.independent(&sc, pb, set, &mut notes)?;
        let set = match self.threshold {
            Some(threshold) => self.settle(&sc, pb, set, threshold, &mut notes),
            None => {
                let path = self.prune(&sc, pb, self.path(&sc, pb, set.clone(), &mut notes), &mut notes);
                let mut forward_notes = Vec::new();
                let forward = self.forward(&sc, pb, &set, &mut forward_notes);
                // taken on very strong evidence alone (Kass & Raftery 1995: a BIC lower by more
                // than 10): forward selection also finds spurious terms a little below the path's
                // support (Lorenz-96 at 1 % noise: six terms for four, the BIC lower by 2-5); a
                // support of fewer terms at a lower BIC is taken as it is (on a short stretch of a
                // motion the path can stand three terms of `v` in for `v` itself)
                match (self.bic(&sc, &path), self.bic(&sc, &forward)) {
                    (Some(b_path), Some(b_forward))
                        if b_forward < b_path - FORWARD_MARGIN
                            || (forward.len() < path.len() && b_forward < b_path) =>
                    {
                        notes.push(format!(
                            "the threshold path's least Bayesian information criterion kept {} terms ({b_path:.1}); \
                             forward selection by the same criterion found {} with less ({b_forward:.1}): taken",
                            path.len(),
                            forward.len()
                        ));
                        notes.extend(forward_notes);
                        forward
                    }
                    _ => path,
                }
            }
        };
        let beta = if set.is_empty() {
            Vec::new()
        } else {
            self.solve(&sc, &set).unwrap_or_else(|| vec![0.0; set.len()])
        };
        // the final fit: forced terms first, then by decreasing |β|
        let mut order: Vec<(usize, f64)> = set.iter().copied().zip(beta.iter().map(|b| b.abs())).collect();
        order.sort_by(|x, y| {
            pb.forced.contains(&y.0).cmp(&pb.forced.contains(&x.0)).then(y.1.total_cmp(&x.1))
        });
        let mut a = sc.a.clone();
        let mut fitted: Vec<usize> = Vec::new();
        let mut steps: Vec<Step> = Vec::new();
        for (j, _) in order {
            if self.collinear(pb, j, a[j * m + j])? {
                notes.push(format!("`{}` left out: collinear with the terms before it", pb.names[j]));
                continue;
            }
            if sc.n_eff - ((fitted.len() + 1) as f64) < 1.0 {
                return Err(SelectError::TooFewRows {
                    rows: sc.n,
                    terms: fitted.len() + 1,
                    intercept: pb.intercept,
                });
            }
            sweep(&mut a, m, j);
            fitted.push(j);
            let mut st = sc.step(&a, &fitted, pb.names, j, false, pb.forced.contains(&j));
            st.step = steps.len() + 1;
            steps.push(st);
        }
        let chosen = steps.len();
        Ok(Selection::from_steps(self.name(), sc.n, pb.names, steps, chosen, Stop::Converged, notes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::select::{Accumulator, Moments};

    /// The statistics of `n` rows at t = i/n, each row's candidates and target from `row`
    /// (given t and a uniform noise source in [−0.5, 0.5) seeded by `seed`), with names x1, x2, ….
    fn rows_of(
        n: usize,
        seed: u64,
        row: impl Fn(f64, &mut dyn FnMut() -> f64) -> (Vec<f64>, f64),
    ) -> (Moments, Vec<String>) {
        let mut seed = seed;
        let mut noise = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let (mut cols, mut ys): (Vec<Vec<f64>>, Vec<f64>) = (Vec::new(), Vec::new());
        for i in 0..n {
            let (x, y) = row(i as f64 / n as f64, &mut noise);
            cols.resize(x.len(), Vec::new());
            for (c, v) in cols.iter_mut().zip(x) {
                c.push(v);
            }
            ys.push(y);
        }
        let mut acc = Accumulator::new(cols.len());
        let columns: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
        acc.push_columns(&columns, &ys, None);
        (acc.finish(), (1..=cols.len()).map(|i| format!("x{i}")).collect())
    }

    /// y = 2·x1 − 3·x3 + 0.5 plus a little noise, six candidates: STLSQ keeps x1 and x3 and
    /// their coefficients are the least-squares ones on that support.
    #[test]
    fn keeps_the_true_terms_and_fits_them_by_least_squares() {
        let (moments, names) = rows_of(300, 7, |t, noise| {
            let x = vec![t, (7.0 * t).sin(), (3.0 * t).cos(), t * t, (11.0 * t).sin() * 0.1, noise()];
            let y = 2.0 * x[0] - 3.0 * x[2] + 0.5 + 0.01 * noise();
            (x, y)
        });
        let pb = Problem { moments: &moments, names: &names, forced: &[], excluded: &[], intercept: true };
        let s = Stlsq::default().select(&pb).unwrap();
        let mut chosen: Vec<&str> = s.terms.iter().map(|t| t.term.as_str()).collect();
        chosen.sort();
        assert_eq!(chosen, ["x1", "x3"]);
        let b = |name: &str| s.terms.iter().find(|t| t.term == name).unwrap().coefficient;
        assert!((b("x1") - 2.0).abs() < 0.01 && (b("x3") + 3.0).abs() < 0.01, "{:?}", s.terms);
        assert!((s.intercept.unwrap().value - 0.5).abs() < 0.01);
        // a threshold of 0 keeps every candidate with variance
        let all = Stlsq { threshold: Some(0.0), ..Stlsq::default() }.select(&pb).unwrap();
        assert_eq!(all.terms.len(), 6);
        assert!(Stlsq { threshold: Some(-1.0), ..Stlsq::default() }.validate().is_err());
    }

    /// A variable far from 0 against its spread (z = 10⁴ + sin): 1, z and z² are collinear to
    /// round-off. y = 2·(z − 10⁴) + x (no intercept, the constant a candidate): z² is left out
    /// with a note and the rest selected as without it; before, the full fit's huge opposite
    /// coefficients led the threshold path to an empty support.
    #[test]
    fn a_collinear_candidate_is_left_out_not_the_true_terms() {
        let (moments, names) = rows_of(500, 5, |t, _| {
            let z = 1e4 + (9.0 * t).sin();
            let x = (4.0 * t).cos();
            (vec![1.0, z, z * z, x], 2.0 * z - 2e4 + x)
        });
        let pb = Problem { moments: &moments, names: &names, forced: &[], excluded: &[], intercept: false };
        let s = Stlsq::default().select(&pb).unwrap();
        let mut chosen: Vec<&str> = s.terms.iter().map(|t| t.term.as_str()).collect();
        chosen.sort();
        assert_eq!(chosen, ["x1", "x2", "x4"], "{:?} {:?}", s.terms, s.notes);
        let b = |name: &str| s.terms.iter().find(|t| t.term == name).unwrap().coefficient;
        assert!((b("x2") - 2.0).abs() < 1e-6 && (b("x4") - 1.0).abs() < 1e-6, "{:?}", s.terms);
        assert!(
            s.notes.iter().any(|n| n.starts_with("`x3` left out of the candidates: collinear")),
            "{:?}",
            s.notes
        );
        // forced, z² is swept first and kept; a candidate collinear with it gives way
        let forced = Problem { forced: &[2], ..pb };
        let s = Stlsq::default().select(&forced).unwrap();
        assert!(s.terms.iter().any(|t| t.term == "x3"), "{:?}", s.terms);
        assert!(s.notes.iter().any(|n| n.contains("left out of the candidates")), "{:?}", s.notes);
    }

    /// y = 2·x1 − 3·x3 + 0.1·x2 with noise a thousand times smaller than x2's part: x2's
    /// standardised coefficient (≈ 0.03) is below SINDy's usual fixed thresholds, so a fixed
    /// threshold of 0.05 drops it; the path, by BIC, keeps it and nothing else.
    #[test]
    fn the_path_keeps_a_small_term_the_data_hold() {
        let (moments, names) = rows_of(400, 11, |t, noise| {
            let x = vec![t, (7.0 * t).sin(), (3.0 * t).cos(), t * t, noise()];
            let y = 2.0 * x[0] - 3.0 * x[2] + 0.1 * x[1] + 1e-4 * noise();
            (x, y)
        });
        let pb = Problem { moments: &moments, names: &names, forced: &[], excluded: &[], intercept: true };
        let chosen = |s: &Selection| {
            let mut c: Vec<String> = s.terms.iter().map(|t| t.term.clone()).collect();
            c.sort();
            c
        };
        let path = Stlsq::default().select(&pb).unwrap();
        assert_eq!(chosen(&path), ["x1", "x2", "x3"]);
        let b2 = path.terms.iter().find(|t| t.term == "x2").unwrap().coefficient;
        assert!((b2 - 0.1).abs() < 1e-4, "{b2}");
        let fixed = Stlsq { threshold: Some(0.05), ..Stlsq::default() }.select(&pb).unwrap();
        assert_eq!(chosen(&fixed), ["x1", "x3"]);
        assert!(Stlsq { floor: 0.0, ..Stlsq::default() }.validate().is_err());
    }

    /// More candidates than the rows' independent evidence (90 for 120 rows that share their
    /// noise four by four, 30 rows' worth): the path's first supports cannot be determined and
    /// are skipped with a note, and the two true terms are found; before, the least BIC of the
    /// path was a support the final fit could not determine, and the fit was refused.
    #[test]
    fn more_candidates_than_the_rows_determine_still_find_the_terms() {
        let (moments, names) = rows_of(120, 3, |t, noise| {
            let tau = std::f64::consts::TAU;
            let mut x = vec![(3.0 * tau * t).sin(), (5.0 * tau * t).cos(), (7.0 * tau * t).sin()];
            x.extend((0..87).map(|_| noise()));
            let y = 2.0 * x[0] - 3.0 * x[2] + noise();
            (x, y)
        });
        let moments = moments.with_overlap(4.0);
        let pb = Problem { moments: &moments, names: &names, forced: &[], excluded: &[], intercept: true };
        let s = Stlsq::default().select(&pb).unwrap();
        let mut chosen: Vec<&str> = s.terms.iter().map(|t| t.term.as_str()).collect();
        chosen.sort();
        assert_eq!(chosen, ["x1", "x3"], "{:?}", s.notes);
        assert!(
            s.notes.iter().any(|n| n.starts_with("supports of more than 28 terms skipped")),
            "{:?}",
            s.notes
        );
    }
}
