//! `termid validate`: a model against held-out runs. Each run is simulated from its recorded
//! initial state with its recorded inputs; per run the error of every measured state, and for
//! a plug-in's models (ships) its metrics of measurement and model side by side; a figure per run.

use anyhow::Result;
use termid::diagnose::Runs;
use termid::plot::{comparison_figures, LABELS};
use termid::plugin::Observation;
use termid::sim::Trajectory;

use termid::model::dimension::shown;

use crate::args::{Format, ValidateCommand};
use crate::monte_carlo::Draws;
use termid::identify::sig;

pub fn run(cmd: ValidateCommand) -> Result<()> {
    if let Some(dir) = &cmd.resim.svg {
        termid::output::check_folder(dir)?;
    }
    let mut model = crate::simulate::load_model(&cmd.model)?;
    model.set_tolerances(cmd.resim.rtol, cmd.resim.atol)?;
    let (runs, sources) =
        crate::runs::load_sources(&model, &cmd.runs.data, cmd.runs.by.as_deref(), &cmd.runs.dataset)?;
    // runs tracked over ground: the day's current is theirs, not the model's
    let current = crate::runs::medium_of_runs(&model, &runs, &sources, &cmd.runs.dataset, &cmd.runs.hold)?;
    let current: Vec<(usize, &str, f64)> = current.iter().map(|(r, n, v)| (*r, n.as_str(), *v)).collect();
    let (integrator, dt) = model.resimulation(cmd.resim.integrator, cmd.resim.dt, &runs);
    let data = Runs::new(&model, &runs, dt, integrator)?
        .with_intercepts(cmd.resim.with_intercept)
        .with_initial(&[], &current);
    let sims = data.simulate(&model, &[], &[])?;
    let gap = data.gap(&sims);
    // how long each run is predictable at all: beyond it any model's errors are of its size
    let horizon = data.horizon(&model, &sims);
    // a plug-in's models: its metrics read off measurement and simulation alike
    let plugin = termid::plugins::of(&model);
    let observe = |f: &termid::data::Frame, s: Option<&Trajectory>| plugin?.observe(&model, f, s);
    let metrics: Vec<Option<(Observation, Observation)>> =
        runs.iter().zip(&sims).map(|(f, s)| Some((observe(f, None)?, observe(f, Some(s))?))).collect();
    // Monte Carlo: every run simulated with each drawn model, its metrics read once per draw
    let mc = match cmd.monte_carlo.monte_carlo {
        0 => None,
        n => Some(Draws::run(
            &model,
            n,
            cmd.monte_carlo.seed,
            sims.iter().map(crate::simulate::trajectory_values).sum(),
            |m| {
                let sims = data.simulate(m, &[], &[])?;
                let seen: Vec<Option<serde_json::Value>> =
                    runs.iter().zip(&sims).map(|(f, s)| observe(f, Some(s)).map(|o| o.json)).collect();
                Ok((sims, seen))
            },
        )?),
    };
    let spreads: Vec<_> = (0..runs.len())
        .map(|k| mc.as_ref().map(|mc| mc.spread(|(_, seen)| seen[k].iter().cloned().collect())))
        .collect();
    if let Some(dir) = &cmd.resim.svg {
        let mut outputs = termid::output::Outputs::new();
        let plane = termid::plugins::of(&model).and_then(|p| p.plane(&model));
        let draws: Vec<&[Trajectory]> =
            mc.iter().flat_map(|mc| mc.shown().iter().map(|(sims, _)| sims.as_slice())).collect();
        let figures =
            comparison_figures(&model, &runs, (&sims, &[]), &draws, ("validate", LABELS), plane.as_ref());
        crate::figures::write(&mut outputs, dir, "validate", figures)?;
        outputs.commit()?;
    }
    // whether each measured metric lies outside the model's own 90 % band (none: no band)
    let outside_band = |k: usize, key: &str, x: Option<f64>| -> Option<bool> {
        let sp = spreads[k].as_ref()?.get(key)?;
        x.map(|x| sp.outside(x))
    };
    // (run, metric) of every banded metric, and whether it fell outside
    let verdicts: Vec<(String, String, bool)> = metrics
        .iter()
        .enumerate()
        .filter_map(|(k, m)| m.as_ref().map(|(a, _)| (k, a)))
        .flat_map(|(k, a)| {
            let run = termid::diagnose::file_name(runs[k].origin());
            a.rows
                .iter()
                .filter_map(|(name, key, x)| {
                    outside_band(k, key, *x).map(|off| (run.clone(), name.clone(), off))
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let outside: Vec<String> =
        verdicts.iter().filter(|v| v.2).map(|(run, name, _)| format!("{name} of {run}")).collect();
    let within = verdicts.len() - outside.len();
    match cmd.format {
        Format::Json => println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "gap": gap,
                "metrics": metrics.iter().zip(&runs).zip(&spreads).map(|((m, f), s)| serde_json::json!({
                    "run": f.origin(),
                    "measured": m.as_ref().map(|m| &m.0.json),
                    "simulated": m.as_ref().map(|m| &m.1.json),
                    "monte_carlo": mc.as_ref().zip(s.as_ref()).map(|(mc, s)| mc.summary(s)),
                })).collect::<Vec<_>>(),
                "predictable_for": runs.iter().zip(&horizon).map(|(f, h)| serde_json::json!({
                    "run": f.origin(),
                    "seconds": h.map(|k| f.since_start(k)),
                })).collect::<Vec<_>>(),
                "within_band": (!verdicts.is_empty()).then(|| serde_json::json!({
                    "within": within,
                    "outside": outside,
                })),
            }))?
        ),
        Format::Text => {
            println!(
                "{} against {} run(s): error of the simulation (model − measured), RMS / max",
                model.spec().model.name,
                runs.len()
            );
            // each state in its unit, angles in degrees
            for (run, per) in &gap.runs {
                let cells: Vec<String> =
                    per.iter().map(|(s, r, m)| error_cell(s, *r, *m, model.unit(s))).collect();
                println!("  {run}: {}", cells.join(", "));
            }
            // each run's errors before it parts from itself (a sample at least)
            let first: Vec<Option<usize>> = horizon.iter().map(|k| k.map(|k| k.max(1))).collect();
            let early = data.run_gaps(&sims, &first);
            for ((f, k), (_, per)) in runs.iter().zip(&horizon).zip(&early) {
                let Some(k) = *k else { continue };
                let (t, end) = (f.since_start(k), f.duration());
                let cells: Vec<String> =
                    per.iter().map(|(s, r, m)| error_cell(s, *r, *m, model.unit(s))).collect();
                println!(
                    "  note: {} is predictable for {} s of its {} s: a start {} of each state's spread \
                     off parts from the model's own run by {} of a spread there (a chaotic or \
                     strongly unstable motion), so later errors are of that size whatever the \
                     model; over the first {} s: {}",
                    f.origin(),
                    sig(t, 3),
                    sig(end, 3),
                    sig(termid::diagnose::PERTURBATION, 1),
                    sig(termid::diagnose::PARTED, 1),
                    sig(t, 3),
                    cells.join(", ")
                );
            }
            for (k, ((m, f), s)) in metrics.iter().zip(&runs).zip(&spreads).enumerate() {
                let Some((a, b)) = m else { continue };
                let band = if s.is_some() { "   model 5 % … 95 %" } else { "" };
                println!("\n{}: metric, measured, model{band}", f.origin());
                for ((name, key, x), (_, _, y)) in a.rows.iter().zip(&b.rows) {
                    if x.is_none() && y.is_none() {
                        continue;
                    }
                    // at the decimals the metric's unit supports (0.01°, 0.01 s)
                    let (_, _, d) = termid::plugin::metric_label(key);
                    let shown = |v: Option<f64>| v.map_or("--".to_string(), |v| format!("{v:.d$}"));
                    let spread = s.as_ref().and_then(|s| s.get(key)).map_or(String::new(), |sp| {
                        let mark =
                            if outside_band(k, key, *x) == Some(true) { "   measured outside" } else { "" };
                        format!("   {:.d$} … {:.d$}{mark}", sp.p05, sp.p95)
                    });
                    println!("  {name:<24} {:>12} {:>12}{spread}", shown(*x), shown(*y));
                }
            }
            if !verdicts.is_empty() {
                // a 90 % band leaves one measurement in ten outside by chance
                println!(
                    "\nmeasured within the model's 90 % band: {within} of {} metrics{}",
                    verdicts.len(),
                    if outside.is_empty() {
                        String::new()
                    } else {
                        format!(" (outside: {})", outside.join("; "))
                    }
                );
            }
            if let Some(note) = metrics.iter().flatten().find_map(|(a, _)| a.note.as_ref()) {
                println!("\nNote: {note}.");
            }
            if let Some(mc) = &mc {
                println!("\n{}", mc.headline());
                if let Some(why) = mc.refusal() {
                    println!("  warning: {why}");
                }
            }
        }
    }
    Ok(())
}

/// One state's error, RMS / max, in its unit with angles in degrees: `ψ 1.55 / 2.74 °`.
pub fn error_cell(state: &str, rms: f64, max: f64, unit: &str) -> String {
    let (factor, unit) = shown(unit);
    format!("{state} {} / {} {unit}", sig(rms * factor, 3), sig(max * factor, 3)).trim_end().to_string()
}
