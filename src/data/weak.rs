//! The weak form of an equation of motion (weak SINDy; Messenger & Bortz 2021): the equation
//! ẋ = Σ c_j θ_j multiplied by a smooth test function φ that vanishes at both ends of a
//! window and integrated over it, −∫ φ′ x dt = Σ c_j ∫ φ θ_j dt. Where the integral form's
//! left side x(b) − x(a) carries the noise of two samples, the weak form's averages x over the
//! whole window with smooth weights: noise of several per cent is averaged out. Chosen as
//! `--derivative weak[:W[:P]]`.

use super::{DataError, Differentiator, TestFunction, Window};

/// The weak form over windows of `window` sample intervals with φ = (1 − s²)^`power`.
#[derive(Clone, Copy, Debug)]
pub struct WeakForm {
    /// Sample intervals per window; `None`: [`WeakForm::WINDOW`], and on a run too short for
    /// four of them the integral form ([`Window::on_rows`]).
    pub window: Option<usize>,
    /// The power of the bump: φ and its first `power − 1` derivatives vanish at the ends, so
    /// the trapezoid over the window errs by O(h^power) (Euler-Maclaurin).
    pub power: u32,
}

impl WeakForm {
    /// The default window: a third of a period at the ODE benchmark's hundred samples per
    /// characteristic period (benches/odes), long enough to average noise of a per cent, short
    /// enough to resolve the period: 32 intervals recover 37, 37 and 34 of its 37 systems exact,
    /// coarse and noisy; 48 recover 33 noisy, and at the power 4, 16 and 64 recover 34 and 33.
    pub const WINDOW: usize = 32;
}

impl Default for WeakForm {
    fn default() -> Self {
        WeakForm { window: None, power: 8 }
    }
}

impl Differentiator for WeakForm {
    fn name(&self) -> &'static str {
        "weak"
    }

    /// No rate: the weak form's target is the signal itself, which the identification
    /// weighs over windows ([`Differentiator::window`]).
    fn differentiate(&self, _t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError> {
        Ok(x.to_vec())
    }

    fn smooth(&self, _t: &[f64], _x: &[f64]) -> Result<super::Smoothed, DataError> {
        Err(super::integral::nothing_to_smooth("weak"))
    }

    /// A window reaches `window` samples ahead.
    fn reach(&self) -> Option<usize> {
        Some(self.window.unwrap_or(Self::WINDOW))
    }

    fn window(&self) -> Option<Window> {
        Some(Window {
            intervals: self.window.unwrap_or(Self::WINDOW),
            test: TestFunction::Bump(self.power),
            shrinks: self.window.is_none(),
            instrumented: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::{integral_rows, integral_rows_held, row_overlap};
    use super::*;

    fn bump(intervals: usize, power: u32) -> Window {
        Window { intervals, test: TestFunction::Bump(power), shrinks: false, instrumented: false }
    }

    /// −∫ φ′ x dt = ∫ φ ẋ dt for x = sin 3t (closed form ẋ = 3 cos 3t), on an even and on an
    /// uneven clock: the rows equal to the quadrature's accuracy, where the integral form's
    /// left side x(b) − x(a) is a different number (the windows are weighed by φ).
    #[test]
    fn the_left_side_is_the_rate_weighed_by_the_test_function() {
        let clocks: [Vec<f64>; 2] = [
            (0..400).map(|k| 0.01 * k as f64).collect(),
            (0..400).map(|k| 0.01 * k as f64 + 0.003 * (0.7 * k as f64).sin()).collect(),
        ];
        for t in clocks {
            let x: Vec<f64> = t.iter().map(|t| (3.0 * t).sin()).collect();
            let rate = vec![t.iter().map(|t| 3.0 * (3.0 * t).cos()).collect::<Vec<f64>>()];
            let (y, columns) = integral_rows(&t, &x, &rate, bump(32, 4));
            assert_eq!(y.len(), 400 - 32);
            let scale = columns[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in y.iter().zip(&columns[0]) {
                assert!((a - b).abs() < 1e-4 * scale, "{a} vs {b}");
            }
        }
    }

    /// ẋ = F held between samples (jumps at samples 40 and 75): windows over a jump integrated
    /// piece by piece match the left side; taken as a line between samples they miss it.
    #[test]
    fn held_inputs_integrate_piece_by_piece() {
        let t: Vec<f64> = (0..120).map(|k| 0.02 * k as f64).collect();
        let level = |k: usize| match k {
            0..=39 => 1.0,
            40..=74 => -2.0,
            _ => 0.5,
        };
        let mut x = vec![0.0];
        for k in 0..119 {
            x.push(x[k] + level(k) * 0.02);
        }
        let held = vec![(0..120).map(level).collect::<Vec<f64>>()];
        let before = vec![(0..120usize).map(|k| level(k.saturating_sub(1))).collect::<Vec<f64>>()];
        let jumps: Vec<bool> = (0..120).map(|k| k > 0 && level(k) != level(k - 1)).collect();
        let (y, pieces) = integral_rows_held(&t, &x, &held, &before, &jumps, bump(16, 8));
        let (_, smeared) = integral_rows(&t, &x, &held, bump(16, 8));
        let error = |c: &[f64]| y.iter().zip(c).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        // x is piecewise linear, so −∫ φ′ x is the trapezoid's up to φ′'s smoothness
        assert!(error(&pieces[0]) < 1e-6, "{}", error(&pieces[0]));
        assert!(error(&smeared[0]) > 1e-3, "{}", error(&smeared[0]));
    }

    /// The rows' overlap: 1 for the flat window; for the bump the initial positive sum of its
    /// left side's autocorrelation, closed form for W = 2 and p = 1: φ′ ∝ (1, 0, −1) at the
    /// three samples, ρ₁ = 0, so 1; growing with the window.
    #[test]
    fn overlapping_windows_count_for_fewer_rows() {
        assert_eq!(
            row_overlap(Window {
                intervals: 32,
                test: TestFunction::Flat,
                shrinks: false,
                instrumented: false
            }),
            1.0
        );
        assert_eq!(row_overlap(bump(2, 1)), 1.0);
        let (a, b, c) = (row_overlap(bump(16, 4)), row_overlap(bump(32, 4)), row_overlap(bump(64, 4)));
        assert!(a > 3.0 && a < b && b < c, "{a} {b} {c}");
        // twice the window, about twice the overlap (φ′'s shape is the same, stretched)
        assert!((c / b - 2.0).abs() < 0.1, "{b} {c}");
    }

    /// A run too short for four default windows takes the integral form's; one the user chose
    /// is kept.
    #[test]
    fn a_short_run_takes_the_integral_form() {
        let default = WeakForm::default().window().unwrap();
        assert_eq!(default.on_rows(10_000), default);
        assert_eq!(default.on_rows(129), default);
        let flat = Window { intervals: 8, test: TestFunction::Flat, shrinks: false, instrumented: false };
        assert_eq!(default.on_rows(128), flat);
        let chosen = WeakForm { window: Some(32), power: 4 }.window().unwrap();
        assert_eq!(chosen.on_rows(41), chosen);
    }
}
