//! What names a term may use: variables (data columns, model states and inputs),
//! parameters (per-run constants such as `u0`), derived variables (`Δu = u - u0`) and
//! aliases (`du` → `Δu`). All are declared, none hard-coded; stage two of reading a term
//! ([`Vocabulary::resolve`]) binds names against it and canonicalises.

use std::collections::BTreeMap;

use super::canon::{Atom, Term};
use super::error::TermError;
use super::functions::{function, FUNCTIONS};
use super::parse::{parse_expr, BinOp, Expr, ExprKind};

/// A derived variable: a name for a term over earlier names, evaluated before the terms.
#[derive(Clone, Debug, PartialEq)]
pub struct Derived {
    /// Its canonical name.
    pub name: String,
    /// Its definition.
    pub definition: Term,
}

/// The names terms may use.
#[derive(Clone, Debug, Default)]
pub struct Vocabulary {
    variables: Vec<String>,
    parameters: Vec<String>,
    derived: Vec<Derived>,
    aliases: BTreeMap<String, String>,
    open: bool,
    /// The time's name, which no term holds: named as such where a term uses it.
    time: Option<String>,
    /// Every declared name → its place in `derived` (None: a variable or parameter), so that
    /// a look-up does not scan (a file of 10⁵ derived variables loads in linear time).
    index: rustc_hash::FxHashMap<String, Option<usize>>,
}

/// `∆` (U+2206, the increment sign keyboards produce) is read as `Δ` (U+0394).
fn normalise_name(name: &str) -> String {
    name.replace('\u{2206}', "\u{394}")
}

/// A name as it looks: combining marks dropped, accented Latin letters and the Cyrillic and
/// Greek letters drawn like Latin ones mapped to those.
fn skeleton(name: &str) -> String {
    name.chars()
        .filter(|c| !('\u{300}'..='\u{36f}').contains(c))
        .map(|c| match c {
            'à' | 'á' | 'â' | 'ã' | 'ä' | 'å' | 'а' | 'α' => 'a',
            'è' | 'é' | 'ê' | 'ë' | 'е' | 'ε' => 'e',
            'ì' | 'í' | 'î' | 'ï' | 'і' | 'ι' => 'i',
            'ò' | 'ó' | 'ô' | 'õ' | 'ö' | 'о' | 'ο' => 'o',
            'ù' | 'ú' | 'û' | 'ü' | 'υ' => 'u',
            'ý' | 'ÿ' | 'у' => 'y',
            'ñ' => 'n',
            'ç' | 'с' => 'c',
            'р' | 'ρ' => 'p',
            'х' | 'χ' => 'x',
            'ѕ' => 's',
            'ј' => 'j',
            'к' | 'κ' => 'k',
            'м' => 'm',
            'т' | 'τ' => 't',
            'в' => 'b',
            'н' | 'η' => 'h',
            'ν' => 'v',
            other => other,
        })
        .collect()
}

/// A name's characters as code points (`U+0445`), to show what differs.
pub fn code_points(name: &str) -> String {
    name.chars().map(|c| format!("U+{:04X}", c as u32)).collect::<Vec<_>>().join(" ")
}

/// Whether `name` is one name of the term language (`u`, `x_dot`, `Δu`), as a variable, a
/// parameter or a time column must be.
pub fn is_identifier(name: &str) -> bool {
    // plain ASCII names (`c12`, `x_dot`) are identifiers of the grammar without asking it
    let mut chars = name.chars();
    let ascii = chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    ascii || matches!(parse_expr(name), Ok(Expr { kind: ExprKind::Var(_), .. }))
}

impl Vocabulary {
    /// An empty vocabulary.
    pub fn new() -> Self {
        Self::default()
    }

    /// A vocabulary that accepts any identifier as a variable (for ad-hoc use and tests).
    pub fn open() -> Self {
        Vocabulary { open: true, ..Self::default() }
    }

    /// Names the time (a model's `model.time`), so that a term that uses it is told why no
    /// term may: it is no variable.
    pub fn with_time(&mut self, name: &str) -> &mut Self {
        self.time = Some(name.to_string());
        self
    }

    fn check_new(&self, name: &str) -> Result<String, TermError> {
        let name = normalise_name(name);
        if !is_identifier(&name) {
            // a column header that carries its unit: plain files and dataset files read it by
            // its bare name
            let hint = match name.split_once('[') {
                Some((bare, unit)) if unit.ends_with(']') && is_identifier(bare.trim()) => format!(
                    " (a header with its unit: a file's column `{name}` is read as `{bare}` in SI, a \
                     dataset file's by `[columns] {bare} = \"{name}\"`)",
                    bare = bare.trim()
                ),
                _ => {
                    // `x.pos`, `y pos`, `z-pos`: the same with `_`, where that makes a name
                    let bare: String = name
                        .trim()
                        .chars()
                        .map(|c| if c.is_alphanumeric() || c == '_' || c == '∆' { c } else { '_' })
                        .collect();
                    if is_identifier(&bare) {
                        format!(
                            " (a name is letters, digits and `_`, not a digit first: call it `{bare}`, the column \
                             renamed or mapped in a dataset file, `[columns] {bare} = \"{name}\"`)"
                        )
                    } else {
                        " (a name is letters, digits and `_`, not a digit first)".to_string()
                    }
                }
            };
            return Err(TermError::Declaration(format!("`{name}` is not a valid name{hint}")));
        }
        if self.is_declared(&name) || self.aliases.contains_key(&name) {
            return Err(TermError::Declaration(format!("`{name}` is declared twice")));
        }
        if function(&name).is_some() {
            return Err(TermError::Declaration(format!("`{name}` is a function name")));
        }
        Ok(name)
    }

    fn is_declared(&self, name: &str) -> bool {
        self.index.contains_key(name)
    }

    /// Declares a variable (a data column, state or input).
    pub fn variable(&mut self, name: &str) -> Result<&mut Self, TermError> {
        let name = self.check_new(name)?;
        self.index.insert(name.clone(), None);
        self.variables.push(name);
        Ok(self)
    }

    /// Declares a parameter (a constant per data set, e.g. `u0`).
    pub fn parameter(&mut self, name: &str) -> Result<&mut Self, TermError> {
        let name = self.check_new(name)?;
        self.index.insert(name.clone(), None);
        self.parameters.push(name);
        Ok(self)
    }

    /// Declares `name = definition`, the definition using earlier names only.
    pub fn derive(&mut self, name: &str, definition: &str) -> Result<&mut Self, TermError> {
        let name = self.check_new(name)?;
        let definition = self.parse(definition)?;
        self.index.insert(name.clone(), Some(self.derived.len()));
        self.derived.push(Derived { name, definition });
        Ok(self)
    }

    /// Declares `alias` as another spelling of `target` (e.g. `du` for `Δu`).
    pub fn alias(&mut self, alias: &str, target: &str) -> Result<&mut Self, TermError> {
        let alias = self.check_new(alias)?;
        let target = normalise_name(target);
        if !self.is_declared(&target) {
            return Err(TermError::Declaration(format!(
                "alias `{alias}` points to `{target}`, which is not declared"
            )));
        }
        self.aliases.insert(alias, target);
        Ok(self)
    }

    /// The declared variables, in order.
    pub fn variables(&self) -> &[String] {
        &self.variables
    }

    /// The declared parameters, in order.
    pub fn parameters(&self) -> &[String] {
        &self.parameters
    }

    /// The derived variables, in order of declaration.
    pub fn derived(&self) -> &[Derived] {
        &self.derived
    }

    /// The aliases (alias → canonical name).
    pub fn aliases(&self) -> &BTreeMap<String, String> {
        &self.aliases
    }

    /// A derived variable's definition.
    pub fn derived_definition(&self, name: &str) -> Option<&Term> {
        self.index.get(name).copied().flatten().map(|k| &self.derived[k].definition)
    }

    /// Whether `name` (a variable or a derived variable) is `variable` or is defined through
    /// it, however deep the derived variables go (`Δu = u - u0` depends on `u`).
    pub fn depends_on(&self, name: &str, variable: &str) -> bool {
        name == variable
            || self
                .derived_definition(name)
                .is_some_and(|d| d.variables().iter().any(|v| v != name && self.depends_on(v, variable)))
    }

    /// A declared name that `name` looks like but is not (a Cyrillic `х` for `x`, a
    /// decomposed `é` for a composed one): for an error that names the look-alike.
    pub fn look_alike(&self, name: &str) -> Option<String> {
        let want = skeleton(name);
        self.index
            .keys()
            .chain(self.aliases.keys())
            .find(|k| k.as_str() != name && skeleton(k) == want)
            .cloned()
    }

    /// The canonical spelling of a name, if the vocabulary knows it.
    pub fn canonical(&self, name: &str) -> Option<String> {
        let name = normalise_name(name);
        if self.is_declared(&name) {
            return Some(name);
        }
        if let Some(t) = self.aliases.get(&name) {
            return Some(t.clone());
        }
        (self.open && function(&name).is_none()).then_some(name)
    }

    /// Parses and resolves a term's text.
    pub fn parse(&self, text: &str) -> Result<Term, TermError> {
        // a declared name alone is that variable (declared names are identifiers, so the
        // grammar would say the same): a finished matrix's columns skip the parser (~4 µs each)
        if self.is_declared(text) {
            return Ok(Term::var(text));
        }
        let expr = parse_expr(text)?;
        self.resolve(&expr, text)
    }

    /// Binds the names of a parsed expression and canonicalises it.
    pub fn resolve(&self, expr: &Expr, input: &str) -> Result<Term, TermError> {
        let at = |msg: String| TermError::at(input, expr.span.0, expr.span.1, msg);
        match &expr.kind {
            ExprKind::Num(v) => Ok(Term::constant(*v)),
            ExprKind::Var(name) => match self.canonical(name) {
                Some(c) => Ok(Term::var(&c)),
                // π by name, where no variable takes the name (`sin(θ*pi/180)` for degrees)
                None if name == "pi" || name == "π" => Ok(Term::constant(std::f64::consts::PI)),
                None if function(name).is_some() => {
                    Err(at(format!("`{name}` is a function: write `{name}(…)`")))
                }
                // a term is a function of the states and inputs at an instant: a simulation's clock
                // starts at 0, a run's at its first sample, so a term of the time would differ
                None if self.time.as_deref() == Some(name.as_str()) => Err(at(format!(
                    "`{name}` is the time, which no term holds (a simulation's clock starts at 0, a run's at its first sample): a forcing that follows the clock, cos(1.2·{name}) or a ramp, is an input: add it to the runs as a column of its own and name it among the inputs"
                ))),
                None => Err(at(match self.look_alike(name) {
                    Some(like) => format!(
                        "unknown variable `{name}`: it looks like `{like}` but is spelt with other characters ({} against {})",
                        code_points(name),
                        code_points(&like)
                    ),
                    None => format!("unknown variable `{name}`; {}", self.known_names()),
                })),
            },
            ExprKind::Neg(e) => self.resolve(e, input)?.scale(-1.0).map_err(at),
            ExprKind::Pow(e, k) => self.resolve(e, input)?.powi(*k).map_err(at),
            ExprKind::Bin(op, a, b) => {
                let (a, b) = (self.resolve(a, input)?, self.resolve(b, input)?);
                match op {
                    BinOp::Add => a.add(&b),
                    BinOp::Sub => a.add(&b.scale(-1.0).map_err(at)?),
                    BinOp::Mul => a.mul(&b),
                    BinOp::Div => b.powi(-1).and_then(|inv| a.mul(&inv)),
                }
                .map_err(at)
            }
            ExprKind::Call(name, name_span, args) => {
                let Some((_, func)) = function(name) else {
                    let known: Vec<_> = FUNCTIONS.iter().map(|f| f.name).collect();
                    return Err(TermError::at(
                        input,
                        name_span.0,
                        name_span.1,
                        format!("unknown function `{name}`; known: {}", known.join(", ")),
                    ));
                };
                if args.len() != func.arity {
                    return Err(at(format!(
                        "function `{name}` takes {} argument{}, found {}",
                        func.arity,
                        if func.arity == 1 { "" } else { "s" },
                        args.len()
                    )));
                }
                let args = args.iter().map(|a| self.resolve(a, input)).collect::<Result<Vec<_>, _>>()?;
                Ok(Term::atom(Atom::Call(name.clone(), args)))
            }
        }
    }

    fn known_names(&self) -> String {
        let mut names: Vec<String> = self
            .variables
            .iter()
            .chain(&self.parameters)
            .cloned()
            .chain(self.derived.iter().map(|d| d.name.clone()))
            .collect();
        names.extend(self.aliases.iter().map(|(a, t)| format!("{a} (= {t})")));
        if names.is_empty() {
            "no names are declared".into()
        } else {
            format!("known: {}", names.join(", "))
        }
    }

    /// Tree-walking interpreter of a parsed expression, the reference the compiled evaluator
    /// is tested against. `value` gives base variables and parameters; derived variables are
    /// expanded through their definitions.
    pub fn interpret(&self, expr: &Expr, value: &dyn Fn(&str) -> f64) -> f64 {
        match &expr.kind {
            ExprKind::Num(v) => *v,
            ExprKind::Var(name) => self.value_of(&self.canonical(name).unwrap_or_default(), value),
            ExprKind::Neg(e) => -self.interpret(e, value),
            ExprKind::Pow(e, k) => self.interpret(e, value).powi(*k),
            ExprKind::Bin(op, a, b) => {
                let (a, b) = (self.interpret(a, value), self.interpret(b, value));
                match op {
                    BinOp::Add => a + b,
                    BinOp::Sub => a - b,
                    BinOp::Mul => a * b,
                    BinOp::Div => a / b,
                }
            }
            ExprKind::Call(name, _, args) => {
                let args: Vec<f64> = args.iter().map(|a| self.interpret(a, value)).collect();
                function(name).map_or(f64::NAN, |(_, f)| (f.eval)(&args))
            }
        }
    }

    /// Value of a canonical name: a base value, or a derived variable's definition.
    pub fn value_of(&self, name: &str, value: &dyn Fn(&str) -> f64) -> f64 {
        match self.derived_definition(name) {
            Some(def) => def.eval(&|n| self.value_of(n, value)),
            None => value(name),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ship() -> Vocabulary {
        let mut v = Vocabulary::new();
        v.variable("u").unwrap().variable("v").unwrap().variable("r").unwrap();
        v.variable("δ").unwrap().parameter("u0").unwrap();
        v.derive("Δu", "u - u0").unwrap();
        v.alias("du", "Δu").unwrap().alias("delta", "δ").unwrap();
        v
    }

    #[test]
    fn aliases_and_math_delta_resolve() {
        let v = ship();
        assert_eq!(v.parse("u*du").unwrap(), v.parse("Δu*u").unwrap());
        assert_eq!(v.parse("u*∆u").unwrap(), v.parse("u*Δu").unwrap());
        assert_eq!(v.parse("u^2*delta^3").unwrap().to_string(), "u^2*δ^3");
        assert_eq!(v.parse("v^2*r/u").unwrap().to_string(), "r*v^2/u");
    }

    #[test]
    fn a_header_with_its_unit_is_pointed_to_its_bare_name() {
        let e = Vocabulary::new().variable("x [m]").map(|_| ()).unwrap_err().to_string();
        assert!(e.contains("is read as `x` in SI") && e.contains("`[columns] x = \"x [m]\"`"), "{e}");
        let e = Vocabulary::new().variable("x y").map(|_| ()).unwrap_err().to_string();
        assert!(e.contains("`x y` is not a valid name") && e.contains("call it `x_y`"), "{e}");
        let e = Vocabulary::new().variable("x.pos").map(|_| ()).unwrap_err().to_string();
        assert!(e.contains("`[columns] x_pos = \"x.pos\"`"), "{e}");
        let e = Vocabulary::new().variable("2x").map(|_| ()).unwrap_err().to_string();
        assert!(e.ends_with("not a digit first)"), "{e}");
    }

    /// `pi` and `π` are π (degrees written as they are read), unless the model names a
    /// variable so.
    #[test]
    fn pi_is_pi_unless_a_variable_takes_the_name() {
        let v = ship();
        assert_eq!(v.parse("sin(δ*pi/180)").unwrap(), v.parse("sin(0.017453292519943295*δ)").unwrap());
        assert_eq!(v.parse("π*u").unwrap(), v.parse("3.141592653589793*u").unwrap());
        let mut named = ship();
        named.variable("pi").unwrap();
        assert_eq!(named.parse("pi*u").unwrap().variables(), ["pi", "u"]);
    }

    #[test]
    fn meaning_errors_point_at_the_name() {
        let v = ship();
        let e = v.parse("u*w").unwrap_err();
        assert_eq!(e.line_col(), Some((1, 3)));
        assert!(e.to_string().contains("unknown variable `w`"), "{e}");
        // the time, named as such: a term of the clock is an input's column
        let mut timed = ship();
        timed.with_time("t");
        let e = timed.parse("u*cos(t)").unwrap_err();
        assert_eq!(e.line_col(), Some((1, 7)));
        assert!(e.to_string().contains("`t` is the time, which no term holds"), "{e}");
        let e = v.parse("foo(u)").unwrap_err();
        assert!(e.to_string().contains("unknown function `foo`"), "{e}");
        let e = v.parse("abs(u, v)").unwrap_err();
        assert!(e.to_string().contains("takes 1 argument, found 2"), "{e}");
        let e = v.parse("u/0").unwrap_err();
        assert!(e.to_string().contains("division by zero"), "{e}");
    }
}
