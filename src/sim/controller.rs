//! Controllers set a system's inputs. The integrator asks once per step for the inputs at
//! the end of the step, given the state at its start: that is what Oltmann's modified Euler
//! (eq. B8) uses, and RK4 interpolates between the two ends.

use crate::data::{DataError, Frame};

/// Sets the inputs of a simulation.
pub trait Controller {
    /// Inputs at time `t` given the latest state `x`. Called once per step, in time order.
    fn input(&mut self, t: f64, x: &[f64], out: &mut [f64]);
    /// Ends the run early (e.g. a manoeuvre is complete).
    fn done(&self, _t: f64, _x: &[f64]) -> bool {
        false
    }
}

/// Fixed inputs.
#[derive(Clone, Debug)]
pub struct Constant(pub Vec<f64>);

impl Controller for Constant {
    fn input(&mut self, _t: f64, _x: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&self.0);
    }
}

/// Inputs replayed from a recorded time series, linearly interpolated; held at the ends.
#[derive(Clone, Debug)]
pub struct Replay {
    time: Vec<f64>,
    columns: Vec<Vec<f64>>,
    cursor: usize,
}

impl Replay {
    /// Replays the named columns of a frame, in the order of the system's inputs.
    pub fn new(frame: &Frame, inputs: &[String]) -> Result<Replay, DataError> {
        let columns =
            inputs.iter().map(|n| frame.require(n).map(<[f64]>::to_vec)).collect::<Result<_, _>>()?;
        Ok(Replay { time: frame.time().to_vec(), columns, cursor: 0 })
    }

    /// The recorded value of input `k` at time `t`.
    pub fn at(&mut self, k: usize, t: f64) -> f64 {
        crate::data::interpolate_at(&self.time, &self.columns[k], t, &mut self.cursor)
    }
}

impl Controller for Replay {
    fn input(&mut self, t: f64, _x: &[f64], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.at(k, t);
        }
    }
}
