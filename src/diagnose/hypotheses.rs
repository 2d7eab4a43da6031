//! The library of candidate effects. Generic: a constant in any equation, each candidate
//! term the model lacks, an offset and a scale error on any input. Plug-ins add their own,
//! with the names their users use (see `ship::hypotheses`).

use serde::Serialize;

use crate::model::Model;

/// What a hypothesis adds to the model.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Effect {
    /// New coefficients: (equation, term) pairs, added to what the model has.
    Terms {
        /// (equation name, term text).
        terms: Vec<(String, String)>,
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
            _ => false,
        }
    }

    /// Number of parameters.
    pub fn parameters(&self) -> usize {
        match &self.effect {
            Effect::Terms { terms } => terms.len(),
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
