//! A model's equations as an ODE system ẋ = f(x, input; parameters).

use std::collections::BTreeMap;

use super::SimError;
use crate::term::{Library, RowScratch, Source, Tangents};

/// The compiled right-hand side of a model with its states, inputs and parameters.
#[derive(Clone, Debug)]
pub struct System {
    /// State names, in integration order.
    pub states: Vec<String>,
    /// Input names.
    pub inputs: Vec<String>,
    /// Lower and upper bounds per state (±∞ when not declared).
    pub bounds: Vec<(f64, f64)>,
    /// The adaptive integrator's tolerances (the model's own, else the defaults).
    pub tolerances: super::Tolerances,
    /// Each state's size, in its unit, that the absolute tolerance is counted in (empty: 1
    /// each, the tolerance in the states' own units). A caller that knows how large the
    /// states run (from records, [`sizes_of`]) sets it, so that concentrations of 1e-6 mol/L
    /// are followed as closely as positions of metres: an absolute 1e-7 would be a tenth of them.
    pub sizes: Vec<f64>,
    /// How much later than given each input acts, s (empty where none does: a dead time).
    pub delays: Vec<f64>,
    /// The time constant of the first-order lag each input acts through, s (empty where none
    /// does).
    pub lags: Vec<f64>,
    rhs: Library,
    /// (scratch slot, state index) and (scratch slot, input index) of the library inputs
    /// that change from row to row; parameters (scratch slot, parameter index) sit in the
    /// workspace from its creation.
    state_slots: Vec<(usize, usize)>,
    input_slots: Vec<(usize, usize)>,
    param_slots: Vec<(usize, usize)>,
    /// What each of the library's inputs is, in its order (for evaluating many rows at once).
    reads: Vec<Slot>,
    param_names: Vec<String>,
    params: Vec<f64>,
}

#[derive(Clone, Copy, Debug)]
enum Slot {
    State(usize),
    Input(usize),
    Param(usize),
}

/// Each state's size ([`System::sizes`]) from how large it is known to run (its largest
/// magnitude in records, or its initial value), in state order: never above 1, so a state in
/// large units keeps the absolute tolerance in its own unit (its relative one governs there) and
/// nothing is followed less closely than before; one known only as 0 is taken as small as the
/// smallest other (a product that starts at 0 among reactants of 1e-6 mol/L), or 1.
pub fn sizes_of(magnitudes: &[f64]) -> Vec<f64> {
    let known = |m: f64| m.is_finite() && m > 0.0;
    let least = magnitudes.iter().copied().filter(|&m| known(m)).fold(1.0f64, f64::min);
    magnitudes.iter().map(|&m| if known(m) { m.min(1.0) } else { least }).collect()
}

/// What the simulator needs of a model: its states (in integration order, with bounds), inputs,
/// parameters and the compiled right-hand side. A model file implements it; so can anything
/// else that yields ẋ = f(x, input; parameters) as terms, so the simulator depends on neither
/// model files nor the regression back-ends.
pub trait RightHandSide {
    /// Where it comes from, for messages (a model file's path).
    fn origin(&self) -> &str;
    /// State names in integration order with their (lower, upper) bounds (±∞ if none).
    fn states(&self) -> Result<Vec<(String, f64, f64)>, SimError>;
    /// Input names.
    fn inputs(&self) -> Vec<String>;
    /// Parameter values by name.
    fn parameters(&self) -> BTreeMap<String, f64>;
    /// ẋ of each state as one compiled library, one output per state in `states` order;
    /// with `with_intercept` each equation's stored constant b0 included.
    fn compile(&self, with_intercept: bool) -> Result<Library, SimError>;
    /// The adaptive integrator's tolerances this model asks for.
    fn tolerances(&self) -> super::Tolerances {
        super::Tolerances::default()
    }
    /// How much later than given each input acts, s, in `inputs` order (a dead time; none by
    /// default).
    fn delays(&self) -> Vec<f64> {
        Vec::new()
    }
    /// The time constant of the first-order lag each input acts through, s, in `inputs` order
    /// (an actuator's; none by default).
    fn lags(&self) -> Vec<f64> {
        Vec::new()
    }
}

impl System {
    /// Compiles a right-hand side (a model). `parameters` override its values.
    pub fn new<R: RightHandSide + ?Sized>(
        model: &R,
        parameters: &BTreeMap<String, f64>,
        with_intercept: bool,
    ) -> Result<System, SimError> {
        let declared = model.states()?;
        let states: Vec<String> = declared.iter().map(|(n, _, _)| n.clone()).collect();
        let bounds: Vec<(f64, f64)> = declared.iter().map(|(_, lo, hi)| (*lo, *hi)).collect();
        let inputs = model.inputs();
        let mut values = model.parameters();
        for (name, value) in parameters {
            let Some(slot) = values.get_mut(name) else {
                return Err(SimError::Settings(format!(
                    "{}: `{name}` is not a parameter of the model ({})",
                    model.origin(),
                    model.parameters().keys().cloned().collect::<Vec<_>>().join(", ")
                )));
            };
            *slot = *value;
        }
        let param_names: Vec<String> = values.keys().cloned().collect();
        let rhs = model.compile(with_intercept)?;
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
                            model.origin()
                        ))
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
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
        let per_input = |values: Vec<f64>| match values.iter().any(|d| *d > 0.0) {
            true => (0..inputs.len()).map(|k| values.get(k).copied().unwrap_or(0.0)).collect(),
            false => Vec::new(),
        };
        let (delays, lags) = (per_input(model.delays()), per_input(model.lags()));
        Ok(System {
            states,
            inputs,
            bounds,
            tolerances: model.tolerances(),
            sizes: Vec::new(),
            delays,
            lags,
            rhs,
            state_slots,
            input_slots,
            param_slots,
            reads: map,
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

    /// Each state's absolute tolerance: the tolerances' `atol` in units of its size.
    pub fn absolute_tolerances(&self) -> Vec<f64> {
        (0..self.dim()).map(|i| self.tolerances.atol * self.sizes.get(i).copied().unwrap_or(1.0)).collect()
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
        self.load(x, input, ws);
        self.rhs.eval_row_prepared(&mut ws.scratch, dx);
    }

    /// The states and inputs into the workspace's slots (the parameters are there already).
    #[inline(always)]
    fn load(&self, x: &[f64], input: &[f64], ws: &mut Workspace) {
        for &(slot, i) in &self.state_slots {
            self.rhs.set_input(&mut ws.scratch, slot, x[i]);
        }
        for &(slot, i) in &self.input_slots {
            self.rhs.set_input(&mut ws.scratch, slot, input[i]);
        }
    }

    /// The directions of [`System::derivatives_and_partials`]: the states `states` (by index)
    /// and then the parameters `parameters` (by name), in that order. A state the right-hand
    /// side does not read has derivatives zero.
    pub fn partials(&self, states: &[usize], parameters: &[String]) -> Result<Tangents, SimError> {
        let mut slots: Vec<Option<usize>> = states
            .iter()
            .map(|&c| self.state_slots.iter().find(|(_, i)| *i == c).map(|(slot, _)| *slot))
            .collect();
        for name in parameters {
            let i = self.param_names.iter().position(|n| n == name).ok_or_else(|| {
                SimError::Settings(format!("`{name}` is not a parameter ({})", self.param_names.join(", ")))
            })?;
            slots.push(self.param_slots.iter().find(|(_, p)| *p == i).map(|(slot, _)| *slot));
        }
        Ok(self.rhs.tangents(&slots))
    }

    /// ẋ = f(x, input) and its partial derivatives with respect to the directions of
    /// `tangents` (made by [`System::partials`]): `partials` row-major, a row per state.
    pub fn derivatives_and_partials(
        &self,
        x: &[f64],
        input: &[f64],
        ws: &mut Workspace,
        tangents: &mut Tangents,
        dx: &mut [f64],
        partials: &mut [f64],
    ) {
        self.load(x, input, ws);
        self.rhs.eval_row_tangents(&mut ws.scratch, tangents, dx, partials);
    }

    /// ẋ on many rows at once, one column per state (per output of the compiled right-hand
    /// side, where it yields more than ẋ), from columns of the states and the inputs (in the
    /// system's orders, all of one length): the compiled terms evaluated block by block, about
    /// twice as fast per row as one row at a time.
    ///
    /// # Panics
    /// Where a state's or an input's column is missing or the columns' lengths differ.
    pub fn derivatives_on_columns(&self, states: &[&[f64]], inputs: &[&[f64]]) -> Vec<Vec<f64>> {
        assert!(
            states.len() == self.dim() && inputs.len() == self.inputs.len(),
            "{} state and {} input columns for {} states and {} inputs",
            states.len(),
            inputs.len(),
            self.dim(),
            self.inputs.len()
        );
        let n = states.first().or(inputs.first()).map_or(0, |c| c.len());
        assert!(states.iter().chain(inputs).all(|c| c.len() == n), "columns of different lengths");
        let mut out = vec![Vec::with_capacity(n); self.rhs.len()];
        if n == 0 {
            return out;
        }
        let sources: Vec<Source<'_>> = self
            .reads
            .iter()
            .map(|r| match *r {
                Slot::State(i) => Source::Column(states[i]),
                Slot::Input(k) => Source::Column(inputs[k]),
                Slot::Param(p) => Source::Constant(self.params[p]),
            })
            .collect();
        self.rhs.for_each_block(&sources, 0..n, |_, columns| {
            for (o, c) in out.iter_mut().zip(columns) {
                o.extend_from_slice(c);
            }
        });
        out
    }

    /// ẋ on every row of a measured run, one column per state: the states and inputs read
    /// from the frame's columns by name (the one-step prediction a regression of the
    /// derivatives is fitted to, where the simulation integrates it).
    pub fn derivatives_on(&self, frame: &crate::data::Frame) -> Result<Vec<Vec<f64>>, SimError> {
        let read = |names: &[String]| -> Result<Vec<&[f64]>, SimError> {
            names.iter().map(|n| Ok(frame.require(n)?)).collect()
        };
        let (states, inputs) = (read(&self.states)?, read(&self.inputs)?);
        Ok(self.derivatives_on_columns(&states, &inputs))
    }

    /// State names in integration order.
    pub fn state_names(&self) -> &[String] {
        &self.states
    }

    /// Whether the right-hand side reads state `i` at all (positions usually are not read: a
    /// derivative with respect to them is zero).
    pub fn reads_state(&self, i: usize) -> bool {
        self.state_slots.iter().any(|&(_, s)| s == i)
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
