//! A system known by its records' columns alone: the states whose rates are identified, the
//! inputs that drive them, one library of candidates for every rate. `identify --states` and
//! Python's `Model.from_states` make it a model file, so the identified system is written,
//! simulated, validated and estimated as any other (a whole system at once, as SINDy fits one).

use std::collections::BTreeMap;

use super::file::DerivedSpec;
use super::{EquationSpec, InputSpec, Meta, Model, ModelError, ModelFile, ParameterSpec, StateSpec};
use crate::data::Frame;
use crate::select::Backend;
use crate::term::{polynomial, polynomial_len};

/// The most candidates a polynomial library may give each rate: beyond, the names or the
/// degree are too many for the runs a system is identified from (ten names to degree 3 give
/// 286).
pub const MOST_MONOMIALS: u128 = 1000;

/// The polynomial library's degree where none is given: the ODE benchmark's (benches/odes),
/// whose 37 systems identified whole with it come back as often as equation by equation.
pub const DEFAULT_DEGREE: u32 = 3;

/// A variable whose mean is this many standard deviations from 0 is offset: its powers and
/// products move with the lower terms (x and x², 1 and x nearly collinear: at 10 spreads the
/// correlation of x with x² is 0.9975, with x³ closer still), and a polynomial library in it
/// says little (two runs of a heated body at ambients of 300 and 350 K, 13 spreads from 0,
/// gave six terms for three). Such a
/// variable is written about a reference value near its mean, as the paper's Δu = u − u₀.
pub const OFFSET_SPREADS: f64 = 10.0;

/// The outline of a system named by its columns: what [`Outline::model`] makes a model
/// file of.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Outline {
    /// What the model is called (`[model] name`).
    pub name: String,
    /// The time column.
    pub time: String,
    /// The states, each one's rate an equation (`x` gives `x_dot`).
    pub states: Vec<String>,
    /// States the runs do not record, each the rate of another (`v` → `x` for `v=dx/dt`):
    /// estimated from that state's record ([`Model::estimated_rates`]), whose equation is then
    /// the kinematic ẋ = v, known rather than identified (a position measured alone, its
    /// acceleration the equation of motion).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub rates: BTreeMap<String, String>,
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
    /// States as `--states` and Python's `states` name them: a column (`x`), or a state the
    /// runs do not record as another state's rate (`v=dx/dt`): the names in order, and each
    /// such state with the state it is the rate of ([`Outline::rates`]).
    pub fn states_named(named: &[String]) -> (Vec<String>, BTreeMap<String, String>) {
        let mut rates = BTreeMap::new();
        let states = named
            .iter()
            .map(|n| match n.split_once('=') {
                Some((state, rate)) => {
                    let rate = rate.trim();
                    // `dx/dt`; anything else is kept whole, for the vocabulary to refuse
                    let of = rate.strip_prefix('d').and_then(|r| r.strip_suffix("/dt")).map(str::trim);
                    rates.insert(state.trim().to_string(), of.unwrap_or(rate).to_string());
                    state.trim().to_string()
                }
                None => n.trim().to_string(),
            })
            .collect();
        (states, rates)
    }

    /// The names the candidates may use, the states' and the inputs', each checked to be a
    /// name a term can use, neither the time nor named twice.
    pub fn vocabulary(&self, origin: &str) -> Result<crate::term::Vocabulary, ModelError> {
        let refuse = |message: String| ModelError::Outline { origin: origin.into(), message };
        if self.states.is_empty() {
            return Err(refuse("no state: name the states whose rates to identify".into()));
        }
        let names: Vec<&String> = self.states.iter().chain(&self.inputs).collect();
        let mut vocabulary = crate::term::Vocabulary::new();
        vocabulary.with_time(&self.time);
        for (k, name) in names.iter().enumerate() {
            if **name == self.time {
                return Err(refuse(format!(
                    "`{name}` is the time, neither a state nor an input (a forcing that follows the clock, \
                     sin(ωt) or a ramp, is an input: write it as a column of its own)"
                )));
            }
            if names[..k].contains(name) {
                return Err(refuse(format!("`{name}` is named twice: a name is a state or an input, once")));
            }
            vocabulary.variable(name).map_err(|e| refuse(e.to_string()))?;
        }
        for (state, of) in &self.rates {
            let written = match crate::term::is_identifier(of) {
                true => format!("`{state}=d{of}/dt`"),
                false => format!("`{state}={of}`"),
            };
            let message = if !crate::term::is_identifier(of) {
                "a state the runs do not record is written as the rate of one they do, `v=dx/dt`".to_string()
            } else if of == state {
                "a state cannot be its own rate".to_string()
            } else if self.rates.contains_key(of) {
                // a rate of an estimated rate would differentiate a smoothed signal again
                format!("`{of}` is not recorded either: a state the runs do not record is the rate of one they do")
            } else if !self.states.contains(of) {
                format!("`{of}` is no state named: name it a state too, --states {of},{state}=d{of}/dt")
            } else if let Some((other, _)) = self.rates.iter().find(|(o, f)| *f == of && *o != state) {
                format!("`{of}`'s rate is `{other}` already: one state is its rate")
            } else {
                continue;
            };
            return Err(refuse(format!("{written}: {message}")));
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
                .map(|n| StateSpec {
                    name: n.clone(),
                    unit: String::new(),
                    initial: 0.0,
                    per_run: None,
                    rate_of: self.rates.get(n).cloned(),
                    min: None,
                    max: None,
                })
                .collect(),
            inputs: self
                .inputs
                .iter()
                .map(|n| InputSpec { name: n.clone(), unit: String::new(), initial: 0.0, delay: 0.0, lag: 0.0 })
                .collect(),
            parameters: BTreeMap::new(),
            derived: Vec::new(),
            aliases: BTreeMap::new(),
            equations: self
                .states
                .iter()
                .map(|s| {
                    // a state whose rate is another state is known: ẋ = v, kinematics
                    let rate = self.rates.iter().find(|(_, of)| *of == s).map(|(rate, _)| rate);
                    let equation = EquationSpec {
                        state: s.clone(),
                        identify: rate.is_none(),
                        candidates: if rate.is_none() { candidates.clone() } else { Vec::new() },
                        forced: Vec::new(),
                        excluded: Vec::new(),
                        backend: rate.is_none().then(|| backend.clone()),
                        intercept: None,
                        coefficients: rate
                            .map(|r| BTreeMap::from([(r.clone(), super::CoefficientSpec::Value(1.0))]))
                            .unwrap_or_default(),
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
        let model = Model::from_spec(spec, &text, origin)?;
        Ok(Model { outline: Some(std::sync::Arc::new(self.clone())), ..model })
    }
}

/// A variable the runs hold far from 0 ([`OFFSET_SPREADS`]): the reference value it is
/// written about and how many spreads its mean sits from 0.
struct Offset {
    name: String,
    reference: f64,
    spreads: f64,
}

/// The variable `name` in `frames` if it is offset: its reference value the mean rounded to
/// the decade above its spread (so it reads round, `300` for 302.3 ± 1.9, and stays within
/// five spreads of the mean).
fn offset(name: &str, frames: &[Frame]) -> Option<Offset> {
    let columns: Vec<&[f64]> = frames.iter().filter_map(|f| f.column(name)).collect();
    let n = columns.iter().map(|c| c.len()).sum::<usize>() as f64;
    if n < 2.0 {
        return None;
    }
    // a constant (g = 9.81 in every row) has nothing to write about a reference: its mean's
    // rounding left it 1.1·10¹⁴ spreads from 0, written about g0 = 9.8100000000001
    let first = columns.iter().find_map(|c| c.first())?;
    if columns.iter().flat_map(|c| c.iter()).all(|v| v == first) {
        return None;
    }
    let mean = columns.iter().flat_map(|c| c.iter()).sum::<f64>() / n;
    let variance = columns.iter().flat_map(|c| c.iter()).map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let spread = variance.sqrt();
    let spreads = mean.abs() / spread;
    if !(spread > 0.0 && spreads.is_finite() && spreads > OFFSET_SPREADS) {
        return None;
    }
    let decade = spread.log10().ceil() as i32;
    // divided by 10^-k rather than times 10^k, so 302.1 is the nearest double to 302.1
    let reference = if decade >= 0 {
        (mean / 10f64.powi(decade)).round() * 10f64.powi(decade)
    } else {
        (mean * 10f64.powi(-decade)).round() / 10f64.powi(-decade)
    };
    Some(Offset { name: name.to_string(), reference, spreads })
}

impl Model {
    /// The outline the model was made from, while its library may still be written about
    /// reference values ([`Model::about_references`]); not in the file.
    pub fn outline(&self) -> Option<&Outline> {
        self.outline.as_deref()
    }

    /// The model as made from `outline` (a model read back from its file's text, as a
    /// pickled one is, made from columns).
    pub fn with_outline(self, outline: Outline) -> Model {
        Model { outline: Some(std::sync::Arc::new(outline)), ..self }
    }

    /// A model made from columns ([`Outline::model`]) with its polynomial library written
    /// about reference values where the runs hold a state or an input far from 0
    /// ([`OFFSET_SPREADS`]: a temperature in kelvin, a pressure in pascal, a ship's speed):
    /// a parameter `T0` (the mean, rounded), a derived `ΔT = T - T0`, and the monomials of
    /// `ΔT` in place of `T`'s — the paper's `Δu = u - u0`. With a sentence saying so; none
    /// where there is no such variable, the candidates are named, or the model was not made
    /// from columns (its file's candidates are its author's). The model returned is settled
    /// either way (no outline): decided once on the whole runs, it is not decided again on
    /// parts of them (a half's smaller spread would put a variable farther from 0).
    pub fn about_references(&self, frames: &[Frame]) -> Result<(Model, Option<String>), ModelError> {
        let settled = || Model { outline: None, ..self.clone() };
        let Some(outline) = self.outline.as_ref().filter(|o| o.candidates.is_empty()) else {
            return Ok((settled(), None));
        };
        let names: Vec<String> = outline.states.iter().chain(&outline.inputs).cloned().collect();
        let offsets: Vec<Offset> = names.iter().filter_map(|n| offset(n, frames)).collect();
        if offsets.is_empty() {
            return Ok((settled(), None));
        }
        let spec = self.spec();
        let mut taken: Vec<String> = names.clone();
        taken.extend(spec.parameters.keys().cloned());
        taken.extend(spec.derived.iter().map(|d| d.name.clone()));
        taken.extend(spec.aliases.keys().cloned());
        // (variable, parameter, derived) for each offset variable that has free names for both
        let mut written = Vec::new();
        for o in &offsets {
            let free = |options: [String; 3], taken: &[String]| {
                options.into_iter().find(|n| crate::term::is_identifier(n) && !taken.contains(n))
            };
            let v = &o.name;
            let Some(parameter) = free([format!("{v}0"), format!("{v}_0"), format!("{v}_ref")], &taken)
            else {
                continue;
            };
            taken.push(parameter.clone());
            let Some(derived) = free([format!("Δ{v}"), format!("Δ_{v}"), format!("{v}_dev")], &taken)
            else {
                continue;
            };
            taken.push(derived.clone());
            written.push((o, parameter, derived));
        }
        if written.is_empty() {
            return Ok((settled(), None));
        }
        let about: Vec<String> = names
            .iter()
            .map(|n| written.iter().find(|(o, ..)| o.name == *n).map_or(n.clone(), |(_, _, d)| d.clone()))
            .collect();
        let library = polynomial(&names, outline.degree);
        let centred = polynomial(&about, outline.degree);
        let said: Vec<String> = written
            .iter()
            .map(|(o, p, d)| {
                format!(
                    "`{}` (its mean {} spreads from 0) as {d} = {} - {p}, {p} = {}",
                    o.name,
                    crate::output::sig(o.spreads, 2),
                    o.name,
                    o.reference
                )
            })
            .collect();
        let note = format!(
            "the candidates are written about reference values: {}; far from 0 a variable's powers and products move with the lower terms (its square with itself and the constant) and the fit cannot tell them apart",
            said.join("; ")
        );
        // terms forced or left out (`with_terms`) follow their candidates into the centred library
        let canonical = |t: &str| self.vocabulary.parse(t).map(|t| t.to_string()).ok();
        let plain: Vec<Option<String>> = library.iter().map(|t| canonical(t)).collect();
        let centre = |t: &String| -> String {
            canonical(t)
                .and_then(|c| plain.iter().position(|p| p.as_deref() == Some(c.as_str())))
                .map_or_else(|| t.clone(), |i| centred[i].clone())
        };
        let mut model = self.edit(|file| {
            for (o, parameter, derived) in &written {
                let unit = file.states.iter().find(|s| s.name == o.name).map(|s| s.unit.clone());
                let unit =
                    unit.or_else(|| file.inputs.iter().find(|i| i.name == o.name).map(|i| i.unit.clone()));
                file.parameters.insert(
                    parameter.clone(),
                    ParameterSpec {
                        value: o.reference,
                        unit: unit.unwrap_or_default(),
                        per_run: None,
                        free: false,
                        prior: None,
                        bounds: None,
                        std_error: None,
                        nuisance: None,
                        medium: false,
                    },
                );
                file.derived.push(DerivedSpec {
                    name: derived.clone(),
                    definition: format!("{} - {parameter}", o.name),
                });
            }
            for equation in file.equations.values_mut() {
                if equation.candidates == library {
                    equation.candidates = centred.clone();
                    equation.forced = equation.forced.iter().map(centre).collect();
                    equation.excluded = equation.excluded.iter().map(centre).collect();
                }
            }
            file.model.provenance =
                format!("every monomial of {} to degree {}", about.join(", "), outline.degree);
            file.model.notes.push(note.clone());
        })?;
        model.outline = None;
        Ok((model, Some(note)))
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
            rates: BTreeMap::new(),
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

    /// `v=dx/dt` names a state the runs do not record as another's rate: x's equation is the
    /// kinematic ẋ = v, known; v's is identified over the monomials of x, v and the input. The
    /// runs get v estimated from x's record (the Kalman smoother's rate, with its standard
    /// error as the column's noise); a run that records v keeps its own. Rates of what is not a
    /// state recorded are refused, as is a file's `rate_of` naming the state itself.
    #[test]
    fn a_state_not_recorded_is_the_rate_of_one_that_is() {
        let named =
            |list: &[&str]| Outline::states_named(&list.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        let (states, rates) = named(&["x", " v = dx/dt"]);
        assert_eq!(states, ["x", "v"]);
        assert_eq!(rates, BTreeMap::from([("v".to_string(), "x".to_string())]));
        let second = Outline { states, rates, inputs: vec!["u".into()], ..lorenz() };
        let model = second.model("--states x,v=dx/dt").unwrap();
        assert_eq!(model.identifiable(), ["v_dot"]);
        let x = model.equation("x_dot").unwrap();
        assert!(!x.identify && x.candidates.is_empty());
        assert_eq!(x.coefficients, [(crate::term::Term::var("v"), 1.0, None)]);
        assert_eq!(model.equation("v_dot").unwrap().candidates.len(), 10);
        assert_eq!(model.estimated_states(), ["v"]);
        let again = Model::parse(&model.to_toml(), "again.toml").unwrap();
        assert_eq!(again.spec(), model.spec());
        for (list, says) in [
            (&["x", "v=dq/dt"][..], "`q` is no state named"),
            (&["x", "v=dx/dt", "a=dv/dt"][..], "`v` is not recorded either"),
            (&["x", "v=dv/dt"][..], "its own rate"),
            (&["x", "v=d2x/dt2"][..], "written as the rate of one they do"),
            (&["x", "v=dx/dt", "w=dx/dt"][..], "one state is its rate"),
        ] {
            let (states, rates) = named(list);
            let e = Outline { states, rates, ..lorenz() }.model("--states").unwrap_err().to_string();
            assert!(e.contains(says), "{list:?}: {e}");
        }
        let mut seed = 11u64;
        let t: Vec<f64> = (0..1000).map(|k| k as f64 * 0.02).collect();
        let mut run = Frame::new("run.csv", "t", t.clone()).unwrap();
        run.push("x", t.iter().map(|t| t.sin() + 0.01 * crate::data::test_noise(&mut seed)).collect())
            .unwrap();
        run.push("u", vec![0.0; t.len()]).unwrap();
        let mut recorded = run.clone();
        recorded.push("v", t.iter().map(|t| t.cos()).collect()).unwrap();
        let (runs, said) = model.estimated_rates(vec![run, recorded]).unwrap();
        assert!(said[0].contains("estimated as `x`'s rate in 1 of 2 run(s)"), "{said:?}");
        // the ends, where the smoother sees one side only, left out: a few rows each
        let kept = runs[0].time();
        assert!(
            kept[0] > 0.0 && kept[0] < 0.2 && kept[kept.len() - 1] > 19.7 && kept.len() < 1000,
            "{kept:?}"
        );
        assert!(said[1].contains("row(s) at the runs' ends left out"), "{said:?}");
        let error = runs[0].estimated_error("v").unwrap();
        let v = runs[0].column("v").unwrap();
        let made =
            (v.iter().zip(kept).map(|(v, t)| (v - t.cos()).powi(2)).sum::<f64>() / kept.len() as f64).sqrt();
        assert!(error < 1.6 * made && made < 1.6 * error, "reported {error}, made {made}");
        let tally = crate::data::NoiseTally::of(&runs[0], "v", 0..kept.len()).unwrap();
        assert!(tally.estimated() && (tally.sd().unwrap() / error - 1.0).abs() < 1e-9);
        assert_eq!(runs[1].column("v").unwrap()[0], 1.0, "a recorded rate is kept");
        assert!(runs[1].estimated_error("v").is_none());
        let own = model.to_toml().replace("rate_of = \"x\"", "rate_of = \"v\"");
        let e = Model::parse(&own, "own.toml").unwrap_err().to_string();
        assert!(e.contains("own.toml") && e.contains("states[1].rate_of"), "{e}");
        let twice = model.to_toml() + "[[states]]\nname = \"w\"\nrate_of = \"x\"\n";
        let e = Model::parse(&twice, "twice.toml").unwrap_err().to_string();
        assert!(e.contains("states[2].rate_of") && e.contains("`x`'s rate is `v` already"), "{e}");
    }

    /// A run of Lorenz-like columns: x and y about 0, z about `z0` with spread about 1.
    fn run(z0: f64, names: [&str; 3]) -> Frame {
        let t: Vec<f64> = (0..400).map(|k| k as f64 * 0.01).collect();
        let mut f = Frame::new("run", "t", t.clone()).unwrap();
        f.push(names[0], t.iter().map(|t| (3.0 * t).sin()).collect()).unwrap();
        f.push(names[1], t.iter().map(|t| (2.0 * t).cos()).collect()).unwrap();
        f.push(names[2], t.iter().map(|t| z0 + 1.4 * (1.3 * t).sin()).collect()).unwrap();
        f
    }

    /// A state far from 0 (z about 302, spread 1) is written about a round reference value,
    /// as the paper's Δu: a parameter `z0` = 300, a derived `Δz = z - z0`, every monomial of
    /// z in its equations' candidates one of Δz (the same count, the same order), the model
    /// re-parses, and a second call changes nothing. Close to 0 (z about 3), with named
    /// candidates, or for a model file not made from columns, nothing is written anew.
    #[test]
    fn a_state_far_from_zero_is_written_about_a_reference_value() {
        let model = lorenz().model("--states x,y,z").unwrap();
        let (about, note) = model.about_references(&[run(302.3, ["x", "y", "z"])]).unwrap();
        let note = note.unwrap();
        assert!(note.contains("`z`") && note.contains("Δz = z - z0, z0 = 300"), "{note}");
        assert_eq!(about.parameter_values()["z0"], 300.0);
        let derived = &about.spec().derived;
        assert_eq!((derived[0].name.as_str(), derived[0].definition.as_str()), ("Δz", "z - z0"));
        let candidates = &about.equation("y_dot").unwrap().candidates;
        let texts: Vec<String> = candidates.iter().map(|c| c.to_string()).collect();
        assert_eq!(texts, ["1", "x", "y", "Δz", "x^2", "x*y", "x*Δz", "y^2", "y*Δz", "Δz^2"]);
        assert!(about.spec().model.provenance.contains("x, y, Δz to degree 2"));
        // a term left out of every rate follows its candidate (it was left naming `z^2`, which
        // the centred library no longer has)
        let without = model.with_terms(&[], &[model.vocabulary.parse("z^2").unwrap()]).unwrap();
        let (about_without, _) = without.about_references(&[run(302.3, ["x", "y", "z"])]).unwrap();
        let left: Vec<String> =
            about_without.equation("y_dot").unwrap().excluded.iter().map(|t| t.to_string()).collect();
        assert_eq!(left, ["Δz^2"]);
        assert!(about.about_references(&[run(302.3, ["x", "y", "z"])]).unwrap().1.is_none());
        Model::parse(&about.to_toml(), "again.toml").unwrap();
        // the reference rounds to the decade above the spread: 0.014 → 0.1
        let fine = Frame::new("run", "t", vec![0.0, 1.0, 2.0, 3.0]).unwrap();
        let mut fine = fine;
        for (name, v) in [("x", [0.0, 1.0, 0.0, -1.0]), ("y", [1.0, 0.0, -1.0, 0.0])] {
            fine.push(name, v.to_vec()).unwrap();
        }
        fine.push("z", vec![-7.23, -7.25, -7.24, -7.22]).unwrap();
        let (fine, _) = model.about_references(&[fine]).unwrap();
        assert_eq!(fine.parameter_values()["z0"], -7.2);
        // a constant is no variable far from 0 (its mean's rounding made it 10¹⁴ spreads off)
        let t: Vec<f64> = (0..4001).map(f64::from).collect();
        let mut constant = Frame::new("run", "t", t.clone()).unwrap();
        constant.push("x", t.iter().map(|t| t.sin()).collect()).unwrap();
        constant.push("y", t.iter().map(|t| t.cos()).collect()).unwrap();
        constant.push("z", vec![9.81; t.len()]).unwrap();
        assert!(model.about_references(&[constant]).unwrap().1.is_none());
        // nothing to write anew
        assert!(model.about_references(&[run(3.0, ["x", "y", "z"])]).unwrap().1.is_none());
        let named = Outline { candidates: vec!["x".into(), "z".into()], ..lorenz() }.model("x").unwrap();
        assert!(named.about_references(&[run(302.3, ["x", "y", "z"])]).unwrap().1.is_none());
        let read = Model::parse(&model.to_toml(), "lorenz.toml").unwrap();
        assert!(read.about_references(&[run(302.3, ["x", "y", "z"])]).unwrap().1.is_none());
        // the outline is carried through edits and can be given back (a pickled model)
        let edited = model.starting_as(&run(302.3, ["x", "y", "z"])).unwrap();
        assert!(edited.outline().is_some());
        assert!(read
            .with_outline(lorenz())
            .about_references(&[run(302.3, ["x", "y", "z"])])
            .unwrap()
            .1
            .is_some());
        // decided once: close to 0 on these runs, the model is settled, and a part of them
        // farther from 0 against its own spread does not write it anew
        let (kept, none) = model.about_references(&[run(3.0, ["x", "y", "z"])]).unwrap();
        assert!(none.is_none() && kept.outline().is_none());
        assert!(kept.about_references(&[run(302.3, ["x", "y", "z"])]).unwrap().1.is_none());
    }

    /// The names a reference value takes give way to the model's own: a state called `z0`
    /// makes the parameter `z_0`.
    #[test]
    fn reference_names_give_way_to_the_models_own() {
        let outline = Outline { states: vec!["x".into(), "z0".into(), "z".into()], ..lorenz() };
        let model = outline.model("--states x,z0,z").unwrap();
        let (about, _) = model.about_references(&[run(302.3, ["x", "z0", "z"])]).unwrap();
        assert_eq!(about.parameter_values()["z_0"], 300.0);
        assert_eq!(about.spec().derived[0].definition, "z - z_0");
    }
}
