//! Efroymson's stepwise regression (Efroymson 1960; the method of MATLAB's `stepwisefit`):
//! forward steps enter the candidate with the smallest partial-F p-value while it is below
//! `p_enter`; after each change, the term in the equation with the largest p-value leaves
//! while it is above `p_remove`. Forced terms enter first and never leave. Unlike STPRG it
//! removes terms, so the sweep (its own inverse) is applied to take a term out again.

use serde::{Deserialize, Serialize};

use super::subset::{f_pvalue, sweep, Scaled};
use super::{Problem, SelectError, Selection, Selector, Step, Stop};

/// Settings (defaults as MATLAB `stepwisefit`).
///
/// | setting | default | meaning |
/// |---|---|---|
/// | `p_enter` | 0.05 | a candidate enters if its partial-F p-value is below this |
/// | `p_remove` | 0.10 | a term leaves if its p-value is above this (must be ≥ `p_enter`) |
/// | `pivot_tolerance` | 1e-10 | a collinear candidate is refused |
/// | `max_steps` | 200 | a guard against cycling |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Efroymson {
    /// p-value to enter.
    pub p_enter: f64,
    /// p-value to remove.
    pub p_remove: f64,
    /// Refusal threshold for a candidate's pivot (correlation scale).
    pub pivot_tolerance: f64,
    /// Most steps (enter or remove) taken.
    pub max_steps: usize,
}

impl Default for Efroymson {
    fn default() -> Self {
        Efroymson { p_enter: 0.05, p_remove: 0.10, pivot_tolerance: 1e-10, max_steps: 200 }
    }
}

impl Efroymson {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), SelectError> {
        if !(self.p_enter > 0.0 && self.p_enter < 1.0 && self.p_remove >= self.p_enter && self.p_remove < 1.0)
        {
            return Err(SelectError::Config(format!(
                "efroymson needs 0 < p_enter ≤ p_remove < 1, has {} and {}",
                self.p_enter, self.p_remove
            )));
        }
        Ok(())
    }
}

impl Selector for Efroymson {
    fn name(&self) -> &'static str {
        "efroymson"
    }

    fn select(&self, pb: &Problem<'_>) -> Result<Selection, SelectError> {
        self.validate()?;
        let sc = Scaled::new(pb)?;
        let (p, m) = (sc.p, sc.m);
        let mut a = sc.a.clone();
        let mut set: Vec<usize> = Vec::new();
        let mut steps: Vec<Step> = Vec::new();
        let mut notes = Vec::new();
        let push =
            |a: &[f64], set: &[usize], j: usize, removed: bool, forced: bool, steps: &mut Vec<Step>| {
                let mut st = sc.step(a, set, pb.names, j, removed, forced);
                st.step = steps.len() + 1;
                steps.push(st);
            };
        for &j in pb.forced {
            let pivot = a[j * m + j];
            if pivot.is_nan() || pivot <= self.pivot_tolerance {
                return Err(SelectError::ForcedCollinear {
                    term: pb.names[j].clone(),
                    pivot,
                    tolerance: self.pivot_tolerance,
                });
            }
            if sc.n_eff - ((set.len() + 1) as f64) < 1.0 {
                return Err(SelectError::TooFewRows {
                    rows: sc.n,
                    terms: set.len() + 1,
                    intercept: pb.intercept,
                });
            }
            sweep(&mut a, m, j);
            set.push(j);
            push(&a, &set, j, false, true, &mut steps);
        }
        let stop = loop {
            if steps.len() >= self.max_steps {
                notes.push(format!(
                    "stopped after {} steps (max_steps): the enter/remove rules may cycle",
                    self.max_steps
                ));
                break Stop::Converged;
            }
            let share = sc.residual_share(&a).max(0.0);
            if share <= 1e-13 {
                notes.push("exact fit: nothing left to explain (later choices would be round-off)".into());
                break Stop::ExactFit { residual_share: share };
            }
            // enter: partial F of each candidate on 1 and n_eff − k − 1 degrees of freedom
            let dof_after = sc.n_eff - (set.len() + 1) as f64;
            let mut best: Option<(usize, f64)> = None;
            if dof_after >= 1.0 {
                for j in (0..p).filter(|j| !set.contains(j) && !pb.excluded.contains(j)) {
                    let pivot = a[j * m + j];
                    if pivot.is_nan() || pivot <= self.pivot_tolerance {
                        continue;
                    }
                    let reduction = a[j * m + p] * a[j * m + p] / pivot;
                    let f = reduction / ((share - reduction).max(0.0) / dof_after);
                    let pv = f_pvalue(f, 1.0, dof_after);
                    if best.is_none_or(|(_, b)| pv < b) {
                        best = Some((j, pv));
                    }
                }
            }
            if let Some((j, _)) = best.filter(|(_, pv)| *pv < self.p_enter) {
                sweep(&mut a, m, j);
                set.push(j);
                push(&a, &set, j, false, false, &mut steps);
                continue;
            }
            // remove: t² = F of each term in (forced terms stay)
            let dof = sc.n_eff - set.len() as f64;
            let worst = set
                .iter()
                .filter(|j| !pb.forced.contains(j))
                .map(|&j| {
                    let b = a[j * m + p];
                    let var = a[j * m + j] * share / dof;
                    (j, f_pvalue(b * b / var, 1.0, dof))
                })
                .max_by(|x, y| x.1.total_cmp(&y.1));
            match worst {
                Some((j, pv)) if pv > self.p_remove => {
                    sweep(&mut a, m, j);
                    set.retain(|&x| x != j);
                    push(&a, &set, j, true, false, &mut steps);
                }
                _ => break if best.is_none() { Stop::AllEntered } else { Stop::Converged },
            }
        };
        let chosen = steps.len();
        Ok(Selection::from_steps(self.name(), sc.n, pb.names, steps, chosen, stop, notes))
    }
}
