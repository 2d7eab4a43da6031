//! No panic on any user input: mutated model files and CSV files get errors, never panics.

use proptest::prelude::*;
use termid::data::Frame;
use termid::model::Model;
use termid::ship::DEFAULT_MODEL;

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// The default model with one line replaced by noise, deleted, or duplicated.
    #[test]
    fn mutated_model_files_never_panic(line in 0usize..400, noise in "\\PC{0,30}", how in 0u8..3) {
        let mut lines: Vec<String> = DEFAULT_MODEL.lines().map(str::to_string).collect();
        let k = line % lines.len();
        match how {
            0 => lines[k] = noise,
            1 => { lines.remove(k); }
            _ => { let l = lines[k].clone(); lines.insert(k, l); }
        }
        let text = lines.join("\n");
        if let Ok(m) = termid::plugins::parse(&text, "mutated.toml") {
            // a model that loads must also compile or refuse cleanly
            let _ = m.compile_rhs(false);
            let _ = termid::ship::Ship::new(&m, false).and_then(|s| s.straight_run());
        }
    }

    /// A model file's back-end settings from any method, option and constraint (columns in
    /// and out of range, term texts that are candidates, other terms and no terms, any values):
    /// the file is refused with its key, or it loads and every equation fits or errs; never a
    /// panic (issue 13: a constraint on column 99 used to panic in the sparse back-end).
    #[test]
    fn back_end_settings_never_panic(
        method in prop::sample::select(vec!["stepwise", "efroymson", "best-subset", "sparse", "lasso"]),
        option in prop::sample::select(vec![
            "", "path = 0", "path = 3", "lambda = -1.0", "lambda = 0.5", "adaptive = true",
            "choice = \"leave-one-run-out\"", "max_size = 2", "node_limit = 0", "min_proportion = 2.0",
            "f_enter = -1.0", "prune_beta = 1e-3", "active_set = false", "lambda_ratio = 1.5",
        ]),
        kind in 0u8..4,
        which in prop::sample::select(vec!["0", "8", "9", "99", "\"x\"", "\"y*x\"", "\"x^7\"", "\"w\"", "\"x**\""]),
        value in prop::sample::select(vec!["1.0", "-1", "0", "2.5", "nan", "1e308"]),
    ) {
        let constraint = match kind {
            0 => format!("fixed = [[{which}, {value}]]"),
            1 => format!("signs = [[{which}, {value}]]"),
            2 => format!("equalities = [{{ terms = [[{which}, {value}], [\"z\", 1.0]], value = {value} }}]"),
            _ => String::new(),
        };
        let settings: Vec<String> = [format!("method = \"{method}\""), option.to_string(), constraint]
            .into_iter()
            .filter(|s| !s.is_empty())
            .collect();
        let lorenz = std::fs::read_to_string("models/lorenz.toml").unwrap();
        let line = lorenz.lines().find(|l| l.starts_with("backend = ")).unwrap();
        let text = lorenz.replacen(line, &format!("backend = {{ {} }}", settings.join(", ")), 1);
        match termid::plugins::parse(&text, "fuzzed.toml") {
            Err(e) => prop_assert!(e.to_string().contains("fuzzed.toml"), "{e}"),
            Ok(model) => {
                let frames = [lorenz_run(&model)];
                for eq in model.identifiable() {
                    let _ = termid::identify::fit_equation(
                        &model, &eq, &frames, &termid::data::CentralDifference, true, None,
                    );
                }
            }
        }
    }

    /// Any small CSV text: a frame or an error naming the file.
    #[test]
    fn csv_text_never_panics(text in "[t,u0-9.eE+\\-\\n NaNinf#x]{0,120}") {
        match Frame::parse_csv(&text, "any.csv", "t") {
            Ok(f) => prop_assert!(!f.time().is_empty()),
            Err(e) => prop_assert!(e.to_string().contains("any.csv") || e.to_string().contains("derivative")),
        }
    }

    /// Manoeuvre strings from the command line.
    #[test]
    fn manoeuvre_strings_never_panic(text in "[a-z:/0-9.\\-]{0,20}") {
        let _ = termid::ship::Manoeuvre::parse(&text);
    }

    /// Derivative methods and resampling on any signal (constant, stepped, huge, uneven in
    /// time) and any `--derivative`/`--resample` text: an error or finite numbers, no panic.
    #[test]
    fn preparation_never_panics(
        steps in prop::collection::vec(1e-3f64..1.0, 1..60),
        values in prop::collection::vec(prop_oneof![Just(0.0), Just(1.0), -1e6f64..1e6], 60),
        spec in "(central|savitzky-golay|spline|kalman|kinematic|x)(:[0-9.e\\-]{0,6}){0,3}",
        dt in -1.0f64..5.0,
    ) {
        let mut t = vec![0.0];
        for s in &steps {
            t.push(t[t.len() - 1] + s);
        }
        let x = &values[..t.len()];
        if let Ok(method) = termid::data::differentiator(&spec) {
            if let Ok(s) = method.smooth(&t, x) {
                prop_assert!(s.rate.iter().chain(&s.value).all(|v| v.is_finite()), "{spec}: {s:?}");
            }
        }
        let mut f = Frame::new("run.csv", "t", t.clone()).unwrap();
        f.push("x", x.to_vec()).unwrap();
        if let Ok(r) = termid::data::resample(&f, dt) {
            prop_assert!(r.column("x").unwrap().iter().all(|v| v.is_finite()));
        }
        // the ship's tracking filter on the same signal in every channel
        let ship = termid::ship::ShipSpec::of(&termid::ship::default_model()).unwrap().unwrap();
        let mut run = Frame::new("run.csv", "t", t.clone()).unwrap();
        for (k, name) in ["u", "v", "r", "ψ", "x0", "y0"].iter().enumerate() {
            run.push(name, x.iter().map(|v| v * (k + 1) as f64).collect()).unwrap();
        }
        if let Ok(tracked) = termid::ship::tracking::track(&run, &ship, true) {
            for name in ["u_dot", "v_dot", "r_dot", "ψ"] {
                prop_assert!(tracked.column(name).unwrap().iter().all(|v| v.is_finite()), "{name}");
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// The grey-box model `new-ship` writes (priors, bounds, per-run nuisances, derived
    /// variables, a propeller) with one line replaced by noise, deleted or duplicated: refused,
    /// or a model that compiles, loads as a ship and finds its straight run or says why.
    #[test]
    fn mutated_grey_box_files_never_panic(line in 0usize..700, noise in "\\PC{0,30}", how in 0u8..3) {
        let mut lines: Vec<String> = grey_box().lines().map(str::to_string).collect();
        let k = line % lines.len();
        match how {
            0 => lines[k] = noise,
            1 => { lines.remove(k); }
            _ => { let l = lines[k].clone(); lines.insert(k, l); }
        }
        if let Ok(m) = termid::plugins::parse(&lines.join("\n"), "mutated.toml") {
            let _ = m.compile_rhs(false);
            let _ = termid::ship::Ship::new(&m, false).and_then(|s| s.straight_run());
        }
    }

    /// A ship's particulars (`termid new-ship`; the propeller's K_T(J) among them) with one value scaled by up to a thousand
    /// either way, negated, or made NaN or infinite: refused naming the key, or a grey-box
    /// model that loads as a ship and finds its straight run or says why; never a panic.
    #[test]
    fn particulars_never_panic(key in 1usize..16, factor in -3.0f64..3.0, how in 0u8..4) {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/kvlcc2_particulars.toml")).unwrap();
        let mut particulars: termid::ship::particulars::Particulars = toml::from_str(&text).unwrap();
        let [k0, k1, k2] = &mut particulars.kt;
        let fields = [
            k0, k1, k2, &mut particulars.lpp, &mut particulars.beam, &mut particulars.draught,
            &mut particulars.block_coefficient, &mut particulars.x_g, &mut particulars.rudder_area,
            &mut particulars.rudder_span, &mut particulars.propeller_diameter, &mut particulars.u0,
            &mut particulars.rudder_rate, &mut particulars.rudder_limit, &mut particulars.density,
        ];
        let value = fields.into_iter().nth(key - 1).unwrap();
        *value = match how {
            0 => *value * 10f64.powf(factor),
            1 => -*value * 10f64.powf(factor),
            2 => f64::NAN,
            _ => f64::INFINITY.copysign(factor),
        };
        match particulars.model() {
            Ok(model) => {
                // the file `new-ship` writes loads as any model file does
                let text = model.to_toml();
                let model = termid::plugins::parse(&text, "new_ship.toml").map_err(|e| TestCaseError::fail(e.to_string()))?;
                let _ = termid::ship::Ship::new(&model, false).and_then(|s| s.straight_run());
            }
            // refused for a value, never by the model file it would have written
            Err(e) => prop_assert!(matches!(e, termid::ship::particulars::ParticularsError::Value { .. }), "{e}"),
        }
    }

    /// Time stamps of any spacing (steps from a tenth to three times the usual, rows dropped,
    /// a clock off from its first step): a run is evened or refused with a reason, never a
    /// panic, and an evened run is even and re-simulates (a model's `admit`, then `Runs`).
    #[test]
    fn uneven_time_stamps_are_evened_or_refused(steps in proptest::collection::vec(0.1f64..3.0, 2..80)) {
        let mut t = vec![0.0];
        for s in &steps {
            t.push(t[t.len() - 1] + 0.05 * s);
        }
        let mut frame = Frame::new("stamps.csv", "t", t.clone()).unwrap();
        frame.push("x", t.iter().map(|v| v.sin()).collect()).unwrap();
        frame.push("w", t.iter().map(|v| v.cos()).collect()).unwrap();
        frame.push("F", vec![0.0; t.len()]).unwrap();
        let model = Model::parse(SPRING, "spring.toml").unwrap();
        if model.admit(&mut frame).is_ok() {
            prop_assert!(termid::data::uneven(frame.time()).is_none(), "{:?}", frame.time());
            let step = frame.time()[1] - frame.time()[0];
            if let Ok(runs) = termid::diagnose::Runs::new(&model, &[frame], step, termid::sim::Integrator::Rk4) {
                prop_assert!(runs.simulate(&model, &[], &[]).is_ok());
            }
        }
    }
}

/// A forced spring: a model with a state pair and an input, for records of any spacing.
const SPRING: &str = r#"
[model]
name = "a forced spring"
[[states]]
name = "x"
[[states]]
name = "w"
[[inputs]]
name = "F"
[equations.x_dot]
state = "x"
identify = false
coefficients = { "w" = 1.0 }
[equations.w_dot]
state = "w"
identify = false
coefficients = { "x" = -1.0, "F" = 1.0 }
"#;

/// The grey-box model file `new-ship` writes for KVLCC2's particulars.
fn grey_box() -> &'static str {
    static TEXT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TEXT.get_or_init(|| {
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/kvlcc2_particulars.toml"))
                .unwrap();
        let particulars: termid::ship::particulars::Particulars = toml::from_str(&text).unwrap();
        particulars.model().unwrap().to_toml()
    })
}

/// Two seconds of the Lorenz system at 0.01 s, with its derivative columns.
fn lorenz_run(model: &Model) -> Frame {
    let system = termid::sim::System::new(model, &Default::default(), false).unwrap();
    let settings = termid::sim::Settings {
        integrator: termid::sim::Integrator::Rk4,
        dt: 0.01,
        duration: 2.0,
        sample: 0.01,
    };
    let x0: Vec<f64> = model.spec().states.iter().map(|s| s.initial).collect();
    let traj = termid::sim::simulate(&system, &x0, &mut termid::sim::Constant(vec![]), &settings).unwrap();
    traj.to_frame("lorenz", "t").unwrap()
}
