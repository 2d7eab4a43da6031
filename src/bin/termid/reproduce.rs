//! `termid reproduce`: Oltmann (1973) end to end from the default model, into a folder with
//! report.md, SVG figures, CSV tables and data, and summary.json; a summary on the terminal.

use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use termid::ship::oltmann::{self, data::AccelerationTiming, data::RateUnit, report, Options};
use termid::ship::Ship;

use crate::args::ReproduceCommand;

pub fn run(cmd: ReproduceCommand) -> Result<()> {
    let started = Instant::now();
    let model = crate::simulate::load_model(&cmd.model)?;
    let options = Options {
        timing: if cmd.rudder_at_end_of_step {
            AccelerationTiming::RudderAtTPlusDt
        } else {
            AccelerationTiming::RudderAtT
        },
        rate_unit: if cmd.round_rates_in_radians { RateUnit::Radians } else { RateUnit::Degrees },
    };
    let bar = ProgressBar::new(11);
    bar.set_style(
        ProgressStyle::with_template("{elapsed:>4} [{bar:30}] {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let mut stage = |msg: &str| {
        bar.inc(1);
        bar.set_message(msg.to_string());
    };
    // a folder that will not take the output, or holds anything termid did not write there,
    // is refused before the work
    termid::output::check_replaceable(&cmd.out)?;
    let study = oltmann::run(&model, &options, &mut stage).context("reproducing Oltmann (1973)")?;
    let ship = Ship::new(&model, false)?;
    // built beside the target and swapped in whole: a failure, or another run at the same
    // time, never leaves a folder of mixed or partial files
    termid::output::replace_folder(&cmd.out, |dir| -> Result<()> {
        report::write(&study, &ship, dir, &mut stage)
            .with_context(|| format!("writing {}", cmd.out.display()))?;
        Ok(())
    })?;
    let path = cmd.out.join("report.md");
    bar.finish_and_clear();

    // the embedded model unless --model named a file: a path that need not exist here
    let from = if std::path::Path::new(&model.path).exists() {
        model.path.clone()
    } else {
        format!("the embedded {}", model.path)
    };
    println!("Oltmann (1973) reproduced from {from} in {:.1} s", started.elapsed().as_secs_f64());
    println!("straight run: δ0 = {:.3}°\n", study.delta0_deg);
    println!(
        "chosen step of the 30°/10° run and of the five runs combined (Komb), exact and alternative 5 data:"
    );
    println!("{:<8} {:>16} {:>16}   Komb terms (alternative 5)", "", "exact", "alternative 5");
    for (e, a) in study.exact.iter().zip(&study.alt5) {
        println!(
            "{:<8} {:>16} {:>16}   {}",
            e.equation,
            format!("{}, {}", e.runs[3].selection.chosen_step, e.komb.selection.chosen_step),
            format!("{}, {}", a.runs[3].selection.chosen_step, a.komb.selection.chosen_step),
            a.komb.selection.terms.iter().map(|t| t.term.as_str()).collect::<Vec<_>>().join(", ")
        );
    }
    println!("\nreplayed zigzags, heading error (max / at 100 s):");
    for r in &study.resimulations {
        match &r.failure {
            Some(f) => println!("  {:<7} {:<18} failed: {f}", r.run, r.coefficients),
            None => println!(
                "  {:<7} {:<18} {:>7.2}° / {:>7.2}°",
                r.run, r.coefficients, r.errors.psi_max_deg, r.errors.psi_final_deg
            ),
        }
    }
    for d in &study.drift {
        let at = |v: &[oltmann::Resimulation]| {
            v.iter().map(|r| format!("{:.1}°", r.errors.psi_final_deg)).collect::<Vec<_>>().join(", ")
        };
        println!(
            "\nheading drift with {} coefficients: {} → {} after adding B0 = {:.5}, C0 = {:.5} (true −0.0000, −0.0014)",
            d.coefficients,
            at(&d.before),
            at(&d.after),
            d.b0,
            d.c0
        );
    }
    if let Some(d) = &study.diagnosis {
        match d.winner {
            Some(w) => println!(
                "\ntermid diagnose on the alternative-5 model: {} ({}), explains {:.1} % of the gap",
                d.candidates[w].name,
                d.candidates[w].estimate.iter().map(|v| format!("{v:.5}")).collect::<Vec<_>>().join(", "),
                100.0 * d.candidates[w].explained
            ),
            None => println!("\ntermid diagnose on the alternative-5 model: no significant effect"),
        }
    }
    println!("\nreport: {}", path.display());
    Ok(())
}
