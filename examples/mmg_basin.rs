//! The MMG basin (issue 15): KVLCC2 in the MMG standard model (`models/mmg_kvlcc2.toml`), a
//! structure unlike any identified model's, recorded as a basin records it — a straight
//! approach at each run's own speed with the propeller at that speed's self-propulsion point,
//! zigzags of several amplitudes to both sides, sensor noise, a rudder indicator that reads
//! 0.3° off, u and v computed from the tracked position (as in the SIMMAN files), the rudder
//! back at midship at the end of each record. From the training zigzags only, termid's recipe
//! for a new ship (`models/new_ship.toml`, the tracking filter, the back-end chosen by
//! prediction on held-out runs) identifies a model that then predicts the truth's turning
//! circles and the held-out zigzags. Prints the table of docs/guide/mmg-basin.md, one row per noise seed.
//!
//! `cargo run --release --example mmg_basin [-- OUTPUT_FOLDER]` (seeds: MMG_SEEDS=0,1,2;
//! MMG_RUNS=simman trains on the SIMMAN HSVA set instead — 13 zigzags from 5°/1° to 35°/5°,
//! all at one speed and propeller rate, 180 s each; MMG_REFINE=1 adds a row for the chosen
//! model refined by output error; MMG_GREYBOX=1 adds a row for the grey-box MMG model that
//! `termid new-ship` writes from KVLCC2's particulars, estimated on the same runs)

use std::path::{Path, PathBuf};

use termid::data::{CentralDifference, Dataset, Frame};
use termid::diagnose::{choose_by_prediction, Prediction};
use termid::identify::ModelIdentification;
use termid::model::Model;
use termid::ship::basin::{at_approach_speed, columns, dataset_file, Basin, Recording, ZIGZAGS_BOTH_SIDES};
use termid::ship::{Manoeuvre, Metrics, Ship};
use termid::sim::{Integrator, Settings};

/// Held-out zigzags: identified from none of them.
const HELD: [(&str, f64); 3] = [("zigzag:25/10", 1.0), ("zigzag:20/10:port", 0.98), ("zigzag:30/5", 1.01)];
/// Turning circles predicted, rudder in degrees (MMG: positive to starboard).
const TURNS: [f64; 4] = [35.0, -35.0, 20.0, -20.0];
/// The SIMMAN 2008 KVLCC2 set of HSVA: every zigzag at the approach speed (first rudder to
/// starboard but where `:port` says).
const SIMMAN_ZIGZAGS: [(&str, f64); 13] = [
    ("zigzag:5/1", 1.0),
    ("zigzag:10/1", 1.0),
    ("zigzag:10/5", 1.0),
    ("zigzag:10/10:port", 1.0),
    ("zigzag:10/10", 1.0),
    ("zigzag:15/1", 1.0),
    ("zigzag:15/5", 1.0),
    ("zigzag:20/5", 1.0),
    ("zigzag:20/10:port", 1.0),
    ("zigzag:20/10", 1.0),
    ("zigzag:25/5", 1.0),
    ("zigzag:30/5", 1.0),
    ("zigzag:35/5", 1.0),
];
/// What the basin's rudder indicator reads more than the true angle, °.
const RUDDER_OFFSET_DEG: f64 = 0.3;

type Error = Box<dyn std::error::Error>;

fn main() -> Result<(), Error> {
    let dir =
        std::env::args().nth(1).map_or_else(|| std::env::temp_dir().join("termid-mmg-basin"), PathBuf::from);
    std::fs::create_dir_all(&dir)?;
    let truth = termid::plugins::load(Path::new("models/mmg_kvlcc2.toml"))?;
    let template = termid::plugins::load(Path::new("models/new_ship.toml"))?;
    let u0 = termid::ship::ShipSpec::of(&truth)?.map_or(1.17, |s| s.u0);
    let seeds: Vec<u64> = std::env::var("MMG_SEEDS")
        .ok()
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![0, 1, 2]);
    // optical tracking (2 mm), gyro, rudder potentiometer, no log: u and v from the track;
    // the rudder indicator 0.3° off, the rudder back at midship at the end
    let basin = Basin::tracked();
    assert_eq!(basin.artefacts.rudder_offset_deg, RUDDER_OFFSET_DEG);

    // the truth: turning circles at the nominal speed, held-out zigzags at their own
    let settings = Settings { integrator: Integrator::Rk4, dt: 0.01, duration: 250.0, sample: 0.05 };
    let true_turns: Vec<(f64, f64)> =
        TURNS.iter().map(|d| turning(&truth, *d, &settings)).collect::<Result<_, _>>()?;
    let true_held: Vec<f64> =
        HELD.iter().map(|(m, f)| overshoot(&truth, m, f * u0, &settings)).collect::<Result<_, _>>()?;

    let mut head = String::from("| seed | chosen back-end |");
    let mut rule = String::from("|---|---|");
    for (d, (a, t)) in TURNS.iter().zip(&true_turns) {
        head += &format!(" δ = {d}°: advance (true {a:.2} m) | tactical diameter (true {t:.2} m) |");
        rule += "---|---|";
    }
    for ((m, _), o) in HELD.iter().zip(&true_held) {
        head += &format!(" {m} 1st overshoot (true {o:.2}°) |");
        rule += "---|";
    }
    println!("{head}\n{rule}");
    let mut summary: Vec<(String, f64, f64, f64)> = Vec::new();
    for seed in seeds {
        let simman = std::env::var("MMG_RUNS").is_ok_and(|v| v == "simman");
        let (set, duration): (&[(&str, f64)], f64) =
            if simman { (&SIMMAN_ZIGZAGS, 180.0) } else { (&ZIGZAGS_BOTH_SIDES, 80.0) };
        let train = basin.record_all(&truth, set, u0, duration, 1000 * seed + 1, Some(&dir))?;
        std::fs::write(dir.join("train.toml"), dataset_file(&columns(&truth), &names(&train)))?;
        let (frames, _) = Dataset::load(&dir.join("train.toml"))?.read(&dir, "t")?;
        // a new ship's recipe: the tracking filter fuses track, heading, gyro and the
        // track-derived velocities; smoothed states as regressors; no intercept (the u² and n²
        // terms carry the asymmetry); the back-end chosen by what it predicts
        let plugin = termid::plugins::with_derivative("kinematic").ok_or("no tracking filter")?;
        let prepared: Vec<Frame> = frames
            .iter()
            .map(|f| plugin.prepare("kinematic", &template, f, true))
            .collect::<Result<_, _>>()?;
        let how = ModelIdentification {
            equations: vec![],
            differentiator: &CentralDifference,
            intercept: false,
            target: None,
        };
        // in order of preference: among back-ends the held-out runs do not tell apart, the
        // sparse fit (a LASSO path refitted) comes first
        let configurations: Vec<(String, Model)> =
            ["sparse", "best-subset", "efroymson", "stepwise", "stlsq"]
                .iter()
                .map(|name| {
                    let backend = termid::select::Backend::by_name(name)?;
                    Ok((name.to_string(), template.with_backend(&backend)?))
                })
                .collect::<Result<_, Error>>()?;
        let prediction =
            Prediction { states: ["u", "v", "r", "ψ"].map(String::from).to_vec(), ..Default::default() };
        let chosen = choose_by_prediction(&configurations, &prepared, &how, &prediction, &mut |_| {})?;
        eprintln!("seed {seed}:\n{}", chosen.text());
        let model = chosen.identified.model;
        std::fs::write(dir.join(format!("identified_{seed}.toml")), model.to_toml())?;
        let (cells, _) = predict(&model, &true_turns, &true_held, u0, &settings)?;
        println!("| {seed} | {} |{cells}", chosen.candidates[chosen.best].label);
        if std::env::var("MMG_REFINE").is_ok_and(|v| v == "1") {
            let runs = termid::diagnose::Runs::new(&model, &prepared, 0.05, Integrator::Rk4)?
                .comparing(&model, &["u", "v", "r", "ψ"].map(String::from))?;
            let refined = termid::diagnose::refine(&model, &runs, &Default::default())?;
            let (cells, _) = predict(&refined.model, &true_turns, &true_held, u0, &settings)?;
            println!("| {seed} | {} refined |{cells}", chosen.candidates[chosen.best].label);
        }
        if std::env::var("MMG_GREYBOX").is_ok_and(|v| v == "1") {
            // a ship nobody has tested: its particulars only, then its zigzags (what `termid
            // new-ship` and `termid estimate --states u,v,r,ψ` do)
            let particulars: termid::ship::particulars::Particulars =
                toml::from_str(&std::fs::read_to_string("examples/kvlcc2_particulars.toml")?)?;
            let start = particulars.model()?;
            let runs = termid::diagnose::Runs::new(
                &start,
                &frames,
                termid::data::sample_step(&frames),
                Integrator::Rk4,
            )?
            .comparing(&start, &["u", "v", "r", "ψ"].map(String::from))?;
            let fit = termid::diagnose::estimate(&start, &runs, &Default::default())?;
            std::fs::write(dir.join(format!("greybox_{seed}.toml")), fit.model.to_toml())?;
            let (cells, _) = predict(&fit.model, &true_turns, &true_held, u0, &settings)?;
            println!("| {seed} | grey-box from particulars |{cells}");
        }
        // every back-end's own model, for the summary: how much the choice matters
        for (k, (label, variant)) in configurations.iter().enumerate() {
            let identified = termid::identify::identify_model(variant, &prepared, &how, &mut |_| {})?.model;
            let (_, worst) = predict(&identified, &true_turns, &true_held, u0, &settings)?;
            if summary.len() <= k {
                summary.push((label.clone(), 0.0, 0.0, 0.0));
            }
            let s = &mut summary[k];
            (s.1, s.2, s.3) = (s.1.max(worst.0), s.2.max(worst.1), s.3.max(worst.2));
        }
    }
    println!("\nevery back-end on every seed, worst of the four turning circles and the held-out zigzags:\n");
    println!("| back-end | advance | tactical diameter | 1st overshoot |\n|---|---|---|---|");
    for (label, a, t, o) in &summary {
        println!("| {label} | {a:.1} % | {t:.1} % | {o:.2}° |");
    }
    println!("\nrecords and identified models in {}", dir.display());
    Ok(())
}

/// The table's cells for a model: each turning circle's advance and tactical diameter and each
/// held-out zigzag's first overshoot against the truth; and the worst |error| of each kind
/// (∞ where a prediction fails).
fn predict(
    model: &Model,
    true_turns: &[(f64, f64)],
    true_held: &[f64],
    u0: f64,
    settings: &Settings,
) -> Result<(String, (f64, f64, f64)), Error> {
    let mut model = model.clone();
    // the rudder's limit is the actuator's: in the indicator's reading it is offset too
    if let Some(mut ship) = termid::ship::ShipSpec::of(&model)? {
        ship.rudder_limit += RUDDER_OFFSET_DEG;
        ship.store(&mut model);
    }
    let mut cells = String::new();
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for (d, (a, t)) in TURNS.iter().zip(true_turns) {
        // the model's rudder is the indicator's: the true angle d reads d + offset
        match turning(&model, d + RUDDER_OFFSET_DEG, settings) {
            Ok((ma, mt)) => {
                cells += &format!(" {ma:.2} ({:+.1} %) | {mt:.2} ({:+.1} %) |", pct(ma, *a), pct(mt, *t));
                worst.0 = worst.0.max(pct(ma, *a).abs());
                worst.1 = worst.1.max(pct(mt, *t).abs());
            }
            Err(e) => {
                cells += &format!(" fails: {e} | |");
                (worst.0, worst.1) = (f64::INFINITY, f64::INFINITY);
            }
        }
    }
    for ((m, f), o) in HELD.iter().zip(true_held) {
        match overshoot(&model, m, f * u0, settings) {
            Ok(v) => {
                cells += &format!(" {v:.2} ({:+.2}°) |", v - o);
                worst.2 = worst.2.max((v - o).abs());
            }
            Err(e) => {
                cells += &format!(" fails: {e} |");
                worst.2 = f64::INFINITY;
            }
        }
    }
    Ok((cells, worst))
}

fn pct(a: f64, b: f64) -> f64 {
    100.0 * (a / b - 1.0)
}

fn names(runs: &[(String, Recording)]) -> Vec<&str> {
    runs.iter().map(|(n, _)| n.as_str()).collect()
}

/// (advance, tactical diameter) in metres of a turning circle at the model's nominal speed.
fn turning(model: &Model, rudder_deg: f64, settings: &Settings) -> Result<(f64, f64), Error> {
    let run = Ship::new(model, false)?.run(&Manoeuvre::parse(&format!("turning:{rudder_deg}"))?, settings)?;
    match run.metrics {
        Metrics::Turning(t) => Ok((
            t.advance_m.ok_or("no 90° heading change")?,
            t.tactical_diameter_m.ok_or("no 180° heading change")?,
        )),
        _ => Err("not a turning circle".into()),
    }
}

/// First overshoot of a zigzag at approach speed `u0`, degrees.
fn overshoot(model: &Model, manoeuvre: &str, u0: f64, settings: &Settings) -> Result<f64, Error> {
    let run = Ship::new(&at_approach_speed(model, u0), false)?
        .run(&Manoeuvre::parse(manoeuvre)?, &Settings { duration: 80.0, ..*settings })?;
    match run.metrics {
        Metrics::ZigZag(z) => Ok(z.first_overshoot_deg.ok_or("no overshoot")?),
        _ => Err("not a zigzag".into()),
    }
}
