//! Simulation of identified equations: a [`System`] (any [`RightHandSide`], e.g. a model
//! file's equations, compiled once),
//! a [`Controller`] that sets the inputs, and an [`Integrator`] (adaptive by default). Nothing
//! here knows about ships; the manoeuvres of the ship plug-in are controllers.

mod controller;
mod dopri5;
mod integrator;
mod rosenbrock;
mod steady;
mod system;

pub use controller::{Ahead, Constant, Controller, Delayed, Replay, Watch};
pub use integrator::{simulate, Integrator, Settings, Tolerances, Trajectory};
pub use steady::{solve_steady, SteadyProblem, Unknown};
pub use system::{sizes_of, RightHandSide, System, Workspace};

/// Why a simulation stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    /// A state became NaN/∞ or left its declared bounds.
    #[error("simulation diverged at t = {t:.3} s: {state} = {value:.6} ({why}); state was {snapshot}")]
    Diverged {
        /// Time of the offending step.
        t: f64,
        /// The state.
        state: String,
        /// Its value.
        value: f64,
        /// Non-finite or out of bounds.
        why: String,
        /// All states at the last good step.
        snapshot: String,
    },
    /// Settings that do not fit.
    #[error("{0}")]
    Settings(String),
    /// A model that cannot be simulated.
    #[error(transparent)]
    Term(#[from] crate::term::TermError),
    /// Replay data missing a column or too short.
    #[error(transparent)]
    Data(#[from] crate::data::DataError),
    /// A run too large for memory, refused before it started.
    #[error(transparent)]
    TooLarge(#[from] crate::budget::TooLarge),
    /// A steady state that could not be found.
    #[error("no steady state found: {0}")]
    NoSteadyState(String),
}

/// The plane a vehicle's run moves in, where its model has one: the states of its position
/// drawn across and up (a ship's y0 and x0), each with its axis label, and the length the
/// positions are drawn in units of (a ship's length), so that a figure draws the track at
/// equal scale instead of each position over time.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    /// The state drawn across, and its axis label.
    pub across: (String, String),
    /// The state drawn up, and its axis label.
    pub up: (String, String),
    /// Positions are drawn divided by this (1: in the states' own unit).
    pub length: f64,
    /// The panel's title.
    pub title: String,
}
