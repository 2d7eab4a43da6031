//! The canonical form of a term: a sum of monomials, each a coefficient times a sorted
//! product of atoms raised to non-zero integer powers. `r*v` and `v*r`, `u*u` and `u^2`,
//! `1/u` and `u^-1` are one value of [`Term`]; its `Display` is the one printer, and its
//! output parses back to an equal term.

use std::cmp::Ordering;
use std::fmt;
use std::hash::{Hash, Hasher};

/// Products of more monomials than this are refused rather than multiplied out.
const MAX_MONOMIALS: usize = 256;

/// A canonical term: monomials sorted by their factors, like monomials merged, no zero
/// coefficients. The empty sum is the constant 0.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct Term {
    monomials: Vec<Monomial>,
}

/// A coefficient times a product of powers of atoms (sorted by atom, exponents ≠ 0).
#[derive(Clone, Debug)]
pub struct Monomial {
    /// The numerical factor (finite, non-zero).
    pub coef: f64,
    /// The atoms with their integer exponents, sorted by atom.
    pub factors: Vec<(Atom, i32)>,
}

/// What a monomial multiplies: a name, a function call, or a sum that cannot be expanded
/// (a power of a sum, kept factored: `1/(u + v)`, `(1.75 - u)^3`).
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Atom {
    /// A variable, parameter or derived variable, by canonical name.
    Var(String),
    /// A function applied to terms.
    Call(String, Vec<Term>),
    /// A sum under a power other than 1, normalised so its first coefficient is 1.
    Group(Term),
}

fn coef_bits(c: f64) -> u64 {
    // +0.0 and -0.0 never occur (zero coefficients are dropped), NaN is refused upstream.
    c.to_bits()
}

impl PartialEq for Monomial {
    fn eq(&self, other: &Self) -> bool {
        coef_bits(self.coef) == coef_bits(other.coef) && self.factors == other.factors
    }
}
impl Eq for Monomial {}
impl Hash for Monomial {
    fn hash<H: Hasher>(&self, state: &mut H) {
        coef_bits(self.coef).hash(state);
        self.factors.hash(state);
    }
}
impl PartialOrd for Monomial {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Monomial {
    fn cmp(&self, other: &Self) -> Ordering {
        self.factors.cmp(&other.factors).then(self.coef.total_cmp(&other.coef))
    }
}

/// Why an arithmetic step of canonicalisation failed (the caller adds the caret).
pub(crate) type CanonResult = Result<Term, String>;

impl Term {
    /// The constant `c`.
    pub fn constant(c: f64) -> Term {
        let mut t = Term { monomials: vec![Monomial { coef: c, factors: vec![] }] };
        t.monomials.retain(|m| m.coef != 0.0);
        t
    }

    /// A single atom to the first power.
    pub fn atom(a: Atom) -> Term {
        Term { monomials: vec![Monomial { coef: 1.0, factors: vec![(a, 1)] }] }
    }

    /// A variable by canonical name.
    pub fn var(name: &str) -> Term {
        Term::atom(Atom::Var(name.to_string()))
    }

    /// The monomials, sorted.
    pub fn monomials(&self) -> &[Monomial] {
        &self.monomials
    }

    /// True for the constant 0.
    pub fn is_zero(&self) -> bool {
        self.monomials.is_empty()
    }

    /// True if the term has no atoms (a constant, possibly 0).
    pub fn is_constant(&self) -> bool {
        self.monomials.iter().all(|m| m.factors.is_empty())
    }

    /// Names of all variables the term uses, including inside calls and groups.
    pub fn variables(&self) -> Vec<String> {
        let mut out = Vec::new();
        self.collect_vars(&mut out);
        out.sort();
        out.dedup();
        out
    }

    fn collect_vars(&self, out: &mut Vec<String>) {
        for m in &self.monomials {
            for (a, _) in &m.factors {
                match a {
                    Atom::Var(n) => out.push(n.clone()),
                    Atom::Call(_, args) => args.iter().for_each(|t| t.collect_vars(out)),
                    Atom::Group(t) => t.collect_vars(out),
                }
            }
        }
    }

    fn normalise(monomials: Vec<Monomial>) -> CanonResult {
        let mut monomials = Term::settle_groups(monomials)?;
        if monomials.iter().any(|m| !m.coef.is_finite()) {
            return Err("a constant in this term overflows".into());
        }
        monomials.sort_by(|a, b| a.factors.cmp(&b.factors));
        let mut out: Vec<Monomial> = Vec::with_capacity(monomials.len());
        for m in monomials {
            match out.last_mut() {
                Some(last) if last.factors == m.factors => last.coef += m.coef,
                _ => out.push(m),
            }
        }
        out.retain(|m| m.coef != 0.0);
        if out.iter().any(|m| !m.coef.is_finite()) {
            return Err("a constant in this term overflows".into());
        }
        Ok(Term { monomials: out })
    }

    /// A group (a sum under a power) is canonical at any exponent but 1: `(u + v)^1` is just
    /// the sum, multiplied out into its neighbours. Powers of sums stay factored, which keeps
    /// `(1.75 - u)^-3` accurate near u = 1.75 where the expanded polynomial would cancel.
    fn settle_groups(monomials: Vec<Monomial>) -> Result<Vec<Monomial>, String> {
        let unsettled =
            |m: &Monomial| m.factors.iter().position(|(a, e)| matches!(a, Atom::Group(_)) && *e == 1);
        if !monomials.iter().any(|m| unsettled(m).is_some()) {
            return Ok(monomials);
        }
        let mut out = Term::default();
        for mut m in monomials {
            let part = match unsettled(&m) {
                None => Term { monomials: vec![m] },
                Some(pos) => {
                    let (atom, _) = m.factors.remove(pos);
                    let Atom::Group(h) = atom else { unreachable!("position() matched a group") };
                    Term { monomials: vec![m] }.mul(&h)?
                }
            };
            out = out.add(&part)?;
        }
        Ok(out.monomials)
    }

    /// Sum of two terms.
    pub fn add(&self, other: &Term) -> CanonResult {
        let mut all = self.monomials.clone();
        all.extend(other.monomials.iter().cloned());
        Term::normalise(all)
    }

    /// The term times a constant.
    pub fn scale(&self, c: f64) -> CanonResult {
        Term::normalise(
            self.monomials
                .iter()
                .map(|m| Monomial { coef: m.coef * c, factors: m.factors.clone() })
                .collect(),
        )
    }

    /// Product of two terms, expanded.
    pub fn mul(&self, other: &Term) -> CanonResult {
        if self.monomials.len() * other.monomials.len() > MAX_MONOMIALS {
            return Err(format!("this product expands to more than {MAX_MONOMIALS} monomials"));
        }
        let mut all = Vec::with_capacity(self.monomials.len() * other.monomials.len());
        for a in &self.monomials {
            for b in &other.monomials {
                all.push(Monomial { coef: a.coef * b.coef, factors: merge(&a.factors, &b.factors)? });
            }
        }
        Term::normalise(all)
    }

    /// Integer power. A sum under a power other than 1 becomes a [`Atom::Group`].
    pub fn powi(&self, k: i32) -> CanonResult {
        if k == 0 {
            return Ok(Term::constant(1.0));
        }
        match self.monomials.as_slice() {
            [] if k < 0 => Err("division by zero".into()),
            [] => Ok(Term::default()),
            [m] => {
                let factors = m
                    .factors
                    .iter()
                    .map(|(a, e)| {
                        e.checked_mul(k)
                            .map(|e| (a.clone(), e))
                            .ok_or_else(|| "exponent out of range".to_string())
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                Term::normalise(vec![Monomial { coef: m.coef.powi(k), factors }])
            }
            [first, ..] => {
                if k == 1 {
                    return Ok(self.clone());
                }
                // factor out the leading coefficient (by division, so the group's is exactly 1):
                // the first variable monomial's, so `(T - 300)^2` stays as written rather than
                // `90000*(1 - 0.0033…*T)^2`
                let lead = self.monomials.iter().find(|m| !m.factors.is_empty()).unwrap_or(first).coef;
                let group = Term::normalise(
                    self.monomials
                        .iter()
                        .map(|m| Monomial { coef: m.coef / lead, factors: m.factors.clone() })
                        .collect(),
                )?;
                Term::normalise(vec![Monomial { coef: lead.powi(k), factors: vec![(Atom::Group(group), k)] }])
            }
        }
    }

    /// Evaluates the canonical form directly (slow; the reference for the compiler).
    pub fn eval(&self, value: &dyn Fn(&str) -> f64) -> f64 {
        self.monomials
            .iter()
            .map(|m| m.coef * m.factors.iter().map(|(a, k)| ipow(atom_value(a, value), *k)).product::<f64>())
            .sum()
    }
}

/// x^k by the recipe the compiler uses (binary powering; a negative power is the reciprocal
/// of the positive one), so the interpreter and compiled code round alike.
pub(crate) fn ipow(x: f64, k: i32) -> f64 {
    match k {
        _ if k < 0 => 1.0 / ipow(x, k.checked_neg().unwrap_or(i32::MAX)),
        0 => 1.0,
        1 => x,
        _ if k % 2 == 0 => {
            let h = ipow(x, k / 2);
            h * h
        }
        _ => ipow(x, k - 1) * x,
    }
}

fn atom_value(a: &Atom, value: &dyn Fn(&str) -> f64) -> f64 {
    match a {
        Atom::Var(n) => value(n),
        Atom::Group(t) => t.eval(value),
        Atom::Call(f, args) => {
            let args: Vec<f64> = args.iter().map(|t| t.eval(value)).collect();
            match super::functions::function(f) {
                Some((_, func)) => (func.eval)(&args),
                None => f64::NAN,
            }
        }
    }
}

fn merge(a: &[(Atom, i32)], b: &[(Atom, i32)]) -> Result<Vec<(Atom, i32)>, String> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let ord = match (a.get(i), b.get(j)) {
            (Some(x), Some(y)) => x.0.cmp(&y.0),
            (Some(_), None) => Ordering::Less,
            _ => Ordering::Greater,
        };
        match ord {
            Ordering::Less => {
                out.push(a[i].clone());
                i += 1;
            }
            Ordering::Greater => {
                out.push(b[j].clone());
                j += 1;
            }
            Ordering::Equal => {
                let e = a[i].1.checked_add(b[j].1).ok_or("exponent out of range")?;
                if e != 0 {
                    out.push((a[i].0.clone(), e));
                }
                i += 1;
                j += 1;
            }
        }
    }
    Ok(out)
}

fn fmt_coef(c: f64) -> String {
    if c.fract() == 0.0 && c.abs() < 1e15 {
        format!("{}", c as i64)
    } else {
        format!("{c:?}")
    }
}

impl fmt::Display for Atom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Atom::Var(n) => write!(f, "{n}"),
            Atom::Call(name, args) => {
                write!(f, "{name}(")?;
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        write!(f, ", ")?;
                    }
                    write!(f, "{a}")?;
                }
                write!(f, ")")
            }
            Atom::Group(t) => write!(f, "({t})"),
        }
    }
}

fn fmt_power(f: &mut fmt::Formatter<'_>, a: &Atom, k: i32) -> fmt::Result {
    if k == 1 {
        write!(f, "{a}")
    } else {
        write!(f, "{a}^{k}")
    }
}

/// Writes |m| (sign handled by the caller).
fn fmt_monomial_abs(f: &mut fmt::Formatter<'_>, m: &Monomial) -> fmt::Result {
    let c = m.coef.abs();
    let num: Vec<_> = m.factors.iter().filter(|(_, k)| *k > 0).collect();
    let den: Vec<_> = m.factors.iter().filter(|(_, k)| *k < 0).collect();
    if c != 1.0 || num.is_empty() {
        write!(f, "{}", fmt_coef(c))?;
        if !num.is_empty() {
            write!(f, "*")?;
        }
    }
    for (i, (a, k)) in num.iter().enumerate() {
        if i > 0 {
            write!(f, "*")?;
        }
        fmt_power(f, a, *k)?;
    }
    for (a, k) in den {
        write!(f, "/")?;
        fmt_power(f, a, -k)?;
    }
    Ok(())
}

impl fmt::Display for Term {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.monomials.is_empty() {
            return write!(f, "0");
        }
        // a sum's constant written last, as one writes `T - 300` (the order is the printer's;
        // the canonical order, by which terms compare, keeps it first)
        let (constant, rest): (Vec<&Monomial>, Vec<&Monomial>) =
            self.monomials.iter().partition(|m| m.factors.is_empty());
        for (i, m) in rest.into_iter().chain(constant).enumerate() {
            match (i, m.coef < 0.0) {
                (0, true) => write!(f, "-")?,
                (0, false) => {}
                (_, true) => write!(f, " - ")?,
                (_, false) => write!(f, " + ")?,
            }
            fmt_monomial_abs(f, m)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sum prints its constant last and a power of a sum keeps the sum as written (its first
    /// variable's coefficient factored out), as one writes a variable about a reference value.
    #[test]
    fn a_sum_about_a_reference_value_prints_as_written() {
        let (t, c) = (Term::var("T"), Term::constant(300.0));
        let about = t.add(&c.scale(-1.0).unwrap()).unwrap();
        assert_eq!(about.to_string(), "T - 300");
        assert_eq!(about.powi(2).unwrap().to_string(), "(T - 300)^2");
        assert_eq!(about.powi(-1).unwrap().to_string(), "1/(T - 300)");
        let reversed = c.add(&t.scale(-1.0).unwrap()).unwrap().powi(-3).unwrap();
        assert_eq!(reversed.to_string(), "-1/(T - 300)^3");
    }

    #[test]
    fn products_merge_and_sort() {
        let (u, v, r) = (Term::var("u"), Term::var("v"), Term::var("r"));
        assert_eq!(v.mul(&r).unwrap(), r.mul(&v).unwrap());
        assert_eq!(u.mul(&u).unwrap(), u.powi(2).unwrap());
        let inv = u.powi(-1).unwrap();
        assert_eq!(r.mul(&v.powi(2).unwrap()).unwrap().mul(&inv).unwrap().to_string(), "r*v^2/u");
        assert_eq!(u.mul(&inv).unwrap(), Term::constant(1.0));
        assert_eq!(u.add(&v).unwrap().powi(-1).unwrap().to_string(), "1/(u + v)");
        assert_eq!(u.scale(-2.0).unwrap().add(&v).unwrap().to_string(), "-2*u + v");
        assert_eq!(u.add(&u.scale(-1.0).unwrap()).unwrap().to_string(), "0");
    }
}
