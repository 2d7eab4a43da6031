//! `termid simulate`: a model file (the default ship if none) under a manoeuvre, constant
//! inputs or replayed inputs → CSV, metrics, and on request an SVG figure.

use std::collections::BTreeMap;

use anyhow::{bail, Context, Result};
use termid::data::Frame;
use termid::model::Model;
use termid::plot::{Figure, Panel, Series};
use termid::ship::{
    figure::{add_bands, manoeuvre_figure},
    Manoeuvre, Ship,
};
use termid::sim::{simulate, Constant, Controller, Integrator, Replay, Settings};

use crate::args::{Format, SimulateCommand};
use crate::monte_carlo::Draws;

pub fn load_model(path: &Option<std::path::PathBuf>) -> Result<Model> {
    Ok(match path {
        Some(p) => Model::load(p)?,
        None => Model::default_model(),
    })
}

pub fn run(cmd: SimulateCommand) -> Result<()> {
    // outputs that cannot be written are refused before any work
    for path in cmd.out.iter().chain(&cmd.svg) {
        termid::output::check_file(path)?;
    }
    let mut model = load_model(&cmd.model)?;
    set_parameters(&mut model, &cmd.params)?;
    let integrator = Integrator::by_name(&cmd.integrator)?;
    match (&cmd.manoeuvre, model.spec.ship.is_some()) {
        (Some(m), true) => {
            // a manoeuvre starts from the straight approach and drives the rudder itself
            if !cmd.initial.is_empty() {
                bail!("--initial does not apply to a ship manoeuvre: it starts from the straight approach at u0 (set it with --param u0=…), v and δ of the straight run, r = ψ = 0");
            }
            if !cmd.inputs.is_empty() {
                bail!("--input does not apply to a ship manoeuvre: the manoeuvre drives the rudder; for recorded inputs use --manoeuvre replay:FILE.csv");
            }
            ship_run(&cmd, &model, m, integrator)
        }
        (Some(m), false) if !m.starts_with("replay:") => {
            bail!("{} has no [ship] section, so `{m}` does not apply; use --input NAME=VALUE or --manoeuvre replay:FILE.csv", model.path)
        }
        _ => generic_run(&cmd, &model, integrator),
    }
}

/// `--param NAME=VALUE`: a parameter of the model; for a ship model `u0` is also the
/// approach speed of the `[ship]` section. Unknown names are refused.
fn set_parameters(model: &mut Model, params: &[String]) -> Result<()> {
    for p in params {
        let (name, value) = p.split_once('=').with_context(|| format!("--param `{p}` must be NAME=VALUE"))?;
        let (name, text) = (name.trim(), value.trim());
        let value = finite(text, || format!("--param `{p}`"))?;
        let mut known = false;
        if let Some(spec) = model.spec.parameters.get_mut(name) {
            spec.value = value;
            known = true;
        }
        if let Some(ship) = model.spec.ship.as_mut().filter(|_| name == "u0") {
            if value <= 0.0 {
                bail!("--param u0={text}: the approach speed must be positive");
            }
            ship.u0 = value;
            known = true;
        }
        if !known {
            let names: Vec<&str> = model.spec.parameters.keys().map(String::as_str).collect();
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

fn ship_run(cmd: &SimulateCommand, model: &Model, text: &str, integrator: Integrator) -> Result<()> {
    let ship = Ship::new(model, cmd.with_intercept)?;
    let manoeuvre = Manoeuvre::parse(text)?;
    let settings = Settings {
        integrator,
        dt: cmd.dt,
        duration: cmd.duration.unwrap_or_else(|| manoeuvre.default_duration()),
        sample: cmd.sample,
    };
    let run = ship.run(&manoeuvre, &settings)?;
    let frame = ship.frame(&run.trajectory, "simulation")?;
    let mc = match cmd.monte_carlo.monte_carlo {
        0 => None,
        n => Some(Draws::run(model, n, cmd.monte_carlo.seed, trajectory_values(&run.trajectory), |m| {
            let drawn = Ship::new(m, cmd.with_intercept)?.run(&manoeuvre, &settings)?;
            Ok((serde_json::to_value(&drawn.metrics)?, drawn.trajectory))
        })?),
    };
    let mut outputs = termid::output::Outputs::new();
    if let Some(out) = &cmd.out {
        outputs.file(out, frame.to_csv().as_bytes())?;
    }
    if let Some(svg) = &cmd.svg {
        let title = format!("{}: {}", model.spec.model.name, manoeuvre.label());
        let fig = match &run.metrics {
            termid::ship::Metrics::Spiral(s) => spiral_figure(&title, s),
            _ => {
                let mut fig = manoeuvre_figure(&ship, &title, &[("simulation", &run.trajectory)], true);
                if let Some(mc) = &mc {
                    let tracks: Vec<&_> = mc.results.iter().map(|(_, t)| t).collect();
                    add_bands(&mut fig, &ship, &tracks);
                }
                fig
            }
        };
        outputs.file(svg, fig.to_svg().map_err(anyhow::Error::msg)?.as_bytes())?;
    }
    outputs.commit()?;
    match cmd.format {
        Format::Json => println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "model": model.path,
                "manoeuvre": manoeuvre.label(),
                "integrator": cmd.integrator,
                "dt": cmd.dt,
                "delta0_deg": run.start.delta0_deg,
                "v0": run.start.v0,
                "metrics": run.metrics,
                "monte_carlo": mc.as_ref().map(|mc| mc.summary(&mc.spread(|r| vec![r.0.clone()]))),
            }))?
        ),
        Format::Text => {
            println!("{} — {}", model.spec.model.name, manoeuvre.label());
            println!(
                "straight run: δ0 = {:.3}°, v0 = {:.5} m/s (u̇ residual {:.2e} m/s²); {} steps of {} s",
                run.start.delta0_deg,
                run.start.v0,
                run.start.surge_residual,
                (settings.duration / settings.dt).round(),
                settings.dt
            );
            let json = serde_json::to_value(&run.metrics)?;
            if let Some(map) = json.as_object() {
                for (k, v) in map {
                    if k == "manoeuvre" || k == "points" || k == "reversals_s" {
                        continue;
                    }
                    println!(
                        "  {k:<28} {}",
                        if v.is_null() { "not reached (run longer?)".to_string() } else { format_value(v) }
                    );
                }
            }
            if let termid::ship::Metrics::Spiral(s) = &run.metrics {
                println!("  {:>8} {:>10} {:>6}", "δ [°]", "r [°/s]", "branch");
                for p in &s.points {
                    println!("  {:>8.1} {:>10.4} {:>6}", p.rudder_deg, p.yaw_rate_deg_s, p.branch);
                }
            }
            if let Some(mc) = &mc {
                print!(
                    "{}",
                    mc.text(&mc.spread(|r| vec![r.0.clone()]), &serde_json::to_value(&run.metrics)?)
                );
            }
            if let Some(out) = &cmd.out {
                println!("wrote {} ({} rows; SI units, angles in rad)", out.display(), frame.len());
            }
        }
    }
    Ok(())
}

/// The values a trajectory holds (time, states, inputs, derivatives), for the memory check of
/// Monte-Carlo draws that keep one each.
pub fn trajectory_values(t: &termid::sim::Trajectory) -> usize {
    t.time.len() * (1 + t.states.len() + t.inputs.len() + t.derivatives.len())
}

fn format_value(v: &serde_json::Value) -> String {
    match v.as_f64() {
        Some(x) => format!("{x:.4}"),
        None => v.to_string(),
    }
}

fn spiral_figure(title: &str, s: &termid::ship::manoeuvre::SpiralMetrics) -> Figure {
    let branch = |b: &str| -> (Vec<f64>, Vec<f64>) {
        s.points.iter().filter(|p| p.branch == b).map(|p| (p.rudder_deg, p.yaw_rate_deg_s)).unzip()
    };
    let (dx, dy) = branch("down");
    let (ux, uy) = branch("up");
    Figure::new(
        title,
        vec![Panel {
            title: "spiral: steady yaw rate against rudder angle".into(),
            x_label: "δ [°]".into(),
            y_label: "r [°/s]".into(),
            series: vec![Series::line("from +δ", dx, dy), Series::points("back from −δ", ux, uy)],
            ..Panel::default()
        }],
    )
}

fn generic_run(cmd: &SimulateCommand, model: &Model, integrator: Integrator) -> Result<()> {
    let system = termid::sim::System::new(model, &BTreeMap::new(), cmd.with_intercept)?;
    let mut x0: Vec<f64> = system
        .states
        .iter()
        .map(|s| model.spec.states.iter().find(|t| &t.name == s).map_or(0.0, |t| t.initial))
        .collect();
    for p in &cmd.initial {
        let (k, v) = p.split_once('=').with_context(|| format!("--initial `{p}` must be NAME=VALUE"))?;
        let name = model.vocabulary.canonical(k.trim()).unwrap_or_else(|| k.trim().to_string());
        let i = system.state_index(&name).with_context(|| format!("--initial: `{k}` is not a state"))?;
        x0[i] = finite(v, || format!("--initial `{p}`"))?;
    }
    let mut inputs: Vec<f64> = model.spec.inputs.iter().map(|i| i.initial).collect();
    for p in &cmd.inputs {
        let (k, v) = p.split_once('=').with_context(|| format!("--input `{p}` must be NAME=VALUE"))?;
        let name = model.vocabulary.canonical(k.trim()).unwrap_or_else(|| k.trim().to_string());
        let i = system.input_index(&name).with_context(|| format!("--input: `{k}` is not an input"))?;
        inputs[i] = finite(v, || format!("--input `{p}`"))?;
    }
    let mut replayed = None;
    let mut controller: Box<dyn Controller> =
        match cmd.manoeuvre.as_deref().and_then(|m| m.strip_prefix("replay:")) {
            Some(file) => {
                let frame = Frame::read_csv(std::path::Path::new(file), &model.spec.model.time)?;
                let t = frame.time();
                replayed = Some(t[t.len() - 1] - t[0]);
                Box::new(Replay::new(&frame, &system.inputs)?)
            }
            None => Box::new(Constant(inputs)),
        };
    // a replay lasts as long as its recording; constant inputs have no natural end
    let duration = cmd.duration.or(replayed).context(
        "give --duration SECONDS: with constant inputs the model has no natural end (a ship model's manoeuvre, or a replay, has)",
    )?;
    let settings = Settings { integrator, dt: cmd.dt, duration, sample: cmd.sample };
    let traj = simulate(&system, &x0, controller.as_mut(), &settings)?;
    let frame = traj.to_frame("simulation", &model.spec.model.time)?;
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
                x_label: model.spec.model.time.clone(),
                y_label: model
                    .spec
                    .states
                    .iter()
                    .find(|t| &t.name == s)
                    .map_or(String::new(), |t| t.unit.clone()),
                series: vec![Series::line(s, traj.time.clone(), traj.states[i].clone())],
                ..Panel::default()
            })
            .collect();
        let svg_text = Figure::new(&model.spec.model.name, panels).to_svg().map_err(anyhow::Error::msg)?;
        outputs.file(svg, svg_text.as_bytes())?;
    }
    outputs.commit()?;
    let last = traj.last_state();
    match cmd.format {
        Format::Json => println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "model": model.path,
                "samples": traj.time.len(),
                "final_state": system.states.iter().zip(&last).map(|(s, v)| (s.clone(), *v)).collect::<BTreeMap<_, _>>(),
            }))?
        ),
        Format::Text => {
            println!(
                "{}: {} samples to t = {}",
                model.spec.model.name,
                traj.time.len(),
                traj.time.last().copied().unwrap_or(0.0)
            );
            for (s, v) in system.states.iter().zip(&last) {
                println!("  {s} = {v:.6}");
            }
            if let Some(out) = &cmd.out {
                println!("wrote {}", out.display());
            }
        }
    }
    Ok(())
}
