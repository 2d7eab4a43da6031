//! Identification of one equation from one or several runs: evaluate the candidate terms on
//! every run (with the run's own parameters, e.g. its `u0`), take the target as a column or
//! the derivative of a state, accumulate the sufficient statistics run by run (the paper's
//! "Komb. Daten" is simply all runs together) and hand them to a back-end.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::data::{DataError, Differentiator, Frame};
use crate::select::{Accumulator, Moments, Problem, SelectError, Selection, Selector};
use crate::term::{Library, Term, TermError, Vocabulary};

/// What the equation explains.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// A column of the data (e.g. measured accelerations `r_dot`).
    Column(String),
    /// The time derivative of a column, computed by the chosen differentiator.
    Derivative(String),
}

impl Target {
    /// Parses `dX/dt` as the derivative of X, anything else as a column name.
    pub fn parse(text: &str) -> Target {
        match text.strip_prefix('d').and_then(|s| s.strip_suffix("/dt")) {
            Some(state) if !state.is_empty() => Target::Derivative(state.to_string()),
            _ => Target::Column(text.to_string()),
        }
    }
}

impl std::fmt::Display for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Target::Column(c) => write!(f, "{c}"),
            Target::Derivative(s) => write!(f, "d{s}/dt"),
        }
    }
}

/// Where a parameter's value comes from in each run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParamValue {
    /// The same value for every run.
    Value(f64),
    /// A rule evaluated on each run: `first:u` is the run's first value of `u`.
    Rule(String),
}

impl ParamValue {
    /// Checks a rule's syntax without data.
    pub fn check_rule(&self, name: &str) -> Result<(), String> {
        match self {
            ParamValue::Value(_) => Ok(()),
            ParamValue::Rule(rule) => match rule.split_once(':') {
                Some(("first", col)) if !col.is_empty() => Ok(()),
                Some(("mean", rest)) if !rest.is_empty() => match rest.split_once(':') {
                    Some((c, secs)) if !c.is_empty() && secs.parse::<f64>().is_ok_and(|s| s > 0.0) => Ok(()),
                    Some(_) => Err(format!("parameter `{name}`: `{rule}`: write mean:COLUMN:SECONDS with SECONDS > 0")),
                    None => Ok(()),
                },
                _ => Err(format!(
                    "parameter `{name}`: `{rule}` is neither a number nor `first:COLUMN`, `mean:COLUMN` or `mean:COLUMN:SECONDS`"
                )),
            },
        }
    }

    /// The value in one run.
    pub fn resolve(&self, name: &str, frame: &Frame) -> Result<f64, IdentifyError> {
        match self {
            ParamValue::Value(v) => Ok(*v),
            ParamValue::Rule(rule) => match rule.split_once(':') {
                Some(("first", col)) => Ok(frame.require(col)?[0]),
                Some(("mean", rest)) => {
                    // `mean:u` over the run, `mean:u:2` over its first 2 time units (the approach)
                    let (col, span) = match rest.split_once(':') {
                        Some((c, secs)) => (c, secs.parse::<f64>().ok().filter(|s| *s > 0.0)),
                        None => (rest, None),
                    };
                    let c = frame.require(col)?;
                    let t = frame.time();
                    let n = span.map_or(c.len(), |s| t.iter().take_while(|ti| **ti - t[0] <= s).count().max(1));
                    Ok(c[..n].iter().sum::<f64>() / n as f64)
                }
                _ => Err(IdentifyError::Parameter(format!(
                    "parameter `{name}`: `{rule}` is neither a number nor `first:COLUMN`, `mean:COLUMN` or `mean:COLUMN:SECONDS`"
                ))),
            },
        }
    }
}

/// Why identification failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IdentifyError {
    /// In a term.
    #[error(transparent)]
    Term(#[from] TermError),
    /// In the data.
    #[error(transparent)]
    Data(#[from] DataError),
    /// In the regression.
    #[error(transparent)]
    Select(#[from] SelectError),
    /// A term evaluates to NaN or ±∞ on some row.
    #[error(
        "{file}: row {row}: term `{term}` evaluates to {value} (check its denominators and the data there)"
    )]
    NonFinite {
        /// The run.
        file: String,
        /// 1-based row.
        row: usize,
        /// The term.
        term: String,
        /// Its value.
        value: f64,
    },
    /// A parameter could not be set.
    #[error("{0}")]
    Parameter(String),
    /// Something the caller asked for does not fit together.
    #[error("{0}")]
    Setup(String),
}

/// The settings shared by the equations of one identification.
pub struct Identification<'a> {
    /// The names terms may use.
    pub vocabulary: &'a Vocabulary,
    /// Per-run parameters.
    pub parameters: &'a BTreeMap<String, ParamValue>,
    /// Derivative method for `Target::Derivative`.
    pub differentiator: &'a dyn Differentiator,
    /// Fit an intercept.
    pub intercept: bool,
    /// A column of row weights (weighted least squares), if any.
    pub weights: Option<String>,
}

/// A fitted equation with its candidates.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Fit {
    /// What was explained.
    pub target: String,
    /// The candidate terms, canonical text, in column order.
    pub candidates: Vec<String>,
    /// The back-end's result.
    pub selection: Selection,
}

impl Identification<'_> {
    /// The per-run parameter values.
    pub fn run_parameters(&self, frame: &Frame) -> Result<BTreeMap<String, f64>, IdentifyError> {
        self.parameters.iter().map(|(n, v)| Ok((n.clone(), v.resolve(n, frame)?))).collect()
    }

    /// The target values of one run.
    pub fn target(&self, target: &Target, frame: &Frame) -> Result<Vec<f64>, IdentifyError> {
        Ok(match target {
            Target::Column(c) => frame.require(c)?.to_vec(),
            Target::Derivative(s) => {
                let x = frame.require(s)?;
                self.differentiator.differentiate(frame.time(), x).map_err(|e| match e {
                    DataError::TooShort { rows, needed, what, .. } => {
                        DataError::TooShort { file: frame.origin().into(), rows, needed, what }
                    }
                    e => e,
                })?
            }
        })
    }

    /// Sufficient statistics of the compiled candidates against the target on one run.
    pub fn moments(
        &self,
        library: &Library,
        target: &Target,
        frame: &Frame,
    ) -> Result<Moments, IdentifyError> {
        let mut acc = Accumulator::new(library.len());
        self.accumulate(library, target, frame, &mut acc)?;
        Ok(acc.finish())
    }

    /// Adds one run's rows to an accumulator (runs simply add up: "Komb. Daten").
    pub fn accumulate(
        &self,
        library: &Library,
        target: &Target,
        frame: &Frame,
        acc: &mut Accumulator,
    ) -> Result<(), IdentifyError> {
        let y = self.target(target, frame)?;
        let params = self.run_parameters(frame)?;
        let sources = library.bind(&|n| frame.column(n), &|n| params.get(n).copied())?;
        let weights = match &self.weights {
            Some(col) => {
                let w = frame.require(col)?;
                if let Some(i) = w.iter().position(|w| *w < 0.0) {
                    return Err(IdentifyError::Setup(format!(
                        "{}: row {}: weight `{col}` = {} is negative",
                        frame.origin(),
                        i + 1,
                        w[i]
                    )));
                }
                Some(w)
            }
            None => None,
        };
        let mut bad: Option<IdentifyError> = None;
        library.for_each_block(&sources, frame.len(), |start, rows, block| {
            if bad.is_some() {
                return;
            }
            if let Some(i) = block.iter().position(|v| !v.is_finite()) {
                bad = Some(IdentifyError::NonFinite {
                    file: frame.origin().into(),
                    row: start + i % rows + 1,
                    term: library.terms()[i / rows].to_string(),
                    value: block[i],
                });
                return;
            }
            acc.push(block, &y[start..start + rows], weights.map(|w| &w[start..start + rows]));
        });
        match bad {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Identifies one equation from all runs together ("Komb. Daten").
    pub fn fit(
        &self,
        target: &Target,
        candidates: &[Term],
        forced: &[Term],
        excluded: &[Term],
        frames: &[Frame],
        backend: &dyn Selector,
    ) -> Result<Fit, IdentifyError> {
        if frames.is_empty() {
            return Err(IdentifyError::Setup("no data: give at least one run".into()));
        }
        let library = Library::compile(candidates, self.vocabulary)?;
        // per run, for the back-ends that cross-validate; together they are "Komb. Daten"
        let folds =
            frames.iter().map(|f| self.moments(&library, target, f)).collect::<Result<Vec<_>, _>>()?;
        let mut moments = Moments::new(candidates.len());
        for f in &folds {
            moments.merge(f);
        }
        let names: Vec<String> = candidates.iter().map(Term::to_string).collect();
        let index_of = |t: &Term, role: &str| {
            candidates
                .iter()
                .position(|c| c == t)
                .ok_or_else(|| IdentifyError::Setup(format!("{role} term `{t}` is not among the candidates")))
        };
        let forced = forced.iter().map(|t| index_of(t, "forced")).collect::<Result<Vec<_>, _>>()?;
        let excluded = excluded.iter().map(|t| index_of(t, "excluded")).collect::<Result<Vec<_>, _>>()?;
        let problem = Problem {
            moments: &moments,
            names: &names,
            forced: &forced,
            excluded: &excluded,
            intercept: self.intercept,
        };
        let selection = backend.select_with_folds(&problem, &folds)?;
        Ok(Fit { target: target.to_string(), candidates: names, selection })
    }
}

/// Identifies one equation of a model from runs: candidates, forced and excluded terms and
/// the back-end come from the model file; the target is the column `<state>_dot` where every
/// run has it, else the derivative of the state.
pub fn fit_equation(
    model: &crate::model::Model,
    equation: &str,
    frames: &[Frame],
    differentiator: &dyn Differentiator,
    intercept: bool,
    target: Option<Target>,
) -> Result<Fit, IdentifyError> {
    let eq = model
        .equation(equation)
        .ok_or_else(|| IdentifyError::Setup(format!("{}: no equation `{equation}`", model.path)))?;
    if eq.candidates.is_empty() {
        return Err(IdentifyError::Setup(format!("{}: equation `{equation}` has no candidates", model.path)));
    }
    let target = target.unwrap_or_else(|| {
        let column = format!("{}_dot", eq.state);
        if frames.iter().all(|f| f.column(&column).is_some()) {
            Target::Column(column)
        } else {
            Target::Derivative(eq.state.clone())
        }
    });
    let rules = model.parameter_rules();
    let identification = Identification {
        vocabulary: &model.vocabulary,
        parameters: &rules,
        differentiator,
        intercept,
        weights: None,
    };
    let backend = eq.backend.build()?;
    identification.fit(&target, &eq.candidates, &eq.forced, &eq.excluded, frames, backend.as_ref())
}

/// The identified coefficients of a fit, as a model stores them (term, value, std. error).
pub fn coefficients_of(
    fit: &Fit,
    vocabulary: &Vocabulary,
) -> Result<Vec<(Term, f64, Option<f64>)>, IdentifyError> {
    fit.selection
        .terms
        .iter()
        .map(|t| Ok((vocabulary.parse(&t.term)?, t.coefficient, Some(t.std_error))))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_over_the_first_seconds() {
        let mut f = Frame::new("run", "t", vec![0.0, 1.0, 2.0, 3.0, 4.0]).unwrap();
        f.push("u", vec![2.0, 2.2, 2.4, 1.0, 1.0]).unwrap();
        let v = ParamValue::Rule("mean:u:2".into()).resolve("u0", &f).unwrap();
        assert!((v - 2.2).abs() < 1e-15);
        assert!(ParamValue::Rule("mean:u:-1".into()).check_rule("u0").is_err());
        assert!(ParamValue::Rule("mean:u".into()).check_rule("u0").is_ok());
    }

    #[test]
    fn target_syntax() {
        assert_eq!(Target::parse("dr/dt"), Target::Derivative("r".into()));
        assert_eq!(Target::parse("r_dot"), Target::Column("r_dot".into()));
        assert_eq!(Target::parse("d/dt"), Target::Column("d/dt".into()));
    }
}
