//! No panic on any user input: mutated model files and CSV files get errors, never panics.

use proptest::prelude::*;
use termid::data::Frame;
use termid::model::{Model, DEFAULT_MODEL};

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
        if let Ok(m) = Model::parse(&text, "mutated.toml") {
            // a model that loads must also compile or refuse cleanly
            let _ = m.compile_rhs(false);
            let _ = termid::ship::Ship::new(&m, false).and_then(|s| s.straight_run());
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
        let ship = Model::default_model().spec.ship.unwrap();
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
