//! Shampine & Reichelt's linearly implicit Rosenbrock pair of orders 2(3), MATLAB's `ode23s`
//! (The MATLAB ODE suite, SIAM J. Sci. Comput. 18, 1997, §3.1): L-stable, one LU of
//! W = I − h·d·J per step with J exact from the compiled right-hand side's tangents. The
//! adaptive integrator takes these steps where a model is stiff (a fast mode beside a slow
//! one, chemical kinetics): there the explicit pair's steps are held by stability, not error.

use nalgebra::{DMatrix, DVector};

use super::system::{System, Workspace};
use super::SimError;
use crate::term::Tangents;

/// d = 1/(2 + √2): W = I − h·d·J.
const D: f64 = 0.292_893_218_813_452_5;
/// e₃₂ = 6 + √2.
const E32: f64 = 7.414_213_562_373_095;

/// The right-hand side's Jacobian at a step's start and the stages' buffers.
pub(super) struct Rosenbrock {
    tangents: Tangents,
    /// ∂f/∂x, a row per state.
    jacobian: Vec<f64>,
    /// ∂f/∂t along the inputs' line (zero where they are held).
    rate: Vec<f64>,
    f0: Vec<f64>,
    f1: Vec<f64>,
    f2: Vec<f64>,
    k1: Vec<f64>,
    k2: Vec<f64>,
    stage: Vec<f64>,
    u: Vec<f64>,
}

impl Rosenbrock {
    pub(super) fn new(system: &System) -> Result<Rosenbrock, SimError> {
        let n = system.dim();
        let states: Vec<usize> = (0..n).collect();
        Ok(Rosenbrock {
            tangents: system.partials(&states, &[])?,
            jacobian: vec![0.0; n * n],
            rate: vec![0.0; n],
            f0: vec![0.0; n],
            f1: vec![0.0; n],
            f2: vec![0.0; n],
            k1: vec![0.0; n],
            k2: vec![0.0; n],
            stage: vec![0.0; n],
            u: vec![0.0; system.inputs.len()],
        })
    }

    /// f, ∂f/∂x and ∂f/∂t at the step's start (`y` at `t`), the inputs `line(t)`.
    pub(super) fn prepare(
        &mut self,
        system: &System,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        line: &dyn Fn(f64, &mut [f64]),
        scale: f64,
    ) {
        line(t, &mut self.u);
        system.derivatives_and_partials(y, &self.u, ws, &mut self.tangents, &mut self.f0, &mut self.jacobian);
        // along the inputs' line by a forward difference (the tangents hold the states'
        // directions alone); nothing where the inputs are held
        let mut ahead = self.u.clone();
        let delta = f64::EPSILON.sqrt() * scale.max(t.abs());
        line(t + delta, &mut ahead);
        if ahead == self.u {
            self.rate.fill(0.0);
        } else {
            system.derivatives(y, &ahead, ws, &mut self.f1);
            for ((r, a), b) in self.rate.iter_mut().zip(&self.f1).zip(&self.f0) {
                *r = (a - b) / delta;
            }
        }
    }

    /// A step of `h` from `y` at `t` (after [`Rosenbrock::prepare`] there): the second-order
    /// solution into `trial`, `dense` the step's interpolant in the adaptive integrator's
    /// form. Returns the error in units of the tolerances (∞ where W is singular).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn attempt(
        &mut self,
        system: &System,
        ws: &mut Workspace,
        (t, y): (f64, &[f64]),
        h: f64,
        line: &dyn Fn(f64, &mut [f64]),
        trial: &mut [f64],
        dense: &mut [[f64; 5]],
        tolerance: (&[f64], f64),
    ) -> f64 {
        let n = y.len();
        let hd = h * D;
        let w = DMatrix::from_fn(n, n, |i, j| f64::from(u8::from(i == j)) - hd * self.jacobian[i * n + j]);
        let lu = w.lu();
        let solve = |b: &[f64]| lu.solve(&DVector::from_column_slice(b));
        // k1 = W⁻¹(F0 + h·d·T)
        let b: Vec<f64> = self.f0.iter().zip(&self.rate).map(|(f, r)| f + hd * r).collect();
        let Some(k1) = solve(&b) else { return f64::INFINITY };
        self.k1.copy_from_slice(k1.as_slice());
        // F1 = f(t + h/2, y + h/2·k1); k2 = W⁻¹(F1 − k1) + k1
        for ((s, y), k) in self.stage.iter_mut().zip(y).zip(&self.k1) {
            *s = y + 0.5 * h * k;
        }
        line(t + 0.5 * h, &mut self.u);
        system.derivatives(&self.stage, &self.u, ws, &mut self.f1);
        let b: Vec<f64> = self.f1.iter().zip(&self.k1).map(|(f, k)| f - k).collect();
        let Some(k2) = solve(&b) else { return f64::INFINITY };
        for ((k2, s), k1) in self.k2.iter_mut().zip(k2.iter()).zip(&self.k1) {
            *k2 = s + k1;
        }
        // y1 = y + h·k2, F2 = f(t + h, y1)
        for ((t1, y), k) in trial.iter_mut().zip(y).zip(&self.k2) {
            *t1 = y + h * k;
        }
        if trial.iter().any(|v| !v.is_finite()) {
            return f64::INFINITY;
        }
        line(t + h, &mut self.u);
        system.derivatives(trial, &self.u, ws, &mut self.f2);
        // k3 = W⁻¹[F2 − e32(k2 − F1) − 2(k1 − F0) + h·d·T]; error h/6·(k1 − 2k2 + k3)
        let b: Vec<f64> = (0..n)
            .map(|i| {
                self.f2[i] - E32 * (self.k2[i] - self.f1[i]) - 2.0 * (self.k1[i] - self.f0[i])
                    + hd * self.rate[i]
            })
            .collect();
        let Some(k3) = solve(&b) else { return f64::INFINITY };
        let (atol, rtol) = tolerance;
        let sum: f64 = (0..n)
            .map(|i| {
                let e = h / 6.0 * (self.k1[i] - 2.0 * self.k2[i] + k3[i]);
                let q = e / (atol[i] + rtol * y[i].abs().max(trial[i].abs()));
                q * q
            })
            .sum();
        // the pair's own interpolant, y + h·θ·k2 + h·θ(1 − θ)/(1 − 2d)·(k1 − k2) (ibid.,
        // §3.1), in the form r1 + θ(r2 + η(r3 + …)) with η = 1 − θ
        for (i, r) in dense.iter_mut().enumerate() {
            *r = [y[i], h * self.k2[i], h / (1.0 - 2.0 * D) * (self.k1[i] - self.k2[i]), 0.0, 0.0];
        }
        let err = (sum / n.max(1) as f64).sqrt();
        if err.is_nan() {
            f64::INFINITY
        } else {
            err
        }
    }

    /// f at the end of the last attempt (its third stage's): the next step's first where it is
    /// accepted.
    pub(super) fn end_rate(&self) -> &[f64] {
        &self.f2
    }
}

/// The next step after an error `err` of a second-order step: by the error's cube root with a
/// safety factor, at most 5× longer and 10× shorter.
pub(super) fn factor(err: f64) -> f64 {
    if err == 0.0 {
        5.0
    } else if err.is_finite() {
        (0.9 * err.powf(-1.0 / 3.0)).clamp(0.1, 5.0)
    } else {
        0.1
    }
}
