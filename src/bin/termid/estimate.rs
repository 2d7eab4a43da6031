//! `termid estimate`: a model file's free parameters estimated by output error (grey-box
//! identification); the estimates, their standard errors and covariance written back.

use anyhow::{Context, Result};
use termid::diagnose::{estimate, EstimateSettings, Runs};

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
    if let Some(dir) = &cmd.svg {
        termid::output::check_folder(dir)?;
    }
    let file = crate::simulate::load_model(&Some(cmd.model.clone()))?;
    // runs tracked over ground carry the current the body moves in: the model's own
    // velocity of the medium is estimated with it, unless the command holds it
    let over_ground = crate::runs::over_ground(&cmd.dataset);
    let (model, medium) = file
        .freed_over_ground(&cmd.free, &cmd.hold, !over_ground.is_empty())
        .map_err(|e| anyhow::anyhow!("--free/--hold: {e}"))?;
    if !medium.is_empty() {
        eprintln!(
            "note: the runs of {} are tracked over ground (by a satellite receiver): their velocities carry the current they move in, so the model's {} {} estimated with it (the model written keeps its file's value; `--hold {}` holds it)",
            over_ground.join(", "),
            medium.join(", "),
            if medium.len() == 1 { "is" } else { "are" },
            medium.join(",")
        );
    } else if !over_ground.is_empty() && !file.spec().parameters.values().any(|p| p.medium) {
        crate::runs::warn_over_ground(&cmd.dataset);
    }
    // said before any run is read
    if model.free_parameters().is_empty() && !cmd.coefficients {
        anyhow::bail!(
            "{} declares no free parameter: mark those to estimate with `free = true` under [parameters.NAME] (or give --coefficients)",
            model.path
        );
    }
    let (frames, sources) = crate::runs::load_sources(&model, &cmd.data, cmd.by.as_deref(), &cmd.dataset)?;
    // multiple shooting: each segment a run of its own, of its run's source
    let (frames, sources) = match cmd.segments {
        Some(count) => termid::diagnose::in_segments(&frames, &sources, count as usize),
        None => (frames, sources),
    };
    // one RK4 step per sample by default, a whole fraction of it where the model is stiff
    let given = cmd.dt.map(|dt| dt * model.seconds_per_time());
    let (mut runs, stiff) = Runs::for_output_error(&model, &frames, given)?;
    if let Some(note) = stiff {
        // beside the report, not in it: JSON on standard output stays one document
        eprintln!("note: {note}");
    }
    if let Some(states) = &cmd.states {
        runs = runs.comparing(&model, states)?;
    }
    let settings = EstimateSettings {
        coefficients: cmd.coefficients,
        iterations: cmd.iterations,
        initial_values: cmd.initial_values,
        sources: sources.clone(),
        per_source: cmd.per_source.clone(),
        per_run: cmd.per_run.clone(),
        coarsest: cmd.coarse.then_some((termid::recipe::RESOLVED, termid::recipe::MOST_SAMPLES_PER_STEP)),
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
    // the runs as the fit re-simulates them: what a plug-in reads off each beside its record
    // (and whether within the field's tolerance), and the figures
    let refit = fit.re_simulated(&runs);
    // what was compared (the states, and the derived variables beside them), over all runs
    let gap = refit.as_ref().ok().map(|sims| runs.gap(sims));
    let (metrics, metric_checks) = match &refit {
        Ok(sims) => termid::plugins::fit_metrics(&fit.model, runs.frames(), sims),
        Err(e) => {
            eprintln!("warning: no metrics of the fit: the estimates do not re-simulate every run: {e}");
            (vec![], vec![])
        }
    };
    let mut outputs = termid::output::Outputs::new();
    if let Some(out) = &cmd.out {
        outputs.file(out, file.as_declared(&fit.model).to_toml().as_bytes())?;
    }
    let mut drawn = false;
    if let Some(dir) = &cmd.svg {
        // a run the start values cannot simulate costs the figures, not the estimate
        let figures =
            refit.map_err(anyhow::Error::from).and_then(|after| figures(&model, &after, &runs, &frames));
        match figures {
            Ok(figures) => {
                crate::figures::write(&mut outputs, dir, "estimate", figures)?;
                drawn = true;
            }
            Err(e) => eprintln!("warning: no figures: {e:#}"),
        }
    }
    outputs.commit()?;
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
    for c in agreement.iter().chain(&metric_checks).filter(|c| !c.passed) {
        eprintln!("warning: {}", c.line());
    }
    match cmd.format {
        Format::Json => {
            let mut report = serde_json::to_value(&fit)?;
            report["metrics"] = serde_json::to_value(&metrics)?;
            report["gap"] = serde_json::json!(gap.as_ref().map(|g| g
                .states
                .iter()
                .map(|(name, unit, rms, max)| serde_json::json!({ "name": name, "unit": unit, "rms": rms, "max": max }))
                .collect::<Vec<_>>()));
            report["metric_checks"] = serde_json::to_value(&metric_checks)?;
            println!("{}", serde_json::to_string_pretty(&report)?)
        }
        Format::Text => {
            print!("{}", fit.text());
            if let Some(gap) = &gap {
                let cells: Vec<String> = gap
                    .states
                    .iter()
                    .map(|(name, _, rms, max)| {
                        crate::validate::error_cell(name, *rms, *max, model.unit(name))
                    })
                    .collect();
                println!(
                    "the fit's re-simulation against the records (model − measured), RMS / max: {}",
                    cells.join(", ")
                );
            }
            if !metrics.is_empty() {
                println!("== each run's metrics: measured → as the fit re-simulates it (the estimates, the run's own values and initial state) ==");
                print!("{}", termid::plugin::metric_pairs_text(&metrics));
                for c in &metric_checks {
                    println!("{}", c.line());
                }
            }
            if !agreement.is_empty() {
                println!(
                    "== against {} ==",
                    cmd.against.as_ref().map_or(String::new(), |p| p.display().to_string())
                );
                for c in &agreement {
                    println!("{}", c.line());
                }
            }
            if fit.per_source_values() {
                print!("{}", crate::runs::source_labels(&cmd.data, &cmd.dataset));
            }
            if let Some(out) = &cmd.out {
                println!("written: {}", out.display());
            }
            if let (Some(dir), true) = (&cmd.svg, drawn) {
                println!("figures: {}/estimate_<run>.svg", dir.display());
            }
        }
    }
    Ok(())
}

/// A figure per run: the compared states measured, simulated with the model's values from the
/// run's first sample, and as the fit re-simulates them (the estimates, each source's or run's
/// own values, the estimated initial state).
fn figures(
    model: &termid::model::Model,
    after: &[termid::sim::Trajectory],
    runs: &Runs,
    frames: &[termid::data::Frame],
) -> Result<Vec<(String, termid::plot::Figure)>> {
    let before = runs.simulate(model, &[], &[])?;
    let plane = termid::plugins::of(model).and_then(|p| p.plane(model));
    Ok(termid::plot::comparison_figures(
        model,
        frames,
        (&before, after),
        &[],
        ("estimate", ["start values", "estimated"]),
        plane.as_ref(),
    ))
}
