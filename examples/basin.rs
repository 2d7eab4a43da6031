//! The synthetic-basin study of issue 7: the default model's five zigzags recorded at 20 Hz
//! with sensor noise and per-run approach speeds, identified from four of them with each
//! derivative method, validated on the fifth and on turning circles against the noise-free
//! truth. Prints the table of docs/guide/ship-records.md.
//!
//! `cargo run --release --example basin [-- OUTPUT_FOLDER]`

use std::collections::BTreeMap;
use std::path::PathBuf;

use termid::data::{
    differentiator, prepare, CentralDifference, DataError, Dataset, Differentiator, Frame, KalmanSmoother,
    Preparation, Smoothed,
};
use termid::diagnose::{refine, RefineSettings, Runs};
use termid::identify::{identify_model, Identification, ModelIdentification, Target};
use termid::model::Model;
use termid::select::{Backend, Moments};
use termid::ship::basin::{at_approach_speed, dataset_toml, Basin, Recording, PAPER_RUNS};
use termid::ship::{Manoeuvre, Metrics, Ship};
use termid::sim::{Integrator, Settings};
use termid::term::Library;

const TURNS: [f64; 6] = [20.0, -20.0, 30.0, -30.0, 35.0, -35.0];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir =
        std::env::args().nth(1).map_or_else(|| std::env::temp_dir().join("termid-basin"), PathBuf::from);
    std::fs::create_dir_all(&dir)?;
    let truth = termid::ship::default_model();
    let u0 = termid::ship::ShipSpec::of(&truth)?.map_or(2.01, |s| s.u0);
    let mut basin = Basin::default();
    // BASIN_NOISE scales every sensor's noise (1 = issue 7's sizes)
    if let Some(k) = std::env::var("BASIN_NOISE").ok().and_then(|s| s.parse::<f64>().ok()) {
        let n = &mut basin.noise;
        for v in [
            &mut n.speed_m_s,
            &mut n.yaw_rate_deg_s,
            &mut n.heading_deg,
            &mut n.position_m,
            &mut n.rudder_deg,
        ] {
            *v *= k;
        }
    }
    let record =
        |(m, f): (&str, f64), seed: u64| -> Result<(String, Recording), Box<dyn std::error::Error>> {
            let name = format!("{}.dat", m.replace([':', '/'], "_"));
            let rec = basin.record(&truth, &Manoeuvre::parse(m)?, f * u0, 100.0, seed, &name)?;
            basin.write(&rec, &truth, &dir.join(&name))?;
            Ok((name, rec))
        };
    // BASIN_SEED varies the noise, to see how much of a result is luck
    let seed: u64 = std::env::var("BASIN_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(0);
    let train: Vec<(String, Recording)> = PAPER_RUNS[..4]
        .iter()
        .enumerate()
        .map(|(k, r)| record(*r, 11 + k as u64 + 100 * seed))
        .collect::<Result<_, _>>()?;
    let held = record(PAPER_RUNS[4], 99 + 100 * seed)?;
    let names: Vec<&str> = train.iter().map(|(n, _)| n.as_str()).collect();
    std::fs::write(dir.join("train.toml"), dataset_toml(&names))?;
    std::fs::write(dir.join("held_out.toml"), dataset_toml(&[held.0.as_str()]))?;
    let (frames, _) = Dataset::load(&dir.join("train.toml"))?.read(&dir, "t")?;
    let (held_frames, _) = Dataset::load(&dir.join("held_out.toml"))?.read(&dir, "t")?;

    // the truth's metrics: held-out zigzag at its own speed, turning circles at the nominal speed
    let settings = Settings { integrator: Integrator::Rk4, dt: 0.01, duration: 100.0, sample: 0.05 };
    let overshoot = |m: &Metrics| match m {
        Metrics::ZigZag(z) => z.first_overshoot_deg.unwrap_or(f64::NAN),
        _ => f64::NAN,
    };
    let tactical = |model: &Model, delta: f64| -> Result<f64, Box<dyn std::error::Error>> {
        let ship = Ship::new(model, true)?;
        let run = ship.run(
            &Manoeuvre::parse(&format!("turning:{delta}"))?,
            &Settings { duration: 250.0, ..settings },
        )?;
        Ok(match run.metrics {
            Metrics::Turning(t) => t.tactical_diameter_m.unwrap_or(f64::NAN),
            _ => f64::NAN,
        })
    };
    let true_overshoot = overshoot(&held.1.metrics);
    let true_tactical: Vec<f64> = TURNS.iter().map(|d| tactical(&truth, *d)).collect::<Result<_, _>>()?;

    println!(
        "truth: held-out {} first overshoot {:.2}°, tactical diameters {:?} m",
        PAPER_RUNS[4].0, true_overshoot, true_tactical
    );
    println!();
    let turn_heads: Vec<String> = TURNS
        .iter()
        .zip(&true_tactical)
        .map(|(d, t)| format!("tactical diameter δ = {d}° [m] (true {t:.2})"))
        .collect();
    println!("| back-end | derivative method | states smoothed | coefficient error u̇ / v̇ / ṙ | held-out ψ RMS [°] | 1st overshoot [°] (true {true_overshoot:.2}) | {} |", turn_heads.join(" | "));
    println!("|---|---|---|---|---|---|{}", "---|".repeat(TURNS.len()));
    // measured runs: u0 from each run's approach, not its first (noisy) sample
    let model = truth.edit(|file| {
        if let Some(p) = file.parameters.get_mut("u0") {
            p.per_run = Some("mean:u:4".into());
        }
    })?;
    let text = model.to_toml();
    // no intercept: the model's u² terms carry the constant asymmetry, and at u ≈ u0 an
    // intercept is nearly the same column (with it the fits become ill-conditioned)
    let intercept = false;
    for (backend, spec, smooth, exact) in [
        ("stepwise", "central", false, true),
        ("stepwise", "central", false, false),
        ("stepwise", "savitzky-golay:21:3", false, false),
        ("stepwise", "spline", false, false),
        ("stepwise", "spline", true, false),
        ("stepwise", "kalman", false, false),
        ("stepwise", "kalman", true, false),
        ("stepwise + output error", "kalman", true, false),
        ("stepwise", "kalman*0.1", true, false),
        ("stepwise", "kalman*10", true, false),
        ("stepwise", "kinematic", true, false),
        ("stepwise, u²δ² forced", "kalman", true, false),
        ("stepwise, u²δ² forced", "kinematic", true, false),
        ("true-terms", "kalman", true, false),
        ("efroymson", "kalman", true, false),
        ("best-subset", "kalman", true, false),
        ("sparse", "kalman", true, false),
    ] {
        let parsed = Model::parse(&text, "basin model")?;
        let rudder_asymmetry = parsed.vocabulary.parse("u^2*δ^2")?;
        let same = |text: &str, t: &termid::term::Term| parsed.vocabulary.parse(text).is_ok_and(|p| p == *t);
        let model = parsed.edit(|file| {
            for (name, e) in file.equations.iter_mut().filter(|(_, e)| e.identify) {
                if backend == "true-terms" {
                    // the true structure forced in: what noise does to the coefficients alone
                    let terms: Vec<String> = truth
                        .equation(name)
                        .map(|t| t.coefficients.iter().map(|c| c.0.to_string()).collect())
                        .unwrap_or_default();
                    e.candidates = terms.clone();
                    e.forced = terms;
                    e.excluded.clear();
                } else if backend == "stepwise, u²δ² forced" {
                    // the propeller's asymmetry in the rudder angle, forced in v̇ and ṙ as the
                    // paper forces it in u̇ (a single-screw ship has it)
                    let t = &rudder_asymmetry;
                    let candidate = e.candidates.iter().find(|c| same(c, t)).cloned();
                    if let Some(c) =
                        candidate.filter(|_| name != "u_dot" && !e.forced.iter().any(|f| same(f, t)))
                    {
                        e.forced.push(c);
                    }
                } else {
                    e.backend = Backend::by_name(backend.trim_end_matches(" + output error")).ok();
                }
            }
        })?;
        let frames: Vec<Frame> =
            if exact { train.iter().map(|(_, r)| r.truth.clone()).collect() } else { frames.clone() };
        let method: Box<dyn Differentiator> = match spec.strip_prefix("kalman*") {
            Some(k) => Box::new(Scaled(k.parse()?)),
            None if spec == "kinematic" => Box::new(CentralDifference),
            None => differentiator(spec)?,
        };
        let how = Preparation {
            resample: None,
            method: method.as_ref(),
            signals: vec!["u".into(), "v".into(), "r".into()],
            smooth,
        };
        let prepared: Vec<Frame> = if let Some(plugin) = termid::plugins::with_derivative(spec) {
            frames.iter().map(|f| plugin.prepare(spec, &model, f, smooth)).collect::<Result<_, _>>()?
        } else {
            frames.iter().map(|f| prepare(f, &how)).collect::<Result<_, _>>()?
        };
        let how = ModelIdentification {
            equations: vec![],
            differentiator: method.as_ref(),
            intercept,
            target: None,
        };
        let mut identified = identify_model(&model, &prepared, &how, &mut |_| {})?.model;
        if backend.ends_with("+ output error") {
            // all coefficients refined together on the training runs as prepared (smoothed
            // initial states), comparing velocities and heading (`identify --refine u,v,r,ψ`)
            let states: Vec<String> = ["u", "v", "r", "ψ"].map(String::from).to_vec();
            let training = Runs::new(&identified, &prepared, 0.05, Integrator::Rk4)?
                .with_intercepts(intercept)
                .comparing(&identified, &states)?;
            identified = refine(&identified, &training, &RefineSettings::default())?.model;
        }
        let mut errors = Vec::new();
        for eq in model.identifiable() {
            let coefficients = identified.equation(&eq).map(|e| e.coefficients.clone()).unwrap_or_default();
            let reference = truth.equation(&eq).map(|e| e.coefficients.clone()).unwrap_or_default();
            let mut union: BTreeMap<String, (f64, f64)> = BTreeMap::new();
            for (t, v, _) in &reference {
                union.entry(t.to_string()).or_default().1 = *v;
            }
            for (t, v, _) in &coefficients {
                union.entry(t.to_string()).or_default().0 = *v;
            }
            // each coefficient weighted by its term's RMS in the truth: the error in the
            // acceleration it contributes, so large numbers on tiny terms do not dominate
            let terms: Vec<_> = union.keys().map(|t| model.vocabulary.parse(t)).collect::<Result<_, _>>()?;
            let library = Library::compile(&terms, &model.vocabulary)?;
            let rules = model.parameter_rules();
            let id = Identification {
                vocabulary: &model.vocabulary,
                parameters: &rules,
                differentiator: method.as_ref(),
                intercept: true,
                weights: None,
            };
            let mut m = Moments::new(terms.len());
            for (_, rec) in &train {
                m.merge(&id.moments(&library, &Target::Column("u".into()), &rec.truth)?);
            }
            let rms: Vec<f64> = (0..terms.len()).map(|j| (m.raw(j, j) / m.weight()).sqrt()).collect();
            let num: f64 = union.values().zip(&rms).map(|((a, b), s)| ((a - b) * s).powi(2)).sum();
            let den: f64 = union.values().zip(&rms).map(|((_, b), s)| (b * s).powi(2)).sum();
            errors.push(format!("{:.0} %", 100.0 * (num / den).sqrt()));
        }
        let runs = Runs::new(&identified, &held_frames, 0.01, Integrator::Rk4)?.with_intercepts(intercept);
        let gap = runs.gap(&runs.simulate(&identified, &[], &[])?);
        let psi = gap.states.iter().find(|s| s.0 == "ψ").map_or(f64::NAN, |s| s.2.to_degrees());
        let held_run = Ship::new(&at_approach_speed(&identified, held.1.u0), true)?
            .run(&Manoeuvre::parse(PAPER_RUNS[4].0)?, &settings)?;
        let tact: Vec<String> = TURNS
            .iter()
            .zip(&true_tactical)
            .map(|(d, t)| {
                tactical(&identified, *d)
                    .map(|v| format!("{v:.2} ({:+.1} %)", 100.0 * (v / t - 1.0)))
                    .unwrap_or_else(|_| "diverges".to_string())
            })
            .collect();
        println!(
            "| {backend} | {spec}{} | {} | {} | {psi:.2} | {:.2} | {} |",
            if exact { " (noise-free data)" } else { "" },
            if smooth { "yes" } else { "no" },
            errors.join(" / "),
            overshoot(&held_run.metrics),
            tact.join(" | ")
        );
    }
    Ok(())
}

/// Kalman smoothing at k times the maximum-likelihood noise ratio (k < 1 smooths more).
struct Scaled(f64);

impl Differentiator for Scaled {
    fn name(&self) -> &'static str {
        "kalman-scaled"
    }
    fn differentiate(&self, t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError> {
        Ok(self.smooth(t, x)?.rate)
    }
    fn smooth(&self, t: &[f64], x: &[f64]) -> Result<Smoothed, DataError> {
        let (_, ratio) = KalmanSmoother::default().fit(t, x)?;
        Ok(KalmanSmoother { ratio: Some(ratio * self.0) }.fit(t, x)?.0)
    }
}
