//! Turning circle at a fixed rudder angle (absolute, in the model's convention; the paper's
//! were δ = 20° and δ = −35°). Advance and transfer at 90° change of heading, tactical
//! diameter at 180°, steady turning diameter 2U/|r| (eq. B10) at the end of the run.

use serde::Serialize;

use super::zigzag::RudderOnly;
use super::{Servo, Ship, ShipError, StraightRun};
use crate::sim::{Ahead, Controller, Trajectory};

/// A turning circle.
#[derive(Clone, Debug, PartialEq)]
pub struct TurningCircle {
    /// Rudder angle, degrees.
    pub rudder_deg: f64,
}

/// Turning-circle metrics (IMO MSC.137(76)); lengths in m and in ship lengths.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TurningMetrics {
    /// Distance along the initial course to the 90° heading change, m.
    pub advance_m: Option<f64>,
    /// Distance across the initial course at 90°, m.
    pub transfer_m: Option<f64>,
    /// Distance across the initial course at 180°, m.
    pub tactical_diameter_m: Option<f64>,
    /// 2U/|r| at the end of the run, m.
    pub steady_diameter_m: f64,
    /// Advance in ship lengths.
    pub advance_lpp: Option<f64>,
    /// Tactical diameter in ship lengths.
    pub tactical_diameter_lpp: Option<f64>,
    /// Steady speed over approach speed.
    pub speed_ratio: f64,
    /// 1 − speed ratio, percent.
    pub speed_loss_percent: f64,
    /// Steady drift angle β, degrees.
    pub drift_angle_deg: f64,
    /// Steady yaw rate, °/s.
    pub yaw_rate_deg_s: f64,
    /// Turn direction: `port` or `starboard`.
    pub direction: String,
}

pub struct TurnControl {
    servo: Servo,
    command: f64,
}

impl Controller for TurnControl {
    fn input(&mut self, t: f64, _x: &[f64], out: &mut [f64]) {
        out[0] = self.servo.step(t, self.command);
    }
    fn passed(&mut self, t: f64) {
        self.servo.step(t, self.command);
    }
    fn ahead(&self, _t: f64, slope: &mut [f64]) -> Option<Ahead> {
        let (rate, until) = self.servo.ahead()?;
        slope[0] = rate;
        Some(Ahead { until, watch: None })
    }
}

/// Linear interpolation of `y` where `x` first reaches `level` (x rising through it).
pub(crate) fn at_level(x: &[f64], y: &[f64], level: f64) -> Option<f64> {
    let i = x.iter().position(|v| *v >= level)?;
    if i == 0 {
        return Some(y[0]);
    }
    let w = (level - x[i - 1]) / (x[i] - x[i - 1]);
    Some(y[i - 1] + w * (y[i] - y[i - 1]))
}

impl TurningCircle {
    pub(crate) fn controller(&self, ship: &Ship, start: &StraightRun) -> RudderOnly<TurnControl> {
        RudderOnly::new(
            ship,
            start,
            TurnControl { servo: Servo::new(ship, start), command: self.rudder_deg.to_radians() },
        )
    }

    /// Metrics from a run sampled at every step.
    pub fn metrics(&self, ship: &Ship, run: &Trajectory) -> TurningMetrics {
        let r = &ship.roles;
        let psi = &run.states[r.psi];
        let n = run.time.len();
        let sign = if psi[n - 1] >= psi[0] { 1.0 } else { -1.0 };
        let turned: Vec<f64> = psi.iter().map(|p| sign * (p - psi[0]).to_degrees()).collect();
        let x: Vec<f64> = run.states[r.x0].iter().map(|v| v - run.states[r.x0][0]).collect();
        let y: Vec<f64> = run.states[r.y0].iter().map(|v| (v - run.states[r.y0][0]).abs()).collect();
        let (speed, drift) = ship.speed_and_drift(run);
        let (u_end, r_end) = (speed[n - 1], run.states[r.r][n - 1]);
        let lpp = ship.spec.lpp;
        let advance = at_level(&turned, &x, 90.0);
        let tactical = at_level(&turned, &y, 180.0);
        TurningMetrics {
            advance_m: advance,
            transfer_m: at_level(&turned, &y, 90.0),
            tactical_diameter_m: tactical,
            steady_diameter_m: 2.0 * u_end / r_end.abs(),
            advance_lpp: advance.map(|a| a / lpp),
            tactical_diameter_lpp: tactical.map(|d| d / lpp),
            speed_ratio: u_end / speed[0],
            speed_loss_percent: 100.0 * (1.0 - u_end / speed[0]),
            drift_angle_deg: drift[n - 1].to_degrees(),
            yaw_rate_deg_s: r_end.to_degrees(),
            direction: if sign > 0.0 { "starboard".into() } else { "port".into() },
        }
    }
}

impl super::Test for TurningCircle {
    type Metrics = TurningMetrics;

    /// `turning:RUDDER`, e.g. `turning:35` (negative: to the other side).
    fn parse(text: &str, rest: &str) -> Result<Self, ShipError> {
        Ok(TurningCircle { rudder_deg: super::parse_num(text, rest, "rudder angle")? })
    }

    fn label(&self) -> String {
        format!("turning circle δ = {}°", self.rudder_deg)
    }

    fn default_duration(&self, scale: f64) -> f64 {
        // a 35° circle completes its 180° within about 20 L/U
        super::scaled(200.0, 30.0, scale)
    }

    fn largest_rudder_deg(&self) -> Option<f64> {
        Some(self.rudder_deg.abs())
    }

    fn controller(&self, ship: &Ship, start: &StraightRun) -> Result<Box<dyn Controller>, ShipError> {
        Ok(Box::new(TurningCircle::controller(self, ship, start)))
    }

    fn metrics(&self, ship: &Ship, run: &Trajectory) -> TurningMetrics {
        TurningCircle::metrics(self, ship, run)
    }
}
