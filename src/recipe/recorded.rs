//! An input that records a state's rate rather than what drives it: an accelerometer's column
//! beside a velocity, taken among a system's inputs (every other column, by default), gives
//! the rate as itself, v̇ = 1.000·a, with every check ok.

use super::Recipe;

/// The share of a rate's variance one input alone explains beyond which the note is said.
const ALONE: f64 = 0.999;

/// `recipe` with a note on each identified equation of its kept start whose first term is an
/// input of `inputs` that alone explains over [`ALONE`] of its rate's variance: where that
/// input is the rate recorded, it is no input. (A pure integrator's input, ẋ = u, is one; the
/// note says both.)
pub(super) fn said(mut recipe: Recipe, inputs: &[String]) -> Recipe {
    let at = recipe.kept;
    for (_, fit) in &mut recipe.starts[at].fits {
        let Some(first) = fit.selection.steps.first() else { continue };
        if !(inputs.contains(&first.term) && first.r2 > ALONE) {
            continue;
        }
        let note = format!(
            "`{input}` alone explains {share:.2} % of {target}'s variance: where it records that rate (an accelerometer beside a velocity) rather than what drives it, it is no input, and the equation is the record's own (name the inputs without it: --inputs, Python's `inputs`); a pure integrator's input (ẋ = u) is one",
            input = first.term,
            share = 100.0 * first.r2,
            target = fit.target,
        );
        fit.selection.notes.push(note);
    }
    recipe
}
