//! Constraints of the sparse fit as users write them (a candidate by its term or column,
//! fixed values, signs, linear equalities), resolved to the problem's columns, and the
//! least-squares refit of a support that keeps them.

use serde::{Deserialize, Serialize};

use super::SparseFit;
use crate::select::subset::Scaled;
use crate::select::{Problem, SelectError, Step};

/// A candidate named in a constraint: its term as model files write it (`"u*δ"`, matched
/// against the candidates' canonical texts; a model file's are canonicalised when it is read)
/// or its 0-based column among the candidates.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Candidate {
    /// Column index.
    Column(usize),
    /// Term text.
    Term(String),
}

impl std::fmt::Display for Candidate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Candidate::Column(j) => write!(f, "column {j}"),
            Candidate::Term(t) => write!(f, "`{t}`"),
        }
    }
}

impl From<usize> for Candidate {
    fn from(j: usize) -> Candidate {
        Candidate::Column(j)
    }
}

impl From<&str> for Candidate {
    fn from(t: &str) -> Candidate {
        Candidate::Term(t.into())
    }
}

impl Candidate {
    /// The column it names among `names`, or an error that lists them.
    pub fn column(&self, names: &[String]) -> Result<usize, SelectError> {
        let found = match self {
            Candidate::Column(j) => Some(*j).filter(|j| *j < names.len()),
            Candidate::Term(t) => names.iter().position(|n| n == t),
        };
        found.ok_or_else(|| {
            SelectError::Config(format!(
                "a sparse constraint names {self}, which is not a candidate (candidates: {})",
                names.join(", ")
            ))
        })
    }
}

/// A linear equality between coefficients: Σ factor × b(term) = value (raw units).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Equality {
    /// (candidate, factor).
    pub terms: Vec<(Candidate, f64)>,
    /// Right-hand side.
    pub value: f64,
}

/// The constraints with every candidate resolved to its column (checked against the problem).
#[derive(Clone, Debug, Default)]
pub(super) struct Columns {
    pub(super) fixed: Vec<(usize, f64)>,
    pub(super) signs: Vec<(usize, f64)>,
    pub(super) equalities: Vec<(Vec<(usize, f64)>, f64)>,
    /// The constraints as a person reads them (`x3 = 1, x3 ≤ 0`), for the error when they conflict.
    pub(super) text: String,
}

impl Columns {
    pub(super) fn is_empty(&self) -> bool {
        self.fixed.is_empty() && self.signs.is_empty() && self.equalities.is_empty()
    }
}

impl SparseFit {
    /// The constraints on the problem's columns: every named candidate must be one, and a
    /// candidate may be fixed or signed once.
    pub(super) fn columns(&self, pb: &Problem<'_>) -> Result<Columns, SelectError> {
        let col = |c: &Candidate| c.column(pb.names);
        let pairs = |list: &[(Candidate, f64)], what: &str| -> Result<Vec<(usize, f64)>, SelectError> {
            let mut out: Vec<(usize, f64)> = Vec::new();
            for (c, v) in list {
                let j = col(c)?;
                if out.iter().any(|(i, _)| *i == j) {
                    return Err(SelectError::Config(format!(
                        "sparse `{what}` names `{}` twice",
                        pb.names[j]
                    )));
                }
                out.push((j, *v));
            }
            Ok(out)
        };
        let mut equalities = Vec::new();
        for e in &self.equalities {
            let terms =
                e.terms.iter().map(|(c, f)| Ok((col(c)?, *f))).collect::<Result<Vec<_>, SelectError>>()?;
            equalities.push((terms, e.value));
        }
        let (fixed, signs) = (pairs(&self.fixed, "fixed")?, pairs(&self.signs, "signs")?);
        let name = |j: usize| pb.names[j].as_str();
        let text = fixed
            .iter()
            .map(|&(j, v)| format!("{} = {v}", name(j)))
            .chain(signs.iter().map(|&(j, s)| format!("{} {} 0", name(j), if s > 0.0 { "≥" } else { "≤" })))
            .chain(equalities.iter().map(|(terms, v)| {
                let lhs: Vec<String> = terms.iter().map(|&(j, f)| format!("{f}·{}", name(j))).collect();
                format!("{} = {v}", lhs.join(" + "))
            }))
            .collect::<Vec<_>>()
            .join(", ");
        let columns = Columns { fixed, signs, equalities, text };
        for &j in columns
            .fixed
            .iter()
            .map(|(j, _)| j)
            .chain(columns.equalities.iter().flat_map(|e| e.0.iter().map(|(j, _)| j)))
        {
            if pb.excluded.contains(&j) {
                return Err(SelectError::Config(format!(
                    "sparse constraint on `{}`, which is excluded",
                    pb.names[j]
                )));
            }
        }
        Ok(columns)
    }

    /// Least squares on `support` under the constraints, written into the step: its
    /// coefficients, intercept and fit; a fixed coefficient's standard error is 0 (it is not
    /// estimated), the others keep the unconstrained fit's. Returns the residual share 1 − R².
    pub(super) fn constrained_refit(
        &self,
        sc: &Scaled,
        w: &[f64],
        support: &[usize],
        c: &Columns,
        st: &mut Step,
    ) -> Result<f64, SelectError> {
        let (p, m) = (sc.p, sc.m);
        let beta = self.solve(sc, 0.0, w, support, c)?;
        // 1 − R² = 1 − 2 rᵀβ + βᵀRβ in correlation scale
        let mut rss = 1.0;
        for &i in support {
            rss -= 2.0 * sc.a[i * m + p] * beta[i];
            for &j in support {
                rss += beta[i] * sc.a[i * m + j] * beta[j];
            }
        }
        let rss = rss.max(0.0);
        st.coefficients = support.iter().map(|&j| beta[j] * sc.d[p] / sc.d[j]).collect();
        for (k, &j) in support.iter().enumerate() {
            if c.fixed.iter().any(|(f, _)| *f == j) {
                st.std_errors[k] = 0.0;
            }
        }
        if let Some(b0) = st.intercept.as_mut() {
            let means = &sc.means;
            b0.value =
                means[p] - support.iter().zip(&st.coefficients).map(|(&j, b)| b * means[j]).sum::<f64>();
            b0.t = b0.value / b0.std_error;
        }
        let r2 = 1.0 - rss;
        let dof = sc.n_eff - support.len() as f64;
        st.r2 = r2;
        st.r = r2.max(0.0).sqrt();
        st.standard_error = (rss * sc.total / dof.max(1.0)).sqrt();
        st.f = if rss > 0.0 { r2 / support.len() as f64 / (rss / dof.max(1.0)) } else { f64::INFINITY };
        Ok(rss)
    }
}
