//! `termid validate`: a model against held-out runs. Each run is simulated from its recorded
//! initial state with its recorded inputs; per run the error of every measured state, and for
//! ship models the manoeuvre metrics of measurement and model side by side; a figure per run.

use anyhow::Result;
use termid::diagnose::{comparison_figures, Runs};
use termid::ship::observed::{observe, Observed};
use termid::sim::{Integrator, Trajectory};

use crate::args::{Format, ValidateCommand};
use crate::identify::num;

pub fn run(cmd: ValidateCommand) -> Result<()> {
    let model = crate::simulate::load_model(&cmd.model)?;
    let time = model.spec.model.time.clone();
    let runs = crate::runs::load(&cmd.runs.data, cmd.runs.dataset.as_deref(), &time)?;
    let data = Runs::new(&model, &runs, cmd.resim.dt, Integrator::by_name(&cmd.resim.integrator)?)?
        .with_intercepts(cmd.resim.with_intercept);
    let sims = data.simulate(&model, &[], &[])?;
    let gap = data.gap(&sims);
    // ship models: metrics read off measurement and simulation alike
    let metrics: Vec<Option<(Observed, Observed)>> = match &model.spec.ship {
        Some(ship) => {
            let names = &ship.names;
            let canon = |n: &str| model.vocabulary.canonical(n).unwrap_or_else(|| n.to_string());
            let (psi, rudder, x0, y0) =
                (canon(&names.psi), canon(&names.rudder), canon(&names.x0), canon(&names.y0));
            runs.iter()
                .zip(&sims)
                .map(|(f, s)| {
                    let col = |n: &str| f.column(n);
                    let state = |t: &Trajectory, n: &str| t.state(n).map(<[f64]>::to_vec);
                    let (mp, md, mx, my) = (col(&psi)?, col(&rudder)?, col(&x0)?, col(&y0)?);
                    let measured = observe(f.time(), mp, md, mx, my);
                    let simulated = observe(&s.time, &state(s, &psi)?, md, &state(s, &x0)?, &state(s, &y0)?);
                    Some((measured, simulated))
                })
                .collect()
        }
        None => vec![None; runs.len()],
    };
    if let Some(dir) = &cmd.resim.svg {
        std::fs::create_dir_all(dir)?;
        for (k, (name, fig)) in comparison_figures(&runs, &sims, &[], "validate").into_iter().enumerate() {
            let stem = std::path::Path::new(&name)
                .file_stem()
                .map_or(format!("run{k}"), |s| s.to_string_lossy().into_owned());
            fig.write_svg(&dir.join(format!("validate_{stem}.svg")))?;
        }
    }
    match cmd.format {
        Format::Json => println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "gap": gap,
                "metrics": metrics.iter().zip(&runs).map(|(m, f)| serde_json::json!({
                    "run": f.origin(),
                    "measured": m.as_ref().map(|m| &m.0),
                    "simulated": m.as_ref().map(|m| &m.1),
                })).collect::<Vec<_>>(),
            }))?
        ),
        Format::Text => {
            println!(
                "{} against {} run(s): error of the simulation (model − measured), RMS / max",
                model.spec.model.name,
                runs.len()
            );
            for (run, per) in &gap.runs {
                let cells: Vec<String> =
                    per.iter().map(|(s, r, m)| format!("{s} {} / {}", num(*r), num(*m))).collect();
                println!("  {run}: {}", cells.join(", "));
            }
            for (m, f) in metrics.iter().zip(&runs) {
                let Some((a, b)) = m else { continue };
                println!("\n{}: metric, measured, model", f.origin());
                let row = |name: &str, x: Option<f64>, y: Option<f64>| {
                    if x.is_some() || y.is_some() {
                        let f = |v: Option<f64>| v.map_or("--".to_string(), num);
                        println!("  {name:<24} {:>12} {:>12}", f(x), f(y));
                    }
                };
                row("1st overshoot [°]", a.first_overshoot_deg, b.first_overshoot_deg);
                row("2nd overshoot [°]", a.second_overshoot_deg, b.second_overshoot_deg);
                row("advance [m]", a.advance_m, b.advance_m);
                row("transfer [m]", a.transfer_m, b.transfer_m);
                row("tactical diameter [m]", a.tactical_diameter_m, b.tactical_diameter_m);
            }
        }
    }
    Ok(())
}
