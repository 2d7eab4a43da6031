//! Simulation of identified equations: a [`System`] (any [`RightHandSide`], e.g. a model
//! file's equations, compiled once),
//! a [`Controller`] that sets the inputs, and a fixed-step [`Integrator`]. Nothing here knows
//! about ships; the manoeuvres of the ship plug-in are controllers.

mod controller;
mod dopri5;
mod integrator;
mod steady;
mod system;

pub use controller::{Constant, Controller, Replay};
pub use integrator::{simulate, Integrator, Settings, Tolerances, Trajectory};
pub use steady::{solve_steady, SteadyProblem, Unknown};
pub use system::{RightHandSide, System, Workspace};

/// Why a simulation stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    /// A state became NaN/∞ or left its declared bounds.
    #[error("simulation diverged at t = {t} s: {state} = {value} ({why}); state was {snapshot}")]
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
