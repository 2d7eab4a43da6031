//! Savitzky-Golay derivatives (Savitzky & Golay 1964): at every sample a polynomial of order
//! `order` is fitted by least squares to the `window` samples around it (shifted inward at
//! the ends), and its slope there is the derivative. Local polynomial fits in the actual
//! times, so uneven sampling is handled; exact for polynomials up to `order`, and far less
//! noisy than central differences on measured signals.

use nalgebra::{DMatrix, DVector};

use super::derivative::Differentiator;
use super::DataError;

/// Savitzky-Golay differentiation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SavitzkyGolay {
    /// Samples per fit (odd, > order).
    pub window: usize,
    /// Polynomial order (≥ 1).
    pub order: usize,
}

impl Default for SavitzkyGolay {
    fn default() -> Self {
        SavitzkyGolay { window: 11, order: 3 }
    }
}

impl Differentiator for SavitzkyGolay {
    fn name(&self) -> &'static str {
        "savitzky-golay"
    }

    fn reach(&self) -> Option<usize> {
        Some(self.window / 2)
    }

    fn differentiate(&self, t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError> {
        let n = t.len().min(x.len());
        let (w, q) = (self.window, self.order);
        if w % 2 == 0 || q == 0 || q >= w {
            return Err(DataError::UnknownMethod(
                format!("savitzky-golay window {w}, order {q}"),
                "an odd window larger than the order, order ≥ 1".into(),
            ));
        }
        if n < w {
            return Err(DataError::TooShort {
                file: "signal".into(),
                rows: n,
                needed: w,
                what: format!("a Savitzky-Golay window of {w}"),
            });
        }
        let half = w / 2;
        let mut out = Vec::with_capacity(n);
        for i in 0..n {
            let start = i.saturating_sub(half).min(n - w);
            // scale time by the window's span: a well-conditioned Vandermonde matrix
            let span = (t[start + w - 1] - t[start]).max(f64::MIN_POSITIVE);
            let a = DMatrix::from_fn(w, q + 1, |r, c| ((t[start + r] - t[i]) / span).powi(c as i32));
            let b = DVector::from_iterator(w, x[start..start + w].iter().copied());
            let fit = |e: &str| DataError::UnknownMethod(format!("savitzky-golay fit: {e}"), String::new());
            let svd = crate::linalg::svd(a).ok_or_else(|| fit("its decomposition did not converge"))?;
            let coef = svd.solve(&b, 1e-12).map_err(fit)?;
            out.push(coef[1] / span);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::CentralDifference;

    #[test]
    fn exact_for_polynomials_of_its_order() {
        let t: Vec<f64> = (0..40).map(|i| i as f64 * 0.1 + 0.01 * ((i * 7) % 3) as f64).collect();
        let x: Vec<f64> = t.iter().map(|t| 2.0 - t + 0.5 * t * t - 0.1 * t * t * t).collect();
        let d = SavitzkyGolay::default().differentiate(&t, &x).unwrap();
        for (ti, di) in t.iter().zip(d) {
            let want = -1.0 + ti - 0.3 * ti * ti;
            assert!((di - want).abs() < 1e-9, "{ti}: {di} vs {want}");
        }
    }

    #[test]
    fn less_noisy_than_central_differences() {
        let t: Vec<f64> = (0..2000).map(|i| i as f64 * 0.05).collect();
        let mut seed = 3u64;
        let x: Vec<f64> =
            t.iter().map(|t| (0.3 * t).sin() + 0.02 * crate::data::test_noise(&mut seed)).collect();
        let err = |d: Vec<f64>| crate::data::sine_rate_error(&t, &d);
        let sg = err(SavitzkyGolay { window: 21, order: 3 }.differentiate(&t, &x).unwrap());
        let cd = err(CentralDifference.differentiate(&t, &x).unwrap());
        assert!(sg < cd / 5.0, "Savitzky-Golay {sg} vs central {cd}");
    }

    #[test]
    fn refuses_bad_settings_and_short_signals() {
        let t = [0.0, 1.0, 2.0];
        assert!(SavitzkyGolay { window: 4, order: 2 }.differentiate(&t, &t).is_err());
        assert!(SavitzkyGolay::default().differentiate(&t, &t).is_err());
    }
}
