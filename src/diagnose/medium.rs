//! The medium a body moved through in runs tracked over ground (a sea trial's current): its
//! velocity estimated alone from each source's runs with the model held, so that a prediction
//! of those runs (`termid validate`) judges the model and not the day's current.

use super::{estimate, DiagnoseError, Estimate, EstimateSettings, InitialValues, Runs};
use crate::data::Frame;
use crate::model::Model;
use crate::sim::Integrator;

/// The model's held velocity of the medium named in `names` (`medium = true`: `new-ship`'s
/// current `c_N`, `c_E`; [`Model::held_medium`]) in `frames`, each of source `sources[k]`:
/// estimated alone, once per source or per run as the parameter's `nuisance` says, every other
/// parameter held and each run simulated from its recorded first sample (as a prediction
/// starts), every recorded state compared, one RK4 step per sample. `None` where `names` is
/// empty. The estimate's [`Estimate::own_values`] give each run its value
/// ([`Runs::with_initial`]).
pub fn medium(
    model: &Model,
    names: &[String],
    frames: &[Frame],
    sources: &[usize],
) -> Result<Option<Estimate>, DiagnoseError> {
    if names.is_empty() {
        return Ok(None);
    }
    let ship: Vec<String> = model.free_parameters().into_iter().map(|p| p.name).collect();
    let alone = model.freed(names, &ship).map_err(DiagnoseError::Setup)?;
    let runs = Runs::new(&alone, frames, crate::data::sample_step(frames), Integrator::Rk4)?;
    let settings = EstimateSettings {
        sources: sources.to_vec(),
        initial_values: InitialValues::Recorded,
        ..Default::default()
    };
    estimate(&alone, &runs, &settings).map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A body drifting in a stream: ẋ = w + c, its own speed w relaxing to the input
    /// (ẇ = (v − w)/τ), the stream c a held medium.
    const DRIFTER: &str = r#"
[model]
name = "drifter"
[[states]]
name = "x"
[[states]]
name = "w"
[[inputs]]
name = "v"
[parameters."τ"]
value = 2.0
free = true
[parameters.c]
value = 0.0
nuisance = "source"
medium = true
[equations.x_dot]
state = "x"
identify = false
coefficients = { "w" = 1.0, "c" = 1.0 }
[equations.w_dot]
state = "w"
identify = false
coefficients = { "v/τ" = 1.0, "w/τ" = -1.0 }
"#;

    /// Two runs of the drifter with τ = 2 in a stream of `c` each (inputs 1 and −0.5).
    fn carried(model: &Model, c: [f64; 2]) -> Vec<Frame> {
        [1.0, -0.5]
            .iter()
            .zip(c)
            .map(|(&v, c)| {
                let mut stream = model.clone();
                stream.set_parameter("c", c);
                let system = crate::sim::System::new(&stream, &Default::default(), false).unwrap();
                let settings = crate::sim::Settings {
                    integrator: Integrator::Rk4,
                    dt: 0.05,
                    duration: 20.0,
                    sample: 0.1,
                };
                let run =
                    crate::sim::simulate(&system, &[0.0, 0.0], &mut crate::sim::Constant(vec![v]), &settings)
                        .unwrap();
                let mut f = Frame::new(&format!("v{v}.csv"), "t", run.time.clone()).unwrap();
                f.push("x", run.states[0].clone()).unwrap();
                f.push("w", run.states[1].clone()).unwrap();
                f.push("v", run.inputs[0].clone()).unwrap();
                f
            })
            .collect()
    }

    /// Tracked over ground in a stream of 0.4, the stream comes back alone, the body's τ
    /// (free in the file) untouched.
    #[test]
    fn a_stream_is_estimated_alone_from_runs_tracked_over_ground() {
        let model = Model::parse(DRIFTER, "drifter.toml").unwrap();
        let frames = carried(&model, [0.4, 0.4]);
        assert_eq!(model.held_medium(), ["c"]);
        let day = medium(&model, &model.held_medium(), &frames, &[0, 0]).unwrap().unwrap();
        let values = day.own_values();
        assert_eq!(values.len(), 2);
        assert!(values.iter().all(|&(_, name, c)| name == "c" && (c - 0.4).abs() < 1e-6), "{values:?}");
        assert!(day.parameters.is_empty(), "τ held: {:?}", day.parameters);
        // nothing named: nothing to estimate
        assert!(medium(&model, &[], &frames, &[0, 0]).unwrap().is_none());
    }

    /// A stream that changed between the runs, estimated per run with the body: each run's
    /// own, and the model written keeps the file's (still water), not their mean, with no
    /// entry in the covariance that Monte-Carlo draws would vary.
    #[test]
    fn a_stream_estimated_per_run_is_not_the_models() {
        let file = Model::parse(DRIFTER, "drifter.toml").unwrap();
        let frames = carried(&file, [0.4, 0.1]);
        let model = file.freed(&["c".into()], &[]).unwrap();
        let runs = Runs::new(&model, &frames, 0.1, Integrator::Rk4).unwrap();
        let settings = EstimateSettings { per_run: vec!["c".into()], ..Default::default() };
        let fit = estimate(&model, &runs, &settings).unwrap();
        let values: Vec<f64> = fit.own_values().iter().map(|v| v.2).collect();
        assert!((values[0] - 0.4).abs() < 1e-4 && (values[1] - 0.1).abs() < 1e-4, "{values:?}");
        assert!(
            fit.per_run[0].medium && fit.text().contains("the model keeps its file's `c`"),
            "{}",
            fit.text()
        );
        assert_eq!(fit.model.parameter_values()["c"], 0.0);
        let covariance = fit.model.spec().parameter_covariance.as_ref().unwrap();
        assert_eq!(covariance.names, ["τ"]);
    }
}
