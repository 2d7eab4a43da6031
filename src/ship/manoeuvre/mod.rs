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

/// What a manoeuvre is: parsed from its text, a label, a duration, the rudder it commands, a
/// controller of the simulator and metrics read off the run. Each manoeuvre's file implements
/// it; the registry below makes [`Manoeuvre`] and [`Metrics`] of them.
pub trait Test: Sized {
    /// Its metrics (serialised into reports and JSON).
    type Metrics: Serialize;
    /// From the text after `name:` (`20/20` of `zigzag:20/20`); `text` is all of it, for errors.
    fn parse(text: &str, rest: &str) -> Result<Self, ShipError>;
    /// A short label, e.g. `zigzag 20°/20° starboard`.
    fn label(&self) -> String;
    /// A sensible duration in seconds when none is given.
    fn default_duration(&self) -> f64;
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

            /// A sensible duration in seconds when none is given.
            pub fn default_duration(&self) -> f64 {
                match self {
                    $( Manoeuvre::$variant(m) => <$test as Test>::default_duration(m), )+
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
