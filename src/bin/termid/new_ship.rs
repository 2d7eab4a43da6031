//! `termid new-ship`: a grey-box MMG model file for a ship from its main particulars, each
//! parameter's estimate and source printed.

use anyhow::{Context, Result};
use termid::ship::particulars::Particulars;

use crate::args::NewShipCommand;

pub fn run(cmd: NewShipCommand) -> Result<()> {
    termid::output::check_file(&cmd.out)?;
    crate::runs::check_outputs(
        &[("--out", cmd.out.as_path())],
        &[("--particulars".to_string(), cmd.particulars.clone())],
    )?;
    let text = termid::budget::read_text(&cmd.particulars)
        .with_context(|| format!("reading {}", cmd.particulars.display()))?;
    let particulars = Particulars::parse(&text, &cmd.particulars.display().to_string())?;
    let model = particulars.model().with_context(|| format!("{}", cmd.particulars.display()))?;
    println!("== {}: the MMG model's parameters from the particulars ==", particulars.name);
    println!("{:<8} {:>14} {:>12}  source", "name", "estimate", "prior sd");
    let free = model.free_parameters();
    for e in particulars.estimates() {
        let sd = free.iter().find(|p| p.name == e.name).and_then(|p| p.prior).map(|(_, sd)| sd);
        println!(
            "{:<8} {:>14} {:>12}  {}",
            e.name,
            termid::identify::num(e.value),
            sd.map_or("fixed".into(), termid::identify::num),
            e.source
        );
    }
    for caution in particulars.cautions() {
        eprintln!("caution: {caution}");
    }
    termid::output::write_file(&cmd.out, model.to_toml().as_bytes())?;
    let medium = model.held_medium();
    println!(
        "wrote {} ({} free parameters): `termid estimate --model {} --dataset …` fits them to the ship's runs{}",
        cmd.out.display(),
        free.len(),
        cmd.out.display(),
        if medium.is_empty() {
            String::new()
        } else {
            format!(
                ", and a current ({}, held at 0) with them where the runs are tracked by satellite fixes",
                medium.join(", ")
            )
        }
    );
    Ok(())
}
