//! IMO's initial turning test (MSC.137(76) 5.3.2): from the straight approach the rudder goes
//! to δ (10°) and stays; measured is how far the ship has travelled, along its track, when the
//! heading has changed by ψ₁ (10°), in metres and ship lengths (the standard asks for at most
//! 2.5 L). Written as the example of a manoeuvre added in one file: the type, its metrics,
//! `impl Test` and one line of the registry in `mod.rs`.

use serde::Serialize;

use super::turning::{at_level, TurningCircle};
use super::{Ship, ShipError, StraightRun};
use crate::sim::{Controller, Trajectory};

/// The initial turning test: rudder δ held until the heading has changed by ψ₁.
#[derive(Clone, Debug, PartialEq)]
pub struct InitialTurning {
    /// Rudder angle, degrees (sign: side, in the model's convention).
    pub rudder_deg: f64,
    /// Heading change at which the reach is read, degrees.
    pub heading_deg: f64,
}

/// Initial-turning metrics.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct InitialTurningMetrics {
    /// Time from rudder execute to the heading change, s.
    pub time_s: Option<f64>,
    /// Distance travelled along the track by then, m.
    pub track_reach_m: Option<f64>,
    /// The same in ship lengths (IMO: at most 2.5).
    pub track_reach_lpp: Option<f64>,
    /// Distance along the initial course by then, m.
    pub advance_m: Option<f64>,
}

impl super::Test for InitialTurning {
    type Metrics = InitialTurningMetrics;

    /// `initial-turning` (10°/10°) or `initial-turning:RUDDER/HEADING`.
    fn parse(text: &str, rest: &str) -> Result<Self, ShipError> {
        if rest.is_empty() {
            return Ok(InitialTurning { rudder_deg: 10.0, heading_deg: 10.0 });
        }
        let (d, p) = rest.split_once('/').ok_or_else(|| ShipError::Manoeuvre {
            text: text.into(),
            message: "write initial-turning:RUDDER/HEADING, e.g. initial-turning:10/10".into(),
        })?;
        let m = InitialTurning {
            rudder_deg: super::parse_num(text, d, "rudder angle")?,
            heading_deg: super::parse_num(text, p, "heading change")?,
        };
        if m.rudder_deg == 0.0 || m.heading_deg <= 0.0 {
            return Err(ShipError::Manoeuvre {
                text: text.into(),
                message: "the rudder angle is not 0 and the heading change is positive".into(),
            });
        }
        Ok(m)
    }

    fn label(&self) -> String {
        format!("initial turning δ = {}° to Δψ = {}°", self.rudder_deg, self.heading_deg)
    }

    fn default_duration(&self, scale: f64) -> f64 {
        super::scaled(100.0, 16.0, scale)
    }

    fn largest_rudder_deg(&self) -> Option<f64> {
        Some(self.rudder_deg.abs())
    }

    fn controller(&self, ship: &Ship, start: &StraightRun) -> Result<Box<dyn Controller>, ShipError> {
        // the rudder of a turning circle; only the metrics differ
        Ok(Box::new(TurningCircle { rudder_deg: self.rudder_deg }.controller(ship, start)))
    }

    fn metrics(&self, ship: &Ship, run: &Trajectory) -> InitialTurningMetrics {
        let r = &ship.roles;
        let psi = &run.states[r.psi];
        let n = run.time.len();
        let sign = if psi[n - 1] >= psi[0] { 1.0 } else { -1.0 };
        let turned: Vec<f64> = psi.iter().map(|p| sign * (p - psi[0]).to_degrees()).collect();
        let (x, y) = (&run.states[r.x0], &run.states[r.y0]);
        let mut reach = vec![0.0; n];
        for k in 1..n {
            reach[k] = reach[k - 1] + (x[k] - x[k - 1]).hypot(y[k] - y[k - 1]);
        }
        let along: Vec<f64> = x.iter().map(|v| v - x[0]).collect();
        let track_reach = at_level(&turned, &reach, self.heading_deg);
        InitialTurningMetrics {
            time_s: at_level(&turned, &run.time, self.heading_deg).map(|t| t - run.time[0]),
            track_reach_m: track_reach,
            track_reach_lpp: track_reach.map(|d| d / ship.spec.lpp),
            advance_m: at_level(&turned, &along, self.heading_deg),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Manoeuvre, Metrics};
    use crate::sim::{Integrator, Settings};

    /// On the default ship: a 10° heading change takes a few seconds and well under the 2.5
    /// ship lengths IMO allows; the track reach exceeds the advance along the initial course
    /// only slightly (the heading changed by 10°: at most by 1/cos 10° − 1 ≈ 1.5 %).
    #[test]
    fn reach_at_ten_degrees_on_the_default_ship() {
        let ship = crate::ship::Ship::new(&crate::ship::default_model(), false).unwrap();
        let m = Manoeuvre::parse("initial-turning").unwrap();
        let settings = Settings { integrator: Integrator::Rk4, dt: 0.02, duration: 30.0, sample: 0.02 };
        let run = ship.run(&m, &settings).unwrap();
        let Metrics::InitialTurning(it) = run.metrics else { panic!("initial turning metrics") };
        let (reach, advance) = (it.track_reach_m.unwrap(), it.advance_m.unwrap());
        assert!(it.time_s.unwrap() > 0.5 && it.time_s.unwrap() < 20.0, "{it:?}");
        assert!(reach >= advance && reach <= advance * 1.016, "{it:?}");
        assert!((it.track_reach_lpp.unwrap() - reach / 4.572).abs() < 1e-12);
        assert!(it.track_reach_lpp.unwrap() < 2.5, "{it:?}");
        assert!(Manoeuvre::parse("initial-turning:10").is_err());
        assert!(Manoeuvre::parse("initial-turning:0/10").is_err());
    }
}
