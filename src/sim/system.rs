//! A model's equations as an ODE system ẋ = f(x, input; parameters).

use std::collections::BTreeMap;

use super::SimError;
use crate::model::Model;
use crate::term::{Library, RowScratch};

/// The compiled right-hand side of a model with its states, inputs and parameters.
#[derive(Clone, Debug)]
pub struct System {
    /// State names, in integration order.
    pub states: Vec<String>,
    /// Input names.
    pub inputs: Vec<String>,
    /// Lower and upper bounds per state (±∞ when not declared).
    pub bounds: Vec<(f64, f64)>,
    rhs: Library,
    /// (scratch slot, state index) and (scratch slot, input index) of the library inputs
    /// that change from row to row; parameters (scratch slot, parameter index) sit in the
    /// workspace from its creation.
    state_slots: Vec<(usize, usize)>,
    input_slots: Vec<(usize, usize)>,
    param_slots: Vec<(usize, usize)>,
    param_names: Vec<String>,
    params: Vec<f64>,
}

#[derive(Clone, Copy, Debug)]
enum Slot {
    State(usize),
    Input(usize),
    Param(usize),
}

impl System {
    /// Compiles a model's equations. `parameters` override the file's values.
    pub fn new(
        model: &Model,
        parameters: &BTreeMap<String, f64>,
        with_intercept: bool,
    ) -> Result<System, SimError> {
        let states: Vec<String> = model.equations.iter().map(|e| e.state.clone()).collect();
        let missing: Vec<&str> = model
            .spec
            .states
            .iter()
            .map(|s| s.name.as_str())
            .filter(|s| !states.iter().any(|t| t == s))
            .collect();
        if !missing.is_empty() {
            return Err(SimError::Settings(format!(
                "{}: state(s) {} have no equation, so the model cannot be simulated",
                model.path,
                missing.join(", ")
            )));
        }
        let inputs: Vec<String> = model.spec.inputs.iter().map(|i| i.name.clone()).collect();
        let mut values = model.parameter_values();
        for (name, value) in parameters {
            let Some(slot) = values.get_mut(name) else {
                return Err(SimError::Settings(format!(
                    "{}: `{name}` is not a parameter of the model ({})",
                    model.path,
                    model.parameter_values().keys().cloned().collect::<Vec<_>>().join(", ")
                )));
            };
            *slot = *value;
        }
        let param_names: Vec<String> = values.keys().cloned().collect();
        let rhs = model.compile_rhs(with_intercept)?;
        let map = rhs
            .inputs()
            .iter()
            .map(|n| {
                states
                    .iter()
                    .position(|s| s == n)
                    .map(Slot::State)
                    .or_else(|| inputs.iter().position(|s| s == n).map(Slot::Input))
                    .or_else(|| param_names.iter().position(|s| s == n).map(Slot::Param))
                    .ok_or_else(|| {
                        SimError::Settings(format!(
                            "{}: `{n}` is neither a state, an input nor a parameter",
                            model.path
                        ))
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let bounds = states
            .iter()
            .map(|s| {
                let spec = model.spec.states.iter().find(|t| &t.name == s);
                (
                    spec.and_then(|t| t.min).unwrap_or(f64::NEG_INFINITY),
                    spec.and_then(|t| t.max).unwrap_or(f64::INFINITY),
                )
            })
            .collect();
        let slot =
            |j: usize| rhs.input_slot(j).ok_or_else(|| SimError::Settings(format!("input {j} has no slot")));
        let (mut state_slots, mut input_slots, mut param_slots) = (Vec::new(), Vec::new(), Vec::new());
        for (j, m) in map.iter().enumerate() {
            match m {
                Slot::State(i) => state_slots.push((slot(j)?, *i)),
                Slot::Input(i) => input_slots.push((slot(j)?, *i)),
                Slot::Param(i) => param_slots.push((slot(j)?, *i)),
            }
        }
        Ok(System {
            states,
            inputs,
            bounds,
            rhs,
            state_slots,
            input_slots,
            param_slots,
            param_names,
            params: values.into_values().collect(),
        })
    }

    /// The same system with some parameters changed (e.g. a run's own approach speed u0).
    pub fn with_parameters(&self, parameters: &BTreeMap<String, f64>) -> Result<System, SimError> {
        let mut out = self.clone();
        for (name, value) in parameters {
            let i = self.param_names.iter().position(|n| n == name).ok_or_else(|| {
                SimError::Settings(format!("`{name}` is not a parameter ({})", self.param_names.join(", ")))
            })?;
            out.params[i] = *value;
        }
        Ok(out)
    }

    /// Number of states.
    pub fn dim(&self) -> usize {
        self.states.len()
    }

    /// Scratch space for [`System::derivatives`], with the parameters in place.
    pub fn workspace(&self) -> Workspace {
        let mut scratch = self.rhs.scratch();
        for &(slot, i) in &self.param_slots {
            self.rhs.set_input(&mut scratch, slot, self.params[i]);
        }
        Workspace { scratch }
    }

    /// ẋ = f(x, input).
    #[inline]
    pub fn derivatives(&self, x: &[f64], input: &[f64], ws: &mut Workspace, dx: &mut [f64]) {
        for &(slot, i) in &self.state_slots {
            self.rhs.set_input(&mut ws.scratch, slot, x[i]);
        }
        for &(slot, i) in &self.input_slots {
            self.rhs.set_input(&mut ws.scratch, slot, input[i]);
        }
        self.rhs.eval_row_prepared(&mut ws.scratch, dx);
    }

    /// Index of a state by name.
    pub fn state_index(&self, name: &str) -> Option<usize> {
        self.states.iter().position(|s| s == name)
    }

    /// Index of an input by name.
    pub fn input_index(&self, name: &str) -> Option<usize> {
        self.inputs.iter().position(|s| s == name)
    }
}

/// Per-thread scratch of a [`System`].
#[derive(Clone, Debug)]
pub struct Workspace {
    scratch: RowScratch,
}
