//! Measured runs from `--data` files (CSV, model names, SI) and/or a `--dataset` file (own
//! column names and units); every unit conversion is stated on standard error.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use termid::data::{check_gaps, Dataset, Frame};
use termid::model::Model;

/// The runs of a command with a model: as [`load`], then each dataset mapping checked to name
/// one of the model's variables and each run checked against the model's known kinematics.
pub fn load_for(model: &Model, data: &[PathBuf], dataset: Option<&Path>) -> Result<Vec<Frame>> {
    if let Some(path) = dataset {
        let ds = Dataset::load(path)?;
        let known = model.data_names();
        if let Some(var) = ds.columns.keys().find(|v| !known.contains(v)) {
            bail!(
                "{}: `columns.{var}` maps a column onto `{var}`, which is not a variable of {} (states, inputs, parameters: {})",
                path.display(),
                model.path,
                model.vocabulary.variables().iter().chain(model.vocabulary.parameters()).cloned().collect::<Vec<_>>().join(", ")
            );
        }
    }
    let mut frames = load(data, dataset, &model.spec().model.time)?;
    for f in &mut frames {
        for note in model.admit(f)? {
            eprintln!("unit: {note}");
        }
    }
    // a per-run rule that reads one sample of a noisy record: said once, for the first such run
    for (name, rule) in model.parameter_rules() {
        let noisy: Vec<String> = frames.iter().filter_map(|f| rule.noisy_first_sample(&name, f)).collect();
        if let Some(first) = noisy.first() {
            eprintln!("warning: {first} ({} of {} runs so)", noisy.len(), frames.len());
        }
    }
    Ok(frames)
}

pub fn load(data: &[PathBuf], dataset: Option<&Path>, time: &str) -> Result<Vec<Frame>> {
    let mut frames = data.iter().map(|p| Frame::read(p, time)).collect::<Result<Vec<_>, _>>()?;
    for f in &frames {
        // a logging dropout would be differentiated across as if it were one step (dataset
        // files are checked as they are read, in their own column names)
        check_gaps(f, 3.0)?;
    }
    if let Some(path) = dataset {
        let ds = Dataset::load(path)?;
        let (more, notes) = ds
            .read(&ds.folder(path)?, time)
            .with_context(|| format!("reading the runs of {}", path.display()))?;
        for n in notes {
            eprintln!("unit: {n}");
        }
        frames.extend(more);
    }
    if frames.is_empty() {
        bail!("no runs: give --data FILE… or --dataset FILE");
    }
    Ok(frames)
}
