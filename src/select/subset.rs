//! What the back-ends share: the cross-products scaled to correlations (so pivots are shares
//! of variance, comparable across terms), Goodnight's sweep, and the least-squares fit of
//! any subset with the statistics of Oltmann's App. A.

use super::{Estimate, Problem, SelectError, Step};

/// Goodnight's sweep of a symmetric matrix (row-major, size m) on pivot k. In this form it
/// is its own inverse: sweeping k again takes the term out.
///
/// The loops are plain Rust; on x86-64 they are compiled a second time for AVX2 (four lanes
/// instead of SSE2's two, a third of a stepwise selection's time) and that copy is chosen at
/// run time. Same operations, same results.
pub(crate) fn sweep(a: &mut [f64], m: usize, k: usize) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2.
        unsafe { sweep_avx2(a, m, k) };
        return;
    }
    sweep_portable(a, m, k);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sweep_avx2(a: &mut [f64], m: usize, k: usize) {
    sweep_portable(a, m, k);
}

#[inline(always)]
fn sweep_portable(a: &mut [f64], m: usize, k: usize) {
    let d = a[k * m + k];
    for x in &mut a[k * m..(k + 1) * m] {
        *x /= d;
    }
    let (before, rest) = a.split_at_mut(k * m);
    let (pivot_row, after) = rest.split_at_mut(m);
    for row in before.chunks_exact_mut(m).chain(after.chunks_exact_mut(m)) {
        let b = row[k];
        if b == 0.0 {
            continue;
        }
        for (x, p) in row.iter_mut().zip(pivot_row.iter()) {
            *x -= b * p;
        }
        row[k] = -b / d;
    }
    pivot_row[k] = 1.0 / d;
}

/// The problem's cross-product matrix in correlation scale, target last.
#[derive(Clone, Debug)]
pub(crate) struct Scaled {
    /// Number of candidates.
    pub p: usize,
    /// p + 1.
    pub m: usize,
    /// Row-major m × m, correlation scale.
    pub a: Vec<f64>,
    /// Scale factors √(cross-product diagonal).
    pub d: Vec<f64>,
    /// Total sum of squares D of the target (corrected, or about the origin without intercept).
    pub total: f64,
    /// Rows.
    pub n: usize,
    /// n − 1 with an intercept, else n; divided by the rows' overlap
    /// ([`super::Moments::overlap`]).
    pub n_eff: f64,
    /// Means (target last).
    pub means: Vec<f64>,
    /// Σ weights.
    pub weight: f64,
    /// Fit an intercept.
    pub intercept: bool,
}

impl Scaled {
    pub fn new(pb: &Problem<'_>) -> Result<Scaled, SelectError> {
        pb.validate()?;
        let mo = pb.moments;
        let p = mo.regressors();
        let m = p + 1;
        let cross = |i: usize, j: usize| if pb.intercept { mo.corrected(i, j) } else { mo.raw(i, j) };
        let total = cross(p, p);
        if total.is_nan() || total <= 0.0 {
            return Err(SelectError::NoVariance);
        }
        let d: Vec<f64> = (0..m).map(|i| cross(i, i).max(0.0).sqrt()).collect();
        let mut a = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                if d[i] > 0.0 && d[j] > 0.0 {
                    a[i * m + j] = cross(i, j) / (d[i] * d[j]);
                }
            }
        }
        let n = mo.count();
        Ok(Scaled {
            p,
            m,
            a,
            d,
            total,
            n,
            // rows that share their noise count for less (a weak form's overlapping windows)
            n_eff: (if pb.intercept { n as f64 - 1.0 } else { n as f64 }) / mo.overlap(),
            means: mo.means().to_vec(),
            weight: mo.weight(),
            intercept: pb.intercept,
        })
    }

    /// The residual share 1 − R² of a swept matrix.
    pub fn residual_share(&self, a: &[f64]) -> f64 {
        a[self.p * self.m + self.p]
    }

    /// The matrix swept on `set`, or the first term whose pivot is at most `tol`.
    pub fn swept(&self, set: &[usize], tol: f64) -> Result<Vec<f64>, usize> {
        let mut a = self.a.clone();
        for &j in set {
            let pivot = a[j * self.m + j];
            if pivot.is_nan() || pivot <= tol {
                return Err(j);
            }
            sweep(&mut a, self.m, j);
        }
        Ok(a)
    }

    /// The statistics of the fit on `set` from a matrix swept on exactly that set, as a step
    /// that entered (or removed) `term`.
    pub fn step(
        &self,
        a: &[f64],
        set: &[usize],
        names: &[String],
        term: usize,
        removed: bool,
        forced: bool,
    ) -> Step {
        let (p, m) = (self.p, self.m);
        let k = set.len() as f64;
        let dof = (self.n_eff - k).max(1.0);
        let share = self.residual_share(a).max(0.0);
        let residual = share * self.total;
        let r2 = 1.0 - share;
        // below m·ε the residual share is round-off of the sweeps, not resolved: at an exact
        // fit the standard errors stay at that level instead of 0 (t = ±∞ for round-off terms)
        let s = (share.max(m as f64 * f64::EPSILON) * self.total / dof).sqrt();
        let coefficients: Vec<f64> = set.iter().map(|&i| a[i * m + p] * self.d[p] / self.d[i]).collect();
        let std_errors: Vec<f64> =
            set.iter().map(|&i| s * a[i * m + i].max(0.0).sqrt() / self.d[i]).collect();
        let intercept = self.intercept.then(|| {
            let means = &self.means;
            let value = means[p] - set.iter().zip(&coefficients).map(|(&i, b)| b * means[i]).sum::<f64>();
            // q = 1/W + x̄ᵀ S⁻¹ x̄ over the set, S⁻¹ in correlation scale: x̄ᵢ/dᵢ
            let g: Vec<f64> = set.iter().map(|&i| means[i] / self.d[i]).collect();
            let mut q = 1.0 / self.weight;
            for (&i, gi) in set.iter().zip(&g) {
                let row = &a[i * m..(i + 1) * m];
                // four partial sums: one running sum is a chain of dependent additions, and
                // this O(k²) loop was a fifth of a selection
                let mut lanes = [0.0f64; 4];
                let (sets, gs) = (set.chunks_exact(4), g.chunks_exact(4));
                let tail: f64 = sets.remainder().iter().zip(gs.remainder()).map(|(&l, gl)| gl * row[l]).sum();
                for (ls, gl) in sets.zip(gs) {
                    for j in 0..4 {
                        lanes[j] += gl[j] * row[ls[j]];
                    }
                }
                q += gi * ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail);
            }
            let std_error = s * q.max(0.0).sqrt();
            Estimate { value, std_error, t: value / std_error }
        });
        Step {
            step: 0,
            term: names[term].clone(),
            index: term,
            forced,
            reduction: f64::NAN,
            proportion: f64::NAN,
            r2,
            r: r2.max(0.0).sqrt(),
            r_adjusted: (1.0 - (1.0 - r2) * self.n_eff / (self.n_eff + 1.0 - k)).max(0.0).sqrt(),
            standard_error: s,
            standard_error_adjusted: s * (self.n_eff / (self.n_eff + 1.0 - k)).sqrt(),
            f: if k > 0.0 { (r2 * self.total / k) / (residual / dof) } else { f64::NAN },
            removed,
            set: set.to_vec(),
            coefficients,
            std_errors,
            intercept,
        }
    }
}

/// Upper-tail probability of an F(d1, d2) value, P(F > f), by the regularised incomplete beta
/// function (continued fraction, Lentz's method; Numerical Recipes §6.4).
pub(crate) fn f_pvalue(f: f64, d1: f64, d2: f64) -> f64 {
    if f.is_nan() || d1 <= 0.0 || d2 <= 0.0 {
        return f64::NAN;
    }
    if f <= 0.0 {
        return 1.0;
    }
    if f.is_infinite() {
        return 0.0;
    }
    // P(F > f) = I_x(d2/2, d1/2) with x = d2 / (d2 + d1 f)
    incomplete_beta(d2 / 2.0, d1 / 2.0, d2 / (d2 + d1 * f))
}

/// Upper-tail probability of a χ²(dof) value, P(χ² > q): the regularised upper incomplete gamma
/// function Q(dof/2, q/2), by its series below a + 1 and its continued fraction above
/// (Numerical Recipes §6.2).
pub(crate) fn chi_square_pvalue(q: f64, dof: f64) -> f64 {
    if q.is_nan() || dof <= 0.0 {
        return f64::NAN;
    }
    if q <= 0.0 {
        return 1.0;
    }
    if q.is_infinite() {
        return 0.0;
    }
    let (a, x) = (dof / 2.0, q / 2.0);
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // P(a, x) = e^-x x^a / Γ(a) Σ x^n / (a (a+1) … (a+n))
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..500 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - front * sum).max(0.0)
    } else {
        // Q(a, x) by Lentz's method
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..500 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            let del = lentz(an, b, &mut c, &mut d);
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (front * h).min(1.0)
    }
}

fn ln_gamma(x: f64) -> f64 {
    // Lanczos (g = 7, n = 9)
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// I_x(a, b).
pub(crate) fn incomplete_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front = (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_cf(a, b, x) / a
    } else {
        1.0 - front * beta_cf(b, a, 1.0 - x) / b
    }
}

/// Keeps Lentz's method off a zero denominator.
const TINY: f64 = 1e-300;

/// One term of a continued fraction … + a/(b + …) by Lentz's method: `c` and `d` carried from
/// the term before, the factor the fraction's value is multiplied by returned (Numerical
/// Recipes §5.2).
fn lentz(a: f64, b: f64, c: &mut f64, d: &mut f64) -> f64 {
    let nonzero = |v: f64| if v.abs() < TINY { TINY } else { v };
    *d = 1.0 / nonzero(b + a * *d);
    *c = nonzero(b + a / *c);
    *d * *c
}

fn beta_cf(a: f64, b: f64, x: f64) -> f64 {
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..300 {
        let m = m as f64;
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        h *= lentz(aa, 1.0, &mut c, &mut d);
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        let del = lentz(aa, 1.0, &mut c, &mut d);
        h *= del;
        if (del - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 5 % points of χ² from the tables (Abramowitz & Stegun, Table 26.8), and the closed
    /// forms at 2 degrees of freedom (e^(-q/2)) and 1 (erfc(√(q/2))).
    #[test]
    fn chi_square_tail_probabilities_match_the_tables() {
        for (q, dof) in
            [(3.841, 1.0), (5.991, 2.0), (7.815, 3.0), (14.067, 7.0), (21.026, 12.0), (43.773, 30.0)]
        {
            let p = chi_square_pvalue(q, dof);
            assert!((p - 0.05).abs() < 2e-5, "χ²({dof}) > {q}: {p}");
        }
        for q in [0.1, 1.0, 4.0, 30.0] {
            let p = chi_square_pvalue(q, 2.0);
            assert!((p - (-q / 2.0_f64).exp()).abs() < 1e-12 * (1.0 + 1.0 / p), "{q}: {p}");
        }
        // P(χ²(1) > 1) = erfc(1/√2) = 0.31731050786291415
        assert!((chi_square_pvalue(1.0, 1.0) - 0.317_310_507_862_914_15).abs() < 1e-12);
        assert_eq!(chi_square_pvalue(0.0, 3.0), 1.0);
        assert_eq!(chi_square_pvalue(f64::INFINITY, 3.0), 0.0);
        assert!(chi_square_pvalue(1.0, 0.0).is_nan());
    }

    #[test]
    fn sweep_is_its_own_inverse() {
        let a0 = vec![4.0, 2.0, 1.0, 2.0, 3.0, 0.5, 1.0, 0.5, 2.0];
        let mut a = a0.clone();
        sweep(&mut a, 3, 1);
        sweep(&mut a, 3, 0);
        sweep(&mut a, 3, 1);
        sweep(&mut a, 3, 0);
        for (x, y) in a.iter().zip(&a0) {
            assert!((x - y).abs() < 1e-14, "{a:?}");
        }
    }

    #[test]
    fn f_distribution_against_tables() {
        // textbook critical values: F(1, 10; 0.05) = 4.9646, F(3, 20; 0.01) = 4.9382,
        // F(2, 5; 0.10) = 3.7797
        assert!((f_pvalue(4.9646, 1.0, 10.0) - 0.05).abs() < 1e-5);
        assert!((f_pvalue(4.9382, 3.0, 20.0) - 0.01).abs() < 1e-5);
        assert!((f_pvalue(3.7797, 2.0, 5.0) - 0.10).abs() < 1e-5);
        assert_eq!(f_pvalue(0.0, 1.0, 10.0), 1.0);
    }
}
