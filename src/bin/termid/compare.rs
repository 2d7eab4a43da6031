//! `termid compare`: every back-end on the same runs and equations, side by side: the terms
//! chosen, coefficients, R², standard error and time; with `--replay`, each back-end's model
//! re-simulated against a recorded run (any model: the recorded inputs are replayed).

use std::time::Instant;

use anyhow::{Context, Result};
use termid::data::{differentiator, Frame};
use termid::diagnose::{simulate_runs, Runs};
use termid::identify::{coefficients_of, equation_design, fit_equation_design, Fit};
use termid::select::Backend;

use crate::args::{CompareCommand, Format};
use termid::identify::num;

/// (state, RMS error, max error) of a re-simulation.
type StateErrors = Vec<(String, f64, f64)>;

struct Entry {
    backend: String,
    fits: Vec<(String, Fit, f64)>,
    replay: Option<Result<StateErrors, String>>,
}

/// The most timed repetitions and the longest warm-up `compare` takes: beyond them a
/// comparison would run for hours and tell no more.
const MAX_REPEAT: usize = 100_000;
const MAX_WARM_UP: f64 = 60.0;

pub fn run(cmd: CompareCommand) -> Result<()> {
    if !(0.0..=MAX_WARM_UP).contains(&cmd.warm_up) {
        anyhow::bail!(
            "--warm-up {}: give seconds from 0 to {MAX_WARM_UP} (the default 0.3 s wakes an idle core)",
            cmd.warm_up
        );
    }
    if !(1..=MAX_REPEAT).contains(&cmd.repeat) {
        anyhow::bail!(
            "--repeat {}: give 1 to {MAX_REPEAT} timed repetitions (the median of 5 is the default)",
            cmd.repeat
        );
    }
    if let Some(dt) = cmd.dt.filter(|dt| !(dt.is_finite() && *dt > 0.0)) {
        anyhow::bail!("--dt {dt}: the integration step must be a number of seconds > 0");
    }
    let model = crate::simulate::load_model(&cmd.model)?;
    let time = model.spec().model.time.clone();
    let frames = crate::runs::load_for(&model, &cmd.data, cmd.by.as_deref(), &cmd.dataset)?;
    crate::runs::warn_over_ground(&cmd.dataset);
    let equations: Vec<String> =
        if cmd.equation.is_empty() { model.identifiable() } else { cmd.equation.clone() };
    let diff = differentiator(&cmd.derivative)?;
    // read and checked before the fits: each back-end's replay would fail alike after the work
    let replay = cmd.replay.as_ref().map(|p| crate::runs::replay_frame(p, &time)).transpose()?;
    // the candidates are compiled once per equation, outside the timings, as the peers' design
    // matrix is built outside theirs
    let designs = equations
        .iter()
        .map(|eq| equation_design(&model, eq).with_context(|| format!("equation `{eq}`")))
        .collect::<Result<Vec<_>>>()?;
    let mut entries = Vec::new();
    for name in Backend::NAMES {
        // the model file's own settings for its back-end, defaults for the others
        let mut m = model.edit(|file| {
            for eq in &equations {
                if let Some(e) = file.equations.get_mut(eq) {
                    if e.backend.clone().unwrap_or_else(Backend::for_rates).name() != *name {
                        e.backend = Backend::by_name(name).ok();
                    }
                }
            }
        })?;
        let mut fits = Vec::new();
        for (eq, design) in equations.iter().zip(&designs) {
            // warm-up fits for `warm_up` seconds (at least one), then the median of `repeat`
            // timed fits (data already loaded)
            let fit_once =
                || fit_equation_design(&m, eq, Some(design), &frames, diff.as_ref(), !cmd.no_intercept, None);
            let fit = crate::progress::with_spinner(&format!("{name} on {eq}"), fit_once)
                .with_context(|| format!("{name} on `{eq}`"))?;
            let warming = Instant::now();
            while warming.elapsed().as_secs_f64() < cmd.warm_up {
                drop(fit_once());
            }
            let mut times: Vec<f64> = (0..cmd.repeat.max(1))
                .map(|_| {
                    let started = Instant::now();
                    let again = fit_once();
                    let t = started.elapsed().as_secs_f64() * 1e3;
                    drop(again);
                    t
                })
                .collect();
            times.sort_by(f64::total_cmp);
            let ms = times[times.len() / 2];
            let coefs = coefficients_of(&fit, &m.vocabulary)?;
            m.set_coefficients(eq, coefs, None);
            fits.push((eq.clone(), fit, ms));
        }
        let replay = replay.as_ref().map(|run| resimulate(&m, run, cmd.dt).map_err(|e| format!("{e:#}")));
        entries.push(Entry { backend: name.to_string(), fits, replay });
    }
    match cmd.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&json(&entries))?),
        Format::Text => print!("{}", text(&model, &entries, &equations)),
    }
    Ok(())
}

/// Replays the recorded inputs from the recorded initial state; RMS and max error per state.
fn resimulate(model: &termid::model::Model, run: &Frame, dt: Option<f64>) -> Result<StateErrors> {
    // the replay starts from the recorded state, so every state must have been measured
    for s in &model.spec().states {
        run.require(&s.name)?;
    }
    let (method, dt) = model.resimulation(None, dt, std::slice::from_ref(run));
    let runs = Runs::new(model, std::slice::from_ref(run), dt, method)?;
    let gap = runs.gap(&simulate_runs(&runs, model)?);
    Ok(gap.runs.into_iter().flat_map(|(_, states)| states).collect())
}

fn text(model: &termid::model::Model, entries: &[Entry], equations: &[String]) -> String {
    let mut out = String::new();
    for (k, eq) in equations.iter().enumerate() {
        out += &format!(
            "== {eq} ==\n{:<12} {:>6} {:>12} {:>12} {:>10}\n",
            "back-end", "terms", "R²", "std. error", "time [ms]"
        );
        for e in entries {
            let (_, fit, ms) = &e.fits[k];
            let s = &fit.selection;
            let st = s.chosen_step.checked_sub(1).and_then(|i| s.steps.get(i));
            out += &format!(
                "{:<12} {:>6} {:>12.8} {:>12} {:>10.3}\n",
                e.backend,
                s.terms.len(),
                st.map_or(f64::NAN, |st| st.r2),
                st.map_or("--".into(), |st| num(st.standard_error)),
                ms
            );
        }
        let mut terms: Vec<String> = Vec::new();
        for e in entries {
            for t in &e.fits[k].1.selection.terms {
                if !terms.contains(&t.term) {
                    terms.push(t.term.clone());
                }
            }
        }
        out += &format!("\n{:<18}", "coefficients");
        for e in entries {
            out += &format!(" {:>13}", e.backend);
        }
        out += "\n";
        for t in &terms {
            out += &format!("{t:<18}");
            for e in entries {
                let c = e.fits[k]
                    .1
                    .selection
                    .terms
                    .iter()
                    .find(|x| &x.term == t)
                    .map_or("--".to_string(), |x| num(x.coefficient));
                out += &format!(" {c:>13}");
            }
            out += "\n";
        }
        out += "\n";
    }
    if entries.iter().any(|e| e.replay.is_some()) {
        out += "re-simulation of the recorded run (RMS / max error per state):\n";
        for e in entries {
            match &e.replay {
                Some(Ok(errs)) => {
                    let cells: Vec<String> = errs
                        .iter()
                        .map(|(s, r, m)| crate::validate::error_cell(s, *r, *m, model.unit(s)))
                        .collect();
                    out += &format!("{:<12} {}\n", e.backend, cells.join(", "));
                }
                Some(Err(msg)) => out += &format!("{:<12} failed: {msg}\n", e.backend),
                None => {}
            }
        }
    }
    out
}

fn json(entries: &[Entry]) -> serde_json::Value {
    serde_json::Value::Array(
        entries
            .iter()
            .map(|e| {
                serde_json::json!({
                    "backend": e.backend,
                    "equations": e.fits.iter().map(|(eq, f, ms)| serde_json::json!({
                        "equation": eq,
                        "time_ms": ms,
                        "terms": f.selection.terms,
                        "intercept": f.selection.intercept,
                        "notes": f.selection.notes,
                    })).collect::<Vec<_>>(),
                    "replay": match &e.replay {
                        Some(Ok(v)) => serde_json::json!(v.iter().map(|(s, r, m)| serde_json::json!({"state": s, "rms": r, "max": m})).collect::<Vec<_>>()),
                        Some(Err(m)) => serde_json::json!({"error": m}),
                        None => serde_json::Value::Null,
                    },
                })
            })
            .collect(),
    )
}
