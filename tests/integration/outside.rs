//! Systems the paper never saw, through `estimate`'s defaults: a predator and its prey started
//! where the fit's phase drifts off, an epidemic whose susceptibles no run records, a chaotic
//! run no whole-run fit follows. Each either comes back to the truth the test's own RK4 made
//! or is flagged as failed; none is printed as if valid when it is not.

use termid::diagnose::{estimate, in_segments, Estimate, EstimateSettings, Runs, FOLLOWS};
use termid::model::Model;
use termid::sim::Integrator;

use crate::common::{lorenz_rows, noise, noisy_frame, trajectory, Lcg, LORENZ_FREE, LORENZ_TRUTH};

/// Each named estimate within `tolerance` of its truth.
fn recovered(fit: &Estimate, truths: &[(&str, f64)], tolerance: f64) {
    for (name, truth) in truths {
        let p = fit.parameters.iter().find(|p| p.name == *name).unwrap();
        assert!((p.value / truth - 1.0).abs() < tolerance, "{name}: {} vs {truth}\n{}", p.value, fit.text());
    }
}

/// The prey's growth, the predation, the predators' death and their gain from it.
const PREDATION: (f64, f64, f64, f64) = (1.0, 0.1, 1.5, 0.075);

/// Thirty seconds of a predator and its prey every `h` seconds (six cycles), from 10 prey and
/// 5 predators.
fn predators(h: f64) -> Vec<Vec<f64>> {
    let (a, b, c, d) = PREDATION;
    trajectory(&[10.0, 5.0], h, 301, 10, |_, x| vec![a * x[0] - b * x[0] * x[1], d * x[0] * x[1] - c * x[1]])
}

const LOTKA_VOLTERRA: &str = r#"
[model]
name = "Lotka-Volterra, a prey x and its predator y"
intercept = false
[[states]]
name = "x"
initial = 10.0
[[states]]
name = "y"
initial = 5.0
[parameters.a]
value = 0.6
free = true
[parameters.b]
value = 0.15
free = true
[parameters.c]
value = 2.2
free = true
[parameters.d]
value = 0.05
free = true
[equations.x_dot]
state = "x"
identify = false
coefficients = { "a*x" = 1.0, "b*x*y" = -1.0 }
[equations.y_dot]
state = "y"
identify = false
coefficients = { "d*x*y" = 1.0, "c*y" = -1.0 }
"#;

/// A predator and its prey over six cycles, 3 % noise, every parameter started 33-47 % off:
/// from the file's values the fit's cycles drift out of phase with the record's and it stops
/// in a minimum that is not the system's (it leaves more of the records' variance than their
/// mean does); started again from the parameters fitted on segments of the run, it comes back
/// to the truth within 1.5 % and says which fit it kept.
#[test]
fn a_predator_and_its_prey_from_a_start_whose_phase_drifts_off() {
    let (a, b, c, d) = PREDATION;
    let h = 0.1;
    let rows = predators(h);
    let frame = noisy_frame("predators", h, &["x", "y"], &rows, &noise(&rows, 0.03), &mut Lcg(11));
    let model = Model::parse(LOTKA_VOLTERRA, "lotka_volterra.toml").unwrap();
    let runs = Runs::new(&model, &[frame], h, Integrator::Rk4).unwrap();
    let fit = estimate(&model, &runs, &EstimateSettings::default()).unwrap();
    let searched = fit.segmented.as_ref().expect("the file's start does not follow the records");
    assert!(searched.kept, "{}", fit.text());
    assert!(searched.other_unexplained.is_some_and(|u| u > FOLLOWS), "{}", fit.text());
    assert!(fit.follows(), "{}", fit.text());
    recovered(&fit, &[("a", a), ("b", b), ("c", c), ("d", d)], 0.015);
    // the report's start is the file's, and it says what it did
    assert_eq!(fit.parameters.iter().find(|p| p.name == "c").unwrap().start, 2.2);
    assert!(fit.text().contains("multiple shooting"), "{}", fit.text());
    assert!(!fit.text().contains("FLAG"), "{}", fit.text());
}

/// Started farther off still (the prey's rate 2.5 for 1, the predation 0.01 for 0.1, the
/// predators' death 0.3 for 1.5), the populations leave their bounds 1.5 s into the run: the
/// file's values re-simulate no run. The runs cut into 60 segments of half a second each do
/// re-simulate from them; fitted there first, the estimate comes back within 1.5 % and says
/// how it started.
#[test]
fn a_start_that_leaves_its_bounds_within_a_run_is_searched_on_segments() {
    let (a, b, c, d) = PREDATION;
    let h = 0.1;
    let rows = predators(h);
    let frame = noisy_frame("predators", h, &["x", "y"], &rows, &noise(&rows, 0.03), &mut Lcg(11));
    let wild = LOTKA_VOLTERRA
        .replace("value = 0.6", "value = 2.5")
        .replace("value = 0.15", "value = 0.01")
        .replace("value = 2.2", "value = 0.3")
        .replace("initial = 5.0", "initial = 5.0\nmax = 1000.0");
    let model = Model::parse(&wild, "lotka_volterra_far.toml").unwrap();
    let runs = Runs::new(&model, &[frame], h, Integrator::Rk4).unwrap();
    assert!(runs.simulate(&model, &[], &[]).is_err(), "the start re-simulates the run");
    let fit = estimate(&model, &runs, &EstimateSettings::default()).unwrap();
    let searched = fit.segmented.as_ref().unwrap();
    assert!(
        searched.start_failed.as_ref().is_some_and(|why| why.contains("outside its bounds")),
        "{}",
        fit.text()
    );
    assert!(fit.follows(), "{}", fit.text());
    recovered(&fit, &[("a", a), ("b", b), ("c", c), ("d", d)], 0.015);
    assert_eq!(fit.parameters.iter().find(|p| p.name == "b").unwrap().start, 0.01);
    assert!(fit.text().contains("the file's values do not re-simulate the runs"), "{}", fit.text());
}

const SIR: &str = r#"
[model]
name = "SIR epidemic: susceptibles S, infected I"
intercept = false
[[states]]
name = "S"
initial = 990.0
[[states]]
name = "I"
initial = 10.0
[parameters.b]
value = 0.0001
free = true
bounds = [0.0, 1.0]
[parameters.g]
value = 0.3
free = true
bounds = [0.0, 10.0]
[equations.s_dot]
state = "S"
identify = false
coefficients = { "b*S*I" = -1.0 }
[equations.i_dot]
state = "I"
identify = false
coefficients = { "b*S*I" = 1.0, "g*I" = -1.0 }
"#;

/// An epidemic recorded by its infected alone: the susceptibles, which no run records, are
/// steady only once none are left, a start from which nothing happens; the run starts them
/// at the file's 990, which re-simulates its record better, and the infection and recovery
/// rates come back within 2 % from a start 4 and 3 times off (the susceptibles' initial value
/// within 2 % too).
#[test]
fn an_epidemic_whose_susceptibles_no_run_records() {
    let (b, g) = (4e-4, 0.1);
    let h = 0.5;
    let rows =
        trajectory(&[990.0, 10.0], h, 201, 10, |_, x| vec![-b * x[0] * x[1], b * x[0] * x[1] - g * x[1]]);
    let infected: Vec<Vec<f64>> = rows.iter().map(|r| vec![r[1]]).collect();
    let frame = noisy_frame("outbreak", h, &["I"], &infected, &noise(&infected, 0.02), &mut Lcg(5));
    let model = Model::parse(SIR, "sir.toml").unwrap();
    let runs = Runs::new(&model, &[frame], h, Integrator::Rk4).unwrap();
    assert_eq!(runs.initial(0, 0), 990.0, "the susceptibles start where the file declares them");
    let fit = estimate(&model, &runs, &EstimateSettings::default()).unwrap();
    assert!(fit.follows(), "{}", fit.text());
    recovered(&fit, &[("b", b), ("g", g)], 0.02);
    assert_eq!(fit.hidden_initial_values, 1, "{}", fit.text());
    let s0 = fit.initial_states.iter().find(|(_, i, _)| *i == 0).unwrap().2;
    assert!((s0 / 990.0 - 1.0).abs() < 0.02, "S(0) {s0}\n{}", fit.text());
}

/// Ten seconds of Lorenz's chaos (some nine Lyapunov times) with 1 % noise, started 40-50 %
/// off: no whole-run re-simulation follows the record, however close its parameters, and the
/// estimate is flagged as failed, saying that the same model follows the run in segments and,
/// fitted so, parts from itself within the run (chaos) and into how many segments to cut it;
/// fitted so (each segment from its own initial values) σ, ρ and β come back within 1 %.
#[test]
fn a_chaotic_run_is_flagged_and_fitted_in_segments() {
    let (sigma, rho, beta) = LORENZ_TRUTH;
    let h = 0.01;
    let rows = lorenz_rows(h, 1001);
    let frame = noisy_frame("chaos", h, &["x", "y", "z"], &rows, &noise(&rows, 0.01), &mut Lcg(3));
    let far = LORENZ_FREE
        .replace("value = 8.0", "value = 5.0")
        .replace("value = 22.4", "value = 40.0")
        .replace("value = 3.2", "value = 1.5");
    let model = Model::parse(&far, "lorenz_far.toml").unwrap();
    let whole = estimate(
        &model,
        &Runs::new(&model, std::slice::from_ref(&frame), h, Integrator::Rk4).unwrap(),
        &EstimateSettings::default(),
    )
    .unwrap();
    assert!(!whole.follows(), "{}", whole.text());
    let text = whole.text();
    assert!(
        text.contains("FLAG the fit does not follow the records")
            && text.contains("a chaotic or unstable motion"),
        "{text}"
    );
    // the count it names: segments of at most half the time the model stays predictable from
    // a start off by the records' noise (about ln(0.1/0.01)/0.906 = 2.5 s by Lorenz's largest
    // Lyapunov exponent; its early growth is faster)
    let (parts, run) = whole.segmented.as_ref().and_then(|s| s.predictable_for).unwrap();
    assert!(parts > 0.5 && parts < 2.5 * 1.5 && (run - 10.0).abs() < 0.02, "{parts} of {run}");
    let count: usize =
        text.split("`--segments ").nth(1).and_then(|r| r.split('`').next()).unwrap().parse().unwrap();
    assert_eq!(count as f64, (2.0 * run / parts).ceil(), "{text}");
    let (pieces, _) = in_segments(&[frame], &[], count);
    assert_eq!(pieces.len(), count);
    let fit = estimate(
        &model,
        &Runs::new(&model, &pieces, h, Integrator::Rk4).unwrap(),
        &EstimateSettings::default(),
    )
    .unwrap();
    assert!(fit.follows(), "{}", fit.text());
    recovered(&fit, &[("σ", sigma), ("ρ", rho), ("β", beta)], 0.01);
}

const REACTIONS: &str = r#"
[model]
name = "two reactions in series, A → B → C"
intercept = false
[[states]]
name = "A"
initial = 1.0
[[states]]
name = "B"
initial = 0.0
[parameters.k1]
value = 30.0
free = true
bounds = [0.0, 1000.0]
[parameters.k2]
value = 0.8
free = true
bounds = [0.0, 1000.0]
[equations.a_dot]
state = "A"
identify = false
coefficients = { "k1*A" = -1.0 }
[equations.b_dot]
state = "B"
identify = false
coefficients = { "k1*A" = 1.0, "k2*B" = -1.0 }
"#;

/// A fast reaction feeding a slow one, sampled at 0.1 s where the fast one's time constant is
/// 0.02 s: one RK4 step a sample (the default where records drive a re-simulation) cannot
/// follow it, and the fit's k1 went where the integrator could (15.8 for 50 on a like record,
/// unflagged). The step
/// is halved until it resolves the start's motion and the estimates' (here to 1/8 of a
/// sample, said in the report), and k1 and k2 come back within 3 %.
#[test]
fn a_fast_rate_is_integrated_at_a_step_that_resolves_it() {
    let (k1, k2) = (50.0, 0.5);
    let h = 0.1;
    let rows = trajectory(&[1.0, 0.0], h, 101, 100, |_, x| vec![-k1 * x[0], k1 * x[0] - k2 * x[1]]);
    let frame = noisy_frame("batch", h, &["A", "B"], &rows, &noise(&rows, 0.01), &mut Lcg(9));
    let model = Model::parse(REACTIONS, "reactions.toml").unwrap();
    let runs = Runs::new(&model, std::slice::from_ref(&frame), h, Integrator::Rk4).unwrap();
    let fit = estimate(&model, &runs, &EstimateSettings::default()).unwrap();
    assert!(fit.finer >= 4, "{}", fit.text());
    assert!(
        fit.text().contains(&format!("integrated at 1/{} of the runs' step", fit.finer)),
        "{}",
        fit.text()
    );
    recovered(&fit, &[("k1", k1), ("k2", k2)], 0.03);
    // re-simulated as the fit has it: at its step, near the records
    let sims = fit.re_simulated(&runs).unwrap();
    assert!(runs.gap(&sims).states.iter().all(|(_, _, rms, _)| *rms < 0.02), "{:?}", runs.gap(&sims).states);
}

/// A record with dropped samples (every seventh row lost, a step of two where it happens) was
/// compared with a re-simulation sample by sample, each row beyond the first gap against
/// the wrong time: `estimate` stopped on a residual "not reached", `validate` printed NaN.
/// The library refuses such a run with its row; the CLI puts it back on its median step,
/// says so, and the predator and its prey come back within 2 %.
#[test]
fn a_record_with_dropped_samples_is_evened_and_said() {
    let (a, b, c, d) = PREDATION;
    let h = 0.1;
    let rows = predators(h);
    let frame = noisy_frame("kept", h, &["x", "y"], &rows, &noise(&rows, 0.01), &mut Lcg(2));
    let kept: Vec<usize> = (0..rows.len()).filter(|k| k % 7 != 3).collect();
    let mut csv = String::from("t,x,y\n");
    for &k in &kept {
        let (x, y) = (frame.column("x").unwrap()[k], frame.column("y").unwrap()[k]);
        csv.push_str(&format!("{},{x},{y}\n", frame.time()[k]));
    }
    let model = Model::parse(LOTKA_VOLTERRA, "lotka_volterra.toml").unwrap();
    let gappy = {
        let mut f =
            termid::data::Frame::new("gappy.csv", "t", kept.iter().map(|&k| frame.time()[k]).collect())
                .unwrap();
        for name in ["x", "y"] {
            f.push(name, kept.iter().map(|&k| frame.column(name).unwrap()[k]).collect()).unwrap();
        }
        f
    };
    let e = Runs::new(&model, &[gappy], h, Integrator::Rk4).err().unwrap().to_string();
    assert!(e.contains("gappy.csv: samples not evenly spaced (row 4"), "{e}");
    let dir = crate::common::Scratch::new("dropped-samples");
    let (data, file) = (dir.join("gappy.csv"), dir.join("lotka_volterra.toml"));
    std::fs::write(&data, csv).unwrap();
    std::fs::write(&file, LOTKA_VOLTERRA).unwrap();
    let (ok, out, err) = crate::common::termid(&[
        "estimate",
        "--model",
        file.to_str().unwrap(),
        "--data",
        data.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains("samples not evenly spaced") && err.contains("resampled onto its median step"),
        "{err}"
    );
    let report = crate::common::json(&out);
    for (name, truth) in [("a", a), ("b", b), ("c", c), ("d", d)] {
        let p = report["parameters"].as_array().unwrap().iter().find(|p| p["name"] == name).unwrap();
        let v = p["value"].as_f64().unwrap();
        assert!((v / truth - 1.0).abs() < 0.02, "{name}: {v} vs {truth}\n{out}");
    }
}

/// `termid estimate --segments 16` on the chaotic run: each segment a run of its own, σ, ρ
/// and β within 1 % from 40-50 % off; fewer than two segments is refused by the option.
#[test]
fn the_estimate_command_fits_a_chaotic_run_in_segments() {
    let h = 0.01;
    let rows = lorenz_rows(h, 1001);
    let frame = noisy_frame("chaos", h, &["x", "y", "z"], &rows, &noise(&rows, 0.01), &mut Lcg(3));
    let mut csv = String::from("t,x,y,z\n");
    for (k, t) in frame.time().iter().enumerate() {
        let v: Vec<String> =
            ["x", "y", "z"].iter().map(|n| frame.column(n).unwrap()[k].to_string()).collect();
        csv.push_str(&format!("{t},{}\n", v.join(",")));
    }
    let dir = crate::common::Scratch::new("chaos-segments");
    let (data, file) = (dir.join("chaos.csv"), dir.join("lorenz_far.toml"));
    std::fs::write(&data, csv).unwrap();
    let far = LORENZ_FREE
        .replace("value = 8.0", "value = 5.0")
        .replace("value = 22.4", "value = 40.0")
        .replace("value = 3.2", "value = 1.5");
    std::fs::write(&file, far).unwrap();
    let run = |segments: &str| {
        crate::common::termid(&[
            "estimate",
            "--model",
            file.to_str().unwrap(),
            "--data",
            data.to_str().unwrap(),
            "--segments",
            segments,
            "--format",
            "json",
        ])
    };
    let (ok, out, err) = run("16");
    assert!(ok, "{err}");
    let report = crate::common::json(&out);
    assert!(report["unexplained"].as_f64().unwrap() < 0.01, "{out}");
    let (sigma, rho, beta) = LORENZ_TRUTH;
    for (name, truth) in [("σ", sigma), ("ρ", rho), ("β", beta)] {
        let p = report["parameters"].as_array().unwrap().iter().find(|p| p["name"] == name).unwrap();
        let v = p["value"].as_f64().unwrap();
        assert!((v / truth - 1.0).abs() < 0.01, "{name}: {v} vs {truth}\n{out}");
    }
    let (ok, _, err) = run("1");
    assert!(!ok && err.contains("--segments"), "{err}");
}
