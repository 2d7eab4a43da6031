//! What a plug-in is: what a field adds to the generic core (ship manoeuvring is the first).
//! A plug-in owns one table of the model file, which the core keeps as data; it checks that
//! table, may bring a default model, derivative preparations, diagnosis hypotheses, metrics of
//! recorded runs and named scenarios to simulate. `crate::plugins` registers them.

use crate::data::Frame;
use crate::diagnose::Hypothesis;
use crate::model::{Model, ModelError};
use crate::sim::{Settings, Trajectory};

/// Why a plug-in could not do what was asked.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PluginError {
    /// An option or request that does not apply (the message says what to do instead).
    #[error("{0}")]
    Refused(String),
    /// The work failed; the plug-in's own error says why.
    #[error(transparent)]
    Failed(Box<dyn std::error::Error + Send + Sync>),
}

impl PluginError {
    /// Wraps a plug-in's own error.
    pub fn failed(e: impl std::error::Error + Send + Sync + 'static) -> PluginError {
        PluginError::Failed(Box::new(e))
    }
}

/// What the recipe does where its caller names no derivative starts, smoothing or refinement
/// (plain data a plug-in returns; [`RecipeDefaults::of`] gives a model's).
#[derive(Clone, Debug, PartialEq)]
pub struct RecipeDefaults {
    /// One start per derivative method.
    pub derivatives: Vec<String>,
    /// Whether the states are smoothed by each start's method.
    pub smooth: bool,
    /// The states the refinement compares (`None`: no refinement; empty: every state).
    pub refine: Option<Vec<String>>,
}

/// A field's extension of the core.
pub trait Plugin: Sync {
    /// The model-file table it owns (`ship`); a model with that table is this plug-in's.
    fn table(&self) -> &'static str;
    /// Checks its table of `model`, read from `text` (errors located by key, as the core's).
    fn check(&self, model: &Model, text: &str) -> Result<(), ModelError>;
    /// Its default model, if it has one (the first plug-in's is termid's default).
    fn default_model(&self) -> Option<Model> {
        None
    }
    /// Sets a value the plug-in's table holds (`u0` of a ship), besides the model's parameter
    /// of that name; `Ok(false)`: not one of its values.
    fn set_parameter(&self, _model: &mut Model, _name: &str, _value: f64) -> Result<bool, PluginError> {
        Ok(false)
    }
    /// The derivative preparations it adds (`kinematic`), by `--derivative` name.
    fn derivative_methods(&self) -> &'static [&'static str] {
        &[]
    }
    /// A run prepared by one of [`Plugin::derivative_methods`]: states smoothed and their
    /// derivatives added as `<state>_dot` columns.
    fn prepare(
        &self,
        method: &str,
        _model: &Model,
        _frame: &Frame,
        _smooth: bool,
    ) -> Result<Frame, PluginError> {
        Err(PluginError::Refused(format!("no derivative method `{method}`")))
    }
    /// What the recipe does for a model of this field where its caller names no derivative
    /// starts, smoothing or refinement (`None`: any system's,
    /// [`RecipeDefaults::of`]).
    fn recipe_defaults(&self, _model: &Model) -> Option<RecipeDefaults> {
        None
    }
    /// The effects `diagnose` tries for a model of this field (`None`: the generic ones).
    fn hypotheses(&self, _model: &Model) -> Option<Vec<Hypothesis>> {
        None
    }
    /// The field's metrics of a recorded run (`simulated`: of the simulation of that run, with
    /// the run's recorded inputs); `None` where the run has none.
    fn observe(
        &self,
        _model: &Model,
        _frame: &Frame,
        _simulated: Option<&Trajectory>,
    ) -> Option<Observation> {
        None
    }
    /// Physical checks of an identified `model` (identified from `runs`), before it is written
    /// or trusted: what the field knows must hold whatever the data said. Empty: none.
    fn checks(&self, _model: &Model, _runs: &[Frame]) -> Vec<Check> {
        vec![]
    }
    /// Those of [`Plugin::checks`] that read the runs themselves (a ship steering its zigzags
    /// as recorded), by the same names, each run with the model that holds its own values (of
    /// a parameter estimated per run or per source). Empty: none.
    fn run_checks(&self, _runs: &[(&Model, &Frame)]) -> Vec<Check> {
        vec![]
    }
    /// Checks of how closely a fit re-simulates what this field reads off its runs
    /// ([`metric_pairs`]: a grey-box estimate's, each run with its own values), by the field's
    /// own tolerance. Empty: none.
    fn metric_checks(&self, _pairs: &[MetricPair]) -> Vec<Check> {
        vec![]
    }
    /// The reference length, speed and density of a model of this field, for nondimensional
    /// coefficients (a ship's length, approach speed and water density).
    fn reference(&self, _model: &Model) -> Option<(f64, f64, f64)> {
        None
    }
    /// The plane a run of `model` moves in (a ship's track), for figures that set measured and
    /// simulated runs side by side; `None`: every state is drawn over time.
    fn plane(&self, _model: &Model) -> Option<crate::sim::Plane> {
        None
    }
    /// The field's name for a coefficient (`Y'_vvr` for the v̇ coefficient of v²r/u).
    fn coefficient_name(&self, _model: &Model, _equation: &str, _term: &crate::term::Term) -> Option<String> {
        None
    }
    /// Rescales the values of its table when the model is rescaled (lengths × `length`, times
    /// × `time`, masses × `mass`; `crate::model::dimension::rescaled` does the rest).
    fn rescale(&self, _model: &mut Model, _length: f64, _time: f64, _mass: f64) -> Result<(), PluginError> {
        Ok(())
    }
    /// A named scenario of this field (`zigzag:20/20`) to simulate `model` under.
    fn scenario(
        &self,
        model: &Model,
        request: &ScenarioRequest<'_>,
    ) -> Result<Box<dyn Scenario>, PluginError>;
}

/// One physical check of a model and its outcome.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Check {
    /// What is checked, e.g. `yaw damping ∂ṙ/∂r < 0`.
    pub name: String,
    /// Whether the model passes.
    pub passed: bool,
    /// Whether failing it refuses the model (else it is flagged: some real hulls fail it).
    pub refuses: bool,
    /// The numbers behind the verdict.
    pub detail: String,
    /// The one number a check is about where it has one (a turning circle's tactical
    /// diameter): what models of one identification are compared by.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measure: Option<Measure>,
}

/// A named number of a check, with its unit.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Measure {
    /// What it is, e.g. `tactical diameter, δ = -30°`.
    pub name: String,
    /// Its value.
    pub value: f64,
    /// Its unit.
    pub unit: String,
}

/// Where several models of one identification (`what`: the starts of a recipe, each
/// plausible by its own checks; a grey-box and a polynomial model) disagree by more than `tolerance` (relative) on a measure of a manoeuvre
/// the runs did not cover: one flag per such measure, with the range of the models and the
/// kept one's value. The runs cannot tell these models apart, so the spread is the
/// uncertainty of that prediction.
pub fn disagreement(models: &[(&str, &[Check])], kept: usize, tolerance: f64, what: &str) -> Vec<Check> {
    let Some((_, kept_checks)) = models.get(kept) else { return vec![] };
    let mut out = Vec::new();
    for m in kept_checks.iter().filter_map(|c| c.measure.as_ref()) {
        let values: Vec<(&str, f64)> = models
            .iter()
            .filter_map(|(label, checks)| {
                let v = checks.iter().filter_map(|c| c.measure.as_ref()).find(|n| n.name == m.name)?;
                Some((*label, v.value))
            })
            .collect();
        if values.len() < 2 {
            continue;
        }
        let (lo, hi) =
            values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (_, v)| (a.min(*v), b.max(*v)));
        let spread = (hi - lo) / m.value.abs().max(1e-300);
        let agree = spread <= tolerance;
        let each: Vec<String> = values.iter().map(|(l, v)| format!("{l} {v:.2}")).collect();
        out.push(Check {
            name: format!("{what} agree on the {} (within {:.0} %)", m.name, 100.0 * tolerance),
            passed: agree,
            refuses: false,
            detail: format!(
                "{lo:.2}-{hi:.2} {unit} (kept {:.2}; {}): {}",
                m.value,
                each.join(", "),
                if agree {
                    format!("spread {:.1} %", 100.0 * spread)
                } else {
                    format!(
                        "the runs cannot tell these models apart, so this prediction is uncertain by {:.0} %",
                        100.0 * spread
                    )
                },
                unit = m.unit
            ),
            measure: None,
        });
    }
    out
}

impl Check {
    /// One line a person reads: `ok`, `FLAG` or `FAIL`, the check and its numbers.
    pub fn line(&self) -> String {
        let verdict = match (self.passed, self.refuses) {
            (true, _) => "ok  ",
            (false, false) => "FLAG",
            (false, true) => "FAIL",
        };
        format!("{verdict} {}: {}", self.name, self.detail)
    }
}

/// What `simulate` asks of a plug-in's scenario.
#[derive(Clone, Debug)]
pub struct ScenarioRequest<'a> {
    /// The scenario as the user wrote it.
    pub text: &'a str,
    /// Simulate the stored intercepts too.
    pub with_intercept: bool,
    /// Initial states were given (a scenario that sets its own refuses them).
    pub initial_given: bool,
    /// Constant inputs were given (a scenario that drives its inputs refuses them).
    pub inputs_given: bool,
}

/// A scenario ready to run on a model and its drawn variants.
pub trait Scenario: Send {
    /// How a title names it (`zigzag 20°/20°`).
    fn label(&self) -> String;
    /// How long it runs unless told otherwise, s.
    fn default_duration(&self) -> f64;
    /// Runs it on `model` (the nominal model or one drawn from its covariance).
    fn run(&self, model: &Model, settings: &Settings) -> Result<Outcome, PluginError>;
    /// Its figure: the nominal outcome, with the 90 % band of the drawn models' trajectories.
    #[cfg(feature = "plot")]
    fn figure(&self, title: &str, nominal: &Outcome, draws: &[&Trajectory]) -> crate::plot::Figure;
}

/// What a scenario produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The simulation, at the output sampling.
    pub trajectory: Trajectory,
    /// The same as a frame of named columns (what `--out` writes).
    pub frame: Frame,
    /// Its metrics (a JSON object of numbers, `null` where not reached).
    pub metrics: serde_json::Value,
    /// Further values for the JSON report (a ship's straight run `delta0_deg`, `v0`, and
    /// its IMO criteria).
    pub extra: serde_json::Map<String, serde_json::Value>,
    /// The report a person reads, one line each, metrics included.
    pub text: Vec<String>,
}

/// A field's metrics of one run.
#[derive(Clone, Debug)]
pub struct Observation {
    /// Every metric, as the JSON report gives it.
    pub json: serde_json::Value,
    /// The ones a table shows: label with unit, key in `json`, value (`None`: not reached).
    pub rows: Vec<(String, String, Option<f64>)>,
    /// How the metrics were read, where that differs from how a simulated scenario reports
    /// them (said once under the table).
    pub note: Option<String>,
}

/// One metric of one run, read off its record and off a simulation of that run alike (a fit's
/// re-simulation, a prediction): what a report sets side by side.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MetricPair {
    /// The run (its file, as the frame's origin says).
    pub run: String,
    /// The metric's key (`first_overshoot_deg`; its unit in the suffix, [`metric_label`]).
    pub metric: String,
    /// Read off the record.
    pub measured: f64,
    /// Read off the simulation.
    pub simulated: f64,
}

/// Every metric `plugin` reads off both a run's record and `sims`' simulation of it (the runs
/// in order, one simulation each).
pub fn metric_pairs(
    plugin: &dyn Plugin,
    model: &Model,
    frames: &[Frame],
    sims: &[Trajectory],
) -> Vec<MetricPair> {
    let mut pairs = Vec::new();
    for (frame, sim) in frames.iter().zip(sims) {
        let (Some(measured), Some(simulated)) =
            (plugin.observe(model, frame, None), plugin.observe(model, frame, Some(sim)))
        else {
            continue;
        };
        for ((_, key, m), (_, _, s)) in measured.rows.iter().zip(&simulated.rows) {
            if let (Some(m), Some(s)) = (m, s) {
                pairs.push(MetricPair {
                    run: frame.origin().to_string(),
                    metric: key.clone(),
                    measured: *m,
                    simulated: *s,
                });
            }
        }
    }
    pairs
}

/// `pairs` as lines of text, a run a line (`name: first overshoot 11.35° → 10.47° (−0.88°), …`:
/// measured → simulated, the difference), and the largest difference of each metric.
pub fn metric_pairs_text(pairs: &[MetricPair]) -> String {
    let mut text = String::new();
    let mut runs: Vec<&str> = pairs.iter().map(|p| p.run.as_str()).collect();
    runs.dedup();
    for run in &runs {
        let cells: Vec<String> = pairs
            .iter()
            .filter(|p| p.run == *run)
            .map(|p| {
                let (name, unit, d) = metric_label(&p.metric);
                let unit = crate::model::dimension::after_number(unit);
                format!(
                    "{name} {:.d$}{unit} → {:.d$}{unit} ({:+.d$}{unit})",
                    p.measured,
                    p.simulated,
                    p.simulated - p.measured
                )
            })
            .collect();
        text += &format!("  {}: {}\n", crate::diagnose::file_name(run), cells.join(", "));
    }
    let mut metrics: Vec<&str> = pairs.iter().map(|p| p.metric.as_str()).collect();
    metrics.sort_unstable();
    metrics.dedup();
    for metric in metrics {
        let worst = pairs
            .iter()
            .filter(|p| p.metric == metric)
            .max_by(|a, b| (a.simulated - a.measured).abs().total_cmp(&(b.simulated - b.measured).abs()));
        if let Some(p) = worst {
            let (name, unit, d) = metric_label(metric);
            let unit = crate::model::dimension::after_number(unit);
            text += &format!(
                "  largest difference of the {name}: {:+.d$}{unit} ({})\n",
                p.simulated - p.measured,
                crate::diagnose::file_name(&p.run)
            );
        }
    }
    text
}

/// A metric's key (its last `.`-part, where nested) as a person reads it: its name in words,
/// its unit (from the key's suffix: `_deg_s`, `_deg`, `_s`, `_m`, `_lpp`, `_percent`) and the
/// decimals that mean something at the sampling of a simulation (0.01°, 0.01 s, 0.01 m, 0.1 %).
pub fn metric_label(key: &str) -> (String, &'static str, usize) {
    // a nested metric (`turning.tactical_diameter_m`) by its own name
    let key = key.rsplit('.').next().unwrap_or(key);
    let units: [(&str, &str, usize); 6] = [
        ("_deg_s", "°/s", 3),
        ("_deg", "°", 2),
        ("_percent", "%", 1),
        ("_lpp", "L", 2),
        ("_m", "m", 2),
        ("_s", "s", 2),
    ];
    let (name, unit, decimals) = units
        .iter()
        .find_map(|(suffix, unit, d)| key.strip_suffix(suffix).map(|n| (n, *unit, *d)))
        .unwrap_or((key, "", 3));
    (name.replace('_', " "), unit, decimals)
}

#[cfg(test)]
mod tests {
    use super::{metric_label, metric_pairs_text, MetricPair};

    #[test]
    fn metric_pairs_read_a_run_a_line_and_the_largest_difference() {
        let pair = |run: &str, metric: &str, measured: f64, simulated: f64| MetricPair {
            run: run.into(),
            metric: metric.into(),
            measured,
            simulated,
        };
        let text = metric_pairs_text(&[
            pair("/basin/z1.dat", "first_overshoot_deg", 11.35, 10.49),
            pair("/basin/z1.dat", "second_overshoot_deg", 13.04, 14.02),
            pair("/basin/z2.dat", "first_overshoot_deg", 9.0, 11.5),
            pair("/basin/t.dat", "tactical_diameter_m", 21.12, 21.11),
        ]);
        assert_eq!(
            text,
            "  z1.dat: first overshoot 11.35° → 10.49° (-0.86°), second overshoot 13.04° → 14.02° (+0.98°)\n\
             \x20 z2.dat: first overshoot 9.00° → 11.50° (+2.50°)\n\
             \x20 t.dat: tactical diameter 21.12 m → 21.11 m (-0.01 m)\n\
             \x20 largest difference of the first overshoot: +2.50° (z2.dat)\n\
             \x20 largest difference of the second overshoot: +0.98° (z1.dat)\n\
             \x20 largest difference of the tactical diameter: -0.01 m (t.dat)\n"
        );
        assert_eq!(metric_pairs_text(&[]), "");
    }

    #[test]
    fn metric_keys_read_as_words_with_units() {
        assert_eq!(metric_label("first_overshoot_deg"), ("first overshoot".to_string(), "°", 2));
        assert_eq!(metric_label("yaw_rate_deg_s"), ("yaw rate".to_string(), "°/s", 3));
        assert_eq!(metric_label("period_s"), ("period".to_string(), "s", 2));
        assert_eq!(metric_label("turning.advance_m"), ("advance".to_string(), "m", 2));
        assert_eq!(metric_label("tactical_diameter_lpp"), ("tactical diameter".to_string(), "L", 2));
        assert_eq!(metric_label("speed_loss_percent"), ("speed loss".to_string(), "%", 1));
        assert_eq!(metric_label("speed_ratio"), ("speed ratio".to_string(), "", 3));
    }
}
