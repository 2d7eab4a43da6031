//! Pull-out (Burcher): a steady turn at a rudder angle, then the rudder back to the
//! straight-run angle δ0; a course-stable ship's yaw rate decays to zero, an unstable one's
//! to a residual rate.

use serde::Serialize;

use super::zigzag::RudderOnly;
use super::{Servo, Ship, ShipError, StraightRun};
use crate::sim::{Ahead, Controller, Trajectory};

/// A pull-out manoeuvre.
#[derive(Clone, Debug, PartialEq)]
pub struct PullOut {
    /// Rudder angle of the turn, degrees.
    pub rudder_deg: f64,
    /// Time in the turn before the rudder returns, s; `None`: long enough for the ship
    /// ([`PullOut::times`]).
    pub turn_s: Option<f64>,
    /// Time after the return, s; `None` as `turn_s`.
    pub after_s: Option<f64>,
}

impl Default for PullOut {
    fn default() -> Self {
        PullOut { rudder_deg: 20.0, turn_s: None, after_s: None }
    }
}

/// Pull-out metrics.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PullOutMetrics {
    /// Yaw rate when the rudder is returned, °/s.
    pub turning_yaw_rate_deg_s: f64,
    /// Yaw rate at the end of the run, °/s.
    pub residual_yaw_rate_deg_s: f64,
    /// Time for |r| to fall to 1/e of its turning value after the return, s.
    pub decay_time_s: Option<f64>,
}

pub struct PullOutControl {
    servo: Servo,
    turn: f64,
    back: f64,
    switch_at: f64,
}

impl Controller for PullOutControl {
    fn input(&mut self, t: f64, _x: &[f64], out: &mut [f64]) {
        let command = if t < self.switch_at { self.turn } else { self.back };
        out[0] = self.servo.step(t, command);
    }
    fn passed(&mut self, t: f64) {
        self.input(t, &[], &mut [0.0]);
    }
    /// The rudder's course, up to the return to its straight-run angle.
    fn ahead(&self, t: f64, slope: &mut [f64]) -> Option<Ahead> {
        let (rate, until) = self.servo.ahead()?;
        slope[0] = rate;
        let switch =
            if t < self.switch_at { self.switch_at - 1e-9 * self.switch_at.max(1.0) } else { f64::INFINITY };
        Some(Ahead { until: until.min(switch), watch: None })
    }
}

impl PullOut {
    /// The time in the turn and after the return, s, for a ship whose time scale L/U0 is
    /// `scale` s: as given, or 16 L/U each (at least 100 s), in which the turn steadies and
    /// the yaw rate decays.
    pub fn times(&self, scale: f64) -> (f64, f64) {
        let default = super::scaled(100.0, 16.0, scale);
        (self.turn_s.unwrap_or(default), self.after_s.unwrap_or(default))
    }

    pub(crate) fn controller(&self, ship: &Ship, start: &StraightRun) -> RudderOnly<PullOutControl> {
        RudderOnly::new(
            ship,
            start,
            PullOutControl {
                servo: Servo::new(ship, start),
                turn: self.rudder_deg.to_radians(),
                back: start.input[ship.roles.rudder],
                switch_at: self.times(ship.time_scale()).0,
            },
        )
    }

    /// Metrics from a run sampled at every step.
    pub fn metrics(&self, ship: &Ship, run: &Trajectory) -> PullOutMetrics {
        let r = &run.states[ship.roles.r];
        let (turn, _) = self.times(ship.time_scale());
        let i_sw = run.time.iter().position(|t| *t >= turn).unwrap_or(r.len() - 1);
        let r_turn = r[i_sw];
        let decay = r[i_sw..]
            .iter()
            .position(|v| v.abs() <= r_turn.abs() / std::f64::consts::E)
            .map(|k| run.time[i_sw + k] - run.time[i_sw]);
        PullOutMetrics {
            turning_yaw_rate_deg_s: r_turn.to_degrees(),
            residual_yaw_rate_deg_s: r[r.len() - 1].to_degrees(),
            decay_time_s: decay,
        }
    }
}

impl super::Test for PullOut {
    type Metrics = PullOutMetrics;

    /// `pullout:RUDDER`, e.g. `pullout:20`.
    fn parse(text: &str, rest: &str) -> Result<Self, ShipError> {
        Ok(PullOut { rudder_deg: super::parse_num(text, rest, "rudder angle")?, ..PullOut::default() })
    }

    fn label(&self) -> String {
        format!("pull-out from δ = {}°", self.rudder_deg)
    }

    fn default_duration(&self, scale: f64) -> f64 {
        let (turn, after) = self.times(scale);
        turn + after
    }

    fn at_scale(&self, scale: f64) -> Self {
        let (turn, after) = self.times(scale);
        PullOut { turn_s: Some(turn), after_s: Some(after), ..self.clone() }
    }

    fn largest_rudder_deg(&self) -> Option<f64> {
        Some(self.rudder_deg.abs())
    }

    fn controller(&self, ship: &Ship, start: &StraightRun) -> Result<Box<dyn Controller>, ShipError> {
        Ok(Box::new(PullOut::controller(self, ship, start)))
    }

    fn metrics(&self, ship: &Ship, run: &Trajectory) -> PullOutMetrics {
        PullOut::metrics(self, ship, run)
    }
}
