//! `termid simulate`: a model file (the default ship if none) under a manoeuvre, constant
//! inputs or replayed inputs → CSV, metrics, and on request an SVG figure.

use std::collections::BTreeMap;

use anyhow::{bail, Context, Result};
use termid::model::Model;
use termid::plot::{Figure, Panel, Series};
use termid::plugin::{Plugin, ScenarioRequest};
use termid::sim::{simulate, Constant, Controller, Integrator, Replay, Settings};

use crate::args::{Format, SimulateCommand};
use crate::monte_carlo::Draws;
use termid::identify::sig;

pub fn load_model(path: &Option<std::path::PathBuf>) -> Result<Model> {
    let model = match path {
        Some(p) => termid::plugins::load(p)?,
        None => termid::plugins::default_model(),
    };
    // a model counted in days is simulated in days, its rates per second; a rate declared per
    // hour is read per second: said
    for note in model.load_notes() {
        crate::runs::say(&note);
    }
    Ok(model)
}

pub fn run(cmd: SimulateCommand) -> Result<()> {
    // outputs that cannot be written are refused before any work
    for path in cmd.out.iter().chain(&cmd.svg) {
        termid::output::check_file(path)?;
    }
    let mut inputs: Vec<(String, std::path::PathBuf)> =
        cmd.model.iter().map(|m| ("--model".into(), m.clone())).collect();
    if let Some(file) = cmd.manoeuvre.as_deref().and_then(|m| m.strip_prefix("replay:")) {
        inputs.push((format!("the replayed file {file}"), file.into()));
    }
    let outputs: Vec<(&str, &std::path::Path)> = cmd
        .out
        .iter()
        .map(|p| ("--out", p.as_path()))
        .chain(cmd.svg.iter().map(|p| ("--svg", p.as_path())))
        .collect();
    crate::runs::check_outputs(&outputs, &inputs)?;
    for (flag, list) in [("--param", &cmd.params), ("--initial", &cmd.initial), ("--input", &cmd.inputs)] {
        crate::runs::check_names_once(flag, list)?;
    }
    if let Some(d) = cmd.duration {
        if !(d.is_finite() && d > 0.0) {
            bail!("--duration {d}: a simulation lasts a positive number of seconds");
        }
        if let Some(dt) = cmd.dt.filter(|dt| dt.is_finite() && *dt > d) {
            bail!("--dt {dt} is longer than --duration {d}: not one step would be taken");
        }
    }
    let mut model = load_model(&cmd.model)?;
    set_parameters(&mut model, &cmd.params)?;
    model.set_tolerances(cmd.rtol, cmd.atol)?;
    // a model counted in days (an epidemic's) is simulated for days, sampled in days, as its
    // run's time column is written
    let per = model.seconds_per_time();
    let cmd = SimulateCommand {
        duration: cmd.duration.map(|d| d * per),
        sample: cmd.sample * per,
        dt: cmd.dt.map(|d| d * per),
        ..cmd
    };
    // the command's method and step, else the model file's, else dopri5 at 0.04 s
    let (integrator, step) = model.simulation(cmd.integrator, None);
    // the adaptive method's accuracy does not hang on the control step: an output interval
    // that is no whole multiple of it (finer, or 0.05 s beside 0.04 s) makes it the largest
    // step at most as long that divides the interval, rather than an error
    let dt = match cmd.dt {
        Some(dt) => dt,
        None if integrator.is_adaptive() && cmd.sample.is_finite() && cmd.sample > 0.0 => {
            let every = (cmd.sample / step * (1.0 - 1e-9)).ceil().max(1.0);
            cmd.sample / every
        }
        None => step,
    };
    match (&cmd.manoeuvre, termid::plugins::of(&model)) {
        (Some(m), Some(plugin)) => {
            // a model that fails what its field knows is simulated, but not silently
            for c in plugin.checks(&model, &[]).iter().filter(|c| !c.passed && c.refuses) {
                eprintln!("warning: {} fails a physical check: {}", model.path, c.line());
            }
            scenario_run(&cmd, &model, plugin, m, (integrator, dt))
        }
        (Some(m), None) if !m.starts_with("replay:") => {
            let tables: Vec<String> =
                termid::plugins::PLUGINS.iter().map(|p| format!("[{}]", p.table())).collect();
            bail!(
                "{} has no plug-in table ({}), so `{m}` does not apply; use --input NAME=VALUE or --manoeuvre replay:FILE.csv",
                model.path,
                tables.join(", ")
            )
        }
        _ => generic_run(&cmd, &model, (integrator, dt)),
    }
}

/// `--param NAME=VALUE`: a parameter of the model, or a value of its plug-in's table (a
/// ship's `u0` is both). Unknown names are refused.
fn set_parameters(model: &mut Model, params: &[String]) -> Result<()> {
    for p in params {
        let (name, value) = p.split_once('=').with_context(|| format!("--param `{p}` must be NAME=VALUE"))?;
        let (name, text) = (name.trim(), value.trim());
        let value = finite(text, || format!("--param `{p}`"))?;
        let mut known = model.set_parameter(name, value);
        if let Some(plugin) = termid::plugins::of(model) {
            known |= plugin.set_parameter(model, name, value)?;
        }
        if !known {
            let names: Vec<&str> = model.spec().parameters.keys().map(String::as_str).collect();
            bail!(
                "--param {name}: not a parameter of {} (parameters: {})",
                model.path,
                if names.is_empty() { "none".into() } else { names.join(", ") }
            );
        }
    }
    Ok(())
}

/// A finite number from the command line (`nan` and `inf` parse as f64 but are no values).
fn finite(text: &str, what: impl FnOnce() -> String) -> Result<f64> {
    let text = text.trim();
    text.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .with_context(|| format!("{}: `{text}` is not a finite number", what()))
}

/// A plug-in's scenario (a ship manoeuvre): the nominal run, Monte-Carlo draws on request,
/// the CSV and figure, and the plug-in's report.
fn scenario_run(
    cmd: &SimulateCommand,
    model: &Model,
    plugin: &dyn Plugin,
    text: &str,
    (integrator, dt): (Integrator, f64),
) -> Result<()> {
    let request = ScenarioRequest {
        text,
        with_intercept: cmd.with_intercept,
        initial_given: !cmd.initial.is_empty(),
        inputs_given: !cmd.inputs.is_empty(),
    };
    let scenario = plugin.scenario(model, &request)?;
    let settings = Settings {
        integrator,
        dt,
        duration: cmd.duration.unwrap_or_else(|| scenario.default_duration()),
        sample: cmd.sample,
    };
    let run = scenario.run(model, &settings)?;
    let mc = match cmd.monte_carlo.monte_carlo {
        0 => None,
        n => Some(Draws::run(model, n, cmd.monte_carlo.seed, trajectory_values(&run.trajectory), |m| {
            let drawn = scenario.run(m, &settings)?;
            Ok((drawn.metrics, drawn.trajectory))
        })?),
    };
    // what the draws' spread comes from: each free parameter one sd up and down
    let effects = crate::monte_carlo::parameter_effects(model, mc.is_some(), |m| {
        Ok(scenario.run(m, &settings)?.metrics)
    });
    let mut outputs = termid::output::Outputs::new();
    if let Some(out) = &cmd.out {
        outputs.file(out, run.frame.to_csv().as_bytes())?;
    }
    if let Some(svg) = &cmd.svg {
        let title = format!("{}: {}", model.spec().model.name, scenario.label());
        let draws: Vec<&_> = mc.iter().flat_map(|mc| mc.shown().iter().map(|(_, t)| t)).collect();
        let fig = scenario.figure(&title, &run, &draws);
        outputs.file(svg, fig.to_svg().map_err(anyhow::Error::msg)?.as_bytes())?;
    }
    outputs.commit()?;
    match cmd.format {
        Format::Json => {
            let mut report = serde_json::Map::new();
            report.insert("model".into(), model.path.clone().into());
            report.insert("manoeuvre".into(), scenario.label().into());
            report.insert("integrator".into(), integrator.name().into());
            report.insert("dt".into(), dt.into());
            report.extend(run.extra.clone());
            report.insert("metrics".into(), run.metrics.clone());
            report.insert(
                "monte_carlo".into(),
                serde_json::to_value(mc.as_ref().map(|mc| mc.summary(&mc.spread(|r| vec![r.0.clone()]))))?,
            );
            // each metric's linearised sd and the share of it each parameter would remove
            let (effects, from) = crate::monte_carlo::effects_json(model, &effects, &run.metrics);
            report.insert("parameter_effects".into(), effects);
            report.insert("spread_from".into(), from);
            println!("{}", serde_json::to_string_pretty(&report)?)
        }
        Format::Text => {
            println!("{} — {}", model.spec().model.name, scenario.label());
            for line in &run.text {
                println!("{line}");
            }
            if let Some(mc) = &mc {
                let spread = mc.spread(|r| vec![r.0.clone()]);
                print!("{}", mc.text(&spread, &run.metrics));
                print!("{}", crate::monte_carlo::effects_text(model, &effects, &spread));
            }
            if let Some(out) = &cmd.out {
                println!("wrote {} ({} rows; SI units, angles in rad)", out.display(), run.frame.len());
            }
        }
    }
    Ok(())
}

/// A run's final states as the Monte-Carlo table's metrics (`final x`, …).
fn final_states(system: &termid::sim::System, run: &termid::sim::Trajectory) -> serde_json::Value {
    let last = run.last_state();
    serde_json::Value::Object(
        system.states.iter().zip(&last).map(|(s, v)| (format!("final {s}"), (*v).into())).collect(),
    )
}

/// The values a trajectory holds (time, states, inputs, derivatives), for the memory check of
/// Monte-Carlo draws that keep one each.
pub fn trajectory_values(t: &termid::sim::Trajectory) -> usize {
    t.time.len() * (1 + t.states.len() + t.inputs.len() + t.derivatives.len())
}

fn generic_run(cmd: &SimulateCommand, model: &Model, (integrator, dt): (Integrator, f64)) -> Result<()> {
    let per = model.seconds_per_time();
    let system = termid::sim::System::new(model, &BTreeMap::new(), cmd.with_intercept)?;
    let mut x0: Vec<f64> = system
        .states
        .iter()
        .map(|s| model.spec().states.iter().find(|t| &t.name == s).map_or(0.0, |t| t.initial))
        .collect();
    for p in &cmd.initial {
        let (k, v) = p.split_once('=').with_context(|| format!("--initial `{p}` must be NAME=VALUE"))?;
        let name = model.vocabulary.canonical(k.trim()).unwrap_or_else(|| k.trim().to_string());
        let i = system.state_index(&name).with_context(|| format!("--initial: `{k}` is not a state"))?;
        x0[i] = finite(v, || format!("--initial `{p}`"))?;
    }
    let mut inputs: Vec<f64> = model.spec().inputs.iter().map(|i| i.initial).collect();
    for p in &cmd.inputs {
        let (k, v) = p.split_once('=').with_context(|| format!("--input `{p}` must be NAME=VALUE"))?;
        let name = model.vocabulary.canonical(k.trim()).unwrap_or_else(|| k.trim().to_string());
        let i = system.input_index(&name).with_context(|| format!("--input: `{k}` is not an input"))?;
        inputs[i] = finite(v, || format!("--input `{p}`"))?;
    }
    let replayed = cmd
        .manoeuvre
        .as_deref()
        .and_then(|m| m.strip_prefix("replay:"))
        .map(|file| -> Result<termid::data::Frame> {
            let mut frame = crate::runs::replay_frame(std::path::Path::new(file), &model.spec().model.time)?;
            // an input held between samples in the record is held in the replay (one with a
            // dead time judged as it acts)
            let inputs: Vec<&str> = system.inputs.iter().map(String::as_str).collect();
            let intersample = model.spec().model.intersample;
            let states: Vec<&str> = system.states.iter().map(String::as_str).collect();
            let mut notes = termid::data::mark_held_acting(
                &mut frame,
                &inputs,
                &model.dead_times(),
                &model.first_order_lags(),
                &states,
                intersample,
            )?;
            // and one that repeats a slower sensor's readings, read at them
            notes.extend(termid::data::read_at_readings(&mut frame, &inputs, intersample)?);
            notes.iter().for_each(|n| crate::runs::say(n));
            Ok(frame)
        })
        .transpose()?;
    // the default absolute tolerance counted in how large the states start
    let sizes = model.sizes(&x0.iter().map(|v| v.abs()).collect::<Vec<_>>());
    let sized = |mut system: termid::sim::System| {
        system.sizes = sizes.clone();
        system
    };
    let system = sized(system);
    let controller = |system: &termid::sim::System| -> Result<Box<dyn Controller>> {
        Ok(match &replayed {
            Some(frame) => Box::new(Replay::new(frame, &system.inputs)?),
            None => Box::new(Constant(inputs.clone())),
        })
    };
    // a replay lasts as long as its recording; constant inputs have no natural end
    let recorded = replayed.as_ref().map(|f| f.duration());
    let duration = cmd.duration.or(recorded).context(
        "give a manoeuvre (-m zigzag:20/20, -m turning:35, -m spiral, -m replay:FILE.csv; each has its own length) or --duration SECONDS for the model under constant inputs (--input NAME=VALUE), which has no natural end",
    )?;
    let settings = Settings { integrator, dt, duration, sample: cmd.sample };
    let traj = simulate(&system, &x0, controller(&system)?.as_mut(), &settings)?;
    // drawn models, simulated as the nominal one: a band per state and the final states' spread
    let mc = match cmd.monte_carlo.monte_carlo {
        0 => None,
        n => Some(Draws::run(model, n, cmd.monte_carlo.seed, trajectory_values(&traj), |m| {
            let system = sized(termid::sim::System::new(m, &BTreeMap::new(), cmd.with_intercept)?);
            let t = simulate(&system, &x0, controller(&system)?.as_mut(), &settings)?;
            Ok((final_states(&system, &t), t))
        })?),
    };
    let effects = crate::monte_carlo::parameter_effects(model, mc.is_some(), |m| {
        let system = sized(termid::sim::System::new(m, &BTreeMap::new(), cmd.with_intercept)?);
        let t = simulate(&system, &x0, controller(&system)?.as_mut(), &settings)?;
        Ok(final_states(&system, &t))
    });
    let frame = traj.to_frame("simulation", &model.spec().model.time)?;
    let mut outputs = termid::output::Outputs::new();
    if let Some(out) = &cmd.out {
        outputs.file(out, frame.to_csv().as_bytes())?;
    }
    if let Some(svg) = &cmd.svg {
        let panels = system
            .states
            .iter()
            .enumerate()
            .map(|(i, s)| Panel {
                title: s.clone(),
                // time in seconds, or in the unit the model's time is named by (`day`) as
                // its run's column; each state by its name and unit
                x_label: match per == 1.0 {
                    true => termid::plot::labelled(&model.spec().model.time, "s"),
                    false => model.spec().model.time.clone(),
                },
                y_label: termid::plot::labelled(
                    s,
                    Some(model.unit(s)).filter(|u| !u.is_empty()).unwrap_or("-"),
                ),
                series: {
                    let time: Vec<f64> = traj.time.iter().map(|t| t / per).collect();
                    let mut series = vec![Series::line(s, time.clone(), traj.states[i].clone())];
                    if let Some(mc) = mc.as_ref().filter(|mc| mc.usable()) {
                        let signals: Vec<Vec<f64>> =
                            mc.shown().iter().map(|(_, t)| t.states[i].clone()).collect();
                        let (lo, hi) = termid::uncertainty::band(&signals);
                        let label = format!("90 % band ({} draws)", signals.len());
                        series.insert(0, Series::band(&label, time, lo, hi));
                    }
                    series
                },
                ..Panel::default()
            })
            .collect();
        let svg_text = Figure::new(&model.spec().model.name, panels).to_svg().map_err(anyhow::Error::msg)?;
        outputs.file(svg, svg_text.as_bytes())?;
    }
    outputs.commit()?;
    let last = traj.last_state();
    let nominal = final_states(&system, &traj);
    let spread = mc.as_ref().map(|mc| mc.spread(|r| vec![r.0.clone()]));
    match cmd.format {
        Format::Json => {
            let (effects, from) = crate::monte_carlo::effects_json(model, &effects, &nominal);
            println!(
                "{}",
                serde_json::to_string_pretty(&serde_json::json!({
                    "model": model.path,
                    "samples": traj.time.len(),
                    "final_state": system.states.iter().zip(&last).map(|(s, v)| (s.clone(), *v)).collect::<BTreeMap<_, _>>(),
                    "monte_carlo": mc.as_ref().zip(spread.as_ref()).map(|(mc, s)| mc.summary(s)),
                    "parameter_effects": effects,
                    "spread_from": from,
                    "stiff_from": traj.stiff_from,
                }))?
            )
        }
        Format::Text => {
            let end = traj.time.last().copied().unwrap_or(0.0);
            let to = match per == 1.0 {
                true => format!("t = {end} s"),
                false => format!("{} = {} ({} s)", model.spec().model.time, sig(end / per, 6), sig(end, 6)),
            };
            println!("{}: {} samples to {to}", model.spec().model.name, traj.time.len());
            for (s, v) in system.states.iter().zip(&last) {
                println!("  {s} = {}", termid::identify::sig(*v, 6));
            }
            if let Some(note) = traj.stiff_note() {
                println!("note: {note}");
            }
            if let Some((mc, spread)) = mc.as_ref().zip(spread.as_ref()) {
                print!("{}", mc.text(spread, &nominal));
                print!("{}", crate::monte_carlo::effects_text(model, &effects, spread));
            }
            if let Some(out) = &cmd.out {
                println!("wrote {}", out.display());
            }
        }
    }
    Ok(())
}
