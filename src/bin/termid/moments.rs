//! `termid moments`: an equation's sufficient statistics over a shard of runs, written for
//! `identify --moments` to merge (the one pass over the rows done where the rows are).

use anyhow::Result;
use termid::data::differentiator;
use termid::identify::EquationMoments;

use crate::args::MomentsCommand;

pub fn run(cmd: MomentsCommand) -> Result<()> {
    termid::output::check_file(&cmd.out)?;
    let model = termid::plugins::load(&cmd.model)?;
    let frames = crate::runs::load_for(&model, &cmd.data, cmd.dataset.as_deref())?;
    let diff = differentiator(&cmd.derivative)?;
    let moments = EquationMoments::of_runs(&model, &cmd.equation, &frames, diff.as_ref(), None)?;
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

/// `identify --moments`: the statistics files read, merged per equation (in the order given),
/// each equation identified from them and stored in the model.
pub fn identify(
    model: &termid::model::Model,
    files: &[std::path::PathBuf],
    intercept: bool,
) -> Result<(termid::model::Model, Vec<(String, termid::identify::Fit)>)> {
    let mut merged: Vec<EquationMoments> = Vec::new();
    for path in files {
        let text = termid::budget::read_text(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let m = EquationMoments::from_json(&text, &path.display().to_string())?;
        match merged.iter().position(|e| e.equation == m.equation) {
            Some(k) => {
                let old = merged.remove(k);
                merged.insert(k, old.merge(m).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?);
            }
            None => merged.push(m),
        }
    }
    let mut identified = model.clone();
    let mut fits = Vec::new();
    for m in &merged {
        let fit = m.fit(model, intercept).map_err(|e| e.in_equation(&m.equation))?;
        let coefficients = termid::identify::coefficients_of(&fit, &model.vocabulary)?;
        identified.set_coefficients(
            &m.equation,
            coefficients,
            fit.selection.intercept.as_ref().map(|b| b.value),
        );
        fits.push((m.equation.clone(), fit));
    }
    Ok((identified, fits))
}
