//! `termid moments`: an equation's sufficient statistics over a shard of runs, written for
//! `identify --moments` to merge (the one pass over the rows done where the rows are).

use anyhow::{Context, Result};
use termid::data::{differentiator, Chunks};
use termid::identify::EquationMoments;

use crate::args::MomentsCommand;
use crate::args::{Format, IdentifyCommand};

pub fn run(cmd: MomentsCommand) -> Result<()> {
    termid::output::check_file(&cmd.out)?;
    let mut inputs = crate::runs::input_files(&cmd.data, &cmd.dataset);
    crate::runs::check_once(&inputs)?;
    inputs.push(("--model".into(), cmd.model.clone()));
    crate::runs::check_outputs(&[("--out", &cmd.out)], &inputs)?;
    let model = termid::plugins::load(&cmd.model)?;
    let diff = differentiator(&cmd.derivative)?;
    let moments = match diff.reach() {
        // plain files with a local derivative: read in pieces, one pass, bounded memory
        Some(reach) if cmd.chunk_rows > 0 && cmd.dataset.is_empty() => {
            let runs = cmd
                .data
                .iter()
                .map(|p| Chunks::open(p, &model.spec().model.time, cmd.chunk_rows, 2 * reach + 2))
                .collect::<Result<Vec<_>, _>>()?;
            let (moments, notes) = EquationMoments::of_chunks(&model, &cmd.equation, runs, diff.as_ref())?;
            for n in notes {
                crate::runs::say(&n);
            }
            moments
        }
        _ => {
            let frames = crate::runs::load_for(&model, &cmd.data, &cmd.dataset)?;
            EquationMoments::of_runs(&model, &cmd.equation, &frames, diff.as_ref(), None)?
        }
    };
    termid::output::write_file(&cmd.out, moments.to_json().as_bytes())?;
    let rows: usize = moments.runs.iter().map(|r| r.moments.count()).sum();
    println!(
        "wrote {}: `{}` ({}), {} candidates over {} run(s), {rows} rows",
        cmd.out.display(),
        moments.equation,
        moments.target,
        moments.candidates.len(),
        moments.runs.len()
    );
    Ok(())
}

/// `identify --moments`: the statistics files read, then merged per equation (in the order
/// given) and identified by the library.
pub fn identify(
    model: &termid::model::Model,
    files: &[std::path::PathBuf],
    equations: &[String],
    intercept: bool,
) -> Result<(termid::model::Model, Vec<(String, termid::identify::Fit)>)> {
    let parts = files
        .iter()
        .map(|path| {
            let text =
                termid::budget::read_json(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
            let origin = path.display().to_string();
            Ok((origin.clone(), EquationMoments::from_json(&text, &origin)?))
        })
        .collect::<Result<Vec<_>>>()?;
    // --equation picks among the statistics; each one named must have some
    for eq in equations {
        if model.equation(eq).is_none() {
            anyhow::bail!(
                "--equation {eq}: {} has no equation `{eq}` (equations: {})",
                model.path,
                model.identifiable().join(", ")
            );
        }
        if !parts.iter().any(|(_, m)| &m.equation == eq) {
            anyhow::bail!("--equation {eq}: none of the --moments files holds statistics of `{eq}`");
        }
    }
    let parts: Vec<_> =
        parts.into_iter().filter(|(_, m)| equations.is_empty() || equations.contains(&m.equation)).collect();
    let identified = termid::identify::identify_from_moments(model, parts, intercept)?;
    Ok((identified.model, identified.fits))
}

/// `identify --model M --moments FILES`: equations identified from merged statistics, as
/// from the runs they were computed on (no residual pass: no correlation time, no checks).
pub fn identify_from_files(cmd: IdentifyCommand) -> Result<()> {
    let path = cmd.model.clone().context("--model")?;
    if let Some(out) = &cmd.out {
        termid::output::check_file(out)?;
    }
    let mut model = termid::plugins::load(&path)?;
    if cmd.backend.is_some() {
        model = model.with_backend(&crate::identify::configure_backend(&cmd)?)?;
    }
    let intercept = crate::identify::intercept_of(&cmd, model.spec().model.intercept);
    let (mut model, fits) = crate::moments::identify(&model, &cmd.moments, &cmd.equation, intercept)?;
    if let Some(out) = &cmd.out {
        let sources = cmd.moments.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ");
        model.mark_identified(&format!("the statistics {sources}"));
        termid::output::write_file(out, model.to_toml().as_bytes())?;
    }
    match cmd.format {
        Format::Json => {
            let all: serde_json::Map<String, serde_json::Value> = fits
                .iter()
                .map(|(n, f)| Ok((n.clone(), serde_json::to_value(f.report())?)))
                .collect::<Result<_>>()?;
            println!("{}", serde_json::to_string_pretty(&all)?);
        }
        Format::Text => {
            for (name, fit) in &fits {
                println!("== {name} ==");
                print!("{}", fit.text());
                println!();
            }
            if let Some(out) = &cmd.out {
                println!("wrote {}", out.display());
            }
        }
    }
    Ok(())
}
