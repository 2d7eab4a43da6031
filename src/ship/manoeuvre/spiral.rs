//! Spiral test (Dieudonné): the rudder is held at a sequence of angles from +max down to
//! −max and back up, each long enough for the yaw rate to settle; the steady yaw rate
//! against the rudder angle, on the way down and on the way back, shows a course-unstable
//! ship's hysteresis loop. Loop width: the distance between the rudder angles at which r
//! changes sign on the two branches.

use serde::Serialize;

use super::zigzag::RudderOnly;
use super::{Servo, Ship, ShipError, StraightRun};
use crate::sim::{Ahead, Controller, Trajectory};

/// A spiral test.
#[derive(Clone, Debug, PartialEq)]
pub struct Spiral {
    /// Largest rudder angle, degrees.
    pub max_deg: f64,
    /// Rudder step, degrees.
    pub step_deg: f64,
    /// Time at each angle, s; `None`: long enough for the ship ([`Spiral::hold`]).
    pub hold_s: Option<f64>,
}

impl Default for Spiral {
    fn default() -> Self {
        Spiral { max_deg: 20.0, step_deg: 2.0, hold_s: None }
    }
}

/// One point of the spiral curve.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SpiralPoint {
    /// Rudder angle, degrees.
    pub rudder_deg: f64,
    /// Steady yaw rate (mean over the last fifth of the hold), °/s.
    pub yaw_rate_deg_s: f64,
    /// `down` (from +max) or `up` (back from −max).
    pub branch: String,
}

/// Spiral metrics.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SpiralMetrics {
    /// r(δ) on both branches.
    pub points: Vec<SpiralPoint>,
    /// Width of the hysteresis loop, degrees (0 for a course-stable ship).
    pub loop_width_deg: Option<f64>,
    /// Largest change of r over the last fifth of any hold, °/s (settling check).
    pub unsettled_deg_s: f64,
}

impl Spiral {
    /// The rudder angles, in order.
    pub fn angles(&self) -> Vec<f64> {
        // whole steps up to the largest angle, never beyond it (30/20 holds 20° and 0°, not a
        // rounded-up 40° the rudder limit would clamp while the table printed it)
        let n = (self.max_deg / self.step_deg + 1e-9).floor() as i64;
        let down: Vec<f64> = (-n..=n).rev().map(|k| k as f64 * self.step_deg).collect();
        let up: Vec<f64> = down.iter().rev().skip(1).copied().collect();
        down.into_iter().chain(up).collect()
    }

    /// Time at each angle, s, for a ship whose time scale L/U0 is `scale` s: as given, or 20
    /// L/U (at least 120 s), in which a full-form hull's yaw rate settles.
    pub fn hold(&self, scale: f64) -> f64 {
        self.hold_s.unwrap_or_else(|| super::scaled(120.0, 20.0, scale))
    }

    /// Length of the whole test, s (the ship's time scale as for [`Spiral::hold`]).
    pub fn duration(&self, scale: f64) -> f64 {
        self.angles().len() as f64 * self.hold(scale)
    }

    pub(crate) fn controller(&self, ship: &Ship, start: &StraightRun) -> RudderOnly<SpiralControl> {
        RudderOnly::new(
            ship,
            start,
            SpiralControl {
                servo: Servo::new(ship, start),
                angles: self.angles().iter().map(|a| a.to_radians()).collect(),
                hold: self.hold(ship.time_scale()),
            },
        )
    }

    /// Metrics from a run sampled at every step.
    pub fn metrics(&self, ship: &Ship, run: &Trajectory) -> SpiralMetrics {
        let angles = self.angles();
        let half = angles.len() / 2 + 1;
        let r = &run.states[ship.roles.r];
        let mut points = Vec::new();
        let mut unsettled: f64 = 0.0;
        let hold = self.hold(ship.time_scale());
        for (k, a) in angles.iter().enumerate() {
            let (t0, t1) = (hold * (k as f64 + 0.8), hold * (k as f64 + 1.0));
            let window: Vec<f64> = run
                .time
                .iter()
                .zip(r)
                .filter(|(t, _)| **t >= t0 - 1e-9 && **t <= t1 + 1e-9)
                .map(|(_, r)| *r)
                .collect();
            if window.is_empty() {
                break;
            }
            let mean = window.iter().sum::<f64>() / window.len() as f64;
            let span = window.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v))
                - window.iter().fold(f64::INFINITY, |m, v| m.min(*v));
            unsettled = unsettled.max(span.to_degrees());
            points.push(SpiralPoint {
                rudder_deg: *a,
                yaw_rate_deg_s: mean.to_degrees(),
                branch: if k < half { "down".into() } else { "up".into() },
            });
        }
        let crossing = |branch: &str| -> Option<f64> {
            let p: Vec<&SpiralPoint> = points.iter().filter(|p| p.branch == branch).collect();
            p.windows(2).find(|w| w[0].yaw_rate_deg_s.signum() != w[1].yaw_rate_deg_s.signum()).map(|w| {
                let (a, b) = (w[0], w[1]);
                a.rudder_deg
                    + (b.rudder_deg - a.rudder_deg) * a.yaw_rate_deg_s / (a.yaw_rate_deg_s - b.yaw_rate_deg_s)
            })
        };
        let loop_width_deg = match (crossing("down"), crossing("up")) {
            (Some(d), Some(u)) => Some((d - u).abs()),
            _ => None,
        };
        SpiralMetrics { points, loop_width_deg, unsettled_deg_s: unsettled }
    }
}

pub struct SpiralControl {
    servo: Servo,
    angles: Vec<f64>,
    hold: f64,
}

impl Controller for SpiralControl {
    fn input(&mut self, t: f64, _x: &[f64], out: &mut [f64]) {
        let k = ((t / self.hold) as usize).min(self.angles.len() - 1);
        out[0] = self.servo.step(t, self.angles[k]);
    }
    fn passed(&mut self, t: f64) {
        self.input(t, &[], &mut [0.0]);
    }
    /// The rudder's course, up to the next angle of the spiral.
    fn ahead(&self, t: f64, slope: &mut [f64]) -> Option<Ahead> {
        let (rate, until) = self.servo.ahead()?;
        slope[0] = rate;
        let k = (t / self.hold) as usize;
        let next = if k + 1 < self.angles.len() {
            let at = (k + 1) as f64 * self.hold;
            at - 1e-9 * at.max(1.0)
        } else {
            f64::INFINITY
        };
        Some(Ahead { until: until.min(next), watch: None })
    }
}

impl super::Test for Spiral {
    type Metrics = SpiralMetrics;

    /// `spiral` or `spiral:MAX/STEP/HOLD` (largest rudder °, step °, hold s).
    fn parse(text: &str, rest: &str) -> Result<Self, ShipError> {
        let bad = |m: &str| ShipError::Manoeuvre { text: text.into(), message: m.into() };
        let mut s = Spiral::default();
        if !rest.is_empty() {
            let v: Vec<&str> = rest.split('/').collect();
            if v.len() != 3 {
                return Err(bad("write spiral:MAX/STEP/HOLD, e.g. spiral:20/2/120"));
            }
            s.max_deg = super::parse_num(text, v[0], "largest rudder angle")?;
            s.step_deg = super::parse_num(text, v[1], "rudder step")?;
            let hold = super::parse_num(text, v[2], "hold time")?;
            s.hold_s = Some(hold);
            if s.max_deg <= 0.0 || s.step_deg <= 0.0 || hold <= 0.0 || s.max_deg / s.step_deg > 200.0 {
                return Err(bad("largest angle, step and hold must be positive, with at most 200 steps"));
            }
            if s.step_deg > s.max_deg {
                return Err(bad(
                    "the rudder step is larger than the largest angle: the spiral would hold 0° only",
                ));
            }
        }
        Ok(s)
    }

    fn label(&self) -> String {
        let each = self.hold_s.map_or_else(|| "20 L/U (at least 120 s)".to_string(), |h| format!("{h} s"));
        format!("spiral ±{}° in {}° steps, {each} each", self.max_deg, self.step_deg)
    }

    fn default_duration(&self, scale: f64) -> f64 {
        self.duration(scale)
    }

    fn at_scale(&self, scale: f64) -> Self {
        Spiral { hold_s: Some(self.hold(scale)), ..self.clone() }
    }

    fn largest_rudder_deg(&self) -> Option<f64> {
        self.angles().into_iter().map(f64::abs).reduce(f64::max)
    }

    fn controller(&self, ship: &Ship, start: &StraightRun) -> Result<Box<dyn Controller>, ShipError> {
        Ok(Box::new(Spiral::controller(self, ship, start)))
    }

    fn metrics(&self, ship: &Ship, run: &Trajectory) -> SpiralMetrics {
        Spiral::metrics(self, ship, run)
    }
}
