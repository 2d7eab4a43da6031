//! What the recipe reports about the kept start: its fits, refinement, the coefficients in
//! the field's nondimensional form, the checks (with the starts' agreement) and whether the
//! model may be written, as text a person reads and as plain values.

use crate::identify::num;
use crate::model::dimension::{nondimensional, Nondimensional};
use crate::model::Model;
use crate::select::Stop;

use super::{ParameterStage, Recipe};

/// The kept model's coefficients in the prime system of its plug-in, each with the field's
/// name for it: the reference length, speed and density and the rows.
pub struct Primes {
    /// L, m.
    pub length: f64,
    /// U, m/s.
    pub speed: f64,
    /// ρ, kg/m³.
    pub density: f64,
    /// (the field's name, the coefficient).
    pub rows: Vec<(String, Nondimensional)>,
}

impl Primes {
    /// The table of `model`'s coefficients of `equations`, where its plug-in has reference
    /// scales.
    pub fn of(model: &Model, equations: &[String]) -> Option<Primes> {
        let plugin = crate::plugins::of(model)?;
        let (length, speed, density) = plugin.reference(model)?;
        let rows = nondimensional(model, length, speed, density)
            .ok()?
            .into_iter()
            .filter(|c| equations.contains(&c.equation))
            .map(|c| {
                let term = model.vocabulary.parse(&c.term).ok();
                let name =
                    term.and_then(|t| plugin.coefficient_name(model, &c.equation, &t)).unwrap_or_default();
                (name, c)
            })
            .collect();
        Some(Primes { length, speed, density, rows })
    }

    /// The table as text.
    pub fn text(&self) -> String {
        let mut out = format!(
            "== nondimensional coefficients (prime system: lengths / L, times / (L/U), masses / ρL³ with L = {} m, U = {} m/s, ρ = {} kg/m³; the equations are accelerations: v̇' = v̇·L/U², ṙ' = ṙ·L²/U²) ==\n{:<10} {:<16} {:<10} {:>14} {:>14}\n",
            self.length, self.speed, self.density, "equation", "term", "name", "coefficient", "prime"
        );
        for (name, c) in &self.rows {
            out += &format!(
                "{:<10} {:<16} {:<10} {:>14} {:>14}\n",
                c.equation,
                c.term,
                name,
                num(c.value),
                num(c.prime)
            );
        }
        out.push('\n');
        out
    }
}

impl Recipe {
    /// Why the kept model must not be written: an equation that used up the rows' degrees of
    /// freedom (it interpolates them, whatever it simulates), and every refusing check.
    pub fn refusals(&self) -> Vec<String> {
        let kept = self.kept();
        kept.fits
            .iter()
            .filter(|(_, f)| {
                f.selection.stop == Stop::NoDegreesOfFreedom && f.selection.chosen_step == f.selection.steps.len()
            })
            .map(|(name, f)| {
                format!(
                    "FAIL `{name}`: {} rows for {} terms{}: no degrees of freedom are left, the coefficients interpolate the rows (give more or longer runs, or fewer candidates)",
                    f.selection.rows,
                    f.selection.terms.len(),
                    if f.selection.intercept.is_some() { " and an intercept" } else { "" }
                )
            })
            .chain(self.checks().iter().filter(|c| !c.passed && c.refuses).map(|c| c.line()))
            .collect()
    }

    /// What a caller says beside the report, a sentence each: every start that failed, each
    /// measure the plausible starts disagree on, the kept start's refinement rejected by the
    /// checks, its free parameters not kept. (A refinement that failed is the caller's to
    /// raise: the kept start's `refine_error`.)
    pub fn warnings(&self) -> Vec<String> {
        let kept = self.kept();
        let failed =
            self.failed.iter().map(|(method, e)| format!("the start from derivative `{method}` fails: {e}"));
        let disagree = self.agreement.iter().filter(|c| !c.passed).map(|c| c.line());
        let rejected = kept.rejected.iter().map(|(_, lost)| {
            format!(
                "the refinement is rejected: the refined model fails physical checks the regression's passes ({}); the regression's model is kept",
                lost.join("; ")
            )
        });
        let parameters = kept.parameters.as_ref().and_then(ParameterStage::warning);
        failed.chain(disagree).chain(rejected).chain(parameters).collect()
    }

    /// The kept start's coefficients in the prime system, where its plug-in has one.
    pub fn primes(&self) -> Option<Primes> {
        let kept = self.kept();
        let fitted: Vec<String> = kept.fits.iter().map(|(n, _)| n.clone()).collect();
        Primes::of(&kept.model, &fitted)
    }

    /// The kept start as text: the choice among configurations, a rejected refinement, each
    /// equation's fit, the refinement, the prime coefficients and the checks.
    pub fn text(&self) -> String {
        let kept = self.kept();
        let mut out = String::new();
        if let Some(text) = &kept.chosen_text {
            out += text;
        }
        if let Some((r, _)) = &kept.rejected {
            out += &r.text();
        }
        for (name, fit) in &kept.fits {
            out += &format!("== {name} ==\n{}\n", fit.text());
        }
        if let Some(r) = &kept.refined {
            out += &r.text();
        }
        if let Some(stage) = &kept.parameters {
            out += &stage.text();
        }
        if let Some(p) = self.primes() {
            out += &p.text();
        }
        let checks = self.checks();
        if !checks.is_empty() {
            // a field's checks are physical; any system's, that its equations retrace the runs
            let physical = crate::plugins::of(&self.kept().model).is_some();
            out += if physical { "== physical checks ==\n" } else { "== checks ==\n" };
            for c in &checks {
                out += &format!("{}\n", c.line());
            }
            out.push('\n');
        }
        out
    }

    /// The kept start as plain values: each equation's fit report, the refinement, the checks
    /// and the prime coefficients.
    pub fn json(&self) -> Result<serde_json::Value, serde_json::Error> {
        let kept = self.kept();
        let mut all = serde_json::Map::new();
        for (n, f) in &kept.fits {
            all.insert(n.clone(), serde_json::to_value(f.report())?);
        }
        if let Some(r) = &kept.refined {
            all.insert("output_error_refinement".into(), serde_json::to_value(r)?);
        }
        match &kept.parameters {
            Some(super::ParameterStage::Kept(e)) => {
                all.insert("parameter_estimate".into(), serde_json::to_value(e)?);
            }
            Some(super::ParameterStage::Rejected(e, lost)) => {
                all.insert(
                    "parameter_estimate_rejected".into(),
                    serde_json::json!({"estimate": e, "fails": lost}),
                );
            }
            Some(super::ParameterStage::Failed(why)) => {
                all.insert("parameter_estimate_failed".into(), why.clone().into());
            }
            None => {}
        }
        let checks = self.checks();
        if !checks.is_empty() {
            all.insert("physical_checks".into(), serde_json::to_value(&checks)?);
        }
        if let Some(p) = self.primes() {
            all.insert("nondimensional".into(), serde_json::to_value(&p.rows)?);
        }
        Ok(serde_json::Value::Object(all))
    }
}
