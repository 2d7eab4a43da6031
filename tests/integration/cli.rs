//! The `termid` binary end to end.

use crate::common::termid;

/// `termid identify` on the Hald cement data (no time column) with `args` after it.
fn identify_hald(args: &[&str]) -> (bool, String, String) {
    let all: Vec<&str> =
        ["identify", "--data", "tests/data/hald.csv", "--no-time"].iter().chain(args).copied().collect();
    termid(&all)
}

/// Hald's cement against Draper & Smith's sums of squares of its pairs: forward stepping's
/// {x4, x1} leaves 74.76, {x2, x1} 57.90, so x2 in x4's place is 2.25 residual variances
/// better (within the noise: said), and x3 is x1's closest rival ({x4, x3}: 175.74).
#[test]
fn hald_x4_could_as_well_be_x2() {
    let (ok, out, err) = identify_hald(&["--target", "y", "--terms", "x1", "x2", "x3", "x4"]);
    assert!(ok, "{err}");
    assert!(out.contains("the rows hardly tell `x4` from `x2` (-2.25 s²)"), "{out}");
    let (ok, out, err) =
        identify_hald(&["--target", "y", "--terms", "x1", "x2", "x3", "x4", "--format", "json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let x1 = v["rivals"].as_array().and_then(|r| r.iter().find(|w| w["chosen"] == "x1")).expect("x1's rival");
    assert_eq!(x1["instead"], "x3");
    assert!((x1["rise"].as_f64().unwrap() - (175.74 - 74.76) / 7.476).abs() < 0.01, "{x1}");
}

#[test]
fn identify_hald_json() {
    let (ok, out, err) = identify_hald(&[
        "--target",
        "y",
        "--terms",
        "x1",
        "x2",
        "x3",
        "x4",
        "--step-rule",
        "last",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["steps"].as_array().unwrap().len(), 4);
    assert_eq!(v["steps"][0]["term"], "x4");
    assert_eq!(v["chosen_step"], 4);
    let b0 = v["intercept"].as_f64().unwrap();
    assert!((b0 - 62.4054).abs() < 1e-3);
    for key in ["standard_error", "f", "r2"] {
        assert!(v["steps"][1][key].is_number(), "{key}");
    }
    assert!(v["terms"][0]["std_error"].is_number());
}

#[test]
fn identify_text_and_errors() {
    let (ok, out, _) = identify_hald(&["--target", "y", "--terms", "x1", "x2", "x4"]);
    assert!(ok);
    assert!(out.contains("term entered") && out.contains("← chosen"), "{out}");
    let (ok, _, err) = identify_hald(&["--target", "y", "--terms", "x1", "x2**x4"]);
    assert!(!ok);
    assert!(err.contains("1:3") && err.contains("powers are written `u^2`"), "{err}");
    let (ok, _, err) = identify_hald(&["--target", "z", "--terms", "x1"]);
    assert!(!ok);
    assert!(err.contains("hald.csv") && err.contains("`z`"), "{err}");
    // output-error refinement re-simulates a model's equations: no model, no refinement
    let (ok, _, err) = identify_hald(&["--target", "y", "--terms", "x1", "--refine", "y"]);
    assert!(!ok && err.contains("--refine") && err.contains("--model"), "{err}");
    let (ok, _, err) = identify_hald(&["--target", "y", "--terms", "x1", "x2*x1", "x1*x2"]);
    assert!(!ok);
    assert!(err.contains("duplicate"), "{err}");
    // the free parameters not estimated and estimated per run: one or the other
    let (ok, _, err) = crate::common::termid(&[
        "identify",
        "--model",
        "models/new_ship.toml",
        "--data",
        "examples/data/zigzag_15_10.dat",
        "--no-parameters",
        "--per-run",
        "δ_0",
    ]);
    assert!(!ok && err.contains("--no-parameters") && err.contains("--per-run"), "{err}");
}

#[test]
fn integer_weights_equal_repeated_rows() {
    let dir = crate::common::Scratch::new("weights");
    let rows = [
        (1.0, 2.0, 3.1, 1),
        (2.0, 1.0, 4.2, 2),
        (3.0, 5.0, 9.0, 1),
        (4.0, 3.0, 8.7, 3),
        (5.0, 4.0, 11.2, 1),
        (6.0, 7.0, 15.1, 2),
    ];
    let mut weighted = String::from("x,z,y,w\n");
    let mut repeated = String::from("x,z,y\n");
    for (x, z, y, w) in rows {
        weighted += &format!("{x},{z},{y},{w}\n");
        for _ in 0..w {
            repeated += &format!("{x},{z},{y}\n");
        }
    }
    let (a, b) = (dir.join("weighted.csv"), dir.join("repeated.csv"));
    std::fs::write(&a, weighted).unwrap();
    std::fs::write(&b, repeated).unwrap();
    let fit = |file: &std::path::Path, extra: &[&str]| {
        let mut args = vec![
            "identify",
            "--data",
            file.to_str().unwrap(),
            "--no-time",
            "--target",
            "y",
            "--terms",
            "x",
            "z",
            "--step-rule",
            "last",
            "--format",
            "json",
        ];
        args.extend_from_slice(extra);
        let (ok, out, err) = termid(&args);
        assert!(ok, "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        v["terms"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| (t["term"].as_str().unwrap().to_string(), t["coefficient"].as_f64().unwrap()))
            .collect::<Vec<_>>()
    };
    let (w, r) = (fit(&a, &["--weight", "w"]), fit(&b, &[]));
    assert_eq!(w.len(), 2);
    for ((tw, cw), (tr, cr)) in w.iter().zip(&r) {
        assert_eq!(tw, tr);
        assert!((cw - cr).abs() < 1e-12 * cr.abs().max(1.0), "{tw}: {cw} vs {cr}");
    }
}

#[test]
fn compare_runs_every_backend() {
    let dir = crate::common::Scratch::new("compare");
    let csv = crate::common::lorenz_csv(&dir, "3");
    let (ok, out, err) = termid(&[
        "compare",
        "--model",
        "models/lorenz.toml",
        "--data",
        csv.to_str().unwrap(),
        "--no-intercept",
        "--replay",
        csv.to_str().unwrap(),
        "--dt",
        "0.001",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let names: Vec<&str> = v.as_array().unwrap().iter().map(|e| e["backend"].as_str().unwrap()).collect();
    assert_eq!(names, ["stepwise", "efroymson", "best-subset", "sparse", "stlsq"]);
    for e in v.as_array().unwrap() {
        assert_eq!(e["equations"].as_array().unwrap().len(), 3);
        assert!(e["equations"][0]["time_ms"].as_f64().unwrap() >= 0.0);
        assert!(e["replay"].is_array(), "{}", e["replay"]);
    }
}

/// A replay file of a single sample is refused before the fits (it used to replay zero steps
/// and report an error of 0 for every back-end).
#[test]
fn compare_refuses_a_one_sample_replay() {
    let dir = crate::common::Scratch::new("compare-one");
    let csv = crate::common::lorenz_csv(&dir, "1");
    let text = std::fs::read_to_string(&csv).unwrap();
    let one = dir.join("one.csv");
    std::fs::write(&one, text.lines().take(2).collect::<Vec<_>>().join("\n")).unwrap();
    let (ok, _, err) = termid(&[
        "compare",
        "--model",
        "models/lorenz.toml",
        "--data",
        csv.to_str().unwrap(),
        "--no-intercept",
        "--replay",
        one.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("at least two rows"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// Issue 7 §1: runs with the basin's own column names, units and layout, via a dataset file.
#[test]
fn identify_from_a_dataset_file() {
    let dir = crate::common::Scratch::new("dataset-cli");
    let csv = crate::common::lorenz_csv(&dir, "4");
    // rewrite as a whitespace log with other names, a preamble, and time in milliseconds
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut log = String::from("lorenz rig\nrecorded by hand\nms X Y Z\n");
    for line in text.lines().skip(1) {
        let f: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        log += &format!("{} {} {} {}\n", f[0] * 1000.0, f[1], f[2], f[3]);
    }
    std::fs::write(dir.join("rig.log"), log).unwrap();
    std::fs::write(
        dir.join("set.toml"),
        "[columns]\nt = \"ms [fortnight]\"\nx = \"X\"\ny = \"Y\"\nz = \"Z\"\n\n[[runs]]\nfile = \"rig.log\"\ndelimiter = \"whitespace\"\nskip = 2\n",
    )
    .unwrap();
    // an unknown unit: a clear error naming it
    let set = dir.join("set.toml");
    let (ok, _, err) = termid(&[
        "identify",
        "--model",
        "models/lorenz.toml",
        "--dataset",
        set.to_str().unwrap(),
        "--no-intercept",
    ]);
    assert!(!ok && err.contains("unknown unit [fortnight]"), "{err}");
    std::fs::write(&set, std::fs::read_to_string(&set).unwrap().replace("[fortnight]", "[ms]")).unwrap();
    let (ok, out, err) = termid(&[
        "identify",
        "--model",
        "models/lorenz.toml",
        "--dataset",
        set.to_str().unwrap(),
        "--no-intercept",
        "--derivative",
        "savitzky-golay",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    // time declared in ms, converted to s: σ = 10 comes back
    let x = &v["x_dot"]["terms"];
    assert_eq!(x.as_array().unwrap().len(), 2, "{x}");
    for t in x.as_array().unwrap() {
        assert!((t["coefficient"].as_f64().unwrap().abs() - 10.0).abs() < 1e-3, "{t}");
    }
}

/// Issue 7 §4: a model validated on held-out runs: errors per run, metrics side by side.
#[test]
fn validate_sets_model_and_measurement_side_by_side() {
    let dir = crate::common::Scratch::new("validate");
    let run = dir.join("z.csv");
    let (ok, _, err) = termid(&["simulate", "-m", "zigzag:20/20", "--out", run.to_str().unwrap()]);
    assert!(ok, "{err}");
    let svg = dir.join("figs");
    let (ok, out, err) = termid(&[
        "validate",
        "--data",
        run.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    // the true model against its own run: the gap is only what replaying the rudder from
    // 0.2 s samples (linear between them, the kinks fall between) costs
    let psi = v["gap"]["states"].as_array().unwrap().iter().find(|s| s[0] == "ψ").unwrap().clone();
    assert!(psi[2].as_f64().unwrap() < 1e-3, "{psi}");
    let m = &v["metrics"][0];
    assert!(
        (m["measured"]["first_overshoot_deg"].as_f64().unwrap()
            - m["simulated"]["first_overshoot_deg"].as_f64().unwrap())
        .abs()
            < 0.05
    );
    assert!(svg.join("validate_z.svg").exists());
    // a zigzag's replayed rudder does not part the ship from itself: predictable throughout
    assert!(v["predictable_for"][0]["seconds"].is_null(), "{}", v["predictable_for"]);
    // the text says how its overshoots are read, and how that differs from `simulate`'s
    let (ok, out, err) = termid(&["validate", "--data", run.to_str().unwrap()]);
    assert!(
        ok && out.contains("beyond the heading at each rudder reversal") && out.contains("`simulate`"),
        "{out}{err}"
    );
}

/// With --model, --backend replaces the file's back-ends (it was silently ignored), and
/// --choose prints the table it chose from and writes the chosen model.
#[test]
fn backend_and_choose_with_a_model() {
    let dir = crate::common::Scratch::new("choose");
    let csv = crate::common::lorenz_csv(&dir, "3");
    let half = dir.join("lorenz2.csv");
    // a second run: the first one's second half, so that one run can be left out
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut second = vec![lines[0]];
    second.extend(&lines[lines.len() / 2..]);
    std::fs::write(&half, second.join("\n")).unwrap();
    let identify = |more: &[&str]| {
        let mut args = vec!["identify", "--model", "models/lorenz.toml", "--data", csv.to_str().unwrap()];
        args.extend(more);
        termid(&args)
    };
    let (ok, out, err) = identify(&["--no-intercept", "--backend", "best-subset"]);
    assert!(ok, "{err}");
    assert_eq!(out.matches("back-end best-subset").count(), 3, "{out}");
    let written = dir.join("chosen.toml");
    let two = half.to_str().unwrap();
    let (ok, out, err) = identify(&[
        two,
        "--no-intercept",
        "--choose",
        "stepwise,sparse",
        "--compare",
        "x,y,z",
        "--out",
        written.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("chosen by prediction") && out.contains("← chosen"), "{out}");
    assert!(out.contains("\nstepwise") && out.contains("\nsparse"), "{out}");
    assert!(std::fs::read_to_string(&written).unwrap().contains("x*z"));
    let (ok, _, err) = identify(&["--choose", "lasso"]);
    assert!(!ok && err.contains("unknown back-end `lasso`"), "{err}");
    // a parameter stage needs a free parameter to estimate
    let (ok, _, err) = identify(&["--no-intercept", "--parameters"]);
    assert!(!ok && err.contains("no parameter is free"), "{err}");
    // a model file among the configurations: a library without x·z cannot predict y
    let text = std::fs::read_to_string("models/lorenz.toml").unwrap().replace("\"x*z\", ", "");
    let poor = dir.join("no_xz.toml");
    std::fs::write(&poor, text).unwrap();
    let choice = format!("{},stepwise", poor.display());
    let (ok, out, err) = identify(&[two, "--no-intercept", "--choose", &choice, "--compare", "x,y,z"]);
    assert!(ok, "{err}");
    let chosen = out.lines().find(|l| l.contains("← chosen")).unwrap_or_default();
    assert!(chosen.starts_with("stepwise"), "{out}");
}

/// A plain CSV as people write it: ASCII `delta` and `psi` (the model file's aliases of δ and
/// ψ) and a European spreadsheet's semicolons with decimal commas, tabs, or blanks aligning
/// the columns are read as the model's names; the same run either way gives the same validation.
#[test]
fn plain_files_with_aliases_and_semicolons() {
    let dir = crate::common::Scratch::new("plain");
    let z = dir.join("z.csv");
    let (ok, _, err) = termid(&["simulate", "-m", "zigzag:20/20", "--out", z.to_str().unwrap()]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&z).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().replace('δ', "delta").replace('ψ', "psi");
    let ascii = dir.join("ascii.csv");
    std::fs::write(&ascii, format!("{header}\n{}\n", lines.clone().collect::<Vec<_>>().join("\n"))).unwrap();
    let european = dir.join("european.csv");
    let body: Vec<String> = lines.map(|l| l.replace(',', ";").replace('.', ",")).collect();
    std::fs::write(&european, format!("{}\n{}\n", header.replace(',', ";"), body.join("\n"))).unwrap();
    let validate = |f: &std::path::Path| {
        let (ok, out, err) = termid(&["validate", "--data", f.to_str().unwrap(), "--format", "json"]);
        assert!(ok, "{err}");
        (out, err)
    };
    let (a, err) = validate(&ascii);
    assert!(err.contains("column `delta` read as `δ`"), "{err}");
    // the model's u0 = first:u on a clean record: no warning; on a noisy one, a warning
    assert!(!err.contains("noisy sample"), "{err}");
    let mut rows: Vec<Vec<String>> = text.lines().map(|l| l.split(',').map(String::from).collect()).collect();
    let u = rows[0].iter().position(|h| h == "u").unwrap();
    for (k, r) in rows.iter_mut().skip(1).enumerate() {
        r[u] = (r[u].parse::<f64>().unwrap() + 0.01 * ((k * 7919 % 13) as f64 - 6.0) / 6.0).to_string();
    }
    let noisy = dir.join("noisy.csv");
    std::fs::write(&noisy, rows.iter().map(|r| r.join(",")).collect::<Vec<_>>().join("\n")).unwrap();
    let (_, err) = validate(&noisy);
    assert!(err.contains("`u0 = first:u` reads one noisy sample") && err.contains("mean:u:2"), "{err}");
    let (b, _) = validate(&european);
    let strip = |s: &str| {
        s.lines().filter(|l| !l.contains(".csv") && !l.contains(".dat")).collect::<Vec<_>>().join("\n")
    };
    assert_eq!(strip(&a), strip(&b));
    // a tab-separated export, and columns aligned by blanks under a comment (a Fortran
    // program's, `save -ascii`'s): the same run (both refused once, "convert the file")
    let ascii_text = std::fs::read_to_string(&ascii).unwrap();
    let tabs = dir.join("tabs.dat");
    std::fs::write(&tabs, ascii_text.replace(',', "\t")).unwrap();
    let aligned: Vec<String> = ascii_text
        .lines()
        .map(|l| l.split(',').map(|c| format!("{c:>22}")).collect::<Vec<_>>().join("  "))
        .collect();
    let blanks = dir.join("blanks.dat");
    std::fs::write(&blanks, format!("# a basin's logger\n{}\n", aligned.join("\n"))).unwrap();
    for f in [&tabs, &blanks] {
        assert_eq!(strip(&a), strip(&validate(f).0), "{}", f.display());
    }
    // blanks that part names as well as columns: refused, saying so
    let spaced = dir.join("spaced.dat");
    std::fs::write(&spaced, "time [s]  x [m]\n0  1.5\n0.1  1.6\n").unwrap();
    let (ok, _, err) = termid(&[
        "identify",
        "--data",
        spaced.to_str().unwrap(),
        "--target",
        "x",
        "--terms",
        "1",
        "--time",
        "time [s]",
    ]);
    assert!(!ok && err.contains("separated by blanks") && err.contains("4 names are 2 readings"), "{err}");
    // the rudder in degrees in a plain file: refused with its row, pointing to a dataset file
    let mut rows: Vec<Vec<String>> = text.lines().map(|l| l.split(',').map(String::from).collect()).collect();
    let d = rows[0].iter().position(|h| h == "δ").unwrap();
    for r in rows.iter_mut().skip(1) {
        r[d] = (r[d].parse::<f64>().unwrap().to_degrees()).to_string();
    }
    let degrees = dir.join("degrees.csv");
    std::fs::write(&degrees, rows.iter().map(|r| r.join(",")).collect::<Vec<_>>().join("\n")).unwrap();
    let (ok, _, err) =
        termid(&["identify", "--model", "models/oltmann1973.toml", "--data", degrees.to_str().unwrap()]);
    assert!(
        !ok && err.contains("degrees.csv: row") && err.contains("`δ`") && err.contains("--dataset"),
        "{err}"
    );
}

/// Seven rows of one run: an equation that uses up the degrees of freedom is refused with its
/// numbers, and nothing is written.
#[test]
fn a_model_without_degrees_of_freedom_is_not_written() {
    let dir = crate::common::Scratch::new("dof");
    let z = dir.join("z.csv");
    let (ok, _, err) = termid(&["simulate", "-m", "zigzag:20/20", "--out", z.to_str().unwrap()]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&z).unwrap();
    let short = dir.join("short.csv");
    std::fs::write(&short, text.lines().take(8).collect::<Vec<_>>().join("\n")).unwrap();
    let out = dir.join("id.toml");
    let (ok, _, err) = termid(&[
        "identify",
        "--model",
        "models/oltmann1973.toml",
        "--data",
        short.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("7 rows for") && err.contains("no degrees of freedom are left"), "{err}");
    assert!(!out.exists());
}

/// What termid prints says what happened, in words, with units and the decimals the data
/// support (issue 28, item 10): no "noisy sample" warning on noise-free runs, an alias is a
/// note and not a unit, a replay says where it ended, a spiral without a loop says so, a
/// simulation without a manoeuvre or duration names `-m`, the Monte-Carlo table names its
/// metrics in words, validation's errors carry three significant figures.
#[test]
fn words_say_what_happened() {
    let dir = crate::common::Scratch::new("words");
    let p = |name: &str| dir.join(name).to_str().unwrap().to_string();
    for (m, f) in [("zigzag:30/10", "z30.csv"), ("zigzag:20/20:port", "z20.csv")] {
        let (ok, _, err) = termid(&["simulate", "-m", m, "--out", &p(f)]);
        assert!(ok, "{err}");
    }
    // noise-free runs with the paper's u0 = first:u: nothing to warn about
    let (ok, _, err) =
        termid(&["identify", "--model", "models/oltmann1973.toml", "--data", &p("z30.csv"), &p("z20.csv")]);
    assert!(ok && !err.contains("noisy sample"), "{err}");
    // an alias read is a note, not a unit conversion
    let text = std::fs::read_to_string(dir.join("z20.csv")).unwrap().replacen('δ', "delta", 1);
    std::fs::write(dir.join("alias.csv"), text).unwrap();
    let (ok, out, err) = termid(&["validate", "--data", &p("alias.csv")]);
    assert!(ok, "{err}");
    assert!(
        err.contains("note: ")
            && err.contains("read as `δ` (an alias of the model)")
            && !err.contains("unit: "),
        "{err}"
    );
    // three significant figures: `ψ 0.0123 / 0.0456 °`, not six
    let errors = out.lines().find(|l| l.contains("alias.csv:")).unwrap();
    for cell in errors.split(", ") {
        let number = cell.split_whitespace().nth(1).unwrap().trim_start_matches("alias.csv:");
        let digits = number.trim_start_matches(['-', '0', '.']).chars().filter(char::is_ascii_digit).count();
        assert!(digits <= 3 || number.contains('e'), "{cell} in {errors}");
    }
    let (ok, out, err) = termid(&["simulate", "-m", &format!("replay:{}", p("z20.csv"))]);
    assert!(ok && out.contains("ended at t = ") && out.contains("termid validate"), "{out}{err}");
    let (ok, out, _) = termid(&["simulate", "-m", "spiral"]);
    assert!(ok && out.contains("loop width") && out.contains("none: both branches"), "{out}");
    let (ok, _, err) = termid(&["simulate", "--model", "models/lorenz.toml"]);
    assert!(!ok && err.contains("-m zigzag:20/20") && err.contains("--duration"), "{err}");
    let model = p("identified.toml");
    let (ok, _, err) = crate::common::identify_sample_records(std::path::Path::new(&model), "kalman", &[]);
    assert!(ok, "{err}");
    let (ok, out, err) = termid(&["simulate", "--model", &model, "-m", "turning:35", "--monte-carlo", "10"]);
    assert!(ok, "{err}");
    assert!(out.contains("tactical diameter [m]") && !out.contains("tactical_diameter_m"), "{out}");
    // the identified model is named as identified, not as the model its candidates came from
    assert!(out.starts_with("identified from examples/data/runs.toml"), "{out}");
}

/// `--dataset` is repeatable wherever runs are read: the runs of two dataset files (two
/// basins, two campaigns) identified together are the runs of one file that lists them all.
#[test]
fn datasets_add_up() {
    let dir = crate::common::Scratch::new("two-datasets");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data");
    let all = std::fs::read_to_string(root.join("runs.toml")).unwrap();
    let (head, runs) = all.split_at(all.find("[[runs]]").unwrap());
    let parts: Vec<&str> = runs.split("[[runs]]").filter(|r| !r.trim().is_empty()).collect();
    let folder = format!("folder = \"{}\"\n", root.display());
    let write = |name: &str, list: &[&str]| {
        let body: String = list.iter().map(|r| format!("[[runs]]{r}")).collect();
        std::fs::write(dir.join(name), format!("{folder}{head}{body}")).unwrap();
        dir.join(name).to_str().unwrap().to_string()
    };
    let (one, a, b) = (write("all.toml", &parts), write("a.toml", &parts[..2]), write("b.toml", &parts[2..]));
    let fit = |datasets: &[&str]| {
        let mut args = vec![
            "identify",
            "--model",
            "examples/data/ship.toml",
            "--derivative",
            "kalman",
            "--format",
            "json",
        ];
        for d in datasets {
            args.extend(["--dataset", d]);
        }
        let (ok, out, err) = termid(&args);
        assert!(ok, "{err}");
        out
    };
    assert_eq!(fit(&[&one]), fit(&[&a, &b]));
}

/// With `--monte-carlo`, `validate` counts the measured metrics within the model's own 90 %
/// band and names those outside: the shipped held-out run's two overshoots are counted; the
/// same run with its heading and yaw rate doubled (overshoots twice as large) falls outside on
/// both, named in the JSON and the text.
#[test]
fn validate_says_which_measurements_leave_the_models_band() {
    let dir = crate::common::Scratch::new("validate_band");
    let model = dir.join("ship.toml");
    let (ok, _, err) = crate::common::identify_sample_records(&model, "kalman", &[]);
    assert!(ok, "{err}");
    let validate = |set: &str| {
        let (ok, out, err) = termid(&[
            "validate",
            "--model",
            model.to_str().unwrap(),
            "--dataset",
            set,
            "--monte-carlo",
            "40",
            "--format",
            "json",
        ]);
        assert!(ok, "{err}");
        serde_json::from_str::<serde_json::Value>(&out).unwrap()
    };
    let v = validate("examples/data/held_out.toml");
    let band = &v["within_band"];
    let outside = band["outside"].as_array().unwrap().len();
    assert_eq!(band["within"].as_u64().unwrap() as usize + outside, 2, "{band}");
    // the same run turning twice as far: its heading and rate doubled
    let text = std::fs::read_to_string("examples/data/zigzag_25_10.dat").unwrap();
    let doubled: Vec<String> = text
        .lines()
        .map(|line| {
            let mut cells: Vec<String> = line.split_whitespace().map(String::from).collect();
            if let (Some(r), Some(psi)) = (
                cells.get(3).and_then(|c| c.parse::<f64>().ok()),
                cells.get(4).and_then(|c| c.parse::<f64>().ok()),
            ) {
                cells[3] = (2.0 * r).to_string();
                cells[4] = (2.0 * psi).to_string();
                cells.join(" ")
            } else {
                line.to_string()
            }
        })
        .collect();
    std::fs::write(dir.join("doubled.dat"), doubled.join("\n")).unwrap();
    let set = dir.join("doubled.toml");
    std::fs::write(
        &set,
        std::fs::read_to_string("examples/data/held_out.toml")
            .unwrap()
            .replace("zigzag_25_10.dat", "doubled.dat"),
    )
    .unwrap();
    let v = validate(set.to_str().unwrap());
    let band = &v["within_band"];
    assert_eq!(band["within"], 0, "{band}");
    let outside: Vec<&str> =
        band["outside"].as_array().unwrap().iter().map(|o| o.as_str().unwrap()).collect();
    assert!(outside.len() == 2 && outside.iter().all(|o| o.ends_with("of doubled.dat")), "{outside:?}");
    let (ok, out, err) = termid(&[
        "validate",
        "--model",
        model.to_str().unwrap(),
        "--dataset",
        set.to_str().unwrap(),
        "--monte-carlo",
        "40",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("measured within the model's 90 % band: 0 of 2 metrics (outside: 1st overshoot"),
        "{out}"
    );
    assert!(out.contains("measured outside"), "{out}");
}
