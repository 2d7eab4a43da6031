//! The SIMMAN case study's dataset files (`examples/simman/`) read records laid out as HSVA's
//! and MARIN's KVLCC2 files are — synthetic ones with known motions, since the records
//! themselves stay in their repository — at the model's scale, in termid's rudder sign, with
//! every column the ship template needs.

use std::path::Path;

use termid::data::Dataset;

/// A body-frame motion: u, v (model scale, m/s), heading (rad), rudder (rad, termid's sign).
const U: f64 = 1.18;
const V: f64 = -0.05;
const PSI: f64 = 0.3;
const DELTA: f64 = 0.1;

#[test]
fn the_case_study_reads_hsva_and_marin_records_alike() {
    let dir = std::env::temp_dir().join(format!("termid-simman-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (c, s) = (PSI.cos(), PSI.sin());
    let (xd, yd) = (U * c - V * s, U * s + V * c);
    let template = termid::plugins::load(Path::new("models/new_ship.toml")).unwrap();
    let known = template.data_names();
    let lambda: f64 = 45.7;
    for (file, text) in [("hsva.toml", "hsva"), ("marin.toml", "marin")] {
        let path = Path::new("examples/simman").join(file);
        let set = Dataset::load(&path).unwrap();
        assert!(set.folder.as_ref().unwrap().to_string_lossy().contains("${SIMMAN}"));
        for var in set.columns.keys() {
            assert!(known.contains(var), "{file}: `{var}` is not a variable of models/new_ship.toml");
        }
        // every run's file, laid out as the basin writes it
        for run in &set.runs {
            let mut body = String::new();
            if text == "hsva" {
                body +=
                    " HSVA, experimental data CPMC\n KVLCC2\n Z10\u{b0}/10\u{b0}\n Time series of motions\n";
                for k in 0..200 {
                    let t = 0.05 * k as f64;
                    // time x0 y0 psi u v p r delta rev thrust torque; a positive rudder turns
                    // HSVA's ship to port
                    body += &format!(
                        "  {t:.9}  {:.9}  {:.9}  {:.9}  9.9  9.9  {:.9}  9.9  {:.9}  10.2295  41.0  1.02\n",
                        xd * t,
                        yd * t,
                        PSI.to_degrees(),
                        0.2,
                        -DELTA.to_degrees()
                    );
                }
            } else {
                body += "MARIN(Maritime Research Institute Netherlands)\nZig-zag manoeuvring for KVLCC2 : 10 / -10\n\n";
                let sq = lambda.sqrt();
                for k in 0..300 {
                    // full scale, three digits: 0.1352 s per row, positions × λ, speeds × √λ
                    let t = 0.02 * sq * k as f64;
                    body += &format!(
                        "{t:.2E}\t{:.2E}\t{:.2E}\t{:.2E}\t{:.2E}\t{:.6E}\t{:.6E}\t{:.2E}\t{:.2E}\t{:.2E}\t{:.2E}\n",
                        xd * sq * t,
                        yd * sq * t,
                        0.1,
                        PSI.to_degrees(),
                        xd * sq,
                        yd * sq,
                        0.0,
                        0.2 / sq,
                        -DELTA.to_degrees(),
                        10.2295 * 60.0 / sq
                    );
                }
            }
            std::fs::write(dir.join(&run.file), body.as_bytes()).unwrap();
        }
        let (frames, notes) = set.read(&dir, "t").unwrap();
        assert_eq!(frames.len(), if text == "hsva" { 13 } else { 4 });
        assert!(notes.iter().any(|n| n.contains("`delta` negated")), "{notes:?}");
        for f in &frames {
            let at = f.len() / 2;
            let near = |name: &str, want: f64, tol: f64| {
                let got = f.require(name).unwrap()[at];
                assert!((got - want).abs() < tol, "{text} `{name}`: {got} vs {want}");
            };
            near("u", U, 2e-3);
            near("v", V, 2e-3);
            near("δ", DELTA, 1e-3);
            near("r", 0.2f64.to_radians(), 1e-4);
            near("n", 10.2295, 0.01);
            // model-scale time at 50 Hz (MARIN) or 20 Hz (HSVA)
            let dt = f.time()[1] - f.time()[0];
            assert!((dt - if text == "hsva" { 0.05 } else { 0.02 }).abs() < 1e-3, "{text}: Δt {dt}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
