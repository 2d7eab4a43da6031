//! Measured runs from `--data` files (CSV, model names, SI) and/or a `--dataset` file (own
//! column names and units); every unit conversion is stated on standard error.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use termid::data::{check_gaps, Dataset, Frame};

pub fn load(data: &[PathBuf], dataset: Option<&Path>, time: &str) -> Result<Vec<Frame>> {
    let mut frames = data.iter().map(|p| Frame::read_csv(p, time)).collect::<Result<Vec<_>, _>>()?;
    for f in &frames {
        // a logging dropout would be differentiated across as if it were one step (dataset
        // files are checked as they are read, in their own column names)
        check_gaps(f, 3.0)?;
    }
    if let Some(path) = dataset {
        let ds = Dataset::load(path)?;
        let base = path.parent().unwrap_or(Path::new("."));
        let (more, notes) =
            ds.read(base, time).with_context(|| format!("reading the runs of {}", path.display()))?;
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
