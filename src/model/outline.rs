//! A system known by its records' columns alone: the states whose rates are identified, the
//! inputs that drive them, one library of candidates for every rate. `identify --states` and
//! Python's `Model.from_states` make it a model file, so the identified system is written,
//! simulated, validated and estimated as any other (a whole system at once, as SINDy fits one).

use std::collections::BTreeMap;

use super::{EquationSpec, InputSpec, Meta, Model, ModelError, ModelFile, StateSpec};
use crate::select::Backend;
use crate::term::{polynomial, polynomial_len};

/// The most candidates a polynomial library may give each rate: beyond, the names or the
/// degree are too many for the runs a system is identified from (ten names to degree 3 give
/// 286).
pub const MOST_MONOMIALS: u128 = 1000;

/// The polynomial library's degree where none is given: the ODE benchmark's (benches/odes),
/// whose 37 systems identified whole with it come back as often as equation by equation.
pub const DEFAULT_DEGREE: u32 = 3;

/// The outline of a system named by its columns: what [`Outline::model`] makes a model
/// file of.
#[derive(Clone, Debug, PartialEq)]
pub struct Outline {
    /// What the model is called (`[model] name`).
    pub name: String,
    /// The time column.
    pub time: String,
    /// The states, each one's rate an equation (`x` gives `x_dot`).
    pub states: Vec<String>,
    /// The inputs: known from the runs' records, not integrated.
    pub inputs: Vec<String>,
    /// Every rate's candidate terms; empty: every monomial of the states and inputs to
    /// `degree` ([`crate::term::polynomial`]), the constant among them.
    pub candidates: Vec<String>,
    /// The polynomial library's degree where `candidates` is empty.
    pub degree: u32,
    /// The back-end of every rate; none: sequential thresholding, as for any rate.
    pub backend: Option<Backend>,
}

impl Outline {
    /// The names the candidates may use, the states' and the inputs', each checked to be a
    /// name a term can use, neither the time nor named twice.
    pub fn vocabulary(&self, origin: &str) -> Result<crate::term::Vocabulary, ModelError> {
        let refuse = |message: String| ModelError::Outline { origin: origin.into(), message };
        if self.states.is_empty() {
            return Err(refuse("no state: name the states whose rates to identify".into()));
        }
        let names: Vec<&String> = self.states.iter().chain(&self.inputs).collect();
        let mut vocabulary = crate::term::Vocabulary::new();
        for (k, name) in names.iter().enumerate() {
            if **name == self.time {
                return Err(refuse(format!("`{name}` is the time, neither a state nor an input")));
            }
            if names[..k].contains(name) {
                return Err(refuse(format!("`{name}` is named twice: a name is a state or an input, once")));
            }
            vocabulary.variable(name).map_err(|e| refuse(e.to_string()))?;
        }
        Ok(vocabulary)
    }

    /// The model file of the system: a state and an equation per state with the same
    /// candidates, the constant a candidate rather than a forced intercept (as for any rate),
    /// no coefficient yet, units unknown. `origin` stands for it in errors and in what the
    /// model says it is (`--states x,y,z`).
    pub fn model(&self, origin: &str) -> Result<Model, ModelError> {
        let refuse = |message: String| ModelError::Outline { origin: origin.into(), message };
        let vocabulary = self.vocabulary(origin)?;
        let names: Vec<&String> = self.states.iter().chain(&self.inputs).collect();
        // candidates checked here, so an error names them and not a line of a file nobody wrote
        for term in &self.candidates {
            vocabulary.parse(term).map_err(|e| refuse(format!("candidate `{term}`:\n{e}")))?;
        }
        let (candidates, library) = if self.candidates.is_empty() {
            let count = polynomial_len(names.len(), self.degree);
            if self.degree == 0 {
                return Err(refuse("degree 0 gives the constant alone: give a degree of 1 or more".into()));
            }
            if count > MOST_MONOMIALS {
                return Err(refuse(format!(
                    "{} names to degree {} make {count} candidates for each rate, more than {MOST_MONOMIALS}: name fewer inputs, a lower degree, or the candidates",
                    names.len(),
                    self.degree
                )));
            }
            let list: Vec<&str> = names.iter().map(|n| n.as_str()).collect();
            (
                polynomial(&names, self.degree),
                format!("every monomial of {} to degree {}", list.join(", "), self.degree),
            )
        } else {
            (self.candidates.clone(), format!("{} candidates named", self.candidates.len()))
        };
        let backend = self.backend.clone().unwrap_or_else(Backend::for_rates);
        let spec = ModelFile {
            model: Meta {
                name: self.name.clone(),
                provenance: library,
                notes: vec![format!(
                    "made from columns ({origin}): each state's rate over the same candidates; the units are not known"
                )],
                time: self.time.clone(),
                intercept: false,
                keep_spikes: false,
                intersample: Default::default(),
            },
            states: self
                .states
                .iter()
                .map(|n| StateSpec { name: n.clone(), unit: String::new(), initial: 0.0, min: None, max: None })
                .collect(),
            inputs: self
                .inputs
                .iter()
                .map(|n| InputSpec { name: n.clone(), unit: String::new(), initial: 0.0, delay: 0.0 })
                .collect(),
            parameters: BTreeMap::new(),
            derived: Vec::new(),
            aliases: BTreeMap::new(),
            equations: self
                .states
                .iter()
                .map(|s| {
                    let equation = EquationSpec {
                        state: s.clone(),
                        identify: true,
                        candidates: candidates.clone(),
                        forced: Vec::new(),
                        excluded: Vec::new(),
                        backend: Some(backend.clone()),
                        intercept: None,
                        coefficients: BTreeMap::new(),
                        covariance: None,
                    };
                    (format!("{s}_dot"), equation)
                })
                .collect(),
            parameter_covariance: None,
            simulation: None,
            plugins: BTreeMap::new(),
        };
        let text = toml::to_string_pretty(&spec).map_err(|e| refuse(e.to_string()))?;
        Model::from_spec(spec, &text, origin)
    }
}

impl Model {
    /// The model starting where `run` starts: each state's `initial` the run's first sample
    /// of it (where the run records it), so that `simulate` without initial values retraces
    /// the run's beginning rather than starting at 0 (a fixed point of many systems).
    pub fn starting_as(&self, run: &crate::data::Frame) -> Result<Model, ModelError> {
        self.edit(|file| {
            for state in &mut file.states {
                if let Some(&first) = run.column(&state.name).and_then(|c| c.first()) {
                    state.initial = first;
                }
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lorenz() -> Outline {
        Outline {
            name: "Lorenz".into(),
            time: "t".into(),
            states: vec!["x".into(), "y".into(), "z".into()],
            inputs: vec![],
            candidates: vec![],
            degree: 2,
            backend: None,
        }
    }

    /// Each state gets an equation over the ten monomials to degree 2, the constant a
    /// candidate; the file reads back as it was written.
    #[test]
    fn a_system_of_columns_is_a_model_file() {
        let model = lorenz().model("--states x,y,z").unwrap();
        assert_eq!(model.identifiable(), ["x_dot", "y_dot", "z_dot"]);
        let z = model.equation("z_dot").unwrap();
        assert_eq!(z.state, "z");
        assert_eq!(z.candidates.len(), 10);
        assert!(!model.spec().model.intercept);
        let again = Model::parse(&model.to_toml(), "again.toml").unwrap();
        assert_eq!(again.spec(), model.spec());
        let forced = Outline { inputs: vec!["F".into()], degree: 3, ..lorenz() }.model("x").unwrap();
        assert_eq!(forced.equation("x_dot").unwrap().candidates.len(), 35);
    }

    #[test]
    fn names_that_cannot_be_a_system_are_refused() {
        let error = |s: Outline| s.model("--states").unwrap_err().to_string();
        assert!(error(Outline { states: vec![], ..lorenz() }).contains("no state"));
        assert!(error(Outline { inputs: vec!["x".into()], ..lorenz() }).contains("`x` is named twice"));
        assert!(error(Outline { inputs: vec!["t".into()], ..lorenz() }).contains("the time"));
        assert!(error(Outline { degree: 0, ..lorenz() }).contains("degree 0"));
        let many = Outline { inputs: (0..12).map(|k| format!("u{k}")).collect(), degree: 3, ..lorenz() };
        assert!(many.model("x").is_ok(), "816 candidates are allowed");
        let more = Outline { inputs: (0..20).map(|k| format!("u{k}")).collect(), degree: 3, ..lorenz() };
        assert!(error(more).contains("2600 candidates"), "too many");
        let bad = Outline { states: vec!["x pos".into()], ..lorenz() };
        assert!(error(bad).starts_with("--states: `x pos`"));
        let typo = Outline { candidates: vec!["x*q".into()], ..lorenz() };
        let e = error(typo);
        assert!(
            e.contains("candidate `x*q`") && e.contains('^') && e.contains("unknown variable `q`"),
            "{e}"
        );
    }
}
