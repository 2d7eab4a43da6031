//! A system made from its columns with the polynomial library, whose terms do not hold: the
//! polynomials may stand in for a law they only approximate (Torricelli's outflow √h of a
//! tank came back as twenty terms in h, h², u², …). Identified again with each state's laws
//! among the candidates ([`crate::term::laws`]), the laws' equations are kept where they pass
//! every check the polynomials' failed, in fewer terms; either way it is said.

use super::{halves, retrace, Recipe};
use crate::model::Model;

/// The checks whose failure a stand-in shows: its terms differ between the halves of the runs,
/// or it re-simulates them no closer than a model off the motion.
const STAND_IN: [&str; 3] = [halves::NAME, retrace::MISSED_NAME, retrace::CLOSE_NAME];

/// `model` (settled about its reference values) with each state of its polynomial library's
/// `outline` given its laws as candidates of every identified equation; `None` where it was not
/// made from columns with the polynomial library, or no state can have them (a state written
/// about a reference value, a heater's temperature in K, has no law of its own).
pub(super) fn with_laws(model: &Model, outline: Option<&crate::model::Outline>) -> Option<Model> {
    let outline = outline.filter(|o| o.candidates.is_empty())?;
    let about_a_reference =
        |s: &str| model.spec().derived.iter().any(|d| d.definition.starts_with(&format!("{s} - ")));
    let laws: Vec<String> = outline
        .states
        .iter()
        .filter(|s| !about_a_reference(s))
        .flat_map(|s| crate::term::laws(s))
        .filter(|l| model.vocabulary.parse(l).is_ok())
        .collect();
    if laws.is_empty() {
        return None;
    }
    model
        .edit(|file| {
            file.model.provenance =
                format!("{}, and each state's laws: sign, x·|x|, √|x|, sin x", file.model.provenance);
            for equation in file.equations.values_mut().filter(|e| e.identify) {
                for law in &laws {
                    if !equation.candidates.contains(law) {
                        equation.candidates.push(law.clone());
                    }
                }
            }
        })
        .ok()
}

/// The stand-in checks ([`STAND_IN`]) the kept start of `recipe` fails, by name.
pub(super) fn stand_in_flags(recipe: &Recipe) -> Vec<String> {
    recipe
        .kept()
        .checks
        .iter()
        .filter(|c| !c.passed && STAND_IN.contains(&c.name.as_str()))
        .map(|c| c.name.clone())
        .collect()
}

/// The terms of the identified equations of `recipe`'s kept model, and the laws among them
/// (each once).
fn terms(recipe: &Recipe) -> (usize, Vec<String>) {
    let model = &recipe.kept().model;
    let chosen: Vec<String> = model
        .identifiable()
        .iter()
        .filter_map(|n| model.equation(n))
        .flat_map(|e| e.coefficients.iter().map(|(t, _, _)| t.to_string()))
        .collect();
    let mut laws: Vec<String> = Vec::new();
    for t in chosen.iter().filter(|t| is_law(t)) {
        if !laws.contains(t) {
            laws.push(t.clone());
        }
    }
    (chosen.len(), laws)
}

/// Whether `term` holds a law ([`crate::term::laws`]) of some variable.
fn is_law(term: &str) -> bool {
    ["sign(", "abs(", "sin("].iter().any(|f| term.contains(f))
}

/// Which of the polynomial library's `polynomials` (whose kept start fails the stand-in
/// checks `flags`) and the `laws`' recipe to keep, and what to say of it: the laws' where
/// its kept start passes every check, holds a law and has fewer terms.
pub(super) fn kept(
    polynomials: Recipe,
    laws: Result<Recipe, super::RecipeError>,
    flags: &[String],
) -> Recipe {
    let (before, _) = terms(&polynomials);
    let failed = flags.iter().map(|f| format!("\"{f}\"")).collect::<Vec<_>>().join(", ");
    let (mut recipe, note) = match laws {
        Ok(laws) => {
            let (after, chosen) = terms(&laws);
            let passes = laws.kept().checks.iter().all(|c| c.passed);
            if passes && !chosen.is_empty() && after < before {
                let note = format!(
                    "the polynomial library's {before} terms failed {failed}: they stood in for a law; with each state's laws among the candidates (sign, x·|x|, √|x|, sin x) the equations hold in {after} ({}), every check ok: kept. Where the polynomials are wanted, --no-laws (Python `laws=False`) keeps them",
                    chosen.iter().map(|t| format!("`{t}`")).collect::<Vec<_>>().join(", ")
                );
                (laws, note)
            } else {
                let why = match (passes, chosen.is_empty()) {
                    (false, _) => {
                        let flagged: Vec<String> = laws.kept().checks.iter().filter(|c| !c.passed).map(|c| format!("\"{}\"", c.name)).collect();
                        format!("they fail {} too", flagged.join(", "))
                    }
                    (true, true) => "no law is chosen".to_string(),
                    (true, false) => format!("{after} terms, no fewer"),
                };
                let note = format!(
                    "the polynomial library's {before} terms failed {failed}; with each state's laws among the candidates (sign, x·|x|, √|x|, sin x) no better ({why}): the polynomials kept, as flagged"
                );
                (polynomials, note)
            }
        }
        Err(e) => (polynomials, format!("the polynomial library's {before} terms failed {failed}; with each state's laws among the candidates the system could not be identified ({e}): the polynomials kept, as flagged")),
    };
    let kept = recipe.kept;
    if let Some((_, fit)) = recipe.starts[kept].fits.first_mut() {
        fit.selection.notes.push(note);
    }
    recipe
}
