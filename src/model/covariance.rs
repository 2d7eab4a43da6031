//! The covariance of an equation's coefficients, as identification stores it for Monte-Carlo
//! prediction bands, and the one check it passes whether it comes from a fit or a file.

use super::{CovarianceSpec, Model};
use crate::term::Term;

/// The covariance of an equation's coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct Covariance {
    /// The terms (each one of the equation's coefficients), in matrix order.
    pub terms: Vec<Term>,
    /// s²(X'X)⁻¹, row-major; symmetric and positive semi-definite.
    pub matrix: Vec<Vec<f64>>,
    /// Residual autocorrelation time in rows (≥ 1); the effective covariance is matrix × this.
    pub correlation_time: f64,
}

/// Why a covariance does not fit its equation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CovarianceError {
    /// No such equation.
    #[error("no equation `{0}`")]
    NoEquation(String),
    /// τ below 1 or not finite.
    #[error("correlation time {0} must be a number ≥ 1")]
    CorrelationTime(f64),
    /// A term that is no coefficient of the equation.
    #[error("`{0}` is not a coefficient of the equation")]
    NotACoefficient(String),
    /// A term named twice.
    #[error("`{0}` appears twice in the covariance's terms")]
    Twice(String),
    /// The matrix is not k×k.
    #[error("`matrix` must be {0}×{0}, one row per term")]
    Shape(usize),
    /// A value is not finite.
    #[error("`matrix` has a value that is not finite")]
    NotFinite,
    /// Not symmetric beyond round-off.
    #[error("`matrix` is not symmetric: [{i}][{j}] = {upper} but [{j}][{i}] = {lower}")]
    NotSymmetric {
        /// Row.
        i: usize,
        /// Column.
        j: usize,
        /// m\[i\]\[j\].
        upper: f64,
        /// m\[j\]\[i\].
        lower: f64,
    },
    /// A negative eigenvalue beyond round-off.
    #[error("`matrix` is not positive semi-definite (eigenvalue {0:e})")]
    NotPositive(f64),
    /// Its eigenvalues not found (values that overflow, or a decomposition that never ends).
    #[error("`matrix`'s eigenvalues could not be found (values near overflow?): give it in units that keep its values nearer 1")]
    Undecomposed,
}

impl Model {
    /// Stores the covariance of an equation's coefficients. Refused unless every term is a
    /// coefficient, the matrix a covariance matrix and the correlation time ≥ 1.
    pub fn set_covariance(&mut self, equation: &str, covariance: Covariance) -> Result<(), CovarianceError> {
        let eq = self
            .equations
            .iter_mut()
            .find(|e| e.name == equation)
            .ok_or_else(|| CovarianceError::NoEquation(equation.into()))?;
        check(&eq.coefficients, &covariance)?;
        if let Some(spec) = self.spec.equations.get_mut(equation) {
            spec.covariance = Some(CovarianceSpec {
                terms: covariance.terms.iter().map(Term::to_string).collect(),
                matrix: covariance.matrix.clone(),
                correlation_time: covariance.correlation_time,
            });
        }
        eq.covariance = Some(covariance);
        Ok(())
    }
}

/// A covariance fits its equation: τ ≥ 1, every term one of the equation's coefficients and
/// named once, the matrix k×k, finite, symmetric and positive semi-definite. The one check for
/// model files and for `set_covariance`.
pub(super) fn check(
    coefficients: &[(Term, f64, Option<f64>)],
    c: &Covariance,
) -> Result<(), CovarianceError> {
    if !(c.correlation_time >= 1.0 && c.correlation_time.is_finite()) {
        return Err(CovarianceError::CorrelationTime(c.correlation_time));
    }
    for (i, t) in c.terms.iter().enumerate() {
        if !coefficients.iter().any(|(o, _, _)| o == t) {
            return Err(CovarianceError::NotACoefficient(t.to_string()));
        }
        if c.terms[..i].contains(t) {
            return Err(CovarianceError::Twice(t.to_string()));
        }
    }
    let (m, k) = (&c.matrix, c.terms.len());
    if m.len() != k || m.iter().any(|r| r.len() != k) {
        return Err(CovarianceError::Shape(k));
    }
    if m.iter().flatten().any(|v| !v.is_finite()) {
        return Err(CovarianceError::NotFinite);
    }
    for i in 0..k {
        for j in 0..i {
            if (m[i][j] - m[j][i]).abs() > 1e-9 * (m[i][i] * m[j][j]).sqrt().max(f64::MIN_POSITIVE) {
                return Err(CovarianceError::NotSymmetric { i, j, upper: m[i][j], lower: m[j][i] });
            }
        }
    }
    let a = nalgebra::DMatrix::from_fn(k, k, |i, j| m[i][j]);
    let eigen = crate::linalg::symmetric_eigen(a).ok_or(CovarianceError::Undecomposed)?;
    let smallest = eigen.eigenvalues.iter().copied().fold(f64::INFINITY, f64::min);
    let largest = m.iter().enumerate().map(|(i, r)| r[i]).fold(0.0, f64::max);
    if k > 0 && smallest < -1e-9 * largest {
        return Err(CovarianceError::NotPositive(smallest));
    }
    Ok(())
}
