//! The standard manoeuvres, one file each, and their metrics. A manoeuvre is a controller
//! of the generic simulator plus a function from the simulated run to its metrics ([`Test`]).
//! Adding one is its file (the type, its metrics, `impl Test`), a `mod` line and one line of
//! the registry (`manoeuvres!` below), which makes the variants and the dispatch.

mod initial;
mod pullout;
mod replay;
mod spiral;
pub(crate) mod turning;
mod zigzag;

use serde::Serialize;

pub use initial::{InitialTurning, InitialTurningMetrics};
pub use pullout::{PullOut, PullOutMetrics};
pub use replay::{NoMetrics, Replayed};
pub use spiral::{Spiral, SpiralMetrics, SpiralPoint};
pub use turning::{TurningCircle, TurningMetrics};
pub use zigzag::{ZigZag, ZigZagMetrics};

use super::{Ship, ShipError, StraightRun};
use crate::sim::{Controller, Trajectory};

/// A number to a hundredth, without trailing zeros (20, 0.3, 35.01, 14.31): a zigzag read off a
/// record is laid to angles like 35.0017°, and IMO's overshoot limit at L/V = 18.6 s is 14.31°.
pub(crate) fn hundredths(v: f64) -> String {
    let s = format!("{v:.2}");
    match s.trim_end_matches('0').trim_end_matches('.') {
        "-0" => "0".into(),
        t => t.into(),
    }
}

/// A default time of a manoeuvre: `lengths` of the ship's own time scale `scale` (L/U0, s) in
/// whole seconds, and never less than `floor` seconds (the defaults at model scale). A ship at full scale
/// turns √λ times slower than its model: a 120 s hold of a spiral that settles a 7 m model
/// leaves a 320 m ship's yaw rate unsettled and draws a hysteresis loop it does not have.
pub fn scaled(floor: f64, lengths: f64, scale: f64) -> f64 {
    floor.max((lengths * scale).ceil())
}

/// What a manoeuvre is: parsed from its text, a label, a duration, the rudder it commands, a
/// controller of the simulator and metrics read off the run. Each manoeuvre's file implements
/// it; the registry below makes [`Manoeuvre`] and [`Metrics`] of them.
pub trait Test: Sized + Clone {
    /// Its metrics (serialised into reports and JSON).
    type Metrics: Serialize;
    /// From the text after `name:` (`20/20` of `zigzag:20/20`); `text` is all of it, for errors.
    fn parse(text: &str, rest: &str) -> Result<Self, ShipError>;
    /// A short label, e.g. `zigzag 20°/20° starboard`.
    fn label(&self) -> String;
    /// A sensible duration in seconds when none is given, for a ship whose time scale L/U0 is
    /// `scale` seconds (see [`scaled`]).
    fn default_duration(&self, scale: f64) -> f64;
    /// Itself with the times it leaves to the ship's time scale `scale` (L/U0, s) filled in,
    /// for its label.
    fn at_scale(&self, _scale: f64) -> Self {
        self.clone()
    }
    /// The largest rudder angle it commands, ° (none for a replay).
    fn largest_rudder_deg(&self) -> Option<f64>;
    /// The controller that drives the rudder from the straight run on.
    fn controller(&self, ship: &Ship, start: &StraightRun) -> Result<Box<dyn Controller>, ShipError>;
    /// Its metrics from the run at full step resolution.
    fn metrics(&self, ship: &Ship, run: &Trajectory) -> Self::Metrics;
}

/// Writes [`Manoeuvre`] (one variant per manoeuvre), [`Metrics`] (tagged `manoeuvre` in
/// JSON) and their dispatch from the registry's lines.
macro_rules! manoeuvres {
    ($( $(#[$doc:meta])* $variant:ident($test:ty) = $name:literal $(| $alias:literal)*, e.g. $example:literal; )+) => {
        /// A manoeuvre to simulate.
        #[derive(Clone, Debug)]
        pub enum Manoeuvre {
            $( $(#[$doc])* $variant($test), )+
        }

        /// Metrics of a manoeuvre, degrees and seconds, metres.
        #[derive(Clone, Debug, Serialize)]
        #[serde(tag = "manoeuvre", rename_all = "snake_case")]
        pub enum Metrics {
            $( $(#[$doc])* $variant(<$test as Test>::Metrics), )+
        }

        impl Manoeuvre {
            /// One example of every manoeuvre, in the registry's order (its name before `:`).
            pub const EXAMPLES: &'static [&'static str] = &[$($example),+];

            /// Parses a manoeuvre by its registry name: `zigzag:20/20`, `zigzag:20/10:port`,
            /// `turning:35`, `spiral`, `spiral:20/2/120` (max rudder °/step °/hold s),
            /// `pullout:20`, `replay:FILE.csv`, ….
            pub fn parse(text: &str) -> Result<Manoeuvre, ShipError> {
                let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
                match kind {
                    $( $name $(| $alias)* => Ok(Manoeuvre::$variant(<$test as Test>::parse(text, rest)?)), )+
                    _ => Err(ShipError::Manoeuvre {
                        text: text.into(),
                        message: format!("known manoeuvres: {}", Manoeuvre::EXAMPLES.join(", ")),
                    }),
                }
            }

            /// A short label, e.g. `zigzag 20°/20° starboard`.
            pub fn label(&self) -> String {
                match self {
                    $( Manoeuvre::$variant(m) => <$test as Test>::label(m), )+
                }
            }

            /// A sensible duration in seconds when none is given, for a ship whose time scale
            /// L/U0 is `scale` seconds ([`Ship::time_scale`]).
            pub fn default_duration(&self, scale: f64) -> f64 {
                match self {
                    $( Manoeuvre::$variant(m) => <$test as Test>::default_duration(m, scale), )+
                }
            }

            /// The manoeuvre with the times it leaves to the ship's time scale `scale` (L/U0,
            /// s) filled in: what its label then states.
            pub fn at_scale(&self, scale: f64) -> Manoeuvre {
                match self {
                    $( Manoeuvre::$variant(m) => Manoeuvre::$variant(<$test as Test>::at_scale(m, scale)), )+
                }
            }

            /// The largest rudder angle the manoeuvre commands, ° (none for a replay).
            pub fn largest_rudder_deg(&self) -> Option<f64> {
                match self {
                    $( Manoeuvre::$variant(m) => <$test as Test>::largest_rudder_deg(m), )+
                }
            }

            pub(crate) fn controller(&self, ship: &Ship, start: &StraightRun) -> Result<Box<dyn Controller>, ShipError> {
                match self {
                    $( Manoeuvre::$variant(m) => <$test as Test>::controller(m, ship, start), )+
                }
            }

            pub(crate) fn metrics(&self, ship: &Ship, run: &Trajectory) -> Metrics {
                match self {
                    $( Manoeuvre::$variant(m) => Metrics::$variant(<$test as Test>::metrics(m, ship, run)), )+
                }
            }
        }
    };
}

// The registry: one line per manoeuvre (variant, type, names, an example for the help).
manoeuvres! {
    /// Z-manoeuvre δ/ψ.
    ZigZag(ZigZag) = "zigzag" | "z", e.g. "zigzag:20/20";
    /// Turning circle at a fixed rudder angle.
    Turning(TurningCircle) = "turning" | "turn", e.g. "turning:35";
    /// Spiral test (Dieudonné), both directions.
    Spiral(Spiral) = "spiral", e.g. "spiral";
    /// Pull-out after a steady turn.
    PullOut(PullOut) = "pullout" | "pull-out", e.g. "pullout:20";
    /// Recorded inputs replayed.
    Replay(Replayed) = "replay", e.g. "replay:FILE.csv";
    /// IMO's initial turning test (10° rudder to 10° heading change).
    InitialTurning(InitialTurning) = "initial-turning", e.g. "initial-turning";
}

/// The steering gear: a rudder moving towards its command at a limited rate, within its limit;
/// a command takes effect `rudder_delay` after it is given, and with `rudder_acceleration` the
/// rate builds up from rest and falls to rest again at the command (a basin's gear does not
/// reach its full rate at once: the SIMMAN case study's HSVA records lag such a gear by 0.3 s).
#[derive(Clone, Debug)]
pub(crate) struct Servo {
    pub angle: f64,
    pub rate: f64,
    pub limit: f64,
    pub last_t: f64,
    /// Dead time, s.
    delay: f64,
    /// Angular acceleration, rad/s² (none: the full rate at once).
    acceleration: Option<f64>,
    /// The rudder's angular velocity now, rad/s (with an acceleration).
    speed: f64,
    /// Commands given and not yet in effect: (time given, command).
    given: std::collections::VecDeque<(f64, f64)>,
    /// The command in effect.
    command: f64,
}

impl Servo {
    pub fn new(ship: &Ship, start: &StraightRun) -> Servo {
        let angle = start.input[ship.roles.rudder];
        Servo {
            angle,
            rate: ship.spec.rudder_rate.to_radians(),
            limit: ship.spec.rudder_limit.to_radians(),
            last_t: 0.0,
            delay: ship.spec.rudder_delay,
            acceleration: ship.spec.rudder_acceleration.map(f64::to_radians),
            speed: 0.0,
            given: std::collections::VecDeque::new(),
            command: angle,
        }
    }

    /// Gives `command` at `t` and moves the rudder over the time since the last call.
    #[inline]
    pub fn step(&mut self, t: f64, command: f64) -> f64 {
        if self.delay > 0.0 {
            if self.given.back().map_or(self.command, |g| g.1) != command {
                self.given.push_back((t, command));
            }
            // in effect from `delay` after it was given, resolved to the control step
            while let Some(&(_, c)) = self.given.front().filter(|g| g.0 + self.delay <= t + 1e-9) {
                self.command = c;
                self.given.pop_front();
            }
        } else {
            self.command = command;
        }
        let target = self.command.clamp(-self.limit, self.limit);
        let dt = (t - self.last_t).max(0.0);
        self.last_t = t;
        match self.acceleration {
            None => {
                let max = self.rate * dt;
                self.angle += (target - self.angle).clamp(-max, max);
            }
            Some(a) => {
                let gap = target - self.angle;
                // the fastest speed from which the gear still stops at the command: v² = 2·a·|gap|
                let wanted = gap.signum() * self.rate.min((2.0 * a * gap.abs()).sqrt());
                self.speed += (wanted - self.speed).clamp(-a * dt, a * dt);
                let step = self.speed * dt;
                if gap == 0.0 || (gap - step) * gap <= 0.0 {
                    self.angle = target;
                    self.speed = 0.0;
                } else {
                    self.angle += step;
                }
            }
        }
        self.angle
    }

    /// The rudder's course after the last [`Servo::step`] while the command stays: its rate
    /// (rad/s) and the time before which it holds — until the rudder reaches its command (the
    /// step that would pass it stops there instead) or a command given takes effect. None where
    /// the gear accelerates: its angle is not a line in time then.
    pub fn ahead(&self) -> Option<(f64, f64)> {
        // a margin on the times: where the promise and the step disagree by a rounding, the
        // control time is asked instead
        let margin = 1e-9 * self.last_t.abs().max(1.0);
        let effect = self.given.front().map_or(f64::INFINITY, |g| g.0 + self.delay - 1e-9 - margin);
        let gap = self.command.clamp(-self.limit, self.limit) - self.angle;
        if gap == 0.0 {
            return (self.speed == 0.0).then_some((0.0, effect));
        }
        match self.acceleration {
            Some(_) => None,
            None => Some((self.rate.copysign(gap), effect.min(self.last_t + gap.abs() / self.rate - margin))),
        }
    }
}

fn parse_num(text: &str, part: &str, what: &str) -> Result<f64, ShipError> {
    part.trim().parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| ShipError::Manoeuvre {
        text: text.into(),
        message: format!("`{part}` is not a number ({what})"),
    })
}

impl Manoeuvre {
    /// Refuses a rudder angle beyond the ship's limit: the servo would clamp it, and the run
    /// would be labelled with an angle the rudder never reached.
    pub fn check(&self, ship: &Ship) -> Result<(), ShipError> {
        match self.largest_rudder_deg() {
            Some(d) if d > ship.spec.rudder_limit => Err(ShipError::Manoeuvre {
                text: self.label(),
                message: format!(
                    "rudder angle {d}° is beyond the ship's rudder limit of {}° (`rudder_limit` in [ship])",
                    ship.spec.rudder_limit
                ),
            }),
            _ => Ok(()),
        }
    }

    /// The manoeuvre's controller, for benchmarks and custom integration loops.
    pub fn controller_for_bench(
        &self,
        ship: &Ship,
        start: &StraightRun,
    ) -> Result<Box<dyn Controller>, ShipError> {
        self.controller(ship, start)
    }
}

#[cfg(test)]
mod tests {
    use super::Servo;

    /// A gear of 15°/s within ±35°, from 0°.
    fn gear(delay: f64, acceleration: Option<f64>) -> Servo {
        Servo {
            angle: 0.0,
            rate: 15f64.to_radians(),
            limit: 35f64.to_radians(),
            last_t: 0.0,
            delay,
            acceleration: acceleration.map(f64::to_radians),
            speed: 0.0,
            given: Default::default(),
            command: 0.0,
        }
    }

    /// The rudder angle, °, at each millisecond of `until` seconds under a 20° command given
    /// at t = 0.
    fn follow(mut servo: Servo, until: f64) -> Vec<f64> {
        (0..=(until * 1000.0).round() as usize)
            .map(|i| servo.step(i as f64 * 1e-3, 20f64.to_radians()).to_degrees())
            .collect()
    }

    #[test]
    fn the_gear_follows_its_command_late_and_at_its_rate() {
        // at once and at full rate: 15°/s from t = 0, there at 4/3 s
        let at_once = follow(gear(0.0, None), 2.0);
        assert!((at_once[500] - 7.5).abs() < 1e-9 && at_once[1400] == 20.0, "{}", at_once[500]);
        // a dead time of 0.3 s: nothing before it, then the same ramp 0.3 s later
        let late = follow(gear(0.3, None), 2.0);
        assert!(late[..300].iter().all(|a| *a == 0.0), "{}", late[299]);
        assert!((late[800] - 7.5).abs() < 0.02 && late[1700] == 20.0, "{} {}", late[800], late[1700]);
        // 30°/s²: the rate builds up over 0.5 s (3.75°), holds 15°/s and falls to rest at the
        // command over the last 3.75°; there after 20/15 + 15/30 = 11/6 s, never beyond it
        let built = follow(gear(0.0, Some(30.0)), 2.5);
        assert!((built[250] - 0.5 * 30.0 * 0.25 * 0.25).abs() < 0.02, "{}", built[250]);
        assert!((built[1000] - (3.75 + 15.0 * 0.5)).abs() < 0.05, "{}", built[1000]);
        assert!(
            (built[1700] - (20.0 - 0.5 * 30.0 * (11.0 / 6.0 - 1.7f64).powi(2))).abs() < 0.05,
            "{}",
            built[1700]
        );
        assert!(built.iter().all(|a| *a <= 20.0) && built[1860] == 20.0, "{}", built[1860]);
    }

    /// What the gear promises of the control times ahead holds: at each control time before
    /// `until` a stepped gear is where the line says, and a gear left alone until then and
    /// asked once ends where the one asked at every control time ends. Commands of ±20° and
    /// 0° given now and then, with and without a dead time.
    #[test]
    fn the_gears_promise_holds() {
        let dt = 0.04;
        for delay in [0.0, 0.3] {
            let command = |k: usize| [20f64, -20.0, 0.0, 35.0][(k / 150) % 4].to_radians();
            let mut asked = gear(delay, None);
            let mut promised = 0;
            for k in 0..1200 {
                let t = k as f64 * dt;
                let angle = asked.step(t, command(k));
                let Some((rate, until)) = asked.ahead() else { panic!("a gear without acceleration") };
                // the command stays for the control steps the test looks ahead (to its next change)
                let mut alone = asked.clone();
                for j in k + 1..(k / 150 + 1) * 150 {
                    let t_j = j as f64 * dt;
                    if t_j >= until {
                        break;
                    }
                    let mut stepped = asked.clone();
                    for i in k + 1..=j {
                        stepped.step(i as f64 * dt, command(k));
                    }
                    let line = angle + rate * (t_j - t);
                    assert!((stepped.angle - line).abs() < 1e-12, "delay {delay}, k {k}, j {j}");
                    // not asked until j: the same gear as asked at every control time
                    let once = alone.clone().step(t_j, command(k));
                    assert!((once - stepped.angle).abs() < 1e-12, "delay {delay}, k {k}, j {j}");
                    promised += 1;
                }
                alone.step(t + dt, command(k));
            }
            // most control steps lie in a promise (the gear at rest or turning)
            assert!(promised > 10_000, "{promised}");
        }
        // a gear that accelerates promises only at rest
        let mut built = gear(0.0, Some(30.0));
        built.step(0.04, 20f64.to_radians());
        assert!(built.ahead().is_none());
        for k in 2..200 {
            built.step(k as f64 * 0.04, 20f64.to_radians());
        }
        assert_eq!(built.ahead().map(|a| a.0), Some(0.0));
    }

    /// A manoeuvre simulated by the adaptive method whose controller promises the control
    /// times ahead (the steps pass them unasked) against the same controller asked at every
    /// control time: the same reversals and metrics, the states within the tolerances.
    #[test]
    fn unasked_control_times_change_nothing() {
        use crate::sim::{simulate, Controller, Integrator, Settings};
        struct Asked(Box<dyn Controller>);
        impl Controller for Asked {
            fn input(&mut self, t: f64, x: &[f64], out: &mut [f64]) {
                self.0.input(t, x, out)
            }
            fn done(&self, t: f64, x: &[f64]) -> bool {
                self.0.done(t, x)
            }
        }
        let model = super::super::default_model();
        for (delay, acceleration) in [(0.0, None), (0.3, None), (0.2, Some(8.0))] {
            let mut ship = super::Ship::new(&model, false).unwrap();
            ship.spec.rudder_delay = delay;
            ship.spec.rudder_acceleration = acceleration;
            let start = ship.straight_run().unwrap();
            for text in ["zigzag:20/20", "zigzag:10/10:port", "turning:35", "pullout:20", "spiral:10/5/40"] {
                let manoeuvre = super::Manoeuvre::parse(text).unwrap();
                let settings =
                    Settings { integrator: Integrator::Dopri5, dt: 0.04, duration: 150.0, sample: 0.2 };
                let free = manoeuvre.controller(&ship, &start).unwrap();
                let a = simulate(&ship.system, &start.x, &mut Asked(free), &settings).unwrap();
                let mut free = manoeuvre.controller(&ship, &start).unwrap();
                let b = simulate(&ship.system, &start.x, free.as_mut(), &settings).unwrap();
                assert_eq!(a.time, b.time, "{text}");
                assert_eq!(a.inputs.len(), b.inputs.len());
                for (ca, cb) in a.inputs.iter().zip(&b.inputs) {
                    for (x, y) in ca.iter().zip(cb) {
                        assert!((x - y).abs() < 1e-12, "{text} (delay {delay}): input {x} vs {y}");
                    }
                }
                for ((ca, cb), name) in a.states.iter().zip(&b.states).zip(&a.state_names) {
                    let scale = ca.iter().fold(1e-3f64, |m, v| m.max(v.abs()));
                    for (x, y) in ca.iter().zip(cb) {
                        assert!((x - y).abs() < 1e-5 * scale, "{text} (delay {delay}): {name} {x} vs {y}");
                    }
                }
            }
        }
    }
}
