//! The SIMMAN 2008 KVLCC2 case study (docs/guide/simman.md): a model identified from HSVA's
//! thirteen zigzags (the guide's `identify` command) predicts MARIN's four zigzags, which it
//! never saw (full scale, read at the model's scale), and its turning circles; and steers
//! HSVA's own zigzags, each basin's steering gear read off its records. Prints the guide's
//! tables and writes two figures.
//!
//! `SIMMAN=/path/to/clone cargo run --release --example simman -- IDENTIFIED.toml [OUT_FOLDER]`;
//! `… --example simman -- --table [--gear-at-once] [--about-neutral] [--zero-from-approach]
//! LABEL=MODEL.toml …` prints one row per model instead: the first overshoot of each MARIN
//! zigzag (steered by the model, the rudder laid about 0 by MARIN's steering gear as MARIN's
//! records show both; or by a gear at full rate at once; or that and about the model's
//! straight-run angle; with `--zero-from-approach` the model's rudder zero moved for each run so
//! that its straight run needs the rudder the record's approach held) less MARIN's, and
//! the ±35° tactical diameters (the guide's table of training sets and model families); then
//! each model's linear sway and yaw at MARIN's approach (time constants, rudder, damping)
//! (the clone: the public repository martinlarsalbert/System-identification-of-Vessel-
//! Manoeuvring-Models; its records are read where they are, never copied).

use std::path::{Path, PathBuf};

use termid::data::{Dataset, Frame};
use termid::diagnose::Runs;
use termid::model::Model;
use termid::plot::{Figure, Panel, Series};
use termid::ship::observed::{observe_run, Observed, SteeringGear, ZigZagShape};
use termid::ship::stability::SwayYaw;
use termid::ship::{Manoeuvre, Metrics, Ship, StraightRun};
use termid::sim::{Integrator, Settings, Trajectory};

type Error = Box<dyn std::error::Error>;

/// Turning circles predicted, rudder in degrees (termid's convention: positive to starboard;
/// MARIN's and HSVA's files count the other way: their `tc_35` is termid's −35°).
const TURNS: [f64; 4] = [35.0, -35.0, 20.0, -20.0];

fn main() -> Result<(), Error> {
    let all: Vec<String> = std::env::args().skip(1).collect();
    if all.first().is_some_and(|a| a == "--table") {
        return table(&all[1..]);
    }
    let mut args = all.into_iter();
    let model_path = PathBuf::from(args.next().ok_or("usage: simman IDENTIFIED.toml [OUT_FOLDER]")?);
    let out = args.next().map_or_else(|| std::env::temp_dir().join("termid-simman"), PathBuf::from);
    std::fs::create_dir_all(&out)?;
    let model = termid::plugins::load(&model_path)?;
    let marin = Path::new("examples/simman/marin.toml");
    let set = Dataset::load(marin)?;
    let (runs, _) = set.read(&set.folder(marin)?, "t")?;

    // MARIN's zigzags re-simulated from their recorded start with their recorded rudder and
    // propeller rate; overshoots read off record and simulation alike
    let data = Runs::new(&model, &runs, 0.02, Integrator::Rk4)?;
    let settings = Settings { integrator: Integrator::Rk4, dt: 0.02, duration: 240.0, sample: 0.2 };
    let sims = data.simulate(&model, &[], &[])?;
    let plugin = termid::plugins::of(&model).ok_or("not a ship model")?;
    // and each zigzag as the model steers it itself: same amplitude and side, from the run's
    // approach speed (the propeller at the model's self-propulsion point for it), the rudder
    // laid to ±A on its own scale as MARIN's records show it laid (plateaus at ±10° and ±20°
    // of the indicator) by MARIN's steering gear as its records show it; for comparison by a
    // gear at its full rate at once (the model file's), and about the straight run's δ0 as
    // well (Oltmann's §5)
    let gear = gear_of(&model, &runs)?;
    println!("MARIN's steering gear (model scale): {}\n", describe(&gear));
    println!("| MARIN run | zigzag (termid) | 1st overshoot measured | predicted | error | 2nd overshoot measured | predicted | error | 1st overshoot, gear at full rate at once | the same, rudder about δ0 | 1st overshoot, recorded rudder replayed |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut panels = Vec::new();
    for (frame, sim) in runs.iter().zip(&sims) {
        let name =
            Path::new(frame.origin()).file_stem().map_or(String::new(), |s| s.to_string_lossy().into());
        let measured = plugin.observe(&model, frame, None).ok_or("no metrics of the record")?.json;
        let replayed = plugin.observe(&model, frame, Some(sim)).ok_or("no metrics of the simulation")?.json;
        let manoeuvre = zigzag_of(frame)?;
        let approach = termid::ship::basin::at_approach_speed(&model, frame.require("u")?[0]);
        let ship = Ship::new(&approach, false)?;
        let at_once = steer(&ship, &manoeuvre, &settings)?;
        let about_neutral = steer(&ship, manoeuvre.trim_end_matches(":absolute"), &settings)?;
        let geared = Ship::new(&gear.on(&approach), false)?;
        let z = steer(&geared, &manoeuvre, &settings)?;
        let mut row = format!("| {name} | {} |", manoeuvre.trim_start_matches("zigzag:"));
        for (key, p) in
            [("first_overshoot_deg", z.first_overshoot_deg), ("second_overshoot_deg", z.second_overshoot_deg)]
        {
            row += &match (measured[key].as_f64(), p) {
                (Some(m), Some(p)) => format!(" {m:.2}° | {p:.2}° | {:+.2}° |", p - m),
                _ => " -- | -- | -- |".into(),
            };
        }
        for p in [at_once.first_overshoot_deg, about_neutral.first_overshoot_deg] {
            row += &p.map_or(" -- |".into(), |p| format!(" {p:.2}° |"));
        }
        row += &replayed["first_overshoot_deg"].as_f64().map_or(" -- |".into(), |p| format!(" {p:.2}° |"));
        println!("{row}");
        panels.push(zigzag_panel(&name, frame, sim)?);
    }
    own_zigzags(&model, &settings)?;
    let mut zigzags = Figure::new(
        "MARIN's KVLCC2 zigzags (model scale), predicted by the model identified from HSVA's",
        panels,
    );
    zigzags.panel_height = 220;
    zigzags.shared_legend = true;
    zigzags.write_svg(&out.join("simman_zigzags.svg"))?;

    // turning circles at MARIN's approach speed, the propeller at the model's self-propulsion
    // point for it
    let u0 = runs.iter().map(|f| f.require("u").map(|u| u[0])).sum::<Result<f64, _>>()? / runs.len() as f64;
    let ship_model = termid::ship::basin::at_approach_speed(&model, u0);
    let straight = Ship::new(&ship_model, false)?.straight_run()?;
    println!(
        "\nturning circles predicted at u0 = {u0:.3} m/s (MARIN's approach; the model's straight run needs δ0 = {:.2}°):\n",
        straight.delta0_deg
    );
    println!("| δ (termid) | advance | tactical diameter | speed in the turn | drift angle |");
    println!("|---|---|---|---|---|");
    let mut tracks = Vec::new();
    for d in TURNS {
        let run =
            Ship::new(&ship_model, false)?.run(&Manoeuvre::parse(&format!("turning:{d}"))?, &settings)?;
        let Metrics::Turning(t) = &run.metrics else { return Err("not a turning circle".into()) };
        let lpp = termid::ship::ShipSpec::of(&model)?.map_or(7.0, |s| s.lpp);
        let m = |v: Option<f64>| v.map_or("--".into(), |v| format!("{v:.2} m ({:.2} L)", v / lpp));
        println!(
            "| {d:+}° | {} | {} | {:.0} % of u0 | {:.1}° |",
            m(t.advance_m),
            m(t.tactical_diameter_m),
            100.0 * t.speed_ratio,
            t.drift_angle_deg
        );
        if d.abs() == 35.0 {
            tracks.push(track(&format!("δ = {d:+}°"), &run.trajectory, lpp)?);
        }
    }
    let mut turning = Figure::new(
        "KVLCC2 (L = 7 m), predicted turning circles",
        vec![Panel {
            title: "track of midship".into(),
            x_label: "y0/L [-]".into(),
            y_label: "x0/L [-]".into(),
            series: tracks,
            equal_axes: true,
            unit_ticks: true,
            ..Default::default()
        }],
    );
    turning.panel_height = 520;
    turning.width = 560;
    turning.write_svg(&out.join("simman_turning.svg"))?;
    println!("\nfigures in {}", out.display());
    Ok(())
}

/// HSVA's thirteen zigzags, which the model was identified from, as it steers them itself from
/// each run's approach: the rudder about 0, as HSVA laid it (the records start at the execute
/// with the rudder at 0 and lay it to ±A), and about the model's straight-run angle δ0. Which
/// convention reproduces the basin's own runs is the one to predict its other runs with.
fn own_zigzags(model: &Model, settings: &Settings) -> Result<(), Error> {
    let hsva = Path::new("examples/simman/hsva.toml");
    let set = Dataset::load(hsva)?;
    let (runs, _) = set.read(&set.folder(hsva)?, "t")?;
    let plugin = termid::plugins::of(model).ok_or("not a ship model")?;
    let gear = gear_of(model, &runs)?;
    println!("\nHSVA's zigzags (the training runs) as the model steers them, first overshoot (HSVA's steering gear: {}):\n", describe(&gear));
    println!("| HSVA run | zigzag (termid) | measured | rudder about 0 | error | rudder about δ0 | error | rudder about 0, HSVA's gear | error | the same from the record's first sample | error |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for frame in &runs {
        let name =
            Path::new(frame.origin()).file_stem().map_or(String::new(), |s| s.to_string_lossy().into());
        let measured = plugin.observe(model, frame, None).ok_or("no metrics of the record")?.json;
        let manoeuvre = zigzag_of(frame)?;
        let approach = termid::ship::basin::at_approach_speed(model, frame.require("u")?[0]);
        let (ship, geared) = (Ship::new(&approach, false)?, Ship::new(&gear.on(&approach), false)?);
        let mut row = format!("| {name} | {} |", manoeuvre.trim_start_matches("zigzag:"));
        let m = measured["first_overshoot_deg"].as_f64();
        row += &m.map_or(" -- |".into(), |m| format!(" {m:.2}° |"));
        for (ship, spec) in [
            (&ship, manoeuvre.as_str()),
            (&ship, manoeuvre.trim_end_matches(":absolute")),
            (&geared, manoeuvre.as_str()),
        ] {
            let z = steer(ship, spec, settings)?;
            row += &cell(m, z.first_overshoot_deg);
        }
        let z = steer_from(&geared, &manoeuvre, settings, recorded_start(&geared, frame)?)?;
        row += &cell(m, z.first_overshoot_deg);
        println!("{row}");
    }
    Ok(())
}

/// `--table [--gear-at-once] [--about-neutral] [--zero-from-approach] LABEL=MODEL.toml …`: per
/// model, each MARIN zigzag's first overshoot as the model steers it less the measured one, and
/// the ±35° tactical diameters at MARIN's approach; the rudder laid about 0 by MARIN's steering
/// gear, or with `--gear-at-once` by the model file's gear (full rate at once), with
/// `--about-neutral` that and about the model's δ0; `--zero-from-approach` moves the model's
/// rudder zero for each run so that its straight run needs the rudder the approach held.
fn table(args: &[String]) -> Result<(), Error> {
    let flags = args.iter().take_while(|a| a.starts_with("--")).count();
    let about_neutral = args[..flags].iter().any(|a| a == "--about-neutral");
    let with_gear = !about_neutral && !args[..flags].iter().any(|a| a == "--gear-at-once");
    let zero_from_approach = args[..flags].iter().any(|a| a == "--zero-from-approach");
    let known = ["--about-neutral", "--gear-at-once", "--zero-from-approach"];
    if let Some(other) = args[..flags].iter().find(|a| !known.contains(&a.as_str())) {
        return Err(format!(
            "unknown option {other}: --table [--gear-at-once] [--about-neutral] [--zero-from-approach] LABEL=MODEL.toml …"
        )
        .into());
    }
    let models = args[flags..]
        .iter()
        .map(|item| {
            let (label, path) = item.split_once('=').ok_or("--table takes LABEL=MODEL.toml")?;
            Ok((label, termid::plugins::load(Path::new(path))?))
        })
        .collect::<Result<Vec<_>, Error>>()?;
    let zigzag = |frame: &Frame| -> Result<String, Error> {
        let spec = zigzag_of(frame)?;
        Ok(if about_neutral { spec.trim_end_matches(":absolute").to_string() } else { spec })
    };
    let marin = Path::new("examples/simman/marin.toml");
    let set = Dataset::load(marin)?;
    let (runs, _) = set.read(&set.folder(marin)?, "t")?;
    // the records' gear, read by the first model's names (the models are of one ship)
    let gear = match models.first() {
        Some((_, model)) if with_gear => Some(gear_of(model, &runs)?),
        _ => None,
    };
    if let Some(gear) = &gear {
        println!("MARIN's steering gear (model scale): {}\n", describe(gear));
    }
    let settings = Settings { integrator: Integrator::Rk4, dt: 0.02, duration: 240.0, sample: 0.2 };
    let mut head = "| model |".to_string();
    for frame in &runs {
        head += &format!(" {} |", zigzag(frame)?.trim_start_matches("zigzag:").trim_end_matches(":absolute"));
    }
    println!("{head} +35° | −35° |\n|---|{}---|---|", "---|".repeat(runs.len()));
    let mut linear = Vec::new();
    for (label, model) in &models {
        let plugin = termid::plugins::of(model).ok_or("not a ship model")?;
        let mut row = format!("| {label} |");
        for frame in &runs {
            let measured = plugin.observe(model, frame, None).ok_or("no metrics of the record")?.json;
            // a model that leaves its bounds is a row of the table too, saying where
            let approach = termid::ship::basin::at_approach_speed(model, frame.require("u")?[0]);
            let approach =
                if zero_from_approach { with_neutral(&approach, approach_rudder(frame)?)? } else { approach };
            let ship = Ship::new(&gear.as_ref().map_or(approach.clone(), |g| g.on(&approach)), false)?;
            let z = match steer(&ship, &zigzag(frame)?, &settings) {
                Ok(z) => z,
                Err(e) => {
                    row += &format!(" {} |", diverged(&e));
                    continue;
                }
            };
            row += &match (measured["first_overshoot_deg"].as_f64(), z.first_overshoot_deg) {
                (Some(m), Some(p)) => format!(" {:+.2}° |", p - m),
                _ => " -- |".into(),
            };
        }
        let u0 =
            runs.iter().map(|f| f.require("u").map(|u| u[0])).sum::<Result<f64, _>>()? / runs.len() as f64;
        let ship = Ship::new(&termid::ship::basin::at_approach_speed(model, u0), false)?;
        let start = ship.straight_run()?;
        linear.push((label, start.delta0_deg, SwayYaw::of(&ship, &start)));
        for d in [35.0, -35.0] {
            let run = match ship.run(&Manoeuvre::parse(&format!("turning:{d}"))?, &settings) {
                Ok(run) => run,
                Err(e) => {
                    row += &format!(" {} |", diverged(&e));
                    continue;
                }
            };
            let Metrics::Turning(t) = &run.metrics else { return Err("not a turning circle".into()) };
            row += &t.tactical_diameter_m.map_or(" -- |".into(), |v| format!(" {v:.1} m |"));
        }
        println!("{row}");
    }
    // what each model carries into the turns: its linear sway and yaw at MARIN's approach
    println!(
        "\nlinear sway-yaw at MARIN's approach, u0 = {:.3} m/s:\n",
        linear.first().map_or(0.0, |l| l.2.u0)
    );
    println!("| model | time constants | ∂ṙ/∂δ | ∂ṙ/∂r | ∂v̇/∂v | δ0 |\n|---|---|---|---|---|---|");
    for (label, delta0, s) in linear {
        let t = s.time_constants().map_or("oscillating".to_string(), |(fast, slow)| {
            let unstable = if slow < 0.0 { " (course-unstable)" } else { "" };
            format!("{fast:.2} s, {slow:.1} s{unstable}")
        });
        println!(
            "| {label} | {t} | {:.4} 1/s² | {:.3} 1/s | {:.3} 1/s | {delta0:+.2}° |",
            s.n_delta, s.nr, s.yv
        );
    }
    Ok(())
}

/// The rudder angle that held the record's approach: the mean of its samples before the
/// rudder first moves 0.5° from where it started (the execute).
fn approach_rudder(frame: &Frame) -> Result<f64, Error> {
    let d = frame.require("δ")?;
    let execute =
        d.iter().position(|x| (x - d[0]).abs() > 0.5f64.to_radians()).ok_or("the rudder never moves")?;
    Ok(d[..execute].iter().sum::<f64>() / execute as f64)
}

/// The model with its rudder indicator's zero `δ_0` moved so that its straight run needs the
/// rudder angle `delta` (every rudder term reads δ − δ_0, so the straight run's angle moves with
/// the zero one for one).
fn with_neutral(model: &Model, delta: f64) -> Result<Model, Error> {
    let neutral = Ship::new(model, false)?.straight_run()?.delta0_deg.to_radians();
    let zero = *model.parameter_values().get("δ_0").ok_or("the model has no rudder zero δ_0")?;
    let mut moved = model.clone();
    moved.set_parameter("δ_0", zero + delta - neutral);
    Ok(moved)
}

/// A predicted value and its error, as two cells.
fn cell(measured: Option<f64>, predicted: Option<f64>) -> String {
    match (measured, predicted) {
        (Some(m), Some(p)) => format!(" {p:.2}° | {:+.2}° |", p - m),
        _ => " -- | -- |".into(),
    }
}

/// A zigzag as the ship steers it itself over 100 s, read off as its record would be.
fn steer(ship: &Ship, spec: &str, settings: &Settings) -> Result<Observed, Error> {
    steer_from(ship, spec, settings, ship.straight_run()?)
}

/// The same from a given start (a record's first sample: its state, rudder and propeller).
fn steer_from(ship: &Ship, spec: &str, settings: &Settings, start: StraightRun) -> Result<Observed, Error> {
    // sampled at every step, read off as a record is: overshoots beyond the heading at each
    // rudder reversal, which a steering gear that answers late moves past the check angle
    let every = Settings { duration: 100.0, sample: settings.dt, ..*settings };
    let run = ship.run_from(&Manoeuvre::parse(spec)?, &every, start)?.trajectory;
    observe_run(&run, &ship.spec.names)
        .ok_or_else(|| "the run lacks the ship's heading, rudder or track".into())
}

/// A record's first sample as the start of a manoeuvre: its states, its rudder and propeller.
fn recorded_start(ship: &Ship, frame: &Frame) -> Result<StraightRun, Error> {
    let first = |name: &String| frame.require(name).map(|c| c[0]);
    let x = ship.system.states.iter().map(first).collect::<Result<Vec<_>, _>>()?;
    let input = ship.system.inputs.iter().map(first).collect::<Result<Vec<_>, _>>()?;
    let delta0_deg = frame.require("δ")?[0].to_degrees();
    Ok(StraightRun { x, input, delta0_deg, v0: frame.require("v")?[0], surge_residual: 0.0 })
}

/// A prediction that failed, as a cell: where a simulation left its bounds, when.
fn diverged(e: &dyn std::fmt::Display) -> String {
    let text = e.to_string();
    let at = text.split("diverged at t = ").nth(1).and_then(|rest| rest.split_whitespace().next());
    match at.and_then(|t| t.parse::<f64>().ok()) {
        Some(t) => format!("diverges at {t:.0} s"),
        None => "fails".into(),
    }
}

/// Heading measured and predicted, and the rudder, in degrees over the run (every fifth
/// sample: the figure stays small).
fn zigzag_panel(name: &str, frame: &Frame, sim: &Trajectory) -> Result<Panel, Error> {
    let every = |v: &[f64], scale: f64| v.iter().step_by(5).map(|x| x * scale).collect::<Vec<f64>>();
    let deg = 180.0 / std::f64::consts::PI;
    let psi = sim.state_names.iter().position(|n| n == "ψ").ok_or("no ψ")?;
    Ok(Panel {
        title: name.into(),
        x_label: "t [s]".into(),
        y_label: "ψ, δ [°]".into(),
        series: vec![
            Series::line("ψ measured", every(frame.time(), 1.0), every(frame.require("ψ")?, deg)),
            Series::line(
                "ψ predicted (recorded rudder)",
                every(&sim.time, 1.0),
                every(&sim.states[psi], deg),
            ),
            Series::line("δ", every(frame.time(), 1.0), every(frame.require("δ")?, deg)),
        ],
        ..Default::default()
    })
}

/// The zigzag a record is: `zigzag:A/H:absolute` (its shape as the ship plug-in reads it),
/// the rudder about 0, as the records lay it.
fn zigzag_of(frame: &Frame) -> Result<String, Error> {
    let z = ZigZagShape::of(frame.require("ψ")?, frame.require("δ")?).ok_or("not a zigzag")?;
    let side = if z.starboard_first { "" } else { ":port" };
    Ok(format!("zigzag:{}/{}{side}:absolute", z.amplitude, z.check))
}

/// A basin's steering gear as its zigzag records show it (model scale).
fn gear_of(model: &Model, runs: &[Frame]) -> Result<SteeringGear, Error> {
    SteeringGear::of_runs(model, runs).ok_or_else(|| "no rudder reversal in the records".into())
}

/// A gear as the tables' headings say it.
fn describe(gear: &SteeringGear) -> String {
    format!(
        "dead time {:.2} s, rate {:.1}°/s reached at {:.0}°/s² (medians of {} reversals)",
        gear.delay_s, gear.rate_deg_s, gear.acceleration_deg_s2, gear.reversals
    )
}

/// A run's track, x0 up and y0 across.
fn track(name: &str, t: &Trajectory, lpp: f64) -> Result<Series, Error> {
    // in ship lengths, as the paper draws tracks
    let col = |n: &str| {
        t.state_names.iter().position(|s| s == n).map(|i| t.states[i].iter().map(|v| v / lpp).collect())
    };
    Ok(Series::line(name, col("y0").ok_or("no y0")?, col("x0").ok_or("no x0")?))
}
