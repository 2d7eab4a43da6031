//! How much white noise a record carries: the spread of its fourth differences, in which a
//! motion sampled finely leaves almost nothing and white noise of σ leaves a spread of √70 σ.
//! Where the motion shows through (a coarse record) the noise cannot be told from it.

/// Σ C(4, k)² = C(8, 4): the variance of the fourth difference of white noise of unit variance.
const FOURTH: f64 = 70.0;

/// Σ C(3, k)² = C(6, 3): the same for the third difference.
const THIRD: f64 = 20.0;

/// The fourth differences' noise over the third's below which the motion is taken to show
/// through: white noise gives 1 from both, a motion sampled k times a period leaves the
/// fourth difference (2π/k) times the third's.
const WHITE: f64 = 0.8;

/// The white noise on a record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// Its standard deviation, in the record's unit; where not `measured`, at most this.
    pub sd: f64,
    /// Whether the differences are white: where the motion shows through them (a record too
    /// coarse: its third differences spread more than white noise would give beside its
    /// fourth), `sd` bounds the noise from above and does not measure it.
    pub measured: bool,
}

/// The white noise on `x`: its fourth differences' median absolute value (robust to a few
/// glitches) scaled to σ. `None` for a record under 20 samples or one not finite. A held or
/// quantised record whose differences are mostly 0 gives 0.
pub fn white_noise(x: &[f64]) -> Option<Noise> {
    if x.len() < 20 || x.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let third: Vec<f64> = x.windows(4).map(|w| w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]).collect();
    let fourth: Vec<f64> = third.windows(2).map(|w| w[1] - w[0]).collect();
    let (s3, s4) = (robust_sd(third) / THIRD.sqrt(), robust_sd(fourth) / FOURTH.sqrt());
    Some(Noise { sd: s4, measured: s4 >= WHITE * s3 })
}

/// 1.4826 times the median absolute value: the standard deviation of Gaussian values about 0.
fn robust_sd(mut values: Vec<f64>) -> f64 {
    values.iter_mut().for_each(|v| *v = v.abs());
    let middle = values.len() / 2;
    let (_, median, _) = values.select_nth_unstable_by(middle, f64::total_cmp);
    1.4826 * *median
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sine sampled 100 times a period with Gaussian noise of 0.05 (Box-Muller on a fixed
    /// sequence): σ found within 5 %; without the noise, at most 10⁻³ of it, unmeasured (the
    /// motion shows through); sampled 6 times a period, unmeasured.
    #[test]
    fn white_noise_is_told_from_a_fine_motion_and_not_claimed_on_a_coarse_one() {
        let mut state = 12345u64;
        let mut uniform = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let gauss: Vec<f64> = (0..20_000)
            .map(|_| (-2.0 * uniform().ln()).sqrt() * (2.0 * std::f64::consts::PI * uniform()).cos())
            .collect();
        let sine = |k: usize, per: f64| (2.0 * std::f64::consts::PI * k as f64 / per).sin();
        let noisy: Vec<f64> = gauss.iter().enumerate().map(|(k, e)| sine(k, 100.0) + 0.05 * e).collect();
        let found = white_noise(&noisy).unwrap();
        assert!(found.measured && (found.sd / 0.05 - 1.0).abs() < 0.05, "{found:?}");
        let clean: Vec<f64> = (0..20_000).map(|k| sine(k, 100.0)).collect();
        let found = white_noise(&clean).unwrap();
        assert!(!found.measured && found.sd < 5e-5, "{found:?}");
        let coarse: Vec<f64> = (0..20_000).map(|k| sine(k, 6.0)).collect();
        assert!(!white_noise(&coarse).unwrap().measured);
        assert_eq!(white_noise(&[1.0; 100]), Some(Noise { sd: 0.0, measured: true }));
        assert_eq!(white_noise(&[1.0; 10]), None);
    }
}
