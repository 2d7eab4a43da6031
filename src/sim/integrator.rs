//! Integration of any right-hand side. `Dopri5` is the default: Dormand & Prince's embedded
//! Runge-Kutta 5(4) pair (Dormand & Prince 1980; Hairer, Nørsett & Wanner, *Solving ODEs I*,
//! II.5) with error control, steps across control intervals while the inputs go on along a
//! line (`dopri5.rs`) and output at the requested sample times; where its steps are held by
//! stability rather than accuracy (a stiff model) it goes on with `Rosenbrock`'s linearly
//! implicit steps (`rosenbrock.rs`), which that method takes from the start. `ModifiedEuler` is Oltmann's
//! eq. (B8): explicit Euler with the inputs taken at the *end* of the step, δ(t+Δt), so that v and r respond in the first step;
//! the paper's model file asks for it. `Rk4` is the classical fourth-order method. Inputs are
//! asked of the controller at the grid t = k·Δt alone, whatever the method, and interpolated
//! linearly within a step; the adaptive method does not ask at the grid times whose inputs the
//! controller promised ([`Controller::ahead`]).

// The stage updates index several parallel arrays at once; index loops read best there.
#![allow(clippy::needless_range_loop)]

use serde::{Deserialize, Serialize};

use super::controller::Controller;
use super::dopri5::Dopri5;
use super::rosenbrock::Rosenbrock;
use super::system::System;
use super::SimError;
use crate::data::Frame;

/// The integration method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Integrator {
    /// Dormand-Prince 5(4), adaptive with error control (the default; linearly implicit steps
    /// from where it finds the model stiff).
    #[default]
    #[cfg_attr(feature = "cli", value(name = "dopri5", alias = "adaptive", alias = "rk45"))]
    #[serde(alias = "adaptive", alias = "rk45")]
    Dopri5,
    /// Oltmann's modified Euler (eq. B8), first order.
    #[cfg_attr(feature = "cli", value(name = "b8", alias = "euler", alias = "modified-euler"))]
    #[serde(rename = "b8", alias = "euler", alias = "modified-euler")]
    ModifiedEuler,
    /// Classical Runge-Kutta, fourth order.
    Rk4,
    /// Shampine & Reichelt's linearly implicit Rosenbrock 2(3) pair (MATLAB's `ode23s`),
    /// adaptive, for stiff models from the start (`dopri5` turns to it where it finds one).
    #[cfg_attr(feature = "cli", value(name = "rosenbrock", alias = "ode23s", alias = "stiff"))]
    #[serde(alias = "ode23s", alias = "stiff")]
    Rosenbrock,
}

impl Integrator {
    /// The name the command line uses (`dopri5`, `b8`, `rk4`).
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Dopri5 => "dopri5",
            Integrator::ModifiedEuler => "b8",
            Integrator::Rk4 => "rk4",
            Integrator::Rosenbrock => "rosenbrock",
        }
    }

    /// Whether its steps follow the error control (`dopri5`, `rosenbrock`) rather than the
    /// control step.
    pub fn is_adaptive(&self) -> bool {
        matches!(self, Integrator::Dopri5 | Integrator::Rosenbrock)
    }

    /// By name: `dopri5` (or `adaptive`, `rk45`), `b8` (or `euler`), `rk4` and `rosenbrock`
    /// (or `ode23s`, `stiff`).
    pub fn by_name(name: &str) -> Result<Integrator, SimError> {
        match name {
            "dopri5" | "adaptive" | "rk45" => Ok(Integrator::Dopri5),
            "b8" | "euler" | "modified-euler" => Ok(Integrator::ModifiedEuler),
            "rk4" => Ok(Integrator::Rk4),
            "rosenbrock" | "ode23s" | "stiff" => Ok(Integrator::Rosenbrock),
            other => Err(SimError::Settings(format!(
                "unknown integrator `{other}` (known: dopri5, b8, rk4, rosenbrock)"
            ))),
        }
    }
}

/// Error tolerances of the adaptive method: a substep is accepted when each state's local
/// error estimate is within `atol + rtol·|x|` (in the root-mean-square over the states).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tolerances {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance, in each state's unit.
    pub atol: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances { rtol: 1e-6, atol: 1e-7 }
    }
}

impl Tolerances {
    /// Checks that both are numbers a step control can work with.
    pub fn check(&self) -> Result<(), SimError> {
        let rtol_ok = self.rtol.is_finite() && self.rtol > 0.0 && self.rtol < 1.0;
        let atol_ok = self.atol.is_finite() && self.atol >= 0.0;
        if !(rtol_ok && atol_ok) {
            return Err(SimError::Settings(format!(
                "tolerances rtol = {:?}, atol = {:?}: rtol lies in (0, 1) and atol ≥ 0",
                self.rtol, self.atol
            )));
        }
        Ok(())
    }
}

/// Step, duration and output interval, in seconds (or the model's time unit).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Method.
    pub integrator: Integrator,
    /// Step Δt.
    pub dt: f64,
    /// Length of the run.
    pub duration: f64,
    /// Output interval, a whole multiple of `dt`.
    pub sample: f64,
}

impl Settings {
    /// Checks the settings for a run that keeps `columns` values per output sample; returns
    /// (steps, steps per sample). A run whose output would not fit in memory is refused here,
    /// before anything is allocated.
    pub fn check(&self, columns: usize) -> Result<(usize, usize), SimError> {
        let (steps, every) = self.validate()?;
        let samples = (steps / every + 2) as f64;
        crate::budget::check_values(
            samples * columns as f64,
            || {
                format!(
                    "a run of {} samples × {columns} columns ({} s every {} s)",
                    crate::budget::count(samples),
                    self.duration,
                    self.sample
                )
            },
            "shorten the duration or sample less often",
        )?;
        Ok((steps, every))
    }

    fn validate(&self) -> Result<(usize, usize), SimError> {
        let bad = |m: String| Err(SimError::Settings(m));
        if self.dt.is_nan() || self.dt <= 0.0 || self.dt.is_infinite() {
            return bad(format!("step {:?} s must be positive", self.dt));
        }
        if self.duration.is_nan() || self.duration < 0.0 || self.duration.is_infinite() {
            return bad(format!("duration {:?} s must be ≥ 0", self.duration));
        }
        let every = (self.sample / self.dt).round();
        if every < 1.0 || (every * self.dt - self.sample).abs() > 1e-9 * self.sample.max(self.dt) {
            let every = (self.sample / self.dt).ceil().max(1.0);
            return bad(format!(
                "output interval {:?} s is not a whole multiple of the step {:?} s: give a step that divides it (e.g. --dt {:?}) or an interval that is a multiple",
                self.sample,
                self.dt,
                self.sample / every
            ));
        }
        let steps = (self.duration / self.dt).round();
        if steps > 1e9 {
            return bad(format!(
                "{:.3e} steps of {:?} s are too many (at most 1e9): shorten the duration or take longer steps",
                steps, self.dt
            ));
        }
        Ok((steps as usize, every as usize))
    }
}

/// A simulated run, sampled at the output interval.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Trajectory {
    /// Sample times.
    pub time: Vec<f64>,
    /// State names.
    pub state_names: Vec<String>,
    /// Input names.
    pub input_names: Vec<String>,
    /// One column per state.
    pub states: Vec<Vec<f64>>,
    /// One column per input (the inputs in force at the sample time).
    pub inputs: Vec<Vec<f64>>,
    /// One column per state: ẋ = f(x(t), input(t)) at the sample time.
    pub derivatives: Vec<Vec<f64>>,
    /// Further quantities along the run, by name, at the sample times (a model's derived
    /// variables that a fit compares with their records); empty unless a caller evaluates
    /// them.
    pub observed: Vec<(String, Vec<f64>)>,
    /// Where the adaptive method found the model stiff and went on with linearly implicit
    /// steps (Rosenbrock), if it did.
    pub stiff_from: Option<f64>,
}

impl Trajectory {
    /// A state's column.
    pub fn state(&self, name: &str) -> Option<&[f64]> {
        self.state_names.iter().position(|n| n == name).map(|i| self.states[i].as_slice())
    }

    /// A state's column, or else a quantity observed along the run ([`Trajectory::observed`]).
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.state(name).or_else(|| self.observed.iter().find(|(n, _)| n == name).map(|(_, c)| c.as_slice()))
    }

    /// An input's column.
    pub fn input(&self, name: &str) -> Option<&[f64]> {
        self.input_names.iter().position(|n| n == name).map(|i| self.inputs[i].as_slice())
    }

    /// As a frame: time, states, inputs, and `<state>_dot` derivatives.
    pub fn to_frame(&self, origin: &str, time_name: &str) -> Result<Frame, crate::data::DataError> {
        let mut f = Frame::new(origin, time_name, self.time.clone())?;
        for (n, c) in self.state_names.iter().zip(&self.states) {
            f.push(n, c.clone())?;
        }
        for (n, c) in self.input_names.iter().zip(&self.inputs) {
            f.push(n, c.clone())?;
        }
        for (n, c) in self.state_names.iter().zip(&self.derivatives) {
            f.push(&format!("{n}_dot"), c.clone())?;
        }
        Ok(f)
    }

    /// What the run's user should know where the adaptive method found the model stiff.
    pub fn stiff_note(&self) -> Option<String> {
        self.stiff_from.map(|t| {
            format!(
                "the model is stiff from t = {} s on (the explicit steps were held by \
                 stability, not accuracy): continued with linearly implicit Rosenbrock steps (the \
                 `rosenbrock` method takes them from the start)",
                crate::output::sig(t, 4)
            )
        })
    }

    /// The last state.
    pub fn last_state(&self) -> Vec<f64> {
        self.states.iter().map(|c| *c.last().unwrap_or(&f64::NAN)).collect()
    }
}

/// Integrates `system` from `x0` under `controller`.
///
/// A damped oscillator written as a model file, ẍ = −ω²x − 2ζωẋ with ω = 2 rad/s, ζ = 0.1,
/// released from x = 1: its first minimum comes at t = π/ω_d, ω_d = ω√(1 − ζ²), with
/// x = −e^(−ζωt).
///
/// ```
/// use std::collections::BTreeMap;
/// use termid::model::Model;
/// use termid::sim::{simulate, Constant, Integrator, Settings, System};
///
/// let model = Model::parse(r#"
///     [model]
///     name = "damped oscillator"
///     [[states]]
///     name = "x"
///     initial = 1.0
///     [[states]]
///     name = "w"
///     [equations.x_dot]
///     state = "x"
///     coefficients = { "w" = 1.0 }
///     [equations.w_dot]
///     state = "w"
///     coefficients = { "x" = -4.0, "w" = -0.4 }
/// "#, "oscillator.toml")?;
/// let system = System::new(&model, &BTreeMap::new(), false)?;
/// let settings = Settings { integrator: Integrator::Rk4, dt: 0.001, duration: 5.0, sample: 0.001 };
/// let run = simulate(&system, &[1.0, 0.0], &mut Constant(vec![]), &settings)?;
/// let (i, x_min) = run.states[0].iter().enumerate().fold((0, f64::MAX), |m, (i, &x)| {
///     if x < m.1 { (i, x) } else { m }
/// });
/// let omega_d = 2.0 * (1.0f64 - 0.01).sqrt();
/// let t_min = std::f64::consts::PI / omega_d;
/// assert!((run.time[i] - t_min).abs() < 2e-3);
/// assert!((x_min + (-0.2 * t_min).exp()).abs() < 1e-4);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn simulate(
    system: &System,
    x0: &[f64],
    controller: &mut dyn Controller,
    settings: &Settings,
) -> Result<Trajectory, SimError> {
    if !(system.delays.is_empty() && system.lags.is_empty()) {
        // inputs that act late: the controller's answers fed to the system that much later,
        // through their lags
        let mut late = super::Delayed::new(controller, &system.delays, &system.lags);
        return run(system, x0, &mut late, settings);
    }
    run(system, x0, controller, settings)
}

/// [`simulate`] with the controller as the system takes it.
fn run(
    system: &System,
    x0: &[f64],
    controller: &mut dyn Controller,
    settings: &Settings,
) -> Result<Trajectory, SimError> {
    let (n, m) = (system.dim(), system.inputs.len());
    // time, states, inputs and derivatives per sample
    let (steps, every) = settings.check(1 + 2 * n + m)?;
    if x0.len() != n {
        return Err(SimError::Settings(format!("{} initial values for {n} states", x0.len())));
    }
    let dt = settings.dt;
    let mut ws = system.workspace();
    let mut x = x0.to_vec();
    let mut u_now = vec![0.0; m];
    let mut u_next = vec![0.0; m];
    let mut u_before = vec![0.0; m];
    controller.input(0.0, &x, &mut u_now);
    let cap = steps / every + 1;
    let adaptive = settings.integrator.is_adaptive();
    let mut out = Trajectory {
        time: Vec::with_capacity(cap),
        state_names: system.states.clone(),
        input_names: system.inputs.clone(),
        states: vec![Vec::with_capacity(cap); n],
        inputs: vec![Vec::with_capacity(cap); m],
        derivatives: vec![Vec::with_capacity(if adaptive { 0 } else { cap }); n],
        observed: Vec::new(),
        stiff_from: None,
    };
    // A sample's derivative f(x(t), input(t)) is filled in by the next step when that step
    // evaluates the same thing (always for RK4's first stage; for B8 when the input is at rest,
    // δ(t+Δt) = δ(t)), else evaluated on its own: it saves an evaluation per sample.
    let record = |t: f64, x: &[f64], u: &[f64], out: &mut Trajectory| {
        out.time.push(t);
        for i in 0..n {
            out.states[i].push(x[i]);
            // the adaptive method's all at once after the run
            if !adaptive {
                out.derivatives[i].push(f64::NAN);
            }
        }
        for k in 0..m {
            out.inputs[k].push(u[k]);
        }
    };
    let fill = |d: &[f64], out: &mut Trajectory| {
        for i in 0..n {
            if let Some(last) = out.derivatives[i].last_mut() {
                *last = d[i];
            }
        }
    };
    let limits = finite_limits(system);
    check(system, &limits, 0.0, &x, x0)?;
    record(0.0, &x, &u_now, &mut out);
    let mut pending = true;
    let mut k = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    let mut tmp = vec![0.0; n];
    let mut u_mid = vec![0.0; m];
    // the state before the step, kept for the error report; the buffers swap, nothing is copied
    let mut prev = x.clone();
    let implicit =
        (settings.integrator == Integrator::Rosenbrock).then(|| Rosenbrock::new(system)).transpose()?;
    let switch = settings.integrator == Integrator::Dopri5;
    let mut dopri = Dopri5::new(system, dt, implicit, switch);
    let end = steps as f64 * dt;
    if adaptive {
        system.tolerances.check()?;
    }
    // samples counted down, not found by a remainder (a division per control step)
    let mut to_sample = every;
    let (mut slope, mut u_given) = (vec![0.0; m], vec![0.0; m]);
    let mut step = 0;
    while step < steps {
        step += 1;
        let t1 = step as f64 * dt;
        controller.input(t1, &x, &mut u_next);
        // an input held between samples that jumps at t1 holds its value before over the step
        let u_end: &[f64] = if controller.before(t1, &mut u_before) { &u_before } else { &u_next };
        // every method below writes all of x
        std::mem::swap(&mut prev, &mut x);
        let x_old: &[f64] = &prev;
        match settings.integrator {
            Integrator::ModifiedEuler => {
                // eq. (B8): rudder at the end of the step
                system.derivatives(x_old, u_end, &mut ws, &mut k[0]);
                if pending {
                    if u_end == u_now {
                        fill(&k[0], &mut out);
                    } else {
                        system.derivatives(x_old, &u_now, &mut ws, &mut tmp);
                        fill(&tmp, &mut out);
                    }
                    pending = false;
                }
                for i in 0..n {
                    x[i] = x_old[i] + dt * k[0][i];
                }
            }
            Integrator::Dopri5 | Integrator::Rosenbrock => {
                // the samples' ẋ all at once after the run (below): the steps end between them
                let start = t1 - dt;
                dopri.advance(system, &mut ws, x_old, &mut x, (&u_now, u_end), (start, dt), end)?;
            }
            Integrator::Rk4 => {
                for j in 0..m {
                    u_mid[j] = 0.5 * (u_now[j] + u_end[j]);
                }
                system.derivatives(x_old, &u_now, &mut ws, &mut k[0]);
                if pending {
                    fill(&k[0], &mut out);
                    pending = false;
                }
                for i in 0..n {
                    tmp[i] = x_old[i] + 0.5 * dt * k[0][i];
                }
                system.derivatives(&tmp, &u_mid, &mut ws, &mut k[1]);
                for i in 0..n {
                    tmp[i] = x_old[i] + 0.5 * dt * k[1][i];
                }
                system.derivatives(&tmp, &u_mid, &mut ws, &mut k[2]);
                for i in 0..n {
                    tmp[i] = x_old[i] + dt * k[2][i];
                }
                system.derivatives(&tmp, u_end, &mut ws, &mut k[3]);
                for i in 0..n {
                    x[i] = x_old[i] + dt / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
                }
            }
        }
        check(system, &limits, t1, &x, &prev)?;
        std::mem::swap(&mut u_now, &mut u_next);
        let done = controller.done(t1, &x);
        to_sample -= 1;
        if to_sample == 0 || done {
            to_sample = every;
            record(t1, &x, &u_now, &mut out);
            pending = true;
        }
        if done {
            break;
        }
        // the adaptive method steps past the control times whose inputs the controller
        // promised, reading the dense output for the watched state and the samples alone
        let Some(ahead) = (if adaptive && step < steps { controller.ahead(t1, &mut slope) } else { None })
        else {
            continue;
        };
        u_given.copy_from_slice(&u_now);
        let on_line = |j: usize, u: &mut [f64]| {
            for ((u, given), slope) in u.iter_mut().zip(&u_given).zip(&slope) {
                *u = given + slope * (j as f64 * dt - t1);
            }
        };
        // taken where the promised inputs go on along the integrator's line (else the next
        // control time is asked, which draws the line anew)
        on_line(step + 1, &mut u_next);
        if !dopri.continues((step + 1) as f64 * dt, &u_next) {
            continue;
        }
        if ahead.watch.is_some_and(|w| !w.holds(x[w.state])) {
            continue;
        }
        // the last control step promised; where it is known before (a rudder reaching its
        // command), the steps end on it instead of running past and being cut back there
        let mut last = ((ahead.until / dt).ceil() as usize).saturating_sub(1).min(steps);
        while last > step && last as f64 * dt >= ahead.until {
            last -= 1;
        }
        let limit = if ahead.until.is_finite() { last as f64 * dt } else { end };
        let from = step;
        while step < last {
            let next = step + 1;
            let stepped = dopri.reach(system, &mut ws, next as f64 * dt, limit)?;
            // the control steps within the step just taken; the first whose watched state
            // left its bounds is the stretch's last (the controller is asked at the one after)
            let covered = ((dopri.end_of_step().0 / dt + 1e-9).floor() as usize).clamp(next, last);
            let (t_end, y) = dopri.end_of_step();
            if stepped && check(system, &limits, t_end, y, &x).is_err() {
                // reported at the first control time beyond the bounds, as where every control
                // time is asked
                for j in next..=covered {
                    dopri.states_at(j as f64 * dt, &mut tmp);
                    check(system, &limits, j as f64 * dt, &tmp, &x)?;
                }
                let (t_end, y) = dopri.end_of_step();
                check(system, &limits, t_end, y, &x)?;
            }
            let left = ahead.watch.and_then(|w| dopri.first_outside(w, next, covered, dt));
            let upto = left.unwrap_or(covered);
            while step + to_sample <= upto {
                step += to_sample;
                to_sample = every;
                let t = step as f64 * dt;
                dopri.states_at(t, &mut x);
                on_line(step, &mut u_now);
                record(t, &x, &u_now, &mut out);
            }
            to_sample -= upto - step;
            step = upto;
            if left.is_some() {
                break;
            }
        }
        if step > from {
            let t = step as f64 * dt;
            dopri.states_at(t, &mut x);
            check(system, &limits, t, &x, &prev)?;
            on_line(step, &mut u_now);
            dopri.coasted();
            controller.passed(t);
        }
    }
    if adaptive {
        let states: Vec<&[f64]> = out.states.iter().map(Vec::as_slice).collect();
        let inputs: Vec<&[f64]> = out.inputs.iter().map(Vec::as_slice).collect();
        out.derivatives = system.derivatives_on_columns(&states, &inputs);
    } else if pending {
        system.derivatives(&x, &u_now, &mut ws, &mut tmp);
        fill(&tmp, &mut out);
    }
    out.stiff_from = dopri.stiff_from;
    Ok(out)
}

#[inline(always)]
fn check(system: &System, limits: &[(f64, f64)], t: f64, x: &[f64], prev: &[f64]) -> Result<(), SimError> {
    // one branch for all states (`&` where `&&` would branch); the limits are finite, so a
    // NaN or ±∞ fails them as a value out of bounds does
    let ok = x.iter().zip(limits).fold(true, |ok, (v, (lo, hi))| ok & (*v >= *lo) & (*v <= *hi));
    if ok {
        return Ok(());
    }
    report(system, t, x, prev)
}

/// Each state's bounds for [`check`], ±∞ replaced by the largest finite numbers.
fn finite_limits(system: &System) -> Vec<(f64, f64)> {
    system.bounds.iter().map(|(lo, hi)| (lo.max(f64::MIN), hi.min(f64::MAX))).collect()
}

#[cold]
fn report(system: &System, t: f64, x: &[f64], prev: &[f64]) -> Result<(), SimError> {
    for (i, &v) in x.iter().enumerate() {
        let (lo, hi) = system.bounds[i];
        let why = if !v.is_finite() {
            "not finite".to_string()
        } else if v < lo || v > hi {
            format!("outside its bounds [{lo}, {hi}]")
        } else {
            continue;
        };
        let snapshot = snapshot(&system.states, prev);
        return Err(SimError::Diverged { t, state: system.states[i].clone(), value: v, why, snapshot });
    }
    Ok(())
}

/// The states' values in a message (`x = 1.000000, y = 2.5e102`): six decimals each, or six
/// significant digits in powers of ten where a state has run far away (a diverged run's
/// 10¹⁰² would print as 103 digits).
pub(crate) fn snapshot(names: &[String], values: &[f64]) -> String {
    let shown = |v: f64| if v.is_finite() && v.abs() < 1e9 { format!("{v:.6}") } else { format!("{v:.6e}") };
    names.iter().zip(values).map(|(n, v)| format!("{n} = {}", shown(*v))).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use crate::sim::{Ahead, Constant, RightHandSide, SimError, Watch};
    use crate::term::{Library, Vocabulary};

    /// ẋ = u − k·x: a first-order lag, the simplest right-hand side that has a state, an
    /// input and a parameter (no model file: the simulator needs only the trait).
    struct Lag {
        k: f64,
        bounds: (f64, f64),
    }

    impl RightHandSide for Lag {
        fn origin(&self) -> &str {
            "lag"
        }
        fn states(&self) -> Result<Vec<(String, f64, f64)>, SimError> {
            Ok(vec![("x".into(), self.bounds.0, self.bounds.1)])
        }
        fn inputs(&self) -> Vec<String> {
            vec!["u".into()]
        }
        fn parameters(&self) -> BTreeMap<String, f64> {
            BTreeMap::from([("k".to_string(), self.k)])
        }
        fn compile(&self, _with_intercept: bool) -> Result<Library, SimError> {
            let mut v = Vocabulary::new();
            v.variable("x")?.variable("u")?.parameter("k")?;
            Ok(Library::compile(&[v.parse("u - k*x")?], &v)?)
        }
    }

    fn final_x(k: f64, u: f64, integrator: Integrator, dt: f64) -> f64 {
        let system =
            System::new(&Lag { k, bounds: (f64::NEG_INFINITY, f64::INFINITY) }, &BTreeMap::new(), false)
                .unwrap();
        let settings = Settings { integrator, dt, duration: 2.0, sample: dt };
        let t = simulate(&system, &[1.0], &mut Constant(vec![u]), &settings).unwrap();
        assert!((t.time.last().unwrap() - 2.0).abs() < 1e-9);
        *t.states[0].last().unwrap()
    }

    /// ẋ on many rows at once (block by block, as the adaptive method's samples get it) is
    /// ẋ row by row: the states, the inputs and the parameters each where they belong.
    #[test]
    fn derivatives_on_columns_are_those_of_each_row() {
        let lag = Lag { k: 2.0, bounds: (f64::NEG_INFINITY, f64::INFINITY) };
        let system = System::new(&lag, &BTreeMap::from([("k".to_string(), 0.5)]), false).unwrap();
        let x: Vec<f64> = (0..600).map(|i| (i as f64 * 0.37).sin()).collect();
        let u: Vec<f64> = (0..600).map(|i| (i as f64 * 0.11).cos()).collect();
        let all = system.derivatives_on_columns(&[&x], &[&u]);
        let mut ws = system.workspace();
        let mut dx = [0.0];
        for i in 0..600 {
            system.derivatives(&[x[i]], &[u[i]], &mut ws, &mut dx);
            assert_eq!(all[0][i], dx[0], "row {i}");
            assert_eq!(dx[0], u[i] - 0.5 * x[i]);
        }
        assert_eq!(system.derivatives_on_columns(&[&[]], &[&[]]), vec![Vec::<f64>::new()]);
    }

    /// The right-hand side on a run's rows is u − k·x row by row; a missing column is named.
    #[test]
    fn derivatives_on_a_run() {
        let lag = Lag { k: 2.0, bounds: (f64::NEG_INFINITY, f64::INFINITY) };
        let system = System::new(&lag, &BTreeMap::from([("k".to_string(), 0.5)]), false).unwrap();
        let mut frame = crate::data::Frame::new("run.csv", "t", vec![0.0, 1.0, 2.0]).unwrap();
        frame.push("x", vec![1.0, 2.0, 4.0]).unwrap();
        let missing = system.derivatives_on(&frame).unwrap_err().to_string();
        assert!(missing.contains("run.csv") && missing.contains("`u`"), "{missing}");
        frame.push("u", vec![0.0, 1.0, -1.0]).unwrap();
        assert_eq!(system.derivatives_on(&frame).unwrap(), vec![vec![-0.5, 0.0, -3.0]]);
    }

    /// x(t) = u/k + (x0 − u/k)·e^(−kt); RK4 is fourth order, the paper's B8 first order.
    #[test]
    fn orders_of_accuracy_on_a_first_order_lag() {
        let exact = |k: f64, u: f64| u / k + (1.0 - u / k) * (-2.0 * k).exp();
        let rk4 = |dt| (final_x(0.5, 0.2, Integrator::Rk4, dt) - exact(0.5, 0.2)).abs();
        let b8 = |dt| (final_x(0.5, 0.0, Integrator::ModifiedEuler, dt) - exact(0.5, 0.0)).abs();
        assert!(rk4(0.1) < 1e-6, "{}", rk4(0.1));
        assert!((12.0..20.0).contains(&(rk4(0.1) / rk4(0.05))), "RK4 ratio {}", rk4(0.1) / rk4(0.05));
        assert!((1.8..2.2).contains(&(b8(0.01) / b8(0.005))), "B8 ratio {}", b8(0.01) / b8(0.005));
    }

    /// ẋ = +x (k = −1) leaves its bounds: stopped with the time and the state, no NaN.
    #[test]
    fn leaving_the_bounds_stops_with_time_and_state() {
        let system = System::new(&Lag { k: -1.0, bounds: (-10.0, 10.0) }, &BTreeMap::new(), false).unwrap();
        let settings = Settings { integrator: Integrator::Rk4, dt: 0.01, duration: 5.0, sample: 0.01 };
        match simulate(&system, &[1.0], &mut Constant(vec![0.0]), &settings) {
            Err(SimError::Diverged { t, state, value, .. }) => {
                assert_eq!(state, "x");
                // e^t = 10 at t = ln 10
                assert!((t - 10f64.ln()).abs() < 0.02 && value > 10.0, "t = {t}, x = {value}");
            }
            other => panic!("expected divergence, got {other:?}"),
        }
        // the adaptive method passing the control times of a constant input unasked stops
        // there too, at the first control time beyond the bound, whether samples lie there or not
        for sample in [0.01, 0.5] {
            let settings = Settings { integrator: Integrator::Dopri5, dt: 0.01, duration: 5.0, sample };
            match simulate(&system, &[1.0], &mut Constant(vec![0.0]), &settings) {
                Err(SimError::Diverged { t, state, value, .. }) => {
                    assert_eq!(state, "x");
                    assert!(t > 10f64.ln() && t - 10f64.ln() < 0.011 && value > 10.0, "t = {t}, x = {value}");
                }
                other => panic!("expected divergence, got {other:?}"),
            }
        }
    }

    #[test]
    fn settings_that_do_not_fit_are_refused() {
        let system = System::new(&Lag { k: 1.0, bounds: (-1e9, 1e9) }, &BTreeMap::new(), false).unwrap();
        let run = |dt: f64, duration: f64, sample: f64| {
            simulate(
                &system,
                &[0.0],
                &mut Constant(vec![0.0]),
                &Settings { integrator: Integrator::Rk4, dt, duration, sample },
            )
        };
        assert!(run(0.1, 1.0, 0.15).is_err(), "a sample that is no multiple of the step");
        assert!(
            run(0.0, 1.0, 0.1).is_err() && run(-0.1, 1.0, 0.1).is_err() && run(f64::NAN, 1.0, 0.1).is_err()
        );
        assert!(run(0.1, 1.0, 0.2).is_ok());
        // unknown parameters are refused by name
        let e = System::new(
            &Lag { k: 1.0, bounds: (-1.0, 1.0) },
            &BTreeMap::from([("q".to_string(), 1.0)]),
            false,
        )
        .unwrap_err();
        assert!(e.to_string().contains("`q` is not a parameter"), "{e}");
    }

    /// The adaptive method across many kinks of its input, against the closed form: a lag
    /// ẋ = u − x driven by a rudder-like input (held, turned at a rate that stops between
    /// control times, reversed at a state-dependent moment), then by a replayed record's (a
    /// new value at every control time), interpolated linearly between the control times as
    /// the simulator does. On an interval where u = u_k + s·τ, the exact step
    /// is x_{k+1} = u_k − s + s·Δt + (x_k − u_k + s)·e^(−Δt). Every step cut at a kink starts
    /// from the right state and derivative, or this drifts.
    #[test]
    fn dopri5_follows_an_input_with_many_kinks() {
        struct Rudder {
            angle: f64,
            command: f64,
        }
        impl Controller for Rudder {
            fn input(&mut self, _: f64, x: &[f64], u: &mut [f64]) {
                // reversed when the state passes ±0.3 (a zigzag's check), 0.35 per second
                if x[0] > 0.3 {
                    self.command = -0.5;
                } else if x[0] < -0.3 {
                    self.command = 0.5;
                }
                self.angle += (self.command - self.angle).clamp(-0.35 * 0.1, 0.35 * 0.1);
                u[0] = self.angle;
            }
        }
        let mut lag =
            System::new(&Lag { k: 1.0, bounds: (f64::NEG_INFINITY, f64::INFINITY) }, &BTreeMap::new(), false)
                .unwrap();
        // tolerances well below the errors a kink handled wrongly leaves (~1e-3)
        lag.tolerances = Tolerances { rtol: 1e-7, atol: 1e-9 };
        let settings = Settings { integrator: Integrator::Dopri5, dt: 0.1, duration: 40.0, sample: 0.1 };
        // the largest distance of a run from the closed form, control step by control step
        let worst = |run: &Trajectory| {
            let (x, u, e) = (&run.states[0], &run.inputs[0], (-0.1f64).exp());
            let (mut exact, mut worst) = (0.0f64, 0.0f64);
            for k in 0..x.len() - 1 {
                let slope = (u[k + 1] - u[k]) / 0.1;
                exact = u[k] - slope + slope * 0.1 + (exact - u[k] + slope) * e;
                worst = worst.max((x[k + 1] - exact).abs());
            }
            worst
        };
        let run = simulate(&lag, &[0.0], &mut Rudder { angle: 0.0, command: 0.5 }, &settings).unwrap();
        let u = &run.inputs[0];
        let kinks =
            (1..u.len() - 1).filter(|&k| ((u[k + 1] - u[k]) - (u[k] - u[k - 1])).abs() > 1e-12).count();
        assert!(kinks >= 10, "{kinks} kinks");
        let worst_kinks = worst(&run);
        // ~1.3e-8 here (1.0e-8 before the cut at kinks); a stale f at a kink costs ~1e-3
        assert!(worst_kinks < 1e-7, "{worst_kinks}");
        // the same rudder promising its course ahead (held, or turning until it reaches its
        // command, while the state stays short of the reversal): the steps pass the control
        // times unasked, to the same closed form
        struct Promising {
            angle: f64,
            command: f64,
            last_t: f64,
            asked: usize,
        }
        impl Controller for Promising {
            fn input(&mut self, t: f64, x: &[f64], u: &mut [f64]) {
                self.asked += 1;
                if x[0] > 0.3 {
                    self.command = -0.5;
                } else if x[0] < -0.3 {
                    self.command = 0.5;
                }
                let most = 0.35 * (t - self.last_t);
                self.angle += (self.command - self.angle).clamp(-most, most);
                self.last_t = t;
                u[0] = self.angle;
            }
            fn passed(&mut self, t: f64) {
                let most = 0.35 * (t - self.last_t);
                self.angle += (self.command - self.angle).clamp(-most, most);
                self.last_t = t;
            }
            fn ahead(&self, _: f64, slope: &mut [f64]) -> Option<Ahead> {
                let gap = self.command - self.angle;
                slope[0] = if gap == 0.0 { 0.0 } else { 0.35f64.copysign(gap) };
                let until = if gap == 0.0 { f64::INFINITY } else { self.last_t + gap.abs() / 0.35 - 1e-9 };
                let (low, high) =
                    if self.command > 0.0 { (f64::NEG_INFINITY, 0.3) } else { (-0.3, f64::INFINITY) };
                Some(Ahead { until, watch: Some(Watch { state: 0, low, high }) })
            }
        }
        let mut promising = Promising { angle: 0.0, command: 0.5, last_t: 0.0, asked: 0 };
        let coasted = simulate(&lag, &[0.0], &mut promising, &settings).unwrap();
        let worst_coasted = worst(&coasted);
        assert!(worst_coasted < 1e-7, "{worst_coasted}");
        assert!(promising.asked < 100, "asked {} times in 400 control steps", promising.asked);
        // a replayed record: the input breaks its line at every control time, each control
        // step then ends on its control time (not read off a longer step's dense output)
        struct Noisy(u64);
        impl Controller for Noisy {
            fn input(&mut self, _: f64, _: &[f64], u: &mut [f64]) {
                self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                u[0] = (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            }
        }
        let worst_replay = worst(&simulate(&lag, &[0.0], &mut Noisy(7), &settings).unwrap());
        // 4.9e-10; 1.2e-8 when each step ran past its control time and was read off there
        assert!(worst_replay < 3e-9, "{worst_replay}");
    }

    /// ẋ = −x from 1e-6 (a concentration in mol/L): sized by its start, it is followed within
    /// the tolerances scaled to it, as ẋ = −x from 1 is within them; counted in its own unit,
    /// the absolute 1e-7 lets the steps miss it by far more.
    #[test]
    fn a_state_of_a_millionth_is_followed_as_closely_as_one_of_one() {
        let settings = Settings { integrator: Integrator::Dopri5, dt: 0.25, duration: 10.0, sample: 0.25 };
        let mut lag =
            System::new(&Lag { k: 1.0, bounds: (f64::NEG_INFINITY, f64::INFINITY) }, &BTreeMap::new(), false)
                .unwrap();
        let Tolerances { rtol, atol } = Tolerances::default();
        let worst = |lag: &System| {
            let run = simulate(lag, &[1e-6], &mut Constant(vec![0.0]), &settings).unwrap();
            run.time
                .iter()
                .zip(&run.states[0])
                .map(|(t, x)| {
                    let exact = 1e-6 * (-t).exp();
                    (x - exact).abs() / (atol * 1e-6 + rtol * exact)
                })
                .fold(0.0f64, f64::max)
        };
        let own_unit = worst(&lag);
        assert!(own_unit > 100.0, "{own_unit}");
        lag.sizes = crate::sim::sizes_of(&[1e-6]);
        assert_eq!(lag.absolute_tolerances(), vec![atol * 1e-6]);
        let sized = worst(&lag);
        assert!(sized < 2.0, "{sized}");
        // sizes never loosen a tolerance; a state known only as 0 is as small as the least other
        assert_eq!(crate::sim::sizes_of(&[1e4]), vec![1.0]);
        assert_eq!(crate::sim::sizes_of(&[2e-7, 0.0]), vec![2e-7, 2e-7]);
    }

    /// The adaptive method on closed forms: ẋ = −x (e^(−t)), a damped oscillator, and an
    /// input ramped by the controller on its grid (ẋ = u, u = t: x = t²/2, exact for any order
    /// above one).
    #[test]
    fn dopri5_meets_closed_forms() {
        let settings =
            |duration: f64| Settings { integrator: Integrator::Dopri5, dt: 0.25, duration, sample: 0.25 };
        let lag =
            System::new(&Lag { k: 1.0, bounds: (f64::NEG_INFINITY, f64::INFINITY) }, &BTreeMap::new(), false)
                .unwrap();
        let run = simulate(&lag, &[1.0], &mut Constant(vec![0.0]), &settings(5.0)).unwrap();
        // within twice the default tolerances, dense output included
        let Tolerances { rtol, atol } = Tolerances::default();
        for (t, x) in run.time.iter().zip(&run.states[0]) {
            assert!((x - (-t).exp()).abs() < 2.0 * (atol + rtol * (-t).exp()), "t = {t}: {x}");
        }
        // the derivative column holds ẋ at each sample
        assert!((run.derivatives[0][4] + run.states[0][4]).abs() < 1e-12);
        // a ramp input: the controller is asked at the grid, the input interpolated between
        struct Ramp;
        impl Controller for Ramp {
            fn input(&mut self, t: f64, _: &[f64], u: &mut [f64]) {
                u[0] = t;
            }
        }
        let free =
            System::new(&Lag { k: 0.0, bounds: (f64::NEG_INFINITY, f64::INFINITY) }, &BTreeMap::new(), false)
                .unwrap();
        let run = simulate(&free, &[0.0], &mut Ramp, &settings(4.0)).unwrap();
        assert!((run.last_state()[0] - 8.0).abs() < 1e-9, "{}", run.last_state()[0]);
        // an input held at 0 that steps to 1 at t = 2 s: the long step taken while it was held
        // is cut at the control time before, the interval ramped (area 1/8), then x = t − 2
        struct Switch;
        impl Controller for Switch {
            fn input(&mut self, t: f64, _: &[f64], u: &mut [f64]) {
                u[0] = if t >= 2.0 { 1.0 } else { 0.0 };
            }
        }
        let run = simulate(&free, &[0.0], &mut Switch, &settings(4.0)).unwrap();
        for (t, x) in run.time.iter().zip(&run.states[0]) {
            let exact = if *t <= 1.75 { 0.0 } else { 0.125 + (t - 2.0) };
            assert!((x - exact).abs() < 1e-9, "t = {t}: {x} vs {exact}");
        }
        // ẍ = −4x − 0.4ẋ from x = 1: x = e^(−0.2t)(cos ω_d t + 0.2/ω_d sin ω_d t)
        let mut v = Vocabulary::new();
        v.variable("x").unwrap().variable("w").unwrap();
        struct Oscillator(Library);
        impl RightHandSide for Oscillator {
            fn origin(&self) -> &str {
                "oscillator"
            }
            fn states(&self) -> Result<Vec<(String, f64, f64)>, SimError> {
                Ok(vec![
                    ("x".into(), f64::NEG_INFINITY, f64::INFINITY),
                    ("w".into(), f64::NEG_INFINITY, f64::INFINITY),
                ])
            }
            fn inputs(&self) -> Vec<String> {
                vec![]
            }
            fn parameters(&self) -> BTreeMap<String, f64> {
                BTreeMap::new()
            }
            fn compile(&self, _: bool) -> Result<Library, SimError> {
                Ok(self.0.clone())
            }
        }
        let terms = [v.parse("w").unwrap(), v.parse("-4*x - 0.4*w").unwrap()];
        let osc =
            System::new(&Oscillator(Library::compile(&terms, &v).unwrap()), &BTreeMap::new(), false).unwrap();
        let run = simulate(&osc, &[1.0, 0.0], &mut Constant(vec![]), &settings(10.0)).unwrap();
        let wd = (4.0f64 - 0.04).sqrt();
        for (t, x) in run.time.iter().zip(&run.states[0]) {
            let exact = (-0.2 * t).exp() * ((wd * t).cos() + 0.2 / wd * (wd * t).sin());
            assert!((x - exact).abs() < 1e-6, "t = {t}: {x} vs {exact}");
        }
    }
}
