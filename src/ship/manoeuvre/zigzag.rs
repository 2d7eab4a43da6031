//! Zigzag (Z-manoeuvre) δ/ψ: the rudder is laid to δ0 ∓ δ_z (relative to the straight-run
//! angle δ0, Oltmann 1973 §5), or to ∓δ_z on the rudder's own scale as a basin lays it by its
//! indicator (`:absolute`), and reversed each time the heading change from the initial
//! heading reaches ±ψ_z. Overshoot is the heading beyond the switching heading (not beyond
//! the rudder angle; for a 20°/10° zigzag those differ), IMO MSC.137(76).

use serde::Serialize;

use super::{Servo, Ship, ShipError, StraightRun};
use crate::sim::{Ahead, Controller, Trajectory, Watch};

/// A zigzag manoeuvre.
#[derive(Clone, Debug, PartialEq)]
pub struct ZigZag {
    /// Rudder angle δ_z, degrees (relative to δ0, or to `about_deg`).
    pub rudder_deg: f64,
    /// Heading change ψ_z at which the rudder is reversed, degrees.
    pub heading_deg: f64,
    /// First turn to starboard (ψ increasing), else to port.
    pub starboard_first: bool,
    /// The angle, degrees, the rudder is laid ±δ_z about, where not about the straight-run
    /// angle δ0: 0 (`:absolute`) as the basins' records show it laid by the indicator, or a
    /// record's own. A model whose straight run needs δ0 ≠ 0 is then turned by δ_z + |δ0| to
    /// one side and δ_z − |δ0| to the other, as a basin's ship is whose neutral rudder angle is
    /// not its indicator's zero.
    pub about_deg: Option<f64>,
}

/// Zigzag metrics (IMO MSC.137(76), ITTC 7.5-04-02-01).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ZigZagMetrics {
    /// Time from rudder execute to the first rudder reversal, s.
    pub initial_turning_time_s: Option<f64>,
    /// First overshoot angle, degrees.
    pub first_overshoot_deg: Option<f64>,
    /// Second overshoot angle, degrees.
    pub second_overshoot_deg: Option<f64>,
    /// Time between the first and third rudder reversals (one full cycle), s.
    pub period_s: Option<f64>,
    /// Times of the rudder reversals, s.
    pub reversals_s: Vec<f64>,
}

/// Reversal logic shared by the controller and the metrics.
#[derive(Clone, Debug)]
struct Switch {
    dir: f64,
    limit: f64,
}

impl Switch {
    /// Updates the direction from the heading change `h`; true when it reversed.
    #[inline]
    fn update(&mut self, h: f64) -> bool {
        if (self.dir > 0.0 && h >= self.limit) || (self.dir < 0.0 && h <= -self.limit) {
            self.dir = -self.dir;
            true
        } else {
            false
        }
    }
}

/// The zigzag controller.
pub struct ZigZagControl {
    servo: Servo,
    switch: Switch,
    delta0: f64,
    amplitude: f64,
    turn_sign: f64,
    psi: usize,
    psi0: f64,
}

impl ZigZagControl {
    /// The rudder for a turn in the switch's direction (+ = starboard): sign from ∂ṙ/∂δ.
    fn command(&self) -> f64 {
        self.delta0 + self.turn_sign * self.switch.dir * self.amplitude
    }
}

impl Controller for ZigZagControl {
    #[inline]
    fn input(&mut self, t: f64, x: &[f64], out: &mut [f64]) {
        self.switch.update(x[self.psi] - self.psi0);
        out[0] = self.servo.step(t, self.command());
    }

    fn passed(&mut self, t: f64) {
        self.servo.step(t, self.command());
    }

    /// The rudder's course until it reaches its command, while the heading change stays short
    /// of the switching heading in the turn's direction.
    fn ahead(&self, _t: f64, slope: &mut [f64]) -> Option<Ahead> {
        let (rate, until) = self.servo.ahead()?;
        slope[0] = rate;
        let limit = self.psi0 + self.switch.dir * self.switch.limit;
        // short of it by a rounding's margin: `update` compares ψ − ψ0 with the limit
        let limit = limit - self.switch.dir * 1e-12 * (limit.abs() + 1.0);
        let (low, high) =
            if self.switch.dir > 0.0 { (f64::NEG_INFINITY, limit) } else { (limit, f64::INFINITY) };
        Some(Ahead { until, watch: Some(Watch { state: self.psi, low, high }) })
    }
}

impl ZigZag {
    fn dir0(&self) -> f64 {
        if self.starboard_first {
            1.0
        } else {
            -1.0
        }
    }

    pub(crate) fn controller(&self, ship: &Ship, start: &StraightRun) -> RudderOnly<ZigZagControl> {
        RudderOnly::new(
            ship,
            start,
            ZigZagControl {
                servo: Servo::new(ship, start),
                switch: Switch { dir: self.dir0(), limit: self.heading_deg.to_radians() },
                delta0: self.about_deg.map_or(start.input[ship.roles.rudder], f64::to_radians),
                amplitude: self.rudder_deg.to_radians(),
                turn_sign: ship.turn_sign,
                psi: ship.roles.psi,
                psi0: start.x[ship.roles.psi],
            },
        )
    }

    /// Metrics from a run sampled at every step.
    pub fn metrics(&self, ship: &Ship, run: &Trajectory) -> ZigZagMetrics {
        let psi = &run.states[ship.roles.psi];
        let h: Vec<f64> = psi.iter().map(|p| (p - psi[0]).to_degrees()).collect();
        let mut sw = Switch { dir: self.dir0(), limit: self.heading_deg };
        let mut idx = Vec::new();
        for (i, &hi) in h.iter().enumerate() {
            if sw.update(hi) {
                idx.push(i);
            }
        }
        let t = &run.time;
        let d0 = self.dir0();
        // heading beyond the switching heading between reversal k and k+1, in the turn's direction
        let overshoot = |k: usize| -> Option<f64> {
            let (a, b) = (*idx.get(k)?, *idx.get(k + 1)?);
            let dir = if k.is_multiple_of(2) { d0 } else { -d0 };
            let extreme = h[a..=b].iter().map(|v| v * dir).fold(f64::NEG_INFINITY, f64::max);
            Some(extreme - self.heading_deg)
        };
        ZigZagMetrics {
            initial_turning_time_s: idx.first().map(|&i| t[i]),
            first_overshoot_deg: overshoot(0),
            second_overshoot_deg: overshoot(1),
            period_s: idx.get(2).map(|&i| t[i] - t[idx[0]]),
            reversals_s: idx.iter().map(|&i| t[i]).collect(),
        }
    }
}

/// Wraps a rudder controller: the rudder goes to the rudder input, every other input keeps
/// its straight-run value.
pub struct RudderOnly<C> {
    inner: C,
    rudder: usize,
    base: Vec<f64>,
}

impl<C: Controller> RudderOnly<C> {
    pub(crate) fn new(ship: &Ship, start: &StraightRun, inner: C) -> Self {
        RudderOnly { inner, rudder: ship.roles.rudder, base: start.input.clone() }
    }
}

impl<C: Controller> Controller for RudderOnly<C> {
    fn input(&mut self, t: f64, x: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&self.base);
        let mut r = [0.0];
        self.inner.input(t, x, &mut r);
        out[self.rudder] = r[0];
    }
    fn done(&self, t: f64, x: &[f64]) -> bool {
        self.inner.done(t, x)
    }
    fn passed(&mut self, t: f64) {
        self.inner.passed(t)
    }
    fn ahead(&self, t: f64, slope: &mut [f64]) -> Option<Ahead> {
        let mut rudder = [0.0];
        let ahead = self.inner.ahead(t, &mut rudder)?;
        slope.fill(0.0);
        slope[self.rudder] = rudder[0];
        Some(ahead)
    }
}

impl super::Test for ZigZag {
    type Metrics = ZigZagMetrics;

    /// `zigzag:RUDDER/HEADING[:port][:absolute]`, e.g. `zigzag:20/20`, `zigzag:20/10:port`,
    /// `zigzag:10/10:port:absolute`.
    fn parse(text: &str, rest: &str) -> Result<Self, ShipError> {
        let bad = |m: &str| ShipError::Manoeuvre { text: text.into(), message: m.into() };
        let mut parts = rest.split(':');
        let angles = parts.next().unwrap_or("");
        let (d, p) =
            angles.split_once('/').ok_or_else(|| bad("write zigzag:RUDDER/HEADING, e.g. zigzag:20/20"))?;
        let (mut side, mut about_deg) = (None, None);
        for part in parts {
            match part {
                "starboard" | "stb" | "s" if side.is_none() => side = Some(true),
                "port" | "p" if side.is_none() => side = Some(false),
                "absolute" if about_deg.is_none() => about_deg = Some(0.0),
                _ => {
                    return Err(bad(
                        "after the angles: the side (`starboard` or `port`) and `absolute` (the rudder about 0, not about the straight run's δ0), each once",
                    ))
                }
            }
        }
        let z = ZigZag {
            rudder_deg: super::parse_num(text, d, "rudder angle")?,
            heading_deg: super::parse_num(text, p, "heading change")?,
            starboard_first: side.unwrap_or(true),
            about_deg,
        };
        if z.rudder_deg <= 0.0 || z.heading_deg <= 0.0 {
            return Err(bad("rudder angle and heading change are positive; choose the side with `:port`"));
        }
        Ok(z)
    }

    fn label(&self) -> String {
        format!(
            "zigzag {}°/{}° {}{}",
            super::hundredths(self.rudder_deg),
            super::hundredths(self.heading_deg),
            if self.starboard_first { "starboard" } else { "port" },
            match self.about_deg {
                Some(0.0) => ", rudder about 0".to_string(),
                Some(a) => format!(", rudder about {}°", super::hundredths(a)),
                None => String::new(),
            }
        )
    }

    fn default_duration(&self, scale: f64) -> f64 {
        super::scaled(100.0, 16.0, scale)
    }

    fn largest_rudder_deg(&self) -> Option<f64> {
        Some(self.rudder_deg)
    }

    fn controller(&self, ship: &Ship, start: &StraightRun) -> Result<Box<dyn Controller>, ShipError> {
        Ok(Box::new(ZigZag::controller(self, ship, start)))
    }

    fn metrics(&self, ship: &Ship, run: &Trajectory) -> ZigZagMetrics {
        ZigZag::metrics(self, ship, run)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Manoeuvre, Metrics};
    use crate::sim::{Integrator, Settings};

    /// The default ship holds a straight course at δ0 = −0.8° (Oltmann's model is not
    /// symmetric), and a negative rudder turns it to starboard. About δ0 the rudder goes to
    /// δ0 ± 20°; laid absolute, to ±20° exactly, which is 19.2° from its neutral to starboard
    /// and 20.8° to port: the first overshoot of a zigzag to starboard shrinks and one to
    /// port grows.
    #[test]
    fn an_absolute_zigzag_lays_the_rudder_about_zero() {
        let ship = crate::ship::Ship::new(&crate::ship::default_model(), false).unwrap();
        let settings = Settings { integrator: Integrator::Rk4, dt: 0.04, duration: 60.0, sample: 0.04 };
        let run = |spec: &str| {
            let run = ship.run(&Manoeuvre::parse(spec).unwrap(), &settings).unwrap();
            let rudder =
                run.trajectory.input("δ").unwrap().iter().map(|d| d.to_degrees()).collect::<Vec<_>>();
            let (lo, hi) = rudder.iter().fold((f64::MAX, f64::MIN), |(lo, hi), d| (lo.min(*d), hi.max(*d)));
            let Metrics::ZigZag(z) = run.metrics else { panic!("zigzag metrics") };
            (lo, hi, z.first_overshoot_deg.unwrap())
        };
        let delta0 = ship.straight_run().unwrap().input[ship.roles.rudder].to_degrees();
        assert!((delta0 + 0.8).abs() < 0.05 && ship.turn_sign < 0.0, "δ0 = {delta0}");
        let (lo, hi, about_neutral) = run("zigzag:20/20");
        assert!((lo - (delta0 - 20.0)).abs() < 1e-9 && (hi - (delta0 + 20.0)).abs() < 1e-9, "{lo} {hi}");
        let (lo, hi, absolute) = run("zigzag:20/20:absolute");
        assert!((lo + 20.0).abs() < 1e-9 && (hi - 20.0).abs() < 1e-9, "{lo} {hi}");
        assert!(absolute < about_neutral, "to starboard: {absolute} ≥ {about_neutral}");
        let (_, _, about_neutral) = run("zigzag:20/20:port");
        let (_, _, absolute) = run("zigzag:20/20:absolute:port");
        assert!(absolute > about_neutral, "to port: {absolute} ≤ {about_neutral}");
        for bad in ["zigzag:20/20:port:port", "zigzag:20/20:absolute:absolute", "zigzag:20/20:sideways"] {
            assert!(Manoeuvre::parse(bad).is_err(), "{bad}");
        }
        assert!(Manoeuvre::parse("zigzag:20/20:port:absolute").unwrap().label().ends_with("rudder about 0"));
    }
}
