//! A command's figures written as it writes them all: one SVG per run into the folder given,
//! named by the command and the run's file stem, with the command's other outputs at once.

use std::path::Path;

use anyhow::Result;
use termid::output::Outputs;
use termid::plot::Figure;

/// `figures` (run name, figure) into `dir` as `<command>_<stem>.svg` (a run without a stem
/// as `run<k>`), among `outputs`.
pub fn write(outputs: &mut Outputs, dir: &Path, command: &str, figures: Vec<(String, Figure)>) -> Result<()> {
    outputs.folder(dir)?;
    for (k, (name, fig)) in figures.into_iter().enumerate() {
        let stem =
            Path::new(&name).file_stem().map_or(format!("run{k}"), |s| s.to_string_lossy().into_owned());
        let svg = fig.to_svg().map_err(anyhow::Error::msg)?;
        outputs.file(&dir.join(format!("{command}_{stem}.svg")), svg.as_bytes())?;
    }
    Ok(())
}
