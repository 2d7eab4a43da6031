//! Records as loggers write them, through the CLI: Lorenz's system sampled every 1 ms, with a
//! state whose sensor reads only every 10th row and is written again until its next reading
//! (a log kept faster than the sensor, sensors of several rates merged and filled forward).
//! Read as the rows have it, the state's rate is zero between readings and a spike at each,
//! and the fits are wrong with nothing said; read at its readings, they are Lorenz's own.
//! And two records in one file, the second from another start: cut into two runs, said.

use crate::common::{chosen_terms, json, lorenz_rows, termid, trajectory, Scratch, LORENZ_TRUTH};

/// Lorenz every 1 ms for 10 s, the columns `repeated` (of x, y, z) read every 10th row and
/// repeated in between.
fn lorenz_log(dir: &std::path::Path, repeated: &str) -> std::path::PathBuf {
    let rows = lorenz_rows(0.001, 10_001);
    let mut csv = String::from("t,x,y,z\n");
    for (k, row) in rows.iter().enumerate() {
        let read = &rows[k - k % 10];
        let v: Vec<f64> =
            (0..3).map(|j| if repeated.contains(["x", "y", "z"][j]) { read[j] } else { row[j] }).collect();
        csv.push_str(&format!("{:?},{:?},{:?},{:?}\n", 0.001 * k as f64, v[0], v[1], v[2]));
    }
    let path = dir.join(format!("lorenz-{repeated}.csv"));
    std::fs::write(&path, csv).unwrap();
    path
}

/// `identify` of `rate` on `data` over the ten quadratic candidates: the JSON report, and
/// what was said on the way (stderr) with its notes.
fn identify(data: &std::path::Path, rate: &str, extra: &[&str]) -> (serde_json::Value, String) {
    let args = ["identify", "--data", data.to_str().unwrap(), "--target", rate, "--terms"];
    let terms = ["x", "y", "z", "x*y", "x*z", "y*z", "x^2", "y^2", "z^2", "--format", "json"];
    let (ok, out, err) = termid(&[&args[..], &terms, extra].concat());
    assert!(ok, "{err}");
    let report = json(&out);
    let said = format!("{err}{}", report["notes"]);
    (report, said)
}

/// `identify --model models/lorenz.toml` of `data`: the model it wrote, and what it said.
fn identified_by_lorenz_model(dir: &std::path::Path, data: &std::path::Path) -> (toml::Value, String) {
    let out = dir.join("identified.toml");
    let (ok, _, err) = termid(&[
        "identify",
        "--model",
        "models/lorenz.toml",
        "--data",
        data.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    (toml::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap(), err)
}

/// ẏ = ρx − y − xz with x read every 10th row: said (a clock of 10 rows), and the three true
/// terms within 0.1 % of ρ, −1, −1 (the cubics between readings 10 ms apart); taken as the
/// rows have it (`--intersample linear`), wrong terms or coefficients 1 % off or worse, which
/// was the default.
#[test]
fn a_state_repeated_between_its_readings_is_read_at_them() {
    let dir = Scratch::new("repeated-x");
    let data = lorenz_log(&dir, "x");
    let (report, notes) = identify(&data, "dy/dt", &[]);
    assert!(
        notes.contains("`x` changes only every 10 rows") && notes.contains("read at its readings"),
        "{notes}"
    );
    let (_, rho, _) = LORENZ_TRUTH;
    let got = chosen_terms(&report);
    let want = [("x", rho), ("x*z", -1.0), ("y", -1.0)];
    assert_eq!(got.len(), 3, "{got:?}");
    for ((term, c), (name, w)) in got.iter().zip(want) {
        assert!(term == name && (c - w).abs() < 1e-3 * w.abs(), "{term} {c} vs {name} {w}");
    }
    let (rows, said) = identify(&data, "dy/dt", &["--intersample", "linear"]);
    assert!(!said.contains("changes only every"), "{said}");
    let got = chosen_terms(&rows);
    let right = got.len() == 3
        && got.iter().zip(want).all(|((term, c), (name, w))| term == name && (c - w).abs() < 0.01 * w.abs());
    assert!(!right, "the staircase fitted as well as the readings: {got:?}");
}

/// The same log with `x` blank between its readings (sensors merged, not filled): refused at
/// the first blank cell, saying what it most often is and what to do (fill it forward, which
/// the test above reads right).
#[test]
fn a_blank_between_readings_is_refused_with_the_remedy() {
    let dir = Scratch::new("blank-x");
    let filled = std::fs::read_to_string(lorenz_log(&dir, "x")).unwrap();
    let mut blank = String::new();
    for (k, line) in filled.lines().enumerate() {
        // data row k (the header is line 0): x read at rows 1, 11, 21, …
        let cells: Vec<&str> = line.split(',').collect();
        let x = if k == 0 || (k - 1) % 10 == 0 { cells[1] } else { "" };
        blank.push_str(&format!("{},{x},{},{}\n", cells[0], cells[2], cells[3]));
    }
    let data = dir.join("blank.csv");
    std::fs::write(&data, blank).unwrap();
    let (ok, _, err) = termid(&[
        "identify",
        "--data",
        data.to_str().unwrap(),
        "--target",
        "dy/dt",
        "--terms",
        "x",
        "y",
        "x*z",
    ]);
    assert!(!ok && err.contains("blank.csv: row 2, column `x`: no reading there"), "{err}");
    assert!(err.contains("fill it forward"), "{err}");
}

/// Every state read every 10th row, through the Lorenz model file: each one said once per
/// equation's admission, and the identified model holds Lorenz's seven coefficients within
/// 0.1 % (and no others).
#[test]
fn a_model_reads_every_repeated_state_at_its_readings() {
    let dir = Scratch::new("repeated-xyz");
    let data = lorenz_log(&dir, "xyz");
    let (model, err) = identified_by_lorenz_model(&dir, &data);
    for state in ["x", "y", "z"] {
        assert!(err.contains(&format!("`{state}` changes only every 10 rows")), "{err}");
    }
    let (sigma, rho, beta) = LORENZ_TRUTH;
    let truth = [
        ("x_dot", vec![("x", -sigma), ("y", sigma)]),
        ("y_dot", vec![("x", rho), ("x*z", -1.0), ("y", -1.0)]),
        ("z_dot", vec![("x*y", 1.0), ("z", -beta)]),
    ];
    for (equation, want) in truth {
        let got = model["equations"][equation]["coefficients"].as_table().unwrap();
        assert_eq!(got.len(), want.len(), "{equation}: {got:?}");
        for (term, w) in want {
            let c = got.get(term).and_then(|c| c["value"].as_float());
            let c = c.unwrap_or_else(|| panic!("{equation}: no {term} in {got:?}"));
            assert!((c - w).abs() < 1e-3 * w.abs(), "{equation}: {term} {c} vs {w}");
        }
    }
}

/// A clean record fitted to rounding (central differences of 1 ms samples) leaves residuals
/// that are smooth but tiny: no column is said to act late.
#[test]
fn a_clean_fit_has_no_dead_time_to_find() {
    let dir = Scratch::new("clean-lorenz");
    let data = lorenz_log(&dir, "");
    for rate in ["dx/dt", "dy/dt", "dz/dt"] {
        let (_, said) = identify(&data, rate, &["--derivative", "central"]);
        assert!(!said.contains("acts on") && !said.contains("changes only every"), "{rate}: {said}");
    }
}

/// Lorenz's `rows` states every 0.01 s from `start` (RK4, ten steps a sample).
fn lorenz_every_10ms(start: &[f64], rows: usize) -> Vec<Vec<f64>> {
    let (sigma, rho, beta) = LORENZ_TRUTH;
    trajectory(start, 0.01, rows, 10, |_, x| {
        vec![sigma * (x[1] - x[0]), x[0] * (rho - x[2]) - x[1], x[0] * x[1] - beta * x[2]]
    })
}

/// `data` cut into runs and identified: by the plain command (what it said returned) and
/// through the model file, ẏ's three true terms each time (within 0.01 %); read in pieces of
/// `chunk_rows`, refused (what it said returned, with the remedy).
fn cut_and_identified(dir: &std::path::Path, data: &std::path::Path, chunk_rows: &str) -> (String, String) {
    let (report, said) = identify(data, "dy/dt", &[]);
    let (_, rho, _) = LORENZ_TRUTH;
    let got = chosen_terms(&report);
    assert_eq!(got.len(), 3, "{got:?}");
    for ((term, c), (name, w)) in got.iter().zip([("x", rho), ("x*z", -1.0), ("y", -1.0)]) {
        assert!(term == name && (c - w).abs() < 1e-4 * w.abs(), "{term} {c} vs {name} {w}");
    }
    let (written, err) = identified_by_lorenz_model(dir, data);
    assert!(err.contains("the run is cut there"), "{err}");
    let y_dot = written["equations"]["y_dot"]["coefficients"].as_table().unwrap();
    assert_eq!(y_dot.len(), 3, "{y_dot:?}");
    let model = ["identify", "--model", "models/lorenz.toml", "--data", data.to_str().unwrap()];
    let (ok, _, err) =
        termid(&[&model[..], &["--derivative", "central", "--chunk-rows", chunk_rows]].concat());
    assert!(!ok && err.contains("--chunk-rows 0"), "{err}");
    (said, err)
}

/// Lorenz from (−8, 7, 27) for 10 s and then, in the same file and on the same clock, from
/// (5, −5, 10) for 10 s more, every 0.01 s.
fn joined_records(dir: &std::path::Path) -> std::path::PathBuf {
    let rows =
        [lorenz_every_10ms(&[-8.0, 7.0, 27.0], 1000), lorenz_every_10ms(&[5.0, -5.0, 10.0], 1000)].concat();
    let mut csv = String::from("t,x,y,z\n");
    for (k, v) in rows.iter().enumerate() {
        csv.push_str(&format!("{:?},{:?},{:?},{:?}\n", 0.01 * k as f64, v[0], v[1], v[2]));
    }
    let path = dir.join("joined.csv");
    std::fs::write(&path, csv).unwrap();
    path
}

/// Two records joined in one file: every state leaps at row 1000 → 1001 and stays. Taken as
/// one motion (the default before), ẏ took all ten candidates with nothing said; now the run
/// is cut there, said with the leaps, and each equation's true terms come back within 0.01 %
/// — by the plain command and through the model file. Read in pieces, a model refuses it
/// (a piece cannot be cut into runs) naming the row.
#[test]
fn records_joined_in_one_file_are_cut_into_runs() {
    let dir = Scratch::new("joined");
    let data = joined_records(&dir);
    let (said, refused) = cut_and_identified(&dir, &data, "600");
    assert!(
        said.contains(
            "`x` (by 8.22), `y` (by -1.24), `z` (by -5.35) leap from row 1000 to row 1001 (t = 10.0 s)"
        ) && said.contains("the run is cut there"),
        "{said}"
    );
    assert!(refused.contains("from row 1000 to row 1001 and stays"), "{refused}");
}

/// A logger's dropouts: Lorenz every 0.01 s for 20 s from (−8, 7, 27), rows 600-640 and
/// 1300-1320 missing (0.42 s and 0.22 s without a sample). Before, refused ("a gap in the
/// record") on the command line (and in Python integrated across as a line); now cut there
/// into runs of their own, said, and ẏ's three true terms within
/// 0.01 % by the plain command and through the model file. Read in pieces, a model refuses it
/// naming the row and the remedy.
#[test]
fn a_run_is_cut_at_a_loggers_dropouts() {
    let dir = Scratch::new("dropouts");
    let rows = lorenz_every_10ms(&[-8.0, 7.0, 27.0], 2000);
    let mut csv = String::from("t,x,y,z\n");
    for (k, v) in
        rows.iter().enumerate().filter(|(k, _)| !(600..641).contains(k) && !(1300..1321).contains(k))
    {
        csv.push_str(&format!("{:?},{:?},{:?},{:?}\n", 0.01 * k as f64, v[0], v[1], v[2]));
    }
    let data = dir.join("dropouts.csv");
    std::fs::write(&data, csv).unwrap();
    let (said, refused) = cut_and_identified(&dir, &data, "400");
    assert!(
        said.contains("`t` jumps at 2 rows (601, 1260; the longest 0.420 s)")
            && said.contains("a logger's dropout"),
        "{said}"
    );
    assert!(refused.contains("row 601"), "{refused}");
}
