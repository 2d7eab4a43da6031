//! Hostile inputs through the `termid` binary (issue 13): every one ends, under a time limit,
//! with a clear error or an honoured request, never a hang, an abort, a half-written file or
//! a silent surprise. One test per class of defect.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::Scratch;

/// Runs `termid args` and kills it if it has not ended within `limit`: (exit code, stdout,
/// stderr). A process that had to be killed fails the test.
pub(crate) fn run_within(args: &[&str], limit: Duration, env: &[(&str, &str)]) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_termid"))
        .args(args)
        .envs(env.iter().copied())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run termid");
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            let out = child.wait_with_output().expect("output");
            return (
                status.code().unwrap_or(-1),
                String::from_utf8_lossy(&out.stdout).into(),
                String::from_utf8_lossy(&out.stderr).into(),
            );
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("termid {} did not end within {limit:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// An error: exit code 2 within 30 s, the message on standard error containing every `needle`.
pub(crate) fn refused(args: &[&str], needles: &[&str]) -> String {
    let (code, _, err) = run_within(args, Duration::from_secs(30), &[]);
    assert_eq!(code, 2, "termid {}: expected an error, got exit {code}\n{err}", args.join(" "));
    for n in needles {
        assert!(err.contains(n), "termid {}: `{n}` not in\n{err}", args.join(" "));
    }
    assert!(!err.contains("panicked") && !err.contains("internal error"), "{err}");
    err
}

/// Success within 60 s; stdout.
pub(crate) fn succeeds(args: &[&str]) -> String {
    let (code, out, err) = run_within(args, Duration::from_secs(60), &[]);
    assert_eq!(code, 0, "termid {}:\n{err}", args.join(" "));
    out
}

pub(crate) fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The default model with `backend` as the v̇ equation's back-end.
pub(crate) fn model_with_backend(dir: &Path, backend: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string("models/oltmann1973.toml").unwrap();
    let marker = "[equations.v_dot]\n";
    assert!(text.contains(marker));
    let start = text.find(marker).unwrap();
    let line = start + text[start..].find("\nbackend = ").unwrap() + 1;
    let end = line + text[line..].find('\n').unwrap();
    let text = format!("{}backend = {backend}{}", &text[..line], &text[end..]);
    let path = dir.join("sparse.toml");
    std::fs::write(&path, text).unwrap();
    path
}

pub(crate) fn zigzag(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("z30_10.csv");
    succeeds(&["simulate", "-m", "zigzag:30/10", "--out", s(&path)]);
    path
}

/// Files in a folder (hidden temporary ones included), sorted.
pub(crate) fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Item 1: a panic ends the process with an error (it used to hang on the spinner's channel), and
/// sparse constraints on candidates that do not exist are refused where the model is read.
#[test]
fn panics_end_the_process_and_bad_constraints_are_refused_at_load() {
    let dir = Scratch::new("hostile-panic");
    let (code, _, err) = run_within(
        &["identify", "--data", "tests/data/hald.csv", "--no-time", "--target", "y", "--terms", "x1"],
        Duration::from_secs(20),
        &[("TERMID_TEST_PANIC", "1")],
    );
    assert_eq!(code, 3, "{err}");
    assert!(err.contains("internal error") && err.contains("bug in termid"), "{err}");
    let z = zigzag(&dir);
    for (backend, needle) in [
        (r#"{ method = "sparse", fixed = [[99, 2.0]] }"#, "backend.fixed[0]"),
        (r#"{ method = "sparse", signs = [["u*w", 1]] }"#, "backend.signs[0]"),
        (r#"{ method = "sparse", signs = [["r^9", 1]] }"#, "not one of the 29 candidates"),
        (
            r#"{ method = "sparse", equalities = [{ terms = [[99, 1.0]], value = 0.0 }] }"#,
            "equalities[0].terms[0]",
        ),
        (r#"{ method = "sparse", fixed = [["u*v", 1.0]], signs = [["v*u", -1]] }"#, ""),
    ] {
        let model = model_with_backend(&dir, backend);
        let args = ["identify", "--model", s(&model), "--data", s(&z), "--equation", "v_dot"];
        if needle.is_empty() {
            // a fixed value against its sign: the constraints conflict, and say which
            refused(&args, &["constraints conflict", "u*v = 1", "u*v ≤ 0"]);
        } else {
            refused(&args, &["sparse.toml:", needle]);
        }
    }
    // by term text, in any spelling, a constraint is honoured
    let model = model_with_backend(&dir, r#"{ method = "sparse", fixed = [["r*v^2/u", -5.0]] }"#);
    let out = succeeds(&["identify", "--model", s(&model), "--data", s(&z), "--equation", "v_dot"]);
    assert!(out.contains("r*v^2/u                    -5.00000            0     fixed"), "{out}");
}

/// Item 2: outputs are checked before any work and written atomically: a failing command leaves
/// the old file as it was and nothing new.
#[test]
fn failed_commands_leave_old_files_and_nothing_new() {
    let dir = Scratch::new("hostile-atomic");
    let out = dir.join("a.csv");
    std::fs::write(&out, "old contents\n").unwrap();
    let nope = dir.join("nope/x.svg");
    refused(
        &["simulate", "-m", "zigzag:20/20", "--out", s(&out), "--svg", s(&nope)],
        &["nope", "does not exist"],
    );
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "old contents\n");
    assert_eq!(listing(&dir), ["a.csv"]);
    // a model file is not replaced by a failed identification
    let model = dir.join("m.toml");
    std::fs::write(&model, "# mine\n").unwrap();
    refused(
        &["identify", "--model", "models/oltmann1973.toml", "--data", s(&out), "--out", s(&model)],
        &["a.csv"],
    );
    assert_eq!(std::fs::read_to_string(&model).unwrap(), "# mine\n");
    assert_eq!(listing(&dir), ["a.csv", "m.toml"]);
    // a folder that is someone else's is never replaced by reproduce
    std::fs::create_dir(dir.join("thesis")).unwrap();
    std::fs::write(dir.join("thesis/chapter1.tex"), "").unwrap();
    refused(&["reproduce", "--out", s(&dir.join("thesis"))], &["did not write"]);
    assert!(dir.join("thesis/chapter1.tex").exists());
    // success replaces, through a link too
    succeeds(&["simulate", "-m", "zigzag:20/20", "--out", s(&out)]);
    assert!(std::fs::read_to_string(&out).unwrap().starts_with("t,"));
    assert_eq!(listing(&dir), ["a.csv", "m.toml", "thesis"]);
}

/// Item 3: two `reproduce --out DIR` at once each leave a whole folder: one run's files, never a
/// mix of both.
#[test]
fn concurrent_reproductions_do_not_splice() {
    let dir = Scratch::new("hostile-reproduce");
    let target = dir.join("out");
    let spawn = |to: &Path, extra: Option<&str>| {
        let mut args = vec!["reproduce", "--out", s(to)];
        args.extend(extra);
        Command::new(env!("CARGO_BIN_EXE_termid"))
            .args(&args)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let finish = |c: std::process::Child| {
        let out = c.wait_with_output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    let read = |d: &Path| {
        (
            std::fs::read_to_string(d.join("report.md")).unwrap(),
            std::fs::read_to_string(d.join("summary.json")).unwrap(),
        )
    };
    // each option alone, for reference
    let (ref_a, ref_b) = (dir.join("a"), dir.join("b"));
    finish(spawn(&ref_a, None));
    finish(spawn(&ref_b, Some("--rudder-at-end-of-step")));
    let (a, b) = (read(&ref_a), read(&ref_b));
    assert_ne!(a.0, b.0, "the two options should give different reports");
    for _ in 0..2 {
        let (x, y) = (spawn(&target, None), spawn(&target, Some("--rudder-at-end-of-step")));
        finish(x);
        finish(y);
        let got = read(&target);
        assert!(got == a || got == b, "report.md and summary.json are not one run's");
        for f in std::fs::read_dir(target.join("figures")).unwrap() {
            let svg = std::fs::read_to_string(f.unwrap().path()).unwrap();
            assert!(svg.trim_end().ends_with("</svg>"), "a figure is cut off");
        }
        assert_eq!(listing(&dir), ["a", "b", "out"], "a sibling folder was left behind");
    }
}

/// Item 4: one noise-free run: the covariance is symmetric, the model is written and reloads.
#[test]
fn a_single_noise_free_run_identifies() {
    let dir = Scratch::new("hostile-single");
    let z = zigzag(&dir);
    let text = std::fs::read_to_string(&z).unwrap();
    for rows in [25usize, 100, 250, 501] {
        let part = dir.join(format!("z{rows}.csv"));
        let lines: Vec<&str> = text.lines().take(rows + 1).collect();
        std::fs::write(&part, lines.join("\n")).unwrap();
        let m = dir.join(format!("m{rows}.toml"));
        succeeds(&["identify", "--model", "models/oltmann1973.toml", "--data", s(&part), "--out", s(&m)]);
        assert!(termid::plugins::load(&m).is_ok());
    }
}

/// Item 5: work too large for memory is refused before anything is allocated, with its size.
#[test]
fn work_too_large_for_memory_is_refused_with_its_size() {
    let dir = Scratch::new("hostile-memory");
    refused(
        &["simulate", "-m", "turning:20", "--duration", "3.9e7", "--sample", "0.04"],
        &["would take", "GB"],
    );
    refused(
        &[
            "simulate",
            "--model",
            "models/lorenz.toml",
            "--duration",
            "1e6",
            "--sample",
            "0.01",
            "--dt",
            "0.01",
        ],
        &["would take"],
    );
    let z = zigzag(&dir);
    refused(
        &["identify", "--model", "models/oltmann1973.toml", "--data", s(&z), "--resample", "1e-9"],
        &["would take", "--resample"],
    );
    let m = dir.join("m.toml");
    succeeds(&["identify", "--model", "models/oltmann1973.toml", "--data", s(&z), "--out", s(&m)]);
    refused(
        &["simulate", "--model", s(&m), "-m", "zigzag:20/20", "--monte-carlo", "100000000"],
        &["Monte-Carlo", "would take"],
    );
    refused(
        &["identify", "--data", "/dev/zero", "--target", "y", "--terms", "x"],
        &["/dev/zero", "not a text file"],
    );
    refused(&["simulate", "--model", "/dev/zero"], &["/dev/zero", "not a text file"]);
}

/// Items 6-8: ship simulation honours or refuses every option; rudder angles beyond the limit and
/// malformed per-run parameters are refused.
#[test]
fn simulate_options_are_honoured_or_refused() {
    let base = succeeds(&["simulate", "-m", "zigzag:20/20", "--format", "json"]);
    let faster = succeeds(&["simulate", "-m", "zigzag:20/20", "--param", "u0=1.5", "--format", "json"]);
    assert_ne!(base, faster, "--param u0 was ignored");
    let v: serde_json::Value = serde_json::from_str(&faster).unwrap();
    assert!(v["metrics"]["first_overshoot_deg"].is_number(), "{v}");
    refused(&["simulate", "-m", "zigzag:20/20", "--initial", "u=1.5"], &["--initial", "u0"]);
    refused(&["simulate", "-m", "zigzag:20/20", "--input", "δ=0.3"], &["--input", "replay"]);
    refused(&["simulate", "-m", "zigzag:20/20", "--sample", "0.1"], &["0.1", "multiple", "0.04"]);
    refused(
        &[
            "simulate",
            "--model",
            "models/lorenz.toml",
            "--duration",
            "1",
            "--sample",
            "0.015",
            "--dt",
            "0.01",
        ],
        &["multiple"],
    );
    refused(&["simulate", "-m", "zigzag:20/20", "--param", "speed=1.5"], &["speed", "not a parameter", "u0"]);
    refused(
        &["simulate", "--model", "models/lorenz.toml", "--duration", "1", "--param", "rho=nan"],
        &["not a finite number"],
    );
    refused(
        &["simulate", "--model", "models/lorenz.toml", "--duration", "1", "--param", "zeta=1"],
        &["zeta", "not a parameter"],
    );
    for m in ["turning:1000", "pullout:1000", "zigzag:90/10", "spiral:40/5/60"] {
        refused(&["simulate", "-m", m], &["beyond the ship's rudder limit of 35°"]);
    }
    let hald = ["identify", "--data", "tests/data/hald.csv", "--no-time", "--target", "y", "--terms", "x1*c"];
    for p in ["c=mean:x1:-3", "c=mean:x1:abc", "c=nan", "c=last:x1"] {
        let mut args = hald.to_vec();
        args.extend(["--param", p]);
        refused(&args, &["--param", "c"]);
    }
}

/// An option that needs `--model` is refused without one, whatever else is given: clap let
/// `identify --terms-file q.txt --out m.toml` run without it (the conflict of `--model` with
/// `--terms` bypassed the requirement), and nothing was written, nothing said.
#[test]
fn options_that_need_a_model_are_refused_without_one() {
    let plain =
        ["identify", "--data", "tests/data/hald.csv", "--no-time", "--target", "y", "--terms", "x1", "x2"];
    for extra in
        [&["--out", "never.toml"][..], &["--equation", "y"], &["--keep-unphysical"], &["--chunk-rows", "10"]]
    {
        let mut args = plain.to_vec();
        args.extend(extra);
        refused(&args, &["--model"]);
    }
    assert!(!std::path::Path::new("never.toml").exists());
    refused(
        &["identify", "--data", "tests/data/hald.csv", "--model", "models/lorenz.toml", "--terms", "x"],
        &["--terms cannot be used with --model"],
    );
}

/// Item 9: data the dataset path refuses is refused on the plain path too; a refinement of no
/// state, a rate in degrees declared in radians and a mapping to an unknown variable.
#[test]
fn plain_and_dataset_files_get_the_same_checks() {
    let dir = Scratch::new("hostile-data");
    let z = zigzag(&dir);
    let text = std::fs::read_to_string(&z).unwrap();
    // a gap: rows 100-199 missing
    let gap = dir.join("gap.csv");
    let lines: Vec<&str> =
        text.lines().enumerate().filter(|(i, _)| !(100..200).contains(i)).map(|(_, l)| l).collect();
    std::fs::write(&gap, lines.join("\n")).unwrap();
    // (cut there into two runs on both paths, said: a logger's dropout; the model's checks
    // then refuse what one zigzag identifies)
    let plain = ["identify", "--data", s(&gap), "--target", "dr/dt", "--terms", "δ"];
    for (args, exit) in
        [(&plain[..], 0), (&["identify", "--model", "models/oltmann1973.toml", "--data", s(&gap)], 2)]
    {
        let (code, _, err) = run_within(args, Duration::from_secs(60), &[]);
        assert!(
            code == exit && err.contains("gap.csv: `t` jumps by") && err.contains("the run is cut there"),
            "{err}"
        );
    }
    refused(
        &["identify", "--model", "models/oltmann1973.toml", "--data", s(&z), "--refine", ","],
        &["names no state"],
    );
    // r written in degrees per second where ψ is in radians
    let mut out = Vec::new();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let r = header.split(',').position(|c| c == "r").unwrap();
    out.push(header.to_string());
    for l in lines {
        let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
        cells[r] = format!("{:?}", cells[r].parse::<f64>().unwrap().to_degrees());
        out.push(cells.join(","));
    }
    let deg = dir.join("deg.csv");
    std::fs::write(&deg, out.join("\n")).unwrap();
    refused(
        &["identify", "--model", "models/oltmann1973.toml", "--data", s(&deg)],
        &["deg.csv", "`r`", "degrees"],
    );
    refused(&["validate", "--data", s(&deg)], &["degrees"]);
    // a dataset that maps a column onto a variable the model does not have
    let ds = dir.join("runs.toml");
    std::fs::write(
        &ds,
        "[columns]\nt = \"t [s]\"\nu = \"u [m/s]\"\nspeed = \"v [m/s]\"\n[[runs]]\nfile = \"z30_10.csv\"\n",
    )
    .unwrap();
    refused(
        &["identify", "--model", "models/oltmann1973.toml", "--dataset", s(&ds)],
        &["runs.toml", "`speed`", "not a variable"],
    );
}

/// A column of text (a run's label, as a logger or a spreadsheet writes it beside the
/// readings) is left out, said, on the plain path and a dataset file's, where it refused the
/// whole file; a dataset that maps a variable onto it is refused with its first cell.
#[test]
fn a_label_column_is_left_out_and_said() {
    let dir = Scratch::new("hostile-label");
    let text = std::fs::read_to_string(zigzag(&dir)).unwrap();
    let labelled: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| if i == 0 { format!("{l},run") } else { format!("{l},zz30-10") })
        .collect();
    let path = dir.join("labelled.csv");
    std::fs::write(&path, labelled.join("\n")).unwrap();
    let (code, out, err) = run_within(&["validate", "--data", s(&path)], Duration::from_secs(60), &[]);
    assert!(
        code == 0 && err.contains("`run` (`zz30-10` in row 1) holds text, not numbers: left out"),
        "{err}"
    );
    assert!(out.contains("labelled.csv"), "{out}");
    let ds = dir.join("runs.toml");
    let dataset = |rudder: &str| {
        format!("[columns]\nt = \"t [s]\"\n\"δ\" = \"{rudder}\"\nu = \"u [m/s]\"\nv = \"v [m/s]\"\nr = \"r [rad/s]\"\n\"ψ\" = \"ψ [rad]\"\n[[runs]]\nfile = \"labelled.csv\"\n")
    };
    std::fs::write(&ds, dataset("δ [rad]")).unwrap();
    let (code, _, err) = run_within(&["validate", "--dataset", s(&ds)], Duration::from_secs(60), &[]);
    assert_eq!(code, 0, "{err}");
    std::fs::write(&ds, dataset("run")).unwrap();
    refused(
        &["validate", "--dataset", s(&ds)],
        &["labelled.csv", "row 1, column `run`", "`zz30-10` is not a number"],
    );
}

/// Item 10: model-file errors point at the key's own line, and a bad term's caret block is shown once.
#[test]
fn model_file_errors_name_the_right_line() {
    let dir = Scratch::new("hostile-lines");
    let text = std::fs::read_to_string("models/lorenz.toml").unwrap();
    let write = |name: &str, t: &str| {
        let p = dir.join(name);
        std::fs::write(&p, t).unwrap();
        p
    };
    let line_of = |t: &str, needle: &str| t.lines().position(|l| l.contains(needle)).unwrap() + 1;
    // a coefficient that is not a number, far below the first mention of its term
    let nan =
        text.replace("[equations.x_dot.coefficients]\n", "[equations.x_dot.coefficients]\n\"x*y*z\" = nan\n");
    let p = write("nan.toml", &nan);
    let err = refused(&["simulate", "--model", s(&p), "--duration", "1"], &["finite"]);
    assert!(err.contains(&format!("nan.toml:{}:", line_of(&nan, "\"x*y*z\" = nan"))), "{err}");
    // a duplicate state
    let dup = text.replacen("[[states]]\nname = \"y\"", "[[states]]\nname = \"x\"", 1);
    assert_ne!(dup, text, "lorenz.toml's layout changed");
    let p = write("dup.toml", &dup);
    let err = refused(&["simulate", "--model", s(&p), "--duration", "1"], &["dup.toml:"]);
    let second_x = dup.lines().enumerate().filter(|(_, l)| *l == "name = \"x\"").nth(1).unwrap().0 + 1;
    assert!(err.contains(&format!("dup.toml:{second_x}:")), "{err}");
    // min above max
    let minmax = text.replacen(
        "name = \"z\"\ninitial = 27.0\nmin = -100.0\nmax = 200.0",
        "name = \"z\"\ninitial = 27.0\nmin = 5.0\nmax = 1.0",
        1,
    );
    assert_ne!(minmax, text, "lorenz.toml's layout changed");
    let p = write("minmax.toml", &minmax);
    let err = refused(&["simulate", "--model", s(&p), "--duration", "1"], &["min 5 is not below max 1"]);
    assert!(err.contains(&format!("minmax.toml:{}:", line_of(&minmax, "min = 5.0"))), "{err}");
    // an alias to an undeclared name
    let alias = format!("{text}\n[aliases]\nq = \"nothing\"\n");
    let p = write("alias.toml", &alias);
    let err = refused(&["simulate", "--model", s(&p), "--duration", "1"], &["aliases.q"]);
    assert!(err.contains(&format!("alias.toml:{}:", line_of(&alias, "q = \"nothing\""))), "{err}");
    // a bad term: one caret block
    let bad = text.replacen("candidates = [\"1\", \"x\"", "candidates = [\"1\", \"x**y\"", 1);
    assert_ne!(bad, text, "lorenz.toml's layout changed");
    let p = write("bad.toml", &bad);
    let err = refused(&["simulate", "--model", s(&p), "--duration", "1"], &["^"]);
    assert_eq!(err.matches(" --> ").count(), 1, "{err}");
}

/// Items 11-13: messages that say what is wrong, in the file's own terms.
#[test]
fn messages_say_what_is_wrong() {
    let dir = Scratch::new("hostile-messages");
    let write = |name: &str, t: &str| {
        let p = dir.join(name);
        std::fs::write(&p, t).unwrap();
        p
    };
    let short = write("short.csv", "x1,x2,y\n1,2,3\n4,5\n");
    let err = refused(
        &["identify", "--data", s(&short), "--no-time", "--target", "y", "--terms", "x1"],
        &["row 2 has 2 cells, the header has 3"],
    );
    assert!(!err.contains("`row`"), "{err}");
    // best subset names the term it leaves out, and fits with the other
    let mut rows = vec!["a,b,c,y".to_string()];
    let mut rng = crate::common::Lcg(3);
    for _ in 0..30 {
        let (a, b) = (rng.next(), rng.next());
        rows.push(format!("{a},{b},{},{}", 3.0 * a, 2.0 * a + b + 0.01 * rng.next()));
    }
    let col = write("col.csv", &rows.join("\n"));
    let out = succeeds(&[
        "identify",
        "--data",
        s(&col),
        "--no-time",
        "--target",
        "y",
        "--terms",
        "a",
        "b",
        "c",
        "--backend",
        "best-subset",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let terms: Vec<&str> =
        v["terms"].as_array().unwrap().iter().map(|t| t["term"].as_str().unwrap()).collect();
    let notes = v["notes"].to_string();
    let left_out = ["a", "c"].into_iter().find(|t| notes.contains(&format!("`{t}` left out"))).expect(&notes);
    assert!(!terms.contains(&left_out), "{left_out} left out but in {terms:?}");
    let hald = |terms: &[&str], extra: &[&str]| {
        let mut a =
            vec!["identify", "--data", "tests/data/hald.csv", "--no-time", "--target", "y", "--terms"];
        a.extend(terms);
        a.extend(extra);
        a.into_iter().map(str::to_string).collect::<Vec<_>>()
    };
    let args = hald(&["x1^1.5"], &[]);
    refused(&args.iter().map(String::as_str).collect::<Vec<_>>(), &["exponents are integers", "`1.5`"]);
    let args = hald(&["x1", "2*x1"], &["--backend", "sparse"]);
    let (code, _, err) =
        run_within(&args.iter().map(String::as_str).collect::<Vec<_>>(), Duration::from_secs(30), &[]);
    assert!(code == 0 || err.contains("multiples or sums"), "{err}");
    let long = "x".repeat(100_000);
    let args = hald(&[&long], &[]);
    let err = refused(&args.iter().map(String::as_str).collect::<Vec<_>>(), &["100000 characters"]);
    assert!(err.len() < 500, "the term was echoed whole ({} bytes)", err.len());
    // overflow is named as such, underflow to one value too; neither is called collinear
    let args = hald(&["x1^5000", "x2"], &[]);
    refused(
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        &["`x1^5000` evaluates to inf", "a power or exponential past the largest number"],
    );
    let args = hald(&["(x1/100)^5000", "x2"], &[]);
    let out = succeeds(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.contains("one value on every row") && !out.contains("collinear"), "{out}");
    let empty = write("empty.csv", "");
    refused(
        &["identify", "--data", s(&empty), "--no-time", "--target", "y", "--terms", "x"],
        &["empty.csv", "the file is empty"],
    );
    let terms = write("terms.txt", "x1\n# a comment\nx2\nx3**x4\n");
    refused(
        &[
            "identify",
            "--data",
            "tests/data/hald.csv",
            "--no-time",
            "--target",
            "y",
            "--terms-file",
            s(&terms),
        ],
        &["terms.txt:4", "^"],
    );
    let z = zigzag(&dir);
    refused(
        &["identify", "--model", "models/oltmann1973.toml", "--data", s(&z), "--resample", "0"],
        &["positive"],
    );
    // a replay of a model without a manoeuvre lasts as long as its recording
    let lorenz = crate::common::lorenz_csv(&dir, "2");
    let out =
        succeeds(&["simulate", "--model", "models/lorenz.toml", "-m", &format!("replay:{}", s(&lorenz))]);
    assert!(out.contains("to t = 2"), "{out}");
}
