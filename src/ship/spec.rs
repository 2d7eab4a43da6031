//! The `[ship]` table of a model file: the particulars and role names the manoeuvring
//! plug-in reads. The core keeps the table as data (`ModelFile::plugins`); this module owns
//! its schema, its checks and the default ship.

use serde::{Deserialize, Serialize};

use super::ShipError;
use crate::model::{line_of_key, Model, ModelError};

/// The model-file table this plug-in owns.
pub const TABLE: &str = "ship";

/// The default model: HSVA model 1512 as identified by Oltmann (1973), true coefficients.
pub const DEFAULT_MODEL: &str = include_str!("../../models/oltmann1973.toml");
/// The name the default model reports as its file.
pub const DEFAULT_MODEL_PATH: &str = "models/oltmann1973.toml";

/// The default model (embedded in the binary).
pub fn default_model() -> Model {
    Model::parse(DEFAULT_MODEL, DEFAULT_MODEL_PATH).expect("the embedded default model is valid (tested)")
}

/// `[ship]`: particulars for the manoeuvring plug-in. Lengths in m, angles in degrees.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShipSpec {
    /// Length between perpendiculars, m.
    pub lpp: f64,
    /// Beam, m.
    #[serde(default)]
    pub beam: f64,
    /// Draught, m.
    #[serde(default)]
    pub draught: f64,
    /// Displacement volume, m³.
    #[serde(default)]
    pub displacement: f64,
    /// Rudder rate, °/s.
    pub rudder_rate: f64,
    /// Largest rudder angle, °.
    pub rudder_limit: f64,
    /// The steering gear's dead time, s: a rudder command takes effect this long after it is
    /// given (0: at once).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub rudder_delay: f64,
    /// The steering gear's angular acceleration, °/s²: the rudder's rate builds up to
    /// `rudder_rate` and falls to rest at its command at this (none: the full rate at once).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rudder_acceleration: Option<f64>,
    /// Approach speed, m/s.
    pub u0: f64,
    /// Water density, kg/m³ (nondimensional coefficients; 1000 when not given, a basin's fresh
    /// water).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// Length of the full-scale ship a model represents, m (IMO's time-based criteria then
    /// use its Froude-scaled L/V).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub full_scale_lpp: Option<f64>,
    /// State names the plug-in reads (defaults: u, v, r, ψ, x0, y0) and the rudder input (δ).
    #[serde(default)]
    pub names: ShipNames,
}

/// Which model names play the ship's roles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ShipNames {
    /// Surge velocity.
    pub u: String,
    /// Sway velocity.
    pub v: String,
    /// Yaw rate.
    pub r: String,
    /// Heading.
    pub psi: String,
    /// North (initial course) position.
    pub x0: String,
    /// East position.
    pub y0: String,
    /// Rudder angle.
    pub rudder: String,
    /// The propeller's rate of revolution, where the model has it as an input: the straight
    /// run then solves it for u̇ = 0 at u0 (the self-propulsion point), as a basin sets it
    /// for each run's approach speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub propeller: Option<String>,
}

impl Default for ShipNames {
    fn default() -> Self {
        ShipNames {
            u: "u".into(),
            v: "v".into(),
            r: "r".into(),
            psi: "ψ".into(),
            x0: "x0".into(),
            y0: "y0".into(),
            rudder: "δ".into(),
            propeller: None,
        }
    }
}

/// A rudder's largest angle each way, ° (what a ship's model file and particulars may give),
/// and why: beyond these no rudder works, and the servo's arithmetic loses its meaning.
pub const RUDDER_LIMIT: (std::ops::RangeInclusive<f64>, &str) =
    (0.1..=90.0, "a rudder turns at most 90° each way (35° is usual)");

/// A rudder's rate, °/s, and why (as [`RUDDER_LIMIT`]).
pub const RUDDER_RATE: (std::ops::RangeInclusive<f64>, &str) =
    (0.01..=1000.0, "a rudder's rate lies between 0.01 and 1000 °/s (2.3 °/s at full scale is usual)");

impl ShipSpec {
    /// The model's `[ship]` table, as written (`None`: not a ship model).
    pub fn of(model: &Model) -> Result<Option<ShipSpec>, ShipError> {
        let Some(table) = model.spec().plugins.get(TABLE) else { return Ok(None) };
        let spec = ShipSpec::deserialize(table.clone())
            .map_err(|e| ShipError::Model(format!("{}: [{TABLE}]: {}", model.path, e.message())))?;
        Ok(Some(spec))
    }

    /// Writes these particulars back into the model's `[ship]` table.
    pub fn store(&self, model: &mut Model) {
        if let Ok(value) = toml::Value::try_from(self) {
            model.set_plugin_table(TABLE, value);
        }
    }

    /// Where a state's bounds leave no room for the ship's own manoeuvres at `u0`: the key
    /// (`states[1].min`) and why. Bounds stop a run as diverging; a template's model-scale
    /// bounds, copied for a ship at full scale (or an approach speed given on the command
    /// line), stop every run at once or a sound turn halfway.
    pub fn bounds_without_room(&self, model: &Model) -> Option<(String, String)> {
        let (n, u0, lpp) = (&self.names, self.u0, self.lpp);
        let room = [
            ("surge speed", &n.u, 0.1 * u0, 1.2 * u0, "at most 0.1·u0 and at least 1.2·u0"),
            ("sway speed", &n.v, -u0, u0, "at least ±u0"),
            ("yaw rate", &n.r, -2.0 * u0 / lpp, 2.0 * u0 / lpp, "at least ±2·u0/lpp"),
        ];
        room.into_iter().find_map(|(role, name, low, high, rule)| {
            let name = model.vocabulary.canonical(name).unwrap_or_else(|| name.to_string());
            let k = model.spec().states.iter().position(|s| s.name == name)?;
            let state = &model.spec().states[k];
            let (min, max) = (state.min.unwrap_or(f64::NEG_INFINITY), state.max.unwrap_or(f64::INFINITY));
            (min > low || max < high).then(|| {
                (
                    format!("states[{k}].{}", if min > low { "min" } else { "max" }),
                    format!(
                        "the bounds [{min}, {max}] of `{name}` (the ship's {role}) leave no room for its manoeuvres at u0 = {u0} m/s, lpp = {lpp} m ({rule}): a run reaching them stops as diverging; widen them (`termid scale` rescales a model file's bounds with it)"
                    ),
                )
            })
        })
    }

    /// Checks the `[ship]` table of a model read from `text`: its schema, positive lengths and
    /// speeds, and role names the model declares. Errors are located in the file.
    pub fn check(model: &Model, text: &str) -> Result<(), ModelError> {
        let key_err = |key: &str, message: String| ModelError::Key {
            file: model.path.clone(),
            line: line_of_key(text, key),
            key: key.into(),
            message,
        };
        if !model.spec().plugins.contains_key(TABLE) {
            return Ok(());
        }
        // read from the text itself, so that toml's message carries the line and column
        #[derive(Deserialize)]
        struct Only {
            ship: ShipSpec,
        }
        let spec = toml::from_str::<Only>(text)
            .map_err(|e| ModelError::Syntax { file: model.path.clone(), message: e.to_string() })?
            .ship;
        for (key, value) in [
            ("lpp", spec.lpp),
            ("rudder_rate", spec.rudder_rate),
            ("rudder_limit", spec.rudder_limit),
            ("u0", spec.u0),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(key_err(
                    &format!("{TABLE}.{key}"),
                    format!("must be a positive number, not {value}"),
                ));
            }
        }
        for (key, value, (range, what)) in [
            ("rudder_limit", spec.rudder_limit, RUDDER_LIMIT),
            ("rudder_rate", spec.rudder_rate, RUDDER_RATE),
        ] {
            if !range.contains(&value) {
                return Err(key_err(&format!("{TABLE}.{key}"), format!("{value} is out of range: {what}")));
            }
        }
        if !(spec.rudder_delay.is_finite() && (0.0..=60.0).contains(&spec.rudder_delay)) {
            return Err(key_err(
                &format!("{TABLE}.rudder_delay"),
                format!(
                    "{} is out of range: the steering gear's dead time lies between 0 and 60 s",
                    spec.rudder_delay
                ),
            ));
        }
        if let Some(a) = spec.rudder_acceleration.filter(|a| !(a.is_finite() && (0.01..=1e5).contains(a))) {
            return Err(key_err(
                &format!("{TABLE}.rudder_acceleration"),
                format!(
                    "{a} is out of range: the steering gear's acceleration lies between 0.01 and 1e5 °/s²"
                ),
            ));
        }
        if let Some(full) = spec.full_scale_lpp.filter(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(key_err(
                &format!("{TABLE}.full_scale_lpp"),
                format!("must be a positive length, not {full}"),
            ));
        }
        let n = &spec.names;
        let declared = |name: &str| {
            let name = model.vocabulary.canonical(name).unwrap_or_else(|| name.to_string());
            model.spec().states.iter().any(|s| s.name == name)
                || model.spec().inputs.iter().any(|i| i.name == name)
        };
        for (role, name) in [
            ("u", &n.u),
            ("v", &n.v),
            ("r", &n.r),
            ("psi", &n.psi),
            ("x0", &n.x0),
            ("y0", &n.y0),
            ("rudder", &n.rudder),
        ] {
            if !declared(name) {
                return Err(key_err(
                    &format!("{TABLE}.names.{role}"),
                    format!("`{name}` is not a state or input of the model"),
                ));
            }
        }
        if let Some((key, message)) = spec.bounds_without_room(model) {
            return Err(key_err(&key, message));
        }
        if let Some(name) = &n.propeller {
            let canonical = model.vocabulary.canonical(name).unwrap_or_else(|| name.to_string());
            if !model.spec().inputs.iter().any(|i| i.name == canonical) {
                return Err(key_err(
                    &format!("{TABLE}.names.propeller"),
                    format!("`{name}` is not an input of the model (the propeller's rate is solved as one)"),
                ));
            }
        }
        Ok(())
    }
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}
