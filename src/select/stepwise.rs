//! Forward stepwise multiple regression as in the IBM System/360 Scientific Subroutine
//! Package, subroutine STPRG, the way Oltmann (1973, Appendix A) used it.
//!
//! Work on the corrected cross-product matrix of candidates and target, scaled to
//! correlations. Each step takes the candidate with the largest sum-of-squares reduction
//! c_j = a_jy²/a_jj (eq. A2) — forced terms first, in that order of size — stops when that
//! share of the total (A3) is below a constant, and sweeps the matrix on it (A9-A10, A15-A17),
//! which leaves the coefficients (A11), the residual and the inverse in place. Terms are only
//! ever added. A candidate whose pivot (the share of its variance not yet explained by the terms
//! in) is non-positive or tiny is refused rather than divided by.

use serde::{Deserialize, Serialize};

use super::{FittedTerm, Problem, SelectError, Selection, Selector, Step, Stop};

/// How the step whose coefficients are reported is chosen (Oltmann 1973, Figs. 2-4).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "rule", rename_all = "kebab-case", deny_unknown_fields)]
pub enum StepRule {
    /// The first relative maximum of F: a step that F rose into and after which it rises by
    /// no more than `tolerance` (relative). Without one, the last forced step.
    FirstFMaximum {
        /// Relative rise of F that still counts as rising.
        #[serde(default)]
        tolerance: f64,
    },
    /// The first step after which the standard error no longer falls by more than
    /// `tolerance` (relative).
    StandardErrorPlateau {
        /// Relative fall that still counts as falling materially.
        tolerance: f64,
    },
    /// Oltmann's reading (1973, Figs. 2-4) of "the standard error no longer falls
    /// materially": the first step after which the standard error never again falls by more
    /// than `tolerance` (relative) in any later step. With exact data that is the step of the
    /// exact fit; with noisy data, where the standard error levels off.
    StandardErrorSettled {
        /// Relative fall that counts as material.
        tolerance: f64,
    },
    /// The last step taken.
    Last,
}

impl Default for StepRule {
    fn default() -> Self {
        StepRule::FirstFMaximum { tolerance: 0.0 }
    }
}

/// Settings of the STPRG back-end.
///
/// | setting | default | meaning |
/// |---|---|---|
/// | `min_proportion` | 0 | stop when the next term's share of the total sum of squares is below this (0: every step, as the paper) |
/// | `pivot_tolerance` | 1e-10 | refuse a term whose unexplained share of variance is at most this |
/// | `exact_fit` | 1e-13 | stop when 1 − R² is at most this: later steps would be chosen by round-off |
/// | `step_rule` | first F maximum | which step's coefficients are reported (an exact fit always reports its own step) |
/// | `max_steps` | none | stop after this many terms |
/// | `prune_t` | 0 (off) | after the chosen step, remove the term with the smallest \|t\| while it is below this, refitting each time |
/// | `prune_beta` | 0 (off) | likewise for the standardised coefficient \|b\|·sd(x)/sd(y) (a scale-free magnitude threshold, as sequential thresholding in SINDy) |
///
/// STPRG itself never removes a term; the two prune rules are termid's additions, off by
/// default so that the paper's procedure is reproduced as it was.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Stepwise {
    /// Stop constant for the share of the next term (A3).
    pub min_proportion: f64,
    /// Refusal threshold for a term's pivot (correlation scale).
    pub pivot_tolerance: f64,
    /// Residual share at which the fit counts as exact.
    pub exact_fit: f64,
    /// Rule choosing the reported step.
    pub step_rule: StepRule,
    /// Maximum number of terms.
    pub max_steps: Option<usize>,
    /// Remove terms with |t| below this after the chosen step (0: off).
    pub prune_t: f64,
    /// Remove terms whose standardised coefficient is below this after the chosen step (0: off).
    pub prune_beta: f64,
}

impl Default for Stepwise {
    fn default() -> Self {
        Stepwise {
            min_proportion: 0.0,
            pivot_tolerance: 1e-10,
            exact_fit: 1e-13,
            step_rule: StepRule::default(),
            max_steps: None,
            prune_t: 0.0,
            prune_beta: 0.0,
        }
    }
}

impl Stepwise {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), SelectError> {
        let bad =
            |what: &str, v: f64| SelectError::Config(format!("stepwise {what} must be in [0, 1), is {v}"));
        if !(0.0..1.0).contains(&self.min_proportion) {
            return Err(bad("min_proportion", self.min_proportion));
        }
        if !(0.0..1.0).contains(&self.pivot_tolerance) {
            return Err(bad("pivot_tolerance", self.pivot_tolerance));
        }
        if !(0.0..1.0).contains(&self.exact_fit) {
            return Err(bad("exact_fit", self.exact_fit));
        }
        if self.prune_t.is_nan() || self.prune_t < 0.0 || self.prune_beta.is_nan() || self.prune_beta < 0.0 {
            return Err(SelectError::Config(format!(
                "stepwise prune_t and prune_beta must be ≥ 0, are {} and {}",
                self.prune_t, self.prune_beta
            )));
        }
        match self.step_rule {
            StepRule::FirstFMaximum { tolerance } | StepRule::StandardErrorPlateau { tolerance }
                if !(0.0..1.0).contains(&tolerance) =>
            {
                Err(bad("step_rule tolerance", tolerance))
            }
            StepRule::StandardErrorSettled { tolerance } if !(0.0..1.0).contains(&tolerance) => {
                Err(bad("step_rule tolerance", tolerance))
            }
            _ => Ok(()),
        }
    }
}

use super::subset::{sweep, Scaled};

/// Chooses the reported step (1-based) from the steps taken.
pub(crate) fn choose_step(rule: StepRule, steps: &[Step], n_forced: usize) -> usize {
    let n = steps.len();
    if n == 0 {
        return 0;
    }
    let first = n_forced.max(1).min(n);
    match rule {
        StepRule::Last => n,
        StepRule::FirstFMaximum { tolerance } => {
            f_maximum(steps, first, tolerance, |_| true).unwrap_or(first)
        }
        StepRule::StandardErrorSettled { tolerance } => (first..=n)
            .find(|&i| {
                let se = steps[i - 1].standard_error;
                steps[i..].iter().all(|later| later.standard_error >= se * (1.0 - tolerance))
            })
            .unwrap_or(n),
        StepRule::StandardErrorPlateau { tolerance } => (first..n)
            .find(|&i| steps[i].standard_error >= steps[i - 1].standard_error * (1.0 - tolerance))
            .unwrap_or(n),
    }
}

/// The first step i ≥ `first` (1-based) that F rose into (the drop that often follows the
/// forced terms is not a maximum), after which F rises by no more than `tolerance`, and that
/// `accept` agrees to.
fn f_maximum(steps: &[Step], first: usize, tolerance: f64, accept: impl Fn(usize) -> bool) -> Option<usize> {
    let n = steps.len();
    (first..=n).find(|&i| {
        let rising = i == 1 || steps[i - 1].f > steps[i - 2].f;
        let peak = i == n || steps[i].f <= steps[i - 1].f * (1.0 + tolerance);
        rising && peak && accept(i)
    })
}

impl Selector for Stepwise {
    fn name(&self) -> &'static str {
        "stepwise"
    }

    fn select(&self, pb: &Problem<'_>) -> Result<Selection, SelectError> {
        self.validate()?;
        let mut sc = Scaled::new(pb)?;
        let (p, m, n) = (sc.p, sc.m, sc.n);
        // the unswept matrix is needed again only to prune
        let mut a = if self.prunes() { sc.a.clone() } else { std::mem::take(&mut sc.a) };
        let mut entered: Vec<usize> = Vec::new();
        let mut notes = Vec::new();
        let mut steps: Vec<Step> = Vec::new();
        // a candidate is open until it is entered, refused or excluded
        let mut open: Vec<bool> = (0..p).map(|j| !pb.excluded.contains(&j)).collect();
        let mut pool: Vec<usize> = Vec::with_capacity(p);
        let stop = loop {
            if let Some(k) = self.max_steps.filter(|k| entered.len() >= *k) {
                break Stop::StepLimit { steps: k };
            }
            pool.clear();
            pool.extend(pb.forced.iter().copied().filter(|&j| open[j]));
            let forcing = !pool.is_empty();
            if !forcing {
                pool.extend((0..p).filter(|&j| open[j]));
            }
            if pool.is_empty() {
                break if entered.is_empty() { Stop::NoCandidate } else { Stop::AllEntered };
            }
            let mut best: Option<(usize, f64)> = None;
            for &j in &pool {
                let pivot = a[j * m + j];
                // a NaN pivot is refused too
                if pivot.is_nan() || pivot <= self.pivot_tolerance {
                    if forcing {
                        return Err(SelectError::ForcedCollinear {
                            term: pb.names[j].clone(),
                            pivot,
                            tolerance: self.pivot_tolerance,
                        });
                    }
                    open[j] = false;
                    // a column that does not vary at all (constant, or under/overflowed to one
                    // value) is said as such, not as collinearity with the others
                    let flat = spread(pb, j) <= 0.0;
                    notes.push(if flat {
                        format!("`{}` refused: it has one value on every row (constant, or over- or underflowed), so it explains nothing", pb.names[j])
                    } else {
                        format!(
                            "`{}` refused: collinear with the terms in (pivot {pivot:.3e} ≤ {:.0e})",
                            pb.names[j], self.pivot_tolerance
                        )
                    });
                    continue;
                }
                let c = a[j * m + p] * a[j * m + p] / pivot; // eq. (A2), as a share of D
                if best.is_none_or(|(_, bc)| c > bc) {
                    best = Some((j, c));
                }
            }
            let Some((j, share)) = best else {
                break if entered.is_empty() { Stop::NoCandidate } else { Stop::AllEntered };
            };
            if !forcing && share < self.min_proportion {
                break Stop::BelowThreshold {
                    term: pb.names[j].clone(),
                    proportion: share,
                    threshold: self.min_proportion,
                };
            }
            let k = entered.len() + 1;
            if sc.n_eff - (k as f64) < 1.0 {
                if forcing {
                    return Err(SelectError::TooFewRows { rows: n, terms: k, intercept: pb.intercept });
                }
                break Stop::NoDegreesOfFreedom;
            }
            sweep(&mut a, m, j);
            entered.push(j);
            open[j] = false;
            let mut step = sc.step(&a, &entered, pb.names, j, false, forcing);
            step.step = k;
            step.reduction = share * sc.total; // eq. (A2)
            step.proportion = share; // eq. (A3)
            steps.push(step);
            let residual_share = sc.residual_share(&a);
            if residual_share <= self.exact_fit {
                notes.push(format!(
                    "exact fit after step {k} (1 − R² = {}): further steps would be chosen by round-off, so stepping stopped", super::round_off_share(residual_share)
                ));
                break Stop::ExactFit { residual_share };
            }
        };
        // At an exact fit the data determine the model: bumps of F before it mean nothing, and
        // any earlier step would leave a residual the data say is real.
        let chosen = match stop {
            Stop::ExactFit { .. } => steps.len(),
            _ => choose_step(self.step_rule, &steps, pb.forced.len()),
        };
        let pruned = self.prune(pb, &sc, &steps[..chosen], &mut notes);
        let mut selection = Selection::from_steps(self.name(), n, pb.names, steps, chosen, stop, notes);
        if let Some(fit) = pruned {
            selection.terms = fit
                .set
                .iter()
                .zip(fit.coefficients.iter().zip(&fit.std_errors))
                .map(|(&i, (&coefficient, &std_error))| FittedTerm {
                    term: pb.names[i].clone(),
                    index: i,
                    coefficient,
                    std_error,
                    t: coefficient / std_error,
                })
                .collect();
            selection.intercept = fit.intercept;
        }
        Ok(selection)
    }
}

impl Stepwise {
    /// Whether a prune rule is on.
    fn prunes(&self) -> bool {
        self.prune_t != 0.0 || self.prune_beta != 0.0
    }

    /// The backward pass of `prune_t` / `prune_beta` on the chosen step's terms: refits by
    /// sweeping a fresh copy of the scaled matrix on the terms kept. None if nothing goes.
    fn prune(&self, pb: &Problem<'_>, sc: &Scaled, chosen: &[Step], notes: &mut Vec<String>) -> Option<Step> {
        if !self.prunes() || chosen.is_empty() {
            return None;
        }
        let (p, m) = (sc.p, sc.m);
        let mut kept: Vec<usize> = chosen.iter().map(|s| s.index).collect();
        let mut removed_any = false;
        loop {
            let a = sc.swept(&kept, 0.0).ok()?;
            let fit = sc.step(&a, &kept, pb.names, *kept.last()?, false, false);
            // standardised coefficient = coefficient in correlation units, |a[j][y]|
            let worst = kept
                .iter()
                .enumerate()
                .filter(|(_, j)| !pb.forced.contains(j))
                .map(|(k, &j)| (k, j, (fit.coefficients[k] / fit.std_errors[k]).abs(), a[j * m + p].abs()))
                .filter(|&(_, _, t, beta)| t < self.prune_t || beta < self.prune_beta)
                .min_by(|x, y| x.3.total_cmp(&y.3));
            match worst {
                Some((k, j, t, beta)) if kept.len() > 1 => {
                    notes.push(format!(
                        "pruned `{}` after the chosen step (|t| = {t:.3}, standardised coefficient {beta:.2e})",
                        pb.names[j]
                    ));
                    kept.remove(k);
                    removed_any = true;
                }
                _ => return removed_any.then_some(fit),
            }
        }
    }
}

/// The spread of candidate `j` about its mean (or its raw sum of squares without an
/// intercept): zero for a column with one value on every row.
fn spread(pb: &Problem<'_>, j: usize) -> f64 {
    if pb.intercept {
        pb.moments.corrected(j, j)
    } else {
        pb.moments.raw(j, j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweep_inverts() {
        // [[4,2],[2,3]]⁻¹ = [[3,-2],[-2,4]]/8
        let mut a = vec![4.0, 2.0, 2.0, 3.0];
        sweep(&mut a, 2, 0);
        sweep(&mut a, 2, 1);
        let want = [3.0 / 8.0, -2.0 / 8.0, -2.0 / 8.0, 4.0 / 8.0];
        for (x, w) in a.iter().zip(want) {
            assert!((x - w).abs() < 1e-15);
        }
    }
}
