//! Numerical time derivatives of sampled signals. Central differences are the paper's
//! choice (Oltmann 1973, §8 alternative 4); smoothing methods for noisy measurements plug in
//! as further implementations of [`Differentiator`] and one row of [`DIFFERENTIATORS`].

use super::DataError;

/// Differentiates one signal sampled at strictly increasing times.
pub trait Differentiator: Send + Sync {
    /// Stable name used on the CLI and in model files.
    fn name(&self) -> &'static str;
    /// dx/dt at every sample.
    fn differentiate(&self, t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError>;
}

/// Second-order central differences, exact for quadratics also on uneven spacing; the
/// end points use the second-order one-sided three-point formula.
#[derive(Clone, Copy, Debug, Default)]
pub struct CentralDifference;

/// Weights of the three-point derivative at `t[k]` from samples `i0, i0+1, i0+2`.
fn three_point(t: &[f64], i0: usize, k: usize) -> [f64; 3] {
    let (a, b, c) = (t[i0], t[i0 + 1], t[i0 + 2]);
    let x = t[k];
    // derivative of the Lagrange basis polynomials at x
    [
        ((x - b) + (x - c)) / ((a - b) * (a - c)),
        ((x - a) + (x - c)) / ((b - a) * (b - c)),
        ((x - a) + (x - b)) / ((c - a) * (c - b)),
    ]
}

impl Differentiator for CentralDifference {
    fn name(&self) -> &'static str {
        "central"
    }

    fn differentiate(&self, t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError> {
        let n = t.len();
        if n < 3 || x.len() != n {
            return Err(DataError::TooShort {
                file: "signal".into(),
                rows: n.min(x.len()),
                needed: 3,
                what: "central differences".into(),
            });
        }
        let d = |i0: usize, k: usize| {
            let w = three_point(t, i0, k);
            w[0] * x[i0] + w[1] * x[i0 + 1] + w[2] * x[i0 + 2]
        };
        let mut out = Vec::with_capacity(n);
        out.push(d(0, 0));
        for k in 1..n - 1 {
            out.push(d(k - 1, k));
        }
        out.push(d(n - 3, n - 1));
        Ok(out)
    }
}

/// Makes a differentiator with default settings.
pub type MakeDifferentiator = fn() -> Box<dyn Differentiator>;

/// The derivative methods by name.
pub static DIFFERENTIATORS: &[(&str, MakeDifferentiator)] = &[
    ("central", || Box::new(CentralDifference)),
    ("savitzky-golay", || Box::new(super::SavitzkyGolay::default())),
];

/// A derivative method by name.
pub fn differentiator(name: &str) -> Result<Box<dyn Differentiator>, DataError> {
    DIFFERENTIATORS.iter().find(|(n, _)| *n == name).map(|(_, make)| make()).ok_or_else(|| {
        let known: Vec<_> = DIFFERENTIATORS.iter().map(|(n, _)| *n).collect();
        DataError::UnknownMethod(name.into(), known.join(", "))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_on_quadratics_even_on_uneven_grids() {
        let t = [0.0, 0.1, 0.25, 0.3, 0.7, 1.0];
        let x: Vec<f64> = t.iter().map(|t| 3.0 * t * t - 2.0 * t + 1.0).collect();
        let d = CentralDifference.differentiate(&t, &x).unwrap();
        for (ti, di) in t.iter().zip(d) {
            assert!((di - (6.0 * ti - 2.0)).abs() < 1e-12, "{ti}: {di}");
        }
        assert!(CentralDifference.differentiate(&t[..2], &x[..2]).is_err());
    }
}
