//! The ship-manoeuvring plug-in: particulars, the straight run that precedes a manoeuvre,
//! the standard manoeuvres (zigzag, turning circle, spiral, pull-out, replay) as controllers
//! of the generic simulator, and their metrics as naval architects define them (IMO
//! MSC.137(76), ITTC 7.5-04-02-01). Angles are radians inside, degrees in metrics.

pub mod basin;
pub mod checks;
#[cfg(feature = "plot")]
pub mod figure;
pub mod hypotheses;
pub mod imo;
pub mod manoeuvre;
pub mod observed;
pub mod particulars;
pub mod plugin;
pub mod spec;
pub mod stability;
pub mod tracking;

use std::collections::BTreeMap;

pub use manoeuvre::{Manoeuvre, Metrics};
pub use spec::{default_model, ShipNames, ShipSpec, DEFAULT_MODEL, DEFAULT_MODEL_PATH};

use crate::data::{DataError, Frame};
use crate::model::Model;
use crate::sim::{self, simulate, Settings, SimError, SteadyProblem, System, Trajectory, Unknown};

/// Why a ship run failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ShipError {
    /// The model lacks the `[ship]` section or a role's state.
    #[error("{0}")]
    Model(String),
    /// The simulation failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// Data (replay) problem.
    #[error(transparent)]
    Data(#[from] DataError),
    /// A manoeuvre string that does not parse.
    #[error("manoeuvre `{text}`: {message}")]
    Manoeuvre {
        /// What was given.
        text: String,
        /// What is wrong.
        message: String,
    },
}

/// Indices of the ship's roles in the system.
#[derive(Clone, Copy, Debug)]
pub struct Roles {
    /// Surge velocity state.
    pub u: usize,
    /// Sway velocity state.
    pub v: usize,
    /// Yaw rate state.
    pub r: usize,
    /// Heading state.
    pub psi: usize,
    /// Position along the initial course.
    pub x0: usize,
    /// Position across it.
    pub y0: usize,
    /// Rudder input.
    pub rudder: usize,
    /// Propeller rate input, solved for the self-propulsion point in the straight run.
    pub propeller: Option<usize>,
}

/// The straight run before a manoeuvre: rudder δ0 and sway v0 that cancel the asymmetry
/// terms at u = u0, r = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct StraightRun {
    /// Initial state of the system.
    pub x: Vec<f64>,
    /// Inputs (δ0 in the rudder slot).
    pub input: Vec<f64>,
    /// δ0 in degrees.
    pub delta0_deg: f64,
    /// Steady sway v0 in m/s.
    pub v0: f64,
    /// u̇ left at the straight run (the model's surge balance at u0; ideally 0), m/s².
    pub surge_residual: f64,
}

/// A ship model ready to manoeuvre.
#[derive(Clone, Debug)]
pub struct Ship {
    /// Particulars.
    pub spec: ShipSpec,
    /// The compiled equations.
    pub system: System,
    /// Where the roles are.
    pub roles: Roles,
    /// sign(∂ṙ/∂δ): −1 when positive rudder turns to port (the paper's convention).
    pub turn_sign: f64,
    /// The inputs' declared values (the model file's `initial`), in the system's order.
    pub base_input: Vec<f64>,
}

/// One simulated manoeuvre.
#[derive(Clone, Debug)]
pub struct Run {
    /// The manoeuvre.
    pub manoeuvre: Manoeuvre,
    /// The straight run it started from.
    pub start: StraightRun,
    /// Output samples.
    pub trajectory: Trajectory,
    /// Metrics (from the run at full step resolution).
    pub metrics: Metrics,
}

/// The model's `[ship]` section with its role names as frames and systems spell them
/// (aliases resolved: `psi` → `ψ`, `delta` → `δ`); `None` for a model without one (or with
/// one that does not read: [`ShipSpec::of`] says why).
pub fn canonical_spec(model: &Model) -> Option<ShipSpec> {
    let mut spec = ShipSpec::of(model).ok().flatten()?;
    let ShipNames { u, v, r, psi, x0, y0, rudder, propeller } = &mut spec.names;
    for n in [u, v, r, psi, x0, y0, rudder].into_iter().chain(propeller.as_mut()) {
        if let Some(c) = model.vocabulary.canonical(n) {
            *n = c;
        }
    }
    Some(spec)
}

impl Ship {
    /// A ship from a model with a `[ship]` section.
    pub fn new(model: &Model, with_intercept: bool) -> Result<Ship, ShipError> {
        let spec = ShipSpec::of(model)?.ok_or_else(|| {
            ShipError::Model(format!("{}: no [ship] section: not a ship model", model.path))
        })?;
        let system = System::new(model, &BTreeMap::new(), with_intercept)?;
        let state = |name: &str| {
            let canonical = model.vocabulary.canonical(name).unwrap_or_else(|| name.to_string());
            system.state_index(&canonical).ok_or_else(|| {
                ShipError::Model(format!(
                    "{}: [ship] names state `{name}`, which has no equation",
                    model.path
                ))
            })
        };
        let n = &spec.names;
        let rudder_name = model.vocabulary.canonical(&n.rudder).unwrap_or_else(|| n.rudder.clone());
        let roles = Roles {
            u: state(&n.u)?,
            v: state(&n.v)?,
            r: state(&n.r)?,
            psi: state(&n.psi)?,
            x0: state(&n.x0)?,
            y0: state(&n.y0)?,
            rudder: system.input_index(&rudder_name).ok_or_else(|| {
                ShipError::Model(format!("{}: rudder input `{}` is not declared", model.path, n.rudder))
            })?,
            propeller: match &n.propeller {
                None => None,
                Some(p) => {
                    let canonical = model.vocabulary.canonical(p).unwrap_or_else(|| p.clone());
                    Some(system.input_index(&canonical).ok_or_else(|| {
                        ShipError::Model(format!("{}: propeller input `{p}` is not declared", model.path))
                    })?)
                }
            },
        };
        // inputs other than the rudder start at their declared values (the propeller's as
        // the straight run's first guess)
        let base_input = system
            .inputs
            .iter()
            .map(|name| model.spec().inputs.iter().find(|i| &i.name == name).map_or(0.0, |i| i.initial))
            .collect();
        let mut ship = Ship { spec, system, roles, turn_sign: -1.0, base_input };
        ship.turn_sign = ship.rudder_effect()?.signum();
        Ok(ship)
    }

    fn rudder_effect(&self) -> Result<f64, ShipError> {
        let mut ws = self.system.workspace();
        let mut x = vec![0.0; self.system.dim()];
        x[self.roles.u] = self.spec.u0;
        let mut input = self.base_input.clone();
        let mut d = vec![0.0; x.len()];
        input[self.roles.rudder] = 0.01;
        self.system.derivatives(&x, &input, &mut ws, &mut d);
        let plus = d[self.roles.r];
        input[self.roles.rudder] = -0.01;
        self.system.derivatives(&x, &input, &mut ws, &mut d);
        let effect = plus - d[self.roles.r];
        if effect == 0.0 || !effect.is_finite() {
            return Err(ShipError::Model("the rudder has no effect on the yaw rate at u0".into()));
        }
        Ok(effect)
    }

    /// The model's own states beyond the ship's (a lag of the hull's forces, a roll angle)
    /// that some derivative depends on at `x`, `input`: those a straight run holds steady. One
    /// nothing depends on (a distance run, like the track's x0 and y0) only integrates.
    pub(crate) fn own_states(&self, x: &[f64], input: &[f64]) -> Vec<usize> {
        let r = &self.roles;
        let roles = [r.u, r.v, r.r, r.psi, r.x0, r.y0];
        let mut ws = self.system.workspace();
        let mut base = vec![0.0; x.len()];
        self.system.derivatives(x, input, &mut ws, &mut base);
        let mut moved = vec![0.0; x.len()];
        (0..x.len())
            .filter(|i| !roles.contains(i))
            .filter(|&i| {
                let mut x = x.to_vec();
                x[i] += 1e-6 * x[i].abs().max(1.0);
                self.system.derivatives(&x, input, &mut ws, &mut moved);
                moved.iter().zip(&base).any(|(a, b)| a != b)
            })
            .collect()
    }

    /// Steady straight running at u0: δ0 and v0 with v̇ = ṙ = 0 (r = 0, heading 0), and
    /// the propeller's rate with u̇ = 0 where the ship names one.
    pub fn straight_run(&self) -> Result<StraightRun, ShipError> {
        let r = &self.roles;
        let mut x = vec![0.0; self.system.dim()];
        x[r.u] = self.spec.u0;
        let mut input = self.base_input.clone();
        input[r.rudder] = 0.0;
        let (mut unknowns, mut zero) = (vec![Unknown::State(r.v), Unknown::Input(r.rudder)], vec![r.v, r.r]);
        if let Some(p) = r.propeller {
            unknowns.push(Unknown::Input(p));
            zero.push(r.u);
        }
        // states the ship has no role for (a lag, a filter of the model file's own) are
        // steady in a straight run too
        for i in self.own_states(&x, &input) {
            unknowns.push(Unknown::State(i));
            zero.push(i);
        }
        let p = SteadyProblem { system: &self.system, x, input, unknowns, zero };
        let (x, input) = sim::solve_steady(&p)?;
        let mut ws = self.system.workspace();
        let mut d = vec![0.0; x.len()];
        self.system.derivatives(&x, &input, &mut ws, &mut d);
        Ok(StraightRun {
            delta0_deg: input[r.rudder].to_degrees(),
            v0: x[r.v],
            surge_residual: d[r.u],
            x,
            input,
        })
    }

    /// The ship's time scale L/U0, s: a manoeuvre's default times are so many of it.
    pub fn time_scale(&self) -> f64 {
        self.spec.lpp / self.spec.u0
    }

    /// Simulates a manoeuvre from the straight run. Metrics use every step; the trajectory
    /// is sampled at `settings.sample`.
    pub fn run(&self, manoeuvre: &Manoeuvre, settings: &Settings) -> Result<Run, ShipError> {
        let mut start = self.straight_run()?;
        if let Manoeuvre::Replay(r) = manoeuvre {
            // a recording starts from its own first state where it has the columns
            for (i, name) in self.system.states.iter().enumerate() {
                if let Some(c) = r.frame.column(name) {
                    start.x[i] = c[0];
                }
            }
            for (i, name) in self.system.inputs.iter().enumerate() {
                if let Some(c) = r.frame.column(name) {
                    start.input[i] = c[0];
                }
            }
        }
        self.run_from(manoeuvre, settings, start)
    }

    /// Like [`Ship::run`], from a given start.
    pub fn run_from(
        &self,
        manoeuvre: &Manoeuvre,
        settings: &Settings,
        start: StraightRun,
    ) -> Result<Run, ShipError> {
        // the output interval is checked as asked for, although every step is kept for the
        // metrics (that run's memory is checked by `simulate`)
        settings.check(0)?;
        manoeuvre.check(self)?;
        let fine = Settings { sample: settings.dt, ..*settings };
        let mut controller = manoeuvre.controller(self, &start)?;
        let full = simulate(&self.system, &start.x, controller.as_mut(), &fine)?;
        let metrics = manoeuvre.metrics(self, &full);
        let every = ((settings.sample / settings.dt).round() as usize).max(1);
        let trajectory = downsample(&full, every);
        Ok(Run { manoeuvre: manoeuvre.clone(), start, trajectory, metrics })
    }

    /// Speed U = √(u² + v²) and drift angle β = −atan(v/u) (eq. B10) of a trajectory.
    pub fn speed_and_drift(&self, t: &Trajectory) -> (Vec<f64>, Vec<f64>) {
        let (u, v) = (&t.states[self.roles.u], &t.states[self.roles.v]);
        let speed = u.iter().zip(v).map(|(u, v)| u.hypot(*v)).collect();
        let drift = u.iter().zip(v).map(|(u, v)| (-v).atan2(*u)).collect();
        (speed, drift)
    }

    /// The trajectory as a frame with U and β added (SI units, radians).
    pub fn frame(&self, t: &Trajectory, origin: &str) -> Result<Frame, DataError> {
        let mut f = t.to_frame(origin, "t")?;
        let (speed, drift) = self.speed_and_drift(t);
        f.push("U", speed)?;
        f.push("β", drift)?;
        Ok(f)
    }
}

fn downsample(t: &Trajectory, every: usize) -> Trajectory {
    let keep: Vec<usize> = (0..t.time.len()).filter(|i| i % every == 0 || *i == t.time.len() - 1).collect();
    let pick = |c: &Vec<f64>| keep.iter().map(|&i| c[i]).collect::<Vec<f64>>();
    Trajectory {
        time: pick(&t.time),
        state_names: t.state_names.clone(),
        input_names: t.input_names.clone(),
        states: t.states.iter().map(pick).collect(),
        inputs: t.inputs.iter().map(pick).collect(),
        derivatives: t.derivatives.iter().map(pick).collect(),
        observed: t.observed.iter().map(|(n, c)| (n.clone(), pick(c))).collect(),
        stiff_from: t.stiff_from,
    }
}
pub mod oltmann;
