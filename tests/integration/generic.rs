//! The core knows nothing of ships: the Lorenz system and a forced Duffing oscillator are
//! simulated and identified with the same code and commands.

use std::collections::BTreeMap;

use termid::data::{CentralDifference, Frame};
use termid::identify::{equation_design, fit_equation, fit_equation_design, Design, Target};
use termid::model::Model;
use termid::sim::{simulate, Constant, Integrator, Replay, Settings, System};

use crate::common::termid;

fn lorenz_run() -> (Model, Frame) {
    let m = termid::plugins::load(std::path::Path::new("models/lorenz.toml")).unwrap();
    let system = System::new(&m, &BTreeMap::new(), false).unwrap();
    let x0: Vec<f64> = m.spec().states.iter().map(|s| s.initial).collect();
    let s = Settings { integrator: Integrator::Rk4, dt: 0.001, duration: 10.0, sample: 0.001 };
    let traj = simulate(&system, &x0, &mut Constant(vec![]), &s).unwrap();
    let f = traj.to_frame("lorenz", "t").unwrap();
    (m, f)
}

fn check(m: &Model, frames: &[Frame], target: fn(&str) -> Option<Target>, rel: f64) {
    for eq in m.equations() {
        let fit = fit_equation(m, &eq.name, frames, &CentralDifference, false, target(&eq.state)).unwrap();
        let mut got: Vec<(String, f64)> =
            fit.selection.terms.iter().map(|t| (t.term.clone(), t.coefficient)).collect();
        got.sort_by(|a, b| a.0.cmp(&b.0));
        let mut want: Vec<(String, f64)> =
            eq.coefficients.iter().map(|(t, c, _)| (t.to_string(), *c)).collect();
        want.sort_by(|a, b| a.0.cmp(&b.0));
        let names = |v: &[(String, f64)]| v.iter().map(|x| x.0.clone()).collect::<Vec<_>>();
        assert_eq!(names(&got), names(&want), "{}: terms (notes: {:?})", eq.name, fit.selection.notes);
        for ((t, g), (_, w)) in got.iter().zip(&want) {
            assert!((g - w).abs() <= rel * w.abs(), "{} {t}: {g} vs {w}", eq.name);
        }
    }
}

#[test]
fn lorenz_identified_exactly_from_exact_derivatives() {
    let (m, f) = lorenz_run();
    check(&m, &[f], |_| None, 1e-6);
}

/// A design compiled once fits exactly as a fresh compilation does, and one compiled from
/// other candidates is refused instead of fitting the wrong candidates.
#[test]
fn a_compiled_design_fits_as_a_fresh_one_and_only_its_own_equation() {
    let (m, f) = lorenz_run();
    let frames = [f];
    for eq in m.equations() {
        let design = equation_design(&m, &eq.name).unwrap();
        let fresh = fit_equation(&m, &eq.name, &frames, &CentralDifference, false, None).unwrap();
        let again =
            fit_equation_design(&m, &eq.name, Some(&design), &frames, &CentralDifference, false, None)
                .unwrap();
        // compared as printed: a thresholding back-end's steps carry NaN (no reduction), and
        // NaN is equal to nothing
        assert_eq!(format!("{:?}", fresh.selection), format!("{:?}", again.selection), "{}", eq.name);
        assert_eq!(fresh.candidates, again.candidates);
    }
    let eq = &m.equations()[0];
    let fewer = Design::new(&eq.candidates[..3], &m.vocabulary).unwrap();
    let err = fit_equation_design(&m, &eq.name, Some(&fewer), &frames, &CentralDifference, false, None)
        .unwrap_err();
    assert!(err.to_string().contains("other candidates"), "{err}");
}

#[test]
fn lorenz_identified_to_one_percent_from_central_differences() {
    let (m, f) = lorenz_run();
    check(&m, &[f], |s| Some(Target::Derivative(s.to_string())), 0.01);
}

#[test]
fn duffing_with_replayed_forcing() {
    let m = termid::plugins::load(std::path::Path::new("models/duffing.toml")).unwrap();
    let system = System::new(&m, &BTreeMap::new(), false).unwrap();
    let t: Vec<f64> = (0..=4000).map(|i| i as f64 * 0.01).collect();
    let mut forcing = Frame::new("forcing", "t", t.clone()).unwrap();
    forcing.push("F", t.iter().map(|t| 0.8 * (0.7 * t).sin() + 0.5 * (1.9 * t).sin()).collect()).unwrap();
    let mut replay = Replay::new(&forcing, &system.inputs).unwrap();
    let s = Settings { integrator: Integrator::Rk4, dt: 0.005, duration: 40.0, sample: 0.01 };
    let traj = simulate(&system, &[0.5, 0.0], &mut replay, &s).unwrap();
    let f = traj.to_frame("duffing", "t").unwrap();
    let fit = fit_equation(&m, "v_dot", &[f], &CentralDifference, false, None).unwrap();
    let mut got: Vec<(String, f64)> =
        fit.selection.terms.iter().map(|t| (t.term.clone(), t.coefficient)).collect();
    got.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(got.len(), 4, "{got:?}");
    for ((name, g), (wn, w)) in got.iter().zip([("F", 1.0), ("v", -0.1), ("x", -1.0), ("x^3", -0.2)]) {
        assert_eq!(name, wn);
        assert!((g - w).abs() < 1e-6, "{name}: {g}");
    }
}

#[test]
fn same_commands_for_lorenz_and_the_ship() {
    let dir = crate::common::Scratch::new("generic");
    let csv = crate::common::lorenz_csv(&dir, "5");
    let out = dir.join("lorenz-identified.toml");
    let (ok, _, err) = termid(&[
        "identify",
        "--model",
        "models/lorenz.toml",
        "--data",
        csv.to_str().unwrap(),
        "--no-intercept",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let back = termid::plugins::load(&out).unwrap();
    assert_eq!(back.equation("y_dot").unwrap().coefficients.len(), 3);
    let (ok, stdout, err) =
        termid(&["simulate", "--model", out.to_str().unwrap(), "--duration", "1", "--format", "json"]);
    assert!(ok, "{err}");
    assert!(stdout.contains("final_state"));
    // the ship: default model, metrics as JSON, CSV and SVG written
    let ship_csv = dir.join("z.csv");
    let svg = dir.join("z.svg");
    let (ok, stdout, err) = termid(&[
        "simulate",
        "-m",
        "zigzag:20/20",
        "--format",
        "json",
        "--out",
        ship_csv.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert!(v["metrics"]["first_overshoot_deg"].as_f64().unwrap() > 5.0);
    let frame = Frame::read_csv(&ship_csv, "t").unwrap();
    for c in ["u", "v", "r", "δ", "ψ", "x0", "y0", "U", "β", "u_dot", "v_dot", "r_dot"] {
        assert!(frame.column(c).is_some(), "column {c}");
    }
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
    // a diverging run writes no file
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        std::fs::read_to_string("models/duffing.toml").unwrap().replace("\"v\" = -0.1", "\"v\" = 2.0"),
    )
    .unwrap();
    let never = dir.join("never.csv");
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        bad.to_str().unwrap(),
        "--input",
        "F=1",
        "--duration",
        "60",
        "--out",
        never.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(err.contains("diverged at t =") && err.contains("outside its bounds"), "{err}");
    assert!(!never.exists());
}

/// Forced Duffing runs at three forcing amplitudes, with their exact derivatives.
fn duffing_runs(m: &Model) -> Vec<Frame> {
    let system = System::new(m, &BTreeMap::new(), false).unwrap();
    let t: Vec<f64> = (0..=2000).map(|i| i as f64 * 0.01).collect();
    [0.3, 0.8, 1.4]
        .iter()
        .enumerate()
        .map(|(k, a)| {
            let mut forcing = Frame::new("forcing", "t", t.clone()).unwrap();
            forcing
                .push("F", t.iter().map(|t| a * (0.7 * t).sin() + 0.3 * (1.9 * t).cos()).collect())
                .unwrap();
            let mut replay = Replay::new(&forcing, &system.inputs).unwrap();
            let s = Settings { integrator: Integrator::Rk4, dt: 0.005, duration: 20.0, sample: 0.01 };
            let traj = simulate(&system, &[0.2 * k as f64, 0.0], &mut replay, &s).unwrap();
            traj.to_frame(&format!("run{k}"), "t").unwrap()
        })
        .collect()
}

/// Choosing by prediction: the library with the cubic stiffness predicts the runs it did not
/// see; a library without it cannot, and the table says so. Each fold's error is the
/// re-simulation of that run by the model identified on the other two.
#[test]
fn choosing_by_prediction_prefers_the_library_that_predicts_held_out_runs() {
    use termid::diagnose::{choose_by_prediction, Prediction, Runs};
    use termid::identify::{identify_model, ModelIdentification};
    let m = termid::plugins::load(std::path::Path::new("models/duffing.toml")).unwrap();
    let frames = duffing_runs(&m);
    let linear = m
        .edit(|file| {
            let e = file.equations.get_mut("v_dot").unwrap();
            e.candidates.retain(|c| !c.contains('3') && !c.contains("^2"));
        })
        .unwrap();
    let configurations = vec![("linear".to_string(), linear.clone()), ("cubic".to_string(), m.clone())];
    let how = ModelIdentification {
        equations: vec![],
        differentiator: &CentralDifference,
        intercept: false,
        target: None,
    };
    let prediction = Prediction::default();
    let chosen = choose_by_prediction(&configurations, &frames, &how, &prediction, &mut |_| {}).unwrap();
    assert_eq!(chosen.best, 1, "{}", chosen.text());
    let (lin, cub) = (&chosen.candidates[0], &chosen.candidates[1]);
    assert!(cub.score < 1e-6 && lin.score > 1e-3, "{}", chosen.text());
    assert!(chosen.text().contains("← chosen"));
    // the first fold of the linear library, computed directly
    let id = identify_model(&linear, &frames[1..], &how, &mut |_| {}).unwrap();
    // by default one step per sample of the held-out run
    assert_eq!(prediction.dt, None);
    let step = frames[0].time()[1] - frames[0].time()[0];
    let runs = Runs::new(&id.model, &frames[..1], step, prediction.integrator)
        .unwrap()
        .comparing(&id.model, &["v".to_string()])
        .unwrap();
    let direct = runs.gap(&runs.simulate(&id.model, &[], &[]).unwrap()).cost;
    assert!((lin.folds[0].1 - direct).abs() <= 1e-9 * direct, "{} vs {direct}", lin.folds[0].1);
    assert_eq!(lin.folds[0].0, "run0");
    // the chosen model is the cubic library identified on all runs: the true coefficients
    let x3 = chosen
        .identified
        .model
        .equation("v_dot")
        .unwrap()
        .coefficients
        .iter()
        .find(|c| c.0.to_string() == "x^3")
        .map(|c| c.1);
    assert!((x3.unwrap() + 0.2).abs() < 1e-6, "{x3:?}");
    // too few runs to leave one out
    assert!(choose_by_prediction(&configurations, &frames[..1], &how, &prediction, &mut |_| {}).is_err());
}

/// `termid moments` on two shards and `identify --moments` give the model `identify` gives
/// from the rows together (the coefficients to round-off); statistics of another equation or
/// a broken file are refused by name.
#[test]
fn statistics_of_shards_identify_as_the_rows_together() {
    let dir = crate::common::Scratch::new("moments");
    let p = |f: &str| dir.join(f).display().to_string();
    // two runs of the Lorenz system from different starts, the derivatives from the data
    for (name, x0) in [("a.csv", "x=-8"), ("b.csv", "x=4")] {
        let (ok, _, err) = termid(&[
            "simulate",
            "--model",
            "models/lorenz.toml",
            "--integrator",
            "rk4",
            "--dt",
            "0.001",
            "--sample",
            "0.004",
            "--duration",
            "3",
            "--initial",
            x0,
            "--out",
            &p(name),
        ]);
        assert!(ok, "{err}");
        let text = std::fs::read_to_string(p(name)).unwrap();
        // states only, as a measurement has them
        let kept: Vec<String> =
            text.lines().map(|l| l.split(',').take(4).collect::<Vec<_>>().join(",")).collect();
        std::fs::write(p(name), kept.join("\n")).unwrap();
    }
    for eq in ["x_dot", "y_dot", "z_dot"] {
        for shard in ["a", "b"] {
            let (ok, out, err) = termid(&[
                "moments",
                "--model",
                "models/lorenz.toml",
                "--equation",
                eq,
                "--data",
                &p(&format!("{shard}.csv")),
                "--out",
                &p(&format!("{shard}_{eq}.moments")),
            ]);
            assert!(ok && out.contains("1 run(s)"), "{out}{err}");
        }
    }
    let files: Vec<String> = ["x_dot", "y_dot", "z_dot"]
        .iter()
        .flat_map(|eq| ["a", "b"].map(|s| p(&format!("{s}_{eq}.moments"))))
        .collect();
    let mut args = vec!["identify", "--model", "models/lorenz.toml", "--out", "MERGED", "--moments"];
    let merged_out = p("merged.toml");
    args[4] = &merged_out;
    args.extend(files.iter().map(String::as_str));
    let (ok, out, err) = termid(&args);
    assert!(ok && out.contains("== z_dot =="), "{out}{err}");
    // `identify --model lorenz --data …`
    let identify = |more: &[&str]| {
        let mut args = vec!["identify", "--model", "models/lorenz.toml", "--data"];
        args.extend(more);
        termid(&args)
    };
    let (a, b) = (p("a.csv"), p("b.csv"));
    let rows_out = p("rows.toml");
    let (ok, _, err) = identify(&[&a, &b, "--derivative", "central", "--out", &rows_out]);
    assert!(ok, "{err}");
    // the same runs read in pieces by identify itself (one pass, bounded memory)
    let pieces_out = p("pieces.toml");
    let (ok, out, err) =
        identify(&[&a, &b, "--chunk-rows", "97", "--derivative", "central", "--out", &pieces_out]);
    assert!(ok && out.contains("== z_dot =="), "{out}{err}");
    let (merged, rows, pieces) = (
        termid::plugins::load(std::path::Path::new(&merged_out)).unwrap(),
        termid::plugins::load(std::path::Path::new(&rows_out)).unwrap(),
        termid::plugins::load(std::path::Path::new(&pieces_out)).unwrap(),
    );
    for eq in ["x_dot", "y_dot", "z_dot"] {
        let b = &rows.equation(eq).unwrap().coefficients;
        assert!(!b.is_empty(), "{eq}");
        for (other, tol) in [(&merged, 1e-12), (&pieces, 1e-10)] {
            let a = &other.equation(eq).unwrap().coefficients;
            assert_eq!(a.len(), b.len(), "{eq}");
            for ((ta, ca, _), (tb, cb, _)) in a.iter().zip(b) {
                assert_eq!(ta, tb);
                assert!((ca - cb).abs() <= tol * ca.abs().max(1.0), "{eq} {ta}: {ca} vs {cb}");
            }
        }
    }
    // what needs whole runs is refused with --chunk-rows, by name
    let (ok, _, err) = identify(&[&a, "--chunk-rows", "97", "--derivative", "spline", "--smooth"]);
    assert!(!ok && err.contains("--smooth") && err.contains("whole runs"), "{err}");
    // statistics of other candidates for the same equation do not merge; a damaged file is named
    let other = std::fs::read_to_string(p("b_x_dot.moments")).unwrap().replacen(
        "\"candidates\":[\"",
        "\"candidates\":[\"1*",
        1,
    );
    std::fs::write(p("other.moments"), other).unwrap();
    let (ok, _, err) = termid(&[
        "identify",
        "--model",
        "models/lorenz.toml",
        "--moments",
        &p("a_x_dot.moments"),
        &p("other.moments"),
    ]);
    assert!(!ok && err.contains("other.moments") && err.contains("cannot be merged"), "{err}");
    std::fs::write(p("bad.moments"), "{\"equation\": \"x_dot\"").unwrap();
    let (ok, _, err) = termid(&["identify", "--model", "models/lorenz.toml", "--moments", &p("bad.moments")]);
    assert!(!ok && err.contains("bad.moments"), "{err}");
}

/// `--data` takes Parquet as it takes CSV: the same run in both identifies to the same model.
#[test]
fn parquet_runs_identify_as_csv_runs() {
    use std::sync::Arc;
    let dir = crate::common::Scratch::new("parquet");
    let csv = crate::common::lorenz_csv(&dir, "2");
    let frame = Frame::read(&csv, "t").unwrap();
    let fields: Vec<arrow_schema::Field> = frame
        .names()
        .iter()
        .map(|n| arrow_schema::Field::new(n, arrow_schema::DataType::Float64, false))
        .collect();
    let arrays: Vec<arrow_array::ArrayRef> = frame
        .names()
        .iter()
        .map(|n| Arc::new(arrow_array::Float64Array::from(frame.column(n).unwrap().to_vec())) as _)
        .collect();
    let batch =
        arrow_array::RecordBatch::try_new(Arc::new(arrow_schema::Schema::new(fields)), arrays).unwrap();
    let pq = dir.join("lorenz.parquet");
    let mut w =
        parquet::arrow::ArrowWriter::try_new(std::fs::File::create(&pq).unwrap(), batch.schema(), None)
            .unwrap();
    w.write(&batch).unwrap();
    w.close().unwrap();
    let fit = |data: &std::path::Path| {
        let (ok, out, err) = termid(&[
            "identify",
            "--model",
            "models/lorenz.toml",
            "--data",
            data.to_str().unwrap(),
            "--format",
            "json",
        ]);
        assert!(ok, "{err}");
        out
    };
    let (a, b) = (fit(&csv), fit(&pq));
    assert!(a.contains("\"terms\""), "{a}");
    assert_eq!(a, b);
}

/// Issue 16 §2: `termid moments` reads plain files in pieces (one pass, bounded memory) and
/// gets the statistics of the whole file to round-off, from CSV and Parquet alike, for the
/// local derivative methods; errors name the file's own rows; a file of no lines is refused
/// at once (it grew without bound).
#[test]
fn moments_read_in_pieces_equal_the_whole_file() {
    use std::sync::Arc;

    use arrow_array::{ArrayRef, Float64Array, RecordBatch};
    let dir = crate::common::Scratch::new("pieces");
    let p = |f: &str| dir.join(f).display().to_string();
    let (_, frame) = lorenz_run();
    // the states only: the target is the derivative, taken piece by piece
    let keep: Vec<String> = ["t", "x", "y", "z"].iter().map(|s| s.to_string()).collect();
    let mut text = keep.join(",") + "\n";
    let cols: Vec<&[f64]> = keep.iter().map(|c| frame.column(c).unwrap()).collect();
    for r in 0..frame.len() {
        text += &cols.iter().map(|c| format!("{:?}", c[r])).collect::<Vec<_>>().join(",");
        text.push('\n');
    }
    std::fs::write(p("run.csv"), &text).unwrap();
    let arrays: Vec<(String, ArrayRef)> = keep
        .iter()
        .zip(&cols)
        .map(|(n, c)| (n.clone(), Arc::new(Float64Array::from(c.to_vec())) as ArrayRef))
        .collect();
    let batch = RecordBatch::try_from_iter(arrays).unwrap();
    let file = std::fs::File::create(p("run.parquet")).unwrap();
    let mut writer = parquet::arrow::ArrowWriter::try_new(file, batch.schema(), None).unwrap();
    // several row groups and batches
    for k in (0..batch.num_rows()).step_by(3000) {
        writer.write(&batch.slice(k, 3000.min(batch.num_rows() - k))).unwrap();
        writer.flush().unwrap();
    }
    writer.close().unwrap();
    let numbers = |path: &str| -> (usize, Vec<f64>) {
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let m = &v["runs"][0]["moments"];
        (
            m["count"].as_u64().unwrap() as usize,
            m["numbers"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect(),
        )
    };
    // `termid moments` of y_dot: (succeeded, stderr)
    let moments = |data: &str, derivative: &str, rows: &str, out: &str| {
        let (ok, _, err) = termid(&[
            "moments",
            "--model",
            "models/lorenz.toml",
            "--equation",
            "y_dot",
            "--data",
            data,
            "--derivative",
            derivative,
            "--chunk-rows",
            rows,
            "--out",
            out,
        ]);
        (ok, err)
    };
    // (method, rows that are not the target's: the integral form's last window starts w
    // samples before the end)
    for (derivative, short) in [
        ("central", 0),
        ("five-point", 0),
        ("savitzky-golay:9:3", 0),
        ("integral", 8),
        ("integral:6", 6),
        ("weak", 32),
        ("weak:16:4", 16),
    ] {
        let run = |data: &str, rows: &str, out: &str| {
            let (ok, err) = moments(data, derivative, rows, out);
            assert!(ok, "{err}");
            numbers(out)
        };
        let whole = run(&p("run.csv"), "0", &p("whole.json"));
        assert_eq!(whole.0, frame.len() - short);
        for (data, rows) in [(p("run.csv"), "97"), (p("run.csv"), "1000"), (p("run.parquet"), "500")] {
            let pieces = run(&data, rows, &p("pieces.json"));
            assert_eq!(pieces.0, whole.0);
            for (a, b) in whole.1.iter().zip(&pieces.1) {
                assert!((a - b).abs() <= 1e-10 * a.abs().max(1.0), "{derivative} {data} {rows}: {a} vs {b}");
            }
        }
    }
    // a smoother needs the whole run: read whole, whatever --chunk-rows says
    let (ok, err) = moments(&p("run.csv"), "spline", "100", &p("spline.json"));
    assert!(ok, "{err}");
    // a bad cell deep in the file: its row in the file, in pieces as whole
    let mut lines: Vec<&str> = text.lines().collect();
    let bad = format!("{},1,2,NaN", frame.time()[7000]);
    lines[7001] = &bad;
    std::fs::write(p("bad.csv"), lines.join("\n")).unwrap();
    for rows in ["0", "300"] {
        let (ok, err) = moments(&p("bad.csv"), "central", rows, &p("bad.json"));
        assert!(!ok && err.contains("row 7001, column `z`"), "{rows}: {err}");
    }
    if std::path::Path::new("/dev/zero").exists() {
        let (ok, err) = moments("/dev/zero", "central", "262144", &p("zero.json"));
        assert!(!ok && (err.contains("not a CSV file") || err.contains("not a text file")), "{err}");
    }
}

/// A damped pendulum, θ̈ = −9.81 sin θ − 0.5 θ̇, released from 1 rad (issue 25 §1).
const PENDULUM: &str = r#"
[model]
name = "damped pendulum"
time = "t"
[[states]]
name = "theta"
unit = "rad"
initial = 1.0
[[states]]
name = "omega"
unit = "rad/s"
initial = 0.0
[equations.theta_dot]
state = "theta"
coefficients = { "omega" = 1.0 }
[equations.omega_dot]
state = "omega"
coefficients = { "sin(theta)" = -9.81, "omega" = -0.5 }
"#;

/// The adaptive Dormand-Prince method against scipy's DOP853 at rtol = atol = 1e-13 (numbers
/// computed outside termid: `solve_ivp(f, (0, T), y0, method="DOP853")`), on the pendulum,
/// the forced Duffing oscillator and Lorenz over less than its Lyapunov time; and as every
/// command's default (B8 at 0.04 s left the pendulum at θ(20) = 0.016 and README's Duffing at
/// v = 0.094).
#[test]
fn adaptive_integration_matches_dop853() {
    let tight = "\n[simulation]\nmethod = \"dopri5\"\nrtol = 1e-11\natol = 1e-12\n";
    // (name, model text, constant inputs, duration, DOP853's final state)
    type Case<'a> = (&'a str, String, BTreeMap<&'a str, f64>, f64, &'a [f64]);
    let cases: [Case; 3] = [
        (
            "pendulum",
            PENDULUM.to_string(),
            BTreeMap::new(),
            20.0,
            &[0.004258497545507634, 0.014630331091916731],
        ),
        (
            "duffing",
            std::fs::read_to_string("models/duffing.toml").unwrap(),
            BTreeMap::from([("F", 0.5)]),
            60.0,
            &[0.4679531943718057, 0.02254676758615276],
        ),
        (
            "lorenz",
            std::fs::read_to_string("models/lorenz.toml").unwrap(),
            BTreeMap::new(),
            1.0,
            &[5.523676640069421, 9.518798956834514, 13.583499714528173],
        ),
    ];
    for (name, text, inputs, duration, expected) in cases {
        let model = Model::parse(&(text.clone() + tight), name).unwrap();
        let system = System::new(&model, &BTreeMap::new(), false).unwrap();
        let x0: Vec<f64> = model.spec().states.iter().map(|s| s.initial).collect();
        let u: Vec<f64> =
            system.inputs.iter().map(|i| inputs.get(i.as_str()).copied().unwrap_or(0.0)).collect();
        let (method, dt) = model.simulation(None, None);
        assert_eq!(method, Integrator::Dopri5);
        let settings = Settings { integrator: method, dt, duration, sample: dt };
        let run = simulate(&system, &x0, &mut Constant(u), &settings).unwrap();
        for (got, want) in run.last_state().iter().zip(expected) {
            assert!((got - want).abs() < 1e-8 * want.abs().max(1.0), "{name}: {got} vs {want}");
        }
        // none of them is stiff: every step explicit
        assert_eq!(run.stiff_from, None, "{name}");
        // the command's default, at the default tolerances
        let path = std::env::temp_dir().join(format!("termid-dop853-{name}-{}.toml", std::process::id()));
        std::fs::write(&path, &text).unwrap();
        let mut args = vec!["simulate", "--model", path.to_str().unwrap(), "--format", "json"];
        let d = duration.to_string();
        args.extend(["--duration", &d]);
        let forcing: Vec<String> = inputs.iter().map(|(k, v)| format!("{k}={v}")).collect();
        if !forcing.is_empty() {
            args.push("--input");
            args.extend(forcing.iter().map(String::as_str));
        }
        let (ok, out, err) = termid(&args);
        assert!(ok, "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        for (state, want) in model.spec().states.iter().zip(expected) {
            let got = v["final_state"][&state.name].as_f64().unwrap();
            assert!(
                (got - want).abs() < 1e-4 * want.abs().max(1.0),
                "{name} default: {} {got} vs {want}",
                state.name
            );
        }
        std::fs::remove_file(&path).ok();
    }
}

/// Right or it says so: Lorenz identified from its own samples (coefficients within 10⁻⁴)
/// validates on that run with errors as large as the attractor after ~10 s, since a start a
/// millionth off parts from the model's own run there (its largest Lyapunov exponent 0.906 /s,
/// Sprott 2003: 10⁵-fold in ln(10⁵)/0.906 = 12.7 s on average). `validate` says for how long
/// the run is predictable at all and gives the errors over that stretch, where they are
/// small; the forced, damped Duffing oscillator is predictable throughout.
#[test]
fn validate_says_how_long_a_chaotic_run_is_predictable() {
    let dir = crate::common::Scratch::new("chaos");
    let data = dir.join("l.csv");
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        "models/lorenz.toml",
        "--duration",
        "20",
        "--dt",
        "0.001",
        "--sample",
        "0.01",
        "--out",
        data.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let found = dir.join("found.toml");
    let (ok, _, err) = termid(&[
        "identify",
        "--model",
        "models/lorenz.toml",
        "--data",
        data.to_str().unwrap(),
        "--out",
        found.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, out, err) = termid(&[
        "validate",
        "--model",
        found.to_str().unwrap(),
        "--data",
        data.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let seconds = v["predictable_for"][0]["seconds"].as_f64().unwrap_or_else(|| panic!("{out}"));
    let mean = (1e5f64).ln() / 0.906;
    assert!(seconds > 0.5 * mean && seconds < 1.5 * mean, "{seconds} s");
    let (ok, out, err) =
        termid(&["validate", "--model", found.to_str().unwrap(), "--data", data.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(out.contains("is predictable for") && out.contains("whatever the model"), "{out}");
    // the errors over the predictable stretch: a few thousandths of the states' size
    let early = out.split("over the first").nth(1).unwrap_or_else(|| panic!("{out}"));
    let x_max: f64 = early
        .split("x ")
        .nth(1)
        .and_then(|c| c.split(" / ").nth(1))
        .and_then(|m| m.split(',').next())
        .and_then(|m| m.trim().parse().ok())
        .unwrap_or_else(|| panic!("{early}"));
    assert!(x_max < 0.05, "{early}");
    // Duffing, forced and damped, is not chaotic here
    let duffing = dir.join("d.csv");
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        "models/duffing.toml",
        "--input",
        "F=0.5",
        "--duration",
        "60",
        "--sample",
        "0.05",
        "--out",
        duffing.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, out, err) = termid(&[
        "validate",
        "--model",
        "models/duffing.toml",
        "--data",
        duffing.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v["predictable_for"][0]["seconds"].is_null(), "{out}");
}

/// Robertson's chemical kinetics (Hairer & Wanner, *Solving ODEs II*, IV.1), the classic
/// stiff test, as `models/robertson.toml` writes it, with its absolute tolerance `atol`.
fn robertson(atol: &str) -> String {
    let text = std::fs::read_to_string("models/robertson.toml").unwrap();
    assert!(text.contains("atol = 1e-10"), "the file's tolerance moved");
    text.replace("atol = 1e-10", &format!("atol = {atol}"))
}

/// Right or it says so: Robertson's reaction conserves a + b + c (= 1), so any candidate in c
/// is one in a and b and a back-end keeps one way of writing the equation, leaving the rest
/// (here b·c, the system's own term) out as collinear. The fit names the invariant; Lorenz,
/// which has none, gets no such note.
#[test]
fn a_conservation_law_is_named() {
    let dir = crate::common::Scratch::new("conserved");
    let model = dir.join("robertson.toml");
    std::fs::write(&model, robertson("1e-12")).unwrap();
    let csv = dir.join("r.csv");
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        model.to_str().unwrap(),
        "--duration",
        "40",
        "--dt",
        "0.01",
        "--sample",
        "0.01",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    // the states alone (the recorded rates would be columns too)
    let text = std::fs::read_to_string(&csv).unwrap();
    let states: Vec<String> =
        text.lines().map(|l| l.split(',').take(4).collect::<Vec<_>>().join(",")).collect();
    std::fs::write(&csv, states.join("\n") + "\n").unwrap();
    let terms = dir.join("terms.txt");
    std::fs::write(&terms, "1\na\nb\nc\na*b\na*c\nb*c\na^2\nb^2\nc^2\n").unwrap();
    let out = identify_text(&csv, "da/dt", &terms, &[]);
    assert!(out.contains("`a + b + c` is the same in every row (a conservation law"), "{out}");
    let lorenz = dir.join("l.csv");
    let rows: Vec<String> =
        lorenz_rows(&dir, "0.01").iter().map(|r| format!("{},{},{},{}", r[0], r[1], r[2], r[3])).collect();
    std::fs::write(&lorenz, format!("t,x,y,z\n{}\n", rows.join("\n"))).unwrap();
    let quadratic = dir.join("quadratic.txt");
    std::fs::write(&quadratic, LORENZ_QUADRATIC).unwrap();
    let out = identify_text(&lorenz, "dx/dt", &quadratic, &[]);
    assert!(!out.contains("conservation law") && !out.contains("but for the records' noise"), "{out}");
}

/// An epidemic's S + I + R (= 1) recorded with 1 % noise on each: no longer exactly collinear,
/// so nothing is left out, and the back-end wrote dI/dt = 0.5·I·S − 0.1·I as 0.3995·I −
/// 0.4999·I·R − 0.4982·I² (the same law with S = 1 − I − R), every check but the halves "ok".
/// The fit says the law holds but for the noise and lists the candidates in R; leaving them
/// out (`--exclude`, which `--states` ignored before) writes it as the noise-free rows do. A
/// term no equation has is refused, not ignored.
#[test]
fn a_conservation_law_seen_through_noise_is_named() {
    let dir = crate::common::Scratch::new("conserved-noisy");
    let (beta, gamma) = (0.5, 0.1);
    let rows = crate::common::trajectory(&[0.99, 0.01, 0.0], 0.1, 1000, 10, |_, x| {
        vec![-beta * x[0] * x[1], beta * x[0] * x[1] - gamma * x[1], gamma * x[1]]
    });
    let sd = crate::common::noise(&rows, 0.01);
    let mut rng = crate::common::Lcg(3);
    let mut csv = String::from("t,S,I,R\n");
    for (k, r) in rows.iter().enumerate() {
        let noisy: Vec<String> = (0..3).map(|i| format!("{:?}", r[i] + sd[i] * rng.normal())).collect();
        csv += &format!("{:?},{}\n", 0.1 * k as f64, noisy.join(","));
    }
    let data = dir.join("sir.csv");
    std::fs::write(&data, csv).unwrap();
    let identified = |extra: &[&str]| {
        let args = ["identify", "--data", data.to_str().unwrap(), "--states", "S,I,R", "--format", "json"];
        let (ok, out, err) = termid(&[&args[..], extra].concat());
        assert!(ok, "{err}");
        crate::common::json(&out)
    };
    let found = identified(&[]);
    let notes = found["I_dot"]["notes"].to_string();
    assert!(
        notes.contains("the same in every row but for the records' noise")
            && notes.contains("the candidates in `R` left out (`R`, `R*S`, `I*R`"),
        "{notes}"
    );
    let holding = "R,R*S,I*R,R^2,R*S^2,I*R*S,R^2*S,I^2*R,I*R^2,R^3";
    let written = identified(&["--exclude", holding]);
    let got = crate::common::chosen_terms(&written["I_dot"]);
    let names: Vec<&str> = got.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["I", "I*S"], "{written}");
    assert!((got[0].1 + gamma).abs() < 0.01 * gamma && (got[1].1 - beta).abs() < 0.01 * beta, "{got:?}");
    let (ok, _, err) =
        termid(&["identify", "--data", data.to_str().unwrap(), "--states", "S,I,R", "--exclude", "I^3*R"]);
    assert!(!ok && err.contains("`I^3*R` is no candidate of an equation identified (excluded"), "{err}");
}

/// Right by default on a stiff model: the explicit steps of the default method are held by
/// stability (Robertson to 4·10⁵ s took four minutes and ended ten times off); it now finds
/// the model stiff, goes on with linearly implicit steps and says so. Against numbers from
/// outside: Robertson at t = 40 (Hairer & Wanner's reference 0.7158270687, 9.185534764e-6,
/// 0.2841637457) and at 10¹¹ s (the IVP test set of Mazzia & Magherini, ROBER: 2.0833401e-8,
/// 8.3333608e-14); van der Pol at μ = 1000, whose relaxation period is (3 − 2 ln 2)μ +
/// 3α·μ^(−1/3) + O(ln μ/μ) = 1614.41 (α = 2.33811, Ai's first zero; Dorodnitsyn 1947).
#[test]
fn stiff_models_by_default() {
    let run = |text: &str, method: Option<Integrator>, (dt, duration): (f64, f64)| {
        let model = Model::parse(text, "stiff.toml").unwrap();
        let system = System::new(&model, &BTreeMap::new(), false).unwrap();
        let x0: Vec<f64> = model.spec().states.iter().map(|s| s.initial).collect();
        let (integrator, _) = model.simulation(method, None);
        let settings = Settings { integrator, dt, duration, sample: dt };
        simulate(&system, &x0, &mut Constant(vec![]), &settings).unwrap()
    };
    let close = |got: &[f64], want: &[f64], rel: f64, what: &str| {
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() <= rel * w.abs(), "{what}: {got:?} vs {want:?}");
        }
    };
    // a ten-thousandth of b's size: the absolute tolerance a model of small numbers sets
    let file = robertson("1e-10");
    let reference = [0.7158270687, 9.185534764e-6, 0.2841637457];
    let by_default = run(&file, None, (1.0, 40.0));
    close(&by_default.last_state(), &reference, 2e-5, "Robertson at 40 s, dopri5");
    let switched = by_default.stiff_from.expect("dopri5 finds Robertson stiff");
    assert!(switched < 1.0, "{switched}");
    let implicit = run(&file, Some(Integrator::Rosenbrock), (1.0, 40.0));
    close(&implicit.last_state(), &reference, 2e-5, "Robertson at 40 s, rosenbrock");
    assert_eq!(implicit.stiff_from, None, "asked for: nothing to say");
    let long = robertson("1e-14");
    let end = run(&long, None, (1e8, 1e11)).last_state();
    close(&end[..2], &[2.0833401e-8, 8.3333608e-14], 1e-3, "Robertson at 1e11 s");
    // van der Pol through the command line: its period from the zero crossings, and the note
    let dir = crate::common::Scratch::new("stiff");
    let model = dir.join("vdp.toml");
    std::fs::write(
        &model,
        "[model]\nname = \"van der Pol\"\nintercept = false\n[parameters.mu]\nvalue = 1000.0\n\
         [[states]]\nname = \"x\"\ninitial = 2.0\n[[states]]\nname = \"y\"\n\
         [equations.x_dot]\nstate = \"x\"\ncoefficients = { \"y\" = 1.0 }\n\
         [equations.y_dot]\nstate = \"y\"\ncoefficients = { \"mu*y\" = 1.0, \"mu*x^2*y\" = -1.0, \"x\" = -1.0 }\n",
    )
    .unwrap();
    let csv = dir.join("vdp.csv");
    let (ok, out, err) = termid(&[
        "simulate",
        "--model",
        model.to_str().unwrap(),
        "--duration",
        "5000",
        "--dt",
        "0.05",
        "--sample",
        "0.05",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("note: the model is stiff from t ="), "{out}");
    let rows: Vec<(f64, f64)> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<f64> = l.split(',').take(2).map(|v| v.parse().unwrap()).collect();
            (c[0], c[1])
        })
        .collect();
    let downward: Vec<f64> = rows
        .windows(2)
        .filter(|w| w[0].1 > 0.0 && w[1].1 <= 0.0)
        .map(|w| w[0].0 + (w[1].0 - w[0].0) * w[0].1 / (w[0].1 - w[1].1))
        .collect();
    assert!(downward.len() >= 3, "{downward:?}");
    for period in downward.windows(2).map(|w| w[1] - w[0]) {
        assert!((period - 1614.41).abs() < 0.2, "period {period} s: {downward:?}");
    }
}

/// Output error on a stiff model, right by default: Robertson's rate constant k1 estimated
/// from a run sampled every 0.5 s, where RK4 at the samples' interval (|λ| up to 4200 /s,
/// h·|λ| = 2100) diverged whatever k1 was; the runs are now re-simulated at a whole fraction of
/// the interval where RK4 is stable, and that is said. A step the user gives is kept, and its
/// failure names the stiffness and the step that would do.
#[test]
fn a_stiff_model_is_estimated_by_output_error() {
    let dir = crate::common::Scratch::new("stiff-estimate");
    // k1 free, from the file's value or 0.06
    let text = |k1: &str| robertson("1e-10").replace("value = 0.04", &format!("value = {k1}\nfree = true"));
    let (truth, start) = (dir.join("truth.toml"), dir.join("start.toml"));
    std::fs::write(&truth, text("0.04")).unwrap();
    std::fs::write(&start, text("0.06")).unwrap();
    let csv = dir.join("run.csv");
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        truth.to_str().unwrap(),
        "--duration",
        "100",
        "--dt",
        "0.5",
        "--sample",
        "0.5",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, out, err) = termid(&[
        "estimate",
        "--model",
        start.to_str().unwrap(),
        "--data",
        csv.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    // the note beside the report: standard output one JSON document
    assert!(err.contains("note: the model is stiff against the runs' step"), "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}"));
    let estimate = json["parameters"]
        .as_array()
        .and_then(|p| p.iter().find(|p| p["name"] == "k1"))
        .and_then(|p| p["value"].as_f64())
        .unwrap_or_else(|| panic!("{json}"));
    assert!((estimate - 0.04).abs() < 1e-5, "k1 = {estimate}");
    let (ok, _, err) = termid(&[
        "estimate",
        "--model",
        start.to_str().unwrap(),
        "--data",
        csv.to_str().unwrap(),
        "--dt",
        "0.5",
    ]);
    assert!(!ok);
    assert!(err.contains("the model is stiff at this step") && err.contains("|λ| = 4"), "{err}");
}

/// `--rtol` and `--atol` set the adaptive method's tolerances for one command: the pendulum at
/// 1e-11 / 1e-12 ends on scipy's DOP853 at 1e-13 within 1e-8; tolerances no step control works
/// with are refused by name.
#[test]
fn tolerances_from_the_command_line() {
    let dir = crate::common::Scratch::new("tolerances");
    let path = dir.join("pendulum.toml");
    std::fs::write(&path, PENDULUM).unwrap();
    let model = path.to_str().unwrap();
    let base = ["simulate", "--model", model, "--duration", "20", "--format", "json"];
    let (ok, out, err) = termid(&[&base[..], &["--rtol", "1e-11", "--atol", "1e-12"]].concat());
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for (state, want) in [("theta", 0.004258497545507634), ("omega", 0.014630331091916731)] {
        let got = v["final_state"][state].as_f64().unwrap();
        assert!((got - want).abs() < 1e-8, "{state}: {got} vs {want}");
    }
    for bad in [["--rtol", "2"], ["--atol", "-1"], ["--rtol", "nan"]] {
        let (ok, _, err) = termid(&[&base[..], &bad[..]].concat());
        assert!(!ok && err.contains("rtol lies in (0, 1) and atol ≥ 0"), "{bad:?}: {err}");
    }
}

/// Right by default (issue 25 §3): Lorenz from a CSV of t, x, y, z only, every monomial to
/// degree 3 as candidates, nothing else given: each equation's terms exactly and its
/// coefficients within 1 % (the paper's defaults gave dz/dt = −55.9 + 0.689 y²). Rescaling a
/// variable (x in mm) changes the coefficients by the factor and the selection not at all.
#[test]
fn lorenz_from_samples_with_the_defaults_and_unit_free_selection() {
    let dir = crate::common::Scratch::new("lorenz-defaults");
    let full = dir.join("full.csv");
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        "models/lorenz.toml",
        "--duration",
        "20",
        "--dt",
        "0.01",
        "--sample",
        "0.01",
        "--out",
        full.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&full).unwrap();
    let states_only = |scale_x: f64| -> String {
        text.lines()
            .enumerate()
            .map(|(k, l)| {
                let c: Vec<&str> = l.split(',').take(4).collect();
                if k == 0 {
                    c.join(",")
                } else {
                    let x: f64 = c[1].parse().unwrap();
                    format!("{},{:?},{},{}", c[0], x * scale_x, c[2], c[3])
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
            + "\n"
    };
    let terms = dir.join("terms.txt");
    std::fs::write(&terms, cubic_library(&["x", "y", "z"])).unwrap();
    let truth: [(&str, &[(&str, f64)]); 3] = [
        ("x", &[("x", -10.0), ("y", 10.0)]),
        ("y", &[("x", 28.0), ("y", -1.0), ("x*z", -1.0)]),
        ("z", &[("x*y", 1.0), ("z", -8.0 / 3.0)]),
    ];
    // and with 1 % Gaussian noise on every state (deterministic): the same terms, each
    // coefficient within 3 % (the paper's defaults and central differences: a dozen spurious
    // terms in x's equation)
    let noisy = {
        let clean = states_only(1.0);
        let mut lines = clean.lines();
        let header = lines.next().unwrap().to_string();
        let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|c| c.parse().unwrap()).collect()).collect();
        let sd: Vec<f64> = (1..4)
            .map(|j| {
                let m = rows.iter().map(|r| r[j]).sum::<f64>() / rows.len() as f64;
                (rows.iter().map(|r| (r[j] - m).powi(2)).sum::<f64>() / rows.len() as f64).sqrt()
            })
            .collect();
        let mut g = crate::common::Lcg(7);
        let body: Vec<String> = rows
            .iter()
            .map(|r| {
                let mut c = vec![format!("{:?}", r[0])];
                c.extend((1..4).map(|j| format!("{:?}", r[j] + 0.01 * sd[j - 1] * g.normal())));
                c.join(",")
            })
            .collect();
        format!("{header}\n{}\n", body.join("\n"))
    };
    for (scale, file, tolerance) in
        [(1.0, "xyz.csv", 1e-5), (1000.0, "xyz_mm.csv", 1e-5), (1.0, "xyz_noisy.csv", 0.03)]
    {
        let csv = dir.join(file);
        std::fs::write(&csv, if file.contains("noisy") { noisy.clone() } else { states_only(scale) })
            .unwrap();
        for (state, expected) in truth {
            let target = format!("d{state}/dt");
            let found = identify_with_defaults(&csv, &target, &terms);
            assert_eq!(found.len(), expected.len(), "{file} {state}: {found:?}");
            for (term, c) in expected {
                // x in mm: a term's coefficient scales by 1000^(power of x in the target) / 1000^(power in the term)
                let px = term.matches('x').count() as i32;
                let pt = if state == "x" { 1 } else { 0 };
                let want = c * scale.powi(pt - px);
                let got = *found.get(*term).unwrap_or_else(|| panic!("{state}: {term} missing: {found:?}"));
                assert!(
                    (got - want).abs() < tolerance * want.abs(),
                    "{file} {state} {term}: {got} vs {want}"
                );
            }
        }
    }
}

/// Lorenz simulated by `termid simulate` at 1 ms and sampled every `sample` s: its rows
/// (t, x, y, z), the rates left out.
fn lorenz_rows(dir: &std::path::Path, sample: &str) -> Vec<Vec<f64>> {
    let full = dir.join(format!("full{sample}.csv"));
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        "models/lorenz.toml",
        "--duration",
        "20",
        "--dt",
        "0.001",
        "--sample",
        sample,
        "--out",
        full.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    std::fs::read_to_string(&full)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').take(4).map(|c| c.parse().unwrap()).collect())
        .collect()
}

/// `termid identify` of `target` in `data` with the candidates of `terms` and `extra`
/// options: what it prints.
fn identify_text(data: &std::path::Path, target: &str, terms: &std::path::Path, extra: &[&str]) -> String {
    let mut args = vec![
        "identify",
        "--data",
        data.to_str().unwrap(),
        "--target",
        target,
        "--terms-file",
        terms.to_str().unwrap(),
    ];
    args.extend(extra);
    let (ok, out, err) = termid(&args);
    assert!(ok, "{err}");
    out
}

/// The library of every monomial of x, y, z to degree 2, the constant among them.
const LORENZ_QUADRATIC: &str = "1\nx\ny\nz\nx*x\nx*y\nx*z\ny*y\ny*z\nz*z\n";

/// Right by default away from the origin and off a regular clock (what a logger writes):
/// Lorenz sampled from a 1 ms simulation (the truth below) with z measured from 10 000
/// below its zero (a temperature in kelvin, a pressure in pascal) and, in a second file, at
/// uneven intervals of 2 to 18 ms. With z far from 0 against its spread, 1, z and z² are
/// collinear to round-off and x, x·z nearly so: the threshold path used to drop the true terms
/// with the collinear ones and print an empty equation; now a collinear candidate is left out
/// with a note, dz/dt and dy/dt come out with their true terms, and every equation whose chosen
/// terms trade against each other says so and names `z`. Written about a reference value
/// (`x*(z - 10000)`), the library is well posed again. On the uneven clock the trapezoid's
/// error (smooth in the states) bought spurious terms in x's and z's equations; the quadratic
/// through each pair of intervals keeps exactly the true terms.
#[test]
fn lorenz_far_from_the_origin_and_on_an_uneven_clock() {
    let dir = crate::common::Scratch::new("lorenz-offset");
    let rows = lorenz_rows(&dir, "0.001");
    let write = |name: &str, picked: &mut dyn Iterator<Item = &Vec<f64>>, z0: f64| {
        let body: Vec<String> =
            picked.map(|r| format!("{:?},{:?},{:?},{:?}", r[0], r[1], r[2], r[3] + z0)).collect();
        let path = dir.join(name);
        std::fs::write(&path, format!("t,x,y,z\n{}\n", body.join("\n"))).unwrap();
        path
    };
    let offset = write("offset.csv", &mut rows.iter().step_by(10), 1e4);
    let mut g = crate::common::Lcg(3);
    let mut next = 0usize;
    let uneven_rows: Vec<&Vec<f64>> = rows
        .iter()
        .enumerate()
        .filter(|(k, _)| {
            let keep = *k == next;
            if keep {
                next += 2 + (g.next() * 17.0) as usize;
            }
            keep
        })
        .map(|(_, r)| r)
        .collect();
    let uneven = write("uneven.csv", &mut uneven_rows.into_iter(), 0.0);
    let terms = dir.join("terms.txt");
    std::fs::write(&terms, LORENZ_QUADRATIC).unwrap();
    let same = |found: &BTreeMap<String, f64>, want: &[(&str, f64)], tolerance: f64, what: &str| {
        let names: Vec<&str> = found.keys().map(String::as_str).collect();
        let mut wanted: Vec<&str> = want.iter().map(|w| w.0).collect();
        wanted.sort();
        assert_eq!(names, wanted, "{what}: {found:?}");
        for (term, c) in want {
            let got = found[*term];
            assert!((got - c).abs() <= tolerance * c.abs(), "{what} {term}: {got} vs {c}");
        }
    };
    // in the offset z: dy/dt = (28 + 10⁴)·x − y − x·z, dz/dt = x·y − 8/3·z + 8/3·10⁴
    same(
        &identify_with_defaults(&offset, "dy/dt", &terms),
        &[("x", 10028.0), ("y", -1.0), ("x*z", -1.0)],
        1e-3,
        "dy/dt, z offset",
    );
    same(
        &identify_with_defaults(&offset, "dz/dt", &terms),
        &[("1", 8e4 / 3.0), ("z", -8.0 / 3.0), ("x*y", 1.0)],
        1e-3,
        "dz/dt, z offset",
    );
    for target in ["dx/dt", "dy/dt", "dz/dt"] {
        let out = identify_text(&offset, target, &terms, &[]);
        assert!(out.contains("`z^2` left out of the candidates: collinear"), "{target}: {out}");
        // dx/dt = 10(y − x) chooses no term of z's
        if target != "dx/dt" {
            assert!(
                out.contains("nearly a combination of the other chosen terms")
                    && out.contains("Far from 0 against their spread: `z`"),
                "{target}: {out}"
            );
        }
    }
    let about = dir.join("about.txt");
    std::fs::write(
        &about,
        "1\nx\ny\nz - 10000\nx*x\nx*y\nx*(z - 10000)\ny*y\ny*(z - 10000)\n(z - 10000)^2\n",
    )
    .unwrap();
    same(
        &identify_with_defaults(&offset, "dx/dt", &about),
        &[("x", -10.0), ("y", 10.0)],
        1e-3,
        "dx/dt about 10⁴",
    );
    let out = identify_text(&offset, "dy/dt", &about, &[]);
    // a candidate that is a sum prints in parentheses after its coefficient
    assert!(out.contains("*(-10000*x + x*z)"), "{out}");
    assert!(!out.contains("nearly a combination"), "{out}");
    let truth: [(&str, &[(&str, f64)]); 3] = [
        ("dx/dt", &[("x", -10.0), ("y", 10.0)]),
        ("dy/dt", &[("x", 28.0), ("y", -1.0), ("x*z", -1.0)]),
        ("dz/dt", &[("x*y", 1.0), ("z", -8.0 / 3.0)]),
    ];
    for (target, want) in truth {
        same(
            &identify_with_defaults(&uneven, target, &terms),
            want,
            0.01,
            &format!("{target}, uneven clock"),
        );
    }
}

/// Right or it says so: Lorenz sampled every 60 ms (12.5 samples in z's characteristic
/// period) keeps spurious terms in dz/dt with coefficients 15 % off, which nothing else in the
/// fit shows; the note says the rows sample z coarsely. Every 20 ms (34 samples) the fit is
/// right and no note is printed.
#[test]
fn coarse_samples_are_said() {
    let dir = crate::common::Scratch::new("lorenz-coarse");
    let terms = dir.join("terms.txt");
    std::fs::write(&terms, LORENZ_QUADRATIC).unwrap();
    for (sample, coarse) in [("0.06", true), ("0.02", false)] {
        let states: Vec<String> = std::iter::once("t,x,y,z".to_string())
            .chain(
                lorenz_rows(&dir, sample)
                    .iter()
                    .map(|r| format!("{:?},{:?},{:?},{:?}", r[0], r[1], r[2], r[3])),
            )
            .collect();
        let csv = dir.join(format!("xyz{sample}.csv"));
        std::fs::write(&csv, states.join("\n") + "\n").unwrap();
        let out = identify_text(&csv, "dz/dt", &terms, &[]);
        assert_eq!(out.contains("the rows sample `z` coarsely"), coarse, "every {sample} s: {out}");
    }
}

/// Right or it says so, where the rows cannot choose: with 5 % noise on Lorenz's states
/// (deterministic), in the integral form `y` and `y*z` explain dy/dt within the noise of each
/// other (z's mean is 2.8 times its spread), and which one a back-end keeps is the noise's;
/// the fit names the pair. On the clean rows every chosen term is far ahead of its rival and
/// nothing is said (Hald's cement through the command line: `cli::hald_x4_could_as_well_be_x2`).
/// The default, the weak form, averages the noise over its windows and chooses Lorenz's own
/// terms for dy/dt = 28x − y − xz.
#[test]
fn a_choice_the_noise_made_is_said() {
    let dir = crate::common::Scratch::new("lorenz-rivals");
    let terms = dir.join("terms.txt");
    std::fs::write(&terms, LORENZ_QUADRATIC).unwrap();
    let rows: Vec<Vec<f64>> = lorenz_rows(&dir, "0.01");
    let sd: Vec<f64> = (1..4)
        .map(|j| {
            let m = rows.iter().map(|r| r[j]).sum::<f64>() / rows.len() as f64;
            (rows.iter().map(|r| (r[j] - m).powi(2)).sum::<f64>() / rows.len() as f64).sqrt()
        })
        .collect();
    let mut g = crate::common::Lcg(11);
    for (name, noise) in [("clean.csv", 0.0), ("noisy.csv", 0.05)] {
        let body: Vec<String> = rows
            .iter()
            .map(|r| {
                let mut c = vec![format!("{:?}", r[0])];
                c.extend((1..4).map(|j| format!("{:?}", r[j] + noise * sd[j - 1] * g.normal())));
                c.join(",")
            })
            .collect();
        let csv = dir.join(name);
        std::fs::write(&csv, format!("t,x,y,z\n{}\n", body.join("\n"))).unwrap();
        for target in ["dx/dt", "dy/dt", "dz/dt"] {
            let out = identify_text(&csv, target, &terms, &["--derivative", "integral"]);
            let said = out.contains("the rows hardly tell");
            if noise == 0.0 {
                assert!(!said, "{name} {target}: {out}");
            } else if target == "dy/dt" {
                assert!(out.contains("`y` from `y*z`") || out.contains("`y*z` from `y`"), "{out}");
            }
        }
    }
    let found = identify_with_defaults(&dir.join("noisy.csv"), "dy/dt", &terms);
    let names: Vec<&str> = found.keys().map(String::as_str).collect();
    assert_eq!(names, ["x", "x*z", "y"], "{found:?}");
    assert!((found["x"] - 28.0).abs() < 0.6 && (found["x*z"] + 1.0).abs() < 0.02, "{found:?}");
}

/// Honest uncertainty (issue 25 §4): when most Monte-Carlo draws fail, no mean, sd or band is
/// printed or drawn as if it described the model; what failed is said, and what helps.
#[test]
fn monte_carlo_that_mostly_fails_shows_no_spread() {
    let dir = crate::common::Scratch::new("mc-fails");
    let csv = dir.join("l5.csv");
    let id = dir.join("lid.toml");
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        "models/lorenz.toml",
        "--duration",
        "5",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, _, err) = termid(&[
        "identify",
        "--model",
        "models/lorenz.toml",
        "--data",
        csv.to_str().unwrap(),
        "--out",
        id.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    // a covariance far too wide (standard deviations of 10 on every coefficient): the draws
    // leave the states' bounds
    let mut v: toml::Value = toml::from_str(&std::fs::read_to_string(&id).unwrap()).unwrap();
    for (_, eq) in v["equations"].as_table_mut().unwrap().iter_mut() {
        if let Some(rows) =
            eq.get_mut("covariance").and_then(|c| c.get_mut("matrix")).and_then(|m| m.as_array_mut())
        {
            for (i, row) in rows.iter_mut().enumerate() {
                for (j, x) in row.as_array_mut().unwrap().iter_mut().enumerate() {
                    *x = toml::Value::Float(if i == j { 100.0 } else { 0.0 });
                }
            }
        }
    }
    let wide = dir.join("wide.toml");
    std::fs::write(&wide, toml::to_string(&v).unwrap()).unwrap();
    let svg = dir.join("mc.svg");
    let args = [
        "simulate",
        "--model",
        wide.to_str().unwrap(),
        "--duration",
        "5",
        "--monte-carlo",
        "40",
        "--svg",
        svg.to_str().unwrap(),
    ];
    let (ok, out, err) = termid(&args);
    assert!(ok, "{err}");
    assert!(out.contains("no mean, sd or band") && out.contains("covariance is too wide"), "{out}");
    assert!(!out.contains("5 % …"), "{out}");
    assert!(!std::fs::read_to_string(&svg).unwrap().contains("90 % band"));
    let (ok, out, err) = termid(&[&args[..7], &["--format", "json"]].concat());
    assert!(ok, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["monte_carlo"]["usable"], false, "{out}");
    assert!(j["monte_carlo"]["spread"].is_null(), "{out}");
    // the identified covariance as it is: every draw runs, and the band is shown
    let (ok, out, err) =
        termid(&["simulate", "--model", id.to_str().unwrap(), "--duration", "5", "--monte-carlo", "20"]);
    assert!(ok, "{err}");
    assert!(out.contains("0 failed") && out.contains("5 % …"), "{out}");
}

/// Every monomial of `states` to degree 3, the constant first, one per line.
fn cubic_library(states: &[&str]) -> String {
    let mut out = vec!["1".to_string()];
    for a in 0..states.len() {
        out.push(states[a].to_string());
        for b in a..states.len() {
            out.push(format!("{}*{}", states[a], states[b]));
            for c in b..states.len() {
                out.push(format!("{}*{}*{}", states[a], states[b], states[c]));
            }
        }
    }
    out.join("\n") + "\n"
}

/// `termid identify` of `target` in the run `data` with the candidates of `terms` and
/// nothing else: the terms and coefficients it reports, the intercept as `1`.
fn identify_with_defaults(
    data: &std::path::Path,
    target: &str,
    terms: &std::path::Path,
) -> BTreeMap<String, f64> {
    let json = identify_text(data, target, terms, &["--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let mut out = terms_of(&v);
    if let Some(b0) = v["intercept"].as_f64() {
        out.insert("1".into(), b0);
    }
    out
}

/// The chosen terms and their coefficients of an `identify --format json` report.
fn terms_of(report: &serde_json::Value) -> BTreeMap<String, f64> {
    report["terms"]
        .as_array()
        .unwrap_or_else(|| panic!("{report}"))
        .iter()
        .map(|t| (t["term"].as_str().unwrap().to_string(), t["coefficient"].as_f64().unwrap()))
        .collect()
}

/// Right by default on a small true term (issue 25 §3, §5): Rössler's dz/dt = 0.2 + x·z − 5.7 z,
/// whose constant explains 0.05 % of the rate's variance. A fixed threshold on standardised
/// coefficients dropped it (and stepwise on exact rates kept terms fitted to round-off); the
/// threshold path chosen by BIC keeps it, from the exact rates (a column `z_dot`, an
/// equation of motion like `dz/dt`) within 0.1 % and from the samples alone within 1 %.
#[test]
fn a_small_true_term_is_kept_from_exact_rates_and_from_samples() {
    let dir = crate::common::Scratch::new("rossler-small-term");
    let run = dir.join("rossler.csv");
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        "benches/odes/systems/rossler.toml",
        "--duration",
        "216",
        "--dt",
        "0.05",
        "--sample",
        "0.05",
        "--out",
        run.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let terms = dir.join("cubic.txt");
    std::fs::write(&terms, cubic_library(&["x", "y", "z"])).unwrap();
    let truth: [(&str, &[(&str, f64)]); 3] = [
        ("x", &[("y", -1.0), ("z", -1.0)]),
        ("y", &[("x", 1.0), ("y", 0.2)]),
        ("z", &[("1", 0.2), ("x*z", 1.0), ("z", -5.7)]),
    ];
    for (state, expected) in truth {
        for (target, tolerance) in [(format!("{state}_dot"), 1e-3), (format!("d{state}/dt"), 1e-2)] {
            let found = identify_with_defaults(&run, &target, &terms);
            let names: Vec<&str> = found.keys().map(String::as_str).collect();
            let mut want: Vec<&str> = expected.iter().map(|(t, _)| *t).collect();
            want.sort();
            assert_eq!(names, want, "{target}: {found:?}");
            for (term, c) in expected {
                assert!(
                    (found[*term] - c).abs() <= tolerance * c.abs(),
                    "{target} {term}: {} vs {c}",
                    found[*term]
                );
            }
        }
    }
}

/// The ODE benchmark's systems (benches/odes/systems) are model files termid reads and
/// simulates: each loads, names its provenance, and runs a second without leaving its bounds.
#[test]
fn the_benchmark_systems_are_model_files_termid_simulates() {
    let mut count = 0;
    for entry in std::fs::read_dir("benches/odes/systems").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let model = Model::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(!model.spec().model.provenance.is_empty(), "{}: no provenance", path.display());
        let system = System::new(&model, &BTreeMap::new(), false)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let settings = Settings { integrator: Integrator::Dopri5, dt: 0.01, duration: 1.0, sample: 0.01 };
        let x0: Vec<f64> = model.spec().states.iter().map(|s| s.initial).collect();
        let run = simulate(&system, &x0, &mut Constant(vec![]), &settings)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(run.time.len(), 101, "{}", path.display());
        count += 1;
    }
    assert!(count >= 25, "{count} systems");
}

/// The adaptive method's output interval is free: 0.05 s beside the default control step of
/// 0.04 s is sampled at 0.05 s (a step of 0.025 s for the inputs), not refused; a fixed-step
/// method is still refused, with a step that would do.
#[test]
fn any_output_interval_for_the_adaptive_method() {
    let dir = crate::common::Scratch::new("sample-interval");
    let out = dir.join("l.csv");
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        "models/lorenz.toml",
        "--duration",
        "1",
        "--sample",
        "0.05",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    let times: Vec<f64> =
        text.lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect();
    assert_eq!(times.len(), 21);
    assert!(times.iter().enumerate().all(|(k, t)| (t - 0.05 * k as f64).abs() < 1e-12), "{times:?}");
    crate::hostile::refused(
        &[
            "simulate",
            "--model",
            "models/lorenz.toml",
            "--integrator",
            "rk4",
            "--duration",
            "1",
            "--sample",
            "0.05",
        ],
        &["not a whole multiple", "--dt 0.025"],
    );
}

/// A glitch is not a motion: Lorenz sampled every 10 ms with one sample of x 30 off and two
/// of z 15 off (a corrupted telegram). Read as recorded, dx/dt takes spurious terms for the
/// glitch; by default each spike is replaced by the line through its neighbours and said
/// with its rows, and every equation has its true terms and coefficients again, from the
/// plain runs and through the model file alike.
#[test]
fn a_glitch_in_a_record_is_mended_and_said() {
    let dir = crate::common::Scratch::new("lorenz-spike");
    let terms = dir.join("terms.txt");
    std::fs::write(&terms, LORENZ_QUADRATIC).unwrap();
    let mut rows = lorenz_rows(&dir, "0.01");
    rows[700][1] += 30.0;
    rows[1200][3] -= 15.0;
    rows[1201][3] -= 15.0;
    let body: Vec<String> =
        rows.iter().map(|r| r.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(",")).collect();
    let csv = dir.join("spiked.csv");
    std::fs::write(&csv, format!("t,x,y,z\n{}\n", body.join("\n"))).unwrap();
    let truth: [(&str, &[(&str, f64)]); 3] = [
        ("dx/dt", &[("x", -10.0), ("y", 10.0)]),
        ("dy/dt", &[("x", 28.0), ("y", -1.0), ("x*z", -1.0)]),
        ("dz/dt", &[("x*y", 1.0), ("z", -8.0 / 3.0)]),
    ];
    let said = |err: &str| {
        // the heights are from the line through the neighbours, which Lorenz's curvature bends
        err.contains("`x` leaps away and straight back by 29.99 at row 701 (t = 7.000)")
            && err.contains("`z` leaps away and straight back by 14.90 at rows 1201-1202 (t = 12.00)")
    };
    for (target, expected) in truth {
        let args = ["identify", "--data", csv.to_str().unwrap(), "--target", target, "--terms-file"];
        let (ok, out, err) = termid(&[&args[..], &[terms.to_str().unwrap(), "--format", "json"]].concat());
        assert!(ok && said(&err), "{err}");
        let found = terms_of(&crate::common::json(&out));
        assert_eq!(found.len(), expected.len(), "{target}: {found:?}");
        for (term, c) in expected {
            assert!((found[*term] - c).abs() < 1e-3 * c.abs(), "{target} {term}: {found:?}");
        }
        if target == "dx/dt" {
            let (ok, out, err) = termid(
                &[&args[..], &[terms.to_str().unwrap(), "--format", "json", "--keep-spikes"]].concat(),
            );
            assert!(ok && !err.contains("leaps"), "{err}");
            let kept = terms_of(&crate::common::json(&out)).len();
            assert!(kept > 2, "as recorded, the glitch buys terms: {out}");
        }
    }
    // a model reads its runs the same way
    let out = dir.join("lorenz_id.toml");
    let (ok, _, err) = termid(&[
        "identify",
        "--model",
        "models/lorenz.toml",
        "--data",
        csv.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok && said(&err), "{err}");
    let m = Model::load(&out).unwrap();
    for (target, expected) in truth {
        let eq = m.equation(&format!("{}_dot", &target[1..2])).unwrap();
        assert_eq!(eq.coefficients.len(), expected.len(), "{target}: {:?}", eq.coefficients);
        for (term, c) in expected {
            let got = eq.coefficients.iter().find(|(t, _, _)| t.to_string() == *term).map(|(_, v, _)| *v);
            assert!(
                got.is_some_and(|g| (g - c).abs() < 1e-3 * c.abs()),
                "{target} {term}: {:?}",
                eq.coefficients
            );
        }
    }
}

/// What the residuals of the integral form say is said of its own rows (its windows), not of
/// the samples: white noise on x = 3·e^(−t/2) differenced over windows leaves residuals
/// correlated at no lag but the window's own (where ρ = −½), so τ ≈ 1 (it was taken of the
/// state minus its rate, the state's own correlation: dozens of rows). And residuals that
/// grow with the rate, as a 1 % error on x = e^(t/2) over 30 s makes them (a dynamic range
/// of 3·10⁶), are said, with the remedy: rows weighted by 1/x², which the integral form now
/// takes (a window weighing as its rows on average), give the growth rate 0.5 within 1 %.
#[test]
fn the_integral_forms_residuals_are_its_windows() {
    let dir = crate::common::Scratch::new("integral-residuals");
    let terms = dir.join("terms.txt");
    std::fs::write(&terms, "1\nx\nx^2\n").unwrap();
    let mut g = crate::common::Lcg(5);
    let write = |name: &str, rows: &[(f64, f64, f64)]| {
        let path = dir.join(name);
        let body: Vec<String> = rows.iter().map(|(t, x, w)| format!("{t:?},{x:?},{w:?}")).collect();
        std::fs::write(&path, format!("t,x,w\n{}\n", body.join("\n"))).unwrap();
        path
    };
    let decay: Vec<(f64, f64, f64)> = (0..1000)
        .map(|k| {
            let t = 0.01 * k as f64;
            (t, 3.0 * (-0.5 * t).exp() + 0.03 * g.normal(), 1.0)
        })
        .collect();
    let fit = |path: &std::path::Path, extra: &[&str]| {
        let args = ["identify", "--data", path.to_str().unwrap(), "--target", "dx/dt", "--terms-file"];
        let (ok, out, err) =
            termid(&[&args[..], &[terms.to_str().unwrap(), "--format", "json"], extra].concat());
        assert!(ok, "{err}");
        crate::common::json(&out)
    };
    let v = fit(&write("decay.csv", &decay), &[]);
    let tau = v["correlation_time"].as_f64().unwrap();
    assert!((1.0..1.5).contains(&tau), "τ = {tau}: {v}");
    let growth: Vec<(f64, f64, f64)> = (0..300)
        .map(|k| {
            let t = 0.1 * k as f64;
            let x = (0.5 * t).exp() * (1.0 + 0.01 * g.normal());
            (t, x, 1.0 / (x * x))
        })
        .collect();
    let path = write("growth.csv", &growth);
    let said = |v: &serde_json::Value| {
        v["notes"]
            .as_array()
            .unwrap()
            .iter()
            .any(|n| n.as_str().unwrap().contains("the residuals grow with the size of `dx/dt`"))
    };
    let plain = fit(&path, &[]);
    assert!(said(&plain), "{plain}");
    let weighted = fit(&path, &["--weight", "w"]);
    let terms = terms_of(&weighted);
    assert!(terms.len() == 1 && terms.get("x").is_some_and(|c| (c - 0.5).abs() < 0.005), "{weighted}");
    assert!(!said(&weighted), "{weighted}");
    // noise of one size everywhere: nothing to say
    assert!(!said(&v), "{v}");
}

/// A forced oscillator's model file: ẋ = v given, v̇ from the candidates x, v, F, x², x³; no intercept.
const FORCED_OSCILLATOR: &str = "[model]\nname = \"forced oscillator\"\nintercept = false\n\
    [[states]]\nname = \"x\"\n[[states]]\nname = \"v\"\n[[inputs]]\nname = \"F\"\n\
    [equations.x_dot]\nstate = \"x\"\nidentify = false\ncoefficients = { \"v\" = 1.0 }\n\
    [equations.v_dot]\nstate = \"v\"\ncandidates = [\"x\", \"v\", \"F\", \"x^2\", \"x^3\"]\n";

/// A model file that names no back-end takes the one an equation of motion takes on the
/// command line and in Python (sequential thresholding), not the paper's stepwise regression:
/// a forced oscillator ẍ = −4x − 0.2ẋ + F sampled with 2 % noise keeps its damping, where the
/// first F maximum stopped after x and F (x −3.85, F 0.898: the damping's share of the
/// variance is under the noise's).
#[test]
fn a_model_file_without_a_backend_keeps_every_true_term() {
    use crate::common::{json, noise, noisy_frame, trajectory, Lcg, Scratch};
    let dir = Scratch::new("generic-default-backend");
    let force = |t: f64| 2.0 * (0.6 * t).sin() + 1.5 * (1.7 * t + 1.0).sin();
    let rows: Vec<Vec<f64>> =
        trajectory(&[1.0, 0.0], 0.01, 10_000, 10, |t, x| vec![x[1], -4.0 * x[0] - 0.2 * x[1] + force(t)])
            .into_iter()
            .enumerate()
            .map(|(i, mut r)| {
                r.push(force(i as f64 * 0.01));
                r
            })
            .collect();
    let mut sd = noise(&rows, 0.02);
    sd[2] = 0.0;
    let run = noisy_frame("run.csv", 0.01, &["x", "v", "F"], &rows, &sd, &mut Lcg(7));
    run.write_csv(&dir.join("run.csv")).unwrap();
    std::fs::write(dir.join("m.toml"), FORCED_OSCILLATOR).unwrap();
    let p = |f: &str| dir.join(f).display().to_string();
    let (ok, out, err) =
        termid(&["identify", "--model", &p("m.toml"), "--data", &p("run.csv"), "--format", "json"]);
    assert!(ok, "{err}");
    let fit = &json(&out)["v_dot"];
    assert_eq!(fit["backend"], "stlsq", "{out}");
    let found = crate::common::chosen_terms(fit);
    let truth = [("F", 1.0), ("v", -0.2), ("x", -4.0)];
    assert_eq!(found.iter().map(|f| f.0.as_str()).collect::<Vec<_>>(), truth.map(|t| t.0), "{out}");
    for ((_, got), (name, want)) in found.iter().zip(truth) {
        assert!((got / want - 1.0).abs() < 0.01, "{name}: {got} vs {want}");
    }
}

/// A file of several runs (a long table, as a data-frame library writes it) is refused whole
/// where its time starts again, the refusal naming its label column; `--by` reads each
/// label's rows as a run of its own, whether the runs follow one another or are interleaved
/// row by row: three runs of ẍ = −4x − 0.3ẋ + 2F give the oscillator back exactly either way.
#[test]
fn a_long_file_of_several_runs_is_read_by_its_label() {
    use crate::common::{chosen_terms, json, trajectory, Scratch};
    let dir = Scratch::new("generic-long");
    let force = |t: f64| (0.9 * t).sin() + 0.5 * (2.1 * t).cos();
    let (h, n) = (0.01, 1500);
    let runs: Vec<Vec<Vec<f64>>> = [[1.0, 0.0], [-2.0, 1.0], [0.5, -3.0]]
        .iter()
        .map(|x0| trajectory(x0, h, n, 10, |t, x| vec![x[1], -4.0 * x[0] - 0.3 * x[1] + 2.0 * force(t)]))
        .collect();
    let line = |i: usize, x: &[f64]| format!("{},{},{},{}", i as f64 * h, x[0], x[1], force(i as f64 * h));
    let mut after = String::from("run,t,x,v,F\n");
    for (k, run) in runs.iter().enumerate() {
        for (i, x) in run.iter().enumerate() {
            after += &format!("zz{k},{}\n", line(i, x));
        }
    }
    let mut interleaved = String::from("t,x,v,F,vessel\n");
    for i in 0..n {
        for (k, run) in runs.iter().enumerate() {
            interleaved += &format!("{},{}\n", line(i, &run[i]), k + 1);
        }
    }
    std::fs::write(dir.join("after.csv"), after).unwrap();
    std::fs::write(dir.join("interleaved.csv"), interleaved).unwrap();
    std::fs::write(dir.join("m.toml"), FORCED_OSCILLATOR).unwrap();
    let p = |f: &str| dir.join(f).display().to_string();
    let model = p("m.toml");
    let identify = |data: &str, by: &[&str]| {
        let mut args = vec!["identify", "--model", &model, "--format", "json", "--data", data];
        args.extend_from_slice(by);
        termid(&args)
    };
    let (ok, _, err) = identify(&p("after.csv"), &[]);
    assert!(!ok && err.contains("row 1501, column `t`") && err.contains("`--by run`"), "{err}");
    for (file, by) in [("after.csv", "run"), ("interleaved.csv", "vessel")] {
        let (ok, out, err) = identify(&p(file), &["--by", by]);
        assert!(ok, "{err}");
        assert!(err.contains(&format!("3 runs told apart by `{by}`")), "{err}");
        let found = chosen_terms(&json(&out)["v_dot"]);
        let truth = [("F", 2.0), ("v", -0.3), ("x", -4.0)];
        assert_eq!(
            found.iter().map(|f| f.0.as_str()).collect::<Vec<_>>(),
            truth.map(|t| t.0),
            "{file}: {out}"
        );
        for ((_, got), (name, want)) in found.iter().zip(truth) {
            assert!((got / want - 1.0).abs() < 1e-4, "{file} {name}: {got} vs {want}");
        }
    }
    // a dataset file's run told apart the same way, its window and units applied to each
    let dataset = "[columns]\nt = \"t [s]\"\nx = \"x [m]\"\nv = \"v [m/s]\"\nF = \"F\"\n\
        [[runs]]\nfile = \"after.csv\"\nby = \"run\"\nfrom = 1.0\n";
    std::fs::write(dir.join("runs.toml"), dataset).unwrap();
    let (ok, out, err) =
        termid(&["identify", "--model", &model, "--format", "json", "--dataset", &p("runs.toml")]);
    assert!(
        ok && err.contains("3 runs told apart by `run`") && err.contains("[run=zz2]: trimmed to 1 ≤ t"),
        "{err}"
    );
    let found = chosen_terms(&json(&out)["v_dot"]);
    assert!(found.iter().any(|(t, c)| t == "x" && (c + 4.0).abs() < 4e-4), "{out}");
    // what is wrong in one run is said at the file's row
    let text = std::fs::read_to_string(dir.join("interleaved.csv")).unwrap();
    let broken: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let mut cells: Vec<&str> = l.split(',').collect();
            if i == 8 {
                cells[1] = "NaN";
            }
            cells.join(",")
        })
        .collect();
    std::fs::write(dir.join("broken.csv"), broken.join("\n")).unwrap();
    let (ok, _, err) = identify(&p("broken.csv"), &["--by", "vessel"]);
    assert!(!ok && err.contains("[vessel=2]: row 8, column `x`"), "{err}");
}

/// Right by default far from 0: a temperature in kelvin read to 0.01 K, dT/dt =
/// −0.5 (T − 300) + 2 P(t), and Lorenz with z read from 10 000 below its zero. Over every
/// monomial of T and P, T, T² and 1 are collinear (T sits some 170 spreads from 0): the fit
/// kept T² and traded it against T and 1 (in one such run −0.517 T + 152.6 + 2.9e-5 T²); `--states` writes
/// the library about a round reference value, as the paper's Δu = u − u₀ (a parameter T0 = 300,
/// a derived ΔT = T − T0), says so, and comes back with the system's two terms; the file
/// re-simulates the run. Named candidates stay as written. Two runs at ambients of 300 and 350 K
/// (13 spreads from 0) come back as −0.5 ΔT + 0.5 ΔTa + 2 P. Lorenz's terms come back about z's
/// reference z0 (Lorenz's constants moved by z0 − 10⁴: dy/dt = (28 − (z0 − 10⁴))·x − y − x·Δz).
#[test]
fn a_system_far_from_zero_is_identified_about_a_reference_value() {
    use crate::common::{json, trajectory, Scratch};
    let dir = Scratch::new("generic-offset");
    let power = |t: f64| (0.7 * t).sin() + 0.6 * (1.9 * t + 0.5).sin();
    let mut text = String::from("t,T,P\n");
    let run = trajectory(&[301.0], 0.02, 3_000, 10, |t, x| vec![-0.5 * (x[0] - 300.0) + 2.0 * power(t)]);
    let mut noise = crate::common::Lcg(5);
    for (i, r) in run.iter().enumerate() {
        let t = i as f64 * 0.02;
        text += &format!("{t},{},{}\n", r[0] + 0.01 * noise.normal(), power(t));
    }
    std::fs::write(dir.join("run.csv"), text).unwrap();
    let p = |f: &str| dir.join(f).display().to_string();
    let (data, out) = (p("run.csv"), p("m.toml"));
    let (ok, report, err) = termid(&[
        "identify", "--data", &data, "--states", "T", "--inputs", "P", "--degree", "2", "--out", &out,
        "--format", "json",
    ]);
    assert!(ok, "{err}");
    let notes = json(&report)["T_dot"]["notes"].to_string();
    assert!(
        notes.contains("written about reference values") && notes.contains("ΔT = T - T0, T0 = 300"),
        "{notes}"
    );
    let model = termid::model::Model::load(std::path::Path::new(&out)).unwrap();
    assert_eq!(model.parameter_values()["T0"], 300.0);
    let chosen = |model: &termid::model::Model, equation: &str| -> BTreeMap<String, f64> {
        let e = model.equation(equation).unwrap();
        e.coefficients
            .iter()
            .map(|(t, c, _)| (t.to_string(), *c))
            .chain(e.intercept.map(|b| ("1".into(), b)))
            .collect()
    };
    let found = chosen(&model, "T_dot");
    assert_eq!(found.keys().collect::<Vec<_>>(), ["P", "ΔT"], "{found:?}");
    assert!((found["ΔT"] + 0.5).abs() < 1e-3 && (found["P"] - 2.0).abs() < 4e-3, "{found:?}");
    let (ok, text, err) = termid(&["validate", "--model", &out, "--data", &data, "--format", "json"]);
    assert!(ok, "{err}");
    let rms = json(&text)["gap"]["states"][0][2].as_f64().unwrap();
    assert!(rms < 0.02, "{text}");
    let (ok, report, err) = termid(&[
        "identify",
        "--data",
        &data,
        "--states",
        "T",
        "--inputs",
        "P",
        "--terms",
        "1,T,P,T^2,T*P,P^2",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let listed = json(&report)["T_dot"]["candidates"].to_string();
    assert!(listed.contains("\"T^2\"") && !listed.contains('Δ'), "{listed}");
    // two runs at ambients Ta of 300 and 350 K, dT/dt = −0.5 (T − Ta) + 2 P: T and Ta sit 13
    // spreads from 0 (the library of them kept six terms for three)
    let mut runs = Vec::new();
    for (k, ambient) in [300.0, 350.0].into_iter().enumerate() {
        let run = trajectory(&[ambient + 1.0], 0.02, 3_000, 10, |t, x| {
            vec![-0.5 * (x[0] - ambient) + 2.0 * power(t)]
        });
        let mut text = String::from("t,T,P,Ta\n");
        for (i, r) in run.iter().enumerate() {
            let t = i as f64 * 0.02;
            text += &format!("{t},{},{},{ambient}\n", r[0] + 0.01 * noise.normal(), power(t));
        }
        let path = p(&format!("ambient{k}.csv"));
        std::fs::write(&path, text).unwrap();
        runs.push(path);
    }
    let ambient = p("ambient.toml");
    let (ok, _, err) = termid(&[
        "identify", "--data", &runs[0], &runs[1], "--states", "T", "--inputs", "P,Ta", "--degree", "2",
        "--out", &ambient,
    ]);
    assert!(ok, "{err}");
    let model = termid::model::Model::load(std::path::Path::new(&ambient)).unwrap();
    let found = chosen(&model, "T_dot");
    let (t0, ta0) = (model.parameter_values()["T0"], model.parameter_values()["Ta0"]);
    // −0.5 (ΔT + T0) + 0.5 (ΔTa + Ta0) + 2 P: a constant only where the references differ
    let mut want = vec![("P", 2.0), ("ΔT", -0.5), ("ΔTa", 0.5)];
    if t0 != ta0 {
        want.insert(0, ("1", 0.5 * (ta0 - t0)));
    }
    assert_eq!(
        found.keys().map(String::as_str).collect::<Vec<_>>(),
        want.iter().map(|w| w.0).collect::<Vec<_>>()
    );
    for (term, c) in want {
        assert!((found[term] - c).abs() <= 2e-3 * c.abs(), "{term}: {found:?}");
    }
    // Lorenz with z from 10 000 below its zero
    let rows = lorenz_rows(&dir, "0.001");
    let body: Vec<String> = rows
        .iter()
        .step_by(10)
        .map(|r| format!("{:?},{:?},{:?},{:?}", r[0], r[1], r[2], r[3] + 1e4))
        .collect();
    std::fs::write(dir.join("lorenz.csv"), format!("t,x,y,z\n{}\n", body.join("\n"))).unwrap();
    let lorenz = p("lorenz.toml");
    let (ok, _, err) = termid(&[
        "identify",
        "--data",
        &p("lorenz.csv"),
        "--states",
        "x,y,z",
        "--degree",
        "2",
        "--out",
        &lorenz,
    ]);
    assert!(ok, "{err}");
    let model = termid::model::Model::load(std::path::Path::new(&lorenz)).unwrap();
    let moved = model.parameter_values()["z0"] - 1e4;
    let truth: [(&str, Vec<(&str, f64)>); 3] = [
        ("x_dot", vec![("x", -10.0), ("y", 10.0)]),
        ("y_dot", vec![("x", 28.0 - moved), ("x*Δz", -1.0), ("y", -1.0)]),
        ("z_dot", vec![("1", -8.0 / 3.0 * moved), ("x*y", 1.0), ("Δz", -8.0 / 3.0)]),
    ];
    for (equation, want) in truth {
        let found = chosen(&model, equation);
        let names: Vec<&str> = found.keys().map(String::as_str).collect();
        let wanted: Vec<&str> = want.iter().map(|w| w.0).collect();
        assert_eq!(names, wanted, "{equation}: {found:?}");
        for (term, c) in want {
            assert!(
                (found[term] - c).abs() <= 1e-3 * c.abs().max(1.0),
                "{equation} {term}: {} vs {c}",
                found[term]
            );
        }
    }
}

/// `identify --states` identifies every state's rate of a system nobody wrote a model file
/// for, from its columns alone (the polynomial library to --degree over the states and every
/// other column as an input, said), and writes a model file that starts where the run starts
/// and re-simulates it: the forced oscillator ẍ = −4x − 0.2ẋ + F from noise-free samples.
#[test]
fn a_whole_system_from_its_columns() {
    use crate::common::{json, trajectory, Scratch};
    let dir = Scratch::new("generic-states");
    let force = |t: f64| 2.0 * (0.6 * t).sin() + 1.5 * (1.7 * t + 1.0).sin();
    let mut text = String::from("t,x,v,F\n");
    for (i, r) in
        trajectory(&[1.0, 0.5], 0.01, 3_000, 10, |t, x| vec![x[1], -4.0 * x[0] - 0.2 * x[1] + force(t)])
            .iter()
            .enumerate()
    {
        let t = i as f64 * 0.01;
        text += &format!("{t},{},{},{}\n", r[0], r[1], force(t));
    }
    std::fs::write(dir.join("run.csv"), text).unwrap();
    let p = |f: &str| dir.join(f).display().to_string();
    let (data, out) = (p("run.csv"), p("m.toml"));
    let (ok, report, err) = termid(&[
        "identify", "--data", &data, "--states", "x,v", "--degree", "3", "--out", &out, "--format", "json",
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("the inputs are F (every other column"), "{err}");
    assert!(json(&report)["v_dot"].is_object(), "{report}");
    let model = termid::model::Model::load(std::path::Path::new(&out)).unwrap();
    let terms = |equation: &str| {
        let e = model.equation(equation).unwrap();
        let mut found: Vec<(String, f64)> =
            e.coefficients.iter().map(|(t, c, _)| (t.to_string(), *c)).collect();
        found.sort_by(|a, b| a.0.cmp(&b.0));
        (found, e.candidates.len())
    };
    let (x_dot, candidates) = terms("x_dot");
    assert_eq!(candidates, 20, "every monomial of x, v, F to degree 3: C(6, 3)");
    assert_eq!(x_dot.len(), 1);
    assert!(x_dot[0].0 == "v" && (x_dot[0].1 - 1.0).abs() < 1e-4, "{x_dot:?}");
    let (v_dot, _) = terms("v_dot");
    let truth = [("F", 1.0), ("v", -0.2), ("x", -4.0)];
    assert_eq!(v_dot.len(), 3, "{v_dot:?}");
    for ((term, value), (want, exact)) in v_dot.iter().zip(truth) {
        assert!(term == want && (value - exact).abs() < 1e-3 * exact.abs(), "{v_dot:?}");
    }
    // it starts where the run starts and re-simulates it under its recorded force
    let initial: Vec<f64> = model.spec().states.iter().map(|s| s.initial).collect();
    assert_eq!(initial, [1.0, 0.5]);
    let (ok, text, err) = termid(&["validate", "--model", &out, "--data", &data, "--format", "json"]);
    assert!(ok, "{err}");
    // each state's RMS and largest error of the re-simulation
    let x = &json(&text)["gap"]["states"][0];
    assert!(x[0] == "x" && x[2].as_f64().is_some_and(|rms| rms < 1e-3), "{text}");
    // what a system of columns cannot be is refused by name
    for (extra, says) in [
        (&["--states", "x,w"][..], "`w` is not a column of"),
        (&["--states", "x,v", "--target", "dv/dt"], "--target cannot be used with --states"),
        (&["--states", "x,v", "--inputs", "x"], "`x` is named twice"),
        (&["--states", "x,v", "--terms", "x*G"], "unknown variable `G`"),
        // a forcing written as a function of the clock: the time is no variable of terms
        (&["--states", "x,v", "--terms", "x,cos(1.2*t)"], "`t` is the time, which no term holds"),
        (&["--states", "x,v", "--degree", "0"], "degree 0"),
    ] {
        let mut args = vec!["identify", "--data", &data];
        args.extend_from_slice(extra);
        let (ok, _, err) = termid(&args);
        assert!(!ok && err.contains(says), "{extra:?}: {err}");
    }
    // candidates listed with commas, as states are (a call's own commas kept)
    let (ok, report, err) = termid(&[
        "identify",
        "--data",
        &data,
        "--states",
        "x,v",
        "--terms",
        "x,v, F,atan2(x, v)",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let listed: Vec<String> = json(&report)["v_dot"]["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    assert_eq!(listed, ["x", "v", "F", "atan2(x, v)"], "{report}");
    // a time column by another name, the only one whose name says so, is taken as the time
    // and said (it was refused, to be named with --time), not taken for an input; beside
    // another such column it is refused with both names
    let renamed = std::fs::read_to_string(&data).unwrap().replacen("t,", "time,", 1);
    std::fs::write(dir.join("time.csv"), &renamed).unwrap();
    let (ok, out, err) =
        termid(&["identify", "--data", &p("time.csv"), "--states", "x,v", "--format", "json"]);
    assert!(ok && err.contains("the time is column `time` (there is no column `t`"), "{err}");
    assert!(!json(&out)["v_dot"]["candidates"].as_array().unwrap().iter().any(|c| c == "time"), "{out}");
    let two: String = renamed
        .lines()
        .enumerate()
        .map(|(k, l)| match (k, l.split_once(',')) {
            (0, _) | (_, None) => format!("{}\n", l.replacen("time,", "time,seconds,", 1)),
            (_, Some((t, rest))) => format!("{t},{t},{rest}\n"),
        })
        .collect();
    std::fs::write(dir.join("two.csv"), two).unwrap();
    let (ok, _, err) = termid(&["identify", "--data", &p("two.csv"), "--states", "x,v"]);
    assert!(!ok && err.contains("`time` looks like time") && !err.contains("the inputs are"), "{err}");
    // a time headed with its unit (`Time (ms)`, as loggers write it) is read in seconds: its
    // milliseconds were read as seconds, every rate a thousand times too slow (ẋ = 0.001v);
    // a model so identified writes its runs' time back in milliseconds, and is given its
    // simulation's times in them
    let lines: Vec<String> = std::fs::read_to_string(&data).unwrap().lines().map(String::from).collect();
    let mut in_ms = String::from("Time (ms),x,v,F\n");
    for line in &lines[1..] {
        let (t, rest) = line.split_once(',').unwrap();
        in_ms += &format!("{},{rest}\n", 1000.0 * t.parse::<f64>().unwrap());
    }
    std::fs::write(dir.join("ms.csv"), in_ms).unwrap();
    let (ms, ms_model, sim) = (p("ms.csv"), p("ms.toml"), p("ms_sim.csv"));
    let (ok, _, err) =
        termid(&["identify", "--data", &ms, "--time", "Time (ms)", "--states", "x,v", "--out", &ms_model]);
    assert!(ok, "{err}");
    let model = termid::model::Model::load(std::path::Path::new(&ms_model)).unwrap();
    let v = model
        .equation("x_dot")
        .unwrap()
        .coefficients
        .iter()
        .find(|(t, _, _)| t.to_string() == "v")
        .unwrap()
        .1;
    assert!((v - 1.0).abs() < 1e-4, "{v}");
    let (ok, _, err) =
        termid(&["simulate", "--model", &ms_model, "--duration", "100", "--sample", "10", "--out", &sim]);
    assert!(ok, "{err}");
    let written = std::fs::read_to_string(&sim).unwrap();
    let second: Vec<&str> = written.lines().nth(2).unwrap().split(',').collect();
    assert!(written.starts_with("Time (ms),") && second[0].parse::<f64>().unwrap() == 10.0, "{written}");
    // a logger's milliseconds since 1970 under `timestamp_ms` are read in seconds too (they
    // were read as seconds: ẋ = 0.001v); under a bare `timestamp`, the year they make as
    // seconds (55 840) is said, with the header that reads them
    let epoch = std::fs::read_to_string(dir.join("ms.csv")).unwrap();
    let mut since_1970 = String::from("timestamp_ms,x,v,F\n");
    for line in epoch.lines().skip(1) {
        let (t, rest) = line.split_once(',').unwrap();
        since_1970 += &format!("{},{rest}\n", 1.7e12 + t.parse::<f64>().unwrap());
    }
    std::fs::write(dir.join("epoch.csv"), &since_1970).unwrap();
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        &p("epoch.csv"),
        "--time",
        "timestamp_ms",
        "--states",
        "x,v",
        "--format",
        "json",
    ]);
    assert!(ok && !err.contains("1970"), "{err}");
    let rate = crate::common::json(&out)["x_dot"]["terms"][0]["coefficient"].as_f64().unwrap();
    assert!((rate - 1.0).abs() < 1e-4, "{out}");
    std::fs::write(dir.join("bare.csv"), since_1970.replacen("timestamp_ms", "timestamp", 1)).unwrap();
    let (ok, _, err) =
        termid(&["identify", "--data", &p("bare.csv"), "--time", "timestamp", "--states", "x,v"]);
    assert!(
        ok && err.contains("as seconds since 1970 is the year 55840; as milliseconds since 1970 it is 2024")
            && err.contains("`timestamp [ms]`"),
        "{err}"
    );
    // headers that carry their unit are read by their bare names in SI, as a dataset file
    // maps them (once refused, "map it in a dataset file"): the velocity in km/h
    let run = std::fs::read_to_string(&data).unwrap();
    let mut headed = String::from("t,x [m],v [km/h],F\n");
    for line in run.lines().skip(1) {
        let cells: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        headed += &format!("{},{},{},{}\n", cells[0], cells[1], 3.6 * cells[2], cells[3]);
    }
    std::fs::write(dir.join("headed.csv"), &headed).unwrap();
    let (ok, out, err) =
        termid(&["identify", "--data", &p("headed.csv"), "--states", "x,v", "--format", "json"]);
    assert!(ok && err.contains("`x [m]` as x, `v [km/h]` as v in SI (× 2.777778e-1)"), "{err}");
    let rate = json(&out)["x_dot"]["terms"][0]["coefficient"].as_f64().unwrap();
    assert!((rate - 1.0).abs() < 1e-4, "{out}");
    // the time too, under the model's time's name with its unit of time (`t [ms]` where the
    // time is `t`: it was refused, naming `--time "t [ms]"`), whole and in pieces; the time
    // not taken for an input
    let mut in_ms = String::from("t [ms],x [m],v [km/h],F\n");
    for line in headed.lines().skip(1) {
        let (t, rest) = line.split_once(',').unwrap();
        in_ms += &format!("{},{rest}\n", 1e3 * t.parse::<f64>().unwrap());
    }
    std::fs::write(dir.join("in_ms.csv"), &in_ms).unwrap();
    let in_ms = p("in_ms.csv");
    for pieces in [&[][..], &["--chunk-rows", "300"]] {
        let args = [&["identify", "--data", &in_ms, "--states", "x,v", "--format", "json"], pieces].concat();
        let (ok, out, err) = termid(&args);
        assert!(
            ok && err.contains("the time `t [ms]` read in seconds (× 1.000000e-3)")
                && err.contains("`x [m]` as x"),
            "{err}"
        );
        assert!(err.contains("note: the inputs are F "), "{err}");
        let rate = json(&out)["x_dot"]["terms"][0]["coefficient"].as_f64().unwrap();
        assert!((rate - 1.0).abs() < 1e-4, "{out}");
    }
    // a unit termid does not know is read as written, and said (a logger's `i [A]`, `w [rpm]`,
    // a lab's `C [mg/L]` were refused: every field but the ship's had its columns renamed); one
    // in parentheses is named, as `f(x)` is a name
    std::fs::write(dir.join("furlongs.csv"), headed.replacen("x [m]", "x [furlong]", 1)).unwrap();
    let (ok, out, err) =
        termid(&["identify", "--data", &p("furlongs.csv"), "--states", "x,v", "--format", "json"]);
    assert!(
        ok && err.contains("`x [furlong]` as x in furlong as written (a unit termid does not convert)"),
        "{err}"
    );
    let rate = json(&out)["x_dot"]["terms"][0]["coefficient"].as_f64().unwrap();
    assert!((rate - 1.0).abs() < 1e-4, "{out}");
    std::fs::write(dir.join("furlongs.csv"), headed.replacen("x [m]", "x (furlong)", 1)).unwrap();
    let (ok, _, err) = termid(&["identify", "--data", &p("furlongs.csv"), "--states", "x,v"]);
    assert!(!ok && err.contains("`x (furlong)` carries in parentheses a unit termid does not know"), "{err}");
}

/// A pendulum swung to 2.8 rad, identified from the cubic library alone (`--no-laws`): the
/// cubic standing in for the sine has a false top at 2.84 rad, so the equations follow the run
/// for 0.39 s of 30 and run away from a start a hundredth of each span off. Every check read
/// "ok" ("which tells nothing"); from a start a ten-thousandth off their own motion follows
/// itself throughout, and losing the run so soon is flagged. By default the flag has the
/// system identified again with each state's laws among the candidates: sin θ, exactly, every
/// check ok, and said.
#[test]
fn a_library_without_the_systems_form_is_flagged_where_its_false_top_is_near() {
    use crate::common::{trajectory, Scratch};
    let dir = Scratch::new("generic-pendulum");
    let mut text = String::from("t,theta,omega\n");
    for (i, r) in trajectory(&[2.8, 0.0], 0.01, 3_001, 10, |_, x| vec![x[1], -9.81 * x[0].sin() - 0.1 * x[1]])
        .iter()
        .enumerate()
    {
        text += &format!("{},{},{}\n", i as f64 * 0.01, r[0], r[1]);
    }
    let data = dir.join("pendulum.csv");
    std::fs::write(&data, text).unwrap();
    let data = data.to_str().unwrap();
    let (ok, out, err) = termid(&["identify", "--data", data, "--states", "theta,omega", "--no-laws"]);
    assert!(ok, "{err}");
    let said = format!("{out}{err}");
    assert!(
        said.contains("FLAG the equations follow their runs as long as their own motion allows")
            && said
                .contains("started a ten-thousandth of each span off, follows itself throughout its 30.0 s"),
        "{said}"
    );
    let (ok, out, err) = termid(&["identify", "--data", data, "--states", "theta,omega", "--format", "json"]);
    assert!(ok, "{err}");
    let report = crate::common::json(&out);
    let terms = crate::common::chosen_terms(&report["omega_dot"]);
    assert_eq!(terms.len(), 2, "{terms:?}");
    assert!(terms.iter().any(|(t, c)| t == "sin(theta)" && (c + 9.81).abs() < 1e-3), "{terms:?}");
    assert!(terms.iter().any(|(t, c)| t == "omega" && (c + 0.1).abs() < 1e-4), "{terms:?}");
    let text = out.to_string();
    assert!(
        text.contains("kept, the polynomials having stood in for a law")
            && !text.contains("\"passed\": false"),
        "{text}"
    );
}

/// Cascaded tanks (ḣ₁ = −0.5√h₁ + 0.4u, ḣ₂ = 0.5√h₁ − 0.4√h₂, u held at random levels every
/// 20 s, the levels read every second with noise of 1 %): the cubic library's 37 terms in h₁,
/// h₂, u (u², h₁u², …) stand in for Torricelli's outflow and differ between the halves; with
/// each state's laws among the candidates the four true terms come back within 1 %, every
/// check ok. (Noise-free, read every second, the weak form's error at each kink of the held
/// input is fitted by small terms of either library: the laws are tried and said no better.)
#[test]
fn a_law_the_polynomials_stand_in_for_is_found() {
    use crate::common::{trajectory, Lcg, Scratch};
    let dir = Scratch::new("generic-tanks");
    let mut draw = Lcg(17);
    let levels: Vec<f64> = (0..100).map(|_| 0.5 + 1.5 * draw.next()).collect();
    let u = |t: f64| levels[((t / 20.0) as usize).min(levels.len() - 1)];
    // (held from each switch on: the integrator's last stage of an interval at its end reads
    // the level before)
    let rows = trajectory(&[1.0, 1.0], 1.0, 2_000, 100, |t, h| {
        let (a, b) = (h[0].max(0.0).sqrt(), h[1].max(0.0).sqrt());
        vec![-0.5 * a + 0.4 * u((t - 1e-6).max(0.0)), 0.5 * a - 0.4 * b]
    });
    let sd = crate::common::noise(&rows, 0.01);
    let mut text = String::from("t,h1,h2,u\n");
    for (i, r) in rows.iter().enumerate() {
        let t = i as f64;
        let (one, two) = (r[0] + sd[0] * draw.normal(), r[1] + sd[1] * draw.normal());
        text += &format!("{t},{one},{two},{}\n", u(t));
    }
    let data = dir.join("tanks.csv");
    std::fs::write(&data, text).unwrap();
    let data = data.to_str().unwrap();
    let (ok, out, err) =
        termid(&["identify", "--data", data, "--states", "h1,h2", "--inputs", "u", "--format", "json"]);
    assert!(ok, "{err}");
    let report = crate::common::json(&out);
    let terms = |rate: &str| crate::common::chosen_terms(&report[rate]);
    let near = |terms: &[(String, f64)], term: &str, value: f64| {
        terms.iter().any(|(t, c)| t == term && (c / value - 1.0).abs() < 1e-2)
    };
    let (one, two) = (terms("h1_dot"), terms("h2_dot"));
    assert!(one.len() == 2 && near(&one, "sqrt(abs(h1))", -0.5) && near(&one, "u", 0.4), "{one:?}");
    assert!(
        two.len() == 2 && near(&two, "sqrt(abs(h1))", 0.5) && near(&two, "sqrt(abs(h2))", -0.4),
        "{two:?}"
    );
    assert!(!out.contains("\"passed\": false"), "{out}");
}

/// Dry friction, ẍ = −4x − 0.1ẋ − 0.5 sign ẋ + u under a sum of two sines. Noise-free, the
/// cubic library's four terms (−0.35v + 0.0066v³ for the friction) re-simulate the run 11
/// times as far off as allowed; with the laws among the candidates sign(v) comes back in as
/// many terms, every check ok, and is kept (it was said "no better: 5 terms, no fewer"). With
/// 1 % noise on x and v the stand-in passes every check; its v³, a state's power alone, has the
/// laws tried, and sign(v) fits the rows clearly better in as many terms: kept (the stand-in
/// was kept with nothing said).
#[test]
fn a_law_in_as_many_terms_as_its_stand_in_is_kept() {
    use crate::common::{trajectory, Lcg, Scratch};
    let dir = Scratch::new("generic-dry-friction");
    let u = |t: f64| 2.5 * (0.7 * t).sin() + 1.5 * (1.9 * t).sin();
    // (sign v smoothed within a thousandth: the integrator's steps stay stable)
    let rows = trajectory(&[1.0, 0.0], 0.02, 6_000, 20, |t, s| {
        vec![s[1], -4.0 * s[0] - 0.1 * s[1] - 0.5 * (s[1] / 1e-3).tanh() + u(t)]
    });
    let sd = crate::common::noise(&rows, 0.01);
    let mut draw = Lcg(29);
    for (name, noisy) in [("friction.csv", false), ("noisy.csv", true)] {
        let mut text = String::from("t,x,v,u\n");
        for (i, r) in rows.iter().enumerate() {
            let t = i as f64 * 0.02;
            let e = |k: usize, draw: &mut Lcg| if noisy { sd[k] * draw.normal() } else { 0.0 };
            text += &format!("{t},{},{},{}\n", r[0] + e(0, &mut draw), r[1] + e(1, &mut draw), u(t));
        }
        let data = dir.join(name);
        std::fs::write(&data, text).unwrap();
        let (report, _) = identified_u(&data, "x,v", &[]);
        let out = report.to_string();
        let terms = crate::common::chosen_terms(&report["v_dot"]);
        assert_eq!(terms.len(), 4, "{name}: {terms:?}");
        coefficients_within(
            &terms,
            &[("x", -4.0), ("v", -0.1), ("sign(v)", -0.5), ("u", 1.0)],
            if noisy { 0.05 } else { 0.01 },
            name,
        );
        assert!(
            out.contains("kept, the polynomials having stood in for a law")
                && !out.contains("\"passed\":false"),
            "{out}"
        );
        assert_eq!(out.contains("hold `v^3`, a variable's power alone"), noisy, "{out}");
    }
}

/// A ship's surge under its propeller, v̇ = −0.3v·|v| + 0.1u·|u| with the propeller's rate u a
/// sum of three sines. Noise-free, the cubic's four terms (u and u³ for the thrust) fail the
/// re-simulation and only the state's laws were tried (no better); at 1 % noise on v the
/// stand-in −0.096v − 0.216v³ + 0.081u + 0.027u³ passed every check, nothing said. With the
/// inputs' laws among the candidates, v·|v| and u·|u| come back, every check ok.
#[test]
fn an_input_s_law_is_found_where_its_powers_stood_in() {
    use crate::common::{trajectory, Lcg, Scratch};
    let dir = Scratch::new("generic-surge");
    let u = |t: f64| 1.5 * (0.31 * t).sin() + (0.83 * t + 1.0).sin() + 0.5 * (2.1 * t + 2.0).sin();
    let rows =
        trajectory(&[0.0], 0.05, 4_000, 10, |t, s| vec![-0.3 * s[0] * s[0].abs() + 0.1 * u(t) * u(t).abs()]);
    let sd = crate::common::noise(&rows, 0.01);
    let mut draw = Lcg(41);
    for (name, noisy) in [("surge.csv", false), ("noisy.csv", true)] {
        let data = one_state_record(&dir.join(name), "v", &rows, &u, noisy.then_some((sd[0], &mut draw)));
        let (report, _) = identified_u(&data, "v", &[]);
        let out = report.to_string();
        let terms = crate::common::chosen_terms(&report["v_dot"]);
        assert_eq!(terms.len(), 2, "{name}: {terms:?}");
        coefficients_within(
            &terms,
            &[("v*abs(v)", -0.3), ("u*abs(u)", 0.1)],
            if noisy { 0.01 } else { 1e-4 },
            name,
        );
        assert!(
            out.contains("kept, the polynomials having stood in for a law")
                && !out.contains("\"passed\":false"),
            "{out}"
        );
    }
}

/// A first-order plant whose input acts 0.5 s late, ẋ = −0.5x + 0.8u(t − 0.5), read every
/// 0.05 s: under a sum of three sines with 1 % noise on x it came back as 0.62u − 0.40x +
/// 0.019x³, every check ok, the dead time only in a note (and the sines, taken as held by the
/// fit the delay fooled, put it a sample short); under a square wave, noise-free, as four
/// polynomial terms, flagged, the dead time not scanned for; under random levels held from
/// random samples (an APRBS) acting 0.25 s late, with 1 % noise, taken as switching between
/// samples (the delay moved the jumps' effects), 1665 of the weak form's 3968 windows left out,
/// which hid the delay from the scan too: flagged, nothing said of a delay. Now identified
/// again with u read late (the levels read as held): the two true terms, every check ok, said.
#[test]
fn an_input_acting_late_is_found_and_fitted_so() {
    use crate::common::{trajectory, Lcg, Scratch};
    let dir = Scratch::new("generic-dead-time");
    let sines = |t: f64| 1.5 * (0.31 * t).sin() + (0.83 * t + 1.0).sin() + 0.5 * (2.1 * t + 2.0).sin();
    let square = |t: f64| if t.rem_euclid(20.0) < 10.0 { 1.0 } else { -1.0 };
    let mut draw = Lcg(42);
    let mut level = 1.0;
    let levels: Vec<f64> = (0..4_000)
        .map(|_| {
            if draw.next() < 1.0 / 60.0 {
                level = 3.0 * draw.next() - 1.5;
            }
            level
        })
        .collect();
    let aprbs = |t: f64| levels[((t / 0.05 + 1e-6).floor().max(0.0) as usize).min(3_999)];
    // each input's file, the input, how late it acts (s), whether x is read with noise
    type Late<'a> = (&'a str, &'a dyn Fn(f64) -> f64, f64, bool);
    let inputs: [Late; 3] = [
        ("aprbs.csv", &aprbs, 0.25, true),
        ("sines.csv", &sines, 0.5, true),
        ("square.csv", &square, 0.5, false),
    ];
    for (name, u, late, noisy) in inputs {
        let rows = trajectory(&[0.0], 0.05, 4_000, 10, |t, s| vec![-0.5 * s[0] + 0.8 * u(t - late)]);
        let sd = crate::common::noise(&rows, 0.01);
        let data = one_state_record(&dir.join(name), "x", &rows, u, noisy.then_some((sd[0], &mut draw)));
        let (report, _) = identified_u(&data, "x", &[]);
        let out = report.to_string();
        let terms = crate::common::chosen_terms(&report["x_dot"]);
        assert_eq!(terms.len(), 2, "{name}: {terms:?}");
        coefficients_within(&terms, &[("x", -0.5), ("u", 0.8)], if noisy { 0.01 } else { 1e-3 }, name);
        assert!(
            out.contains(&format!(
                "identified again with the inputs read as acting late, `u` by {late:.3} s (a dead time, or a first-order lag"
            ))
                && out.contains("the equations hold, every check ok: kept")
                && !out.contains("\"passed\":false"),
            "{out}"
        );
    }
    // each dead time declared on the command line instead: the same terms, nothing left to
    // find; each input judged between its samples as it acts (the sines and the levels, judged
    // as logged, read as held and as switching: 1 % off with a spurious x³), by --states and
    // by a single --target alike
    for (name, _, late, noisy) in inputs {
        let data = dir.join(name);
        let delay = format!("u={late}");
        let (declared, _) = identified_u(&data, "x", &["--delay", &delay, "--no-dead-times"]);
        let terms = crate::common::chosen_terms(&declared["x_dot"]);
        assert_eq!(terms.len(), 2, "{name}: {terms:?}");
        let within = if noisy { 0.01 } else { 1e-3 };
        coefficients_within(&terms, &[("x", -0.5), ("u", 0.8)], within, name);
        assert!(!declared.to_string().contains("acts on dx/dt"), "{declared}");
        let (ok, out, err) = termid(&[
            "identify",
            "--data",
            data.to_str().unwrap(),
            "--target",
            "dx/dt",
            "--terms",
            "x,u,x^3",
            "--delay",
            &delay,
            "--format",
            "json",
        ]);
        assert!(ok, "{err}");
        let terms = crate::common::chosen_terms(&crate::common::json(&out));
        assert_eq!(terms.len(), 2, "{name}, --target: {terms:?}");
        coefficients_within(&terms, &[("x", -0.5), ("u", 0.8)], within, name);
    }
    let data = dir.join("square.csv");
    let (ok, _, err) =
        termid(&["identify", "--data", data.to_str().unwrap(), "--states", "x", "--delay", "w=0.5"]);
    assert!(!ok && err.contains("`w` is no input (the inputs: u)"), "{err}");
}

/// Michaelis-Menten, ẋ = −2x/(0.5 + x) + u, noise-free, from the default cubic library: eight
/// or nine polynomial terms stand in for the rational rate, and the halves of the run choose
/// others; flagged, the missing form named first (it named only noise and a half that does
/// not excite, where the noise check measures none; then noise first of three).
#[test]
fn polynomials_standing_in_for_a_missing_form_are_flagged() {
    use crate::common::{trajectory, Scratch};
    let dir = Scratch::new("generic-michaelis-menten");
    let u = |t: f64| 1.0 + 0.8 * (0.7 * t).sin() + 0.5 * (1.9 * t + 1.0).sin();
    let mut text = String::from("t,x,u\n");
    for (i, r) in
        trajectory(&[0.2], 0.01, 6_001, 10, |t, x| vec![-2.0 * x[0] / (0.5 + x[0]) + u(t)]).iter().enumerate()
    {
        let t = i as f64 * 0.01;
        text += &format!("{t},{},{}\n", r[0], u(t));
    }
    let data = dir.join("mm.csv");
    std::fs::write(&data, text).unwrap();
    let (ok, out, err) =
        termid(&["identify", "--data", data.to_str().unwrap(), "--states", "x", "--inputs", "u"]);
    assert!(ok, "{err}");
    let said = format!("{out}{err}");
    assert!(
        said.contains("FLAG the terms hold on each half of the runs")
            && said
                .contains("next to no noise (the noise check's reading), so terms that stand in for a form")
            && !said.contains("terms the noise chose"),
        "{said}"
    );
}

/// A coefficient as the output-error refinement of an identification's JSON report left it.
fn refined(report: &serde_json::Value, equation: &str, term: &str) -> Option<f64> {
    let all = report["output_error_refinement"]["coefficients"].as_array()?;
    all.iter().find(|c| c["equation"] == equation && c["term"] == term)?["refined"].as_f64()
}

/// Equations whose rates fit the rows may still run away when integrated: Lotka-Volterra
/// sampled ten times a period, noise-free, gives the cubic library's regression spurious
/// terms that cancel on the samples; re-simulated from the run's start the system they make
/// diverged within 5 s and was refused. Their terms are now chosen again by re-simulation (of
/// the regression's and the best subsets of each size per equation, each refined by output
/// error: the rows are coarse for the rates): the truth's, refined to it within 10⁻⁴ and
/// written; sampled five times faster, the regression's own terms are the truth's and pass.
#[test]
fn equations_that_run_away_from_a_coarse_run_are_chosen_again_by_resimulation() {
    use crate::common::{json, Scratch};
    let dir = Scratch::new("generic-run-away");
    let p = |f: &str| dir.join(f).display().to_string();
    std::fs::write(
        dir.join("lv.toml"),
        "[model]\nname = \"Lotka-Volterra\"\nintercept = false\n[simulation]\nrtol = 1e-10\natol = 1e-10\n\
         [[states]]\nname = \"x\"\ninitial = 4.0\n[[states]]\nname = \"z\"\ninitial = 1.0\n\
         [equations.x_dot]\nstate = \"x\"\ncoefficients = { \"x\" = 1.0, \"x*z\" = -0.5 }\n\
         [equations.z_dot]\nstate = \"z\"\ncoefficients = { \"z\" = -1.5, \"x*z\" = 0.25 }\n",
    )
    .unwrap();
    // the states alone, as a record has them (a simulation writes their rates too)
    let run = |sample: &str, duration: &str, out: &str| {
        let (ok, _, err) = termid(&[
            "simulate",
            "--model",
            &p("lv.toml"),
            "--duration",
            duration,
            "--sample",
            sample,
            "--out",
            &p(out),
        ]);
        assert!(ok, "{err}");
        let text = std::fs::read_to_string(p(out)).unwrap();
        let states: String =
            text.lines().map(|l| l.split(',').take(3).collect::<Vec<_>>().join(",") + "\n").collect();
        assert!(states.starts_with("t,x,z\n"), "{states}");
        std::fs::write(p(out), states).unwrap();
    };
    run("0.5", "19.5", "coarse.csv");
    run("0.1", "19.9", "fine.csv");
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        &p("coarse.csv"),
        "--states",
        "x,z",
        "--out",
        &p("m.toml"),
        "--format",
        "json",
    ]);
    assert!(ok && dir.join("m.toml").exists(), "{err}");
    let report = json(&out);
    assert!(
        report["x_dot"]["notes"].as_array().unwrap().iter().any(|n| n
            .as_str()
            .unwrap()
            .starts_with("terms chosen by re-simulation: the regression's (9 of `x_dot`, 9 of `z_dot`) fit the rates but lose the runs; the best re-simulated terms, 2 of `x_dot`, 2 of `z_dot`")),
        "{out}"
    );
    assert_eq!(report["output_error_refinement"]["coefficients"].as_array().map(Vec::len), Some(4), "{out}");
    for (equation, term, truth) in
        [("x_dot", "x", 1.0), ("x_dot", "x*z", -0.5), ("z_dot", "z", -1.5), ("z_dot", "x*z", 0.25)]
    {
        let value = refined(&report, equation, term);
        assert!(value.is_some_and(|v| (v / truth - 1.0).abs() < 1e-4), "{equation} {term}: {value:?}\n{out}");
    }
    assert!(report["physical_checks"].as_array().unwrap()[..2].iter().all(|c| c["passed"] == true), "{out}");
    // the model written re-identifies as chosen: its terms forced, the others excluded
    let written = std::fs::read_to_string(p("m.toml")).unwrap();
    assert!(written.contains("forced = [") && written.contains("excluded = ["), "{written}");
    let (ok, out, err) =
        termid(&["identify", "--data", &p("fine.csv"), "--states", "x,z", "--format", "json"]);
    assert!(ok, "{err}");
    let report = json(&out);
    assert_eq!(report["physical_checks"][0]["passed"], true, "{out}");
    assert!(!out.contains("re-simulation"), "{out}");
}

/// A pendulum swinging to ±2.8 rad (θ̈ = −9.81 sin θ − 0.1 θ̇): from its angle alone no
/// equation of θ can turn back as θ does, and the fit that explains almost nothing says so;
/// from θ and ω with the sine among the candidates the truth comes back, followed
/// throughout; with the cubic library alone the re-simulation is said to part from the run
/// early (a cubic standing in for the sine at these angles); in the integral form, a term the
/// halves of the run do not both choose is flagged.
#[test]
fn a_rate_the_candidates_cannot_explain_is_said_to() {
    use crate::common::{json, Scratch};
    let dir = Scratch::new("generic-pendulum");
    let p = |f: &str| dir.join(f).display().to_string();
    std::fs::write(
        dir.join("pendulum.toml"),
        "[model]\nname = \"pendulum\"\nintercept = false\n[simulation]\nrtol = 1e-10\natol = 1e-10\n\
         [[states]]\nname = \"theta\"\ninitial = 2.8\n[[states]]\nname = \"omega\"\ninitial = 0.0\n\
         [equations.theta_dot]\nstate = \"theta\"\ncoefficients = { \"omega\" = 1.0 }\n\
         [equations.omega_dot]\nstate = \"omega\"\ncoefficients = { \"sin(theta)\" = -9.81, \"omega\" = -0.1 }\n",
    )
    .unwrap();
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        &p("pendulum.toml"),
        "--duration",
        "30",
        "--sample",
        "0.01",
        "--out",
        &p("run.csv"),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(p("run.csv")).unwrap();
    let columns = |k: usize| -> String {
        text.lines().map(|l| l.split(',').take(k).collect::<Vec<_>>().join(",") + "\n").collect()
    };
    std::fs::write(p("angle.csv"), columns(2)).unwrap();
    std::fs::write(p("both.csv"), columns(3)).unwrap();
    let (ok, out, err) = termid(&["identify", "--data", &p("angle.csv"), "--states", "theta"]);
    assert!(ok, "{err}");
    assert!(
        out.contains("of the variance of `theta`'s rate") && out.contains("needs its rate as a state too"),
        "{out}"
    );
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        &p("both.csv"),
        "--states",
        "theta,omega",
        "--terms",
        "theta,omega,sin(theta),theta^3",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let found = json(&out);
    let omega = &found["omega_dot"]["terms"];
    assert!(
        omega[0]["term"] == "sin(theta)" && (omega[0]["coefficient"].as_f64().unwrap() + 9.81).abs() < 1e-3,
        "{out}"
    );
    assert!(found["physical_checks"][0]["detail"].as_str().unwrap().ends_with("span throughout"), "{out}");
    assert_eq!(found["physical_checks"][1]["passed"], true, "{out}");
    assert!(!out.contains("of the variance of"), "{out}");
    let (ok, out, err) =
        termid(&["identify", "--data", &p("both.csv"), "--states", "theta,omega", "--no-laws"]);
    assert!(ok, "{err}");
    // the cubic's re-simulation parts from the run within its first period (2.1 s at small angles)
    let follows = out.split("they follow them within a tenth of each state's span for ").nth(1).unwrap();
    let seconds: f64 = follows.split(' ').next().unwrap().parse().unwrap();
    assert!(seconds < 2.1 && follows.contains(" s of 30.0 s (") && follows.contains("both.csv)"), "{out}");
    // its odd terms only (θ and θ³, sin θ's Taylor; no symmetric pendulum has a θ²), which both
    // halves of the run choose again (the integral form's θ² was flagged: not from the second
    // half, whose swings have decayed)
    let cubic = out.split("domega/dt =").nth(1).unwrap().split("\n\n").next().unwrap();
    assert!(cubic.contains("*theta^3") && !cubic.contains("theta^2"), "{out}");
    assert!(out.contains("ok   the terms hold on each half of the runs"), "{out}");
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        &p("both.csv"),
        "--states",
        "theta,omega",
        "--derivative",
        "integral",
        "--no-laws",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("FLAG the terms hold on each half of the runs")
            && out.contains("`omega_dot`: `theta^2`"),
        "{out}"
    );
}

/// A forcing that follows the clock (ẋ = −x + sin t, x alone recorded): no equation of x
/// alone holds, the identification chooses no term, and the re-simulation of ẋ = 0 says how
/// soon it leaves the run (it was not re-simulated at all: an equation without terms was
/// taken for one not identified). The time refused as an input names the remedy, a column
/// of its own, with which the forcing is found.
#[test]
fn a_forcing_that_follows_the_clock_is_said_to_be_missing() {
    use crate::common::Scratch;
    let dir = Scratch::new("generic-clock");
    let p = |f: &str| dir.join(f).display().to_string();
    // x(t) = (sin t − cos t)/2 + 3/2 e^(−t), x(0) = 1
    let rows = (0..3000).map(|k| {
        let t = k as f64 * 0.01;
        (t, 0.5 * (t.sin() - t.cos()) + 1.5 * (-t).exp(), t.sin())
    });
    let (mut alone, mut forced) = (String::from("t,x\n"), String::from("t,x,u\n"));
    for (t, x, u) in rows {
        alone += &format!("{t},{x}\n");
        forced += &format!("{t},{x},{u}\n");
    }
    std::fs::write(p("alone.csv"), alone).unwrap();
    std::fs::write(p("forced.csv"), forced).unwrap();
    let (ok, out, err) = termid(&["identify", "--data", &p("alone.csv"), "--states", "x", "--inputs"]);
    assert!(ok, "{err}");
    assert!(out.contains("explain 0 % of the variance of `x`'s rate"), "{out}");
    let follows = out.split("they follow them within a tenth of each state's span for ").nth(1).unwrap();
    let seconds: f64 = follows.split(' ').next().unwrap().parse().unwrap();
    assert!(seconds < 1.0 && follows.contains(" s of 30.0 s ("), "{out}");
    let (ok, _, err) = termid(&["identify", "--data", &p("alone.csv"), "--states", "x", "--inputs", "t"]);
    assert!(!ok && err.contains("`t` is the time") && err.contains("a column of its own"), "{err}");
    let (ok, out, err) =
        termid(&["identify", "--data", &p("forced.csv"), "--states", "x", "--format", "json"]);
    assert!(ok, "{err}");
    let found = crate::common::json(&out);
    let terms = found["x_dot"]["terms"].as_array().unwrap();
    let coefficient =
        |name: &str| terms.iter().find(|t| t["term"] == name).map(|t| t["coefficient"].as_f64().unwrap());
    assert_eq!(terms.len(), 2, "{out}");
    assert!(
        (coefficient("x").unwrap() + 1.0).abs() < 1e-4 && (coefficient("u").unwrap() - 1.0).abs() < 1e-4,
        "{out}"
    );
}

/// A stiff pair: x follows y at a rate of 200/s (dx/dt = −200 (x − y)), y is driven slowly
/// (dy/dt = −0.5 y + u), sampled every 0.02 s, four samples per x's time constant. Both
/// equations come back with their own terms, the note on the near-constant combination of
/// x, y and u names the fast state, and no dead time is said (u read a sample early took up
/// the rounding and quadrature error of the undelayed fit, a millionth of the rates' sum of
/// squares, and was said as a delay that biased the fit).
#[test]
fn a_fast_state_that_follows_another_is_no_dead_time() {
    use crate::common::{json, trajectory, Scratch};
    let dir = Scratch::new("generic-stiff");
    let input = |t: f64| (0.3 * t).sin() + 0.3 * (1.1 * t).sin();
    let run = trajectory(&[0.0, 0.0], 0.02, 1_500, 200, |t, s| {
        vec![-200.0 * (s[0] - s[1]), -0.5 * s[1] + input(t)]
    });
    let mut text = String::from("t,x,y,u\n");
    for (i, s) in run.iter().enumerate() {
        let t = i as f64 * 0.02;
        text += &format!("{t},{},{},{}\n", s[0], s[1], input(t));
    }
    let data = dir.join("stiff.csv").display().to_string();
    std::fs::write(&data, text).unwrap();
    let (ok, report, err) = termid(&[
        "identify", "--data", &data, "--states", "x,y", "--inputs", "u", "--degree", "1", "--format", "json",
    ]);
    assert!(ok, "{err}");
    let report = json(&report);
    for (rate, want) in [("x_dot", [("x", -200.0), ("y", 200.0)]), ("y_dot", [("u", 1.0), ("y", -0.5)])] {
        let found = crate::common::chosen_terms(&report[rate]);
        assert_eq!(found.len(), 2, "{rate}: {found:?}");
        for ((term, c), (name, value)) in want.iter().zip(&found) {
            assert!(term == name && (value - c).abs() < 1e-3 * c.abs(), "{rate}: {found:?}");
        }
        let notes = report[rate]["notes"].to_string();
        assert!(!notes.contains("later than the rows have it"), "{rate}: {notes}");
    }
    let notes = report["x_dot"]["notes"].to_string();
    assert!(notes.contains("a fast state that follows the others"), "{notes}");
}

/// Lü's system (dx/dt = 36 (y − x), dy/dt = −x z + 20 y, dz/dt = x y − 3 z; 4000 samples
/// 0.006 s apart, about 100 a period) with white noise of 5 % of each state's spread,
/// identified whole from the cubic library: the regression kept ten terms for x's two and both
/// halves of the run chose them alike, every check "ok" (errors in the states bias a library
/// nonlinear in them). The noise is measured off the records and said, over the 2 % where
/// that begins, also in the notes of one equation fitted without a model, in the checks of
/// runs read in pieces and of statistics, and where a sensor filtered it; at 1 % it passes.
#[test]
fn noise_that_biases_the_terms_is_measured_and_said() {
    use crate::common::{check_named, json, trajectory, Lcg, Scratch};
    let dir = Scratch::new("generic-noise");
    let run = trajectory(&[-9.21952, -6.47352, 26.5296], 0.006, 4_000, 10, |_, s| {
        vec![36.0 * (s[1] - s[0]), -s[0] * s[2] + 20.0 * s[1], s[0] * s[1] - 3.0 * s[2]]
    });
    let spread: Vec<f64> = (0..3)
        .map(|i| {
            let mean = run.iter().map(|r| r[i]).sum::<f64>() / run.len() as f64;
            (run.iter().map(|r| (r[i] - mean).powi(2)).sum::<f64>() / run.len() as f64).sqrt()
        })
        .collect();
    // the run's states, each sample as `record` reads it, written as a file of its own
    let write = |name: &str, record: &mut dyn FnMut(&[f64]) -> Vec<f64>| -> String {
        let mut text = String::from("t,x,y,z\n");
        for (k, r) in run.iter().enumerate() {
            let s = record(r);
            text += &format!("{},{},{},{}\n", k as f64 * 0.006, s[0], s[1], s[2]);
        }
        let path = dir.join(name).display().to_string();
        std::fs::write(&path, text).unwrap();
        path
    };
    let check = |share: f64| -> serde_json::Value {
        let mut noise = Lcg(17);
        let data = write(&format!("lu{share}.csv"), &mut |r| {
            (0..3).map(|i| r[i] + share * spread[i] * noise.normal()).collect()
        });
        let (ok, report, err) =
            termid(&["identify", "--data", &data, "--states", "x,y,z", "--inputs", "--format", "json"]);
        assert!(ok, "{err}");
        let checks = json(&report)["physical_checks"].clone();
        checks
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["name"] == "the records' noise leaves the terms unbiased")
            .unwrap_or_else(|| panic!("{checks}"))
            .clone()
    };
    let share_of = |detail: &str, state: &str| -> f64 {
        detail
            .split(&format!("`{state}` "))
            .nth(1)
            .and_then(|s| s.split(" %").next())
            .unwrap()
            .parse()
            .unwrap()
    };
    let noisy = check(0.05);
    // one equation without a model (`--target dx/dt --terms`): said in its notes
    let data = dir.join("lu0.05.csv").display().to_string();
    let one = |data: &str, terms: &str| {
        let (ok, report, err) =
            termid(&["identify", "--data", data, "--target", "dz/dt", "--terms", terms, "--format", "json"]);
        assert!(ok, "{err}");
        json(&report)["notes"].to_string()
    };
    // (ż = xy − bz: the chosen x·y holds x and y nonlinearly)
    let notes = one(&data, "x*y,z,x,y,x*z");
    assert!(notes.contains("the records' noise may bias the terms: white noise of `x` "), "{notes}");
    // candidates linear in the variables are not biased so, and not said to be
    assert!(!one(&data, "x,y,z").contains("the records' noise"));
    // the model identified, read again in pieces (`--chunk-rows`) and from statistics written
    // apart (`termid moments`): no rows kept, so the noise tallied with the statistics checks it
    let model = dir.join("lu.toml").display().to_string();
    let (ok, _, err) =
        termid(&["identify", "--data", &data, "--states", "x,y,z", "--inputs", "--out", &model]);
    assert!(ok, "{err}");
    let pieces = &["--derivative", "central", "--chunk-rows", "500", "--format", "json", "--keep-unphysical"];
    let (ok, report, err) =
        termid(&[&["identify", "--model", &model, "--data", &data], &pieces[..]].concat());
    assert!(ok, "{err}");
    let report = json(&report);
    let noise = check_named(&report, "noise leaves the terms unbiased");
    let detail = noise["detail"].as_str().unwrap();
    assert!(noise["passed"] == false && detail.contains("white noise of `x` "), "{noise}");
    assert!((share_of(detail, "z") - 5.0).abs() < 0.5, "{detail}");
    // re-simulated from the run as kept: central differences of 5 % noise leave equations that
    // run away (refused, but for --keep-unphysical), from the run's start or, where a CPU's
    // rounding keeps that one bounded, from a start a hundredth of each span off (which the
    // true equations of some chaos do too: said, not flagged)
    let retrace = check_named(&report, "retrace their runs");
    let own = check_named(&report, "as long as their own motion allows");
    assert!(
        retrace["passed"] == false || own["detail"].as_str().unwrap().contains("cannot be simulated"),
        "{report}"
    );
    let moments = dir.join("y.json").display().to_string();
    let (ok, _, err) = termid(
        &[
            &["moments", "--model", &model, "--data", &data, "--equation", "y_dot", "--out", &moments],
            &pieces[..4],
        ]
        .concat(),
    );
    assert!(ok, "{err}");
    let (ok, report, err) =
        termid(&["identify", "--model", &model, "--moments", &moments, "--format", "json"]);
    assert!(ok, "{err}");
    assert!(check_named(&json(&report), "noise leaves the terms unbiased")["passed"] == false, "{report}");
    let detail = noisy["detail"].as_str().unwrap();
    assert!(noisy["passed"] == false && noisy["refuses"] == false, "{noisy}");
    for state in ["x", "y", "z"] {
        assert!((share_of(detail, state) - 5.0).abs() < 0.5, "{detail}");
    }
    // the same noise filtered by a sensor (correlated 0.8 from one sample to the next, its
    // variance kept): read over one sample it showed 1.8 % and passed, the terms wrong
    let (mut noise, mut filtered) = (Lcg(29), [0.0; 3]);
    let sensor = write("filtered.csv", &mut |r| {
        for (i, f) in filtered.iter_mut().enumerate() {
            *f = 0.8 * *f + 0.6 * 0.05 * spread[i] * noise.normal();
        }
        (0..3).map(|i| r[i] + filtered[i]).collect()
    });
    let notes = one(&sensor, "x*y,z,x,y,x*z");
    assert!(
        notes.contains("the records' noise may bias the terms: white noise of `x` at least 2."),
        "{notes}"
    );
    assert!(notes.contains("it reads more over two samples than over one"), "{notes}");
    // the run printed to whole units: it moves a unit at a time, its rounding noise of 1/√12
    // (3.7 % of x's spread) that the differences misread as at most 2.3 %, unflagged
    let printed = write("printed.csv", &mut |r| r.iter().map(|v| v.round()).collect());
    let notes = one(&printed, "x*y,z,x,y,x*z");
    let rounding = 100.0 / 12f64.sqrt() / spread[0];
    assert!((share_of(&notes, "x") / rounding - 1.0).abs() < 0.03, "{rounding}: {notes}");
    let quiet = check(0.01);
    let detail = quiet["detail"].as_str().unwrap();
    assert!(quiet["passed"] == true, "{quiet}");
    let data = dir.join("lu0.01.csv").display().to_string();
    let (ok, report, err) =
        termid(&[&["identify", "--model", &model, "--data", &data], &pieces[..]].concat());
    assert!(ok, "{err}");
    assert!(check_named(&json(&report), "noise leaves the terms unbiased")["passed"] == true, "{report}");
    for state in ["x", "y", "z"] {
        assert!((share_of(detail, state) - 1.0).abs() < 0.15, "{detail}");
    }
}

/// Lorenz-96 with ten states (ẋᵢ = (xᵢ₊₁ − xᵢ₋₂)·xᵢ₋₁ − xᵢ + 8) at 1 % noise over 15 s: the
/// cubic library's 286 candidates are more than the 219 rows of independent evidence the weak
/// form's overlapping windows leave. The fit was refused ("1468 rows cannot determine 219
/// terms"); from its quadratic library (66 candidates) a half of the run kept 48 terms for
/// four. Now each rate holds its four true terms within 2 %, and any term beside them is
/// named by the halves check as uncertain; where a half is too short to choose among the
/// candidates, the check says it could not tell.
#[test]
fn many_states_with_few_rows_of_evidence_keep_their_terms() {
    use crate::common::{json, trajectory, Lcg, Scratch};
    const N: usize = 10;
    let dir = Scratch::new("generic-lorenz96");
    let mut x0 = vec![8.0; N];
    x0[0] += 0.01;
    let run = trajectory(&x0, 0.01, 2_000, 4, |_, x| {
        (0..N).map(|i| (x[(i + 1) % N] - x[(i + N - 2) % N]) * x[(i + N - 1) % N] - x[i] + 8.0).collect()
    });
    let run = &run[500..];
    let spread: Vec<f64> = (0..N)
        .map(|i| {
            let mean = run.iter().map(|r| r[i]).sum::<f64>() / run.len() as f64;
            (run.iter().map(|r| (r[i] - mean).powi(2)).sum::<f64>() / run.len() as f64).sqrt()
        })
        .collect();
    let names: Vec<String> = (0..N).map(|i| format!("x{i}")).collect();
    let mut noise = Lcg(96);
    let mut text = format!("t,{}\n", names.join(","));
    for (k, r) in run.iter().enumerate() {
        let row: Vec<String> =
            (0..N).map(|i| format!("{}", r[i] + 0.01 * spread[i] * noise.normal())).collect();
        text += &format!("{},{}\n", k as f64 * 0.01, row.join(","));
    }
    let data = dir.join("l96.csv").display().to_string();
    std::fs::write(&data, &text).unwrap();
    let identify = |data: &str, extra: &[&str]| {
        let states = names.join(",");
        let mut args = vec!["identify", "--data", data, "--states", &states, "--inputs", "--format", "json"];
        args.extend_from_slice(extra);
        let (ok, report, err) = termid(&args);
        assert!(ok, "{err}");
        let report = json(&report);
        let halves = crate::common::check_named(&report, "the terms hold on each half of the runs").clone();
        (report, halves)
    };
    // the first 7 s from the quadratic library (66 candidates): the whole's 104 rows' worth
    // choose the four terms of each rate; a half's 50 cannot choose among 66 candidates (they
    // chose 20 to 45 terms each, and the check named the true terms as uncertain): said so
    // where the halves chose otherwise
    let short = dir.join("l96_7s.csv").display().to_string();
    std::fs::write(&short, text.lines().take(701).collect::<Vec<_>>().join("\n") + "\n").unwrap();
    let (report, halves) = identify(&short, &["--degree", "2"]);
    assert!(halves["passed"] == false, "{halves}");
    let detail = halves["detail"].as_str().unwrap();
    assert!(detail.contains("not confirmed: their halves chose other terms, but a half holds"), "{halves}");
    assert!(!detail.contains("chosen from all the rows but not from both"), "{halves}");
    for i in 0..N {
        assert_eq!(terms_of(&report[&format!("x{i}_dot")]).len(), 4, "x{i}_dot: {report}");
    }
    let (report, halves) = identify(&data, &[]);
    let halves = halves["detail"].to_string();
    for i in 0..N {
        let equation = format!("x{i}_dot");
        let (a, b, c) = (format!("x{}", (i + N - 2) % N), format!("x{}", (i + N - 1) % N), (i + 1) % N);
        let (pair, plus) = (format!("{a}*{b}"), format!("x{}*{b}", c));
        // a product is written with its factors in the library's order
        let ordered = |t: &str| {
            let mut f: Vec<&str> = t.split('*').collect();
            f.sort_by_key(|v| v[1..].parse::<usize>().unwrap());
            f.join("*")
        };
        let truth =
            [(ordered(&pair), -1.0), (ordered(&plus), 1.0), ("1".to_string(), 8.0), (format!("x{i}"), -1.0)];
        let found = terms_of(&report[&equation]);
        for (term, value) in &truth {
            let got = found.get(term).unwrap_or_else(|| panic!("{equation}: {term} not in {found:?}"));
            assert!((got - value).abs() < 0.02 * value.abs(), "{equation}: {term} {got} for {value}");
        }
        // the halves check's terms for this equation: "`x2_dot`: `a`, `b`; `x5_dot`: …"
        let named =
            halves.split(&format!("`{equation}`: ")).nth(1).and_then(|s| s.split(';').next()).unwrap_or("");
        for term in found.keys().filter(|t| !truth.iter().any(|(u, _)| u == *t)) {
            assert!(named.contains(&format!("`{term}`")), "{equation}: {term} unsaid: {halves}");
        }
    }
}

/// Step tests of ẋ = −x/τ + K·u/τ (τ = 5 s, K = 2), the input held in each: from three at
/// u = 1, 2, 3 the equation is ẋ = 0.4 u − 0.2 x; from one at u = 2 the input cannot be told
/// from a constant (ẋ = 0.8 − 0.2 x, `u` left out as collinear): that is said, not left to a
/// note on collinearity, also where the runs are read in pieces.
#[test]
fn an_input_held_at_one_value_in_every_run_is_said() {
    use crate::common::{json, Scratch};
    let dir = Scratch::new("generic-held-input");
    let step = |u: f64| -> String {
        let mut text = String::from("t,x,u\n");
        for k in 0..300 {
            let t = k as f64 * 0.1;
            text += &format!("{t},{},{u}\n", 2.0 * u * (1.0 - (-t / 5.0).exp()));
        }
        let path = dir.join(format!("step{u}.csv")).display().to_string();
        std::fs::write(&path, text).unwrap();
        path
    };
    let steps: Vec<String> = [1.0, 2.0, 3.0].into_iter().map(step).collect();
    let identify = |runs: &[String]| {
        let mut args = vec!["identify", "--states", "x", "--format", "json"];
        for r in runs {
            args.extend(["--data", r.as_str()]);
        }
        let (ok, report, err) = termid(&args);
        assert!(ok, "{err}");
        json(&report)["x_dot"].clone()
    };
    let said = "`u` = 2 in every run: what it does cannot be told from a constant";
    let all = identify(&steps);
    let terms = terms_of(&all);
    assert!((terms["u"] - 0.4).abs() < 1e-3 && (terms["x"] + 0.2).abs() < 1e-3, "{terms:?}");
    assert!(!all["notes"].to_string().contains("in every run: what it does"), "{all}");
    let one = identify(&steps[1..2]);
    let terms = terms_of(&one);
    assert!((terms["1"] - 0.8).abs() < 1e-3 && !terms.contains_key("u"), "{terms:?}");
    assert!(one["notes"].to_string().contains(said), "{one}");
    // read in pieces, from statistics alone: said as well, and not of steps at several values
    let pieces = |runs: &[String]| {
        let mut args = vec!["identify", "--states", "x", "--chunk-rows", "100", "--format", "json"];
        for r in runs {
            args.extend(["--data", r.as_str()]);
        }
        let (ok, report, err) = termid(&args);
        assert!(ok, "{err}");
        json(&report)["x_dot"]["notes"].to_string()
    };
    assert!(pieces(&steps[1..2]).contains(said));
    assert!(!pieces(&steps).contains("in every run: what it does"));
    // the input recorded with a sensor's noise (±0.5 % of its value): said as held at its
    // mean (before, only the noise check's flag said anything); three such steps are not
    let mut rng = crate::common::Lcg(21);
    let noisy: Vec<String> = steps
        .iter()
        .map(|path| {
            let text = std::fs::read_to_string(path).unwrap();
            let mut out = String::from("t,x,u\n");
            for line in text.lines().skip(1) {
                let v: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
                out += &format!("{},{},{}\n", v[0], v[1], v[2] + 0.01 * rng.normal());
            }
            let noisy = path.replace(".csv", "_noisy.csv");
            std::fs::write(&noisy, out).unwrap();
            noisy
        })
        .collect();
    let about = "(varying by its noise alone) in every run: what it does cannot be told";
    let one = identify(&noisy[1..2])["notes"].to_string();
    assert!(one.contains(about) && one.contains("`u` ≈ 2.00"), "{one}");
    assert!(pieces(&noisy[1..2]).contains(about));
    assert!(!identify(&noisy)["notes"].to_string().contains("in every run: what it does"));
}

/// A short stretch of a motion, less than one period (Duffing's ẍ = −x − x³ − 0.1ẋ over 2 s
/// and 4 s with 1 % noise): the threshold path's support stood three terms of `v` in for
/// `v` itself in ẋ (0.80v² − 0.20v³ + 0.40 on the second half, where v stays in 1…2) and v²,
/// x² in for the damping of v̇, while forward selection found the true terms at a lower BIC
/// (by 3 to 6, under the margin that keeps forward selection from taking more terms than
/// the path): a support of fewer terms at a lower BIC is taken.
#[test]
fn a_short_stretch_of_a_motion_keeps_the_fewer_terms_that_fit_it() {
    use crate::common::{json, noise, noisy_frame, trajectory, Lcg, Scratch};
    let dir = Scratch::new("generic-short-duffing");
    for (samples, seed) in [(200, 3), (400, 5)] {
        let rows =
            trajectory(&[1.5, 0.0], 0.01, samples, 10, |_, x| vec![x[1], -x[0] - x[0].powi(3) - 0.1 * x[1]]);
        let sd = noise(&rows, 0.01);
        let name = format!("duffing{samples}.csv");
        noisy_frame(&name, 0.01, &["x", "v"], &rows, &sd, &mut Lcg(seed))
            .write_csv(&dir.join(&name))
            .unwrap();
        let (ok, out, err) = termid(&[
            "identify",
            "--data",
            &dir.join(&name).display().to_string(),
            "--states",
            "x,v",
            "--inputs",
            "--format",
            "json",
        ]);
        assert!(ok, "{err}");
        let found = json(&out);
        let terms = |eq: &str| crate::common::chosen_terms(&found[eq]);
        let x_dot = terms("x_dot");
        assert!(x_dot.len() == 1 && x_dot[0].0 == "v" && (x_dot[0].1 - 1.0).abs() < 0.01, "{samples}: {out}");
        let v_dot = terms("v_dot");
        let truth = [("v", -0.1), ("x", -1.0), ("x^3", -1.0)];
        assert_eq!(
            v_dot.iter().map(|t| t.0.as_str()).collect::<Vec<_>>(),
            truth.map(|t| t.0),
            "{samples}: {out}"
        );
        for ((_, got), (term, want)) in v_dot.iter().zip(truth) {
            assert!((got / want - 1.0).abs() < 0.05, "{samples}: {term} {got} for {want}");
        }
    }
}

/// A forced pendulum θ̈ = −sin θ − 0.1θ̇ + 0.5 cos 0.7t that goes over the top (2.7 turns in
/// 120 s), its angle read by atan2 in ±π: taken as recorded, θ leapt by 2π at eight rows, "too
/// often for records joined", and dθ/dt came out 0.644ω (5 % explained; from the cubic
/// library 1.58ω − 0.49ωθ²). Now θ is
/// found an angle on a dial and read as one continuous angle, said with the candidates that
/// hold a force turning with it; given them, the three true terms within 10⁻⁴.
#[test]
fn an_angle_that_wraps_on_a_dial_is_read_as_one_angle() {
    use crate::common::{chosen_terms, json, trajectory, Scratch};
    let force = |t: f64| 0.5 * (0.7 * t).cos();
    let rows = trajectory(&[0.0, 2.5], 0.02, 6000, 8, |t, x| vec![x[1], -x[0].sin() - 0.1 * x[1] + force(t)]);
    let mut csv = String::from("t,theta,omega,u\n");
    for (k, row) in rows.iter().enumerate() {
        let t = 0.02 * k as f64;
        csv += &format!("{t:?},{:?},{:?},{:?}\n", row[0].sin().atan2(row[0].cos()), row[1], force(t));
    }
    let dir = Scratch::new("generic-dial");
    let data = dir.join("pendulum.csv");
    std::fs::write(&data, csv).unwrap();
    let path = data.to_str().unwrap();
    let identify = |more: &[&str]| {
        termid(
            &[&["identify", "--data", path, "--states", "theta,omega", "--inputs", "u"][..], more].concat(),
        )
    };
    let (ok, out, err) =
        identify(&["--terms", "sin(theta)", "cos(theta)", "theta", "omega", "u", "--format", "json"]);
    assert!(ok, "{err}");
    assert!(
        err.contains("`theta` stays within 2π and jumps by about that at 8 rows")
            && err.contains("read as one continuous angle, in radians")
            && err.contains("sin(theta) and cos(theta) among the candidates")
            && !err.contains("leaps"),
        "{err}"
    );
    let found = json(&out);
    for (rate, want) in [
        ("theta_dot", &[("omega", 1.0)][..]),
        ("omega_dot", &[("omega", -0.1), ("sin(theta)", -1.0), ("u", 1.0)]),
    ] {
        let got = chosen_terms(&found[rate]);
        assert_eq!(got.len(), want.len(), "{rate}: {got:?}");
        for ((term, c), (name, truth)) in got.iter().zip(want) {
            assert!(term == name && (c - truth).abs() < 1e-4, "{term} {c}: {out}");
        }
    }
    // read in pieces of 10 s, each unwrapped on its own and laid onto the one before by whole
    // turns: the same angle as read whole, so a candidate polynomial in it and the run
    // re-simulated over 2.7 turns agree (the pieces' record jumped by 2π every 10 s, and the
    // re-simulation "followed" it for 10 s where the whole run is followed for 93)
    let read = |more: &[&str]| {
        let args = [
            &["--derivative", "central", "--terms", "sin(theta)", "cos(theta)", "theta", "theta^2"][..],
            &["omega", "u", "--format", "json"],
            more,
        ]
        .concat();
        let (ok, out, err) = identify(&args);
        assert!(ok, "{err}");
        let found = json(&out);
        let retrace = crate::common::check_named(&found, "retrace their runs")["detail"].clone();
        (chosen_terms(&found["omega_dot"]), retrace)
    };
    let (whole, pieces) = (read(&[]), read(&["--chunk-rows", "500"]));
    assert_eq!(whole.1, pieces.1);
    assert_eq!(whole.0.len(), pieces.0.len(), "{whole:?} {pieces:?}");
    for ((a, x), (b, y)) in whole.0.iter().zip(&pieces.0) {
        assert!(a == b && (x - y).abs() < 1e-6, "{whole:?} {pieces:?}");
    }
}

/// Lorenz logged with jittered timestamps (each sample 8-12 ms after the last, as a logger
/// on events stamps them; the states read exactly at those times): evened onto the median
/// step by the cubic through the four nearest samples, said, and every true term within
/// 10⁻⁴ (a line between the samples left y's damping 0.6 % off).
#[test]
fn a_log_with_jittered_timestamps_is_evened_by_cubics() {
    use crate::common::{chosen_terms, json, lorenz_rows, Lcg, Scratch};
    let fine = lorenz_rows(0.001, 20_001);
    let mut rng = Lcg(31);
    let (mut csv, mut k) = (String::from("t,x,y,z\n"), 0usize);
    while k < fine.len() {
        let row = &fine[k];
        csv += &format!("{:?},{:?},{:?},{:?}\n", 0.001 * k as f64, row[0], row[1], row[2]);
        k += 8 + (rng.next() * 5.0) as usize;
    }
    let dir = Scratch::new("generic-jitter");
    let data = dir.join("logged.csv");
    std::fs::write(&data, csv).unwrap();
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        data.to_str().unwrap(),
        "--states",
        "x,y,z",
        "--inputs",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("samples not evenly spaced") && err.contains("by the cubic through"), "{err}");
    let found = json(&out);
    let truths: [(&str, &[(&str, f64)]); 3] = [
        ("x_dot", &[("x", -10.0), ("y", 10.0)]),
        ("y_dot", &[("x", 28.0), ("x*z", -1.0), ("y", -1.0)]),
        ("z_dot", &[("x*y", 1.0), ("z", -8.0 / 3.0)]),
    ];
    for (rate, want) in truths {
        let got = chosen_terms(&found[rate]);
        assert_eq!(got.len(), want.len(), "{rate}: {got:?}");
        for ((term, c), (name, truth)) in got.iter().zip(want) {
            assert!(term == name && (c - truth).abs() < 1e-4 * truth.abs(), "{term} {c}: {out}");
        }
    }
}

/// A run read in pieces (`--chunk-rows`, as files beyond 256 MiB are by default) is checked on
/// its halves as a run read whole: ẋ = −x + u with u acting over the first 8 s of 20 only, so
/// that the second half cannot choose `u`: named alike whole, in pieces of 97 rows (the run's
/// middle inside a piece) and from statistics written apart (`termid moments`); with u acting
/// throughout, passed. The pieces printed the fit with no check of its halves at all.
#[test]
fn a_run_read_in_pieces_is_checked_on_its_halves() {
    use crate::common::{check_named, json, Scratch};
    let dir = Scratch::new("generic-halves-in-pieces");
    // exact samples of ẋ = −x + u by fine Euler steps, every 0.05 s over 20 s
    let write = |name: &str, u: &dyn Fn(f64) -> f64| -> String {
        let (dt, fine) = (0.05, 200);
        let (mut x, mut t, mut text) = (0.5, 0.0, String::from("t,x,u\n"));
        for k in 0..400 {
            text += &format!("{},{x},{}\n", k as f64 * dt, u(k as f64 * dt));
            for _ in 0..fine {
                x += dt / fine as f64 * (-x + u(t));
                t += dt / fine as f64;
            }
        }
        let path = dir.join(name).display().to_string();
        std::fs::write(&path, text).unwrap();
        path
    };
    let early = write("early.csv", &|t| if t < 8.0 { (0.7 * t).sin() * (1.0 - t / 8.0) } else { 0.0 });
    let throughout = write("throughout.csv", &|t| (0.7 * t).sin() + 0.3 * (1.9 * t).cos());
    let halves = |data: &str, more: &[&str]| -> (serde_json::Value, String) {
        let args =
            [&["identify", "--data", data, "--states", "x", "--inputs", "u", "--format", "json"], more]
                .concat();
        let (ok, report, err) = termid(&args);
        assert!(ok, "{err}");
        let report = json(&report);
        let terms: Vec<&str> = report["x_dot"]["terms"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["term"].as_str().unwrap())
            .collect();
        assert_eq!(terms, ["u", "x"], "{report}");
        (check_named(&report, "the terms hold on each half").clone(), err)
    };
    let pieces = ["--derivative", "central", "--chunk-rows", "97"];
    for (more, how) in [(&[][..], "whole"), (&pieces[..], "in pieces")] {
        let (check, err) = halves(&early, more);
        assert!(check["passed"] == false, "{how}: {check}");
        assert!(check["detail"].as_str().unwrap().contains("`x_dot`: `u`"), "{how}: {check}");
        let (check, _) = halves(&throughout, more);
        assert!(check["passed"] == true, "{how}: {check}{err}");
    }
    // statistics written apart, then identified: the halves travel with them
    let model = dir.join("lag.toml").display().to_string();
    let (ok, _, err) =
        termid(&["identify", "--data", &early, "--states", "x", "--inputs", "u", "--out", &model]);
    assert!(ok, "{err}");
    let moments = dir.join("x.json").display().to_string();
    let (ok, _, err) = termid(
        &[
            &["moments", "--model", &model, "--data", &early, "--equation", "x_dot", "--out", &moments],
            &pieces[..],
        ]
        .concat(),
    );
    assert!(ok, "{err}");
    let (ok, report, err) =
        termid(&["identify", "--model", &model, "--moments", &moments, "--format", "json"]);
    assert!(ok && err.contains("whether the equations retrace their runs is not checked"), "{err}");
    let check = check_named(&json(&report), "the terms hold on each half").clone();
    assert!(
        check["passed"] == false && check["detail"].as_str().unwrap().contains("`x_dot`: `u`"),
        "{check}"
    );
}

/// A run read in pieces is re-simulated as a run read whole is, from a copy kept as at most
/// 20 000 rows (each the average of as many consecutive rows): Lotka-Volterra sampled ten
/// times a period, its rates from the integral form in pieces of 10 rows, runs away (as read
/// whole) and is refused, not written; the pieces wrote it, every check "ok". A run of 60 000
/// rows of ẋ = −x + u kept as averages is followed throughout.
#[test]
fn equations_that_run_away_from_a_run_read_in_pieces_are_refused() {
    use crate::common::{check_named, json, Scratch};
    let dir = Scratch::new("generic-run-away-in-pieces");
    let p = |f: &str| dir.join(f).display().to_string();
    // x' = x − 0.5xz, z' = −1.5z + 0.25xz from (4, 1), by RK4 steps of 1 ms, every 0.5 s
    let (mut s, h) = ([4.0f64, 1.0], 0.001);
    let f = |s: [f64; 2]| [s[0] - 0.5 * s[0] * s[1], -1.5 * s[1] + 0.25 * s[0] * s[1]];
    let mut text = String::from("t,x,z\n");
    for k in 0..40 {
        text += &format!("{},{},{}\n", k as f64 * 0.5, s[0], s[1]);
        for _ in 0..500 {
            let add = |a: [f64; 2], b: [f64; 2], c: f64| [a[0] + c * b[0], a[1] + c * b[1]];
            let k1 = f(s);
            let k2 = f(add(s, k1, h / 2.0));
            let k3 = f(add(s, k2, h / 2.0));
            let k4 = f(add(s, k3, h));
            s = [0, 1].map(|i| s[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
        }
    }
    std::fs::write(p("coarse.csv"), text).unwrap();
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        &p("coarse.csv"),
        "--states",
        "x,z",
        "--derivative",
        "integral",
        "--chunk-rows",
        "10",
        "--out",
        &p("m.toml"),
    ]);
    assert!(!ok && out.contains("FAIL the equations retrace their runs without running away"), "{out}{err}");
    assert!(err.contains("not written") && !dir.join("m.toml").exists(), "{err}");
    // a long run kept as averages of three or more rows each
    let (mut x, mut text) = (0.5, String::from("t,x,u\n"));
    for k in 0..60_000 {
        let t = k as f64 * 0.01;
        let u = (0.7 * t).sin() + 0.3 * (1.9 * t).cos();
        text += &format!("{t},{x},{u}\n");
        for j in 0..10 {
            let t = t + j as f64 * 0.001;
            x += 0.001 * (-x + (0.7 * t).sin() + 0.3 * (1.9 * t).cos());
        }
    }
    std::fs::write(p("long.csv"), text).unwrap();
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        &p("long.csv"),
        "--states",
        "x",
        "--inputs",
        "u",
        "--derivative",
        "central",
        "--chunk-rows",
        "5000",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let retrace = check_named(&json(&out), "retrace their runs").clone();
    assert!(
        retrace["passed"] == true && retrace["detail"].as_str().unwrap().ends_with("throughout"),
        "{retrace}"
    );
}

/// A motion seen in one coordinate: the forced oscillator ẍ = −2x − 0.3ẋ + F recorded by its
/// position alone (`--states x`), so that no rate of x is a function of x and F. The best the
/// library does explains 14 % of ẋ (said in a note), stays bounded and followed its run for
/// 1.0 s of 60 s with every check "ok". Now the equations' own motion, started a hundredth of
/// x's span off, follows itself throughout, so the run is not lost to chaos: flagged, not
/// refused (the model is written). With v recorded too, the same check passes.
#[test]
fn a_motion_seen_in_one_coordinate_is_flagged_as_missed() {
    use crate::common::{check_named, json, trajectory, Scratch};
    let dir = Scratch::new("one-coordinate");
    let force = |t: f64| (0.5 * t).sin() + 0.3 * (1.7 * t + 1.0).sin();
    let mut text = String::from("t,x,v,F\n");
    let rows =
        trajectory(&[0.0, 0.0], 0.05, 1_200, 10, |t, x| vec![x[1], -2.0 * x[0] - 0.3 * x[1] + force(t)]);
    for (i, r) in rows.iter().enumerate() {
        let t = i as f64 * 0.05;
        text += &format!("{t},{},{},{}\n", r[0], r[1], force(t));
    }
    let data = dir.join("run.csv");
    std::fs::write(&data, text).unwrap();
    let out = dir.join("x.toml");
    let identified = |states: &str, out: &std::path::Path| {
        let (ok, report, err) = termid(&[
            "identify",
            "--data",
            data.to_str().unwrap(),
            "--states",
            states,
            "--inputs",
            "F",
            "--out",
            out.to_str().unwrap(),
            "--format",
            "json",
        ]);
        assert!(ok, "{err}");
        json(&report)
    };
    let position = identified("x", &out);
    assert_eq!(check_named(&position, "retrace")["passed"], true, "{position}");
    let missed = check_named(&position, "as long as their own motion allows");
    assert!(missed["passed"] == false && missed["refuses"] == false, "{missed}");
    let said = missed["detail"].as_str().unwrap();
    assert!(said.contains("follows itself throughout") && said.contains("the equations miss it"), "{said}");
    assert!(out.exists());
    let both = identified("x,v", &dir.join("xv.toml"));
    assert_eq!(check_named(&both, "as long as their own motion allows")["passed"], true, "{both}");
}

/// A dozen samples of a decay, ẋ = −0.3x, taken at 0.25, 0.5, 1, 2 … 24 h (a pharmacokinetic
/// study's): read as an irregular log, not cut at its three long intervals (it was refused:
/// "9 rows are too few for a run between its gaps"); and its rows too few to halve, the halves
/// check says it did not check the terms (it was left out, every check reading "ok" beside the
/// cubic's spurious terms).
#[test]
fn a_dozen_irregular_samples_are_read_and_their_terms_said_unconfirmed() {
    use crate::common::Scratch;
    let dir = Scratch::new("generic-dozen");
    let mut text = String::from("t,x\n");
    for t in [0.0, 0.25, 0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0] {
        text += &format!("{t},{}\n", 10.0 * f64::exp(-0.3 * t));
    }
    let data = dir.join("dozen.csv");
    std::fs::write(&data, text).unwrap();
    let (ok, out, err) = termid(&["identify", "--data", data.to_str().unwrap(), "--states", "x"]);
    assert!(ok, "{err}");
    assert!(err.contains("a log sampled on events, not a clock with dropouts: not cut"), "{err}");
    assert!(
        out.contains("FLAG the terms hold on each half of the runs: not checked: the runs' ")
            && out.contains(" rows are too few to halve"),
        "{out}"
    );
}

/// A spreadsheet's "Unicode text" export: UTF-16 (little-endian, with its byte-order mark),
/// tab-separated. It was refused at its first byte ("byte 3 is NUL: this is not a text
/// file"); now read as the same text in UTF-8, whole and in pieces, and in big-endian order.
#[test]
fn a_utf16_export_reads_as_its_text() {
    use crate::common::{json, Scratch};
    let dir = Scratch::new("generic-utf16");
    let mut text = String::from("t\tx\tv\n");
    for k in 0..2001 {
        let t = k as f64 * 0.01;
        text += &format!("{t}\t{}\t{}\n", (0.9 * t).sin(), 0.9 * (0.9 * t).cos());
    }
    let units: Vec<u16> = text.encode_utf16().collect();
    for (name, bytes) in [
        (
            "le.txt",
            [0xFF, 0xFE].into_iter().chain(units.iter().flat_map(|u| u.to_le_bytes())).collect::<Vec<u8>>(),
        ),
        ("be.txt", [0xFE, 0xFF].into_iter().chain(units.iter().flat_map(|u| u.to_be_bytes())).collect()),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let path = path.to_str().unwrap();
        for pieces in [&[][..], &["--chunk-rows", "500"]] {
            let args =
                [&["identify", "--data", path, "--states", "x,v", "--format", "json"], pieces].concat();
            let (ok, out, err) = termid(&args);
            assert!(ok, "{name}: {err}");
            let terms = &json(&out)["x_dot"]["terms"];
            assert!(
                terms[0]["term"] == "v" && (terms[0]["coefficient"].as_f64().unwrap() - 1.0).abs() < 1e-4,
                "{out}"
            );
        }
    }
}

/// A chain A → B → C of first-order reactions in mol/L (A from 1e-6, k₁ = 0.5/s, k₂ = 0.2/s;
/// B = A₀k₁/(k₂ − k₁)(e^(−k₁t) − e^(−k₂t))). The rates fit exactly, yet re-simulated with an
/// absolute tolerance of 1e-7 mol/L, a tenth of the states, the retrace check followed the
/// run for part of it and `simulate` ended A a hundredfold off: the tolerance is now counted in
/// how large the states run (the records' largest, the model's initial values).
#[test]
fn states_of_a_millionth_are_simulated_as_closely_as_states_of_one() {
    use crate::common::Scratch;
    let dir = Scratch::new("generic-micromolar");
    let (a0, k1, k2) = (1e-6, 0.5, 0.2);
    let a = |t: f64| a0 * (-k1 * t).exp();
    let b = |t: f64| a0 * k1 / (k2 - k1) * ((-k1 * t).exp() - (-k2 * t).exp());
    let mut text = String::from("t,A,B\n");
    for k in 0..=2000 {
        let t = k as f64 * 0.01;
        text += &format!("{t},{:e},{:e}\n", a(t), b(t));
    }
    let data = dir.join("chain.csv");
    std::fs::write(&data, text).unwrap();
    let model = dir.join("chain.toml");
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        data.to_str().unwrap(),
        "--states",
        "A,B",
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("ok   the equations retrace their runs without running away")
            && out.contains("within a tenth of each state's span throughout"),
        "{out}"
    );
    let (ok, out, err) = termid(&["simulate", "--model", model.to_str().unwrap(), "--duration", "20"]);
    assert!(ok, "{err}");
    for (name, exact) in [("A", a(20.0)), ("B", b(20.0))] {
        let line = out.lines().find(|l| l.trim_start().starts_with(&format!("{name} = "))).expect(&out);
        let value: f64 = line.split('=').nth(1).unwrap().trim().parse().unwrap();
        assert!((value / exact - 1.0).abs() < 1e-3, "{name} = {value}, exact {exact}\n{out}");
    }
}

/// A ball dropped from 2 m that bounces back at 0.8 of its speed (g = 9.81 m/s², the flights in
/// closed form, sampled at 100 Hz for 5 s). Its speed leaps at every bounce, which read as a
/// staircase "taken as recorded": the rates spiked there and the cubic library fitted
/// dv/dt = 45.9h² − 40.3h − 14.4h³ − 1.22 with every check "ok". The run is now cut at each
/// bounce into flights, said once, and the flights hold ḣ = v, v̇ = −9.81.
#[test]
fn a_bouncing_ball_is_identified_between_its_bounces() {
    use crate::common::{json, Scratch};
    let dir = Scratch::new("generic-ball");
    let g = 9.81;
    let v1 = (2.0 * g * 2.0f64).sqrt();
    let mut bounces = vec![(v1 / g, 0.8 * v1)];
    while bounces.last().unwrap().0 < 5.0 {
        let (t, v) = *bounces.last().unwrap();
        bounces.push((t + 2.0 * v / g, 0.8 * v));
    }
    let rows: Vec<Vec<f64>> = (0..=500)
        .map(|k| {
            let t = k as f64 * 0.01;
            let (h, v) = match bounces.iter().rev().find(|b| b.0 <= t) {
                Some(&(tb, vb)) => (vb * (t - tb) - 0.5 * g * (t - tb).powi(2), vb - g * (t - tb)),
                None => (2.0 - 0.5 * g * t * t, -g * t),
            };
            vec![t, h, v]
        })
        .collect();
    let write = |name: &str, share: f64| {
        let sd = crate::common::noise(&rows, share);
        let mut rng = crate::common::Lcg(7);
        let mut text = String::from("t,h,v\n");
        for r in &rows {
            let (h, v) = (r[1] + sd[1] * rng.normal(), r[2] + sd[2] * rng.normal());
            text += &format!("{},{h:e},{v:e}\n", r[0]);
        }
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    let data = write("ball.csv", 0.0);
    let (ok, out, err) =
        termid(&["identify", "--data", data.to_str().unwrap(), "--states", "h,v", "--format", "json"]);
    assert!(ok, "{err}");
    assert!(err.contains("`v` leaps at 9 rows and stays") && err.contains("a motion reset at each"), "{err}");
    let report = json(&out);
    let h = terms_of(&report["h_dot"]);
    let v = terms_of(&report["v_dot"]);
    assert!(h.len() == 1 && (h["v"] - 1.0).abs() < 1e-6, "{h:?}");
    assert!(v.len() == 1 && (v["1"] + g).abs() < 1e-6, "{v:?}");
    // with 1 % noise the last flight (22 rows, 0.06 m high) holds its height's noise at a tenth
    // of its span: followed "0.04 s of 0.21 s" and flagged, where a record is followed no
    // closer than its noise lets it be
    let noisy = write("noisy.csv", 0.01);
    let (ok, out, err) = termid(&["identify", "--data", noisy.to_str().unwrap(), "--states", "h,v"]);
    assert!(ok, "{err}");
    assert!(
        out.contains("(six of its noise's standard deviations, where more) throughout")
            && !out.contains("FLAG")
            && out.contains("- 9.8"),
        "{out}"
    );
}

/// An epidemic's day count and a pharmacokinetic study's hours: ẋ = −0.1x per day sampled daily
/// under `day`, ẋ = −0.3x per hour under `t [h]`. A `t [h]` was "no time column `t`" (hours
/// unknown), a time named `day` was read as seconds, every rate 86 400 times too fast, unsaid;
/// both are now read in seconds and said, and a file without `--time` names `day` as the time.
#[test]
fn days_and_hours_are_read_as_the_time_in_seconds() {
    use crate::common::{json, Scratch};
    let dir = Scratch::new("generic-days");
    for (header, rate, per, extra) in
        [("day", 0.1, 86400.0, &["--time", "day"][..]), ("t [h]", 0.3, 3600.0, &[][..])]
    {
        let mut text = format!("{header},x\n");
        for k in 0..=60 {
            text += &format!("{k},{}\n", 100.0 * (-rate * k as f64).exp());
        }
        let data = dir.join("decay.csv");
        std::fs::write(&data, text).unwrap();
        let mut args =
            vec!["identify", "--data", data.to_str().unwrap(), "--states", "x", "--format", "json"];
        args.extend_from_slice(extra);
        let (ok, out, err) = termid(&args);
        assert!(ok, "{header}: {err}");
        let said = format!("the time `{header}` read in seconds (× {per:.6e}): every rate is per second");
        assert!(err.contains(&said), "{header}: {err}");
        let terms = terms_of(&json(&out)["x_dot"]);
        assert!((terms["x"] * per / -rate - 1.0).abs() < 1e-3, "{header}: {terms:?}");
    }
    // the model of a study in hours keeps its time `t [h]`: simulated for 24 hours by
    // `--duration 24` (named `t`, it ran 24 seconds), its run written in hours
    let (model, run) = (dir.join("hours.toml"), dir.join("hours.csv"));
    let (ok, _, err) = termid(&[
        "identify",
        "--data",
        dir.join("decay.csv").to_str().unwrap(),
        "--states",
        "x",
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(std::fs::read_to_string(&model).unwrap().contains("time = \"t [h]\""));
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        model.to_str().unwrap(),
        "--initial",
        "x=100",
        "--duration",
        "24",
        "--sample",
        "1",
        "--out",
        run.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&run).unwrap();
    let last: Vec<f64> =
        text.lines().last().unwrap().split(',').take(2).map(|c| c.parse().unwrap()).collect();
    assert!(text.starts_with("t [h],x") && last[0] == 24.0, "{text}");
    assert!((last[1] / (100.0 * f64::exp(-0.3 * 24.0)) - 1.0).abs() < 1e-3, "{last:?}");
    let (ok, _, err) =
        termid(&["identify", "--data", dir.join("decay.csv").to_str().unwrap(), "--states", "x"]);
    assert!(ok, "{err}");
    std::fs::write(dir.join("days.csv"), "day,hours,x\n0,0,1\n1,24,0.9\n").unwrap();
    let (ok, _, err) =
        termid(&["identify", "--data", dir.join("days.csv").to_str().unwrap(), "--states", "x"]);
    assert!(!ok && err.contains("`day` looks like time: name it as the time column (`--time day`"), "{err}");
}

/// A model counted in days is simulated for days (`--duration 60` of an epidemic's day count
/// was 60 s, its run's `day` column ending at 6.9e-4), and records far from a ship's time
/// scale are re-simulated at their own sample interval: a decay counted daily took a control
/// step of 0.04 s (2 million a day), one sampled every 0.1 µs was refused ("the integration
/// step 0.04 s is too long for the shortest run").
#[test]
fn a_model_counted_in_days_is_simulated_in_days_and_records_at_their_own_step() {
    use crate::common::Scratch;
    let dir = Scratch::new("generic-day-steps");
    for (header, rate, extra) in [("day", 0.1, &["--time", "day"][..]), ("t", 1e5, &[][..])] {
        let step = if header == "day" { 1.0 } else { 1e-7 };
        let mut text = format!("{header},x\n");
        for k in 0..=60 {
            text += &format!("{},{}\n", k as f64 * step, 100.0 * (-rate * k as f64 * step).exp());
        }
        let (data, model) = (dir.join(format!("{header}.csv")), dir.join(format!("{header}.toml")));
        std::fs::write(&data, text).unwrap();
        let (data, model) = (data.to_str().unwrap(), model.to_str().unwrap());
        let mut args = vec!["identify", "--data", data, "--states", "x", "--out", model];
        args.extend_from_slice(extra);
        let (ok, _, err) = termid(&args);
        assert!(ok, "{header}: {err}");
        let (ok, out, err) = termid(&["validate", "--model", model, "--data", data]);
        assert!(ok, "{header}: {err}");
        let error: f64 = out.split("x ").nth(1).and_then(|s| s.split(' ').next()).unwrap().parse().unwrap();
        assert!(error < 0.01, "{header}: {out}");
    }
    let (model, run) = (dir.join("day.toml"), dir.join("run.csv"));
    let (ok, out, err) = termid(&[
        "simulate",
        "--model",
        model.to_str().unwrap(),
        "--duration",
        "60",
        "--sample",
        "1",
        "--out",
        run.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("the model's time `day` is counted in units of 8.640000e4 s"), "{err}");
    assert!(!err.contains("name its time `t`"), "{err}");
    assert!(out.contains("61 samples to day = 60.0000 (5.18400e6 s)"), "{out}");
    // a file written by hand in days would be read 86 400 times too fast: said, with the remedy
    let by_hand = dir.join("by_hand.toml");
    std::fs::write(
        &by_hand,
        "[model]\nname = \"decay\"\ntime = \"day\"\n[[states]]\nname = \"x\"\ninitial = 100.0\n\
         [equations.x_dot]\nstate = \"x\"\nidentify = false\ncoefficients = { \"x\" = -0.1 }\n",
    )
    .unwrap();
    let (ok, _, err) = termid(&["simulate", "--model", by_hand.to_str().unwrap(), "--duration", "1"]);
    assert!(ok && err.contains("where this file writes them per `day`, name its time `t`"), "{err}");
    let text = std::fs::read_to_string(&run).unwrap();
    let last: Vec<f64> = text.lines().last().unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(last[0], 60.0);
    assert!((last[1] / (100.0 * (-6.0f64).exp()) - 1.0).abs() < 1e-4, "{last:?}");
}

/// Newton's cooling logged as a lab writes it: `t [min]`, `T [°C]`. The temperature's unit was
/// "a unit termid does not read: write the column in SI units" (degrees Celsius are SI's own);
/// it is read as it is, its zero kept: dT/dt = −k·T + k·20 with k = 0.05 per minute.
#[test]
fn a_temperature_in_degrees_celsius_is_read_as_it_is() {
    use crate::common::{json, Scratch};
    let dir = Scratch::new("generic-celsius");
    let mut text = String::from("t [min],T [°C]\n");
    for k in 0..=120 {
        text += &format!("{k},{}\n", 20.0 + 70.0 * (-0.05 * k as f64).exp());
    }
    let data = dir.join("cooling.csv");
    std::fs::write(&data, text).unwrap();
    let (ok, out, err) =
        termid(&["identify", "--data", data.to_str().unwrap(), "--states", "T", "--format", "json"]);
    assert!(ok, "{err}");
    assert!(err.contains("`T [°C]` as T"), "{err}");
    let terms = terms_of(&json(&out)["T_dot"]);
    assert!((terms["T"] * 60.0 / -0.05 - 1.0).abs() < 1e-4, "{terms:?}");
    assert!((terms["1"] * 60.0 / (0.05 * 20.0) - 1.0).abs() < 1e-4, "{terms:?}");
}

/// A model's runs whose time is a column `time` (as most loggers and dataframes name it) were
/// refused by the model's commands ("name it as the time column (`--time time`…)", an option
/// `validate` does not have); the one column named as a time is the model's time, said.
#[test]
fn a_model_s_commands_take_a_file_s_one_time_column() {
    use crate::common::Scratch;
    let dir = Scratch::new("generic-time-column");
    let (mut by_t, mut by_time) = (String::from("t,x\n"), String::from("time,x\n"));
    for k in 0..=200 {
        let (t, x) = (k as f64 * 0.05, (-0.3 * k as f64 * 0.05).exp());
        by_t += &format!("{t},{x}\n");
        by_time += &format!("{t},{x}\n");
    }
    let (a, b, model) = (dir.join("a.csv"), dir.join("b.csv"), dir.join("m.toml"));
    std::fs::write(&a, by_t).unwrap();
    std::fs::write(&b, &by_time).unwrap();
    let (a, b, model) = (a.to_str().unwrap(), b.to_str().unwrap(), model.to_str().unwrap());
    let (ok, _, err) = termid(&["identify", "--data", a, "--states", "x", "--out", model]);
    assert!(ok, "{err}");
    let (ok, out, err) = termid(&["validate", "--model", model, "--data", b]);
    assert!(ok, "{err}");
    assert!(err.contains("the time `t` is column `time`, the one whose name says it is the time"), "{err}");
    let error: f64 = out.split("x ").nth(1).and_then(|s| s.split(' ').next()).unwrap().parse().unwrap();
    assert!(error < 1e-4, "{out}");
    // beside another such column, neither is taken
    std::fs::write(dir.join("c.csv"), "time,seconds,x\n0,0,1\n1,1,0.74\n").unwrap();
    let (ok, _, err) = termid(&["validate", "--model", model, "--data", dir.join("c.csv").to_str().unwrap()]);
    assert!(!ok && err.contains("no time column `t`"), "{err}");
}

/// A pharmacokinetic study: an oral dose absorbed at ka = 1.2 /h from the gut (A) into the
/// plasma (C), eliminated at ke = 0.15 /h, sampled on the usual schedule (0, 0.25, 0.5, 1 …
/// 24 h) in three subjects of doses 100, 200 and 400. The closed form is the truth: C =
/// D·ka/(ka − ke)·(e^(−ke·t) − e^(−ka·t)). The runs were evened onto their median step (1 h),
/// which lost the absorption, and 400's C read as an angle on a dial (0 → 256 at its first
/// hour, within 360): dC/dt came out as −0.0015 + 5.7e-6·C − 8.3e-5·A. Now every sample is kept,
/// the two rates come back within 1 %; a model file that declares its rates `1/h` is told
/// they are read per second; and a state nobody measures (the gut's A) starts each run at its
/// dose (`per_run = "first:dose"`), from which `estimate` finds ka and ke on C alone.
#[test]
fn a_dose_sampled_on_a_schedule_gives_its_absorption_and_elimination() {
    use crate::common::{json, Scratch};
    let dir = Scratch::new("generic-pk");
    let (ka, ke) = (1.2, 0.15);
    let hours = [0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0];
    // each subject's gut and plasma, and the plasma alone (as a study measures it)
    let (mut files, mut plasma) = (Vec::new(), Vec::new());
    for dose in [100.0, 200.0, 400.0] {
        let (mut both, mut alone) = (String::from("t [h],A,C,dose\n"), String::from("t [h],C,dose\n"));
        for h in hours {
            let a = dose * f64::exp(-ka * h);
            let c = dose * ka / (ka - ke) * (f64::exp(-ke * h) - f64::exp(-ka * h));
            both += &format!("{h},{a},{c},{dose}\n");
            alone += &format!("{h},{c},{dose}\n");
        }
        for (text, list, name) in [(both, &mut files, "both"), (alone, &mut plasma, "plasma")] {
            let path = dir.join(format!("{name}{dose}.csv"));
            std::fs::write(&path, text).unwrap();
            list.push(path.to_str().unwrap().to_string());
        }
    }
    let mut args =
        vec!["identify", "--states", "A,C", "--inputs", "", "--degree", "1", "--format", "json", "--data"];
    args.extend(files.iter().map(String::as_str));
    let (ok, out, err) = termid(&args);
    assert!(ok, "{err}");
    assert!(
        err.contains("its shortest step, 900 s, on which every sample lies") && !err.contains("angle"),
        "{err}"
    );
    let report = json(&out);
    let (a, c) = (terms_of(&report["A_dot"]), terms_of(&report["C_dot"]));
    let per_hour = |v: f64| v * 3600.0;
    assert!(a.len() == 1 && (per_hour(a["A"]) / -ka - 1.0).abs() < 0.01, "{a:?}");
    assert!(c.len() == 2 && (per_hour(c["A"]) / ka - 1.0).abs() < 0.01, "{c:?}");
    assert!((per_hour(c["C"]) / -ke - 1.0).abs() < 0.01, "{c:?}");
    // the plasma alone, the gut starting at each run's dose, the rates started 60 % low
    let model = |ka: f64, ke: f64, unit: &str| {
        format!(
            "[model]\nname = \"one compartment, oral\"\n\n[[states]]\nname = \"A\"\nper_run = \"first:dose\"\n\n[[states]]\nname = \"C\"\n\n[[inputs]]\nname = \"dose\"\n\n[parameters.ka]\nvalue = {ka}\nunit = \"{unit}\"\nfree = true\nbounds = [0.0, 100.0]\n\n[parameters.ke]\nvalue = {ke}\nunit = \"{unit}\"\nfree = true\nbounds = [0.0, 100.0]\n\n[equations.A_dot]\nstate = \"A\"\nidentify = false\ncoefficients = {{ \"ka*A\" = -1.0 }}\n\n[equations.C_dot]\nstate = \"C\"\nidentify = false\ncoefficients = {{ \"ka*A\" = 1.0, \"ke*C\" = -1.0 }}\n"
        )
    };
    let (hourly, per_second) = (dir.join("pk_h.toml"), dir.join("pk.toml"));
    std::fs::write(&hourly, model(0.5, 0.06, "1/h")).unwrap();
    std::fs::write(&per_second, model(0.5 / 3600.0, 0.06 / 3600.0, "1/s")).unwrap();
    let estimate = |model: &std::path::Path| {
        let mut args = vec![
            "estimate",
            "--model",
            model.to_str().unwrap(),
            "--states",
            "C",
            "--format",
            "json",
            "--data",
        ];
        args.extend(plasma.iter().map(String::as_str));
        termid(&args)
    };
    let (_, _, err) = estimate(&hourly);
    assert!(
        err.contains(
            "parameter `ka` is declared in `1/h`, but a model file's values are SI, time in seconds"
        ) && err.contains("write `value = 1.38889e-4` and `unit = \"1/s\"`"),
        "{err}"
    );
    let (ok, out, err) = estimate(&per_second);
    assert!(ok, "{err}");
    assert!(!err.contains("declared in"), "{err}");
    let report = json(&out);
    let value = |name: &str| {
        report["parameters"].as_array().unwrap().iter().find(|p| p["name"] == name).unwrap()["value"]
            .as_f64()
            .unwrap()
            * 3600.0
    };
    assert!((value("ka") / ka - 1.0).abs() < 0.01 && (value("ke") / ke - 1.0).abs() < 0.01, "{out}");
    // at the times each sample was actually drawn (0.27 h for 0.25, 1.05 for 1 …), of no common
    // step: on the median step the absorption was lost again; on half the shortest interval,
    // each sample compared at its own row, within 0.5 %
    let actual = [0.0, 0.27, 0.52, 1.05, 1.48, 2.03, 3.1, 3.95, 6.05, 8.1, 12.2, 15.9, 24.1];
    for (k, dose) in [100.0, 200.0, 400.0].into_iter().enumerate() {
        let mut text = String::from("t [h],C,dose\n");
        for h in actual {
            text +=
                &format!("{h},{},{dose}\n", dose * ka / (ka - ke) * (f64::exp(-ke * h) - f64::exp(-ka * h)));
        }
        std::fs::write(&plasma[k], text).unwrap();
    }
    let (ok, out, err) = estimate(&per_second);
    assert!(ok && err.contains("half its shortest interval"), "{err}");
    let report = json(&out);
    let value = |name: &str| {
        report["parameters"].as_array().unwrap().iter().find(|p| p["name"] == name).unwrap()["value"]
            .as_f64()
            .unwrap()
            * 3600.0
    };
    assert!((value("ka") / ka - 1.0).abs() < 0.005 && (value("ke") / ke - 1.0).abs() < 0.005, "{out}");
    // with an assay's noise (σ = 2 on C), ten studies: the estimates scatter as their standard
    // errors say. Compared at every row of the even grid (seven of eight rows the cubic's
    // between samples, counted as samples) the errors were half the scatter; at the samples
    // only, about it (widened by the residuals' correlation time)
    let mut rng = crate::common::Lcg(7);
    let mut studies: Vec<[(f64, f64); 2]> = Vec::new();
    for _ in 0..10 {
        for (k, dose) in [100.0, 200.0, 400.0].into_iter().enumerate() {
            let mut text = String::from("t [h],C,dose\n");
            for h in hours {
                let c = dose * ka / (ka - ke) * (f64::exp(-ke * h) - f64::exp(-ka * h));
                let noise = if h > 0.0 { 2.0 * rng.normal() } else { 0.0 };
                text += &format!("{h},{},{dose}\n", c + noise);
            }
            std::fs::write(&plasma[k], text).unwrap();
        }
        let (ok, out, err) = estimate(&per_second);
        assert!(ok, "{err}");
        let report = json(&out);
        assert_eq!(report["noise_unread"], 3, "{out}");
        let of = |name: &str| {
            let p = report["parameters"].as_array().unwrap().iter().find(|p| p["name"] == name).unwrap();
            (3600.0 * p["value"].as_f64().unwrap(), 3600.0 * p["std_error"].as_f64().unwrap())
        };
        studies.push([of("ka"), of("ke")]);
    }
    for (j, truth) in [ka, ke].into_iter().enumerate() {
        let n = studies.len() as f64;
        let mean = studies.iter().map(|s| s[j].0).sum::<f64>() / n;
        let sd = (studies.iter().map(|s| (s[j].0 - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let error = studies.iter().map(|s| s[j].1).sum::<f64>() / n;
        assert!((mean / truth - 1.0).abs() < 0.015, "{j}: mean {mean}");
        assert!(error > 0.7 * sd && error < 3.0 * sd, "{j}: standard error {error}, scatter {sd}");
    }
}

/// A DC motor (L di/dt = V − R i − K ω, J dω/dt = K i − b ω) logged as a bench logger heads
/// its columns (`V [V]`, `i [A]`, `w [rpm]`), the voltage stepped every 0.2 s and logged a
/// sample late at some of its steps (the command switched just after a sample): the columns
/// were refused ("a unit termid does not read"), and with the voltage taken as held from each
/// sample every coefficient of di/dt came out 1.2 % high. Read as their headers say (rpm as
/// written) and the steps held misfits left out of the fit, the coefficients come back exact.
#[test]
fn a_motor_logged_with_its_units_and_late_steps_is_identified_exactly() {
    use crate::common::{json, Scratch};
    let dir = Scratch::new("generic-motor");
    let (r, l, k, j, b) = (2.0, 0.005, 0.05, 2e-4, 1e-4);
    let rpm = 60.0 / std::f64::consts::TAU;
    let rate = |i: f64, w: f64, v: f64| [(v - r * i - k * w) / l, (k * i - b * w) / j];
    let (h, n) = (1e-4, 20_000);
    let mut files = Vec::new();
    for (run, levels) in [
        [5.0, -8.0, 11.0, -3.0, 9.0, -12.0, 2.0, 7.0, -6.0, 10.0],
        [-4.0, 9.0, -11.0, 6.0, 1.0, -7.0, 12.0, -2.0, 8.0, -9.0],
    ]
    .iter()
    .enumerate()
    {
        // the voltage acting over each interval: the level of its 0.2 s, switched a sample
        // early (the log a sample late) at the third and sixth steps
        let level = |s: usize| levels[(s / 2000).min(9)];
        let acting = |s: usize| if s == 3 * 2000 - 1 || s == 6 * 2000 - 1 { level(s + 1) } else { level(s) };
        let (mut i, mut w) = (0.0, 0.0);
        let mut text = String::from("t [s],V [V],i [A],w [rpm]\n");
        for s in 0..n {
            text += &format!("{:.4},{},{i:.10e},{:.10e}\n", s as f64 * h, level(s), w * rpm);
            // RK4 in 20 steps an interval: exact to rounding for a time constant of 25 intervals
            let (v, dt) = (acting(s), h / 20.0);
            for _ in 0..20 {
                let k1 = rate(i, w, v);
                let k2 = rate(i + 0.5 * dt * k1[0], w + 0.5 * dt * k1[1], v);
                let k3 = rate(i + 0.5 * dt * k2[0], w + 0.5 * dt * k2[1], v);
                let k4 = rate(i + dt * k3[0], w + dt * k3[1], v);
                i += dt / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]);
                w += dt / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]);
            }
        }
        let path = dir.join(format!("motor{run}.csv"));
        std::fs::write(&path, text).unwrap();
        files.push(path.to_str().unwrap().to_string());
    }
    let mut args =
        vec!["identify", "--states", "i,w", "--inputs", "V", "--degree", "1", "--format", "json", "--data"];
    args.extend(files.iter().map(String::as_str));
    let (ok, out, err) = termid(&args);
    assert!(ok, "{err}");
    assert!(
        err.contains("`i [A]` as i, `w [rpm]` as w in rpm as written (a unit termid does not convert)"),
        "{err}"
    );
    assert!(
        err.contains("held misfits a state's rate at 2 of the 9 windows")
            && err.contains("those 2 jumps moved to the sample before (at t = 0.5999, 1.1999)"),
        "{err}"
    );
    let report = json(&out);
    let (di, dw) = (terms_of(&report["i_dot"]), terms_of(&report["w_dot"]));
    let near = |got: f64, want: f64| (got / want - 1.0).abs() < 1e-3;
    assert!(di.len() == 3 && near(di["V"], 1.0 / l) && near(di["i"], -r / l), "{di:?} {err}");
    assert!(near(di["w"], -k / l / rpm), "{di:?}");
    assert!(dw.len() == 2 && near(dw["i"], k / j * rpm) && near(dw["w"], -b / j), "{dw:?}");
    // the motor's own parameters by output error, started twice too large, from the replay of
    // the voltage held with its late steps moved (a line across them left L 0.7 % high)
    let model = format!(
        "[model]\nname = \"DC motor\"\nintercept = false\n\n[[states]]\nname = \"i\"\nunit = \"A\"\n\n[[states]]\nname = \"w\"\nunit = \"rpm\"\n\n[[inputs]]\nname = \"V\"\nunit = \"V\"\n\n[parameters.R]\nvalue = 4.0\nfree = true\nbounds = [0.0, 100.0]\n\n[parameters.L]\nvalue = 0.01\nfree = true\nbounds = [1e-5, 1.0]\n\n[parameters.K]\nvalue = 0.1\nfree = true\nbounds = [0.0, 10.0]\n\n[parameters.J]\nvalue = 4e-4\nfree = true\nbounds = [1e-6, 1.0]\n\n[parameters.b]\nvalue = 2e-4\nfree = true\nbounds = [0.0, 1.0]\n\n[equations.i_dot]\nstate = \"i\"\nidentify = false\ncoefficients = {{ \"V/L\" = 1.0, \"R*i/L\" = -1.0, \"K*w/L\" = {} }}\n\n[equations.w_dot]\nstate = \"w\"\nidentify = false\ncoefficients = {{ \"K*i/J\" = {rpm}, \"b*w/J\" = -1.0 }}\n",
        -1.0 / rpm
    );
    let path = dir.join("motor.toml");
    std::fs::write(&path, model).unwrap();
    let mut args = vec!["estimate", "--model", path.to_str().unwrap(), "--format", "json", "--data"];
    args.extend(files.iter().map(String::as_str));
    let (ok, out, err) = termid(&args);
    assert!(ok, "{err}");
    let report = json(&out);
    for (name, truth) in [("R", r), ("L", l), ("K", k), ("J", j), ("b", b)] {
        let found = report["parameters"].as_array().unwrap().iter().find(|p| p["name"] == name).unwrap();
        let value = found["value"].as_f64().unwrap();
        assert!(near(value, truth), "{name}: {value} for {truth}\n{out}");
    }
}

/// A census of hares and lynx read yearly for 60 years (Lotka-Volterra, ẋ = 0.55x − 0.028xy,
/// ẏ = 0.024xy − 0.8y per year; ten samples a cycle, no noise at all): the lynx record's sharp
/// peaks passed for noise of "at least 53 %" of its spread, and a bound of 6.7 % on the hares'
/// passed as "under 2.0 %". The noise is now not told, and flagged so; the time, a column
/// `year`, read in seconds, said. The regression's six terms an equation (the weak form's
/// quadrature error explained by spurious ones) lost the run after 8 years: the terms are
/// chosen again by re-simulation and refined by output error at steps fine enough for the
/// cycle, back to the truth; read in pieces (no re-simulated choice there), the equations that
/// lose the run early name the rows' coarseness among the causes.
#[test]
fn a_yearly_census_claims_no_noise_it_cannot_see() {
    let dir = crate::common::Scratch::new("generic-census");
    let (mut x, mut y) = (30.0f64, 4.0f64);
    let rate = |x: f64, y: f64| (0.55 * x - 0.028 * x * y, 0.024 * x * y - 0.8 * y);
    let mut csv = String::from("year,hare,lynx\n");
    for year in 1900..=1960 {
        csv += &format!("{year},{x:.6},{y:.6}\n");
        for _ in 0..1000 {
            let h = 1e-3;
            let (a, b) = rate(x, y);
            let (c, d) = rate(x + 0.5 * h * a, y + 0.5 * h * b);
            let (e, f) = rate(x + 0.5 * h * c, y + 0.5 * h * d);
            let (g, i) = rate(x + h * e, y + h * f);
            x += h / 6.0 * (a + 2.0 * c + 2.0 * e + g);
            y += h / 6.0 * (b + 2.0 * d + 2.0 * f + i);
        }
    }
    let path = dir.join("census.csv");
    std::fs::write(&path, csv).unwrap();
    let census = |more: &[&str]| {
        let mut args =
            vec!["identify", "--data", path.to_str().unwrap(), "--states", "hare,lynx", "--degree", "2"];
        args.extend(more);
        let (ok, out, err) = termid(&args);
        assert!(ok, "{err}");
        (out, err)
    };
    let (out, err) = census(&[]);
    assert!(err.contains("the time `year` read in seconds (× 3.155760e7)"), "{err}");
    assert!(
        out.contains(
            "FLAG the records' noise leaves the terms unbiased: not told: white noise of `hare` at most"
        ) && !out.contains("`lynx` at least"),
        "{out}"
    );
    assert!(
        out.contains("note: terms chosen by re-simulation: the regression's (6 of `hare_dot`, 6 of `lynx_dot`) fit the rates but lose the runs; the best re-simulated terms, 2 of `hare_dot`, 2 of `lynx_dot`, follow them")
            && out.contains("ok   the equations follow their runs as long as their own motion allows"),
        "{out}"
    );
    let (out, _) = census(&["--format", "json"]);
    let report = crate::common::json(&out);
    assert_eq!(report["output_error_refinement"]["coefficients"].as_array().map(Vec::len), Some(4), "{out}");
    // per second in the model; per year here
    for (equation, term, truth) in [
        ("hare_dot", "hare", 0.55),
        ("hare_dot", "hare*lynx", -0.028),
        ("lynx_dot", "hare*lynx", 0.024),
        ("lynx_dot", "lynx", -0.8),
    ] {
        let value = refined(&report, equation, term).map(|v| v * 3.15576e7);
        assert!(value.is_some_and(|v| (v / truth - 1.0).abs() < 1e-3), "{equation} {term}: {value:?}\n{out}");
    }
    // read in pieces: the equations lose the run early, and among the causes, the rows' coarseness
    let (out, _) = census(&["--chunk-rows", "20"]);
    assert!(
        out.contains("or rows too coarse for the rates: `hare` 9.84, `lynx` 9.61 samples in a characteristic period, under 16"),
        "{out}"
    );
}

/// An oscillator ẍ = −4x − 0.4ẋ + w under a random force w (process noise of 0.3/√s, by
/// Euler-Maruyama at 1 ms), read every 0.02 s for 200 s with a sensor's noise of 0.5 % on
/// both: the weak form's windows take in the force they explain, and the terms come back
/// biased (here the spring −3.64 and no damping at all). `v`'s roughness is in `x`'s record
/// too (motion, not a sensor's noise), so the recipe identifies the system again by Itô's
/// steps: the damping within three standard errors (0.05 each) of the truth, said, and
/// written in the model file.
#[test]
fn a_random_force_is_found_and_its_damping_identified_unbiased() {
    use crate::common::{Lcg, Scratch};
    let dir = Scratch::new("generic-random-force");
    let mut draw = Lcg(29);
    let (h, every, steps) = (0.001, 20, 200_000);
    let (mut x, mut v, mut rows) = (1.0_f64, 0.0_f64, Vec::new());
    for k in 0..steps {
        if k % every == 0 {
            rows.push((k as f64 * h, x, v));
        }
        let a = -4.0 * x - 0.4 * v;
        x += h * v;
        v += h * a + 0.3 * h.sqrt() * draw.normal();
    }
    let mut text = String::from("t,x,v\n");
    for (t, x, v) in &rows {
        text += &format!("{t:.3},{},{}\n", x + 0.005 * 0.3 * draw.normal(), v + 0.005 * 0.4 * draw.normal());
    }
    let data = dir.join("forced.csv");
    std::fs::write(&data, text).unwrap();
    let data = data.to_str().unwrap();
    let damping = |extra: &[&str]| {
        let mut args = vec!["identify", "--data", data, "--states", "x,v", "--format", "json"];
        args.extend_from_slice(extra);
        let (ok, out, err) = termid(&args);
        assert!(ok, "{err}");
        let terms = crate::common::chosen_terms(&crate::common::json(&out)["v_dot"]);
        let of = |term: &str| terms.iter().find(|(t, _)| t == term).map(|(_, c)| *c);
        (of("x"), of("v"), out.contains("a random force moves `v`"), terms)
    };
    let written = dir.join("forced.toml");
    let (spring, damping_ito, said, terms) = damping(&["--out", written.to_str().unwrap()]);
    assert!(said, "{terms:?}");
    // the model file says it too (simulated without the force, it follows the record in the mean)
    let file = std::fs::read_to_string(&written).unwrap();
    assert!(file.contains("a random force (process noise) moves `v`: identified by Itô's steps"), "{file}");
    assert!(spring.is_some_and(|c| (c + 4.0).abs() < 0.3), "{terms:?}");
    assert!(damping_ito.is_some_and(|c| (c + 0.4).abs() < 0.15), "{terms:?}");
    let (_, damping_weak, said, terms) = damping(&["--no-random-force"]);
    assert!(!said && damping_weak.is_none_or(|c| c > -0.3), "{terms:?}");
}

/// A first-order state under a random force (ẋ = −x + u + w, an Ornstein-Uhlenbeck process
/// under a held input, w of 0.2/√s, read every 0.02 s for 300 s): no other state's record holds
/// its roughness, so nothing tells a random force from a filtered sensor's noise; the weak form's
/// terms are biased (a decay short and spurious terms) and the recipe says that the roughness
/// grows as a Brownian path's, and which method a random force needs: `--derivative ito` gives
/// −x + u within three standard errors. A white sensor's noise of 1 % on the same motion
/// without the force draws no such note.
#[test]
fn a_random_force_no_record_can_tell_is_named_with_its_method() {
    use crate::common::{Lcg, Scratch};
    let dir = Scratch::new("generic-ornstein-uhlenbeck");
    let mut draw = Lcg(31);
    let write = |name: &str, force: f64, sensor: f64, draw: &mut Lcg| {
        let (h, every, steps) = (0.001, 20, 300_000);
        let (mut x, mut u, mut text) = (0.0_f64, 0.0_f64, String::from("t,x,u\n"));
        for k in 0..steps {
            if k % 4000 == 0 {
                u = 2.0 * draw.next() - 1.0;
            }
            if k % every == 0 {
                text += &format!("{:.3},{},{u}\n", k as f64 * h, x + sensor * draw.normal());
            }
            x += h * (u - x) + force * h.sqrt() * draw.normal();
        }
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let forced = write("ou.csv", 0.2, 0.0, &mut draw);
    let (ok, out, err) = termid(&["identify", "--data", &forced, "--states", "x", "--inputs", "u"]);
    assert!(ok, "{err}");
    assert!(out.contains("grows as a Brownian path's") && out.contains("--derivative ito"), "{out}");
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        &forced,
        "--states",
        "x",
        "--inputs",
        "u",
        "--derivative",
        "ito",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let terms = crate::common::chosen_terms(&crate::common::json(&out)["x_dot"]);
    let of = |term: &str| terms.iter().find(|(t, _)| t == term).map(|(_, c)| *c);
    assert!(terms.len() == 2, "{terms:?}");
    assert!(
        of("x").is_some_and(|c| (c + 1.0).abs() < 0.15) && of("u").is_some_and(|c| (c - 1.0).abs() < 0.15),
        "{terms:?}"
    );
    let white = write("white.csv", 0.0, 0.005, &mut draw);
    let (ok, out, err) = termid(&["identify", "--data", &white, "--states", "x", "--inputs", "u"]);
    assert!(ok && !out.contains("Brownian"), "{out}{err}");
}

/// A damped oscillator driven by a switched force, ẍ = −4x − 0.4ẋ + 2u (u = ±1 for 10 s
/// each), from x = `x0` at rest: rows t, x, v, u every 0.02 s for 60 s (RK4 at 1 ms, the force
/// held over each step).
fn switched_oscillator(x0: f64) -> Vec<[f64; 4]> {
    oscillator_sampled(x0, 20, 60_000)
}

/// `termid identify --data run --states states --inputs u` with `extra` arguments, its JSON
/// report and what it said on stderr, or a panic that shows the error.
fn identified_u(run: &std::path::Path, states: &str, extra: &[&str]) -> (serde_json::Value, String) {
    let mut args = vec!["identify", "--data", run.to_str().unwrap(), "--states", states, "--inputs", "u"];
    args.extend(extra);
    args.extend(["--format", "json"]);
    let (ok, out, err) = termid(&args);
    assert!(ok, "{err}");
    (crate::common::json(&out), err)
}

/// Writes to `path` a record of one `state` (`rows`, sampled every 0.05 s) and its input `u`,
/// the state read with white noise of the given standard deviation where `noise` is given.
fn one_state_record(
    path: &std::path::Path,
    state: &str,
    rows: &[Vec<f64>],
    u: &dyn Fn(f64) -> f64,
    mut noise: Option<(f64, &mut crate::common::Lcg)>,
) -> std::path::PathBuf {
    let mut text = format!("t,{state},u\n");
    for (i, r) in rows.iter().enumerate() {
        let t = i as f64 * 0.05;
        let e = noise.as_mut().map_or(0.0, |(sd, draw)| *sd * draw.normal());
        text += &format!("{t},{},{}\n", r[0] + e, u(t));
    }
    std::fs::write(path, text).unwrap();
    path.to_path_buf()
}

/// Asserts each of `truths` (term, true coefficient) among the chosen `terms`, within
/// `within` of the truth (relative); `label` names the record in the message.
fn coefficients_within(terms: &[(String, f64)], truths: &[(&str, f64)], within: f64, label: &str) {
    for (term, truth) in truths {
        let found = terms.iter().find(|(t, _)| t == term).map(|(_, c)| *c);
        assert!(found.is_some_and(|c| (c / truth - 1.0).abs() < within), "{label} {term}: {terms:?}");
    }
}

/// [`switched_oscillator`] sampled every `every` ms for `steps` ms.
fn oscillator_sampled(x0: f64, every: usize, steps: usize) -> Vec<[f64; 4]> {
    let h = 0.001;
    let (mut x, mut v) = (x0, 0.0_f64);
    let force = |k: usize| if (k / 10_000).is_multiple_of(2) { 1.0 } else { -1.0 };
    let rate = |x: f64, v: f64, u: f64| (v, -4.0 * x - 0.4 * v + 2.0 * u);
    let mut rows = Vec::new();
    for k in 0..steps {
        let u = force(k);
        if k % every == 0 {
            rows.push([k as f64 * h, x, v, u]);
        }
        let (k1x, k1v) = rate(x, v, u);
        let (k2x, k2v) = rate(x + 0.5 * h * k1x, v + 0.5 * h * k1v, u);
        let (k3x, k3v) = rate(x + 0.5 * h * k2x, v + 0.5 * h * k2v, u);
        let (k4x, k4v) = rate(x + h * k3x, v + h * k3v, u);
        x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    rows
}

/// [`switched_oscillator`] recorded as its position alone with noise of 1 % (a displacement
/// sensor): `--states x` cannot turn back as x does and says how to name the rate;
/// `--states x,v=dx/dt` estimates v from x's record, writes ẋ = v as kinematics, and identifies v's equation within 1 % of each coefficient,
/// every check passing (the re-simulations judged by x, the recorded state). `validate` reads
/// the written model against the same position-only record.
#[test]
fn a_motion_recorded_in_one_coordinate_is_identified_with_its_rate_estimated() {
    use crate::common::{Lcg, Scratch};
    let dir = Scratch::new("generic-position-only");
    let mut draw = Lcg(47);
    let mut text = String::from("t,x,u\n");
    for [t, x, _, u] in switched_oscillator(1.0) {
        // the position's spread is about 0.55
        text += &format!("{t:.3},{},{u}\n", x + 0.0055 * draw.normal());
    }
    let run = dir.join("position.csv");
    std::fs::write(&run, text).unwrap();
    let run = run.to_str().unwrap();
    let (_, out, err) = termid(&["identify", "--data", run, "--states", "x", "--inputs", "u"]);
    assert!(out.contains("--states x,v=dx/dt"), "{out}{err}");
    let model = dir.join("found.toml");
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        run,
        "--states",
        "x,v=dx/dt",
        "--inputs",
        "u",
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("`v` is not recorded: estimated as `x`'s rate"), "{err}");
    assert!(!out.contains("FLAG") && !out.contains("FAIL"), "{out}");
    let found = termid::model::Model::load(&model).unwrap();
    let kinematic = found.equation("x_dot").unwrap();
    assert!(!kinematic.identify, "ẋ = v is known");
    assert_eq!(kinematic.coefficients.len(), 1);
    let of = |term: &str| {
        found.equation("v_dot").unwrap().coefficients.iter().find(|c| c.0.to_string() == term).map(|c| c.1)
    };
    let count = found.equation("v_dot").unwrap().coefficients.len();
    for (term, truth) in [("x", -4.0), ("v", -0.4), ("u", 2.0)] {
        assert!(of(term).is_some_and(|c| (c / truth - 1.0).abs() < 0.01), "{term}: {:?}", of(term));
    }
    assert_eq!(count, 3);
    let (ok, out, err) = termid(&["validate", "--model", model.to_str().unwrap(), "--data", run]);
    assert!(ok && out.contains("position.csv: x "), "{out}{err}");
}

/// [`switched_oscillator`] from x = 0.3 read with noise of 1 % on x and v, x by a sensor whose
/// range ends at ±0.8 (its output clipped after the noise, as a converter at full scale):
/// 14 % of the rows pinned. Taken as the motion, v's rate came back as
/// −4.05x + 1.88u − 4.88x³ + 3.26u·x² − 0.40v and x's in six terms for v, every check "ok";
/// the pinned stretches are now said and cut out, and the pieces between give the truth within
/// 1 %.
#[test]
fn a_sensor_pinned_at_the_end_of_its_range_is_cut_around() {
    use crate::common::{Lcg, Scratch};
    let dir = Scratch::new("generic-clipped");
    let mut draw = Lcg(53);
    let mut text = String::from("t,x,v,u\n");
    for [t, x, v, u] in switched_oscillator(0.3) {
        let x = (x + 0.0055 * draw.normal()).clamp(-0.8, 0.8);
        text += &format!("{t:.3},{x},{},{u}\n", v + 0.011 * draw.normal());
    }
    let run = dir.join("clipped.csv");
    std::fs::write(&run, text).unwrap();
    let (report, err) = identified_u(&run, "x,v", &[]);
    assert!(
        err.contains("`x` rests at its largest value, 0.800,") && err.contains("smallest value, -0.800,"),
        "{err}"
    );
    let terms = crate::common::chosen_terms(&report["v_dot"]);
    let of = |term: &str| terms.iter().find(|(t, _)| t == term).map(|(_, c)| *c);
    assert_eq!(terms.len(), 3, "{terms:?}");
    for (term, truth) in [("x", -4.0), ("v", -0.4), ("u", 2.0)] {
        assert!(of(term).is_some_and(|c| (c / truth - 1.0).abs() < 0.01), "{term}: {terms:?}");
    }
    // the position read alone, v estimated on each piece: the pieces' ends, where the smoother
    // sees one side only, are left out where the rate is over twice as uncertain as the
    // median (they chose u·x², x's coefficient 2.9 % off, every check ok, on another draw);
    // what the pieces leave is either the truth or flagged
    let mut text = String::from("t,x,u\n");
    for [t, x, _, u] in switched_oscillator(0.3) {
        text += &format!("{t:.3},{},{u}\n", (x + 0.0055 * draw.normal()).clamp(-0.8, 0.8));
    }
    let alone = dir.join("position.csv");
    std::fs::write(&alone, text).unwrap();
    let (report, err) = identified_u(&alone, "x,v=dx/dt", &[]);
    assert!(err.contains("at the runs' ends left out, where an estimated rate's standard error"), "{err}");
    let terms = crate::common::chosen_terms(&report["v_dot"]);
    let of = |term: &str| terms.iter().find(|(t, _)| t == term).map(|(_, c)| *c);
    let right = terms.len() == 3
        && [("x", -4.0), ("v", -0.4), ("u", 2.0)]
            .iter()
            .all(|&(term, truth)| of(term).is_some_and(|c| (c / truth - 1.0).abs() < 0.015));
    let flagged = report["physical_checks"].as_array().unwrap().iter().any(|c| c["passed"] == false);
    assert!(right || flagged, "{terms:?} with every check ok");
}

/// [`switched_oscillator`] stamped in Unix time (1.7·10⁹ s, as a logger or an ISO 8601 date
/// gives it, read to 2.4·10⁻⁷ s) is identified as the same run stamped from 0: before, the
/// re-simulation stepped on the median of its rounded steps fell behind the record and took
/// each of the force's jumps a sample late (the exact equations flagged 0.37 % of v's span
/// off).
#[test]
fn a_record_stamped_in_unix_time_is_identified_as_from_zero() {
    use crate::common::Scratch;
    let dir = Scratch::new("generic-unix-time");
    let mut text = String::from("t,x,v,u\n");
    for [t, x, v, u] in switched_oscillator(1.0) {
        text += &format!("{:.3},{x},{v},{u}\n", 1.7e9 + t);
    }
    let run = dir.join("logged.csv");
    std::fs::write(&run, text).unwrap();
    let (report, _) = identified_u(&run, "x,v", &[]);
    let checks = report["physical_checks"].as_array().unwrap();
    assert!(checks.iter().all(|c| c["passed"] == true), "{checks:?}");
    let terms = crate::common::chosen_terms(&report["v_dot"]);
    coefficients_within(&terms, &[("x", -4.0), ("v", -0.4), ("u", 2.0)], 1e-4, "");
}

/// A record longer than the retrace re-simulates whole (30 000 rows at 100 Hz) under a command
/// held between samples is re-simulated whole: resampled first, the square wave's jumps were
/// smeared by the filter and the exact equations flagged 0.19 % of v's span off.
#[test]
fn a_long_record_under_a_held_command_is_re_simulated_with_its_jumps() {
    use crate::common::Scratch;
    let dir = Scratch::new("generic-long-held");
    let mut text = String::from("t,x,v,u\n");
    for [t, x, v, u] in oscillator_sampled(1.0, 10, 300_000) {
        text += &format!("{t:.2},{x},{v},{u}\n");
    }
    let run = dir.join("long.csv");
    std::fs::write(&run, text).unwrap();
    let (ok, out, err) =
        termid(&["identify", "--data", run.to_str().unwrap(), "--states", "x,v", "--inputs", "u"]);
    assert!(ok, "{err}");
    assert!(out.contains("dv/dt on 29") && !out.contains("FLAG") && !out.contains("FAIL"), "{out}");
}

/// `--resample` with the default derivative, the weak form (which estimates no rate), resamples
/// the runs and identifies them (it was refused: "nothing to smooth or draw: leave out --smooth
/// and --prepared-svg"); the held force is resampled as held, not through the filter, which
/// rang at each jump (u² no longer 1: u³ and u²·x chosen for a position read alone).
#[test]
fn a_run_resampled_is_identified_in_the_weak_form_its_held_force_held() {
    use crate::common::{Lcg, Scratch};
    let dir = Scratch::new("generic-resampled");
    let mut draw = Lcg(61);
    let (mut both, mut alone) = (String::from("t,x,v,u\n"), String::from("t,x,u\n"));
    for [t, x, v, u] in switched_oscillator(1.0) {
        let x = x + 0.0055 * draw.normal();
        both += &format!("{t:.3},{x},{},{u}\n", v + 0.011 * draw.normal());
        alone += &format!("{t:.3},{x},{u}\n");
    }
    for (name, text, states) in [("both.csv", both, "x,v"), ("alone.csv", alone, "x,v=dx/dt")] {
        let run = dir.join(name);
        std::fs::write(&run, text).unwrap();
        let (report, _) = identified_u(&run, states, &["--resample", "0.04"]);
        assert!(report["v_dot"]["rows"].as_u64().unwrap() < 1500, "{name}: {report}");
        let terms = crate::common::chosen_terms(&report["v_dot"]);
        assert_eq!(terms.len(), 3, "{name}: {terms:?}");
        coefficients_within(&terms, &[("x", -4.0), ("v", -0.4), ("u", 2.0)], 0.01, name);
    }
}

/// A log that holds an accelerometer's column beside the velocity, taken among the inputs by
/// default, every sensor with noise of 1 %: v's rate came back as the record's own,
/// v̇ = 1.000·a, every check ok and nothing said; now a note names the input that alone
/// explains the rate and how to leave it out.
#[test]
fn an_input_that_records_a_state_s_rate_is_said() {
    use crate::common::{Lcg, Scratch};
    let dir = Scratch::new("generic-accelerometer");
    let mut draw = Lcg(67);
    let mut text = String::from("t,x,v,u,a\n");
    for [t, x, v, u] in switched_oscillator(1.0) {
        // every sensor reads with noise of about 1 % of its spread
        let a = -4.0 * x - 0.4 * v + 2.0 * u + 0.02 * draw.normal();
        text += &format!("{t:.3},{},{},{u},{a}\n", x + 0.0055 * draw.normal(), v + 0.011 * draw.normal());
    }
    let run = dir.join("imu.csv");
    std::fs::write(&run, text).unwrap();
    let run = run.to_str().unwrap();
    let (ok, out, err) = termid(&["identify", "--data", run, "--states", "x,v"]);
    assert!(ok, "{err}");
    assert!(out.contains("`a` alone explains") && out.contains("it is no input"), "{out}");
    let (ok, out, err) = termid(&["identify", "--data", run, "--states", "x,v", "--inputs", "u"]);
    assert!(ok && !out.contains("alone explains"), "{out}{err}");
}

/// A predator-prey cycle whose predators' intake saturates (Rosenzweig-MacArthur,
/// ẋ = x(1 − x/3) − xy/(1 + 0.8x), ẏ = 0.6xy/(1 + 0.8x) − 0.25y), recorded noise-free for
/// 200 s: the cubic library (`--no-laws`) stands in for the rational rates with ten terms per
/// equation whose cycle grows (simulated on, they ran off to 10¹⁰² at 290 s), followed 24 s
/// of the run, their own motion lost after 47 s as chaos loses itself, and every check read
/// "ok". Chaos stays on its attractor: continued beyond the run, these equations run away,
/// and it is flagged. By default the saturating intake is found: xy/(1 + 0.8x) is
/// 1.25·xy/(x + 1.25), its K scanned, the truth's five terms, every check ok.
#[test]
fn a_stand_in_whose_cycle_runs_away_beyond_its_run_is_no_chaos() {
    use crate::common::{trajectory, Scratch};
    let dir = Scratch::new("saturating-intake");
    let rows = trajectory(&[1.0, 0.5], 0.05, 4001, 10, |_, s| {
        let intake = s[0] * s[1] / (1.0 + 0.8 * s[0]);
        vec![s[0] * (1.0 - s[0] / 3.0) - intake, 0.6 * intake - 0.25 * s[1]]
    });
    let path = dir.join("cycle.csv");
    let mut text = String::from("t,x,y\n");
    for (i, r) in rows.iter().enumerate() {
        text += &format!("{},{},{}\n", i as f64 * 0.05, r[0], r[1]);
    }
    std::fs::write(&path, text).unwrap();
    let identified = |laws: bool| {
        let mut args =
            vec!["identify", "--data", path.to_str().unwrap(), "--states", "x,y", "--format", "json"];
        if !laws {
            args.push("--no-laws");
        }
        let (ok, out, err) = termid(&args);
        assert!(ok, "{err}");
        crate::common::json(&out)
    };
    let report = identified(false);
    let missed = crate::common::check_named(&report, "as long as their own motion allows");
    assert_eq!(missed["passed"], false, "{missed}");
    assert!(
        missed["detail"].as_str().unwrap().contains("as a chaotic motion's does, but no chaos runs away"),
        "{missed}"
    );
    let report = identified(true);
    let checks = report["physical_checks"].as_array().unwrap();
    assert!(checks.iter().all(|c| c["passed"] == true), "{report}");
    let terms = |equation: &str| -> Vec<(String, f64)> {
        report[equation]["terms"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| (t["term"].as_str().unwrap().to_string(), t["coefficient"].as_f64().unwrap()))
            .collect()
    };
    let (prey, predators) = (terms("x_dot"), terms("y_dot"));
    assert_eq!((prey.len(), predators.len()), (3, 2), "{prey:?} {predators:?}");
    // the half-saturation written in the term: x*y/(x + K)
    let intake = |terms: &[(String, f64)]| -> (f64, f64) {
        let (term, c) = terms.iter().find(|(t, _)| t.starts_with("x*y/(x + ")).expect("the intake");
        (term.trim_start_matches("x*y/(x + ").trim_end_matches(')').parse().unwrap(), *c)
    };
    let ((k, eaten), (k2, grown)) = (intake(&prey), intake(&predators));
    assert!((k - 1.25).abs() < 0.005 && k == k2, "{prey:?} {predators:?}");
    assert!((eaten + 1.25).abs() < 0.01 && (grown - 0.75).abs() < 0.01, "{prey:?} {predators:?}");
}

/// An actuator whose force saturates, ẍ = −4x − 0.4ẋ + 2·tanh(u/0.5) under a multisine
/// command, its states read with 1 % noise: the cubic library stood in with u³, u²x and ux²,
/// flagged by the re-simulation and the halves, the four laws no better. The command takes
/// both signs, so tanh(u/K) is tried with K scanned: its gain found within 2 % (1.974), its
/// coefficient within 1 %, every check ok.
#[test]
fn an_actuators_limit_is_found_with_its_gain() {
    use crate::common::{trajectory, Lcg, Scratch};
    let dir = Scratch::new("actuator-limit");
    let u = |t: f64| 1.5 * (0.31 * t).sin() + (0.83 * t + 1.0).sin() + 0.5 * (2.1 * t + 2.0).sin();
    let rows = trajectory(&[0.0, 0.0], 0.05, 4001, 20, |t, s| {
        vec![s[1], -4.0 * s[0] - 0.4 * s[1] + 2.0 * (u(t) / 0.5).tanh()]
    });
    let spread = |i: usize| {
        let (lo, hi) =
            rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| (a.min(r[i]), b.max(r[i])));
        hi - lo
    };
    let (sx, sv) = (spread(0), spread(1));
    let mut noise = Lcg(5);
    let path = dir.join("limit.csv");
    let mut text = String::from("t,x,v,u\n");
    for (i, r) in rows.iter().enumerate() {
        let t = i as f64 * 0.05;
        text += &format!(
            "{t},{},{},{}\n",
            r[0] + 0.01 * sx * noise.normal(),
            r[1] + 0.01 * sv * noise.normal(),
            u(t)
        );
    }
    std::fs::write(&path, text).unwrap();
    let (terms, gain, coefficient) = saturating_form(&path, "x,v", "v_dot", ("tanh(", "*u)"));
    assert_eq!(terms, 3);
    assert!((gain - 2.0).abs() < 0.04 && (coefficient - 2.0).abs() < 0.02, "{gain} {coefficient}");
}

/// `identify` of the run at `path` (`states`, the input `u`), every check passing: how many
/// terms `equation` holds, and of its term written `prefix`NUMBER`suffix` (a saturating
/// form), the number and the coefficient.
fn saturating_form(
    path: &std::path::Path,
    states: &str,
    equation: &str,
    (prefix, suffix): (&str, &str),
) -> (usize, f64, f64) {
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        path.to_str().unwrap(),
        "--states",
        states,
        "--inputs",
        "u",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let report = crate::common::json(&out);
    assert!(report["physical_checks"].as_array().unwrap().iter().all(|c| c["passed"] == true), "{report}");
    let terms = report[equation]["terms"].as_array().unwrap();
    let form = terms
        .iter()
        .find(|t| t["term"].as_str().unwrap().starts_with(prefix))
        .unwrap_or_else(|| panic!("no {prefix}…{suffix} in {terms:?}"));
    let text = form["term"].as_str().unwrap();
    let number = text.trim_start_matches(prefix).trim_end_matches(suffix).parse().unwrap();
    (terms.len(), number, form["coefficient"].as_f64().unwrap())
}

/// An enzyme's turnover under a stepped feed, ẋ = u − 2x/(0.5 + x), recorded noise-free: the
/// cubic library's stand-in re-simulates it 1.1 times as far off as a noise-free record allows,
/// its halves choosing other terms; the saturating form is found with its K, in two terms.
#[test]
fn an_enzymes_turnover_is_found_with_its_constant() {
    use crate::common::{trajectory, Scratch};
    let dir = Scratch::new("michaelis-menten");
    let feed = |t: f64| [0.6, 1.2, 0.3, 1.5, 0.9, 0.45, 1.3, 0.7][(t / 25.0) as usize % 8];
    let rows = trajectory(&[0.3], 0.05, 4001, 20, |t, s| vec![feed(t) - 2.0 * s[0] / (0.5 + s[0])]);
    let path = dir.join("feed.csv");
    let mut text = String::from("t,x,u\n");
    for (i, r) in rows.iter().enumerate() {
        let t = i as f64 * 0.05;
        text += &format!("{t},{},{}\n", r[0], feed(t));
    }
    std::fs::write(&path, text).unwrap();
    let (terms, k, coefficient) = saturating_form(&path, "x", "x_dot", ("x/(x + ", ")"));
    assert_eq!(terms, 2);
    assert!((k - 0.5).abs() < 0.002 && (coefficient + 2.0).abs() < 0.01, "{k} {coefficient}");
}

/// Two runs of one oscillator, ẍ = −4x − c·ẋ + u, whose damping changed between them (c = 0.2,
/// then 0.6: a load, a temperature), noise-free: all the rows fit a compromise, −0.58v with
/// cubic stand-ins, said only to miss its runs (a state, a term or an input the candidates
/// lack). Each run identified alone with the same terms tells its own damping: flagged, naming
/// both.
#[test]
fn runs_of_two_systems_are_said_to_disagree() {
    use crate::common::{trajectory, Scratch};
    let dir = Scratch::new("two-dampings");
    let u = |t: f64| 1.5 * (0.31 * t).sin() + (0.83 * t + 1.0).sin() + 0.5 * (2.1 * t + 2.0).sin();
    let mut args = vec!["identify".to_string()];
    for (k, c) in [(1, 0.2), (2, 0.6)] {
        let rows = trajectory(&[0.0, 0.0], 0.05, 2001, 10, |t, s| vec![s[1], -4.0 * s[0] - c * s[1] + u(t)]);
        let path = dir.join(format!("run{k}.csv"));
        let mut text = String::from("t,x,v,u\n");
        for (i, r) in rows.iter().enumerate() {
            let t = i as f64 * 0.05;
            text += &format!("{t},{},{},{}\n", r[0], r[1], u(t));
        }
        std::fs::write(&path, text).unwrap();
        args.extend(["--data".to_string(), path.to_str().unwrap().to_string()]);
    }
    args.extend(["--states", "x,v", "--inputs", "u", "--format", "json"].map(String::from));
    let (ok, out, err) = termid(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(ok, "{err}");
    let report = crate::common::json(&out);
    let apart = crate::common::check_named(&report, "the runs tell one system");
    let detail = apart["detail"].as_str().unwrap();
    assert_eq!(apart["passed"], false, "{apart}");
    assert!(detail.contains("`v_dot`'s `v` is -0.200 (± ") && detail.contains("and -0.600 (± "), "{detail}");
}

/// A logger's clock: Lotka-Volterra's cycle sampled every 50 ms give or take 10 ms, with white
/// noise of 3 % of each state's spread. The recipe evens the run onto a finer grid by cubics
/// between the samples, whose rows are smooth: their noise read 0.09 %, and the noise check
/// passed the records as too quiet to bias the terms. Read at the samples at their own times,
/// the noise is measured (within a fifth: a sample's row holds the cubic at the grid's time,
/// which smooths it a little) and flagged; noise-free, the jitter is no noise.
#[test]
fn a_jittered_loggers_noise_is_measured_at_its_samples() {
    use crate::common::{check_named, json, noise, trajectory, Lcg, Scratch};
    let dir = Scratch::new("jittered-logger");
    let mut rng = Lcg(17);
    let times: Vec<f64> = (0..1000)
        .map(|k| if k == 0 { 0.0 } else { 0.05 * k as f64 + 0.01 * (2.0 * rng.next() - 1.0) })
        .collect();
    let mut rows = vec![vec![1.8, 0.6]];
    for w in times.windows(2) {
        let from = rows.last().unwrap().clone();
        let next = trajectory(&from, w[1] - w[0], 2, 20, |_, s| {
            vec![2.0 / 3.0 * s[0] - 4.0 / 3.0 * s[0] * s[1], s[0] * s[1] - s[1]]
        });
        rows.push(next[1].clone());
    }
    let sd = noise(&rows, 0.03);
    let mut check = |share: f64| {
        let path = dir.join(format!("logger{share}.csv"));
        let mut text = String::from("t,x,y\n");
        for (t, r) in times.iter().zip(&rows) {
            text += &format!(
                "{t},{},{}\n",
                r[0] + share * sd[0] * rng.normal(),
                r[1] + share * sd[1] * rng.normal()
            );
        }
        std::fs::write(&path, text).unwrap();
        let (ok, out, err) =
            termid(&["identify", "--data", path.to_str().unwrap(), "--states", "x,y", "--format", "json"]);
        assert!(ok, "{err}");
        check_named(&json(&out), "noise leaves the terms unbiased").clone()
    };
    let noisy = check(1.0);
    let detail = noisy["detail"].as_str().unwrap();
    assert!(noisy["passed"] == false, "{noisy}");
    for state in ["x", "y"] {
        let read: f64 = detail
            .split(&format!("`{state}` "))
            .nth(1)
            .and_then(|s| s.split(" %").next())
            .unwrap()
            .parse()
            .unwrap();
        assert!((read / 3.0 - 1.0).abs() < 0.2, "{state}: {detail}");
    }
    assert!(check(0.0)["passed"] == true);
}

/// Three masses in a chain under a multisine force on the first, recorded noise-free: each
/// rate's exact terms leave 4·10⁻¹⁴ of it. The dead-time scan, judging every one of the 120
/// cubic candidates at once (which passes over their collinear directions), found more left
/// and the force read a sample early taking up most of it: a dead time said of a record
/// that had none, and the system identified again with it (rejected by its checks) for
/// 100 s. A fit that leaves nothing to explain is not scanned.
#[test]
fn an_exact_fit_has_no_dead_time_to_find() {
    use crate::common::{check_named, json, trajectory, Scratch};
    let dir = Scratch::new("mass-chain");
    let u = |t: f64| {
        1.5 * (0.31 * t).sin()
            + (0.83 * t + 1.0).sin()
            + 0.5 * (2.1 * t + 2.0).sin()
            + 0.7 * (1.37 * t + 0.3).sin()
    };
    let (k1, k2, k3, c) = (4.0, 3.0, 2.0, 0.3);
    let rows = trajectory(&[0.0; 6], 0.05, 6001, 10, |t, s| {
        let (x1, x2, x3, v1, v2, v3) = (s[0], s[1], s[2], s[3], s[4], s[5]);
        vec![
            v1,
            v2,
            v3,
            -k1 * x1 + k2 * (x2 - x1) - c * v1 + u(t),
            -k2 * (x2 - x1) + k3 * (x3 - x2) - c * v2,
            -k3 * (x3 - x2) - c * v3,
        ]
    });
    let path = dir.join("chain.csv");
    let mut text = String::from("t,x1,x2,x3,v1,v2,v3,u\n");
    for (i, r) in rows.iter().enumerate() {
        let t = i as f64 * 0.05;
        let values: Vec<String> = r.iter().map(|v| v.to_string()).collect();
        text += &format!("{t},{},{}\n", values.join(","), u(t));
    }
    std::fs::write(&path, text).unwrap();
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        path.to_str().unwrap(),
        "--states",
        "x1,x2,x3,v1,v2,v3",
        "--inputs",
        "u",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    assert!(!out.contains("later than the rows have it") && !out.contains("acting late"), "{out}");
    let report = json(&out);
    let v1: Vec<(String, f64)> = crate::common::chosen_terms(&report["v1_dot"]);
    let want = [("u", 1.0), ("v1", -0.3), ("x1", -7.0), ("x2", 3.0)];
    assert_eq!(v1.len(), want.len(), "{v1:?}");
    for ((term, got), (name, value)) in v1.iter().zip(want) {
        assert!(term == name && (got - value).abs() < 1e-6, "{v1:?}");
    }
    assert!(check_named(&report, "retrace their runs")["passed"] == true);
}

/// A mass on a spring driven through an actuator's first-order lag, ẍ = −4x − 0.4ẋ + 2y with
/// ẏ = (u − y)/0.5, x and v = ẋ read every 0.05 s beside the command u (the actuator starting
/// from 0 under a command of 1.3): read as 0.45 s late, it came back with stand-in terms (u·x²,
/// u²·x, x³) beside the delay, flagged noise-free, at 1 % noise by the noise check alone. The
/// scan now finds that a lag of 0.5 s explains the rates better than any dead time over the
/// same rows, and the system is identified again through it: the three true terms, `lag = 0.5`
/// in the model written, every check ok. Behind a lag of 2 s (which reads as no dead time at
/// all, flagged with stand-in terms u·x², u²·x) the same, `lag = 2.0`. The same mass driven 0.5 s
/// late stays a dead time.
#[test]
fn an_actuators_first_order_lag_is_found_and_fitted_so() {
    use crate::common::{json, trajectory, Lcg, Scratch};
    let dir = Scratch::new("actuator-lag");
    let u = |t: f64| 1.5 * (0.31 * t).sin() + (0.83 * t + 1.0).sin() + 0.5 * (2.1 * t + 2.0).sin();
    let lagged = |lag: f64| {
        trajectory(&[0.0; 3], 0.05, 4001, 10, |t, s| {
            vec![s[1], -4.0 * s[0] - 0.4 * s[1] + 2.0 * s[2], (u(t) - s[2]) / lag]
        })
    };
    let (lagged, slow) = (lagged(0.5), lagged(2.0));
    let late = trajectory(&[0.0; 2], 0.05, 4001, 10, |t, s| {
        vec![s[1], -4.0 * s[0] - 0.4 * s[1] + 2.0 * if t >= 0.5 { u(t - 0.5) } else { 0.0 }]
    });
    let mut draw = Lcg(7);
    for (name, rows, noisy, key) in [
        ("lag.csv", &lagged, false, "lag = 0.5"),
        ("lag_noisy.csv", &lagged, true, "lag = 0.5"),
        ("slow.csv", &slow, false, "lag = 2.0"),
        ("slow_noisy.csv", &slow, true, "lag = 2.0"),
        ("late.csv", &late, false, "delay = 0.5"),
    ] {
        let sd = crate::common::noise(rows, if noisy { 0.01 } else { 0.0 });
        let mut text = String::from("t,x,v,u\n");
        for (i, r) in rows.iter().enumerate() {
            let t = i as f64 * 0.05;
            let (ex, ev) = (sd[0] * draw.normal(), sd[1] * draw.normal());
            text += &format!("{t},{},{},{}\n", r[0] + ex, r[1] + ev, u(t));
        }
        let (data, model) = (dir.join(name), dir.join(format!("{name}.toml")));
        std::fs::write(&data, text).unwrap();
        let (ok, out, err) = termid(&[
            "identify",
            "--data",
            data.to_str().unwrap(),
            "--states",
            "x,v",
            "--inputs",
            "u",
            "--out",
            model.to_str().unwrap(),
            "--format",
            "json",
        ]);
        assert!(ok, "{err}");
        let report = json(&out);
        let v: Vec<(String, f64)> = crate::common::chosen_terms(&report["v_dot"]);
        let want = [("x", -4.0), ("u", 2.0), ("v", -0.4)];
        assert_eq!(v.len(), want.len(), "{name}: {v:?}");
        let within = if noisy { 0.01 } else { 2e-3 };
        for (term, value) in want {
            let got = v.iter().find(|(t, _)| t == term).map_or(f64::NAN, |(_, c)| *c);
            assert!((got / value - 1.0).abs() < within, "{name}: {term} {got} for {value}: {v:?}");
        }
        assert!(!out.contains("\"passed\":false"), "{name}: {out}");
        let written = std::fs::read_to_string(&model).unwrap();
        assert!(written.contains(&format!("\n{key}\n")), "{name}: {written}");
        let other = if key.starts_with("lag") { "delay = " } else { "lag = " };
        assert!(!written.contains(other), "{name}: {written}");
    }
}

/// A first-order plant ẋ = −x + y behind a lag of 0.5 s (`lag = 0.5`), replaying a command
/// that steps from 0 to 1 at t = 1 s (held between its samples): x = 1 − 2e^(−s) + e^(−2s),
/// s = t − 1, the lag's output reaching the plant smoothly; read in pieces (`moments
/// --chunk-rows`) it is refused, and a lag below 0 by its key.
#[test]
fn a_model_declares_its_inputs_first_order_lag() {
    use crate::common::Scratch;
    let dir = Scratch::new("declared-lag");
    let model = |lag: &str| {
        format!(
            "[model]\nname = \"plant\"\ntime = \"t\"\n[[states]]\nname = \"x\"\n[[inputs]]\nname = \"u\"\nlag = {lag}\n[equations.x_dot]\nstate = \"x\"\ncoefficients = {{ \"x\" = -1.0, \"u\" = 1.0 }}\n"
        )
    };
    let (path, run, out) = (dir.join("plant.toml"), dir.join("step.csv"), dir.join("sim.csv"));
    std::fs::write(&path, model("0.5")).unwrap();
    let mut text = String::from("t,u\n");
    for k in 0..=80 {
        let t = 0.1 * k as f64;
        text += &format!("{t},{}\n", if t >= 1.0 - 1e-9 { 1.0 } else { 0.0 });
    }
    std::fs::write(&run, text).unwrap();
    let replay = format!("replay:{}", run.display());
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        path.to_str().unwrap(),
        "--manoeuvre",
        &replay,
        "--duration",
        "8",
        "--sample",
        "0.1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let frame = termid::data::Frame::read_csv(&out, "t").unwrap();
    let (t, x) = (frame.time(), frame.column("x").unwrap());
    assert!(t.len() > 70, "{}", t.len());
    for (t, x) in t.iter().zip(x) {
        let s = (t - 1.0).max(0.0);
        let want = 1.0 - 2.0 * (-s).exp() + (-2.0 * s).exp();
        assert!((x - want).abs() < 1e-3, "t = {t}: {x} for {want}");
    }
    // read in pieces, a lag's state would start afresh in each: refused
    let moments = dir.join("x.moments");
    let (ok, _, err) = termid(&[
        "moments",
        "--model",
        path.to_str().unwrap(),
        "--equation",
        "x_dot",
        "--data",
        out.to_str().unwrap(),
        "--chunk-rows",
        "20",
        "--out",
        moments.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("first-order lag") && err.contains("--chunk-rows 0"), "{err}");
    std::fs::write(&path, model("-0.5")).unwrap();
    let (ok, _, err) = termid(&["simulate", "--model", path.to_str().unwrap(), "--input", "u=1"]);
    assert!(!ok && err.contains("inputs[0].lag") && err.contains("no first-order lag"), "{err}");
}
