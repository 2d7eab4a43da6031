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
    /// Replays the named columns of a frame, in the order of the system's inputs. Time is
    /// counted from the frame's first sample, as a simulation counts it from its start (a
    /// record cut with a dataset's `from`, or logged from a clock that did not start at 0,
    /// was replayed shifted by its start time).
    pub fn new(frame: &Frame, inputs: &[String]) -> Result<Replay, DataError> {
        let columns =
            inputs.iter().map(|n| frame.require(n).map(<[f64]>::to_vec)).collect::<Result<_, _>>()?;
        let t0 = frame.time()[0];
        Ok(Replay { time: frame.time().iter().map(|t| t - t0).collect(), columns, cursor: 0 })
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A record that starts at t = 12 s is replayed from its first sample at simulation time 0.
    #[test]
    fn replay_counts_time_from_the_first_sample() {
        let mut f = Frame::new("late.csv", "t", vec![12.0, 13.0, 14.0]).unwrap();
        f.push("δ", vec![0.0, 1.0, 3.0]).unwrap();
        let mut r = Replay::new(&f, &["δ".to_string()]).unwrap();
        let mut out = [0.0];
        for (t, want) in [(0.0, 0.0), (0.5, 0.5), (1.5, 2.0), (2.0, 3.0), (9.0, 3.0)] {
            r.input(t, &[], &mut out);
            assert_eq!(out[0], want, "t = {t}");
        }
    }
}
