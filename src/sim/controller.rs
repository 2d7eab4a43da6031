//! Controllers set a system's inputs. The integrator asks once per step for the inputs at
//! the end of the step, given the state at its start: that is what Oltmann's modified Euler
//! (eq. B8) uses, and RK4 interpolates between the two ends. A controller that knows its
//! inputs ahead (a rudder held, or turning at its rate, until the heading reaches a limit)
//! says so ([`Controller::ahead`]), and the adaptive integrator steps past the control times
//! without asking.

use crate::data::{DataError, Frame};

/// Sets the inputs of a simulation.
pub trait Controller {
    /// Inputs at time `t` given the latest state `x`. Called once per step, in time order.
    fn input(&mut self, t: f64, x: &[f64], out: &mut [f64]);
    /// Ends the run early (e.g. a manoeuvre is complete).
    fn done(&self, _t: f64, _x: &[f64]) -> bool {
        false
    }
    /// Asked right after the inputs for control time `t` were given: whether those of the
    /// control times ahead are known without asking, with their rate of change (per second,
    /// one per input) written into `slope`. A promise: at a control time t′ before
    /// [`Ahead::until`], while the watched state lay inside its bounds at every control time
    /// from `t` up to the one before t′, [`Controller::input`] would give the inputs for `t`
    /// plus `slope·(t′ − t)` and [`Controller::done`] would be false. The adaptive integrator
    /// then steps past those control times (the dense output read only for the watched state
    /// and at the samples) and, before it asks again, says with [`Controller::passed`] how far
    /// it went. `None`, the default: asked at every control time.
    fn ahead(&self, _t: f64, _slope: &mut [f64]) -> Option<Ahead> {
        None
    }
    /// The control times up to `t` passed as [`Controller::ahead`] promised, unasked: the
    /// controller catches up to `t` as if it had been asked at each (a gear turned on to
    /// where the line says), so that the next ask moves it over one control step alone.
    fn passed(&mut self, _t: f64) {}
}

/// What [`Controller::ahead`] promises of the control times after the one just asked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ahead {
    /// The inputs go on along their line at the control times before this (∞: for ever).
    pub until: f64,
    /// While this state stays inside its bounds (none: whatever the states do).
    pub watch: Option<Watch>,
}

impl Ahead {
    /// For ever, whatever the states do.
    pub const ALWAYS: Ahead = Ahead { until: f64::INFINITY, watch: None };
}

/// A state the controller answers (a zigzag's heading): strictly inside (`low`, `high`) the
/// inputs go on as promised; at a bound the controller is asked again.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Watch {
    /// The state's index.
    pub state: usize,
    /// Lower bound (−∞: none).
    pub low: f64,
    /// Upper bound (∞: none).
    pub high: f64,
}

impl Watch {
    /// Whether `value` of the watched state keeps the promise.
    #[inline]
    pub fn holds(&self, value: f64) -> bool {
        value > self.low && value < self.high
    }
}

/// Fixed inputs.
#[derive(Clone, Debug)]
pub struct Constant(pub Vec<f64>);

impl Controller for Constant {
    fn input(&mut self, _t: f64, _x: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&self.0);
    }
    fn ahead(&self, _t: f64, slope: &mut [f64]) -> Option<Ahead> {
        slope.fill(0.0);
        Some(Ahead::ALWAYS)
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
