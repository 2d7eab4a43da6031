//! The registry of plug-ins: [`PLUGINS`] is the one place a plug-in is named; the CLI and the
//! loaders here iterate it. Load model files through [`load`] / [`parse`] to have every
//! plug-in table checked (the core's `Model::load` keeps them unread).

use crate::model::{line_of_key, Model, ModelError};
use crate::plugin::Plugin;

/// Every plug-in termid knows. A new one is a module and one line here.
pub static PLUGINS: &[&dyn Plugin] = &[&crate::ship::plugin::Manoeuvring];

/// The plug-in whose table `model` has.
pub fn of(model: &Model) -> Option<&'static dyn Plugin> {
    PLUGINS.iter().copied().find(|p| model.spec().plugins.contains_key(p.table()))
}

/// How a fit reproduces what `model`'s plug-in reads off each of its runs (a ship's
/// overshoots, its tactical diameter): each run's record in `frames` beside its re-simulation
/// in `sims` (a grey-box estimate's: [`crate::diagnose::Estimate::re_simulated`]), and the
/// plug-in's checks of them; empty for a model no plug-in owns. A structure can fit the runs'
/// time series in the mean and still miss the numbers a manoeuvre is judged by.
pub fn fit_metrics(
    model: &Model,
    frames: &[crate::data::Frame],
    sims: &[crate::sim::Trajectory],
) -> (Vec<crate::plugin::MetricPair>, Vec<crate::plugin::Check>) {
    let Some(plugin) = of(model) else { return (vec![], vec![]) };
    let pairs = crate::plugin::metric_pairs(plugin, model, frames, sims);
    let checks = plugin.metric_checks(&pairs);
    (pairs, checks)
}

/// The hypotheses `diagnose` tests for `model`: its plug-in's, else the generic library with
/// the products of its variables beyond its candidates
/// ([`crate::diagnose::beyond_candidates`]).
pub fn hypotheses(model: &Model) -> Vec<crate::diagnose::Hypothesis> {
    of(model).and_then(|p| p.hypotheses(model)).unwrap_or_else(|| {
        let mut out = crate::diagnose::generic_hypotheses(model);
        out.extend(crate::diagnose::beyond_candidates(model));
        out
    })
}

/// The plug-in that adds derivative method `name`.
pub fn with_derivative(name: &str) -> Option<&'static dyn Plugin> {
    PLUGINS.iter().copied().find(|p| p.derivative_methods().contains(&name))
}

/// termid's default model: the first plug-in's (the Oltmann ship).
pub fn default_model() -> Model {
    PLUGINS.iter().find_map(|p| p.default_model()).expect("the first plug-in brings the default model")
}

/// Parses model text and checks its plug-in tables: each must be a registered plug-in's, and
/// pass that plug-in's checks. `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<Model, ModelError> {
    let model = Model::parse(text, file)?;
    for table in model.spec().plugins.keys() {
        let Some(plugin) = PLUGINS.iter().find(|p| p.table() == table) else {
            let known: Vec<String> = PLUGINS.iter().map(|p| format!("[{}]", p.table())).collect();
            return Err(ModelError::Key {
                file: file.into(),
                line: line_of_key(text, table),
                key: table.clone(),
                message: format!("no plug-in reads this table (tables of plug-ins: {})", known.join(", ")),
            });
        };
        plugin.check(&model, text)?;
    }
    Ok(model)
}

/// Reads a model file and checks it as [`parse`] does.
pub fn load(path: &std::path::Path) -> Result<Model, ModelError> {
    let file = path.display().to_string();
    let text =
        crate::budget::read_text(path).map_err(|error| ModelError::Io { file: file.clone(), error })?;
    parse(&text, &file)
}

/// The model at another scale with its plug-in's table ([`crate::model::dimension::rescaled`],
/// then [`Plugin::rescale`]): Froude's law (`length` λ, `time` √λ, `mass` λ³) takes a basin's
/// model to its ship, particulars, approach speed and steering gear with it (the coefficients
/// alone left a ship's model at the basin's speed and rudder rate).
pub fn rescaled(
    model: &Model,
    length: f64,
    time: f64,
    mass: f64,
) -> Result<Model, crate::plugin::PluginError> {
    let mut scaled = crate::model::dimension::rescaled(model, length, time, mass)
        .map_err(crate::plugin::PluginError::failed)?;
    if let Some(plugin) = of(&scaled) {
        plugin.rescale(&mut scaled, length, time, mass)?;
    }
    Ok(scaled)
}
