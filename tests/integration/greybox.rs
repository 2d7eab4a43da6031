//! Grey-box identification: named parameters of a model file, nonlinear in them, estimated by
//! output error from noisy runs. The truths are generated here by an RK4 loop of the test's
//! own (not termid's simulator), and the estimates start well away from them.

use termid::data::Frame;
use termid::diagnose::{estimate, Estimate, EstimateSettings, InitialValues, Runs};
use termid::model::Model;
use termid::sim::Integrator;

use crate::common::{lorenz_rows, noise, noisy_frame, trajectory, Lcg, LORENZ_FREE, LORENZ_TRUTH};

/// Nomoto's T·ṙ + r = K·δ in a zigzag (the rudder put over to ∓`rudder` when the heading
/// passes ±`rudder`; the test's own logic), from rest: the rows (ψ, r) every `h` seconds
/// and the rudder as recorded at each (the value in force over the next interval).
pub(crate) fn nomoto_zigzag(
    k: f64,
    t_const: f64,
    rudder: f64,
    h: f64,
    samples: usize,
) -> (Vec<Vec<f64>>, Vec<f64>) {
    nomoto_zigzag_holding(k, t_const, rudder, 0.0, h, samples)
}

/// The same for a ship that holds its course at the rudder angle `−bias` (rad): it answers to
/// δ + bias, recorded as δ.
fn nomoto_zigzag_holding(
    k: f64,
    t_const: f64,
    rudder: f64,
    bias: f64,
    h: f64,
    samples: usize,
) -> (Vec<Vec<f64>>, Vec<f64>) {
    let mut delta = rudder;
    let mut deltas = Vec::new();
    let rows = trajectory(&[0.0, 0.0], h, samples, 4, |_, x| {
        if delta > 0.0 && x[0] > rudder {
            delta = -rudder;
        } else if delta < 0.0 && x[0] < -rudder {
            delta = rudder;
        }
        deltas.push(delta);
        vec![x[1], (k * (delta + bias) - x[1]) / t_const]
    });
    // four RK4 stages of four sub-steps a sample: the first stage's rudder is the sample's
    let recorded = (0..rows.len()).map(|i| deltas[(i * 16).min(deltas.len() - 1)]).collect();
    (rows, recorded)
}

/// A zigzag's heading and yaw rate (`rows` of ψ, r) as a gyro reads them: 0.1° and 0.05 °/s
/// of noise, from `seed`.
fn gyro(rows: &[Vec<f64>], seed: u64) -> Vec<(f64, f64)> {
    let mut rng = Lcg(seed);
    rows.iter()
        .map(|row| {
            (row[0] + 0.1f64.to_radians() * rng.normal(), row[1] + 0.05f64.to_radians() * rng.normal())
        })
        .collect()
}

/// The MMG truth (`models/mmg_kvlcc2.toml`).
fn mmg_truth() -> Model {
    termid::plugins::load(std::path::Path::new("models/mmg_kvlcc2.toml")).unwrap()
}

/// Four zigzags of the MMG basin (10/10 and 20/20 to both sides, 60 s after the approach,
/// sensor noise on every channel), recorded from `truth`; written into `dir` when given.
/// Returns (file name, measured run).
fn basin_zigzags(truth: &Model, dir: Option<&std::path::Path>) -> Vec<(String, Frame)> {
    let zigzags = [
        ("zigzag:10/10", 0.98),
        ("zigzag:10/10:port", 1.02),
        ("zigzag:20/20", 1.01),
        ("zigzag:20/20:port", 0.97),
    ];
    termid::ship::basin::Basin::default()
        .record_all(truth, &zigzags, 1.17248, 60.0, 31, dir)
        .unwrap()
        .into_iter()
        .map(|(name, r)| (name, r.measured))
        .collect()
}

/// A ship model's tactical diameter turning with `rudder` degrees, m (RK4 at 0.01 s).
fn tactical_diameter(model: &Model, rudder: f64) -> f64 {
    use termid::ship::{Manoeuvre, Metrics, Ship};
    let ship = Ship::new(model, false).unwrap();
    let s = termid::sim::Settings { integrator: Integrator::Rk4, dt: 0.01, duration: 200.0, sample: 0.05 };
    let Metrics::Turning(t) =
        ship.run(&Manoeuvre::parse(&format!("turning:{rudder}")).unwrap(), &s).unwrap().metrics
    else {
        unreachable!()
    };
    t.tactical_diameter_m.unwrap()
}

/// Runs re-simulated one RK4 step a sample.
fn runs_of(model: &Model, frames: &[Frame]) -> Runs {
    let sample = frames[0].time()[1] - frames[0].time()[0];
    Runs::new(model, frames, sample, Integrator::Rk4).unwrap()
}

/// Lorenz's σ, ρ, β from one trajectory with 1 % noise, started 20 % off: the trajectory cut
/// into windows of half a Lyapunov time (a chaotic system's output error over longer horizons
/// has many minima), each re-simulated from its own first sample.
#[test]
fn lorenz_parameters_from_one_noisy_trajectory() {
    let (sigma, rho, beta) = LORENZ_TRUTH;
    let h = 0.01;
    let rows = lorenz_rows(h, 1001);
    let sd = noise(&rows, 0.01);
    let mut rng = Lcg(7);
    let frames: Vec<Frame> = rows
        .chunks(51)
        .enumerate()
        .filter(|(_, w)| w.len() > 25)
        .map(|(k, w)| noisy_frame(&format!("window{k}"), h, &["x", "y", "z"], w, &sd, &mut rng))
        .collect();
    let model = Model::parse(LORENZ_FREE, "lorenz_free.toml").unwrap();
    let runs = Runs::new(&model, &frames, h, Integrator::Rk4).unwrap();
    let fit = estimate(&model, &runs, &EstimateSettings::default()).unwrap();
    assert!(fit.cost_after < 0.05 * fit.cost_before, "{}", fit.text());
    for (name, truth) in [("σ", sigma), ("ρ", rho), ("β", beta)] {
        let p = fit.parameters.iter().find(|p| p.name == name).unwrap();
        assert!((p.value / truth - 1.0).abs() < 0.01, "{name}: {} vs {truth}\n{}", p.value, fit.text());
        // the truth within three standard errors: the errors are honest, not decorative
        assert!(
            p.std_error.is_finite() && (p.value - truth).abs() < 3.0 * p.std_error.max(1e-3 * truth),
            "{}",
            fit.text()
        );
    }
    // written back: values, standard errors and the covariance in the file
    let text = fit.model.to_toml();
    let again = Model::parse(&text, "estimated.toml").unwrap();
    assert!((again.parameter_values()["ρ"] / rho - 1.0).abs() < 0.01);
    assert!(again.spec().parameter_covariance.as_ref().is_some_and(|c| c.names.len() == 3));
}

const NOMOTO: &str = r#"
[model]
name = "Nomoto's first-order steering model, K and T free"
intercept = false

[[states]]
name = "ψ"
unit = "rad"
[[states]]
name = "r"
unit = "rad/s"

[[inputs]]
name = "δ"
unit = "rad"

[parameters.K]
value = 0.195
unit = "1/s"
free = true
bounds = [0.0, 5.0]
[parameters.T]
value = 5.6
unit = "s"
free = true
bounds = [0.1, 100.0]

[equations.psi_dot]
state = "ψ"
identify = false
coefficients = { "r" = 1.0 }
[equations.r_dot]
state = "r"
identify = false
coefficients = { "K*δ/T" = 1.0, "r/T" = -1.0 }
"#;

/// Nomoto's K and T estimated from a 20°/20° zigzag of `rows` with gyro noise, started 30 %
/// off both, the initial values as `initial`.
fn nomoto_estimate(
    name: &str,
    h: f64,
    zigzag: (Vec<Vec<f64>>, Vec<f64>),
    initial: InitialValues,
) -> Estimate {
    nomoto_estimate_with(name, h, zigzag, &EstimateSettings { initial_values: initial, ..Default::default() })
}

/// The same with any settings.
fn nomoto_estimate_with(
    name: &str,
    h: f64,
    (rows, recorded): (Vec<Vec<f64>>, Vec<f64>),
    settings: &EstimateSettings,
) -> Estimate {
    let mut rng = Lcg(11);
    let mut frame =
        noisy_frame(name, h, &["ψ", "r"], &rows, &[0.1f64.to_radians(), 0.05f64.to_radians()], &mut rng);
    frame.push("δ", recorded).unwrap();
    let model = Model::parse(NOMOTO, "nomoto.toml").unwrap();
    let runs = Runs::new(&model, &[frame], h, Integrator::Rk4).unwrap();
    estimate(&model, &runs, settings).unwrap()
}

/// Fitted at the coarsest step that resolves the run (as the identify recipe's parameter stage
/// fits; a gyro at 50 Hz), the zigzag gives K and T within one standard error of the fit at
/// every sample, with standard errors within 20 % of its, and the report's costs are still the
/// run's at every sample: the start's exactly.
#[test]
fn an_estimate_at_a_coarser_step_reports_at_every_sample() {
    let (k, t_const, h) = (0.15, 8.0, 0.02);
    let zigzag = nomoto_zigzag(k, t_const, 20f64.to_radians(), h, 6001);
    let every = nomoto_estimate_with("zigzag", h, zigzag.clone(), &EstimateSettings::default());
    let coarse = EstimateSettings { coarsest: Some((1e-3, 8)), ..Default::default() };
    let coarse = nomoto_estimate_with("zigzag", h, zigzag, &coarse);
    assert_eq!(every.step_samples, 1);
    assert!(coarse.step_samples > 1 && coarse.text().contains("fitted at a step of"), "{}", coarse.text());
    assert_eq!(coarse.cost_before, every.cost_before);
    // another fit (a coarser step holds for this run), reported at every sample
    assert_ne!(coarse.cost_after, every.cost_after);
    assert!((coarse.cost_after / every.cost_after - 1.0).abs() < 0.02, "{}\n{}", coarse.text(), every.text());
    for (a, b) in coarse.parameters.iter().zip(&every.parameters) {
        assert!(
            (a.value - b.value).abs() < b.std_error,
            "{}: {} vs {} ± {}",
            a.name,
            a.value,
            b.value,
            b.std_error
        );
        assert!(
            (a.std_error / b.std_error - 1.0).abs() < 0.2,
            "{}: ± {} vs ± {}",
            a.name,
            a.std_error,
            b.std_error
        );
    }
    // the correlation time in the record's samples, not the coarse step's
    let (ta, tb) = (coarse.correlation_time.unwrap(), every.correlation_time.unwrap());
    assert!(ta / tb > 0.5 && ta / tb < 2.0, "τ {ta} vs {tb}");
}

/// Nomoto's K and T from a 20°/20° zigzag with gyro noise, started 30 % off both.
#[test]
fn nomoto_k_and_t_from_a_zigzag() {
    let (k, t_const, h) = (0.15, 8.0, 0.1);
    for initial in [InitialValues::Measured, InitialValues::Free] {
        let fit =
            nomoto_estimate("zigzag", h, nomoto_zigzag(k, t_const, 20f64.to_radians(), h, 1201), initial);
        for (name, truth) in [("K", k), ("T", t_const)] {
            let p = fit.parameters.iter().find(|p| p.name == name).unwrap();
            assert!((p.value / truth - 1.0).abs() < 0.03, "{name}: {} vs {truth}\n{}", p.value, fit.text());
        }
        // the initial values move by about the first samples' noise: the structure holds
        let from = fit.from_records.as_ref().unwrap();
        assert!(!from.leans && from.moved.unwrap() < 2.0, "{initial:?}: {}", fit.text());
    }
}

/// A fit whose model lacks an effect the ship has (a rudder that holds the course at −3°, not
/// at 0) leans on its estimated initial values: they move far beyond the first samples' noise
/// to absorb it when free, and the report says so rather than print the fit's cost as the
/// model's; held by the records' noise they do not, and the default then keeps that fit, which
/// the report flags as not following its records (the missing offset builds up over the run).
#[test]
fn a_fit_that_leans_on_its_initial_values_is_flagged() {
    let (k, t_const, h) = (0.15, 8.0, 0.1);
    let zigzag = nomoto_zigzag_holding(k, t_const, 20f64.to_radians(), 3f64.to_radians(), h, 1201);
    let free = nomoto_estimate("biased", h, zigzag.clone(), InitialValues::Free);
    let from = free.from_records.as_ref().unwrap();
    assert!(from.leans && from.moved.unwrap() > 3.0, "{}", free.text());
    let text = free.text();
    assert!(text.contains("FLAG the fit leans on its estimated initial values"), "{text}");
    // held by the first samples' noise they cannot: the fit's cost is the cost
    // from the records, the one a prediction has, and the missing effect shows in it
    let held = nomoto_estimate("biased", h, zigzag.clone(), InitialValues::Measured);
    let from = held.from_records.as_ref().unwrap();
    assert!(!from.leans && from.moved.unwrap() < 2.0, "{}", held.text());
    assert!((from.cost.unwrap() / held.cost_after - 1.0).abs() < 0.05, "{}", held.text());
    assert!(held.cost_after > 2.0 * free.cost_after, "{}\n{}", held.text(), free.text());
    assert!(!held.text().contains("FLAG the fit leans"), "{}", held.text());
    // and it says that the fit fails: the offset the model lacks builds up over the run, which
    // segments of it would hide
    assert!(!held.follows(), "{}", held.text());
    assert!(
        held.text().contains("FLAG the fit does not follow the records") && held.text().contains("an offset")
    );
    // a stable model fitted on segments does not part from itself: no chaos is claimed
    assert!(!held.text().contains("parts from itself"), "{}", held.text());
    // the default fits free, sees the lean, fits again held and keeps that fit: it predicts
    // the run from its record better
    let auto = nomoto_estimate("biased", h, zigzag, InitialValues::Auto);
    let again = auto.held_again.as_ref().unwrap();
    assert!(again.kept && again.other.leans, "{}", auto.text());
    assert_eq!(auto.cost_after, held.cost_after);
    assert!(auto.text().contains("the initial values held to the first samples' noise"), "{}", auto.text());
    assert!(!auto.text().contains("FLAG the fit leans"), "{}", auto.text());
    assert!(!auto.follows(), "{}", auto.text());
}

/// A prior holds what the runs cannot see: a ship at rest (ψ and r noise about zero, no
/// rudder) tells nothing of K and T, so the estimate is the prior and its standard error
/// the prior's sd.
#[test]
fn a_prior_holds_what_the_runs_do_not_see() {
    let text = NOMOTO
        .replace(
            "value = 0.195\nunit = \"1/s\"\nfree = true",
            "value = 0.195\nunit = \"1/s\"\nfree = true\nprior = { value = 0.2, sd = 0.01 }",
        )
        .replace(
            "value = 5.6\nunit = \"s\"\nfree = true",
            "value = 5.6\nunit = \"s\"\nfree = true\nprior = { value = 6.0, sd = 0.5 }",
        );
    assert_eq!(text.matches("prior =").count(), 2);
    let model = Model::parse(&text, "nomoto.toml").unwrap();
    let t: Vec<f64> = (0..200).map(|i| i as f64 * 0.1).collect();
    let mut f = Frame::new("still", "t", t.clone()).unwrap();
    let mut rng = Lcg(3);
    // at rest from the first sample on (where a simulation starts): noise after it
    let noise = |rng: &mut Lcg| {
        t.iter().enumerate().map(|(i, _)| if i == 0 { 0.0 } else { 1e-4 * rng.normal() }).collect()
    };
    f.push("ψ", noise(&mut rng)).unwrap();
    f.push("r", noise(&mut rng)).unwrap();
    f.push("δ", vec![0.0; t.len()]).unwrap();
    let runs = Runs::new(&model, &[f], 0.1, Integrator::Rk4).unwrap();
    // the initial values held at the first sample (estimated, a noise-sized r(0) would tell T)
    let settings = EstimateSettings { initial_values: InitialValues::Recorded, ..Default::default() };
    let fit = estimate(&model, &runs, &settings).unwrap();
    for (name, mean, sd) in [("K", 0.2, 0.01), ("T", 6.0, 0.5)] {
        let p = fit.parameters.iter().find(|p| p.name == name).unwrap();
        assert!((p.value - mean).abs() < 1e-3 * mean, "{}", fit.text());
        assert!((p.std_error / sd - 1.0).abs() < 1e-3, "{}", fit.text());
        // and the report says the runs gave it nothing
        assert!(p.from_runs.is_some_and(|s| s < 0.01), "{}", fit.text());
    }
    assert!(
        fit.text().contains("the runs gave less than half the precision of K (0 %), T (0 %)"),
        "{}",
        fit.text()
    );
}

/// What the runs decide is reported beside the estimates: the spring's stiffness split in two
/// parts that act only as their sum, each with a wide prior, is a pair the runs tie (their
/// correlation −1 within 1 %: the runs fix k₁ + k₂ = 1.4 within 2 %, not each), while the
/// damping, which the runs show, has nearly all its precision from them (≥ 99 %).
#[test]
fn a_pair_the_runs_tie_and_what_they_decide_are_reported() {
    let text = LOAD_CELL
        .replace(
            "[parameters.k]\nvalue = 1.0\nfree = true",
            "[parameters.k1]\nvalue = 0.5\nfree = true\nprior = { value = 0.5, sd = 10.0 }\n[parameters.k2]\nvalue = 0.5\nfree = true\nprior = { value = 0.5, sd = 10.0 }",
        )
        .replace("[parameters.b]\nvalue = 0.1\nfree = true", "[parameters.b]\nvalue = 0.1\nfree = true\nprior = { value = 0.1, sd = 1.0 }")
        .replace("[parameters.g]\nvalue = 1.0\nfree = true", "[parameters.g]\nvalue = 1.0")
        .replace("definition = \"k*x + 0.3*x^3\"", "definition = \"(k1 + k2)*x + 0.3*x^3\"");
    assert_eq!(text.matches("prior =").count(), 3);
    let model = Model::parse(&text, "split.toml").unwrap();
    let runs = Runs::new(&model, &[load_cell_run(5)], 0.05, Integrator::Rk4).unwrap();
    let fit = estimate(&model, &runs, &EstimateSettings::default()).unwrap();
    let value = |name: &str| fit.parameters.iter().find(|p| p.name == name).unwrap();
    let sum = value("k1").value + value("k2").value;
    assert!((sum / LOAD_CELL_TRUTH.0 - 1.0).abs() < 0.02, "{sum}\n{}", fit.text());
    assert_eq!(fit.correlated.len(), 1, "{}", fit.text());
    let pair = &fit.correlated[0];
    assert!((pair.a.as_str(), pair.b.as_str()) == ("k1", "k2") && pair.correlation < -0.99, "{}", fit.text());
    assert!(value("b").from_runs.is_some_and(|s| s >= 0.99), "{}", fit.text());
    assert!(fit.text().contains("estimates correlated beyond ±0.95"), "{}", fit.text());
}

/// `termid estimate --initial-values`: by default a fit that leans on its initial values (a
/// ship holding its course at −3°, fitted without that offset) is made again with them held
/// and says so; `free` keeps the leaning fit, flagged; a way that is none is refused by name.
#[test]
fn the_estimate_command_holds_initial_values_where_the_fit_leans() {
    let (k, t_const, h) = (0.15, 8.0, 0.1);
    let (rows, deltas) = nomoto_zigzag_holding(k, t_const, 20f64.to_radians(), 3f64.to_radians(), h, 1201);
    let dir = crate::common::Scratch::new("estimate-initial");
    let mut csv = String::from("t,ψ,r,δ\n");
    for (i, (psi, r)) in gyro(&rows, 7).into_iter().enumerate() {
        csv.push_str(&format!("{},{psi},{r},{}\n", i as f64 * h, deltas[i]));
    }
    let data = dir.join("biased.csv");
    std::fs::write(&data, csv).unwrap();
    let run = |way: Option<&str>| {
        let mut args = vec!["estimate", "--model", "models/nomoto.toml", "--data", data.to_str().unwrap()];
        if let Some(way) = way {
            args.extend(["--initial-values", way]);
        }
        crate::common::termid(&args)
    };
    let (ok, text, err) = run(None);
    assert!(ok, "{err}");
    assert!(
        text.contains("the initial values held to the first samples' noise")
            && !text.contains("FLAG the fit leans")
            && text.contains("FLAG the fit does not follow the records"),
        "{text}"
    );
    let (ok, text, err) = run(Some("free"));
    assert!(ok, "{err}");
    assert!(text.contains("FLAG the fit leans on its estimated initial values"), "{text}");
    let (ok, _, err) = run(Some("fixed"));
    assert!(!ok && err.contains("none of auto, measured, free, recorded"), "{err}");
}

/// A heading recorded as a compass reads it, in [0, 2π): the zigzag about north wraps at every
/// crossing. `estimate` reads it as one continuous angle and says so, and fits K and T as from
/// the continuous record; `Runs::new`, which compares the records as given, refuses it with
/// the row (it compared a ship turning on with one jumping back by a full turn: 352° "off").
#[test]
fn the_estimate_command_reads_a_compass_heading_through_north() {
    let (k, t_const, h) = (0.15, 8.0, 0.1);
    let (rows, deltas) = nomoto_zigzag(k, t_const, 10f64.to_radians(), h, 901);
    let dir = crate::common::Scratch::new("estimate-compass");
    let (mut continuous, mut compass) = (String::from("t,ψ,r,δ\n"), String::from("t,ψ,r,δ\n"));
    for (i, (psi, r)) in gyro(&rows, 11).into_iter().enumerate() {
        let t = i as f64 * h;
        continuous.push_str(&format!("{t},{psi},{r},{}\n", deltas[i]));
        compass.push_str(&format!("{t},{},{r},{}\n", psi.rem_euclid(std::f64::consts::TAU), deltas[i]));
    }
    let estimate = |name: &str, text: &str| {
        let (data, out) = (dir.join(format!("{name}.csv")), dir.join(format!("{name}.toml")));
        std::fs::write(&data, text).unwrap();
        let args = ["estimate", "--model", "models/nomoto.toml", "--data", data.to_str().unwrap()];
        let (ok, stdout, err) =
            crate::common::termid(&[&args[..], &["--out", out.to_str().unwrap()]].concat());
        assert!(ok, "{err}");
        (termid::plugins::load(&out).unwrap().parameter_values(), format!("{stdout}{err}"))
    };
    let (want, _) = estimate("continuous", &continuous);
    let (got, said) = estimate("compass", &compass);
    assert!(said.contains("`ψ` jumps by a full turn") && !said.contains("FLAG"), "{said}");
    for p in ["K", "T"] {
        assert!((got[p] / want[p] - 1.0).abs() < 1e-9, "{p}: {} against {}", got[p], want[p]);
    }
    assert!((got["K"] / k - 1.0).abs() < 0.05 && (got["T"] / t_const - 1.0).abs() < 0.05, "{got:?}");
    // the library compares what it is given: a wrapped record is refused, with its row
    let model = termid::plugins::load(std::path::Path::new("models/nomoto.toml")).unwrap();
    let frame = Frame::parse_csv(&compass, "compass.csv", "t").unwrap();
    let e = Runs::new(&model, &[frame], h, Integrator::Rk4).err().unwrap().to_string();
    assert!(e.contains("compass.csv: `ψ` jumps by more than half a turn at row"), "{e}");
}

/// A run whose time is a logger's stamps, a clock's (`23:59:58.300`) or a date's
/// (`2026-11-27T11:58:40.300Z`): read as seconds, the run fitted as from seconds since its
/// start (it was refused: "`12:00:00.0` is not a number"); within 1e-4, as a date's seconds
/// since 1970 resolve a step to 2e-7 s. A clock that passes midnight is read on into the
/// next day.
#[test]
fn the_estimate_command_reads_a_loggers_time_stamps() {
    let (k, t_const, h) = (0.15, 8.0, 0.1);
    let (rows, deltas) = nomoto_zigzag(k, t_const, 10f64.to_radians(), h, 601);
    let dir = crate::common::Scratch::new("estimate-stamps");
    let clock = |s: f64| {
        let (whole, ms) = ((s.floor() as u64) % 86_400, ((s - s.floor()) * 1000.0).round() as u64);
        format!("{:02}:{:02}:{:02}.{ms:03}", whole / 3600, whole / 60 % 60, whole % 60)
    };
    let estimate = |name: &str, stamp: &dyn Fn(f64) -> String| {
        let mut text = String::from("t,ψ,r,δ\n");
        for (i, row) in rows.iter().enumerate() {
            text.push_str(&format!("{},{},{},{}\n", stamp(i as f64 * h), row[0], row[1], deltas[i]));
        }
        let (data, out) = (dir.join(format!("{name}.csv")), dir.join(format!("{name}.toml")));
        std::fs::write(&data, text).unwrap();
        let args = ["estimate", "--model", "models/nomoto.toml", "--data", data.to_str().unwrap()];
        let (ok, _, err) = crate::common::termid(&[&args[..], &["--out", out.to_str().unwrap()]].concat());
        (ok, ok.then(|| termid::plugins::load(&out).unwrap().parameter_values()), err)
    };
    let (_, seconds, _) = estimate("seconds", &|t| format!("{t:.3}"));
    let seconds = seconds.unwrap();
    assert!(
        (seconds["K"] / k - 1.0).abs() < 0.02 && (seconds["T"] / t_const - 1.0).abs() < 0.02,
        "{seconds:?}"
    );
    let (ok, dated, err) = estimate("dated", &|t| format!("2026-11-27T{}Z", clock(43_120.3 + t)));
    assert!(ok, "{err}");
    let (ok, clocked, err) = estimate("clocked", &|t| clock(43_120.3 + t));
    assert!(ok, "{err}");
    // a clock that passes midnight is read on into the next day (it was refused as going back)
    let (ok, midnight, err) = estimate("midnight", &|t| clock(86_380.0 + t));
    assert!(ok, "{err}");
    for fit in [dated.unwrap(), clocked.unwrap(), midnight.unwrap()] {
        for p in ["K", "T"] {
            assert!((fit[p] / seconds[p] - 1.0).abs() < 1e-4, "{p}: {} against {}", fit[p], seconds[p]);
        }
    }
}

/// Keys that make no sense are refused with the file and key.
#[test]
fn free_parameter_keys_are_checked() {
    for (from, to, key) in [
        ("bounds = [0.0, 5.0]", "bounds = [5.0, 0.0]", "parameters.K.bounds"),
        ("bounds = [0.0, 5.0]", "bounds = [0.5, 5.0]", "parameters.K.value"),
        (
            "free = true\nbounds = [0.0, 5.0]",
            "free = true\nprior = { value = 0.2, sd = 0.0 }",
            "parameters.K.prior",
        ),
        ("free = true\nbounds = [0.0, 5.0]", "free = true\nper_run = \"first:r\"", "parameters.K.free"),
        ("free = true\nbounds = [0.0, 5.0]", "free = true\nmedium = 1", "expected a boolean"),
        (
            "free = true\nbounds = [0.0, 5.0]",
            "free = true\nnuisance = \"basin\"",
            "expected `run` or `source`",
        ),
    ] {
        let text = NOMOTO.replacen(from, to, 1);
        assert_ne!(text, NOMOTO, "{from}");
        let e = Model::parse(&text, "nomoto.toml").unwrap_err().to_string();
        assert!(e.contains("nomoto.toml") && e.contains(key), "{key}: {e}");
    }
}

/// The MMG model of KVLCC2 from the MMG basin's zigzags (sensor noise on every channel): the
/// hull's linear derivatives, the rudder's wake ratio ε and flow-straightening γ_R, started
/// 30 % off, back to the truth's within 5 %, and the turning circles (a manoeuvre no run
/// covered) within 1 %. Each run's initial state is estimated with them (by default): from
/// the noisy first samples the same fit lands 30-150 % off.
#[test]
fn mmg_kvlcc2_parameters_from_basin_zigzags() {
    let truth = mmg_truth();
    let frames: Vec<Frame> = basin_zigzags(&truth, None).into_iter().map(|(_, f)| f).collect();
    let free = ["Y_v", "Y_r", "N_v", "N_r", "ε", "γ_Rp", "γ_Rm"];
    let values = truth.parameter_values();
    let start = truth
        .edit(|file| {
            for (k, name) in free.iter().enumerate() {
                let p = file.parameters.get_mut(*name).unwrap();
                // 30 % off, alternately above and below
                p.value *= if k % 2 == 0 { 1.3 } else { 0.7 };
                p.free = true;
            }
        })
        .unwrap();
    let fit = estimate(&start, &runs_of(&start, &frames), &EstimateSettings::default()).unwrap();
    for name in free {
        let p = fit.parameters.iter().find(|p| p.name == name).unwrap();
        let truth = values[name];
        assert!((p.value / truth - 1.0).abs() < 0.05, "{name}: {} vs {truth}\n{}", p.value, fit.text());
    }
    for rudder in [35.0, -35.0] {
        let (a, b) = (tactical_diameter(&fit.model, rudder), tactical_diameter(&truth, rudder));
        assert!(
            (a / b - 1.0).abs() < 0.01,
            "δ = {rudder}°: tactical diameter {a} m, truth {b} m\n{}",
            fit.text()
        );
    }
    // the model has the truth's structure: its initial values move by the sensors' noise
    assert!(!fit.from_records.as_ref().unwrap().leans, "{}", fit.text());
}

/// `simulate --monte-carlo` says what the spread comes from: the MMG KVLCC2 with a covariance
/// that leaves ε uncertain (sd 0.1) and γ_R+ all but known. One sd of ε moves the ±35°
/// tactical diameter by half the difference of two `simulate --param` runs at ε ± 0.1, all of
/// its variance is ε's, none γ_R+'s, and the linearised sd lies near the draws' (within 35 %
/// on 40 draws).
#[test]
fn monte_carlo_says_what_its_spread_comes_from() {
    use crate::common::{json, termid};
    let dir = crate::common::Scratch::new("spread-from");
    let model = dir.join("mmg.toml");
    let text = std::fs::read_to_string("models/mmg_kvlcc2.toml").unwrap();
    let covariance =
        "\n[parameter_covariance]\nnames = [\"ε\", \"γ_Rp\"]\nmatrix = [[0.01, 0.0], [0.0, 1e-8]]\n";
    std::fs::write(&model, format!("{text}{covariance}")).unwrap();
    let model = model.to_str().unwrap();
    // the ±35° turn, with more options
    let turn = |more: &[&str]| {
        let mut args = vec!["simulate", "--model", model, "-m", "turning:35"];
        args.extend(more);
        termid(&args)
    };
    let diameter = |epsilon: f64| {
        let (ok, out, err) = turn(&["--param", &format!("ε={epsilon}"), "--format", "json"]);
        assert!(ok, "{err}");
        json(&out)["metrics"]["tactical_diameter_m"].as_f64().unwrap()
    };
    let effect = 0.5 * (diameter(1.09 + 0.1) - diameter(1.09 - 0.1));
    let (ok, out, err) = turn(&["--monte-carlo", "40", "--format", "json"]);
    assert!(ok, "{err}");
    let report = json(&out);
    let epsilon =
        report["parameter_effects"].as_array().unwrap().iter().find(|e| e["parameter"] == "ε").unwrap();
    let moved = epsilon["effects"]["tactical_diameter_m"].as_f64().unwrap();
    assert!((moved - effect).abs() < 1e-9 * effect.abs(), "{moved} vs {effect}");
    let from = &report["spread_from"]["tactical_diameter_m"];
    assert_eq!(from["explained"][0][0], "ε", "{from}");
    assert!(
        from["explained"][0][1].as_f64().unwrap() > 0.999
            && from["explained"][1][1].as_f64().unwrap() < 0.001,
        "{from}"
    );
    let (linearised, drawn) = (
        from["linearised_sd"].as_f64().unwrap(),
        report["monte_carlo"]["spread"]["tactical_diameter_m"]["sd"].as_f64().unwrap(),
    );
    assert!((linearised / effect.abs() - 1.0).abs() < 1e-6, "{linearised} vs {effect}");
    assert!((linearised / drawn - 1.0).abs() < 0.35, "{linearised} vs {drawn}");
    let (_, text, _) = turn(&["--monte-carlo", "40"]);
    assert!(text.contains("what the spread comes from") && text.contains("ε 100 %"), "{text}");
}

/// The same for a model under constant inputs (`simulate --input … --monte-carlo`): Nomoto's
/// step response with K and T uncertain (sd 0.01 and 0.5, correlation 0.1). At t = 200 s
/// ψ = Kδ(t − T(1 − e^(−t/T))) in closed form: one sd of K moves it by 0.01·δ·190, one of T by
/// −K·δ·0.5, and the final yaw rate Kδ is K's alone (T's share its correlation's square).
#[test]
fn monte_carlo_under_constant_inputs_says_what_its_spread_comes_from() {
    use crate::common::{json, termid};
    let dir = crate::common::Scratch::new("spread-from-step");
    let model = dir.join("nomoto.toml");
    let covariance =
        "\n[parameter_covariance]\nnames = [\"K\", \"T\"]\nmatrix = [[1e-4, 5e-4], [5e-4, 0.25]]\n";
    let text = std::fs::read_to_string("models/nomoto.toml").unwrap();
    std::fs::write(&model, format!("{text}{covariance}")).unwrap();
    let model = model.to_str().unwrap();
    let args = ["simulate", "--model", model, "--input", "δ=0.1", "--duration", "200", "--monte-carlo", "20"];
    let (ok, out, err) = termid(&[&args[..], &["--format", "json"]].concat());
    assert!(ok, "{err}");
    let report = json(&out);
    let effects = &report["parameter_effects"];
    let effect = |k: usize, metric: &str| effects[k]["effects"][metric].as_f64().unwrap();
    assert!((effect(0, "final ψ") - 0.01 * 0.1 * 190.0).abs() < 1e-6, "{effects}");
    assert!((effect(1, "final ψ") + 0.1 * 0.1 * 0.5).abs() < 1e-6, "{effects}");
    let rate = &report["spread_from"]["final r"]["explained"];
    assert!(rate[0][0] == "K" && (rate[0][1].as_f64().unwrap() - 1.0).abs() < 1e-6, "{rate}");
    assert!((rate[1][1].as_f64().unwrap() - 0.01).abs() < 1e-6, "{rate}");
    let (_, text, _) = termid(&args);
    assert!(text.contains("what the spread comes from") && text.contains("K 100 %, T 1 %"), "{text}");
}

/// `termid estimate` end to end on the shipped Nomoto file: a zigzag CSV in, the estimates
/// with standard errors and covariance written, and `simulate --monte-carlo` drawing from
/// that covariance.
#[test]
fn the_estimate_command_writes_estimates_that_monte_carlo_draws_from() {
    let (k, t_const, h) = (0.15, 8.0, 0.1);
    let (rows, deltas) = nomoto_zigzag(k, t_const, 20f64.to_radians(), h, 601);
    let mut rng = Lcg(5);
    let dir = crate::common::Scratch::new("estimate-cli");
    let mut csv = String::from("t,ψ,r,δ\n");
    for (i, row) in rows.iter().enumerate() {
        let d = deltas[i];
        let (psi, r) = (row[0] + 0.002 * rng.normal(), row[1] + 0.001 * rng.normal());
        csv.push_str(&format!("{},{psi},{r},{d}\n", i as f64 * h));
    }
    let data = dir.join("zigzag.csv");
    std::fs::write(&data, csv).unwrap();
    let out = dir.join("nomoto_estimated.toml");
    let figures = dir.join("figures");
    let (ok, text, err) = crate::common::termid(&[
        "estimate",
        "--model",
        "models/nomoto.toml",
        "--data",
        data.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--svg",
        figures.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(text.contains("estimate") && text.contains("initial values"), "{text}");
    // the run measured beside the start values' simulation and the estimate's
    let svg = std::fs::read_to_string(figures.join("estimate_zigzag.svg")).unwrap();
    assert!(svg.contains("start values") && svg.contains("estimated") && svg.contains("measured"), "{text}");
    let model = Model::load(&out).unwrap();
    let p = model.parameter_values();
    assert!((p["K"] / k - 1.0).abs() < 0.03 && (p["T"] / t_const - 1.0).abs() < 0.03, "{p:?}\n{text}");
    let spec = model.spec();
    assert!(spec.parameters["K"].std_error.is_some_and(|s| s > 0.0 && s < 0.01), "{text}");
    assert_eq!(spec.parameter_covariance.as_ref().unwrap().names, ["K", "T"]);
    // at the coarsest step that resolves the run (as the recipe's parameter stage fits), said
    // so, the same estimates within their standard errors
    let (ok, coarse, err) = crate::common::termid(&[
        "estimate",
        "--model",
        "models/nomoto.toml",
        "--data",
        data.to_str().unwrap(),
        "--coarse",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let coarse: serde_json::Value = serde_json::from_str(&coarse).unwrap();
    assert!(coarse["step_samples"].as_u64().unwrap() > 1, "{coarse}");
    // no plug-in owns the Nomoto model: no metrics to read off its runs
    assert_eq!(coarse["metrics"], serde_json::json!([]), "{coarse}");
    for q in coarse["parameters"].as_array().unwrap() {
        let name = q["name"].as_str().unwrap();
        let sd = spec.parameters[name].std_error.unwrap();
        assert!((q["value"].as_f64().unwrap() - p[name]).abs() < sd, "{name}: {q}");
    }
    // the draws come from the parameters' covariance: the model has no other
    let (ok, text, err) = crate::common::termid(&[
        "simulate",
        "--model",
        out.to_str().unwrap(),
        "--input",
        "δ=0.1",
        "--duration",
        "30",
        "--monte-carlo",
        "40",
    ]);
    assert!(ok, "{err}");
    assert!(text.contains("40") || text.to_lowercase().contains("monte"), "{text}");
    // a model without free parameters is told so
    let (ok, _, err) = crate::common::termid(&[
        "estimate",
        "--model",
        "models/lorenz.toml",
        "--data",
        data.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("free"), "{err}");
}

/// A ship nobody has tested: the grey-box MMG model `termid new-ship` writes from KVLCC2's
/// particulars (hull by Kijima et al. 1990, rudder lift by Fujii, wake by Taylor; generic
/// interaction coefficients), every parameter free with its prior, estimated from four
/// zigzags of the MMG basin, predicts the ±35° turning circles (no run covered them) within
/// 5 % of the truth's; the particulars alone are 19-31 % off.
#[test]
fn a_new_ship_from_its_particulars_and_four_zigzags() {
    use termid::ship::particulars::Particulars;

    let truth = mmg_truth();
    let particulars: Particulars = toml::from_str(KVLCC2_PARTICULARS).unwrap();
    let start = particulars.model().unwrap();
    let frames: Vec<Frame> = basin_zigzags(&truth, None).into_iter().map(|(_, f)| f).collect();
    let fit = estimate(&start, &runs_of(&start, &frames), &EstimateSettings::default()).unwrap();
    for rudder in [35.0, -35.0] {
        let (before, after, true_d) = (
            tactical_diameter(&start, rudder),
            tactical_diameter(&fit.model, rudder),
            tactical_diameter(&truth, rudder),
        );
        assert!(
            (before / true_d - 1.0).abs() > 0.1,
            "δ = {rudder}°: the particulars alone {before} m, truth {true_d} m"
        );
        assert!(
            (after / true_d - 1.0).abs() < 0.05,
            "δ = {rudder}°: {after} m, truth {true_d} m\n{}",
            fit.text()
        );
    }
}

/// The MMG basin as `examples/mmg_basin.rs` records it (optical tracking, a rudder indicator
/// 0.3° off, eight zigzags to both sides): the grey-box model from the particulars, estimated on
/// those runs, predicts the truth's turning circles, which no run covered, within 1.5 %
/// (measured on the example's seeds 0-3: tactical diameters −1.0 to −1.5 %, advances within
/// 0.2 %; here its seed 0, −1.19 % and −1.45 %). The template declares the rudder zero a
/// nuisance of each run; this basin's indicator holds one zero, the eight runs' values agree,
/// and the estimate says so and fits one.
#[test]
fn a_new_ship_from_its_particulars_and_the_basins_zigzags_turns_within_one_and_a_half_percent() {
    use termid::ship::basin::Basin;
    use termid::ship::particulars::Particulars;
    use termid::ship::ShipSpec;

    const OFFSET_DEG: f64 = 0.3;
    let truth = mmg_truth();
    let basin = Basin::tracked();
    assert_eq!(basin.artefacts.rudder_offset_deg, OFFSET_DEG);
    let frames = tracked_zigzags(&basin, &truth, 1);
    let particulars: Particulars = toml::from_str(KVLCC2_PARTICULARS).unwrap();
    let start = particulars.model().unwrap();
    let runs = runs_of(&start, &frames).comparing(&start, &["u", "v", "r", "ψ"].map(String::from)).unwrap();
    let fit = estimate(&start, &runs, &EstimateSettings::default()).unwrap();
    // declared per run (real basins drift), but this one's runs agree: one zero for all, at the
    // indicator's 0.3°
    let [agreed] = fit.one_value.as_slice() else { panic!("the runs' zeros agree\n{}", fit.text()) };
    assert!(agreed.name == "δ_0" && agreed.runs == 8 && agreed.agree() && fit.per_run.is_empty());
    let zero = fit.parameters.iter().find(|p| p.name == "δ_0").expect("one δ_0").value.to_degrees();
    assert!((zero - OFFSET_DEG).abs() < 0.05, "δ_0 {zero}°\n{}", fit.text());
    assert!(fit
        .text()
        .contains("`δ_0` one value for every run: declared per run, but the 8 runs' values agreed"));
    // the model's rudder is the indicator's: the true angle d reads d + 0.3°, its limit too
    let mut model = fit.model.clone();
    let mut ship = ShipSpec::of(&model).unwrap().unwrap();
    ship.rudder_limit += OFFSET_DEG;
    ship.store(&mut model);
    for rudder in [35.0, -35.0] {
        let (predicted, true_d) =
            (tactical_diameter(&model, rudder + OFFSET_DEG), tactical_diameter(&truth, rudder));
        assert!(
            (predicted / true_d - 1.0).abs() < 0.015,
            "δ = {rudder}°: {predicted} m, truth {true_d} m\n{}",
            fit.text()
        );
    }
}

/// A single-screw ship whose propeller turns it to port at every speed (N_P = −0.3: its side
/// force at the stern, as `termid new-ship` writes it), recorded by the MMG basin with a rudder
/// indicator 0.3° off: both are in the straight run, but the propeller's moment goes with its
/// load and the rudder's zero with the rudder's inflow, which falls in the turns; the estimate
/// from the particulars (both started at 0, every parameter free) tells them apart.
#[test]
fn the_propellers_yaw_moment_is_told_from_the_rudders_zero() {
    use termid::ship::basin::Basin;
    use termid::ship::particulars::Particulars;

    let particulars: Particulars = toml::from_str(KVLCC2_PARTICULARS).unwrap();
    let start = particulars.model().unwrap();
    assert_eq!(start.parameter_values()["N_P"], 0.0);
    let truth = start.edit(|file| file.parameters.get_mut("N_P").unwrap().value = -0.3).unwrap();
    let basin = Basin::tracked();
    let offset = basin.artefacts.rudder_offset_deg.to_radians();
    assert!(offset > 0.0);
    let frames = tracked_zigzags(&basin, &truth, 3);
    let fit = estimate(&start, &runs_of(&start, &frames), &EstimateSettings::default()).unwrap();
    let value = |name: &str| fit.parameters.iter().find(|p| p.name == name).unwrap().value;
    assert!((value("N_P") / -0.3 - 1.0).abs() < 0.1, "N_P {}\n{}", value("N_P"), fit.text());
    // the file's `nuisance = "run"`, but one indicator: the runs' zeros agree, one is estimated
    let zero = fit.model.parameter_values()["δ_0"];
    assert_eq!(fit.one_value.len(), 1, "{}", fit.text());
    assert!(
        (zero - offset).abs() < 0.05f64.to_radians(),
        "δ_0 {}° for {}°\n{}",
        zero.to_degrees(),
        offset.to_degrees(),
        fit.text()
    );
}

/// The MMG basin's eight zigzags (10/10, 20/20, 15/5, 35/5 to both sides, 80 s) of `truth`
/// as `basin` records them with noise `seed`.
fn tracked_zigzags(basin: &termid::ship::basin::Basin, truth: &Model, seed: u64) -> Vec<Frame> {
    basin
        .record_all(truth, &termid::ship::basin::ZIGZAGS_BOTH_SIDES, 1.17248, 80.0, seed, None)
        .unwrap()
        .into_iter()
        .map(|(_, r)| r.measured)
        .collect()
}

/// KVLCC2 at model scale (SIMMAN 2008; Yasukawa & Yoshimura 2015, Table 1) as a particulars file.
pub const KVLCC2_PARTICULARS: &str = r#"
name = "KVLCC2"
lpp = 7.0
beam = 1.27
draught = 0.46
block_coefficient = 0.81
x_g = 0.25
rudder_area = 0.0539
rudder_span = 0.345
propeller_diameter = 0.216
u0 = 1.17248
rudder_rate = 15.8
"#;

/// `termid new-ship` writes a grey-box model file that `estimate` reads, prints each
/// parameter's source, and names the file and key of a bad particular.
#[test]
fn the_new_ship_command_writes_a_model_estimate_reads() {
    let dir = crate::common::Scratch::new("new-ship");
    let new_ship = |particulars: &std::path::Path, out: &std::path::Path| {
        crate::common::termid(&[
            "new-ship",
            "--particulars",
            particulars.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let out = dir.join("kvlcc2_greybox.toml");
    let (ok, text, err) = new_ship(std::path::Path::new("examples/kvlcc2_particulars.toml"), &out);
    assert!(ok, "{err}");
    assert!(text.contains("Kijima") && text.contains("Clarke") && text.contains("Fujii"), "{text}");
    let model = termid::plugins::load(&out).unwrap();
    assert!(model.free_parameters().len() > 20);
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, KVLCC2_PARTICULARS.replace("block_coefficient = 0.81", "block_coefficient = 81"))
        .unwrap();
    let (ok, _, err) = new_ship(&bad, &dir.join("x.toml"));
    assert!(!ok && err.contains("bad.toml") && err.contains("block_coefficient"), "{err}");
    let (ok, _, err) = new_ship(&bad, &bad);
    assert!(!ok && std::fs::read_to_string(&bad).unwrap().contains("= 81"), "{err}");
    // a slender hull is written, with a caution that the hull formulas extrapolate there
    let slender = dir.join("slender.toml");
    std::fs::write(&slender, KVLCC2_PARTICULARS.replace("beam = 1.27", "beam = 0.7")).unwrap();
    let written = dir.join("slender_greybox.toml");
    let (ok, _, err) = new_ship(&slender, &written);
    assert!(ok && written.exists() && err.contains("caution: L/B = 10.000"), "{err}");
}

/// The rudder indicator's zero of each of two basins, degrees.
const BASIN_ZEROS: [f64; 2] = [0.3, -0.5];

/// A record whose rudder indicator reads `zero_deg` degrees off.
fn reading_off(mut f: Frame, zero_deg: f64) -> Frame {
    let read: Vec<f64> = f.column("δ").unwrap().iter().map(|d| d + zero_deg.to_radians()).collect();
    f.set("δ", read).unwrap();
    f
}

/// `zigzags` of `truth` as two basins record them (each its own noise), their rudder
/// indicators reading [`BASIN_ZEROS`] off: the runs and each run's basin.
fn two_basins(truth: &Model, zigzags: &[(&str, f64)]) -> (Vec<Frame>, Vec<usize>) {
    two_basins_reading(truth, zigzags, BASIN_ZEROS)
}

/// [`two_basins`] with the indicators reading `zeros` off, degrees.
fn two_basins_reading(truth: &Model, zigzags: &[(&str, f64)], zeros: [f64; 2]) -> (Vec<Frame>, Vec<usize>) {
    let (mut frames, mut sources) = (Vec::new(), Vec::new());
    for (s, (zero, seed)) in zeros.iter().zip([41, 51]).enumerate() {
        let records =
            termid::ship::basin::Basin::default().record_all(truth, zigzags, 1.17248, 60.0, seed, None);
        for (_, rec) in records.unwrap() {
            frames.push(reading_off(rec.measured, *zero));
            sources.push(s);
        }
    }
    (frames, sources)
}

/// The MMG KVLCC2 with a rudder indicator zero `δ_0` (free, prior 0 ± 0.02 rad: the rudder
/// the hull feels is the reading less it) and the hull's linear derivatives freed 30 % off.
fn zeroed_start() -> (Model, [&'static str; 4]) {
    let text = std::fs::read_to_string("models/mmg_kvlcc2.toml").unwrap();
    let text = text
        .replacen("[[derived]]", "[[derived]]\nname = \"δ_t\"\ndefinition = \"δ - δ_0\"\n\n[[derived]]", 1)
        .replace("definition = \"δ - atan2(v_R, u_R)\"", "definition = \"δ_t - atan2(v_R, u_R)\"")
        .replace("sin(δ)", "sin(δ_t)")
        .replace("cos(δ)", "cos(δ_t)")
        .replace("# ---- hull (eq. 10), nondimensional ----", "[parameters.\"δ_0\"]\nvalue = 0.0\nunit = \"rad\"\nfree = true\nprior = { value = 0.0, sd = 0.02 }\n\n# ---- hull (eq. 10), nondimensional ----");
    assert_eq!(text.matches("δ_t").count(), 5, "the rudder angle appears in α_R, X, Y and N");
    let zeroed = termid::plugins::parse(&text, "kvlcc2_zero.toml").unwrap();
    let free = ["Y_v", "Y_r", "N_v", "N_r"];
    let start = zeroed
        .edit(|file| {
            for (k, name) in free.iter().enumerate() {
                let p = file.parameters.get_mut(*name).unwrap();
                p.value *= if k % 2 == 0 { 1.3 } else { 0.7 };
                p.free = true;
            }
        })
        .unwrap();
    (start, free)
}

/// A rudder zero the model file declares per source (`nuisance = "source"`) is tested as a
/// per-run one is: two basins whose indicators read alike (+0.3° both) agree, and the zero is
/// estimated once for both; two that read +0.3° and −0.5° differ, each keeps its own.
#[test]
fn a_zero_declared_per_source_is_one_where_the_basins_agree() {
    let truth = mmg_truth();
    let (start, _) = zeroed_start();
    let declared = start
        .edit(|file| file.parameters.get_mut("δ_0").unwrap().nuisance = Some(termid::model::Nuisance::Source))
        .unwrap();
    let zigzags = [("zigzag:20/20", 1.0), ("zigzag:20/20:port", 0.98)];
    let fit = |zeros: [f64; 2]| {
        let (frames, sources) = two_basins_reading(&truth, &zigzags, zeros);
        let settings = EstimateSettings { sources, ..Default::default() };
        estimate(&declared, &runs_of(&declared, &frames), &settings).unwrap()
    };
    let alike = fit([0.3, 0.3]);
    let merged =
        alike.one_value.iter().find(|r| r.name == "δ_0").unwrap_or_else(|| panic!("{}", alike.text()));
    assert!(merged.per == termid::model::Nuisance::Source && merged.runs == 2, "{}", alike.text());
    assert!(alike.per_source.is_empty() && alike.text().contains("declared per source"), "{}", alike.text());
    let zero = alike.parameters.iter().find(|p| p.name == "δ_0").unwrap().value;
    assert!((zero - 0.3f64.to_radians()).abs() < 0.1f64.to_radians(), "{}", alike.text());
    let apart = fit(BASIN_ZEROS);
    assert!(apart.one_value.is_empty(), "{}", apart.text());
    let test = &apart.per_source_spread[0];
    assert!(test.name == "δ_0" && test.runs == 2 && !test.agree(), "{}", apart.text());
    assert!(
        apart.text().contains("sources' values of `δ_0` differ: χ²")
            && apart.text().contains("on 1 degree of freedom"),
        "{}",
        apart.text()
    );
    assert_eq!(apart.per_source.len(), 2);
}

/// Two basins, one hull: each basin's rudder indicator reads off by its own zero (+0.3° and
/// −0.5°), a nuisance estimated per source beside the hull's derivatives (started 30 % off);
/// both come back, and the hull's derivatives as from one basin without offsets.
#[test]
fn two_basins_with_their_own_rudder_zero() {
    let truth = mmg_truth();
    let (start, free) = zeroed_start();
    let (frames, sources) = two_basins(&truth, &[("zigzag:20/20", 1.0), ("zigzag:20/20:port", 0.98)]);
    let settings = EstimateSettings { sources, per_source: vec!["δ_0".into()], ..Default::default() };
    let fit = estimate(&start, &runs_of(&start, &frames), &settings).unwrap();
    for (s, offset) in BASIN_ZEROS.iter().map(|z| z.to_radians()).enumerate() {
        let p = fit.per_source.iter().find(|p| p.source == s).unwrap();
        assert!(
            (p.value - offset).abs() < 0.1f64.to_radians(),
            "source {s}: {} vs {offset}\n{}",
            p.value,
            fit.text()
        );
    }
    let values = truth.parameter_values();
    for name in free {
        let p = fit.parameters.iter().find(|p| p.name == name).unwrap();
        assert!((p.value / values[name] - 1.0).abs() < 0.05, "{name}: {}\n{}", p.value, fit.text());
    }
    // the model keeps the file's δ_0: each source's own is reported, not written, and the
    // report says how to predict a source with it
    assert_eq!(fit.model.parameter_values()["δ_0"], 0.0);
    let text = fit.text();
    assert!(
        text.contains(
            "not written: the model keeps its file's `δ_0`; predict source 2's runs with `--param δ_0="
        ),
        "{text}"
    );
}

/// One basin whose rudder indicator drifts: each of four zigzags reads off by its own zero
/// (−0.6° to +0.5°), a nuisance estimated per run beside the hull's derivatives (started 30 %
/// off). Each run's zero comes back, and the derivatives within 2 %; one zero for all runs
/// cannot stand in for them.
#[test]
fn runs_with_their_own_rudder_zero() {
    let truth = mmg_truth();
    let (start, free) = zeroed_start();
    let zigzags = [
        ("zigzag:20/20", 1.0),
        ("zigzag:20/20:port", 0.98),
        ("zigzag:10/10", 1.01),
        ("zigzag:10/10:port", 0.99),
    ];
    let zeros = [0.5f64, -0.6, 0.2, -0.3];
    let records =
        termid::ship::basin::Basin::default().record_all(&truth, &zigzags, 1.17248, 60.0, 61, None).unwrap();
    let frames: Vec<Frame> =
        records.into_iter().zip(zeros).map(|((_, rec), zero)| reading_off(rec.measured, zero)).collect();
    let runs = runs_of(&start, &frames);
    let settings = EstimateSettings { per_run: vec!["δ_0".into()], ..Default::default() };
    let per_run = estimate(&start, &runs, &settings).unwrap();
    assert_eq!(per_run.per_source.len(), 4, "{}", per_run.text());
    for (p, zero) in per_run.per_source.iter().zip(zeros) {
        assert!(p.run.is_some(), "{}", per_run.text());
        assert!(
            (p.value.to_degrees() - zero).abs() < 0.1,
            "{:?}: {}° vs {zero}°\n{}",
            p.run,
            p.value.to_degrees(),
            per_run.text()
        );
    }
    let values = truth.parameter_values();
    // the hull's derivatives' largest relative error
    let off = |fit: &Estimate| -> f64 {
        let error =
            |name: &str| fit.parameters.iter().find(|p| p.name == name).unwrap().value / values[name] - 1.0;
        free.iter().map(|name| error(name).abs()).fold(0.0, f64::max)
    };
    assert!(off(&per_run) < 0.02, "{}", per_run.text());
    let text = per_run.text();
    assert!(
        text.contains("(run zigzag_20_20_port.dat)") && text.contains("the model holds their mean"),
        "{text}"
    );
    // the model holds the runs' mean, a new run's best guess (the zeros' mean: −0.05°)
    let written = per_run.model.parameter_values()["δ_0"].to_degrees();
    assert!(
        (written - (-0.05)).abs() < 0.05 && (per_run.per_run[0].sd.to_degrees() - 0.49).abs() < 0.1,
        "{text}"
    );
    // a new run's zero is as uncertain as the runs' scatter (sd² and the mean's sd²/n), in the
    // written covariance beside the hull's, uncorrelated with them: Monte-Carlo draws vary it
    let c = per_run.model.spec().parameter_covariance.clone().expect("a covariance");
    let i = c.names.iter().position(|n| n == "δ_0").expect("δ_0 in the covariance");
    let sd = per_run.per_run[0].sd;
    assert!((c.matrix[i][i] / (sd * sd * 1.25) - 1.0).abs() < 1e-12, "{:?}", c.matrix[i]);
    assert!(c.matrix[i].iter().enumerate().all(|(j, v)| j == i || *v == 0.0));
    let sampler = termid::uncertainty::Sampler::new(&per_run.model);
    let mut normal = termid::uncertainty::Normal::new(3);
    let drawn: Vec<f64> = (0..400).map(|_| sampler.draw(&mut normal).parameter_values()["δ_0"]).collect();
    let spread = termid::uncertainty::spread_of(&drawn).unwrap();
    assert!((spread.sd / (sd * 1.25f64.sqrt()) - 1.0).abs() < 0.15, "{spread:?} for sd {sd}");
    // the zeros differ beyond their uncertainty, and the report says so
    let spread = &per_run.per_run[0];
    assert!(!spread.agree() && spread.p_value.unwrap() < 1e-3, "{text}");
    assert!(text.contains("the runs' values differ: χ² "), "{text}");
    // declared per run in the file instead of asked, the zeros stay each run's (they differ)
    let declared = start
        .edit(|f| f.parameters.get_mut("δ_0").unwrap().nuisance = Some(termid::model::Nuisance::Run))
        .unwrap();
    let by_file = estimate(&declared, &runs, &EstimateSettings::default()).unwrap();
    assert!(by_file.one_value.is_empty() && by_file.per_source.len() == 4, "{}", by_file.text());
    // one zero for all four runs cannot stand in for theirs: the derivatives bend for it
    let once = estimate(&start, &runs, &EstimateSettings::default()).unwrap();
    assert!(off(&once) > 0.04 && off(&once) > 3.0 * off(&per_run), "{}\n{}", once.text(), per_run.text());
    // a parameter per source and per run at once is refused
    let both = EstimateSettings {
        per_run: vec!["δ_0".into()],
        per_source: vec!["δ_0".into()],
        ..Default::default()
    };
    let e = estimate(&start, &runs, &both).unwrap_err().to_string();
    assert!(e.contains("per source and per run"), "{e}");
    // and one that is no free parameter, by name
    let unknown = EstimateSettings { per_run: vec!["δ_1".into()], ..Default::default() };
    let e = estimate(&start, &runs, &unknown).unwrap_err().to_string();
    assert!(e.contains("`δ_1` is to be estimated per run, but it is no free parameter"), "{e}");
}

/// The polynomial template from two basins, each with its own rudder zero (+0.3° and −0.5°),
/// by the recipe with its parameter stage: the regression cannot move `δ_0` (the template's
/// rudder terms read `δ_t = δ − δ_0`), so each basin's zero is estimated with the term
/// coefficients last. The absolute zero trades against the template's asymmetry terms (u²,
/// n²); the two basins' difference cannot, and comes back.
#[test]
fn the_polynomial_template_from_two_basins_with_their_own_rudder_zero() {
    use termid::recipe::{identify, ParameterOptions, ParameterStage, RecipeSettings};

    let truth = mmg_truth();
    let template = termid::plugins::load(std::path::Path::new("models/new_ship.toml")).unwrap();
    let zigzags = [("zigzag:20/20", 1.0), ("zigzag:20/20:port", 0.98), ("zigzag:10/10", 1.0)];
    let (frames, sources) = two_basins(&truth, &zigzags);
    let settings = RecipeSettings {
        derivatives: vec!["kalman".into()],
        smooth: true,
        intercept: false,
        parameters: Some(ParameterOptions { sources, per_source: vec!["δ_0".into()], ..Default::default() }),
        ..Default::default()
    };
    let recipe = identify(&template, &frames, None, &settings).unwrap();
    let Some(ParameterStage::Kept(fit)) = &recipe.kept().parameters else {
        panic!("the parameter stage: {}", recipe.text());
    };
    let zero = |s: usize| fit.per_source.iter().find(|p| p.source == s).unwrap().value;
    let (got, want) = (zero(0) - zero(1), (BASIN_ZEROS[0] - BASIN_ZEROS[1]).to_radians());
    assert!(
        (got - want).abs() < 0.1f64.to_radians(),
        "the basins' zeros differ by {:.3}°, truly {:.3}°\n{}",
        got.to_degrees(),
        want.to_degrees(),
        fit.text()
    );
    assert!(fit.cost_after < fit.cost_before, "{}", fit.text());
    // the kept model holds the estimated coefficients and the file's zero; the report says so
    assert_eq!(recipe.kept().model.parameter_values()["δ_0"], 0.0);
    assert!(recipe.text().contains("output-error estimate of the free parameters"), "{}", recipe.text());
    // the checks that steer the runs as recorded do so with each basin's own zero: with the
    // file's zero for every run instead, the runs are steered further off
    let steering = "steers its training zigzags as recorded";
    let worst = |c: &termid::plugin::Check| -> f64 {
        c.detail.split("within ").nth(1).unwrap().split('°').next().unwrap().parse().unwrap()
    };
    let own = recipe.checks().into_iter().find(|c| c.name == steering).unwrap();
    assert!(own.passed && own.detail.contains("of 6 records'"), "{}", recipe.text());
    let kept = &recipe.kept().model;
    let each: Vec<(&Model, &Frame)> = frames.iter().map(|f| (kept, f)).collect();
    let file_zero = termid::ship::checks::steering_check(&each).unwrap();
    assert!(worst(&file_zero) > worst(&own) + 0.1, "{file_zero:?} against {own:?}");
}

/// The recipe with `--refine` on the polynomial template, which declares each run's rudder zero
/// free: every start is refined with it (the estimate in place of the refinement, so no start
/// is refined twice), the table of starts says so, and the starts are judged by that
/// estimate's cost; asked not to, or without a refinement, the stage does not run; with runs
/// that stop the refinement, it follows the refinement.
#[test]
fn the_recipe_refines_every_start_with_the_templates_free_parameters() {
    use termid::recipe::{identify, ParameterOptions, ParameterStage, RecipeSettings, RefineOptions};

    let truth = mmg_truth();
    let template = termid::plugins::load(std::path::Path::new("models/new_ship.toml")).unwrap();
    let (frames, _) = two_basins_reading(
        &truth,
        &[("zigzag:20/20", 1.0), ("zigzag:20/20:port", 0.98), ("zigzag:10/10", 1.0)],
        [0.3, 0.3],
    );
    let asked = |asked, refined| ParameterOptions::asked(&template, asked, refined, vec![], vec![], vec![]);
    assert!(asked(None, true).is_some(), "the template declares `δ_0` free: refined with it");
    assert!(asked(None, false).is_none() && asked(Some(false), true).is_none());
    assert!(asked(Some(true), false).is_some());
    let paper = termid::plugins::load(std::path::Path::new("models/oltmann1973.toml")).unwrap();
    assert!(ParameterOptions::asked(&paper, None, true, vec![], vec![], vec![]).is_none());
    let refine = RefineOptions {
        states: Some(["u", "v", "r", "ψ"].map(String::from).to_vec()),
        prior: 1e-4,
        iterations: 30,
        step: None,
    };
    let settings = RecipeSettings {
        derivatives: vec!["kalman".into(), "central".into()],
        smooth: true,
        intercept: false,
        refine: Some(refine),
        parameters: asked(None, true),
        ..Default::default()
    };
    let recipe = identify(&template, &frames, None, &settings).unwrap();
    for start in &recipe.starts {
        let Some(ParameterStage::Kept(fit)) = &start.parameters else {
            panic!(
                "{}: the stage {:?}\n{}",
                start.derivative,
                start.parameters.as_ref().map(|p| p.text()),
                recipe.starts_text()
            );
        };
        assert!(start.refined.is_none() && start.rejected.is_none(), "{} refined twice", start.derivative);
        assert_eq!(start.cost(), fit.cost_after);
        assert!(fit.cost_after < fit.cost_before && !fit.coefficients.is_empty(), "{}", fit.text());
    }
    assert!(
        recipe.starts_text().contains("each refined with the model file's free parameters (δ_0)"),
        "{}",
        recipe.starts_text()
    );
    assert!(recipe.text().contains("output-error estimate of the free parameters"), "{}", recipe.text());
    // in place of the refinement, the estimate takes the refinement's iterations a round
    let short = RefineOptions { iterations: 1, ..settings.refine.clone().unwrap() };
    let one = RecipeSettings { derivatives: vec!["kalman".into()], refine: Some(short), ..settings.clone() };
    let recipe = identify(&template, &frames, None, &one).unwrap();
    let Some(ParameterStage::Kept(fit) | ParameterStage::Rejected(fit, _)) = &recipe.kept().parameters else {
        panic!("{}", recipe.text());
    };
    assert!(fit.iterations <= 2, "{} iterations in two rounds of one", fit.iterations);
    // runs that stop the refinement: by default they are not overruled (the refinement alone);
    // asked for, the estimate runs after the refinement
    let (train, held) = frames.split_at(frames.len() - 1);
    let with_held = |parameters| {
        let settings = RecipeSettings { derivatives: vec!["kalman".into()], parameters, ..settings.clone() };
        identify(&template, train, Some(held), &settings).unwrap()
    };
    let recipe = with_held(asked(None, true));
    assert!(recipe.kept().refined.is_some() && recipe.kept().parameters.is_none(), "{}", recipe.text());
    let recipe = with_held(asked(Some(true), true));
    let kept = recipe.kept();
    assert!(kept.refined.is_some() && kept.parameters.is_some(), "{}", recipe.text());
    // where no start's stage is kept (here each fails: a stopping fraction it refuses), every
    // start is refined without the free parameters, and the stage's failure is reported
    let failing = ParameterOptions { converged: 2.0, ..asked(None, true).unwrap() };
    let recipe = identify(
        &template,
        &frames,
        None,
        &RecipeSettings { derivatives: vec!["kalman".into()], parameters: Some(failing), ..settings.clone() },
    )
    .unwrap();
    let kept = recipe.kept();
    assert!(matches!(kept.parameters, Some(ParameterStage::Failed(_))) && kept.refined.is_some());
    assert!(recipe.text().contains("stopping fraction") && recipe.text().contains("output-error refinement"));
    // not asked: the refinement alone, the file's zero kept
    let recipe = identify(
        &template,
        &frames,
        None,
        &RecipeSettings { derivatives: vec!["kalman".into()], parameters: None, ..settings },
    )
    .unwrap();
    let kept = recipe.kept();
    assert!(kept.refined.is_some() && kept.parameters.is_none());
    assert_eq!(kept.model.parameter_values()["δ_0"], 0.0);
    assert!(!recipe.starts_text().contains("free parameters"));
    // a stopping fraction that would stop at once, or never, is refused
    for converged in [1.0, f64::NAN, -1e-3] {
        let settings = EstimateSettings { converged, ..Default::default() };
        let e = estimate(&truth, &runs_of(&truth, &frames), &settings).unwrap_err().to_string();
        assert!(e.contains("stopping fraction"), "{e}");
    }
}

/// `estimate --against`: the estimated grey-box model and another of the same ship compared
/// on what the runs did not cover; the particulars' unestimated model (19-31 % off on the
/// turning circles) is flagged, the truth is not.
#[test]
fn estimate_against_another_model_flags_where_they_disagree() {
    use termid::ship::basin::{columns, dataset_file};
    let dir = crate::common::Scratch::new("estimate-against");
    let truth = mmg_truth();
    let files: Vec<String> = basin_zigzags(&truth, Some(&dir)).into_iter().map(|(name, _)| name).collect();
    let names: Vec<&str> = files.iter().map(String::as_str).collect();
    std::fs::write(dir.join("train.toml"), dataset_file(&columns(&truth), &names)).unwrap();
    let greybox = dir.join("greybox.toml");
    let (ok, _, err) = crate::common::termid(&[
        "new-ship",
        "--particulars",
        "examples/kvlcc2_particulars.toml",
        "--out",
        greybox.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let train = dir.join("train.toml");
    for (against, flagged) in [("models/mmg_kvlcc2.toml", false), (greybox.to_str().unwrap(), true)] {
        let (ok, text, err) = crate::common::termid(&[
            "estimate",
            "--model",
            greybox.to_str().unwrap(),
            "--dataset",
            train.to_str().unwrap(),
            "--against",
            against,
        ]);
        assert!(ok, "{err}");
        assert!(text.contains("the models agree on the tactical diameter"), "{text}");
        assert_eq!(text.contains("FLAG the models agree"), flagged, "against {against}:\n{text}");
        assert!(text.contains("ok   the fit re-simulates its runs' first overshoots within 1°"), "{text}");
        // the structure is the truth's: the fit re-simulates every run's overshoots as the
        // records show them, within what reading them off noisy samples allows (an extremum of
        // a heading noisy by 0.05°, less the heading at the reversal, itself noisy: 0.5°);
        // re-simulated from the noisy first samples instead the MMG basin's eight zigzags came out
        // up to 1.8° off
        let lines: Vec<&str> =
            text.lines().filter(|l| l.contains("first overshoot") && l.contains(" → ")).collect();
        assert_eq!(lines.len(), files.len(), "{text}");
        for line in lines {
            for cell in line.split("), ") {
                let difference: f64 = cell
                    .rsplit('(')
                    .next()
                    .and_then(|d| d.trim_end_matches([')', '°']).parse().ok())
                    .unwrap_or_else(|| panic!("{cell}\n{text}"));
                assert!(difference.abs() < 0.5, "{line}\n{text}");
            }
        }
    }
}

/// A forced spring whose force a load cell records through a gain `g` the motion does not
/// show: ẍ = −k x − 0.3 x³ − b ẋ + F, the cell reading g·(k x + 0.3 x³).
const LOAD_CELL: &str = r#"
[model]
name = "a forced spring on a load cell"
[[states]]
name = "x"
[[states]]
name = "w"
[[inputs]]
name = "F"
[parameters.k]
value = 1.0
free = true
[parameters.b]
value = 0.1
free = true
[parameters.g]
value = 1.0
free = true
[[derived]]
name = "spring"
definition = "k*x + 0.3*x^3"
[[derived]]
name = "cell"
definition = "g*spring"
[equations.x_dot]
state = "x"
identify = false
coefficients = { "w" = 1.0 }
[equations.w_dot]
state = "w"
identify = false
coefficients = { "-spring - b*w + F" = 1.0 }
"#;

/// The load cell's truth: stiffness k, damping b, the cell's gain g.
const LOAD_CELL_TRUTH: (f64, f64, f64) = (1.4, 0.2, 0.8);

/// The truth forced by two sines (the test's own RK4), 40 s at 0.05 s: x, w, F and the cell's
/// reading, with noise (seed `seed`) on all but the force.
fn load_cell_run(seed: u64) -> Frame {
    let ((k, b, g), h) = (LOAD_CELL_TRUTH, 0.05);
    let force = |t: f64| 0.8 * (0.7 * t).sin() + 0.5 * (1.9 * t).sin();
    let rows = trajectory(&[0.0, 0.0], h, 801, 4, |t, x| {
        vec![x[1], -k * x[0] - 0.3 * x[0].powi(3) - b * x[1] + force(t)]
    });
    let rows: Vec<Vec<f64>> = rows
        .iter()
        .enumerate()
        .map(|(i, x)| vec![x[0], x[1], force(i as f64 * h), g * (k * x[0] + 0.3 * x[0].powi(3))])
        .collect();
    noisy_frame("cell", h, &["x", "w", "F", "cell"], &rows, &[0.002, 0.004, 0.0, 0.01], &mut Lcg(seed))
}

/// A derived variable compared with its record (a load cell's reading beside the motion)
/// estimates what only it shows, the cell's gain, with the motion's parameters: each within
/// 2 % from a start 30 % off, through the library and the `estimate` command alike.
#[test]
fn a_derived_variable_compared_with_its_record_estimates_what_only_it_shows() {
    let (k, b, g) = LOAD_CELL_TRUTH;
    let frame = load_cell_run(5);
    let text = LOAD_CELL
        .replace("value = 1.0\nfree = true\n[parameters.b]", "value = 0.98\nfree = true\n[parameters.b]");
    let text = text.replace("value = 0.1\nfree = true", "value = 0.14\nfree = true");
    let model = Model::parse(&text, "cell.toml").unwrap();
    let names: Vec<String> = ["x", "w", "cell"].iter().map(|s| s.to_string()).collect();
    let runs = Runs::new(&model, std::slice::from_ref(&frame), 0.05, Integrator::Rk4)
        .unwrap()
        .comparing(&model, &names)
        .unwrap();
    let fit = estimate(&model, &runs, &EstimateSettings::default()).unwrap();
    for (name, truth) in [("k", k), ("b", b), ("g", g)] {
        let p = fit.parameters.iter().find(|p| p.name == name).unwrap();
        assert!((p.value / truth - 1.0).abs() < 0.02, "{name}: {} vs {truth}\n{}", p.value, fit.text());
    }
    // the command: `--states` names the derived variable beside the states; the dataset file
    // reads the cell as an `[extra]` record, which a model without it does not refuse
    let dir = crate::common::Scratch::new("estimate-derived");
    let (model_path, set, out) = (dir.join("cell.toml"), dir.join("set.toml"), dir.join("fit.toml"));
    std::fs::write(&model_path, &text).unwrap();
    frame.write_csv(&dir.join("run.csv")).unwrap();
    let columns = "[columns]\nt = \"t [s]\"\nx = \"x\"\nw = \"w\"\nF = \"F\"\n";
    std::fs::write(&set, format!("{columns}\n[extra]\ncell = \"cell\"\n\n[[runs]]\nfile = \"run.csv\"\n"))
        .unwrap();
    let (model_arg, set_arg) = (model_path.to_str().unwrap(), set.to_str().unwrap());
    let (ok, report, err) = crate::common::termid(&[
        "estimate",
        "--model",
        model_arg,
        "--dataset",
        set_arg,
        "--states",
        "x,w,cell",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(report.contains("cell"), "{report}");
    let written = Model::load(&out).unwrap();
    let gain = written.parameter_values()["g"];
    assert!((gain / g - 1.0).abs() < 0.02, "g {gain}\n{report}");
    // a model without the cell reads the same dataset; under `[columns]` it would be refused
    let without = text.replace(
        "name = \"cell\"\ndefinition = \"g*spring\"",
        "name = \"reading\"\ndefinition = \"g*spring\"",
    );
    std::fs::write(&model_path, &without).unwrap();
    let (ok, _, err) = crate::common::termid(&["validate", "--model", model_arg, "--dataset", set_arg]);
    assert!(ok, "{err}");
    std::fs::write(&set, format!("{columns}cell = \"cell\"\n\n[[runs]]\nfile = \"run.csv\"\n")).unwrap();
    let (ok, _, err) = crate::common::termid(&["validate", "--model", model_arg, "--dataset", set_arg]);
    assert!(
        !ok && err.contains("`columns.cell` maps a column onto `cell`, which is not a variable"),
        "{err}"
    );
}

/// Two sources of the same spring, one with the load cell and the rate `w`, one with neither
/// (a basin that logs a propeller's thrust and a yaw rate beside one that logs neither): each
/// is compared in the run that records it, the other holds the fit to its displacement alone
/// (its rate started where it is steady), and the parameters come out within 2 %; the report
/// says in how many runs each was compared.
#[test]
fn states_and_derived_variables_are_compared_in_the_sources_that_record_them() {
    let g = LOAD_CELL_TRUTH.2;
    let text = LOAD_CELL
        .replace("value = 1.0\nfree = true\n[parameters.b]", "value = 0.98\nfree = true\n[parameters.b]");
    let dir = crate::common::Scratch::new("estimate-derived-sources");
    let (model_path, out) = (dir.join("spring.toml"), dir.join("fit.toml"));
    std::fs::write(&model_path, &text).unwrap();
    let columns = "[columns]\nt = \"t [s]\"\nx = \"x\"\nF = \"F\"\n";
    let mut sets = Vec::new();
    for (name, seed, extra) in [("cell", 5, "w = \"w\"\n\n[extra]\ncell = \"cell\"\n"), ("plain", 9, "")] {
        load_cell_run(seed).write_csv(&dir.join(format!("{name}.csv"))).unwrap();
        let set = dir.join(format!("{name}.toml"));
        std::fs::write(&set, format!("{columns}{extra}\n[[runs]]\nfile = \"{name}.csv\"\n")).unwrap();
        sets.push(set);
    }
    let (model_arg, with, without) =
        (model_path.to_str().unwrap(), sets[0].to_str().unwrap(), sets[1].to_str().unwrap());
    let estimate =
        |more: &[&str]| crate::common::termid(&[&["estimate", "--model", model_arg][..], more].concat());
    let (ok, report, err) = estimate(&[
        "--dataset",
        with,
        "--dataset",
        without,
        "--states",
        "x,w,cell",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    for name in ["w", "cell"] {
        assert!(
            report.contains(&format!("`{name}` is compared in the 1 of 2 runs that record it")),
            "{report}"
        );
    }
    let values = Model::load(&out).unwrap().parameter_values();
    for (name, truth) in [("k", LOAD_CELL_TRUTH.0), ("b", LOAD_CELL_TRUTH.1), ("g", g)] {
        assert!((values[name] / truth - 1.0).abs() < 0.02, "{name} {}\n{report}", values[name]);
    }
    // a source alone without it has nothing to compare it with
    let (ok, _, err) = estimate(&["--dataset", without, "--states", "x,cell"]);
    assert!(!ok && err.contains("no run has a column `cell`"), "{err}");
}

/// A compared derived variable outside its domain along the start's re-simulation (√ of a
/// spring that swings negative) is named with its run and time, not reported as a
/// divergence.
#[test]
fn a_derived_variable_that_is_not_finite_is_named() {
    let text = LOAD_CELL.replace("definition = \"g*spring\"", "definition = \"g*sqrt(spring)\"");
    let model = Model::parse(&text, "cell.toml").unwrap();
    let names: Vec<String> = ["x", "w", "cell"].iter().map(|s| s.to_string()).collect();
    let runs = Runs::new(&model, &[load_cell_run(5)], 0.05, Integrator::Rk4)
        .unwrap()
        .comparing(&model, &names)
        .unwrap();
    let err = estimate(&model, &runs, &EstimateSettings::default())
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        err.contains("gives no finite residual at the start")
            && err.contains("`cell` is not finite in run cell at t = "),
        "{err}"
    );
}

/// Nomoto's ship behind a steering lag δ_e that no run records (the rudder's effective angle,
/// τ = 1.5 s); the file starts it at 0.
const NOMOTO_LAGGED: &str = r#"
[model]
name = "Nomoto's steering model behind a rudder lag"
intercept = false
[[states]]
name = "ψ"
[[states]]
name = "r"
[[states]]
name = "δ_e"
[[inputs]]
name = "δ"
[parameters.K]
value = 0.12
free = true
bounds = [0.0, 5.0]
[parameters.T]
value = 10.0
free = true
bounds = [0.1, 100.0]
[parameters."τ"]
value = 1.5
[equations.psi_dot]
state = "ψ"
identify = false
coefficients = { "r" = 1.0 }
[equations.r_dot]
state = "r"
identify = false
coefficients = { "(K*δ_e - r)/T" = 1.0 }
[equations.de_dot]
state = "δ_e"
identify = false
coefficients = { "(δ - δ_e)/τ" = 1.0 }
"#;

/// A state the runs do not record that the motion depends on (a steering lag) starts where it
/// is steady at the run's first sample and is estimated with the run's other initial values:
/// a run that begins in a steady turn at 10° of rudder gives K and T within 2 % and the lag's
/// initial value within 0.1° of the truth's 10°; held (the runs' initial values held to their
/// records) it stays there, K as close. Started at the file's 0 (the ship unwinding a turn it
/// was not unwinding) the same fit leans on the recorded states' initial values and misses K
/// and T by about 4 %.
#[test]
fn a_state_no_run_records_starts_steady_and_is_estimated() {
    let (k, t_const, tau, h) = (0.15, 8.0, 1.5, 0.1);
    let hold = 10f64.to_radians();
    // the rudder every sample (linear between them, as a record is replayed): held, then ±20°
    let schedule: Vec<f64> = (0..1200)
        .map(|i| match i {
            0..=19 => hold,
            _ if (i - 20) / 250 % 2 == 0 => 20f64.to_radians(),
            _ => -20f64.to_radians(),
        })
        .collect();
    let rudder = |t: f64| {
        let i = ((t / h).floor() as usize).min(schedule.len() - 2);
        let w = (t / h - i as f64).clamp(0.0, 1.0);
        schedule[i] * (1.0 - w) + schedule[i + 1] * w
    };
    let start = [0.0, k * hold, hold];
    let rows = trajectory(&start, h, schedule.len(), 4, |t, x| {
        vec![x[1], (k * x[2] - x[1]) / t_const, (rudder(t) - x[2]) / tau]
    });
    let mut rng = Lcg(3);
    let mut frame = noisy_frame(
        "turning",
        h,
        &["ψ", "r"],
        &rows,
        &[0.05f64.to_radians(), 0.02f64.to_radians()],
        &mut rng,
    );
    frame.push("δ", schedule.clone()).unwrap();
    let model = Model::parse(NOMOTO_LAGGED, "lagged.toml").unwrap();
    let runs = Runs::new(&model, &[frame], h, Integrator::Rk4).unwrap();
    let fit = estimate(&model, &runs, &EstimateSettings::default()).unwrap();
    for (name, truth) in [("K", k), ("T", t_const)] {
        let p = fit.parameters.iter().find(|p| p.name == name).unwrap();
        assert!((p.value / truth - 1.0).abs() < 0.02, "{name}: {} vs {truth}\n{}", p.value, fit.text());
    }
    assert_eq!(fit.hidden_initial_values, 1, "{}", fit.text());
    let lag = fit.initial_states.iter().find(|(_, i, _)| *i == 2).unwrap().2;
    assert!((lag - hold).abs() < 0.1f64.to_radians(), "δ_e(0) {:.3}°\n{}", lag.to_degrees(), fit.text());
    assert!(fit.text().contains("1 of states the runs do not record"), "{}", fit.text());
    // held, the initial values stay where the record says, and the lag where it is steady
    let held = EstimateSettings { initial_values: InitialValues::Measured, ..Default::default() };
    let fit = estimate(&model, &runs, &held).unwrap();
    assert_eq!(fit.hidden_initial_values, 0, "{}", fit.text());
    let k_held = fit.parameters.iter().find(|p| p.name == "K").unwrap().value;
    assert!((k_held / k - 1.0).abs() < 0.02, "K {k_held}\n{}", fit.text());
}

/// `identify --refine` compares a derived variable as `estimate --states` does: the spring's
/// identified coefficients refined with the load cell's reading beside the motion (the cell's
/// gain known), each within 2 % of the truth's; a name that is neither a state nor a derived
/// variable is refused, naming both kinds.
#[test]
fn the_refinement_compares_a_derived_variable_with_its_record() {
    let (k, b, _) = LOAD_CELL_TRUTH;
    let frame = load_cell_run(2);
    let model = r#"
[model]
name = "a spring to identify, on a load cell"
[[states]]
name = "x"
[[states]]
name = "w"
[[inputs]]
name = "F"
[parameters.g]
value = 0.8
[[derived]]
name = "cell"
definition = "g*(1.4*x + 0.3*x^3)"
[equations.x_dot]
state = "x"
identify = false
coefficients = { "w" = 1.0 }
[equations.w_dot]
state = "w"
candidates = ["x", "x^3", "w", "F"]
"#;
    let dir = crate::common::Scratch::new("refine-derived");
    let (model_path, data, out) = (dir.join("spring.toml"), dir.join("run.csv"), dir.join("identified.toml"));
    std::fs::write(&model_path, model).unwrap();
    frame.write_csv(&data).unwrap();
    let identify = |refine: &str| {
        crate::common::termid(&[
            "identify",
            "--model",
            model_path.to_str().unwrap(),
            "--data",
            data.to_str().unwrap(),
            "--refine",
            refine,
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let (ok, report, err) = identify("x,w,cell");
    assert!(ok, "{err}");
    assert!(report.contains("output-error refinement"), "{report}");
    let identified = Model::load(&out).unwrap();
    let eq = identified.equation("w_dot").unwrap();
    for (term, truth) in [("x", -k), ("x^3", -0.3), ("w", -b), ("F", 1.0)] {
        let c = eq.coefficients.iter().find(|(t, _, _)| t.to_string() == term).unwrap().1;
        assert!((c / truth - 1.0).abs() < 0.02, "{term}: {c} vs {truth}\n{report}");
    }
    let (ok, _, err) = identify("x,w,torque");
    assert!(!ok && err.contains("neither a state nor a derived variable") && err.contains("cell"), "{err}");
}
