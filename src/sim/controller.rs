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
    /// The inputs just before control time `t`, asked right after [`Controller::input`] for
    /// `t`, written into `out` where some jump at `t` (an input held between samples: its
    /// value up to the sample, which the step ending at `t` takes instead of the new one);
    /// false, the default, where none jumps (`out` left as it was).
    fn before(&mut self, _t: f64, _out: &mut [f64]) -> bool {
        false
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

/// Inputs replayed from a recorded time series: linearly interpolated between samples, or
/// held from each sample to the next where the frame says the input is ([`Frame::hold`]: a
/// step ending on a sample then takes the value before it, [`Controller::before`]); held at
/// the ends.
#[derive(Clone, Debug)]
pub struct Replay {
    time: Vec<f64>,
    columns: Vec<Vec<f64>>,
    held: Vec<bool>,
    cursor: usize,
    /// Where the last lookup of a held input's sample ended (apart from the line's cursor,
    /// which may stand one sample back).
    sample: usize,
    /// How close to a sample a time is on it, by the record's own times before the shift
    /// (their rounding far from zero is in the shifted ones too).
    close: f64,
}

impl Replay {
    /// Replays the named columns of a frame, in the order of the system's inputs. Time is
    /// counted from the frame's first sample, as a simulation counts it from its start (a
    /// record cut with a dataset's `from`, or logged from a clock that did not start at 0,
    /// was replayed shifted by its start time).
    pub fn new(frame: &Frame, inputs: &[String]) -> Result<Replay, DataError> {
        let columns =
            inputs.iter().map(|n| frame.require(n).map(<[f64]>::to_vec)).collect::<Result<_, _>>()?;
        let held = inputs.iter().map(|n| frame.is_held(n)).collect();
        let t0 = frame.time()[0];
        Ok(Replay {
            time: frame.time().iter().map(|t| t - t0).collect(),
            columns,
            held,
            cursor: 0,
            sample: 0,
            close: crate::data::on_sample(frame.time()),
        })
    }

    /// The recorded value of input `k` at time `t`.
    pub fn at(&mut self, k: usize, t: f64) -> f64 {
        if self.held[k] {
            let j = self.sample_at(t);
            return self.columns[k][j];
        }
        crate::data::interpolate_at(&self.time, &self.columns[k], t, &mut self.cursor)
    }

    /// The last sample at or before `t` ([`crate::data::sample_at`]).
    fn sample_at(&mut self, t: f64) -> usize {
        crate::data::sample_at(&self.time, t, self.close, &mut self.sample)
    }
}

impl Controller for Replay {
    fn input(&mut self, t: f64, _x: &[f64], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.at(k, t);
        }
    }

    fn before(&mut self, t: f64, out: &mut [f64]) -> bool {
        if !self.held.contains(&true) {
            return false;
        }
        let j = self.sample_at(t);
        if j == 0 || (self.time[j] - t).abs() > self.close {
            return false;
        }
        let mut jumped = false;
        for (k, o) in out.iter_mut().enumerate() {
            if self.held[k] {
                *o = self.columns[k][j - 1];
                jumped |= self.columns[k][j] != self.columns[k][j - 1];
            } else {
                *o = self.at(k, t);
            }
        }
        jumped
    }
}

/// A controller's inputs acting later than it gives them (a dead time per input, s, and a
/// first-order lag's time constant, s): asked at every control time as usual, it answers with
/// what `inner` gave `delay` before (between two control times a line from the one's value to
/// the other's value before any jump there; before the start, the first), passed through the
/// lag (ẏ = (u − y)/T, exact for that line between control times, at rest at the first value
/// at the start). A held input's jumps arrive whole, `delay` later; through a lag they do not
/// jump.
pub struct Delayed<'a> {
    inner: &'a mut dyn Controller,
    delays: Vec<f64>,
    lags: Vec<f64>,
    /// (control time, inputs given, inputs just before where they jumped there)
    history: Vec<(f64, Vec<f64>, Option<Vec<f64>>)>,
    /// The lags' outputs at the last control time (empty before the first).
    lagged: Vec<f64>,
    scratch: Vec<f64>,
}

impl<'a> Delayed<'a> {
    /// `inner`'s inputs, input k acting `delays[k]` seconds later through a first-order lag of
    /// `lags[k]` seconds (either list short or empty: 0 for the inputs it does not reach).
    pub fn new(inner: &'a mut dyn Controller, delays: &[f64], lags: &[f64]) -> Delayed<'a> {
        let m = delays.len().max(lags.len());
        let (delays, lags) = (Self::padded(delays, m), Self::padded(lags, m));
        Delayed { inner, delays, lags, history: Vec::new(), lagged: Vec::new(), scratch: vec![0.0; m] }
    }

    fn padded(values: &[f64], m: usize) -> Vec<f64> {
        (0..m).map(|k| values.get(k).copied().unwrap_or(0.0)).collect()
    }

    /// Input `k` at time `s` as given (`left`: just before `s`, where it jumped there).
    fn given(&self, k: usize, s: f64, left: bool) -> f64 {
        let h = &self.history;
        let close = 1e-9 * h.last().map_or(1.0, |e| e.0.abs().max(1.0));
        if s <= h[0].0 + close {
            return h[0].1[k];
        }
        // the last control time at or before s
        let i = h.partition_point(|e| e.0 <= s + close) - 1;
        let (t, value, before) = &h[i];
        if (t - s).abs() <= close {
            return if left { before.as_ref().unwrap_or(value)[k] } else { value[k] };
        }
        match h.get(i + 1) {
            Some((t1, v1, b1)) => {
                let end = b1.as_ref().unwrap_or(v1)[k];
                value[k] + (end - value[k]) * (s - t) / (t1 - t)
            }
            None => value[k],
        }
    }
}

impl Controller for Delayed<'_> {
    fn input(&mut self, t: f64, x: &[f64], out: &mut [f64]) {
        self.inner.input(t, x, out);
        let given = out.to_vec();
        let before = self.inner.before(t, &mut self.scratch).then(|| self.scratch.clone());
        if self.history.last().is_some_and(|e| e.0 >= t) {
            // asked again at an earlier or the same time (a new run): start over
            self.history.clear();
            self.lagged.clear();
        }
        self.history.push((t, given, before));
        let previous = (self.history.len() > 1).then(|| self.history[self.history.len() - 2].0);
        // what no delay reaches back to any more, dropped in batches (a long run's memory stays
        // at about twice the longest delay's control steps); the first value stays for the
        // times before the start
        // (from the last control time on: a lag reads the step since)
        let reach = previous.unwrap_or(t) - self.delays.iter().copied().fold(0.0, f64::max);
        let stale = self.history.partition_point(|e| e.0 < reach).saturating_sub(1);
        if stale > 1 && stale > self.history.len() / 2 {
            self.history.drain(1..stale);
        }
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.given(k, t - self.delays.get(k).copied().unwrap_or(0.0), false);
        }
        if self.lags.iter().all(|&l| l <= 0.0) {
            return;
        }
        match previous {
            // at rest at the first value
            None => self.lagged = out.to_vec(),
            Some(p) => {
                for (k, &lag) in self.lags.iter().enumerate().filter(|(_, l)| **l > 0.0) {
                    // the input over the step: a line from its value after the last control
                    // time to its value before this one (u = u₀ + b s: y₁ = u₁ − bT + (y₀ − u₀ + bT)
                    // e^(−h/T))
                    let d = self.delays[k];
                    let (u0, u1) = (self.given(k, p - d, false), self.given(k, t - d, true));
                    let h = t - p;
                    let bt = (u1 - u0) / h * lag;
                    self.lagged[k] = u1 - bt + (self.lagged[k] - u0 + bt) * (-h / lag).exp();
                }
            }
        }
        for (k, o) in out.iter_mut().enumerate() {
            if self.lags[k] > 0.0 {
                *o = self.lagged[k];
            }
        }
    }

    fn before(&mut self, t: f64, out: &mut [f64]) -> bool {
        let mut jumped = false;
        for (k, o) in out.iter_mut().enumerate() {
            if self.lags.get(k).is_some_and(|&l| l > 0.0) {
                // a lag's output does not jump
                *o = self.lagged[k];
                continue;
            }
            let s = t - self.delays.get(k).copied().unwrap_or(0.0);
            *o = self.given(k, s, true);
            jumped |= *o != self.given(k, s, false);
        }
        jumped
    }

    fn done(&self, t: f64, x: &[f64]) -> bool {
        self.inner.done(t, x)
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

    /// A held input replays its sample's value up to the next sample, and just before a
    /// sample where it jumps, the value before the jump; a linear one beside it is a line.
    #[test]
    fn a_held_input_steps_at_its_samples() {
        let mut f = Frame::new("rig.csv", "t", vec![0.0, 0.1, 0.2, 0.3]).unwrap();
        f.push("F", vec![1.0, 1.0, 4.0, 4.0]).unwrap();
        f.push("u", vec![0.0, 1.0, 2.0, 3.0]).unwrap();
        f.hold("F").unwrap();
        let mut r = Replay::new(&f, &["F".to_string(), "u".to_string()]).unwrap();
        let mut out = [0.0; 2];
        for (t, want) in [(0.0, [1.0, 0.0]), (0.15, [1.0, 1.5]), (0.2, [4.0, 2.0]), (0.25, [4.0, 2.5])] {
            r.input(t, &[], &mut out);
            assert_eq!(out, want, "t = {t}");
        }
        r.input(0.2, &[], &mut out);
        assert!(r.before(0.2 + 1e-12, &mut out));
        assert_eq!(out[0], 1.0);
        assert!((out[1] - 2.0).abs() < 1e-10, "{out:?}");
        assert!(!r.before(0.1, &mut out), "no jump at 0.1");
        assert!(!r.before(0.25, &mut out), "0.25 is no sample");
    }

    /// Delayed by 0.2 s (two control steps of 0.1): the held input's jump at 0.2 s arrives at
    /// 0.4 s whole (before it, the old value); the line delayed by 0.15 s is the line 0.15 s back
    /// (the first value before the start).
    #[test]
    fn a_delayed_controller_answers_with_what_was_given_before() {
        let t: Vec<f64> = (0..8).map(|k| 0.1 * k as f64).collect();
        let mut f = Frame::new("rig.csv", "t", t.clone()).unwrap();
        f.push("F", vec![1.0, 1.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0]).unwrap();
        f.push("u", t.iter().map(|t| 10.0 * t).collect()).unwrap();
        f.hold("F").unwrap();
        let mut replay = Replay::new(&f, &["F".to_string(), "u".to_string()]).unwrap();
        let mut late = Delayed::new(&mut replay, &[0.2, 0.15], &[]);
        let mut out = [0.0; 2];
        for (k, want) in [(0, [1.0, 0.0]), (1, [1.0, 0.0]), (2, [1.0, 0.5]), (3, [1.0, 1.5]), (4, [4.0, 2.5])]
        {
            let t = 0.1 * k as f64;
            late.input(t, &[], &mut out);
            assert_eq!(out[0], want[0], "t = {t}");
            assert!((out[1] - want[1]).abs() < 1e-9, "t = {t}: {out:?}");
            let jumped = late.before(t, &mut out);
            assert_eq!(jumped, k == 4, "t = {t}");
            if jumped {
                assert_eq!(out[0], 1.0);
            }
        }
    }

    /// A long run keeps only what the delay reaches back to: a ramp asked every 0.01 s for
    /// 100 s, delayed 0.2 s, is the ramp 0.2 s back throughout with under 50 control times kept.
    #[test]
    fn a_delayed_controller_forgets_what_no_delay_reaches() {
        struct Ramp;
        impl Controller for Ramp {
            fn input(&mut self, t: f64, _: &[f64], out: &mut [f64]) {
                out[0] = t;
            }
        }
        let mut ramp = Ramp;
        let mut late = Delayed::new(&mut ramp, &[0.2], &[]);
        let mut out = [0.0];
        for k in 0..10_000 {
            let t = 0.01 * k as f64;
            late.input(t, &[], &mut out);
            assert!((out[0] - (t - 0.2).max(0.0)).abs() < 1e-9, "t = {t}: {}", out[0]);
            assert!(late.history.len() < 50, "{} kept at t = {t}", late.history.len());
        }
    }

    /// Through a lag of 0.5 s: a unit step given at 0.1 s (held) reaches 1 − e^(−(t − 0.1)/0.5)
    /// at each control time; delayed by 0.2 s as well, 0.2 s later; a ramp 2t beside it,
    /// lagged 0.3 s, is 2(t − 0.3(1 − e^(−t/0.3))), exactly; none jumps.
    #[test]
    fn a_lagged_controller_answers_through_the_lag() {
        let t: Vec<f64> = (0..41).map(|k| 0.05 * k as f64).collect();
        let mut f = Frame::new("rig.csv", "t", t.clone()).unwrap();
        f.push("F", t.iter().map(|&t| if t >= 0.1 - 1e-12 { 1.0 } else { 0.0 }).collect()).unwrap();
        f.push("u", t.iter().map(|t| 2.0 * t).collect()).unwrap();
        f.hold("F").unwrap();
        for delay in [0.0, 0.2] {
            let mut replay = Replay::new(&f, &["F".to_string(), "u".to_string()]).unwrap();
            let mut late = Delayed::new(&mut replay, &[delay], &[0.5, 0.3]);
            let mut out = [0.0; 2];
            for k in 0..200 {
                let t = 0.01 * k as f64;
                late.input(t, &[], &mut out);
                let on = t - 0.1 - delay;
                let want = if on > 1e-9 { 1.0 - (-on / 0.5f64).exp() } else { 0.0 };
                assert!((out[0] - want).abs() < 1e-9, "t = {t}: {} for {want}", out[0]);
                let ramp = 2.0 * (t - 0.3 * (1.0 - (-t / 0.3f64).exp()));
                assert!((out[1] - ramp).abs() < 1e-9, "t = {t}: {} for {ramp}", out[1]);
                assert!(!late.before(t, &mut out), "t = {t}");
            }
        }
    }
}
