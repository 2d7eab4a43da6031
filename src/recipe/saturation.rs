//! Rates that saturate: an enzyme's turnover x/(x + K), a predator's intake xy/(x + K), a
//! switch's 1/(1 + (x/K)²), an actuator's limit tanh(u/K). The polynomial library stands in
//! for them and fails beyond its runs (a predator-prey cycle's ten cubic terms whose cycle
//! grows); their scale K is no coefficient, so it is found by a scan of the regression's
//! information criterion, each variable's in turn, and the system identified again with the
//! saturating forms at the K found; kept as the laws are (`laws.rs`), either way said.

use super::laws::{self, Tried, CLEARLY};
use super::{start, Recipe, RecipeError, RecipeSettings};
use crate::data::Frame;
use crate::identify::{select_model, ModelIdentification};
use crate::model::Model;
use crate::select::Selection;
use rayon::prelude::*;

/// The half-saturations tried first, as multiples of each variable's median over the runs:
/// from an eighth (where x/(x + K) is nearly 1, the library's constant) to eight times (nearly
/// x/K, its x), [`PER_OCTAVE`] to the octave. Where the records hold no noise, the criterion
/// dips sharply at the true K and the library's stand-ins make it slope elsewhere as they
/// please: a Hill switch's K = 1 lies between two grid points an octave apart, the criterion
/// falling away from it to 2.5.
const GRID: (f64, f64) = (0.125, 8.0);

/// Grid points to the octave: a quarter-octave (19 %) apart.
const PER_OCTAVE: usize = 4;

/// Golden-section steps refining the grid's best K within a grid step each side: to 0.01 % of
/// K, below which a noise-free record's re-simulation no longer tells.
const REFINE: usize = 16;

/// How a variable saturates: one positive in every row (a population, a concentration) as
/// x/(x + K) and its kin ([`crate::term::saturations`]), one of either sign (a command, a
/// voltage) as tanh(x/K).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    Rational,
    Odd,
}

/// The forms tried, in words.
const FAMILY: &str = "saturating rates among the candidates (x/(x + K), x·y/(x + K), x²/(x² + K²) of a variable positive in every row, tanh(x/K) of one of either sign)";

/// A variable's saturation: its name, K (its half-saturation, or the scale tanh divides it
/// by) and shape.
type Saturation = (String, f64, Shape);

/// The polynomial library's recipe `polynomials` (the laws' stage having kept it, whose kept
/// start fails the stand-in checks `flags`) and the system identified again (`again`) with
/// the saturating forms of the variables of `model`'s `outline` whose scan over `frames`
/// finds them: which to keep, said in a note ([`laws::kept`]); where the scan finds none,
/// said so.
pub(super) fn stage(
    polynomials: Recipe,
    model: &Model,
    outline: &crate::model::Outline,
    frames: &[Frame],
    settings: &RecipeSettings,
    flags: &[String],
    again: &dyn Fn(&Model) -> Result<Recipe, RecipeError>,
) -> Recipe {
    let variables = laws::own_variables(model, outline);
    let scaled: Vec<Saturation> =
        variables.iter().filter_map(|v| scale(frames, v).map(|(k, s)| (v.clone(), k, s))).collect();
    if scaled.is_empty() {
        return polynomials;
    }
    let Some(found) = scanned(&polynomials, model, &variables, &scaled, settings) else {
        let mut polynomials = polynomials;
        polynomials.say(format!(
            "with {FAMILY} of {}, K scanned from an eighth to eight times its median, none lowers the regression's information criterion by {CLEARLY} or more at any K: the polynomials kept, as flagged",
            scaled.iter().map(|(v, _, _)| format!("`{v}`")).collect::<Vec<_>>().join(", ")
        ));
        return polynomials;
    };
    let forms = saturating_forms(model, &found, &variables);
    if forms.is_empty() {
        return polynomials;
    }
    let family = format!(
        "{FAMILY} ({}, K found by a scan of the regression's information criterion)",
        found
            .iter()
            .map(|(v, k, s)| format!(
                "`{v}` {} at K = {}",
                if *s == Shape::Odd { "as tanh" } else { "as x/(x + K)" },
                crate::identify::num(*k)
            ))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let extended = match with_forms(model, &forms, false) {
        Some(extended) => extended,
        None => return polynomials,
    };
    let tried = Tried { laws: &forms, flags, powers: &[], family, beside: false };
    laws::kept(polynomials, again(&extended), &tried).0
}

/// How variable `name` may saturate over every row of `frames`, with the scale its K is
/// scanned about: where it is positive in each (finite, above 0), as x/(x + K) about its
/// median; else as tanh(x/K) about its magnitude's median. `None` where no run records it, a
/// value is not finite, or it is mostly 0.
fn scale(frames: &[Frame], name: &str) -> Option<(f64, Shape)> {
    let mut values: Vec<f64> = Vec::new();
    for frame in frames {
        values.extend_from_slice(frame.column(name)?);
    }
    if values.is_empty() || !values.iter().all(|v| v.is_finite()) {
        return None;
    }
    let shape = if values.iter().all(|v| *v > 0.0) { Shape::Rational } else { Shape::Odd };
    let mut magnitudes: Vec<f64> = values.iter().map(|v| v.abs()).collect();
    magnitudes.sort_by(f64::total_cmp);
    let median = magnitudes[magnitudes.len() / 2];
    (median > 0.0).then_some((median, shape))
}

/// The saturating forms of each variable of `found` at its K, among `variables`, as the
/// model's vocabulary writes them.
fn saturating_forms(model: &Model, found: &[Saturation], variables: &[String]) -> Vec<String> {
    found
        .iter()
        .flat_map(|(v, k, shape)| match shape {
            Shape::Rational => crate::term::saturations(v, *k, variables),
            Shape::Odd => vec![crate::term::odd_saturation(v, *k)],
        })
        .filter_map(|f| model.vocabulary.parse(&f).ok().map(|t| t.to_string()))
        .collect()
}

/// `model` with `forms` among the candidates of every identified equation; with `every`,
/// each equation fitted on every candidate (least squares, none left out but the collinear).
fn with_forms(model: &Model, forms: &[String], every: bool) -> Option<Model> {
    model
        .edit(|file| {
            for equation in file.equations.values_mut().filter(|e| e.identify) {
                if every {
                    let all = crate::select::Stlsq { threshold: Some(0.0), ..Default::default() };
                    equation.backend = Some(crate::select::Backend::Stlsq(all));
                }
                for form in forms {
                    if !equation.candidates.contains(form) {
                        equation.candidates.push(form.clone());
                    }
                }
            }
        })
        .ok()
}

/// The variables of `scaled` (with their scales and shapes) that saturate, each with its K:
/// in turn, the one whose forms lower the regression's information criterion on the kept
/// start's rows of `polynomials` most, while they do so [`CLEARLY`]. A variable's K is the
/// best of [`GRID`] by the terms the selection keeps, refined within a grid step by golden
/// section on every candidate fitted together (smooth in K, where the terms a selection keeps
/// jump) and taken where the selection's criterion there is lower still. `None` where none
/// saturates, or the rows cannot be fitted so.
fn scanned(
    polynomials: &Recipe,
    model: &Model,
    variables: &[String],
    scaled: &[Saturation],
    settings: &RecipeSettings,
) -> Option<Vec<Saturation>> {
    let start = polynomials.kept();
    let differentiator = start::derivative_method(&start.derivative).ok()?;
    let how = ModelIdentification {
        equations: model.identifiable(),
        differentiator: differentiator.as_ref(),
        intercept: settings.intercept,
        target: None,
    };
    // each equation's rows counted as independent once per its residuals' correlation time,
    // the polynomials' throughout, so that every K is judged on one scale
    let correlation: Vec<(String, f64)> =
        start.fits.iter().map(|(n, f)| (n.clone(), f.correlation_time.unwrap_or(1.0).max(1.0))).collect();
    let score = |found: &[Saturation], every: bool| -> Option<f64> {
        let extended = with_forms(model, &saturating_forms(model, found, variables), every)?;
        let selections = select_model(&extended, &start.prepared, &how).ok()?;
        information(&selections, &correlation)
    };
    let mut best = score(&[], false)?;
    let mut found: Vec<Saturation> = Vec::new();
    loop {
        let with = |name: &str, k: f64, shape: Shape, every: bool| {
            let mut h = found.clone();
            h.push((name.to_string(), k, shape));
            score(&h, every).unwrap_or(f64::INFINITY)
        };
        let mut round: Option<(f64, &str, f64, Shape)> = None;
        for (name, about, shape) in scaled.iter().filter(|(n, _, _)| !found.iter().any(|(h, _, _)| h == n)) {
            let shape = *shape;
            let with = |k: f64, every: bool| with(name, k, shape, every);
            let octaves = (GRID.1 / GRID.0).log2().round() as usize;
            let grid: Vec<f64> = (0..=octaves * PER_OCTAVE)
                .map(|i| about * GRID.0 * 2f64.powf(i as f64 / PER_OCTAVE as f64))
                .collect();
            let Some((at, k)) =
                grid.par_iter().map(|k| (with(*k, false), *k)).min_by(|a, b| a.0.total_cmp(&b.0))
            else {
                continue;
            };
            let fine = refined(&|k| with(k, true), k, with(k, true));
            let (selected, k) = match with(fine, false) {
                s if s < at => (s, fine),
                _ => (at, k),
            };
            if round.is_none_or(|(r, _, _, _)| selected < r) {
                round = Some((selected, name, k, shape));
            }
        }
        match round {
            Some((s, name, k, shape)) if best - s > CLEARLY => {
                found.push((name.to_string(), k, shape));
                best = s;
            }
            _ => break,
        }
    }
    (!found.is_empty()).then_some(found)
}

/// The K within a grid step of `k` (whose criterion is `at_k`) that lowers `criterion` most, by
/// golden section on ln K.
fn refined(criterion: &dyn Fn(f64) -> f64, k: f64, at_k: f64) -> f64 {
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    let step = std::f64::consts::LN_2 / PER_OCTAVE as f64;
    let (mut a, mut b) = (k.ln() - step, k.ln() + step);
    let mut c = b - golden * (b - a);
    let mut d = a + golden * (b - a);
    let (mut fc, mut fd) = (criterion(c.exp()), criterion(d.exp()));
    for _ in 0..REFINE {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - golden * (b - a);
            fc = criterion(c.exp());
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + golden * (b - a);
            fd = criterion(d.exp());
        }
    }
    let (x, fx) = if fc < fd { (c, fc) } else { (d, fd) };
    if fx < at_k {
        x.exp()
    } else {
        k
    }
}

/// The Bayesian information criterion of each equation's `selections` ([`laws::information`]),
/// summed: each counted in its rows over its residuals' `correlation` time (the independent
/// ones).
fn information(selections: &[(String, Selection)], correlation: &[(String, f64)]) -> Option<f64> {
    let mut total = 0.0;
    for (name, selection) in selections {
        let tau = correlation.iter().find(|(n, _)| n == name).map_or(1.0, |(_, t)| *t);
        total += laws::information(selection, selection.rows as f64 / tau)?;
    }
    Some(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The golden section finds the least of a criterion smooth in ln K within a grid step of
    /// where it starts, and keeps its start where nothing there is lower.
    #[test]
    fn the_golden_section_finds_the_least_within_a_step() {
        let bowl = |k: f64| (k.ln() - 1.3f64.ln()).powi(2);
        let k = refined(&bowl, 1.2, bowl(1.2));
        assert!((k / 1.3 - 1.0).abs() < 1e-4, "{k}");
        // beyond a grid step (19 %) the least is not reached: its edge, nearest it
        let k = refined(&bowl, 1.0, bowl(1.0));
        assert!((k / 2f64.powf(0.25) - 1.0).abs() < 1e-3, "{k}");
        // a start lower than all about it is kept
        assert_eq!(refined(&|k: f64| if k == 2.0 { -1.0 } else { 0.0 }, 2.0, -1.0), 2.0);
    }

    /// A variable positive in every row of every run saturates as x/(x + K) about its median,
    /// one of either sign as tanh(x/K) about its magnitude's.
    #[test]
    fn a_variable_saturates_by_its_sign() {
        let run = |x: Vec<f64>| {
            let t: Vec<f64> = (0..x.len()).map(|k| k as f64).collect();
            let mut f = Frame::new("run.csv", "t", t).unwrap();
            f.push("x", x).unwrap();
            f
        };
        assert_eq!(
            scale(&[run(vec![3.0, 1.0, 2.0]), run(vec![5.0, 4.0])], "x"),
            Some((3.0, Shape::Rational))
        );
        assert_eq!(scale(&[run(vec![3.0, -1.0]), run(vec![0.0, -4.0])], "x"), Some((3.0, Shape::Odd)));
        assert_eq!(scale(&[run(vec![0.0, 0.0, 1.0])], "x"), None);
        assert_eq!(scale(&[run(vec![3.0, 1.0])], "y"), None);
    }
}
