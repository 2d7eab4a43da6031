//! Dormand & Prince's embedded Runge-Kutta 5(4) pair with error control and its dense output
//! (Dormand & Prince 1980; Hairer, Nørsett & Wanner, *Solving ODEs I*, II.5-II.6). While the
//! controller's inputs go on along one straight line (held, or a rudder turning at its rate),
//! steps span as many control intervals as the tolerances allow and the states at the control
//! times inside a step come from the dense output. Where the line breaks, the step that ran
//! past the last control time is cut there and a new line starts, through the inputs at that
//! control time and the next; where it broke at the control time before as well (a replayed
//! record), the steps end on the next control time. Where the controller promised its inputs
//! ahead (`Controller::ahead`), the simulation loop passes the control times unasked, reading
//! the watched state alone off the dense output (`first_outside`). Where the steps are held by
//! stability rather than accuracy (Hairer's stiffness test), the same loop goes on with
//! linearly implicit Rosenbrock steps (`rosenbrock.rs`) along the same input lines.

use super::rosenbrock::{self, Rosenbrock};
use super::system::{System, Workspace};
use super::{SimError, Watch};

// Dormand & Prince (1980), Table 5.2 of Hairer, Nørsett & Wanner
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0],
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
];
/// The fifth-order weights less the embedded fourth-order ones: the error estimate.
const E: [f64; 7] =
    [71.0 / 57600.0, 0.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0];
/// The dense output's fourth-order weights (Hairer's DOPRI5, `CONTD5`; Shampine 1986).
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// The adaptive integrator's state between control intervals.
pub(super) struct Dopri5 {
    k: [Vec<f64>; 7],
    stage: Vec<f64>,
    trial: Vec<f64>,
    u: Vec<f64>,
    /// The step size to try next.
    h: f64,
    /// Whether `k[0]` holds f at (`t`, `y`) (first same as last).
    fresh: bool,
    /// Where the integration stands: the end of the last step, which may lie beyond the
    /// control time last asked for.
    t: f64,
    y: Vec<f64>,
    /// The last free step, [t − span, t], as its dense-output polynomial: per state its five
    /// coefficients side by side (the control times read all five of each state).
    span: f64,
    /// 1/`span` (θ at a control time without a division).
    per_span: f64,
    dense: Vec<[f64; 5]>,
    /// The line the inputs follow: `held` at `held_t`, changing by `slope` per second.
    held: Vec<f64>,
    held_t: f64,
    slope: Vec<f64>,
    /// The relative tolerance, and each state's absolute one ([`System::absolute_tolerances`]).
    rtol: f64,
    atol: Vec<f64>,
    /// Whether (`t`, `y`) hold the run's start or a later point.
    started: bool,
    /// The control interval (for the smallest step allowed and the time tolerance).
    dt: f64,
    control: StepControl,
    /// Whether the inputs left their line at the last control time.
    broke: bool,
    /// The linearly implicit steps, once taken (a stiff model; from the start where asked).
    stiff: Option<Box<Rosenbrock>>,
    /// Whether the explicit steps watch for stiffness and hand over to the implicit ones.
    switch: bool,
    /// Hairer's counters: accepted steps in a row held by stability, and not.
    stability: (u32, u32),
    /// Where the steps turned linearly implicit by themselves.
    pub(super) stiff_from: Option<f64>,
}

/// h·|λ| above which an explicit step is held by stability rather than accuracy (the
/// Dormand-Prince pair's stability region reaches about 3.3 along the negative axis), and the
/// accepted steps in a row that make a model stiff (Hairer, Nørsett & Wanner, *Solving ODEs
/// II*, IV.2, and their DOPRI5's test); six steps in a row below it clear the count.
const STABILITY: f64 = 3.25;
const STIFF_STEPS: u32 = 15;
const CALM_STEPS: u32 = 6;

impl Dopri5 {
    /// The steps of `system` (its states, inputs and tolerances) on a control interval `dt`.
    /// `stiff`: linearly implicit steps from the start (else they are taken where the
    /// explicit ones find the model stiff, where `switch`).
    pub(super) fn new(system: &System, dt: f64, stiff: Option<Rosenbrock>, switch: bool) -> Dopri5 {
        let (n, m) = (system.dim(), system.inputs.len());
        Dopri5 {
            k: std::array::from_fn(|_| vec![0.0; n]),
            stage: vec![0.0; n],
            trial: vec![0.0; n],
            u: vec![0.0; m],
            h: dt,
            fresh: false,
            t: 0.0,
            y: vec![0.0; n],
            span: 0.0,
            per_span: 0.0,
            dense: vec![[0.0; 5]; n],
            held: vec![f64::NAN; m],
            held_t: 0.0,
            slope: vec![0.0; m],
            rtol: system.tolerances.rtol,
            atol: system.absolute_tolerances(),
            started: false,
            dt,
            control: StepControl::default(),
            broke: false,
            stiff: stiff.map(Box::new),
            switch,
            stability: (0, 0),
            stiff_from: None,
        }
    }

    fn at(&self, t: f64) -> bool {
        (self.t - t).abs() <= 1e-9 * self.dt
    }

    /// The inputs on the line at `t`.
    fn line(&self, t: f64, out: &mut [f64]) {
        for ((o, held), slope) in out.iter_mut().zip(&self.held).zip(&self.slope) {
            *o = held + slope * (t - self.held_t);
        }
    }

    /// Whether `u` lies on the line at `t` (to rounding: a rate added up step by step).
    fn on_line(&self, t: f64, u: &[f64]) -> bool {
        u.iter().enumerate().all(|(j, v)| {
            let w = self.held[j] + self.slope[j] * (t - self.held_t);
            (v - w).abs() <= 1e-10 * v.abs().max(w.abs()).max(1e-3)
        })
    }

    /// From `x0` at `t0` (the state this integrator gave for `t0`) over the control interval
    /// `dt` into `x`, the inputs going linearly from `u.0` to `u.1`; `end` is the last control
    /// time of the run, beyond which no step reaches.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn advance(
        &mut self,
        system: &System,
        ws: &mut Workspace,
        x0: &[f64],
        x: &mut [f64],
        u: (&[f64], &[f64]),
        (t0, dt): (f64, f64),
        end: f64,
    ) -> Result<(), SimError> {
        let t1 = t0 + dt;
        let first = !self.started;
        if first {
            self.started = true;
            self.t = t0;
            self.y.copy_from_slice(x0);
            self.fresh = false;
        }
        // the inputs at t0 are the last call's at its t1, which lie on the line (it was drawn
        // through them where they left the one before), but where an input held between
        // samples jumped at t0 (the step before ended on its value before the jump)
        let from_line = !first && self.on_line(t0, u.0);
        let breaks = !from_line || !self.on_line(t1, u.1);
        // how far a step may reach: past t1 while the line may hold on; to t1 where the line
        // broke at the control time before as well (a replayed record breaks it at every
        // control time: a step past t1 would be cut there, its work lost and the state at t1
        // read off the dense output instead of a step's end)
        let reach = if breaks && self.broke { t1 } else { end };
        self.broke = breaks;
        if breaks {
            // the inputs leave their line: the step that ran past t0 is cut there and a new
            // line starts, through this interval's two ends; f at t0 is kept only where it was
            // taken there with this input
            self.fresh &= from_line && self.at(t0);
            self.t = t0;
            self.y.copy_from_slice(x0);
            self.held.copy_from_slice(u.0);
            self.held_t = t0;
            for j in 0..self.slope.len() {
                self.slope[j] = (u.1[j] - u.0[j]) / dt;
            }
            self.span = 0.0;
            // a kink in the inputs excites what the step before it had settled: the steps
            // start again short (five control steps at most) and grow as the error allows
            self.h = self.h.min(5.0 * dt);
        }
        self.reach(system, ws, t1, reach)?;
        self.states_at(t1, x);
        Ok(())
    }

    /// Free steps along the inputs' line until the integration has passed `t`, none ending
    /// beyond `end`; whether any was taken.
    #[inline]
    pub(super) fn reach(
        &mut self,
        system: &System,
        ws: &mut Workspace,
        t: f64,
        end: f64,
    ) -> Result<bool, SimError> {
        if self.t >= t - 1e-9 * self.dt {
            return Ok(false);
        }
        while self.t < t - 1e-9 * self.dt {
            self.free_step(system, ws, end)?;
        }
        Ok(true)
    }

    /// The states at `t`, within the last step (its end, or its dense output).
    pub(super) fn states_at(&self, t: f64, x: &mut [f64]) {
        if self.at(t) || self.span == 0.0 {
            x.copy_from_slice(&self.y);
        } else {
            let (theta, eta) = self.theta(t);
            for (x, r) in x.iter_mut().zip(&self.dense) {
                *x = Self::interpolate(r, theta, eta);
            }
        }
    }

    /// θ = (t − t_start)/h within the last step, and 1 − θ.
    #[inline]
    fn theta(&self, t: f64) -> (f64, f64) {
        let theta = 1.0 - (self.t - t) * self.per_span;
        (theta, 1.0 - theta)
    }

    #[inline]
    fn interpolate([r1, r2, r3, r4, r5]: &[f64; 5], theta: f64, eta: f64) -> f64 {
        r1 + theta * (r2 + eta * (r3 + theta * (r4 + eta * r5)))
    }

    /// The first control step in `from..=to` (at `j·dt`, all within the last step) at which
    /// the watched state lies outside its bounds.
    pub(super) fn first_outside(&self, watch: Watch, from: usize, to: usize, dt: f64) -> Option<usize> {
        if self.span == 0.0 {
            return (!watch.holds(self.y[watch.state])).then_some(from);
        }
        // θ at each control time, read off the one polynomial in a loop without branches but the test
        let r = &self.dense[watch.state];
        (from..=to).find(|&j| {
            let (theta, eta) = self.theta(j as f64 * dt);
            !watch.holds(Self::interpolate(r, theta, eta))
        })
    }

    /// Whether the inputs `u` at control time `t` go on along the line the steps follow (a
    /// controller's promise of the control times ahead is taken only where they do).
    pub(super) fn continues(&self, t: f64, u: &[f64]) -> bool {
        self.started && self.on_line(t, u)
    }

    /// The control times up to `t` passed without asking, the inputs on their line: the next
    /// interval continues it.
    pub(super) fn coasted(&mut self) {
        self.broke = false;
    }

    /// Where the integration stands: the end of the last step and the states there.
    pub(super) fn end_of_step(&self) -> (f64, &[f64]) {
        (self.t, &self.y)
    }

    /// One step from (`t`, `y`) along the inputs' line, of the size the error control allows
    /// and ending at `reach` at the latest, retried smaller until accepted; keeps its dense
    /// output.
    fn free_step(&mut self, system: &System, ws: &mut Workspace, reach: f64) -> Result<(), SimError> {
        if self.stiff.is_some() {
            return self.implicit_step(system, ws, reach);
        }
        if !self.fresh {
            let mut u = std::mem::take(&mut self.u);
            self.line(self.t, &mut u);
            system.derivatives(&self.y, &u, ws, &mut self.k[0]);
            self.u = u;
            self.fresh = true;
        }
        let (held, slope, held_t) =
            (std::mem::take(&mut self.held), std::mem::take(&mut self.slope), self.held_t);
        let mut tries = 0usize;
        loop {
            let h = self.h.min(reach - self.t);
            let (y, t) = (std::mem::take(&mut self.y), self.t);
            let input = |st: usize, u: &mut [f64]| {
                for j in 0..u.len() {
                    u[j] = held[j] + slope[j] * (t + C[st] * h - held_t);
                }
            };
            let err = self.attempt(system, ws, &y, h, input);
            self.y = y;
            if err <= 1.0 {
                if self.switch {
                    self.watch_stiffness(h);
                }
                // dense output before the last stage becomes the next step's first (Hairer's CONTD5)
                let k = &self.k;
                for (i, r) in self.dense.iter_mut().enumerate() {
                    let diff = self.trial[i] - self.y[i];
                    let bspl = h * k[0][i] - diff;
                    // D[1] = 0
                    let d = D[0] * k[0][i]
                        + D[2] * k[2][i]
                        + D[3] * k[3][i]
                        + D[4] * k[4][i]
                        + D[5] * k[5][i]
                        + D[6] * k[6][i];
                    *r = [self.y[i], diff, bspl, diff - h * k[6][i] - bspl, h * d];
                }
                self.y.copy_from_slice(&self.trial);
                self.t += h;
                self.span = h;
                self.per_span = 1.0 / h;
                self.k.swap(0, 6);
                self.h = h * self.control.accept(err);
                (self.held, self.slope) = (held, slope);
                if self.switch && self.stability.0 >= STIFF_STEPS {
                    self.stiff = Some(Box::new(Rosenbrock::new(system)?));
                    self.stiff_from = Some(self.t);
                    self.switch = false;
                }
                return Ok(());
            }
            self.h = self.control.reject(h, err);
            tries += 1;
            if self.h < smallest_step(self.t, self.dt) || tries > 100_000 {
                self.fresh = false;
                (self.held, self.slope) = (held, slope);
                return Err(self.stuck(system, self.t));
            }
        }
    }

    /// Hairer's test after an accepted explicit step of `h` (before its last stage becomes the
    /// next one's first): h·|λ| ≈ h·‖k₇ − k₆‖ / ‖y₇ − y₆‖ from the last two stages, whose
    /// points differ by h·Σ (a₇ⱼ − a₆ⱼ)·kⱼ.
    fn watch_stiffness(&mut self, h: f64) {
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..self.y.len() {
            let dk = self.k[6][i] - self.k[5][i];
            let dy: f64 = (0..6).map(|j| (A[6][j] - A[5][j]) * self.k[j][i]).sum::<f64>() * h;
            num += dk * dk;
            den += dy * dy;
        }
        let held = den > 0.0 && h * (num / den).sqrt() > STABILITY;
        let (stiff, calm) = &mut self.stability;
        if held {
            (*stiff, *calm) = (*stiff + 1, 0);
        } else {
            *calm += 1;
            if *calm >= CALM_STEPS {
                *stiff = 0;
            }
        }
    }

    /// One linearly implicit step from (`t`, `y`) along the inputs' line ([`Rosenbrock`]),
    /// retried smaller until accepted; keeps its dense output.
    fn implicit_step(&mut self, system: &System, ws: &mut Workspace, reach: f64) -> Result<(), SimError> {
        let Some(mut stiff) = self.stiff.take() else { return Ok(()) };
        let (held, slope, held_t) = (self.held.clone(), self.slope.clone(), self.held_t);
        let line = move |t: f64, u: &mut [f64]| {
            for j in 0..u.len() {
                u[j] = held[j] + slope[j] * (t - held_t);
            }
        };
        let t = self.t;
        stiff.prepare(system, ws, t, &self.y, &line, self.dt);
        let tolerance = (&self.atol[..], self.rtol);
        let mut tries = 0usize;
        loop {
            let h = self.h.min(reach - t);
            let err = stiff.attempt(
                system,
                ws,
                (t, &self.y),
                h,
                &line,
                &mut self.trial,
                &mut self.dense,
                tolerance,
            );
            if err <= 1.0 {
                self.y.copy_from_slice(&self.trial);
                self.k[0].copy_from_slice(stiff.end_rate());
                self.fresh = true;
                self.t += h;
                self.span = h;
                self.per_span = 1.0 / h;
                self.h = h * rosenbrock::factor(err);
                self.stiff = Some(stiff);
                return Ok(());
            }
            self.h = h * rosenbrock::factor(err).min(0.9);
            tries += 1;
            if self.h < smallest_step(self.t, self.dt) || tries > 100_000 {
                self.fresh = false;
                self.stiff = Some(stiff);
                return Err(self.stuck(system, t));
            }
        }
    }

    /// Stages 2-7 of a step of `h` from `x` (`k[0]` holds f there), the fifth-order solution
    /// into `trial`; returns the error estimate in units of the tolerances.
    fn attempt(
        &mut self,
        system: &System,
        ws: &mut Workspace,
        x: &[f64],
        h: f64,
        input: impl Fn(usize, &mut [f64]),
    ) -> f64 {
        for st in 1..7 {
            // stage = x + h·Σ a_j k_j, one state vector at a time (the loops vectorise)
            self.stage.copy_from_slice(x);
            for (j, a) in A[st][..st].iter().enumerate() {
                if *a != 0.0 {
                    let c = h * a;
                    self.stage.iter_mut().zip(&self.k[j]).for_each(|(s, k)| *s += c * k);
                }
            }
            input(st, &mut self.u);
            let (_, rest) = self.k.split_at_mut(st);
            system.derivatives(&self.stage, &self.u, ws, &mut rest[0]);
        }
        // stage 7's point is the fifth-order solution (A[6] = b)
        self.trial.copy_from_slice(&self.stage);
        // the error estimate h·Σ e_j k_j (e_2 = 0), gathered in `stage` (free until the next attempt)
        let err = &mut self.stage;
        err.iter_mut().zip(&self.k[0]).for_each(|(e, k)| *e = h * E[0] * k);
        for (j, w) in E.iter().enumerate().skip(2) {
            let c = h * w;
            err.iter_mut().zip(&self.k[j]).for_each(|(e, k)| *e += c * k);
        }
        let rtol = self.rtol;
        let sum: f64 = err
            .iter()
            .zip(x)
            .zip(&self.trial)
            .zip(&self.atol)
            .map(|(((e, x), y), atol)| {
                let q = e / (atol + rtol * x.abs().max(y.abs()));
                q * q
            })
            .sum();
        (sum / x.len().max(1) as f64).sqrt()
    }

    fn stuck(&self, system: &System, t: f64) -> SimError {
        SimError::Settings(format!(
            "the adaptive integrator could not meet its tolerances at t = {} s (step {:.3e} s): the model is stiff or diverging there; state {}",
            if t.abs() >= 1e-3 { format!("{t:.6}") } else { format!("{t:.3e}") },
            self.h,
            super::integrator::snapshot(&system.states, &self.y)
        ))
    }
}

/// Below this step at time `t` (control step `dt`) the error control is stuck (a
/// singularity, a state that is not finite): ten decades below both the control step and the
/// time run so far. Not below the control step alone: a stiff model's first steps are many
/// decades shorter than the interval its run is sampled at (Robertson's kinetics to 10¹¹ s,
/// sampled every 10⁸ s, starts with 10⁻⁶ s).
fn smallest_step(t: f64, dt: f64) -> f64 {
    (1e-10 * t.abs().min(dt)).max(1e-150)
}

/// Step-size control (Hairer, Nørsett & Wanner II.4): the next step by the error's fifth root
/// with a safety factor, at most 10× longer and 10× shorter; after a rejection the step does
/// not grow again at once.
#[derive(Clone, Copy, Debug, Default)]
struct StepControl {
    /// Whether the step before was rejected.
    rejected: bool,
}

impl StepControl {
    /// The factor on `h` for the step after one accepted with error `err` (≤ 1).
    fn accept(&mut self, err: f64) -> f64 {
        let factor = if err == 0.0 { 10.0 } else { (0.9 * inverse_fifth_root(err)).clamp(0.1, 10.0) };
        let factor = if self.rejected { factor.min(1.0) } else { factor };
        self.rejected = false;
        factor
    }

    /// The retry after a step rejected with error `err` (> 1).
    fn reject(&mut self, h: f64, err: f64) -> f64 {
        self.rejected = true;
        if err.is_finite() {
            h * (0.9 * inverse_fifth_root(err)).clamp(0.1, 0.9)
        } else {
            h * 0.1
        }
    }
}

/// err^(−1/5) as exp(−ln(err)/5): a quarter less time than `powf` here (profiled on the
/// 100 s zigzag), and a step control needs no more than its first digits.
#[inline]
fn inverse_fifth_root(err: f64) -> f64 {
    (-0.2 * err.ln()).exp()
}
