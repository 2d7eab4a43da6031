//! A model file as the simulator's right-hand side: its equations' coefficients times their
//! terms are ẋ (`crate::sim` knows only the trait).

use std::collections::BTreeMap;

use super::Model;
use crate::term::Library;

/// A model file is what the simulator integrates: its equations' coefficients times their
/// terms are ẋ.
impl crate::sim::RightHandSide for Model {
    fn origin(&self) -> &str {
        &self.path
    }

    fn delays(&self) -> Vec<f64> {
        self.spec.inputs.iter().map(|i| i.delay).collect()
    }

    fn lags(&self) -> Vec<f64> {
        self.spec.inputs.iter().map(|i| i.lag).collect()
    }

    fn tolerances(&self) -> crate::sim::Tolerances {
        let d = crate::sim::Tolerances::default();
        match &self.spec.simulation {
            Some(s) => {
                crate::sim::Tolerances { rtol: s.rtol.unwrap_or(d.rtol), atol: s.atol.unwrap_or(d.atol) }
            }
            None => d,
        }
    }

    fn states(&self) -> Result<Vec<(String, f64, f64)>, crate::sim::SimError> {
        let missing: Vec<&str> = self
            .spec
            .states
            .iter()
            .map(|s| s.name.as_str())
            .filter(|s| !self.equations.iter().any(|e| e.state == *s))
            .collect();
        if !missing.is_empty() {
            return Err(crate::sim::SimError::Settings(format!(
                "{}: state(s) {} have no equation, so the model cannot be simulated",
                self.path,
                missing.join(", ")
            )));
        }
        Ok(self
            .equations
            .iter()
            .map(|e| {
                let spec = self.spec.states.iter().find(|t| t.name == e.state);
                (
                    e.state.clone(),
                    spec.and_then(|t| t.min).unwrap_or(f64::NEG_INFINITY),
                    spec.and_then(|t| t.max).unwrap_or(f64::INFINITY),
                )
            })
            .collect())
    }

    fn inputs(&self) -> Vec<String> {
        self.spec.inputs.iter().map(|i| i.name.clone()).collect()
    }

    fn parameters(&self) -> BTreeMap<String, f64> {
        self.parameter_values()
    }

    fn compile(&self, with_intercept: bool) -> Result<Library, crate::sim::SimError> {
        Ok(self.compile_rhs(with_intercept)?)
    }
}
