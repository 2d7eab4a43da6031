//! The standard manoeuvres, one file each, and their metrics. A manoeuvre is a controller
//! of the generic simulator plus a function from the simulated run to its metrics. Adding a
//! manoeuvre is one file, one variant and one line in [`Manoeuvre::parse`].

mod pullout;
mod replay;
mod spiral;
pub(crate) mod turning;
mod zigzag;

use serde::Serialize;

pub use pullout::{PullOut, PullOutMetrics};
pub use replay::Replayed;
pub use spiral::{Spiral, SpiralMetrics, SpiralPoint};
pub use turning::{TurningCircle, TurningMetrics};
pub use zigzag::{ZigZag, ZigZagMetrics};

use super::{Ship, ShipError, StraightRun};
use crate::sim::{Controller, Trajectory};

/// A manoeuvre to simulate.
#[derive(Clone, Debug)]
pub enum Manoeuvre {
    /// Z-manoeuvre δ/ψ.
    ZigZag(ZigZag),
    /// Turning circle at a fixed rudder angle.
    Turning(TurningCircle),
    /// Spiral test (Dieudonné), both directions.
    Spiral(Spiral),
    /// Pull-out after a steady turn.
    PullOut(PullOut),
    /// Recorded inputs replayed.
    Replay(Replayed),
}

/// Metrics of a manoeuvre, degrees and seconds, metres.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "manoeuvre", rename_all = "snake_case")]
pub enum Metrics {
    /// Zigzag.
    ZigZag(ZigZagMetrics),
    /// Turning circle.
    Turning(TurningMetrics),
    /// Spiral.
    Spiral(SpiralMetrics),
    /// Pull-out.
    PullOut(PullOutMetrics),
    /// Replay: none.
    Replay,
}

/// A rudder moving at a limited rate towards its command, within its limit.
#[derive(Clone, Debug)]
pub(crate) struct Servo {
    pub angle: f64,
    pub rate: f64,
    pub limit: f64,
    pub last_t: f64,
}

impl Servo {
    pub fn new(ship: &Ship, start: &StraightRun) -> Servo {
        Servo {
            angle: start.input[ship.roles.rudder],
            rate: ship.spec.rudder_rate.to_radians(),
            limit: ship.spec.rudder_limit.to_radians(),
            last_t: 0.0,
        }
    }

    /// Moves towards `command` over the time since the last call.
    #[inline]
    pub fn step(&mut self, t: f64, command: f64) -> f64 {
        let target = command.clamp(-self.limit, self.limit);
        let max = self.rate * (t - self.last_t).max(0.0);
        self.angle += (target - self.angle).clamp(-max, max);
        self.last_t = t;
        self.angle
    }
}

fn parse_num(text: &str, part: &str, what: &str) -> Result<f64, ShipError> {
    part.trim().parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| ShipError::Manoeuvre {
        text: text.into(),
        message: format!("`{part}` is not a number ({what})"),
    })
}

impl Manoeuvre {
    /// Parses `zigzag:20/20`, `zigzag:20/10:port`, `turning:35`, `spiral`,
    /// `spiral:20/2/120` (max rudder °/step °/hold s), `pullout:20`, `replay:FILE.csv`.
    pub fn parse(text: &str) -> Result<Manoeuvre, ShipError> {
        let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
        let bad = |m: &str| ShipError::Manoeuvre { text: text.into(), message: m.into() };
        match kind {
            "zigzag" | "z" => {
                let mut parts = rest.split(':');
                let angles = parts.next().unwrap_or("");
                let (d, p) = angles
                    .split_once('/')
                    .ok_or_else(|| bad("write zigzag:RUDDER/HEADING, e.g. zigzag:20/20"))?;
                let side = parts.next().unwrap_or("starboard");
                let starboard_first = match side {
                    "starboard" | "stb" | "s" => true,
                    "port" | "p" => false,
                    _ => return Err(bad("the side is `starboard` or `port`")),
                };
                let z = ZigZag {
                    rudder_deg: parse_num(text, d, "rudder angle")?,
                    heading_deg: parse_num(text, p, "heading change")?,
                    starboard_first,
                };
                if z.rudder_deg <= 0.0 || z.heading_deg <= 0.0 {
                    return Err(bad(
                        "rudder angle and heading change are positive; choose the side with `:port`",
                    ));
                }
                Ok(Manoeuvre::ZigZag(z))
            }
            "turning" | "turn" => {
                Ok(Manoeuvre::Turning(TurningCircle { rudder_deg: parse_num(text, rest, "rudder angle")? }))
            }
            "spiral" => {
                let mut s = Spiral::default();
                if !rest.is_empty() {
                    let v: Vec<&str> = rest.split('/').collect();
                    if v.len() != 3 {
                        return Err(bad("write spiral:MAX/STEP/HOLD, e.g. spiral:20/2/120"));
                    }
                    s.max_deg = parse_num(text, v[0], "largest rudder angle")?;
                    s.step_deg = parse_num(text, v[1], "rudder step")?;
                    s.hold_s = parse_num(text, v[2], "hold time")?;
                    if s.max_deg <= 0.0
                        || s.step_deg <= 0.0
                        || s.hold_s <= 0.0
                        || s.max_deg / s.step_deg > 200.0
                    {
                        return Err(bad(
                            "largest angle, step and hold must be positive, with at most 200 steps",
                        ));
                    }
                }
                Ok(Manoeuvre::Spiral(s))
            }
            "pullout" | "pull-out" => Ok(Manoeuvre::PullOut(PullOut {
                rudder_deg: parse_num(text, rest, "rudder angle")?,
                ..PullOut::default()
            })),
            "replay" => {
                if rest.is_empty() {
                    return Err(bad("write replay:FILE.csv"));
                }
                Ok(Manoeuvre::Replay(Replayed::read(rest)?))
            }
            _ => Err(bad("known manoeuvres: zigzag:20/20, turning:35, spiral, pullout:20, replay:FILE.csv")),
        }
    }

    /// A short label, e.g. `zigzag 20/20 starboard`.
    pub fn label(&self) -> String {
        match self {
            Manoeuvre::ZigZag(z) => format!(
                "zigzag {}°/{}° {}",
                z.rudder_deg,
                z.heading_deg,
                if z.starboard_first { "starboard" } else { "port" }
            ),
            Manoeuvre::Turning(t) => format!("turning circle δ = {}°", t.rudder_deg),
            Manoeuvre::Spiral(s) => {
                format!("spiral ±{}° in {}° steps, {} s each", s.max_deg, s.step_deg, s.hold_s)
            }
            Manoeuvre::PullOut(p) => format!("pull-out from δ = {}°", p.rudder_deg),
            Manoeuvre::Replay(r) => format!("replay of {}", r.frame.origin()),
        }
    }

    /// A sensible duration in seconds when none is given.
    pub fn default_duration(&self) -> f64 {
        match self {
            Manoeuvre::ZigZag(_) => 100.0,
            Manoeuvre::Turning(_) => 200.0,
            Manoeuvre::Spiral(s) => s.duration(),
            Manoeuvre::PullOut(p) => p.turn_s + p.after_s,
            Manoeuvre::Replay(r) => r.duration(),
        }
    }

    /// The largest rudder angle the manoeuvre commands, ° (none for a replay).
    pub fn largest_rudder_deg(&self) -> Option<f64> {
        match self {
            Manoeuvre::ZigZag(z) => Some(z.rudder_deg),
            Manoeuvre::Turning(t) => Some(t.rudder_deg.abs()),
            Manoeuvre::Spiral(s) => Some(s.max_deg),
            Manoeuvre::PullOut(p) => Some(p.rudder_deg.abs()),
            Manoeuvre::Replay(_) => None,
        }
    }

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

    pub(crate) fn controller(
        &self,
        ship: &Ship,
        start: &StraightRun,
    ) -> Result<Box<dyn Controller>, ShipError> {
        Ok(match self {
            Manoeuvre::ZigZag(z) => Box::new(z.controller(ship, start)),
            Manoeuvre::Turning(t) => Box::new(t.controller(ship, start)),
            Manoeuvre::Spiral(s) => Box::new(s.controller(ship, start)),
            Manoeuvre::PullOut(p) => Box::new(p.controller(ship, start)),
            Manoeuvre::Replay(r) => Box::new(r.controller(ship)?),
        })
    }

    pub(crate) fn metrics(&self, ship: &Ship, run: &Trajectory) -> Metrics {
        match self {
            Manoeuvre::ZigZag(z) => Metrics::ZigZag(z.metrics(ship, run)),
            Manoeuvre::Turning(t) => Metrics::Turning(t.metrics(ship, run)),
            Manoeuvre::Spiral(s) => Metrics::Spiral(s.metrics(ship, run)),
            Manoeuvre::PullOut(p) => Metrics::PullOut(p.metrics(ship, run)),
            Manoeuvre::Replay(_) => Metrics::Replay,
        }
    }
}
