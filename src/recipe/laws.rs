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
/// `outline` given its laws as candidates of every identified equation, and those laws (their
/// canonical text); `None` where it was not made from columns with the polynomial library, or
/// no state can have them (a state written about a reference value, a heater's temperature in
/// K, has no law of its own).
pub(super) fn with_laws(
    model: &Model,
    outline: Option<&crate::model::Outline>,
) -> Option<(Model, Vec<String>)> {
    let outline = outline.filter(|o| o.candidates.is_empty())?;
    let about_a_reference =
        |s: &str| model.spec().derived.iter().any(|d| d.definition.starts_with(&format!("{s} - ")));
    let laws: Vec<String> = outline
        .states
        .iter()
        .filter(|s| !about_a_reference(s))
        .flat_map(|s| crate::term::laws(s))
        .filter_map(|l| model.vocabulary.parse(&l).ok().map(|t| t.to_string()))
        .collect();
    if laws.is_empty() {
        return None;
    }
    let extended = model
        .edit(|file| {
            file.model.provenance = format!("{}, and each state's laws: {ALL}", file.model.provenance);
            for equation in file.equations.values_mut().filter(|e| e.identify) {
                for law in &laws {
                    if !equation.candidates.contains(law) {
                        equation.candidates.push(law.clone());
                    }
                }
            }
        })
        .ok()?;
    Some((extended, laws))
}

/// The laws, in words.
const ALL: &str = "sign, x·|x|, √|x|, sin x";

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

/// The number of terms of the identified equations of `recipe`'s kept model, and the `laws`
/// among them (each once).
fn terms(recipe: &Recipe, laws: &[String]) -> (usize, Vec<String>) {
    let model = &recipe.kept().model;
    let chosen: Vec<String> = model
        .identifiable()
        .iter()
        .filter_map(|n| model.equation(n))
        .flat_map(|e| e.coefficients.iter().map(|(t, _, _)| t.to_string()))
        .collect();
    let held = laws.iter().filter(|l| chosen.contains(l)).cloned().collect();
    (chosen.len(), held)
}

/// Checks named as a list: "a", "b".
fn named(checks: impl IntoIterator<Item = String>) -> String {
    checks.into_iter().map(|c| format!("\"{c}\"")).collect::<Vec<_>>().join(", ")
}

/// Which of the polynomial library's recipe `polynomials` (whose kept start fails the
/// stand-in checks `flags`) and the recipe with the `laws` among the candidates (`with`) to
/// keep, the choice said in a note of the kept start: the laws' where its kept start passes
/// every check, holds a law and has fewer terms.
pub(super) fn kept(
    polynomials: Recipe,
    with: Result<Recipe, super::RecipeError>,
    laws: &[String],
    flags: &[String],
) -> Recipe {
    let (before, _) = terms(&polynomials, laws);
    let tried = format!(
        "the polynomial library's {before} terms failed {}; with each state's laws among the candidates ({ALL})",
        named(flags.iter().cloned())
    );
    let (mut recipe, note) = match with {
        Ok(with) => {
            let (after, held) = terms(&with, laws);
            let failing: Vec<String> =
                with.kept().checks.iter().filter(|c| !c.passed).map(|c| c.name.clone()).collect();
            let why = match (failing.is_empty(), held.is_empty()) {
                (false, _) => Some(format!("they fail {} too", named(failing))),
                (true, true) => Some("no law is chosen".to_string()),
                (true, false) if after >= before => Some(format!("{after} terms, no fewer")),
                (true, false) => None,
            };
            match why {
                None => {
                    let held: Vec<String> = held.iter().map(|t| format!("`{t}`")).collect();
                    let note = format!(
                        "{tried} the equations hold in {after} ({}), every check ok: kept, the polynomials having stood in for a law. Where the polynomials are wanted, --no-laws (Python `laws=False`) keeps them",
                        held.join(", ")
                    );
                    (with, note)
                }
                Some(why) => {
                    (polynomials, format!("{tried} no better ({why}): the polynomials kept, as flagged"))
                }
            }
        }
        Err(e) => (
            polynomials,
            format!("{tried} the system could not be identified ({e}): the polynomials kept, as flagged"),
        ),
    };
    let at = recipe.kept;
    if let Some((_, fit)) = recipe.starts[at].fits.first_mut() {
        fit.selection.notes.push(note);
    }
    recipe
}
