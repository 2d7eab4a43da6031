//! Cubic smoothing spline (Reinsch 1967; Green & Silverman 1994, ch. 2): the curve g that
//! minimises Σ (yᵢ − g(tᵢ))² + α ∫ g''² dt, with α chosen by generalised cross-validation
//! (Craven & Wahba 1979) unless given. Everything is banded, O(n) per α: the GCV trace comes
//! from the band of the inverse (Hutchinson & de Hoog 1985), so long runs at 50 Hz are cheap.

use super::derivative::{Differentiator, Smoothed};
use super::DataError;

/// Smoothing-spline differentiation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SmoothingSpline {
    /// α in units of the mean sample spacing cubed (≈ window⁴ in samples); `None` = GCV.
    pub alpha: Option<f64>,
}

/// The pentadiagonal system of one data set; time scaled to a mean spacing of 1.
struct Banded {
    h: Vec<f64>,
    /// Q's three entries per column k (rows k, k+1, k+2).
    q: Vec<[f64; 3]>,
    /// R's diagonal and first off-diagonal.
    r: (Vec<f64>, Vec<f64>),
    /// QᵀQ's diagonal and two off-diagonals.
    qq: (Vec<f64>, Vec<f64>, Vec<f64>),
    /// Qᵀy.
    qty: Vec<f64>,
}

/// One fit at a given α.
struct SplineFit {
    value: Vec<f64>,
    gamma: Vec<f64>,
    gcv: f64,
}

impl Banded {
    fn new(t: &[f64], y: &[f64]) -> Banded {
        let n = t.len();
        let scale = (t[n - 1] - t[0]) / (n - 1) as f64;
        let h: Vec<f64> = t.windows(2).map(|w| (w[1] - w[0]) / scale).collect();
        let m = n - 2;
        let q: Vec<[f64; 3]> =
            (0..m).map(|k| [1.0 / h[k], -1.0 / h[k] - 1.0 / h[k + 1], 1.0 / h[k + 1]]).collect();
        let rd = (0..m).map(|k| (h[k] + h[k + 1]) / 3.0).collect();
        let ro = (0..m.saturating_sub(1)).map(|k| h[k + 1] / 6.0).collect();
        let d0 = q.iter().map(|c| c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).collect();
        let d1 = (0..m.saturating_sub(1)).map(|k| q[k][1] * q[k + 1][0] + q[k][2] * q[k + 1][1]).collect();
        let d2 = (0..m.saturating_sub(2)).map(|k| q[k][2] * q[k + 2][0]).collect();
        let qty = (0..m).map(|k| q[k][0] * y[k] + q[k][1] * y[k + 1] + q[k][2] * y[k + 2]).collect();
        Banded { h, q, r: (rd, ro), qq: (d0, d1, d2), qty }
    }

    /// Solves (R + αQᵀQ)γ = Qᵀy by a banded LDLᵀ, and the GCV score from the band of the inverse.
    fn fit(&self, y: &[f64], alpha: f64) -> SplineFit {
        let m = self.qty.len();
        let (d0, d1, d2) = &self.qq;
        let b0: Vec<f64> = (0..m).map(|k| self.r.0[k] + alpha * d0[k]).collect();
        let b1: Vec<f64> = (0..m.saturating_sub(1)).map(|k| self.r.1[k] + alpha * d1[k]).collect();
        let b2: Vec<f64> = (0..m.saturating_sub(2)).map(|k| alpha * d2[k]).collect();
        // LDLᵀ: l1[k] = L[k+1][k], l2[k] = L[k+2][k]
        let (mut d, mut l1, mut l2) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        for k in 0..m {
            let mut dk = b0[k];
            if k >= 1 {
                dk -= l1[k - 1] * l1[k - 1] * d[k - 1];
            }
            if k >= 2 {
                dk -= l2[k - 2] * l2[k - 2] * d[k - 2];
            }
            d[k] = dk;
            if k + 1 < m {
                let mut v = b1[k];
                if k >= 1 {
                    v -= l2[k - 1] * l1[k - 1] * d[k - 1];
                }
                l1[k] = v / dk;
            }
            if k + 2 < m {
                l2[k] = b2[k] / dk;
            }
        }
        let mut gamma = self.qty.clone();
        for k in 0..m {
            if k >= 1 {
                gamma[k] -= l1[k - 1] * gamma[k - 1];
            }
            if k >= 2 {
                gamma[k] -= l2[k - 2] * gamma[k - 2];
            }
        }
        for k in (0..m).rev() {
            gamma[k] /= d[k];
            if k + 1 < m {
                gamma[k] -= l1[k] * gamma[k + 1];
            }
            if k + 2 < m {
                gamma[k] -= l2[k] * gamma[k + 2];
            }
        }
        // g = y − αQγ
        let mut value = y.to_vec();
        for (k, c) in self.q.iter().enumerate() {
            for (j, cj) in c.iter().enumerate() {
                value[k + j] -= alpha * cj * gamma[k];
            }
        }
        // band of S = B⁻¹ from S = D⁻¹L⁻¹ + (I − Lᵀ)S, from the last row up
        let (mut s0, mut s1, mut s2) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        for i in (0..m).rev() {
            let s = |a: usize, b: usize, s0: &[f64], s1: &[f64], s2: &[f64]| {
                let (lo, hi) = (a.min(b), a.max(b));
                match hi - lo {
                    0 => s0[lo],
                    1 => s1[lo],
                    _ => s2[lo],
                }
            };
            let l = |k: usize| if k == i + 1 { l1[i] } else { l2[i] };
            let below: Vec<usize> = (i + 1..(i + 3).min(m)).collect();
            for j in [i + 2, i + 1] {
                if j < m {
                    let v: f64 = below.iter().map(|&k| -l(k) * s(k, j, &s0, &s1, &s2)).sum();
                    if j == i + 1 {
                        s1[i] = v;
                    } else {
                        s2[i] = v;
                    }
                }
            }
            s0[i] = 1.0 / d[i] - below.iter().map(|&k| l(k) * s(k, i, &s0, &s1, &s2)).sum::<f64>();
        }
        let mut trace = 0.0; // tr(QᵀQ S)
        for k in 0..m {
            trace += d0[k] * s0[k];
            if k + 1 < m {
                trace += 2.0 * d1[k] * s1[k];
            }
            if k + 2 < m {
                trace += 2.0 * d2[k] * s2[k];
            }
        }
        let n = y.len() as f64;
        let rss: f64 = y.iter().zip(&value).map(|(a, b)| (a - b) * (a - b)).sum();
        let df_resid = alpha * trace;
        let gcv = (rss / n) / (df_resid / n).powi(2);
        SplineFit { value, gamma, gcv }
    }

    /// Slope at every knot from the values and the interior second derivatives (natural ends).
    fn slopes(&self, g: &[f64], gamma: &[f64]) -> Vec<f64> {
        let n = g.len();
        let c = |i: usize| if i == 0 || i == n - 1 { 0.0 } else { gamma[i - 1] };
        let mut out: Vec<f64> = (0..n - 1)
            .map(|i| (g[i + 1] - g[i]) / self.h[i] - self.h[i] * (2.0 * c(i) + c(i + 1)) / 6.0)
            .collect();
        let i = n - 2;
        out.push((g[n - 1] - g[i]) / self.h[i] + self.h[i] * (c(i) + 2.0 * c(n - 1)) / 6.0);
        out
    }
}

impl SmoothingSpline {
    /// The fitted curve and its slope, and the α used (GCV's choice unless fixed).
    pub fn fit(&self, t: &[f64], x: &[f64]) -> Result<(Smoothed, f64), DataError> {
        let n = t.len().min(x.len());
        if n < 4 {
            return Err(DataError::TooShort {
                file: "signal".into(),
                rows: n,
                needed: 4,
                what: "a smoothing spline".into(),
            });
        }
        let (t, x) = (&t[..n], &x[..n]);
        let band = Banded::new(t, x);
        let alpha = match self.alpha {
            Some(a) if a > 0.0 && a.is_finite() => a,
            Some(a) => {
                return Err(DataError::UnknownMethod(
                    format!("spline:{a}"),
                    "a smoothing α > 0 (samples⁴), or none for GCV".into(),
                ))
            }
            None => gcv_alpha(&band, x, n),
        };
        let f = band.fit(x, alpha);
        let scale = (t[n - 1] - t[0]) / (n - 1) as f64;
        let rate = band.slopes(&f.value, &f.gamma).into_iter().map(|d| d / scale).collect();
        Ok((Smoothed { value: f.value, rate }, alpha))
    }
}

/// α minimising GCV: a grid over window sizes of 1 to ~n/2 samples (α ≈ window⁴), then a
/// golden-section refinement in log α around the best grid point.
fn gcv_alpha(band: &Banded, x: &[f64], n: usize) -> f64 {
    let top = 4.0 * ((n as f64 / 2.0).min(2000.0)).log10();
    let grid: Vec<f64> = (0..=((top + 2.0) * 2.0) as usize).map(|i| -2.0 + 0.5 * i as f64).collect();
    10f64.powf(super::search::minimise(&grid, 0.01, |p| band.fit(x, 10f64.powf(p)).gcv))
}

impl Differentiator for SmoothingSpline {
    fn name(&self) -> &'static str {
        "spline"
    }

    fn differentiate(&self, t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError> {
        Ok(self.fit(t, x)?.0.rate)
    }

    fn smooth(&self, t: &[f64], x: &[f64]) -> Result<Smoothed, DataError> {
        Ok(self.fit(t, x)?.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::test_noise as noise;
    use nalgebra::{DMatrix, DVector};

    /// The same minimiser from dense linear algebra: (I + αQR⁻¹Qᵀ)g = y.
    #[test]
    fn equals_the_dense_solution_and_its_trace() {
        let t: Vec<f64> = (0..12).map(|i| i as f64 * 0.3 + 0.05 * ((i * 5) % 3) as f64).collect();
        let mut s = 7;
        let y: Vec<f64> = t.iter().map(|t| t.sin() + 0.1 * noise(&mut s)).collect();
        let band = Banded::new(&t, &y);
        let (n, m) = (t.len(), t.len() - 2);
        let q = DMatrix::from_fn(n, m, |i, k| if (k..k + 3).contains(&i) { band.q[k][i - k] } else { 0.0 });
        let r = DMatrix::from_fn(m, m, |i, j| match i.abs_diff(j) {
            0 => band.r.0[i],
            1 => band.r.1[i.min(j)],
            _ => 0.0,
        });
        let alpha = 0.7;
        let a_inv = DMatrix::identity(n, n) + alpha * &q * r.clone().try_inverse().unwrap() * q.transpose();
        let hat = a_inv.try_inverse().unwrap();
        let g = &hat * DVector::from_vec(y.clone());
        let f = band.fit(&y, alpha);
        for i in 0..n {
            assert!((g[i] - f.value[i]).abs() < 1e-12, "{i}: {} vs {}", g[i], f.value[i]);
        }
        let rss: f64 = (0..n).map(|i| (y[i] - g[i]).powi(2)).sum();
        let tr = n as f64 - hat.trace();
        let gcv = (rss / n as f64) / (tr / n as f64).powi(2);
        assert!((gcv - f.gcv).abs() < 1e-10 * gcv, "{gcv} vs {}", f.gcv);
    }

    #[test]
    fn interpolates_straight_lines_and_gets_their_slope() {
        let t: Vec<f64> = (0..30).map(|i| i as f64 * 0.1 + 0.03 * ((i * 7) % 3) as f64).collect();
        let x: Vec<f64> = t.iter().map(|t| 2.0 - 3.0 * t).collect();
        let (s, _) = SmoothingSpline { alpha: Some(1e3) }.fit(&t, &x).unwrap();
        for ((v, d), x) in s.value.iter().zip(&s.rate).zip(&x) {
            assert!((v - x).abs() < 1e-9 && (d + 3.0).abs() < 1e-9);
        }
    }

    #[test]
    fn gcv_picks_a_smoothing_that_beats_central_differences() {
        let t: Vec<f64> = (0..2000).map(|i| i as f64 * 0.05).collect();
        let mut seed = 3u64;
        let x: Vec<f64> = t.iter().map(|t| (0.3 * t).sin() + 0.02 * noise(&mut seed)).collect();
        let err = |d: &[f64]| crate::data::sine_rate_error(&t, d);
        let (s, alpha) = SmoothingSpline::default().fit(&t, &x).unwrap();
        let cd = crate::data::CentralDifference.differentiate(&t, &x).unwrap();
        assert!(alpha > 1.0, "GCV chose α = {alpha}");
        assert!(err(&s.rate) < err(&cd) / 10.0, "spline {} vs central {}", err(&s.rate), err(&cd));
        assert!(SmoothingSpline { alpha: Some(-1.0) }.fit(&t, &x).is_err());
        assert!(SmoothingSpline::default().fit(&t[..3], &x[..3]).is_err());
    }
}
