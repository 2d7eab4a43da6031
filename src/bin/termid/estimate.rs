//! `termid estimate`: a model file's free parameters estimated by output error (grey-box
//! identification); the estimates, their standard errors and covariance written back.

use anyhow::{Context, Result};
use termid::diagnose::{estimate, EstimateSettings, Runs};
use termid::sim::Integrator;

use crate::args::{EstimateCommand, Format};

pub fn run(cmd: EstimateCommand) -> Result<()> {
    // an output that cannot be written is refused before any work
    if let Some(out) = &cmd.out {
        termid::output::check_file(out)?;
        let mut inputs = crate::runs::input_files(&cmd.data, &[]);
        for d in &cmd.dataset {
            inputs.extend(crate::runs::input_files(&[], std::slice::from_ref(d)));
        }
        inputs.push(("--model".to_string(), cmd.model.clone()));
        crate::runs::check_outputs(&[("--out", out)], &inputs)?;
    }
    let model = crate::simulate::load_model(&Some(cmd.model.clone()))?;
    // said before any run is read
    if model.free_parameters().is_empty() && !cmd.coefficients {
        anyhow::bail!(
            "{} declares no free parameter: mark those to estimate with `free = true` under [parameters.NAME] (or give --coefficients)",
            model.path
        );
    }
    let (frames, sources) = crate::runs::load_sources(&model, &cmd.data, &cmd.dataset)?;
    // one RK4 step per sample by default: the recorded input is known only at the samples
    let dt = cmd.dt.unwrap_or_else(|| termid::data::sample_step(&frames));
    let mut runs = Runs::new(&model, &frames, dt, Integrator::Rk4)?;
    if let Some(states) = &cmd.states {
        runs = runs.comparing(states)?;
    }
    let settings = EstimateSettings {
        coefficients: cmd.coefficients,
        iterations: cmd.iterations,
        sources,
        per_source: cmd.per_source.clone(),
        ..Default::default()
    };
    let label = format!(
        "estimating {} free parameters{} by output error on {} runs",
        model.free_parameters().len(),
        if cmd.coefficients { " and the term coefficients" } else { "" },
        frames.len()
    );
    let fit = crate::progress::with_spinner(&label, || estimate(&model, &runs, &settings))
        .context("estimating the free parameters")?;
    if let Some(out) = &cmd.out {
        let mut outputs = termid::output::Outputs::new();
        outputs.file(out, fit.model.to_toml().as_bytes())?;
        outputs.commit()?;
    }
    // where another model of the same ship predicts differently what the runs did not cover
    let agreement = match &cmd.against {
        Some(path) => {
            let other = crate::simulate::load_model(&Some(path.clone()))?;
            let checks = |m: &termid::model::Model| {
                termid::plugins::of(m).map(|p| p.checks(m, &frames)).unwrap_or_default()
            };
            let (mine, theirs) = (checks(&fit.model), checks(&other));
            let label = path.display().to_string();
            termid::plugin::disagreement(
                &[("estimated", &mine), (label.as_str(), &theirs)],
                0,
                0.10,
                "the models",
            )
        }
        None => vec![],
    };
    for c in agreement.iter().filter(|c| !c.passed) {
        eprintln!("warning: {}", c.line());
    }
    match cmd.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&fit)?),
        Format::Text => {
            print!("{}", fit.text());
            if !agreement.is_empty() {
                println!(
                    "== against {} ==",
                    cmd.against.as_ref().map_or(String::new(), |p| p.display().to_string())
                );
                for c in &agreement {
                    println!("{}", c.line());
                }
            }
            if !fit.per_source.is_empty() {
                print!("{}", crate::runs::source_labels(&cmd.data, &cmd.dataset));
            }
            if let Some(out) = &cmd.out {
                println!("written: {}", out.display());
            }
        }
    }
    Ok(())
}
