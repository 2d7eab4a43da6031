//! Output error: simulate the measured runs with their recorded inputs from their recorded
//! initial states, compare every measured state (each scaled by its spread in the data; and
//! any derived variable asked for, evaluated along the re-simulation), and
//! fit a hypothesis's parameters by Gauss-Newton / Levenberg-Marquardt on those residuals.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::hypotheses::{Effect, Hypothesis};
use super::{DiagnoseError, Gap, Location, RunGap};
use std::collections::BTreeMap;

use crate::data::Frame;
use crate::identify::ParamValue;
use crate::model::Model;
use crate::sim::{
    simulate, solve_steady, Controller, Integrator, Replay, RightHandSide, Settings, SimError, SteadyProblem,
    System, Trajectory, Unknown,
};
use crate::term::{Library, Term};

/// The fewest samples [`in_segments`] gives a segment: a run [`Runs::new`] takes has 20
/// integration steps at least.
pub const SEGMENT_SAMPLES: usize = 20;

/// Records cut into `count` segments each (none shorter than [`SEGMENT_SAMPLES`]), each a run
/// of its own from its first sample: multiple shooting, where a motion's errors grow over a
/// run (a chaotic system) and no whole-run re-simulation follows its record. With each
/// segment's source (of its run's; `sources` empty: one source, empty too).
pub fn in_segments(frames: &[Frame], sources: &[usize], count: usize) -> (Vec<Frame>, Vec<usize>) {
    let mut out = (Vec::new(), Vec::new());
    for (r, f) in frames.iter().enumerate() {
        for piece in f.pieces(count, SEGMENT_SAMPLES) {
            out.0.push(piece);
            if let Some(&s) = sources.get(r) {
                out.1.push(s);
            }
        }
    }
    out
}

/// The measured runs prepared for re-simulation.
#[derive(Clone)]
pub struct Runs {
    pub(super) frames: Vec<Frame>,
    /// (state index in the system, measured column) for the compared states.
    pub(super) states: Vec<(usize, String)>,
    pub(super) scale: Vec<f64>,
    units: Vec<String>,
    pub(super) x0: Vec<Vec<f64>>,
    /// Each run's own parameters (the model's per-run rules, e.g. u0 = the run's start speed).
    pub(super) params: Vec<BTreeMap<String, f64>>,
    pub(super) settings: Vec<Settings>,
    pub(super) intercepts: bool,
    /// The model's inputs, which the re-simulation replays from the runs.
    inputs: Vec<String>,
    /// The model's derived quantities compared with their records (after the states).
    pub(super) outputs: Vec<Output>,
    /// Per run, the states (indices) it does not record that the motion depends on, started
    /// where they are steady or at the file's value, whichever re-simulates the run better; an
    /// estimate frees them where it frees the runs' initial values.
    pub(super) hidden: Vec<Vec<usize>>,
    /// How large each of the model's states runs in the records, that the default absolute
    /// tolerance is counted in ([`Model::sizes`]).
    sizes: Vec<f64>,
}

/// A run's initial state with its `hidden` states (unrecorded, read by the motion) where they
/// are steady with the recorded ones and the inputs at the run's first sample (a lag of the
/// hull's forces, an engine's rate: a run starts from a steady approach more often than not;
/// `Runs::new` keeps the file's value where that re-simulates the run better); all together
/// where that has a solution, else each alone, else the `declared` value (a state whose own
/// rate does not depend on it).
fn steady_hidden(system: &System, frame: &Frame, declared: Vec<f64>, hidden: &[usize]) -> Vec<f64> {
    if hidden.is_empty() {
        return declared;
    }
    let input: Vec<f64> = system
        .inputs
        .iter()
        .map(|i| frame.column(i).and_then(|c| c.first().copied()).unwrap_or(0.0))
        .collect();
    let solve = |x: &[f64], states: &[usize]| -> Option<Vec<f64>> {
        let problem = SteadyProblem {
            system,
            x: x.to_vec(),
            input: input.clone(),
            unknowns: states.iter().map(|&i| Unknown::State(i)).collect(),
            zero: states.to_vec(),
        };
        let (x, _) = solve_steady(&problem).ok()?;
        x.iter().all(|v| v.is_finite()).then_some(x)
    };
    if let Some(x) = solve(&declared, hidden) {
        return x;
    }
    hidden.iter().fold(declared, |x, &i| solve(&x, &[i]).unwrap_or(x))
}

/// A derived variable of the model compared with its record (a propeller's thrust, a rudder's
/// force): evaluated along each re-simulation from its states, inputs and parameters.
#[derive(Clone, Debug)]
pub(super) struct Output {
    /// Its name, the model's and the record's column's.
    pub name: String,
    /// What it is, in the model's states, inputs and parameters.
    pub term: Term,
    /// Its spread in the records, as a state's scales its residuals.
    pub scale: f64,
}

/// A compared state or derived variable that some runs do not record (one basin logs a
/// propeller's thrust, another not; one run lacks its gyro's yaw rate): compared in the runs
/// that do, the others held to what they record.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PartlyRecorded {
    /// The state or derived variable.
    pub name: String,
    /// How many runs record it.
    pub runs: usize,
    /// Of how many.
    pub of: usize,
}

impl PartlyRecorded {
    /// What a report says of it.
    pub fn line(&self) -> String {
        format!(
            "`{}` is compared in the {} of {} runs that record it (the others hold the fit to what they record)",
            self.name, self.runs, self.of
        )
    }
}

/// A model's right-hand side with further outputs after ẋ (or in its place, without
/// `rates`): the derived quantities a fit compares with their records, the identified terms
/// whose values the sensitivities need. Compiled as one library, what they share is computed
/// once.
pub(super) struct WithOutputs<'a> {
    pub model: &'a Model,
    /// Whether ẋ comes first.
    pub rates: bool,
    pub outputs: Vec<Term>,
}

impl RightHandSide for WithOutputs<'_> {
    fn origin(&self) -> &str {
        &self.model.path
    }
    fn states(&self) -> Result<Vec<(String, f64, f64)>, SimError> {
        self.model.states()
    }
    fn inputs(&self) -> Vec<String> {
        self.model.inputs()
    }
    fn delays(&self) -> Vec<f64> {
        self.model.delays()
    }
    fn lags(&self) -> Vec<f64> {
        self.model.lags()
    }
    fn parameters(&self) -> BTreeMap<String, f64> {
        self.model.parameters()
    }
    fn compile(&self, with_intercept: bool) -> Result<Library, SimError> {
        let mut outputs = Vec::new();
        if self.rates {
            for e in self.model.equations() {
                outputs.push(e.rhs(with_intercept)?);
            }
        }
        outputs.extend(self.outputs.iter().cloned());
        Ok(Library::compile(&outputs, &self.model.vocabulary)?)
    }
}

/// h·|λ| on the negative real axis below which a fixed step is stable: RK4's 2.785, the
/// explicit Euler of Oltmann's B8 2; none for the adaptive methods, which find their own.
fn stability_limit(integrator: Integrator) -> f64 {
    match integrator {
        Integrator::Rk4 => 2.78,
        Integrator::ModifiedEuler => 2.0,
        _ => f64::INFINITY,
    }
}

/// The most steps per sample [`Runs::stable`] takes: beyond it the model wants an implicit
/// method or a quasi-steady-state form, not a million explicit steps per run.
const MOST_SUBSTEPS: f64 = 10_000.0;

/// [`Runs::horizon`]'s twin starts this share of each compared state's spread off, and has
/// parted where it differs by [`PARTED`] of a spread.
pub const PERTURBATION: f64 = 1e-6;
/// See [`PERTURBATION`].
pub const PARTED: f64 = 0.1;

/// One compared quantity's errors in one run, model − measured: (name, unit, errors).
type Compared = (String, String, Vec<f64>);

/// Each run's RMS and max |·| per compared quantity, from its errors.
fn run_gaps(errors: Vec<(String, Vec<Compared>)>) -> Vec<RunGap> {
    errors
        .into_iter()
        .map(|(run, per)| {
            // a quantity the run does not record has no gap there
            let per = per
                .into_iter()
                .filter(|(_, _, d)| !d.is_empty())
                .map(|(name, _, d)| {
                    let rms = (d.iter().map(|v| v * v).sum::<f64>() / d.len().max(1) as f64).sqrt();
                    (name, rms, d.iter().fold(0.0f64, |a, b| a.max(b.abs())))
                })
                .collect();
            (run, per)
        })
        .collect()
}

/// The spread of a column over every run (1 where it does not vary): what scales its residuals.
fn spread(frames: &[Frame], name: &str) -> f64 {
    let all: Vec<f64> = frames.iter().flat_map(|f| f.column(name).unwrap_or(&[]).iter().copied()).collect();
    let mean = all.iter().sum::<f64>() / all.len() as f64;
    let sd = (all.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / all.len() as f64).sqrt();
    if sd > 0.0 {
        sd
    } else {
        1.0
    }
}

/// How large a state runs in the records (its largest magnitude; 0 where they do not record
/// it): what the simulator counts its absolute tolerance in ([`Model::sizes`]).
fn largest(frames: &[Frame], name: &str) -> f64 {
    frames
        .iter()
        .flat_map(|f| f.column(name).unwrap_or(&[]).iter())
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()))
}

/// Recorded inputs with an offset and a factor applied.
struct Transformed {
    replay: Replay,
    offset: Vec<f64>,
    factor: Vec<f64>,
}

impl Controller for Transformed {
    fn input(&mut self, t: f64, x: &[f64], out: &mut [f64]) {
        self.replay.input(t, x, out);
        for ((o, a), b) in out.iter_mut().zip(&self.offset).zip(&self.factor) {
            *o = *o * b + a;
        }
    }

    fn before(&mut self, t: f64, out: &mut [f64]) -> bool {
        let jumped = self.replay.before(t, out);
        if jumped {
            for ((o, a), b) in out.iter_mut().zip(&self.offset).zip(&self.factor) {
                *o = *o * b + a;
            }
        }
        jumped
    }
}

/// Simulates every run of `runs` with `model` (for scripts and tests).
pub fn simulate_runs(runs: &Runs, model: &Model) -> Result<Vec<Trajectory>, SimError> {
    runs.simulate(model, &[], &[])
}

impl Runs {
    /// Prepares runs: every state the model has that a run records is compared, in the runs
    /// that record it.
    pub fn new(
        model: &Model,
        frames: &[Frame],
        dt: f64,
        integrator: Integrator,
    ) -> Result<Runs, DiagnoseError> {
        if frames.is_empty() {
            return Err(DiagnoseError::Setup("no measured runs".into()));
        }
        // a step that does not fit a run many times over re-simulates nothing of it
        let shortest = frames
            .iter()
            .map(|f| f.time().last().copied().unwrap_or(0.0) - f.time().first().copied().unwrap_or(0.0))
            .fold(f64::INFINITY, f64::min);
        if !(dt.is_finite() && dt > 0.0) {
            return Err(DiagnoseError::Setup(format!(
                "the integration step {dt} must be a number of seconds > 0"
            )));
        }
        if dt > shortest / 20.0 {
            return Err(DiagnoseError::Setup(format!(
                "the integration step {} s is too long for the shortest run ({} s): a re-simulation takes at least 20 steps; give --dt {} or less",
                crate::identify::num(dt),
                crate::identify::num(shortest),
                crate::identify::num(shortest / 20.0)
            )));
        }
        // a re-simulation meets a run's k-th row at its k-th sample
        for f in frames {
            if let Some((row, at, place)) = crate::data::uneven(f.time()) {
                return Err(DiagnoseError::Setup(format!(
                    "{}: samples not evenly spaced (row {}: t = {at} s where the first step puts it at {place} s), and a re-simulation compares a run sample by sample: resample it (termid::data::evened; the CLI and the Python package do)",
                    f.origin(),
                    row + 1
                )));
            }
        }
        // a state's angle that wraps at a full turn would be compared with one that turns on
        for s in model.spec().states.iter().filter(|s| s.unit == "rad") {
            for f in frames {
                if let Some(row) = f.column(&s.name).and_then(crate::data::wrapped) {
                    return Err(DiagnoseError::Setup(format!(
                        "{}: `{}` jumps by more than half a turn at row {} (a compass wrapping at 360°), and a re-simulation turns on: unwrap it (termid::data::unwrapped; the CLI and the Python package do)",
                        f.origin(),
                        s.name,
                        row + 1
                    )));
                }
            }
        }
        let system = System::new(model, &Default::default(), false)?;
        // the default absolute tolerance counted in each state's size in the records (an
        // absolute 1e-7 is a tenth of a concentration of 1e-6 mol/L)
        let sizes = model.sizes(&system.states.iter().map(|s| largest(frames, s)).collect::<Vec<_>>());
        // a state is compared in the runs that record it: one run or basin without a record of
        // it (a yaw rate without a gyro) does not take it from the others' comparison
        let states: Vec<(usize, String)> = system
            .states
            .iter()
            .enumerate()
            .filter(|(_, s)| frames.iter().any(|f| f.column(s).is_some()))
            .map(|(i, s)| (i, s.clone()))
            .collect();
        if states.is_empty() {
            return Err(DiagnoseError::Setup(format!(
                "the runs have none of the model's states ({}) as columns",
                system.states.join(", ")
            )));
        }
        for f in frames {
            for i in &system.inputs {
                f.require(i)?;
            }
        }
        let scale = states.iter().map(|(_, s)| spread(frames, s)).collect();
        let units = states
            .iter()
            .map(|(_, s)| {
                model.spec().states.iter().find(|t| &t.name == s).map_or(String::new(), |t| t.unit.clone())
            })
            .collect();
        // a run is simulated at its own parameters, as it was identified (Δu = u − u0 of that run)
        let rules = model.parameter_rules();
        let params = frames
            .iter()
            .map(|f| {
                rules
                    .iter()
                    .filter(|(_, r)| matches!(r, ParamValue::Rule(_)))
                    .map(|(n, r)| {
                        Ok((n.clone(), r.resolve(n, f).map_err(|e| DiagnoseError::Setup(e.to_string()))?))
                    })
                    .collect::<Result<BTreeMap<_, _>, DiagnoseError>>()
            })
            .collect::<Result<Vec<_>, _>>()?;
        // the states a run does not record that the motion depends on (a lag, an engine), but
        // for those the file sets per run (a dose: known, started there, never estimated)
        let per_run =
            |i: usize| model.spec().states.iter().any(|t| t.name == system.states[i] && t.per_run.is_some());
        let hidden: Vec<Vec<usize>> = frames
            .iter()
            .map(|f| {
                (0..system.dim())
                    .filter(|&i| {
                        system.reads_state(i) && f.column(&system.states[i]).is_none() && !per_run(i)
                    })
                    .collect()
            })
            .collect();
        // each run's declared start (its first samples; the file's values of the rest, or their
        // own per run where the file reads them off the run: a dose) and that with its hidden
        // states where they are steady
        let starts = frames
            .iter()
            .zip(&params)
            .zip(&hidden)
            .map(|((f, p), hidden)| {
                let declared: Vec<f64> = system
                    .states
                    .iter()
                    .map(|s| match (f.column(s), model.spec().states.iter().find(|t| &t.name == s)) {
                        (Some(c), _) => Ok(c[0]),
                        (None, Some(spec)) => match &spec.per_run {
                            Some(rule) => ParamValue::Rule(rule.clone())
                                .resolve(s, f)
                                .map_err(|e| DiagnoseError::Setup(e.to_string())),
                            None => Ok(spec.initial),
                        },
                        (None, None) => Ok(0.0),
                    })
                    .collect::<Result<_, DiagnoseError>>()?;
                let steady = steady_hidden(&system.with_parameters(p)?, f, declared.clone(), hidden);
                Ok((declared, steady))
            })
            .collect::<Result<Vec<_>, DiagnoseError>>()?;
        let settings = frames
            .iter()
            .map(|f| {
                let t = f.time();
                let sample = crate::data::run_step(t).unwrap_or(dt);
                let sub = (sample / dt).round().max(1.0);
                Settings { integrator, dt: sample / sub, duration: t[t.len() - 1] - t[0], sample }
            })
            .collect();
        let mut runs = Runs {
            frames: frames.to_vec(),
            states,
            scale,
            units,
            x0: starts.iter().map(|(_, steady)| steady.clone()).collect(),
            params,
            settings,
            intercepts: false,
            inputs: system.inputs.clone(),
            outputs: Vec::new(),
            hidden,
            sizes,
        };
        // a run starts where its hidden states are steady (a steady approach, a steering lag
        // in a steady turn) unless the file's values re-simulate its record better: a state
        // that is steady only where nothing happens (an epidemic's susceptibles, steady once
        // none are left) starts where the file declares it
        for (r, (declared, steady)) in starts.into_iter().enumerate() {
            if declared != steady {
                let mut cost = |x0: &[f64]| {
                    runs.x0[r] = x0.to_vec();
                    let sim = runs.simulate_one(&system, r, &[], &[]).ok();
                    let c: f64 = sim.map_or(f64::NAN, |sim| runs.run_residuals(r, &sim).map(|e| e * e).sum());
                    if c.is_nan() {
                        f64::INFINITY
                    } else {
                        c
                    }
                };
                let better = cost(&declared) < cost(&steady);
                runs.x0[r] = if better { declared } else { steady };
            }
        }
        Ok(runs)
    }

    /// Run `r`'s scaled residuals, simulated as `sim`: each compared quantity it records in
    /// turn, (simulated − measured) / its scale at each sample.
    fn run_residuals<'a>(&'a self, r: usize, sim: &'a Trajectory) -> impl Iterator<Item = f64> + 'a {
        let f = &self.frames[r];
        self.compared_in(sim).into_iter().flat_map(move |(name, _, sc, simulated)| {
            let meas = f.column(name).unwrap_or(&[]);
            // a row between a schedule's samples is the interpolation's: compared as none
            meas.iter().enumerate().map(move |(k, m)| match f.is_sample(k) {
                true => (simulated.get(k).copied().unwrap_or(f64::NAN) - m) / sc,
                false => 0.0,
            })
        })
    }

    /// Compares only the named states (all must be compared ones; the others are still
    /// simulated from their recorded initial values) and the named derived variables of
    /// `model` (`[[derived]]`: a propeller's thrust), each with the runs' column of its name,
    /// evaluated along the re-simulation.
    pub fn comparing(mut self, model: &Model, names: &[String]) -> Result<Runs, DiagnoseError> {
        if names.iter().any(|n| n.trim().is_empty()) {
            return Err(DiagnoseError::Setup(
                "an empty name among the compared states (a stray comma?)".into(),
            ));
        }
        let derived = &model.spec().derived;
        let state = |n: &String| self.states.iter().any(|(_, s)| s == n);
        if names.iter().any(|n| derived.iter().any(|d| &d.name == n)) && !names.iter().any(state) {
            return Err(DiagnoseError::Setup(
                "compare at least one state: the derived variables alone do not hold a re-simulation to its record"
                    .into(),
            ));
        }
        let mut outputs = Vec::new();
        for n in names {
            // a name given twice is compared once, as a state is
            if state(n) || outputs.iter().any(|o: &Output| &o.name == n) {
                continue;
            }
            if !derived.iter().any(|d| &d.name == n) {
                let have: Vec<&str> = self.states.iter().map(|(_, s)| s.as_str()).collect();
                let derived: Vec<&str> = derived.iter().map(|d| d.name.as_str()).collect();
                return Err(DiagnoseError::Setup(format!(
                    "cannot compare `{n}`: the model's states the runs have are {}{}",
                    have.join(", "),
                    if derived.is_empty() {
                        String::new()
                    } else {
                        format!("; its derived variables {}", derived.join(", "))
                    }
                )));
            }
            // compared where it is recorded: one basin logs a propeller's thrust, another not
            if self.frames.iter().all(|f| f.column(n).is_none()) {
                return Err(DiagnoseError::Setup(format!(
                    "cannot compare the derived `{n}`: no run has a column `{n}` (a dataset file names it under [extra])"
                )));
            }
            outputs.push(Output {
                name: n.clone(),
                term: model.vocabulary.parse(n)?,
                scale: spread(&self.frames, n),
            });
        }
        self.outputs = outputs;
        let names: Vec<String> =
            names.iter().filter(|n| self.states.iter().any(|(_, s)| s == *n)).cloned().collect();
        // states, scales and units are parallel lists
        fn kept<T>(v: Vec<T>, keep: &[bool]) -> Vec<T> {
            v.into_iter().zip(keep).filter(|(_, k)| **k).map(|(x, _)| x).collect()
        }
        let keep: Vec<bool> = self.states.iter().map(|(_, s)| names.contains(s)).collect();
        self.states = kept(self.states, &keep);
        self.scale = kept(self.scale, &keep);
        self.units = kept(self.units, &keep);
        Ok(self)
    }

    /// Simulate with the equations' intercepts b0 (off by default: the paper re-simulates
    /// without them, and its B0, C0 stand for effects it did not model, §8).
    pub fn with_intercepts(mut self, yes: bool) -> Runs {
        self.intercepts = yes;
        self
    }

    /// The compared states (their indices in the model's system and names).
    pub fn compared(&self) -> &[(usize, String)] {
        &self.states
    }

    /// The runs' records.
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }

    /// Number of runs.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether there are no runs (never, once made).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Run `run`'s initial value of the state with system index `state`.
    pub fn initial(&self, run: usize, state: usize) -> f64 {
        self.x0[run][state]
    }

    /// The measurement noise of a compared state in run `run` (a standard deviation, in the
    /// state's unit), from the record's second differences: a motion sampled finely leaves
    /// little in them besides the noise (white noise of σ gives differences of variance 6σ²),
    /// and a record's rounding or held samples count with it, as they should. `None` where the
    /// state is not compared or its record is constant.
    pub fn noise(&self, run: usize, state: usize) -> Option<f64> {
        let (_, name) = self.states.iter().find(|(i, _)| *i == state)?;
        let frame = self.frames.get(run)?;
        // the rows between a schedule's samples are the cubic's, smooth: they hide the noise,
        // and the samples' own uneven intervals leave their motion in second differences
        if frame.recorded().is_some() {
            return None;
        }
        let x = frame.column(name)?;
        let n = x.len().checked_sub(2).filter(|n| *n > 0)?;
        let ss: f64 = x.windows(3).map(|w| (w[2] - 2.0 * w[1] + w[0]).powi(2)).sum();
        let sigma = (ss / (6.0 * n as f64)).sqrt();
        (sigma > 0.0 && sigma.is_finite()).then_some(sigma)
    }

    /// The cost the records' white noise accounts for, in the residuals' scaling: Σ rows ·
    /// (σ / spread)² over each compared state of each run whose noise its fourth differences
    /// measure ([`crate::data::white_noise`]; where the motion shows through them, none).
    /// No effect can close it: what a re-simulation that follows its run still leaves. Not
    /// [`Runs::noise_share`]'s second differences, which take a coarse record's motion for
    /// noise: here an over-reading would make a term's share beyond it look larger.
    pub fn white_noise_cost(&self) -> f64 {
        let mut sum = 0.0;
        // (the rows between a schedule's samples are the cubic's: no noise read there)
        for f in self.frames.iter().filter(|f| f.recorded().is_none()) {
            for ((_, name), scale) in self.states.iter().zip(&self.scale) {
                let Some(column) = f.column(name) else { continue };
                if let Some(noise) = crate::data::white_noise(column).filter(|n| n.measured) {
                    sum += column.len() as f64 * (noise.sd / scale).powi(2);
                }
            }
        }
        if sum.is_finite() {
            sum
        } else {
            0.0
        }
    }

    /// The share of the compared records' variance that is their noise ([`Runs::noise`] of
    /// each compared state in each run, scaled as its residuals are, over every compared
    /// value; a derived variable's counts as none): what a fit that holds leaves.
    pub fn noise_share(&self) -> f64 {
        let mut sum = 0.0;
        for (r, f) in self.frames.iter().enumerate() {
            for ((i, name), scale) in self.states.iter().zip(&self.scale) {
                let (Some(column), Some(sigma)) = (f.column(name), self.noise(r, *i)) else {
                    continue;
                };
                sum += column.len() as f64 * (sigma / scale).powi(2);
            }
        }
        sum / self.residual_count().max(1) as f64
    }

    /// The runs re-simulated from other initial values, (run, state index, value), and with
    /// their own values of parameters, (run, parameter, value).
    pub fn with_initial(&self, values: &[(usize, usize, f64)], parameters: &[(usize, &str, f64)]) -> Runs {
        let mut out = self.clone();
        for &(r, i, v) in values {
            out.x0[r][i] = v;
        }
        for &(r, name, v) in parameters {
            out.params[r].insert(name.to_string(), v);
        }
        out
    }

    /// Each run cut into `pieces` segments of equal length (none shorter than `shortest`
    /// samples: a short run gives fewer), each a run of its own from its
    /// recorded first sample (a state it does not record from its run's initial value), with
    /// its run's parameters, compared and scaled as these are; and the run each segment is
    /// of. Multiple shooting's pieces: over a segment a model far from the truth stays near
    /// the record, where over a whole run its phase drifts off and the fit's cost has minima
    /// that are not the system's.
    pub fn segments(
        &self,
        model: &Model,
        pieces: usize,
        shortest: usize,
    ) -> Result<(Runs, Vec<usize>), DiagnoseError> {
        let names = System::new(model, &Default::default(), false)?.states;
        let mut out = Runs {
            frames: Vec::new(),
            states: self.states.clone(),
            scale: self.scale.clone(),
            units: self.units.clone(),
            x0: Vec::new(),
            params: Vec::new(),
            settings: Vec::new(),
            intercepts: self.intercepts,
            inputs: self.inputs.clone(),
            outputs: self.outputs.clone(),
            hidden: Vec::new(),
            sizes: self.sizes.clone(),
        };
        let mut of = Vec::new();
        for (r, f) in self.frames.iter().enumerate() {
            for piece in f.pieces(pieces, shortest) {
                let x0 = names
                    .iter()
                    .enumerate()
                    .map(|(i, s)| piece.column(s).map_or(self.x0[r][i], |c| c[0]))
                    .collect();
                let t = piece.time();
                out.settings.push(Settings { duration: t[t.len() - 1] - t[0], ..self.settings[r] });
                out.frames.push(piece);
                out.x0.push(x0);
                out.params.push(self.params[r].clone());
                out.hidden.push(self.hidden[r].clone());
                of.push(r);
            }
        }
        Ok((out, of))
    }

    /// The runs resampled (anti-aliased) to `factor` times their sample step and re-simulated
    /// one RK4 step per new sample, compared and weighted as these are, from the same
    /// recorded initial states and with the same per-run parameters. Only what a
    /// re-simulation reads and is compared with is kept of each run.
    pub fn coarser(&self, factor: usize) -> Result<Runs, DiagnoseError> {
        let mut out = self.clone();
        if factor <= 1 {
            return Ok(out);
        }
        let setup = |e: crate::data::DataError| DiagnoseError::Setup(e.to_string());
        let read: Vec<&String> = self.inputs.iter().chain(self.compared_names()).collect();
        for (f, s) in out.frames.iter_mut().zip(&mut out.settings) {
            let mut slim = Frame::new(f.origin(), f.time_name(), f.time().to_vec()).map_err(setup)?;
            for name in &read {
                if let Some(column) = f.column(name) {
                    if slim.column(name).is_none() {
                        slim.push(name, column.to_vec()).map_err(setup)?;
                    }
                }
            }
            let step = s.sample * factor as f64;
            *f = crate::data::resample(&slim, step).map_err(setup)?;
            *s = Settings { dt: step, sample: step, ..*s };
        }
        Ok(out)
    }

    /// These runs coarsened as far as `model` allows, with the factor ([`Runs::coarser`], up to
    /// `most`): the model re-simulates them there as it did at their samples (`fine`, its
    /// simulation of these runs), every compared state and derived variable within `tolerance`
    /// of its scale (RMS over all runs, at the coarse samples). Both the integration's error and
    /// the inputs' resampling show in that difference. Factor 1 (the runs themselves) where no
    /// coarser step holds.
    pub fn coarsest(&self, model: &Model, fine: &[Trajectory], tolerance: f64, most: usize) -> (usize, Runs) {
        let holds = |factor: usize| self.holding(model, fine, factor, tolerance);
        // runs compared at a schedule's samples only are not coarsened: a coarse grid would
        // pass between them
        if self.frames.iter().any(|f| f.recorded().is_some()) {
            return (1, self.clone());
        }
        // the first factor that does not hold ends the search
        let mut kept = (1, self.clone());
        for factor in 2..=most {
            match holds(factor) {
                Some(runs) => kept = (factor, runs),
                None => break,
            }
        }
        kept
    }

    /// These runs coarsened `factor` times ([`Runs::coarser`]) where `model` re-simulates them
    /// there as it did at their samples (`fine`), within `tolerance` of each compared
    /// quantity's scale; `None` where it does not.
    pub fn holding(&self, model: &Model, fine: &[Trajectory], factor: usize, tolerance: f64) -> Option<Runs> {
        let coarse = self.coarser(factor).ok()?;
        let sims = coarse.simulate(model, &[], &[]).ok()?;
        (self.largest_difference(fine, &sims, factor) <= tolerance).then_some(coarse)
    }

    /// The largest difference between two simulations of these runs, `a` at every sample and
    /// `b` at every `stride`-th: RMS over the runs of each compared state and derived variable,
    /// in units of its scale (infinite where they share no sample or one is not finite).
    fn largest_difference(&self, a: &[Trajectory], b: &[Trajectory], stride: usize) -> f64 {
        let pairs: Vec<_> =
            a.iter().zip(b).map(|(a, b)| (self.compared_in(a), self.compared_in(b))).collect();
        (0..self.states.len() + self.outputs.len())
            .map(|q| {
                let (mut sq, mut n) = (0.0, 0usize);
                for (a, b) in &pairs {
                    for (k, v) in b[q].3.iter().enumerate() {
                        if let Some(w) = a[q].3.get(k * stride) {
                            sq += (v - w).powi(2);
                            n += 1;
                        }
                    }
                }
                let d = (sq / n as f64).sqrt() / self.compared_scale(q);
                if d.is_nan() {
                    f64::INFINITY
                } else {
                    d
                }
            })
            .fold(0.0, f64::max)
    }

    /// These runs integrated `factor` times finer, their samples as they are (the recorded
    /// inputs interpolated between them, as at every step).
    pub fn finer(&self, factor: usize) -> Runs {
        let mut out = self.clone();
        for s in &mut out.settings {
            s.dt /= factor.max(1) as f64;
        }
        out
    }

    /// How far the integration step is from resolving `model`'s motion on these runs: the
    /// largest difference between their simulations at the step and at half of it (RMS over
    /// the runs, in units of each compared quantity's scale; RK4's error falls sixteen-fold a
    /// halving, so this is nearly the error at the step). Infinite where the simulation at the
    /// step fails and at half of it does not; `None` where both fail (the model, not the step).
    pub fn step_error(&self, model: &Model) -> Option<f64> {
        let half = self.finer(2);
        match (self.simulate(model, &[], &[]), half.simulate(model, &[], &[])) {
            (Ok(at), Ok(fine)) => Some(self.largest_difference(&fine, &at, 1)),
            (Err(_), Ok(_)) => Some(f64::INFINITY),
            _ => None,
        }
    }

    /// These runs integrated `finer` times finer than their step, or twice, four times … as
    /// fine again until the step resolves `model`'s motion ([`Runs::step_error`] within
    /// `tolerance`, up to `most` steps a sample), with how many times finer: a motion sampled
    /// ten times a cycle (a yearly census) drifts in phase at one RK4 step a sample, which an
    /// output-error fit makes up for with biased parameters (a predator's growth by 1.8 %).
    pub fn resolving(&self, model: &Model, finer: usize, tolerance: f64, most: usize) -> (usize, Runs) {
        let finest = |runs: &Runs| runs.settings.iter().all(|s| s.dt * most as f64 <= s.sample * 1.0001);
        let mut finer = finer.max(1);
        loop {
            let at = self.finer(finer);
            if finest(&at) || !at.step_error(model).is_some_and(|e| e > tolerance) {
                return (finer, at);
            }
            finer *= 2;
        }
    }

    /// Number of compared values.
    pub fn residual_count(&self) -> usize {
        self.frames
            .iter()
            .map(|f| {
                let samples = (0..f.len()).filter(|k| f.is_sample(*k)).count();
                self.recorded(f).map(|(_, n)| n.min(samples)).sum::<usize>()
            })
            .sum()
    }

    /// The compared quantities' (states', then derived variables') names in run `f` with their
    /// number of samples there: 0 for one the run does not record.
    fn recorded<'a>(&'a self, f: &'a Frame) -> impl Iterator<Item = (&'a str, usize)> + 'a {
        self.compared_names().map(move |n| (n.as_str(), f.column(n).map_or(0, |c| c.len())))
    }

    /// The compared states' and then derived variables' names, as residuals order them.
    fn compared_names(&self) -> impl Iterator<Item = &String> + '_ {
        self.states.iter().map(|(_, s)| s).chain(self.outputs.iter().map(|o| &o.name))
    }

    /// The compared derived variables' names.
    pub fn observed(&self) -> Vec<String> {
        self.outputs.iter().map(|o| o.name.clone()).collect()
    }

    /// The compared states and derived variables that some runs do not record.
    pub fn partly_recorded(&self) -> Vec<PartlyRecorded> {
        self.compared_names()
            .map(|name| PartlyRecorded {
                name: name.clone(),
                runs: self.frames.iter().filter(|f| f.column(name).is_some()).count(),
                of: self.frames.len(),
            })
            .filter(|p| p.runs < p.of)
            .collect()
    }

    /// Simulates every run; `offsets` and `factors` by input index.
    pub fn simulate(
        &self,
        model: &Model,
        offsets: &[(usize, f64)],
        factors: &[(usize, f64)],
    ) -> Result<Vec<Trajectory>, SimError> {
        let mut system = System::new(model, &Default::default(), self.intercepts)?;
        system.sizes = self.sizes.clone();
        let observer = match self.outputs.is_empty() {
            true => None,
            false => {
                let outputs = self.outputs.iter().map(|o| o.term.clone()).collect();
                Some(System::new(&WithOutputs { model, rates: false, outputs }, &Default::default(), false)?)
            }
        };
        (0..self.frames.len())
            .map(|r| {
                let run = self.simulate_one(&system, r, offsets, factors)?;
                match &observer {
                    Some(observer) => self.observe(observer, &self.params[r], run),
                    None => Ok(run),
                }
            })
            .collect()
    }

    /// The compared derived variables along a re-simulated run, in its `observed`.
    fn observe(
        &self,
        observer: &System,
        parameters: &BTreeMap<String, f64>,
        mut run: Trajectory,
    ) -> Result<Trajectory, SimError> {
        let observer = observer.with_parameters(parameters)?;
        let states: Vec<&[f64]> = run.states.iter().map(|c| c.as_slice()).collect();
        let inputs: Vec<&[f64]> = run.inputs.iter().map(|c| c.as_slice()).collect();
        let values = observer.derivatives_on_columns(&states, &inputs);
        run.observed = self.outputs.iter().map(|o| o.name.clone()).zip(values).collect();
        Ok(run)
    }

    /// Run `r` re-simulated with its recorded inputs, `offsets` and `factors` by input index.
    fn simulate_one(
        &self,
        system: &System,
        r: usize,
        offsets: &[(usize, f64)],
        factors: &[(usize, f64)],
    ) -> Result<Trajectory, SimError> {
        let m = system.inputs.len();
        let system = system.with_parameters(&self.params[r])?;
        let mut c = Transformed {
            replay: Replay::new(&self.frames[r], &system.inputs)?,
            offset: vec![0.0; m],
            factor: vec![1.0; m],
        };
        for &(i, v) in offsets {
            c.offset[i] = v;
        }
        for &(i, v) in factors {
            c.factor[i] = v;
        }
        simulate(&system, &self.x0[r], &mut c, &self.settings[r])
    }

    /// Why `model` leaves a residual on these runs that is not finite: its re-simulation's
    /// failure, or the first compared quantity that is not finite (a derived variable outside
    /// its domain, √ of a negative): which, in which run, from when. `None` where every
    /// residual is finite.
    pub(super) fn not_finite(&self, model: &Model) -> Option<String> {
        let sims = match self.simulate(model, &[], &[]) {
            Ok(sims) => sims,
            Err(e) => {
                let why = self.stiffness(model).map_or(String::new(), |s| format!("; {s}"));
                return Some(format!("{e}{why}"));
            }
        };
        for (f, sim) in self.frames.iter().zip(&sims) {
            for (name, _, _, simulated) in self.compared_in(sim) {
                let Some(meas) = f.column(name) else { continue };
                let bad = (0..meas.len()).find(|&k| !simulated.get(k).is_some_and(|v| v.is_finite()));
                if let Some(k) = bad {
                    return Some(format!(
                        "`{name}` is not finite in run {} at t = {} s (the model's value: {})",
                        f.origin(),
                        crate::identify::num(f.since_start(k)),
                        simulated.get(k).map_or("not reached".to_string(), |v| v.to_string())
                    ));
                }
            }
        }
        None
    }

    /// Each run's fastest decaying mode of ∂f/∂x for `model` over its samples (their recorded
    /// states, the start's values of the rest): (|λ| of the eigenvalue with Re λ < 0 largest in
    /// size, /s; the time into the run where it is), `None` for a run with no such mode or a
    /// method that is not a fixed step (the adaptive ones find their own).
    fn fastest_decay(&self, model: &Model) -> Vec<Option<(f64, f64)>> {
        let Ok(system) = System::new(model, &Default::default(), self.intercepts) else {
            return vec![None; self.frames.len()];
        };
        let n = system.dim();
        let Ok(mut tangents) = system.partials(&(0..n).collect::<Vec<_>>(), &[]) else {
            return vec![None; self.frames.len()];
        };
        let mut ws = system.workspace();
        let (mut dx, mut jac) = (vec![0.0; n], vec![0.0; n * n]);
        let mut out = Vec::with_capacity(self.frames.len());
        for (r, f) in self.frames.iter().enumerate() {
            let fixed = matches!(self.settings[r].integrator, Integrator::Rk4 | Integrator::ModifiedEuler);
            let inputs: Vec<&[f64]> = system.inputs.iter().filter_map(|i| f.column(i)).collect();
            let system = match system.with_parameters(&self.params[r]) {
                Ok(system) if fixed && inputs.len() == system.inputs.len() => system,
                _ => {
                    out.push(None);
                    continue;
                }
            };
            let columns: Vec<Option<&[f64]>> = system.states.iter().map(|s| f.column(s)).collect();
            let mut fastest: Option<(f64, f64)> = None;
            // two hundred samples of each run are enough to find where it is stiff
            for k in (0..f.len()).step_by((f.len() / 200).max(1)) {
                let x: Vec<f64> =
                    columns.iter().enumerate().map(|(i, c)| c.map_or(self.x0[r][i], |c| c[k])).collect();
                let u: Vec<f64> = inputs.iter().map(|c| c[k]).collect();
                system.derivatives_and_partials(&x, &u, &mut ws, &mut tangents, &mut dx, &mut jac);
                if jac.iter().any(|v| !v.is_finite()) {
                    continue;
                }
                let Some(modes) = crate::linalg::eigenvalues(nalgebra::DMatrix::from_row_slice(n, n, &jac))
                else {
                    continue;
                };
                let speed = modes.iter().filter(|l| l.re < 0.0).map(|l| l.norm()).fold(0.0, f64::max);
                if speed > 0.0 && fastest.is_none_or(|(s, _)| speed > s) {
                    fastest = Some((speed, f.since_start(k)));
                }
            }
            out.push(fastest);
        }
        out
    }

    /// Where the runs' fixed step is beyond its method's stability for `model` (h·|λ| of the
    /// fastest decaying mode above the method's limit): a stiff model's re-simulation then
    /// oscillates and diverges whatever its parameters, which a bare "diverged" does not say.
    pub(super) fn stiffness(&self, model: &Model) -> Option<String> {
        let (r, (speed, t)) = self
            .fastest_decay(model)
            .into_iter()
            .enumerate()
            .filter_map(|(r, f)| f.map(|f| (r, f)))
            .filter(|(r, (speed, _))| {
                self.settings[*r].dt * speed > stability_limit(self.settings[*r].integrator)
            })
            .max_by(|a, b| a.1 .0.total_cmp(&b.1 .0))?;
        let settings = &self.settings[r];
        let limit = stability_limit(settings.integrator);
        Some(format!(
            "the model is stiff at this step: at t = {} s of run {}, ∂f/∂x has a decaying mode of \
             |λ| = {} /s, and {} at {} s (h·|λ| = {}) is stable only below h·|λ| ≈ {limit}: its \
             re-simulation needs steps of {} s or less (--dt), or the fast mode replaced by its \
             steady state (a quasi-steady-state model)",
            crate::identify::num(t),
            self.frames[r].origin(),
            crate::identify::sig(speed, 3),
            settings.integrator.name(),
            crate::identify::num(settings.dt),
            crate::identify::sig(settings.dt * speed, 3),
            crate::identify::sig(limit / speed, 2)
        ))
    }

    /// Runs for an output-error fit of `model` by RK4: at `dt` where given, else one step per
    /// sample (the recorded inputs are known only at the samples) cut to a whole fraction of
    /// it where the model is stiff there ([`Runs::stable`]), with what was cut. A step given
    /// is kept: where it is unstable, the re-simulation's failure says so.
    pub fn for_output_error(
        model: &Model,
        frames: &[Frame],
        dt: Option<f64>,
    ) -> Result<(Runs, Option<String>), DiagnoseError> {
        let step = dt.unwrap_or_else(|| crate::data::sample_step(frames));
        let runs = Runs::new(model, frames, step, Integrator::Rk4)?;
        Ok(if dt.is_some() { (runs, None) } else { runs.stable(model) })
    }

    /// These runs with each run's fixed step cut to a whole fraction at which `model`'s
    /// re-simulation is stable (h·|λ| at most 80 % of the method's limit, RK4's 2.78, for the
    /// fastest decaying mode over the run's samples), and what was done, if anything was: a
    /// stiff model (chemical kinetics, a fast lag) re-simulated at its records' interval
    /// diverges whatever its parameters. A run that would need more than 10 000 steps per
    /// sample keeps its step (its re-simulation then says why it fails).
    pub fn stable(&self, model: &Model) -> (Runs, Option<String>) {
        let mut out = self.clone();
        let mut cut: Option<(usize, f64, f64)> = None;
        for (r, fastest) in self.fastest_decay(model).into_iter().enumerate() {
            let Some((speed, _)) = fastest else { continue };
            let s = &mut out.settings[r];
            let limit = 0.8 * stability_limit(s.integrator);
            let per_step = (s.dt * speed / limit).ceil();
            if per_step <= 1.0 || per_step > MOST_SUBSTEPS {
                continue;
            }
            // the samples fall on the finer grid: the step a whole fraction of the interval
            let every = (s.sample / s.dt).round().max(1.0);
            s.dt = s.sample / (every * per_step);
            if cut.is_none_or(|(_, _, d)| s.dt < d) {
                cut = Some((r, speed, s.dt));
            }
        }
        let note = cut.map(|(r, speed, dt)| {
            format!(
                "the model is stiff against the runs' step (a decaying mode of |λ| = {} /s in run {}: \
                 {} is stable only below h·|λ| ≈ {}): re-simulated at {} s, {} steps per sample",
                crate::identify::sig(speed, 3),
                self.frames[r].origin(),
                self.settings[r].integrator.name(),
                stability_limit(self.settings[r].integrator),
                crate::identify::sig(dt, 2),
                (self.settings[r].sample / dt).round()
            )
        });
        (out, note)
    }

    /// [`Runs::residuals`] cut into their series, one per run and compared state or derived
    /// variable.
    pub fn series(&self, residuals: &[f64]) -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        let mut at = 0;
        for f in &self.frames {
            // a quantity the run does not record has an empty series there
            for (_, len) in self.recorded(f) {
                let end = (at + len).min(residuals.len());
                // a schedule's samples only: the rows between are compared as none
                let samples = residuals[at..end].iter().enumerate().filter(|(k, _)| f.is_sample(*k));
                out.push(samples.map(|(_, r)| *r).collect());
                at = end;
            }
        }
        out
    }

    /// What a run's re-simulation `sim` is compared in: each compared state and then each
    /// derived variable, as (name, unit, scale, simulated at the samples).
    fn compared_in<'a>(&'a self, sim: &'a Trajectory) -> Vec<(&'a str, &'a str, f64, &'a [f64])> {
        let states = self.states.iter().zip(&self.units).zip(&self.scale).map(|(((i, name), unit), sc)| {
            (name.as_str(), unit.as_str(), *sc, sim.states.get(*i).map_or(&[][..], |c| c.as_slice()))
        });
        let outputs = self.outputs.iter().map(|o| {
            let simulated =
                sim.observed.iter().find(|(n, _)| *n == o.name).map_or(&[][..], |(_, c)| c.as_slice());
            (o.name.as_str(), "", o.scale, simulated)
        });
        states.chain(outputs).collect()
    }

    /// The scale of compared quantity `q` ([`Runs::compared_in`]'s order).
    fn compared_scale(&self, q: usize) -> f64 {
        self.scale.get(q).copied().unwrap_or_else(|| self.outputs[q - self.scale.len()].scale)
    }

    /// Scaled residuals (sim − measured) of every compared state and derived variable, run by
    /// run (a sample the re-simulation did not reach is NaN).
    pub fn residuals(&self, sims: &[Trajectory]) -> Vec<f64> {
        let mut r = Vec::with_capacity(self.residual_count());
        for (run, sim) in sims.iter().enumerate().take(self.frames.len()) {
            r.extend(self.run_residuals(run, sim));
        }
        r
    }

    /// How long each run's re-simulation by `model` is predictable at all: the sample at which
    /// a twin started a millionth of each compared state's spread off (`sims` the nominal
    /// ones) parts from it by a tenth of a spread, `None` where it never does within the run.
    /// A chaotic model (Lorenz) or a strongly unstable one parts from itself so, and any
    /// model's errors after that sample, however right the model, are of that size: they say
    /// nothing about it.
    pub fn horizon(&self, model: &Model, sims: &[Trajectory]) -> Vec<Option<usize>> {
        self.horizon_from(model, sims, PERTURBATION)
    }

    /// [`Runs::horizon`] of a twin started `offset` of each compared state's spread off (the
    /// records' noise: how long a run is predictable from its recorded start).
    pub fn horizon_from(&self, model: &Model, sims: &[Trajectory], offset: f64) -> Vec<Option<usize>> {
        let mut twin = self.clone();
        for x0 in &mut twin.x0 {
            for ((i, _), scale) in self.states.iter().zip(&self.scale) {
                x0[*i] += offset * scale;
            }
        }
        let Ok(twins) = twin.simulate(model, &[], &[]) else { return vec![None; self.frames.len()] };
        sims.iter()
            .zip(&twins)
            .map(|(a, b)| {
                let parted = |k: usize| {
                    self.states.iter().zip(&self.scale).any(|((i, _), scale)| {
                        let (x, y) = (a.states[*i].get(k), b.states[*i].get(k));
                        // a NaN twin has parted too
                        x.zip(y).is_none_or(|(x, y)| (x - y).abs().is_nan() || (x - y).abs() > PARTED * scale)
                    })
                };
                (0..a.time.len().min(b.time.len())).find(|&k| parted(k))
            })
            .collect()
    }

    /// Each run's errors (model − measured) of each compared quantity, over its first
    /// `rows[r]` samples (every sample where `None`).
    fn errors(&self, sims: &[Trajectory], rows: &[Option<usize>]) -> Vec<(String, Vec<Compared>)> {
        self.frames
            .iter()
            .zip(sims)
            .zip(rows)
            .map(|((f, sim), rows)| {
                let per = self
                    .compared_in(sim)
                    .into_iter()
                    .map(|(name, unit, _, simulated)| {
                        let meas = f.column(name).unwrap_or(&[]);
                        let d: Vec<f64> = meas
                            .iter()
                            .take(rows.unwrap_or(usize::MAX))
                            .enumerate()
                            .filter(|(k, _)| f.is_sample(*k))
                            .map(|(k, m)| simulated.get(k).copied().unwrap_or(f64::NAN) - m)
                            .collect();
                        (name.to_string(), unit.to_string(), d)
                    })
                    .collect();
                (f.origin().to_string(), per)
            })
            .collect()
    }

    /// Each run's RMS and max per compared quantity over its first `rows[r]` samples (a run
    /// before its motion parts from itself, [`Runs::horizon`]); every sample where `None`.
    pub fn run_gaps(&self, sims: &[Trajectory], rows: &[Option<usize>]) -> Vec<RunGap> {
        run_gaps(self.errors(sims, rows))
    }

    /// RMS and max per compared state and derived variable, in its unit.
    pub fn gap(&self, sims: &[Trajectory]) -> Gap {
        let errors = self.errors(sims, &vec![None; self.frames.len()]);
        // over all runs, sample after sample
        let quantities = errors.first().map_or(0, |(_, per)| per.len());
        let states = (0..quantities)
            .map(|q| {
                let (mut sq, mut n, mut max) = (0.0, 0usize, 0.0f64);
                for d in errors.iter().map(|(_, per)| &per[q].2) {
                    for v in d {
                        sq += v * v;
                        n += 1;
                        max = max.max(v.abs());
                    }
                }
                let (name, unit, _) = &errors[0].1[q];
                (name.clone(), unit.clone(), (sq / n.max(1) as f64).sqrt(), max)
            })
            .collect();
        let cost = self.residuals(sims).iter().map(|r| r * r).sum();
        Gap { states, runs: run_gaps(errors), cost }
    }

    /// Where the gap is: leading state, onset, growth, and what it goes with.
    pub fn locate(&self, sims: &[Trajectory]) -> Location {
        let scaled_rms: Vec<f64> = self
            .states
            .iter()
            .zip(&self.scale)
            .map(|((i, name), sc)| {
                let (mut sq, mut n) = (0.0, 0usize);
                for (f, sim) in self.frames.iter().zip(sims) {
                    for (k, m) in f.column(name).unwrap_or(&[]).iter().enumerate() {
                        sq += ((sim.states[*i][k.min(sim.states[*i].len() - 1)] - m) / sc).powi(2);
                        n += 1;
                    }
                }
                (sq / n.max(1) as f64).sqrt()
            })
            .collect();
        let lead = scaled_rms.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).map_or(0, |x| x.0);
        let (li, lname) = &self.states[lead];
        let mut onset = Vec::new();
        let (mut first, mut second) = (0.0, 0.0);
        // growth rate of the gap against the magnitude of every measured column
        let mut rates: Vec<f64> = Vec::new();
        let mut times: Vec<f64> = Vec::new();
        let mut columns: Vec<(String, Vec<f64>)> =
            self.frames[0].names().iter().skip(1).map(|n| (n.clone(), Vec::new())).collect();
        for (f, sim) in self.frames.iter().zip(sims) {
            let meas = f.column(lname).unwrap_or(&[]);
            let t = f.time();
            let e: Vec<f64> = meas
                .iter()
                .enumerate()
                .map(|(k, m)| sim.states[*li][k.min(sim.states[*li].len() - 1)] - m)
                .collect();
            let emax = e.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            let k0 = e.iter().position(|v| v.abs() > 0.1 * emax).unwrap_or(0);
            onset.push((f.origin().to_string(), t[k0] - t[0]));
            let half = e.len() / 2;
            first += e[..half].iter().map(|v| v * v).sum::<f64>();
            second += e[half..].iter().map(|v| v * v).sum::<f64>();
            for k in 1..e.len() {
                rates.push(((e[k] - e[k - 1]) / (t[k] - t[k - 1])).abs());
                times.push(t[k] - t[0]);
                for (name, col) in columns.iter_mut() {
                    col.push(f.column(name).map_or(f64::NAN, |c| c[k].abs()));
                }
            }
        }
        let growth = (second / first.max(1e-300)).sqrt();
        let regime = columns
            .iter()
            .filter(|(n, _)| n != lname && !n.ends_with("_dot"))
            // a column that grows with the time run (a distance run, a position) says only
            // "late in the run": not a regime of the motion
            .filter(|(_, c)| correlation(&times, c).abs() < 0.9)
            .map(|(n, c)| (n.clone(), correlation(&rates, c)))
            .filter(|(_, r)| r.is_finite())
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
            .unwrap_or_default();
        let earliest = onset.iter().map(|o| o.1).fold(f64::INFINITY, f64::min);
        let size = if regime.1 >= 0.0 { "large" } else { "small" };
        let with = if regime.1.abs() >= 0.3 {
            format!("it grows fastest where |{}| is {size} (correlation {:.2})", regime.0, regime.1)
        } else {
            format!(
                "its growth goes with no one measured signal (the closest: |{}| {size}, correlation {:.2})",
                regime.0, regime.1
            )
        };
        let words = format!(
            "The gap is led by {lname}; it is visible from t = {earliest:.1} s on; {}; {with}.",
            if growth > 1.5 {
                format!("it keeps growing (second half {growth:.1}× the first): an effect that accumulates")
            } else {
                format!("it does not grow much (second half {growth:.1}× the first)")
            },
        );
        Location { leading_state: lname.clone(), onset, growth, regime, words }
    }
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()) as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma).powi(2);
        sbb += (y - mb).powi(2);
    }
    sab / (saa * sbb).sqrt()
}

/// An equation's coefficients as a model stores them: (term, value, standard error).
type Coefficients = Vec<(crate::term::Term, f64, Option<f64>)>;

/// The model with a hypothesis's term coefficients added (inputs are changed in simulation).
pub fn apply(model: &Model, h: &Hypothesis, theta: &[f64]) -> Result<Model, super::DiagnoseError> {
    let mut m = model.clone();
    let terms = h.terms();
    if !terms.is_empty() {
        // each equation's coefficients changed together and stored once (a refinement
        // applies every identified term at every iteration)
        let mut changed: Vec<(&str, Coefficients, Option<f64>)> = Vec::new();
        for ((eq, text), value) in terms.iter().zip(theta) {
            let term = m.vocabulary.parse(text)?;
            let at = match changed.iter().position(|(name, _, _)| name == eq) {
                Some(at) => at,
                None => {
                    let e = m
                        .equation(eq)
                        .ok_or_else(|| super::DiagnoseError::Setup(format!("no equation {eq}")))?;
                    changed.push((eq.as_str(), e.coefficients.clone(), e.intercept));
                    changed.len() - 1
                }
            };
            let coefs = &mut changed[at].1;
            match coefs.iter_mut().find(|(t, _, _)| *t == term) {
                Some(c) => c.1 += value,
                None => coefs.push((term, *value, None)),
            }
        }
        for (eq, coefs, intercept) in changed {
            m.set_coefficients(eq, coefs, intercept);
        }
    }
    if let Effect::Beyond { equation, term, .. } = &h.effect {
        m.add_candidate(equation, m.vocabulary.parse(term)?);
    }
    Ok(m)
}

/// Scaled residuals of the runs re-simulated with the hypothesis at θ; `None` where the
/// simulation fails or a residual is not finite.
pub(super) fn residuals(data: &Runs, model: &Model, h: &Hypothesis, theta: &[f64]) -> Option<Vec<f64>> {
    let m = apply(model, h, theta).ok()?;
    let sims = data.simulate(&m, &h.input_offsets(theta, model), &h.input_scales(theta, model)).ok()?;
    let r = data.residuals(&sims);
    r.iter().all(|v| v.is_finite()).then_some(r)
}

fn jacobian(data: &Runs, model: &Model, h: &Hypothesis, theta: &[f64]) -> Option<(Vec<f64>, DMatrix<f64>)> {
    let r0 = residuals(data, model, h, theta)?;
    // the columns are independent re-simulations: all threads take them
    let columns: Vec<Option<Vec<f64>>> = (0..theta.len())
        .into_par_iter()
        .map(|j| {
            let step = 1e-6 * theta[j].abs().max(1e-3);
            let (mut up, mut down) = (theta.to_vec(), theta.to_vec());
            up[j] += step;
            down[j] -= step;
            let (ru, rd) = (residuals(data, model, h, &up)?, residuals(data, model, h, &down)?);
            Some(ru.iter().zip(&rd).map(|(a, b)| (a - b) / (2.0 * step)).collect())
        })
        .collect();
    let mut jac = DMatrix::<f64>::zeros(r0.len(), theta.len());
    for (j, column) in columns.into_iter().enumerate() {
        jac.set_column(j, &DVector::from_vec(column?));
    }
    Some((r0, jac))
}

/// Sum of squares.
pub(super) fn cost(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// Why a Gauss-Newton or Levenberg-Marquardt estimate could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EstimateError {
    /// The re-simulation left its bounds or gave a non-finite residual; where it did so.
    #[error("diverges {0}")]
    Diverges(&'static str),
    /// The model at its start values does not re-simulate the runs to a finite residual: why.
    #[error("gives no finite residual at the start (the free parameters' values in the file): {0}")]
    StartNotFinite(String),
    /// JᵀJ has no inverse (a parameter the runs do not excite).
    #[error("has singular normal equations")]
    Singular,
    /// The re-simulation's derivative with respect to these is not finite (a term whose slope
    /// is infinite where the motion passes through).
    #[error(
        "has no finite slope with respect to {0}: a term whose slope is infinite where the motion passes (sqrt(v), |v|^0.5 at v = 0) cannot be fitted by output error there; hold that free value fixed, or write the term so that it is smooth there"
    )]
    SlopeNotFinite(String),
}

/// `iterations` Gauss-Newton steps from θ = 0; (θ, cost).
pub fn gauss_newton(
    data: &Runs,
    model: &Model,
    h: &Hypothesis,
    iterations: usize,
) -> Result<(Vec<f64>, f64), EstimateError> {
    let mut theta = vec![0.0; h.parameters()];
    let mut best =
        cost(&residuals(data, model, h, &theta).ok_or(EstimateError::Diverges("with the unchanged model"))?);
    for _ in 0..iterations {
        let (r, j) = jacobian(data, model, h, &theta).ok_or(EstimateError::Diverges("near the start"))?;
        let jt = j.transpose();
        let step = (&jt * &j).lu().solve(&(&jt * DVector::from_vec(r))).ok_or(EstimateError::Singular)?;
        let trial: Vec<f64> = theta.iter().zip(step.iter()).map(|(t, d)| t - d).collect();
        match residuals(data, model, h, &trial) {
            Some(rt) if cost(&rt) < best => {
                best = cost(&rt);
                theta = trial;
            }
            _ => break,
        }
    }
    Ok((theta, best))
}

/// A Levenberg-Marquardt fit of a hypothesis's parameters.
pub struct Estimated {
    /// The parameters.
    pub theta: Vec<f64>,
    /// Scaled sum of squares at θ.
    pub cost: f64,
    /// σ²(JᵀJ)⁻¹ with σ² = cost / (residuals − parameters), if JᵀJ is invertible (it
    /// assumes independent residuals).
    pub covariance: Option<DMatrix<f64>>,
}

impl Estimated {
    /// √ of the covariance's diagonal (NaN without one).
    pub fn std_errors(&self) -> Vec<f64> {
        match &self.covariance {
            Some(c) => (0..self.theta.len()).map(|i| c[(i, i)].max(0.0).sqrt()).collect(),
            None => vec![f64::NAN; self.theta.len()],
        }
    }
}

/// Levenberg-Marquardt from θ0.
pub fn levenberg_marquardt(
    data: &Runs,
    model: &Model,
    h: &Hypothesis,
    theta0: Vec<f64>,
) -> Result<Estimated, EstimateError> {
    let mut theta = theta0;
    let (mut r, mut j) = jacobian(data, model, h, &theta).ok_or(EstimateError::Diverges("at the start"))?;
    let mut c = cost(&r);
    let mut lambda = 1e-3;
    for _ in 0..30 {
        let jt = j.transpose();
        let jtj = &jt * &j;
        let g = &jt * DVector::from_vec(r.clone());
        let mut a = jtj.clone();
        for k in 0..a.nrows() {
            a[(k, k)] += lambda * jtj[(k, k)].max(1e-300);
        }
        let Some(step) = a.lu().solve(&g) else { break };
        let trial: Vec<f64> = theta.iter().zip(step.iter()).map(|(t, d)| t - d).collect();
        match residuals(data, model, h, &trial) {
            Some(rt) if cost(&rt) < c => {
                let improvement = (c - cost(&rt)) / c.max(1e-300);
                theta = trial;
                (r, j) = jacobian(data, model, h, &theta).ok_or(EstimateError::Diverges("on the way"))?;
                c = cost(&r);
                lambda = (lambda / 10.0).max(1e-12);
                if improvement < 1e-10 {
                    break;
                }
            }
            _ => {
                lambda *= 10.0;
                if lambda > 1e10 {
                    break;
                }
            }
        }
    }
    // counted at the samples (a schedule's rows between them are compared as none)
    let n = data.residual_count().min(r.len()) as f64;
    let k = theta.len() as f64;
    let sigma2 = c / (n - k).max(1.0);
    let covariance = (j.transpose() * &j).try_inverse().map(|inv| inv * sigma2);
    Ok(Estimated { theta, cost: c, covariance })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An oscillator of ω = 0.63 /s sampled once a second (ten samples a cycle): one RK4 step
    /// a sample drifts 0.007 rad a cycle, a thousandth of the motion's spread within the
    /// first cycles; the step is halved until it resolves the motion, and the runs then
    /// re-simulate it far closer; sampled ten times as fast they keep their step.
    #[test]
    fn a_motion_sampled_coarsely_is_resolved_in_finer_steps() {
        let model = Model::parse(
            "[model]\nname = \"oscillator\"\n[[states]]\nname = \"x\"\n[[states]]\nname = \"v\"\n\
             [equations.x_dot]\nstate = \"x\"\ncoefficients = { \"v\" = 1.0 }\n\
             [equations.v_dot]\nstate = \"v\"\ncoefficients = { \"x\" = -0.3969 }\n",
            "oscillator.toml",
        )
        .unwrap();
        let run = |step: f64| {
            let t: Vec<f64> = (0..=(60.0 / step) as usize).map(|k| k as f64 * step).collect();
            let mut f = Frame::new("run", "t", t.clone()).unwrap();
            f.push("x", t.iter().map(|t| (0.63 * t).cos()).collect()).unwrap();
            f.push("v", t.iter().map(|t| -0.63 * (0.63 * t).sin()).collect()).unwrap();
            f
        };
        let (whole, _) = Runs::for_output_error(&model, &[run(1.0)], None).unwrap();
        let (finer, runs) = whole.resolving(&model, 1, 1e-3, 64);
        assert!(finer >= 2 && runs.step_error(&model).is_some_and(|e| e <= 1e-3), "{finer}");
        assert!(whole.step_error(&model).is_some_and(|e| e > 1e-3));
        // RK4's error a step goes as h⁵: the squared errors over six cycles far smaller
        let cost = |runs: &Runs| runs.gap(&runs.simulate(&model, &[], &[]).unwrap()).cost;
        let (fine, coarse) = (cost(&runs), cost(&whole));
        assert!(fine < coarse / 100.0, "{fine} at 1/{finer} s, {coarse} at 1 s");
        // at most as fine as asked
        assert_eq!(whole.resolving(&model, 1, 1e-3, 1).0, 1);
        let (fast, _) = Runs::for_output_error(&model, &[run(0.1)], None).unwrap();
        assert_eq!(fast.resolving(&model, 1, 1e-3, 64).0, 1);
    }
}
