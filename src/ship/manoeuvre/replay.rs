//! Recorded inputs replayed (the paper's "modified" manoeuvres): the rudder history of a
//! run is fed to the model as it was, linearly interpolated; the run starts from the
//! recording's first state where the file has the state columns, else from the straight run.

use super::Ship;
use crate::data::Frame;
use crate::ship::ShipError;
use crate::sim::Replay;

/// A recorded run whose inputs are replayed.
#[derive(Clone, Debug)]
pub struct Replayed {
    /// The recording (time column `t`), boxed: a manoeuvre of any other kind is a few numbers.
    pub frame: Box<Frame>,
}

impl Replayed {
    /// Reads a recording.
    pub fn read(path: &str) -> Result<Replayed, ShipError> {
        Ok(Replayed { frame: Box::new(Frame::read(std::path::Path::new(path), "t")?) })
    }

    /// Length of the recording.
    pub fn duration(&self) -> f64 {
        let t = self.frame.time();
        t[t.len() - 1] - t[0]
    }

    pub(crate) fn controller(&self, ship: &Ship) -> Result<Replay, ShipError> {
        Ok(Replay::new(&self.frame, &ship.system.inputs)?)
    }
}

/// A replay has no metrics of its own (`validate` reads a recording's).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct NoMetrics;

impl super::Test for Replayed {
    type Metrics = NoMetrics;

    /// `replay:FILE.csv`.
    fn parse(text: &str, rest: &str) -> Result<Self, ShipError> {
        if rest.is_empty() {
            return Err(ShipError::Manoeuvre { text: text.into(), message: "write replay:FILE.csv".into() });
        }
        Replayed::read(rest)
    }

    fn label(&self) -> String {
        format!("replay of {}", self.frame.origin())
    }

    fn default_duration(&self, _scale: f64) -> f64 {
        self.duration()
    }

    fn largest_rudder_deg(&self) -> Option<f64> {
        None
    }

    fn controller(
        &self,
        ship: &Ship,
        _start: &super::StraightRun,
    ) -> Result<Box<dyn crate::sim::Controller>, ShipError> {
        Ok(Box::new(Replayed::controller(self, ship)?))
    }

    fn metrics(&self, _ship: &Ship, _run: &crate::sim::Trajectory) -> NoMetrics {
        NoMetrics
    }
}
