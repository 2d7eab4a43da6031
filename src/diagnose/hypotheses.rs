//! The library of candidate effects. Generic: a constant in any equation, each candidate
//! term the model lacks, an offset and a scale error on any input, and for a model no plug-in
//! names, the products of its variables beyond its candidates and the laws a polynomial only
//! approximates (dry friction, drag, an orifice, a pendulum). Plug-ins add their own, with
//! the names their users use (see `ship::hypotheses`).

use serde::Serialize;

use crate::model::Model;
use crate::term::Term;

/// What a hypothesis adds to the model.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Effect {
    /// New coefficients: (equation, term) pairs, added to what the model has.
    Terms {
        /// (equation name, term text).
        terms: Vec<(String, String)>,
    },
    /// A term beyond its equation's candidates, the equation's own coefficients refitted
    /// with it: it joins the candidates of the model written.
    Beyond {
        /// The equation.
        equation: String,
        /// The new term's text.
        term: String,
        /// The terms of the equation's coefficients, corrected with it.
        refitted: Vec<String>,
    },
    /// An equation's coefficients refitted by output error, nothing added: the baseline a
    /// term beyond the candidates must beat.
    Refit {
        /// The equation.
        equation: String,
        /// The terms of its coefficients.
        refitted: Vec<String>,
    },
    /// The true input is the recorded one plus an offset.
    InputOffset {
        /// The input.
        input: String,
    },
    /// The true input is the recorded one times a factor.
    InputScale {
        /// The input.
        input: String,
    },
}

/// A named effect to test.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Hypothesis {
    /// Name in the report.
    pub name: String,
    /// What it adds.
    pub effect: Effect,
}

impl Hypothesis {
    /// Whether every added term is one of its equation's declared candidates (the model
    /// author's physics) rather than a catch-all such as a constant or an input error.
    pub fn declared(&self, model: &Model) -> bool {
        match &self.effect {
            Effect::Terms { terms } => terms.iter().all(|(eq, t)| {
                let (Some(e), Ok(term)) = (model.equation(eq), model.vocabulary.parse(t)) else {
                    return false;
                };
                e.candidates.contains(&term)
            }),
            Effect::Refit { .. } => true,
            _ => false,
        }
    }

    /// Whether a screening step cannot rank it: a refit moves every coefficient of an
    /// equation, and one Gauss-Newton step from the identified values stops far short of
    /// where it leads (a Duffing's refit: 3 % of the gap after one step, 80 % refined), so
    /// these are always refined.
    pub fn needs_refining(&self) -> bool {
        matches!(self.effect, Effect::Refit { .. } | Effect::Beyond { .. })
    }

    /// The (equation, term) pairs whose coefficients it moves, in the order of its parameters;
    /// empty for an input's error.
    pub fn terms(&self) -> Vec<(String, String)> {
        match &self.effect {
            Effect::Terms { terms } => terms.clone(),
            Effect::Beyond { equation, term, refitted } => {
                std::iter::once(term).chain(refitted).map(|t| (equation.clone(), t.clone())).collect()
            }
            Effect::Refit { equation, refitted } => {
                refitted.iter().map(|t| (equation.clone(), t.clone())).collect()
            }
            _ => vec![],
        }
    }

    /// Number of parameters.
    pub fn parameters(&self) -> usize {
        match &self.effect {
            Effect::Terms { terms } => terms.len(),
            Effect::Beyond { refitted, .. } => 1 + refitted.len(),
            Effect::Refit { refitted, .. } => refitted.len(),
            _ => 1,
        }
    }

    /// Parameters as reported (coefficients, offsets; a scale as its factor).
    pub fn natural(&self, theta: &[f64]) -> Vec<f64> {
        match &self.effect {
            Effect::InputScale { .. } => theta.iter().map(|t| 1.0 + t).collect(),
            _ => theta.to_vec(),
        }
    }

    /// The inverse of [`Hypothesis::natural`].
    pub fn internal(&self, natural: &[f64]) -> Vec<f64> {
        match &self.effect {
            Effect::InputScale { .. } => natural.iter().map(|t| t - 1.0).collect(),
            _ => natural.to_vec(),
        }
    }

    /// (input index, offset) this hypothesis applies.
    pub fn input_offsets(&self, theta: &[f64], model: &Model) -> Vec<(usize, f64)> {
        match &self.effect {
            Effect::InputOffset { input } => {
                input_index(model, input).map(|i| (i, theta[0])).into_iter().collect()
            }
            _ => vec![],
        }
    }

    /// (input index, factor) this hypothesis applies.
    pub fn input_scales(&self, theta: &[f64], model: &Model) -> Vec<(usize, f64)> {
        match &self.effect {
            Effect::InputScale { input } => {
                input_index(model, input).map(|i| (i, 1.0 + theta[0])).into_iter().collect()
            }
            _ => vec![],
        }
    }
}

fn input_index(model: &Model, input: &str) -> Option<usize> {
    model.spec().inputs.iter().position(|i| i.name == input)
}

/// The generic library for a model.
pub fn generic_hypotheses(model: &Model) -> Vec<Hypothesis> {
    let mut out = Vec::new();
    for eq in model.equations().iter().filter(|e| e.identify) {
        out.push(Hypothesis {
            name: format!("constant in {}", eq.name),
            effect: Effect::Terms { terms: vec![(eq.name.clone(), "1".into())] },
        });
        for c in &eq.candidates {
            if eq.coefficient(c) == 0.0 {
                out.push(Hypothesis {
                    name: format!("missing term `{c}` in {}", eq.name),
                    effect: Effect::Terms { terms: vec![(eq.name.clone(), c.to_string())] },
                });
            }
        }
    }
    for i in &model.spec().inputs {
        out.push(Hypothesis {
            name: format!("offset on input {}", i.name),
            effect: Effect::InputOffset { input: i.name.clone() },
        });
        out.push(Hypothesis {
            name: format!("scale error on input {}", i.name),
            effect: Effect::InputScale { input: i.name.clone() },
        });
    }
    out
}

/// Highest degree of the products [`beyond_candidates`] offers (3 for up to this many
/// variables in an equation's candidates, 2 for more: a cubic library of six variables would
/// be 83 hypotheses an equation, each an output-error fit).
const CUBIC_UP_TO: usize = 4;

/// Effects beyond the model's own candidates: in each identified equation, every product of
/// the states and inputs its candidates use, up to degree 3 (2 beyond four variables; an
/// input to the first power), that is not a candidate already. Where the author's library
/// lacks the term the system has (a Duffing oscillator's x³ in a quadratic library), the
/// declared hypotheses cannot name it; this names it as `x^3 in v_dot, beyond the
/// candidates`; and for each state, the laws a cubic stands in for (`sign`, `v*abs(v)`,
/// `sqrt(abs(h))`, `sin`). Each equation's coefficients refitted alone come first: the
/// baseline a new term must beat.
pub fn beyond_candidates(model: &Model) -> Vec<Hypothesis> {
    let spec = model.spec();
    // the states and inputs
    let dynamic: Vec<&str> = model.vocabulary.variables().iter().map(String::as_str).collect();
    let inputs: Vec<&str> = spec.inputs.iter().map(|i| i.name.as_str()).collect();
    let mut out = Vec::new();
    for eq in model.equations().iter().filter(|e| e.identify) {
        let mut vars: Vec<String> = eq
            .candidates
            .iter()
            .flat_map(Term::variables)
            .filter(|v| dynamic.contains(&v.as_str()))
            .collect();
        vars.sort();
        vars.dedup();
        let degree = if vars.len() <= CUBIC_UP_TO { 3 } else { 2 };
        let mut products: Vec<Term> = vec![Term::constant(1.0)];
        let mut all: Vec<Term> = Vec::new();
        for _ in 0..degree {
            // each product once: extend by variables at or after its last factor's
            let mut next = Vec::new();
            for p in &products {
                let factors = p.variables();
                let start = vars.iter().rposition(|v| factors.contains(v)).unwrap_or(0);
                for v in &vars[start..] {
                    // an input enters once: F²·v, where a forcing switches between ±a, is v
                    // but where the replay ramps between samples, and "explains" that ramp
                    if inputs.contains(&v.as_str()) && factors.contains(v) {
                        continue;
                    }
                    if let Ok(t) = p.mul(&Term::var(v)) {
                        if !next.contains(&t) {
                            next.push(t);
                        }
                    }
                }
            }
            all.extend(next.iter().cloned());
            products = next;
        }
        // the equation's own coefficients move with the new term: identified without it, they
        // have taken up what they could of its part (a Duffing's x³ fitted by a stiffer x), and
        // the term alone on top of them explains a fraction of the gap it closes
        let refitted: Vec<String> = eq.coefficients.iter().map(|(t, _, _)| t.to_string()).collect();
        // the baseline each new term must beat: the coefficients refitted alone (a term that
        // only re-weighs them, F²·v where F is ±a, explains what the refit does, with one
        // parameter more)
        if !refitted.is_empty() {
            out.push(Hypothesis {
                name: format!("{}'s coefficients refitted (output error)", eq.name),
                effect: Effect::Refit { equation: eq.name.clone(), refitted: refitted.clone() },
            });
        }
        // the laws a polynomial only approximates, each state's ([`crate::term::laws`])
        for v in vars.iter().filter(|v| !inputs.contains(&v.as_str())) {
            for text in crate::term::laws(v) {
                if let Ok(t) = model.vocabulary.parse(&text) {
                    all.push(t);
                }
            }
        }
        for t in all {
            if eq.candidates.contains(&t) || eq.coefficient(&t) != 0.0 {
                continue;
            }
            out.push(Hypothesis {
                name: format!("`{t}` in {}, beyond the candidates", eq.name),
                effect: Effect::Beyond {
                    equation: eq.name.clone(),
                    term: t.to_string(),
                    refitted: refitted.clone(),
                },
            });
        }
    }
    out
}
