//! Physical dimensions of a model's names and terms, read off the units its file declares
//! (`m/s`, `rad/s`, `kg m²`, `1/s`): exponents of length, time and mass. They give each
//! coefficient's dimension (that of its equation's rate over that of its term), and so its
//! value under a change of scale and its nondimensional form.

use std::collections::BTreeMap;

use super::Model;
use crate::term::{Atom, Term};

/// How a quantity in `unit` is shown to a person: angles in degrees (a unit that begins with
/// rad: rad, rad/s, rad/s^2 become °, °/s, °/s^2), anything else as it is. The factor from
/// the model's unit, and the unit shown.
pub fn shown(unit: &str) -> (f64, String) {
    match unit.strip_prefix("rad") {
        Some(rest) => (180.0 / std::f64::consts::PI, format!("°{rest}")),
        None => (1.0, unit.to_string()),
    }
}

/// A unit as it follows a number: degrees close up (`9.32°`), the rest after a space
/// (`21.45 m`), none as none.
pub fn after_number(unit: &str) -> String {
    if unit.is_empty() || unit.starts_with('°') {
        unit.to_string()
    } else {
        format!(" {unit}")
    }
}

/// Exponents of length, time and mass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dimension {
    /// Length.
    pub length: f64,
    /// Time.
    pub time: f64,
    /// Mass.
    pub mass: f64,
}

impl Dimension {
    fn add(self, o: Dimension, k: f64) -> Dimension {
        Dimension {
            length: self.length + k * o.length,
            time: self.time + k * o.time,
            mass: self.mass + k * o.mass,
        }
    }

    /// The factor a quantity of this dimension takes when lengths scale by `l`, times by `t`
    /// and masses by `m`.
    pub fn factor(&self, l: f64, t: f64, m: f64) -> f64 {
        l.powf(self.length) * t.powf(self.time) * m.powf(self.mass)
    }
}

impl std::fmt::Display for Dimension {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut parts = Vec::new();
        for (sym, e) in [("L", self.length), ("T", self.time), ("M", self.mass)] {
            if e != 0.0 {
                parts.push(if e == 1.0 { sym.to_string() } else { format!("{sym}^{e}") });
            }
        }
        if parts.is_empty() {
            write!(f, "1")
        } else {
            write!(f, "{}", parts.join(" "))
        }
    }
}

/// Why a dimension could not be found.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DimensionError {
    /// A unit this parser does not know.
    #[error("unit `{unit}` of `{name}` is not one termid reads (m, s, kg, rad, deg, 1, products, quotients and powers of them)")]
    Unit {
        /// The name declared with it.
        name: String,
        /// The unit.
        unit: String,
    },
    /// A sum of terms of different dimensions.
    #[error("`{term}` adds quantities of different dimensions ({a} and {b})")]
    Inconsistent {
        /// The term.
        term: String,
        /// One dimension.
        a: Dimension,
        /// The other.
        b: Dimension,
    },
    /// A name without a declaration.
    #[error("`{0}` has no declared unit")]
    Unknown(String),
}

/// The dimension of a unit: `m/s`, `rad/s^2`, `kg m²`, `kg/m³`, `1/s`, `deg`, `-`.
pub fn parse_unit(unit: &str) -> Option<Dimension> {
    let unit = unit.trim();
    if unit.is_empty() || unit == "-" || unit == "1" {
        return Some(Dimension::default());
    }
    let mut out = Dimension::default();
    for (k, part) in unit.split('/').enumerate() {
        let sign = if k == 0 { 1.0 } else { -1.0 };
        for factor in part.split([' ', '*', '·']).filter(|f| !f.is_empty()) {
            let (base, power) = match factor.split_once('^') {
                Some((b, p)) => (b, p.parse::<f64>().ok()?),
                None => match factor.strip_suffix('²').or_else(|| factor.strip_suffix('³')) {
                    Some(b) => (b, if factor.ends_with('²') { 2.0 } else { 3.0 }),
                    None => (factor, 1.0),
                },
            };
            let d = match base {
                "m" => Dimension { length: 1.0, ..Default::default() },
                "s" => Dimension { time: 1.0, ..Default::default() },
                "kg" => Dimension { mass: 1.0, ..Default::default() },
                "rad" | "deg" | "1" => Dimension::default(),
                _ => return None,
            };
            out = out.add(d, sign * power);
        }
    }
    Some(out)
}

/// The factor that takes a value in `unit` to SI where the unit counts time in anything but
/// seconds (`1/h`: 1/3600; `mg·h/L`: 3600), with the unit in seconds (`1/s`, `mg·s/L`);
/// `None` where it counts time in seconds or not at all.
pub fn time_in_seconds(unit: &str) -> Option<(f64, String)> {
    let mut factor = 1.0;
    let mut si = String::new();
    let mut rest = unit;
    // the unit's words, each with what follows it (a separator, a power, a parenthesis)
    while !rest.is_empty() {
        let start = rest.find(|c: char| c.is_alphabetic()).unwrap_or(rest.len());
        si.push_str(&rest[..start]);
        rest = &rest[start..];
        let end = rest.find(|c: char| !c.is_alphabetic()).unwrap_or(rest.len());
        let word = &rest[..end];
        rest = &rest[end..];
        // a model file's values are SI: a unit of time other than seconds is read in seconds
        let Some(seconds) = crate::data::seconds_of_unit(word).filter(|s| *s != 1.0) else {
            si.push_str(word);
            continue;
        };
        si.push('s');
        let power = match rest.chars().next() {
            Some('²') => 2.0,
            Some('³') => 3.0,
            Some('^') => rest[1..]
                .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
                .next()
                .and_then(|p| p.parse().ok())
                .unwrap_or(1.0),
            _ => 1.0,
        };
        // a unit of time under the unit's (first) slash divides
        let under = si.contains('/');
        factor *= seconds.powf(if under { -power } else { power });
    }
    (factor != 1.0).then_some((factor, si))
}

/// The dimensions of every name of a model: states, inputs and parameters from their units,
/// derived variables from their definitions.
pub fn dimensions(model: &Model) -> Result<BTreeMap<String, Dimension>, DimensionError> {
    let spec = model.spec();
    let mut out = BTreeMap::new();
    let declared = spec
        .states
        .iter()
        .map(|s| (&s.name, &s.unit))
        .chain(spec.inputs.iter().map(|i| (&i.name, &i.unit)))
        .chain(spec.parameters.iter().map(|(n, p)| (n, &p.unit)));
    for (name, unit) in declared {
        let d = parse_unit(unit)
            .ok_or_else(|| DimensionError::Unit { name: name.clone(), unit: unit.clone() })?;
        out.insert(name.clone(), d);
    }
    for d in model.vocabulary.derived() {
        let dim = term_dimension(&d.definition, &out)?;
        out.insert(d.name.clone(), dim);
    }
    Ok(out)
}

/// The dimension of a term over names of known dimension.
pub fn term_dimension(term: &Term, names: &BTreeMap<String, Dimension>) -> Result<Dimension, DimensionError> {
    let mut first: Option<Dimension> = None;
    for m in term.monomials() {
        let mut d = Dimension::default();
        for (atom, k) in &m.factors {
            d = d.add(atom_dimension(atom, names)?, f64::from(*k));
        }
        match first {
            None => first = Some(d),
            Some(a)
                if (a.length - d.length).abs() > 1e-9
                    || (a.time - d.time).abs() > 1e-9
                    || (a.mass - d.mass).abs() > 1e-9 =>
            {
                return Err(DimensionError::Inconsistent { term: term.to_string(), a, b: d });
            }
            Some(_) => {}
        }
    }
    Ok(first.unwrap_or_default())
}

fn atom_dimension(atom: &Atom, names: &BTreeMap<String, Dimension>) -> Result<Dimension, DimensionError> {
    match atom {
        Atom::Var(n) => names.get(n).copied().ok_or_else(|| DimensionError::Unknown(n.clone())),
        Atom::Group(t) => term_dimension(t, names),
        Atom::Call(f, args) => match f.as_str() {
            "sqrt" => Ok(Dimension::default().add(term_dimension(&args[0], names)?, 0.5)),
            "abs" => term_dimension(&args[0], names),
            // angles and ratios in, numbers out
            _ => Ok(Dimension::default()),
        },
    }
}

/// Each coefficient's dimension: its equation's rate (the state's dimension per time) over
/// its term's; (equation, term, dimension) in the equations' order.
pub fn coefficient_dimensions(model: &Model) -> Result<Vec<(String, Term, Dimension)>, DimensionError> {
    let names = dimensions(model)?;
    let mut out = Vec::new();
    for e in model.equations() {
        let state = names.get(&e.state).copied().ok_or_else(|| DimensionError::Unknown(e.state.clone()))?;
        let rate = Dimension { time: state.time - 1.0, ..state };
        for (t, _, _) in &e.coefficients {
            let d = term_dimension(t, &names)?;
            out.push((e.name.clone(), t.clone(), rate.add(d, -1.0)));
        }
    }
    Ok(out)
}

/// The model at another scale: every quantity whose dimension is length^a time^b mass^c is
/// multiplied by `length`^a · `time`^b · `mass`^c — coefficients (with their standard errors,
/// covariances and intercepts), parameters, and the states' initial values and bounds.
/// Froude's law (`length` λ, `time` √λ, `mass` λ³) takes a model basin's model to its ship.
/// A plug-in's own table (a ship's particulars) is its plug-in's to rescale:
/// `termid::plugins::rescaled` does both.
pub fn rescaled(model: &Model, length: f64, time: f64, mass: f64) -> Result<Model, super::ModelError> {
    let names = dimensions(model)
        .map_err(|e| super::ModelError::Syntax { file: model.path.clone(), message: e.to_string() })?;
    let coefficient = coefficient_dimensions(model)
        .map_err(|e| super::ModelError::Syntax { file: model.path.clone(), message: e.to_string() })?;
    let factor_of = |eq: &str, text: &str| -> f64 {
        let Ok(term) = model.vocabulary.parse(text) else { return 1.0 };
        coefficient
            .iter()
            .find(|(e, t, _)| e == eq && *t == term)
            .map_or(1.0, |(_, _, d)| d.factor(length, time, mass))
    };
    let rate_factor = |state: &str| {
        names.get(state).map_or(1.0, |d| Dimension { time: d.time - 1.0, ..*d }.factor(length, time, mass))
    };
    let mut factors: BTreeMap<(String, String), f64> = BTreeMap::new();
    for e in model.spec().equations.iter() {
        for text in e.1.coefficients.keys() {
            factors.insert((e.0.clone(), text.clone()), factor_of(e.0, text));
        }
        if let Some(c) = &e.1.covariance {
            for text in &c.terms {
                factors.insert((e.0.clone(), text.clone()), factor_of(e.0, text));
            }
        }
    }
    model.edit(|file| {
        for s in &mut file.states {
            let f = names.get(&s.name).map_or(1.0, |d| d.factor(length, time, mass));
            s.initial *= f;
            s.min = s.min.map(|v| v * f);
            s.max = s.max.map(|v| v * f);
        }
        for i in &mut file.inputs {
            i.initial *= names.get(&i.name).map_or(1.0, |d| d.factor(length, time, mass));
        }
        for (n, p) in &mut file.parameters {
            p.value *= names.get(n).map_or(1.0, |d| d.factor(length, time, mass));
        }
        for (name, e) in &mut file.equations {
            let rate = rate_factor(&e.state);
            e.intercept = e.intercept.map(|b| b * rate);
            for (text, c) in &mut e.coefficients {
                let f = factors.get(&(name.clone(), text.clone())).copied().unwrap_or(1.0);
                *c = match *c {
                    super::CoefficientSpec::Value(v) => super::CoefficientSpec::Value(v * f),
                    super::CoefficientSpec::WithError { value, std_error } => {
                        super::CoefficientSpec::WithError { value: value * f, std_error: std_error * f.abs() }
                    }
                };
            }
            if let Some(c) = &mut e.covariance {
                let fs: Vec<f64> = c
                    .terms
                    .iter()
                    .map(|t| factors.get(&(name.clone(), t.clone())).copied().unwrap_or(1.0))
                    .collect();
                for (i, row) in c.matrix.iter_mut().enumerate() {
                    for (j, v) in row.iter_mut().enumerate() {
                        *v *= fs[i] * fs[j];
                    }
                }
            }
        }
    })
}

/// One coefficient in nondimensional form.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Nondimensional {
    /// Its equation.
    pub equation: String,
    /// Its term.
    pub term: String,
    /// The coefficient's dimension.
    pub dimension: String,
    /// Its value as identified.
    pub value: f64,
    /// Its value over L^a (L/U)^b (ρL³)^c, the reference scales' product of its dimension.
    pub prime: f64,
}

/// Every coefficient of `model` nondimensionalised by a reference length, speed and density
/// (the prime system: lengths by L, times by L/U, masses by ρL³). For explicit accelerations
/// this makes v̇' = v̇·L/U² and ṙ' = ṙ·L²/U² the equations the prime coefficients multiply;
/// they are force derivatives of the ρ/2·L²U² (ρ/2·L³U² for moments) convention only once
/// multiplied by the nondimensional mass and added mass the accelerations fold in.
pub fn nondimensional(
    model: &Model,
    length: f64,
    speed: f64,
    density: f64,
) -> Result<Vec<Nondimensional>, DimensionError> {
    let dims = coefficient_dimensions(model)?;
    let time = length / speed;
    let mass = density * length.powi(3);
    Ok(dims
        .into_iter()
        .map(|(eq, term, d)| {
            let value = model
                .equation(&eq)
                .and_then(|e| e.coefficients.iter().find(|c| c.0 == term).map(|c| c.1))
                .unwrap_or(f64::NAN);
            Nondimensional {
                equation: eq,
                term: term.to_string(),
                dimension: d.to_string(),
                value,
                prime: value / d.factor(length, time, mass),
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_shown_in_degrees_other_units_as_they_are() {
        let (f, u) = shown("rad/s");
        assert!((f - 57.29577951308232).abs() < 1e-12);
        assert_eq!(u, "°/s");
        assert_eq!(shown("rad").1, "°");
        assert_eq!(shown("m/s"), (1.0, "m/s".to_string()));
    }

    /// Rates per hour, minute or day read in seconds, with their SI unit; units that count
    /// time in seconds or not at all are left alone.
    #[test]
    fn units_of_time_other_than_seconds_are_found_with_their_factor() {
        let close = |u: &str, f: f64, si: &str| {
            let (got, unit) = time_in_seconds(u).unwrap();
            assert!((got / f - 1.0).abs() < 1e-12 && unit == si, "{u}: {got} {unit}");
        };
        close("1/h", 1.0 / 3600.0, "1/s");
        close("1/min", 1.0 / 60.0, "1/s");
        close("L/(mol·h)", 1.0 / 3600.0, "L/(mol·s)");
        close("mg·h/L", 3600.0, "mg·s/L");
        close("m/h^2", 1.0 / 3600f64.powi(2), "m/s^2");
        close("1/day", 1.0 / 86400.0, "1/s");
        for si in ["1/s", "m/s", "rad/s^2", "mol/L", "", "kg m²", "hPa", "mmHg"] {
            assert_eq!(time_in_seconds(si), None, "{si}");
        }
    }

    /// Froude scaling of the paper's ship to a 20× larger one: a zigzag's overshoots and
    /// the track in ship lengths are the same, its period √20 times longer.
    #[test]
    fn a_froude_scaled_model_moves_as_the_model_scaled() {
        use crate::sim::{simulate, Constant, Integrator, Settings, System};
        let model = crate::model::Model::parse(
            &std::fs::read_to_string("models/oltmann1973.toml").unwrap(),
            "models/oltmann1973.toml",
        )
        .unwrap();
        let lambda = 20.0f64;
        let big = rescaled(&model, lambda, lambda.sqrt(), lambda.powi(3)).unwrap();
        assert!((big.parameter_values()["u0"] - 2.010 * lambda.sqrt()).abs() < 1e-12);
        let run = |m: &crate::model::Model, t_scale: f64, delta: f64| {
            let system = System::new(m, &BTreeMap::new(), false).unwrap();
            let x0: Vec<f64> = m.spec().states.iter().map(|s| s.initial).collect();
            let s = Settings {
                integrator: Integrator::Rk4,
                dt: 0.01 * t_scale,
                duration: 30.0 * t_scale,
                sample: 0.01 * t_scale,
            };
            simulate(&system, &x0, &mut Constant(vec![delta]), &s).unwrap()
        };
        let (a, b) = (run(&model, 1.0, 0.3), run(&big, lambda.sqrt(), 0.3));
        for k in [500, 1500, 3000] {
            // ψ equal at corresponding times, positions λ times, speeds √λ times
            assert!((a.states[3][k] - b.states[3][k]).abs() < 1e-9, "ψ at {k}");
            assert!((a.states[4][k] * lambda - b.states[4][k]).abs() < 1e-6 * lambda, "x0 at {k}");
            assert!((a.states[0][k] * lambda.sqrt() - b.states[0][k]).abs() < 1e-9, "u at {k}");
        }
    }

    /// Nondimensional coefficients do not change under Froude scaling.
    #[test]
    fn prime_coefficients_are_the_same_at_every_scale() {
        let model = crate::model::Model::parse(
            &std::fs::read_to_string("models/oltmann1973.toml").unwrap(),
            "models/oltmann1973.toml",
        )
        .unwrap();
        let lambda = 50.0f64;
        let big = rescaled(&model, lambda, lambda.sqrt(), lambda.powi(3)).unwrap();
        let a = nondimensional(&model, 4.572, 2.01, 1000.0).unwrap();
        let b = nondimensional(&big, 4.572 * lambda, 2.01 * lambda.sqrt(), 1000.0).unwrap();
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            assert!((x.prime - y.prime).abs() <= 1e-9 * x.prime.abs(), "{x:?} vs {y:?}");
        }
        // ṙ = c·u·r: c [1/L], c' = c·L
        let ur = a.iter().find(|c| c.equation == "r_dot" && c.term == "r*u").unwrap();
        assert!((ur.prime - ur.value * 4.572).abs() < 1e-12, "{ur:?}");
    }

    #[test]
    fn units_parse_to_their_dimensions() {
        let d = |l, t, m| Some(Dimension { length: l, time: t, mass: m });
        assert_eq!(parse_unit("m/s"), d(1.0, -1.0, 0.0));
        assert_eq!(parse_unit("rad/s^2"), d(0.0, -2.0, 0.0));
        assert_eq!(parse_unit("kg m²"), d(2.0, 0.0, 1.0));
        assert_eq!(parse_unit("kg/m³"), d(-3.0, 0.0, 1.0));
        assert_eq!(parse_unit("1/s"), d(0.0, -1.0, 0.0));
        assert_eq!(parse_unit(""), d(0.0, 0.0, 0.0));
        assert_eq!(parse_unit("furlong"), None);
    }

    /// The paper's v̇ = … + c·r·v²/u: c has the dimension of 1/L (m/s² over m²/s²·1/s … ).
    #[test]
    fn coefficients_of_the_papers_ship_have_their_dimensions() {
        let model = crate::model::Model::parse(
            &std::fs::read_to_string("models/oltmann1973.toml").unwrap(),
            "models/oltmann1973.toml",
        )
        .unwrap();
        let dims = coefficient_dimensions(&model).unwrap();
        let find = |eq: &str, t: &str| {
            let term = model.vocabulary.parse(t).unwrap();
            dims.iter().find(|(e, x, _)| e == eq && *x == term).unwrap().2
        };
        // v̇ [L T⁻²] = c · v²r/u [L T⁻²]: dimensionless
        assert_eq!(find("v_dot", "v^2*r/u"), Dimension::default());
        // v̇ = c · u·v [L² T⁻²]: 1/L
        assert_eq!(find("v_dot", "u*v"), Dimension { length: -1.0, ..Default::default() });
        // ṙ [T⁻²] = c · u·r [L T⁻²]: 1/L
        assert_eq!(find("r_dot", "u*r"), Dimension { length: -1.0, ..Default::default() });
        // u̇ = c · u²δ² : 1/L
        assert_eq!(find("u_dot", "u^2*delta^2"), Dimension { length: -1.0, ..Default::default() });
    }
}
