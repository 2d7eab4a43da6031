//! A system made from its columns with the polynomial library, whose terms do not hold: the
//! polynomials may stand in for a law they only approximate (Torricelli's outflow √h of a
//! tank came back as twenty terms in h, h², u², …). Identified again with each state's and
//! input's laws among the candidates ([`crate::term::laws`]: a propeller's thrust n·|n| is an
//! input's), the laws' equations are kept where they pass every check the polynomials'
//! failed, in no more terms; either way it is said.

use super::{agreement, halves, retrace, Recipe};
use crate::model::Model;
use crate::term::Atom;

/// The checks whose failure a stand-in shows: its terms differ between the halves of the runs,
/// it re-simulates them no closer than a model off the motion, or runs over other ranges give
/// its coefficients apart (a cubic's for a pendulum's sine).
const STAND_IN: [&str; 4] = [halves::NAME, retrace::MISSED_NAME, retrace::CLOSE_NAME, agreement::NAME];

/// `model` (settled about its reference values) with each state and input of its polynomial
/// library's `outline` given its laws as candidates of every identified equation, and those
/// laws (their canonical text); `None` where it was not made from columns with the polynomial
/// library, or no variable can have them (one written about a reference value, a heater's
/// temperature in K, has no law of its own).
pub(super) fn with_laws(
    model: &Model,
    outline: Option<&crate::model::Outline>,
) -> Option<(Model, Vec<String>)> {
    let outline = outline.filter(|o| o.candidates.is_empty())?;
    let laws: Vec<String> = own_variables(model, outline)
        .iter()
        .flat_map(|s| crate::term::laws(s))
        .filter_map(|l| model.vocabulary.parse(&l).ok().map(|t| t.to_string()))
        .collect();
    if laws.is_empty() {
        return None;
    }
    let extended = model
        .edit(|file| {
            file.model.provenance =
                format!("{}, and each state's and input's laws: {ALL}", file.model.provenance);
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

/// The states and inputs of `model`'s `outline` that can have laws of their own: not one
/// written about a reference value (a heater's temperature in K, whose library holds its
/// difference from it).
pub(super) fn own_variables(model: &Model, outline: &crate::model::Outline) -> Vec<String> {
    let about_a_reference =
        |s: &str| model.spec().derived.iter().any(|d| d.definition.starts_with(&format!("{s} - ")));
    outline.states.iter().chain(&outline.inputs).filter(|s| !about_a_reference(s)).cloned().collect()
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

/// The powers of one of `variables` alone (x², v³, n³) the kept start of `recipe` holds in
/// its identified equations: what a variable's law stands in as (sign v ≈ av + bv³, sin x ≈ x − x³/6,
/// v·|v| ≈ v³, √h ≈ a + bh − ch²), which may pass every check where the records' noise hides
/// what it misses (dry friction at 1 % noise as −0.35v + 0.0065v³, every check ok).
pub(super) fn powers_held(recipe: &Recipe, variables: &[String]) -> Vec<String> {
    let model = &recipe.kept().model;
    let alone = |t: &crate::term::Term| match t.monomials() {
        [m] => matches!(m.factors.as_slice(), [(Atom::Var(name), p)] if *p >= 2 && variables.contains(name)),
        _ => false,
    };
    let mut held: Vec<String> = model
        .identifiable()
        .iter()
        .filter_map(|n| model.equation(n))
        .flat_map(|e| e.coefficients.iter().filter(|(t, _, _)| alone(t)).map(|(t, _, _)| t.to_string()))
        .collect();
    held.sort();
    held.dedup();
    held
}

/// How much better the kept start of `with` fits its rows than that of `polynomials`, as the
/// difference of their Bayesian information criteria (the polynomials' less the laws', summed
/// over the identified equations, each counted in its rows over its residuals' correlation
/// time: those rows are what is independent). `None` where an equation's rows or target differ.
fn fits_better(polynomials: &Recipe, with: &Recipe) -> Option<f64> {
    let mut gain = 0.0;
    for (name, poly) in &polynomials.kept().fits {
        let (_, laws) = with.kept().fits.iter().find(|(n, _)| n == name)?;
        let (a, b) = (&poly.selection, &laws.selection);
        if a.rows != b.rows || poly.target != laws.target {
            return None;
        }
        let rows = a.rows as f64
            / poly.correlation_time.unwrap_or(1.0).max(laws.correlation_time.unwrap_or(1.0)).max(1.0);
        gain += information(a, rows)? - information(b, rows)?;
    }
    Some(gain)
}

/// The Bayesian information criterion of the terms `selection` chose, its rows counted as
/// `rows` independent ones.
pub(super) fn information(selection: &crate::select::Selection, rows: f64) -> Option<f64> {
    // 1 − R², at least the smallest positive double (a noise-free fit's may be 0)
    let unexplained = (1.0 - selection.chosen_r2()?).max(f64::MIN_POSITIVE);
    Some(rows * unexplained.ln() + selection.terms.len() as f64 * rows.ln())
}

/// How much lower the laws' information criterion must be where the polynomials pass every
/// check: "very strong" evidence (Kass & Raftery 1995).
pub(super) const CLEARLY: f64 = 10.0;

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

/// What a stage added to the polynomial library's candidates, and why.
pub(super) struct Tried<'a> {
    /// The terms added (canonical text).
    pub(super) laws: &'a [String],
    /// The stand-in checks the polynomials' kept start fails.
    pub(super) flags: &'a [String],
    /// Where they fail none, the powers of a variable alone they hold.
    pub(super) powers: &'a [String],
    /// The added terms in words: "each state's and input's laws among the candidates (…)".
    pub(super) family: String,
    /// Whether a power of a chosen law's variable beside it stands in too (sign v beside v³);
    /// not so for a saturating rate, beside which a logistic growth's x² is its own.
    pub(super) beside: bool,
}

impl Tried<'_> {
    /// The four laws of every state and input ([`ALL`]) added.
    pub(super) fn laws<'a>(laws: &'a [String], flags: &'a [String], powers: &'a [String]) -> Tried<'a> {
        Tried {
            laws,
            flags,
            powers,
            family: format!("each state's and input's laws among the candidates ({ALL})"),
            beside: true,
        }
    }
}

/// Which of the polynomial library's recipe `polynomials` (whose kept start fails the
/// stand-in checks `tried.flags`, or none where it holds `tried.powers` of a variable alone)
/// and the recipe with the `tried.laws` among the candidates (`with`) to keep, the choice said
/// in a note of the kept start: the laws' where its kept start passes every check, holds a law
/// and (where `tried.beside`) no power of that law's variable alone, has no more terms, and
/// where the polynomials pass every check too, fits the rows clearly better. With whether the
/// laws' were kept.
pub(super) fn kept(
    polynomials: Recipe,
    with: Result<Recipe, super::RecipeError>,
    tried: &Tried<'_>,
) -> (Recipe, bool) {
    let Tried { laws, flags, powers, family, .. } = tried;
    let (before, _) = terms(&polynomials, laws);
    let tried_text = match flags.is_empty() {
        true => format!(
            "the polynomial library's {before} terms hold {}, a variable's power alone, which may stand in for a law of it; with {family}",
            powers.iter().map(|t| format!("`{t}`")).collect::<Vec<_>>().join(", ")
        ),
        false => format!(
            "the polynomial library's {before} terms failed {}; with {family}",
            named(flags.iter().cloned())
        ),
    };
    let flagged = if flags.is_empty() { "" } else { ", as flagged" };
    let (mut recipe, note, lawful) = match with {
        Ok(with) => {
            let (after, held) = terms(&with, laws);
            let failing: Vec<String> =
                with.kept().checks.iter().filter(|c| !c.passed).map(|c| c.name.clone()).collect();
            // a law stands in for its state's powers: beside them it is one more stand-in
            // (Michaelis-Menten's rational rate as all four laws of x, x³ and x: every check ok)
            let of_laws: Vec<String> = held
                .iter()
                .filter_map(|l| with.kept().model.vocabulary.parse(l).ok())
                .flat_map(|t| t.variables())
                .collect();
            let beside = if tried.beside { powers_held(&with, &of_laws) } else { Vec::new() };
            let why = match (failing.is_empty(), held.is_empty()) {
                (false, _) => Some(format!("they fail {} too", named(failing))),
                (true, true) => Some("no law is chosen".to_string()),
                (true, false) if !beside.is_empty() => Some(format!(
                    "{} beside its variable's laws: they stand in too",
                    beside.iter().map(|t| format!("`{t}`")).collect::<Vec<_>>().join(", ")
                )),
                // (in as many terms, laws that pass where the polynomials fail stand in for
                // nothing: dry friction's sign(v), whose stand-in v³ re-simulated the run 11
                // times as far off as allowed, in four terms each)
                (true, false) if after > before => Some(format!("{after} terms, more than the polynomials'")),
                // where the polynomials pass every check too, the rows must tell
                (true, false) if flags.is_empty() => match fits_better(&polynomials, &with) {
                    Some(gain) if gain > CLEARLY => None,
                    _ => Some("they fit the rows no clearly better".to_string()),
                },
                (true, false) => None,
            };
            match why {
                None => {
                    let held: Vec<String> = held.iter().map(|t| format!("`{t}`")).collect();
                    let note = format!(
                        "{tried_text} the equations hold in {after} ({}), every check ok: kept, the polynomials having stood in for a law. Where the polynomials are wanted, --no-laws (Python `laws=False`) keeps them",
                        held.join(", ")
                    );
                    (with, note, true)
                }
                Some(why) => (
                    polynomials,
                    format!("{tried_text} no better ({why}): the polynomials kept{flagged}"),
                    false,
                ),
            }
        }
        Err(e) => (
            polynomials,
            format!("{tried_text} the system could not be identified ({e}): the polynomials kept{flagged}"),
            false,
        ),
    };
    recipe.say(note);
    (recipe, lawful)
}
