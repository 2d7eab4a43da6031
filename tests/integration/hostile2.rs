//! The second hostile-input sweep (issue 24), through the `termid` binary: termid never
//! deletes or overwrites a file it did not write, never overwrites its own input, turns a
//! dependency's panic into a located error, and refuses what it would otherwise ignore.

use std::path::Path;
use std::time::Duration;

use crate::common::Scratch;
use crate::hostile::{model_with_backend, refused, run_within, s, succeeds, zigzag};

/// Runs `termid args` under `sh` with an address-space limit of `kb` KiB.
fn under_limit(kb: u64, args: &[&str]) -> (i32, String) {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let script = format!("ulimit -v {kb}; exec '{}' {}", env!("CARGO_BIN_EXE_termid"), quoted.join(" "));
    let out = std::process::Command::new("sh").args(["-c", &script]).output().expect("sh");
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).into())
}

/// Item 1: a reproduction folder with anything of the user's in it is refused, at once and
/// whole; termid's own folder, unchanged, is replaced.
#[test]
fn reproduce_never_deletes_the_users_files() {
    let dir = Scratch::new("hostile2-reproduce");
    let out = dir.join("o");
    succeeds(&["reproduce", "--out", s(&out)]);
    assert!(out.join(".termid-files").is_file());
    // termid's own folder, as it left it, is replaced
    succeeds(&["reproduce", "--out", s(&out)]);
    type Add<'a> = &'a dyn Fn(&Path);
    let cases: [(&str, Add); 4] = [
        ("precious.txt", &|o| std::fs::write(o.join("precious.txt"), "x").unwrap()),
        ("data/mine.csv", &|o| std::fs::write(o.join("data/mine.csv"), "x").unwrap()),
        ("notes/", &|o| std::fs::create_dir(o.join("notes")).unwrap()),
        ("report.md", &|o| std::fs::write(o.join("report.md"), "my edits").unwrap()),
    ];
    for (what, add) in cases {
        add(&out);
        let started = std::time::Instant::now();
        refused(&["reproduce", "--out", s(&out)], &[what, "termid replaces only a folder it wrote itself"]);
        // before any work: the study takes ~0.8 s
        assert!(started.elapsed() < Duration::from_millis(500), "{what}: {:?}", started.elapsed());
        let p = out.join(what.trim_end_matches('/'));
        assert!(p.exists(), "{what} was removed");
        if p.is_dir() {
            std::fs::remove_dir(&p).unwrap();
        } else {
            std::fs::remove_file(&p).unwrap();
        }
        if what == "report.md" {
            // an edited file of termid's, put back: the folder stays the user's until removed
            refused(&["reproduce", "--out", s(&out)], &["report.md"]);
            std::fs::remove_dir_all(&out).unwrap();
        }
        succeeds(&["reproduce", "--out", s(&out)]);
    }
    // a folder of an older termid, without the record, is not replaced either
    std::fs::remove_file(out.join(".termid-files")).unwrap();
    refused(&["reproduce", "--out", s(&out)], &["did not write"]);
}

/// Item 2: the sparse back-end's settings are checked against what the solver can take; λ at
/// or beyond λ_max is an error that says so, never a panic.
#[test]
fn sparse_settings_beyond_the_solver_are_errors() {
    let dir = Scratch::new("hostile2-sparse");
    let z = zigzag(&dir);
    // the ship's v̇ has forced terms: a λ beyond λ_max keeps those (it panicked in the solver)
    for lambda in ["0.5", "1e10"] {
        let m = model_with_backend(&dir, &format!("{{ method = \"sparse\", lambda = {lambda} }}"));
        succeeds(&["identify", "--model", s(&m), "--data", s(&z), "--equation", "v_dot"]);
    }
    // Lorenz has none: nothing is kept, and the error says why
    let csv = crate::common::lorenz_csv(&dir, "1");
    let lorenz = std::fs::read_to_string("models/lorenz.toml").unwrap();
    for (backend, needles) in [
        ("{ method = \"sparse\", lambda = 1.5 }", &["keeps a term", "λ_max"][..]),
        ("{ method = \"sparse\", lambda = 1e10 }", &["keeps a term"][..]),
        ("{ method = \"sparse\", lambda = inf }", &["lambda = inf", "finite"][..]),
        ("{ method = \"sparse\", path = 1000000000 }", &["path = 1000000000", "10000"][..]),
        ("{ method = \"sparse\", path = 1 }", &["path ≥ 2"][..]),
    ] {
        let m = dir.join("l.toml");
        std::fs::write(&m, lorenz.replace("{ method = \"stlsq\" }", backend)).unwrap();
        refused(&["identify", "--model", s(&m), "--data", s(&csv), "--equation", "x_dot"], needles);
    }
}

/// `termid moments` of Lorenz's z_dot over one simulated second: the file and its JSON.
fn z_statistics(dir: &Path) -> (std::path::PathBuf, serde_json::Value) {
    let csv = crate::common::lorenz_csv(dir, "1");
    let file = dir.join("z.moments");
    succeeds(&[
        "moments",
        "--model",
        "models/lorenz.toml",
        "--equation",
        "z_dot",
        "--data",
        s(&csv),
        "--out",
        s(&file),
    ]);
    let v = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    (file, v)
}

/// Item 4: whatever `termid moments` writes, `identify --moments` reads back, however many
/// runs (10 000 runs: a line of tens of MB).
#[test]
fn statistics_of_many_runs_read_back() {
    let dir = Scratch::new("hostile2-moments-size");
    let (_, mut v) = z_statistics(&dir);
    let run = v["runs"][0].clone();
    let runs: Vec<serde_json::Value> = (0..10_000)
        .map(|k| {
            let mut r = run.clone();
            r["run"] = format!("run{k}.csv").into();
            r
        })
        .collect();
    v["runs"] = runs.into();
    // (the halves of one run cannot be the halves of ten thousand: left out, as files written
    // before termid gathered them leave them)
    v.as_object_mut().unwrap().remove("halves");
    let many = dir.join("many.moments");
    std::fs::write(&many, v.to_string()).unwrap();
    assert!(std::fs::metadata(&many).unwrap().len() > 1 << 20);
    let out = succeeds(&["identify", "--model", "models/lorenz.toml", "--moments", s(&many)]);
    assert!(out.contains("x*y"), "{out}");
}

/// Item 5: statistics that no data could give, or of another equation, are refused with the
/// reason; a run twice is not counted twice.
#[test]
fn statistics_files_are_checked_for_consistency() {
    let dir = Scratch::new("hostile2-moments-check");
    let (one, v) = z_statistics(&dir);
    let write = |name: &str, v: &serde_json::Value| {
        let p = dir.join(name);
        std::fs::write(&p, v.to_string()).unwrap();
        p
    };
    let mut other = v.clone();
    other["equation"] = "y_dot".into();
    let p = write("other.moments", &other);
    refused(
        &["identify", "--model", "models/lorenz.toml", "--moments", s(&p)],
        &["another equation", "z_dot"],
    );
    // numbers[0] is the weight; then the means; then the lower triangle (first: the first
    // candidate's sum of squares)
    let p_cand = v["candidates"].as_array().unwrap().len();
    for (k, value, needle) in
        [(0usize, 7.0, "weight"), (1, 1e308, "beyond any measurement"), (2 + p_cand, -5.0, "sum of squares")]
    {
        let mut bad = v.clone();
        bad["runs"][0]["moments"]["numbers"][k] = value.into();
        let p = write("bad.moments", &bad);
        refused(
            &["identify", "--model", "models/lorenz.toml", "--moments", s(&p)],
            &["cannot come from data", needle],
        );
    }
    let mut twice = v.clone();
    let run = twice["runs"][0].clone();
    twice["runs"].as_array_mut().unwrap().push(run);
    let p = write("twice.moments", &twice);
    refused(&["identify", "--model", "models/lorenz.toml", "--moments", s(&p)], &["appears twice"]);
    // the same file given twice
    refused(
        &["identify", "--model", "models/lorenz.toml", "--moments", s(&one), s(&one)],
        &["counted twice"],
    );
    // item 10: --equation picks among the statistics
    refused(
        &["identify", "--model", "models/lorenz.toml", "--moments", s(&one), "--equation", "bogus"],
        &["bogus"],
    );
    refused(
        &["identify", "--model", "models/lorenz.toml", "--moments", s(&one), "--equation", "x_dot"],
        &["x_dot", "none of the --moments"],
    );
}

/// Item 6: an output that is an input (by identity: another spelling, a link) is refused
/// before the input is read; two outputs onto one file likewise.
#[test]
fn outputs_never_replace_inputs() {
    let dir = Scratch::new("hostile2-same-file");
    let csv = crate::common::lorenz_csv(&dir, "1");
    let before = std::fs::read(&csv).unwrap();
    let dotted = format!("{}/./{}", dir.display(), csv.file_name().unwrap().to_string_lossy());
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink(&csv, &link).unwrap();
    let m = "models/lorenz.toml";
    for args in [
        vec!["moments", "--model", m, "--equation", "z_dot", "--data", s(&csv), "--out", s(&csv)],
        vec![
            "moments",
            "--model",
            m,
            "--equation",
            "z_dot",
            "--data",
            s(&csv),
            "--out",
            &dotted,
            "--chunk-rows",
            "100",
        ],
        vec!["identify", "--model", m, "--data", s(&csv), "--out", s(&link)],
        vec!["simulate", "--model", m, "-m", &format!("replay:{}", s(&csv)), "--out", s(&csv)],
    ] {
        refused(&args, &["same file", "never overwrites its own input"]);
        assert_eq!(std::fs::read(&csv).unwrap(), before, "{args:?}");
    }
    let x = dir.join("x.out");
    refused(
        &["simulate", "--model", m, "--duration", "1", "--out", s(&x), "--svg", s(&x)],
        &["--svg and --out"],
    );
    // the same data file twice would count its run twice
    refused(&["identify", "--model", m, "--data", s(&csv), s(&link)], &["counted twice"]);
}

/// Item 7: the memory budget knows the process's address-space limit; too much work is an
/// error with its size, not an abort. Item 8: compare's timing settings are bounded.
#[test]
fn memory_limits_and_endless_settings_are_refused() {
    let (code, err) = under_limit(400_000, &["simulate", "-m", "turning:20", "--duration", "1000000"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("would take") && err.contains("ulimit"), "{err}");
    let dir = Scratch::new("hostile2-compare");
    let z = zigzag(&dir);
    for (flag, value) in
        [("--warm-up", "inf"), ("--warm-up", "1e9"), ("--warm-up", "nan"), ("--repeat", "4000000000")]
    {
        refused(&["compare", "--data", s(&z), flag, value], &[flag]);
    }
    refused(&["compare", "--data", s(&z), "--dt", "0"], &["--dt"]);
}

/// Item 9: a model file of many derived variables loads in about linear time (10⁵ in ~1.4 s;
/// before, 4·10⁴ took 2.6 s and 2·10⁵ over a minute).
#[test]
fn many_derived_variables_load_quickly() {
    let dir = Scratch::new("hostile2-derived");
    let mut text = std::fs::read_to_string("models/lorenz.toml").unwrap();
    text.push('\n');
    for k in 0..100_000 {
        let def = if k == 0 { "x + 1".to_string() } else { format!("d{} + x", k - 1) };
        text.push_str(&format!("[[derived]]\nname = \"d{k}\"\ndefinition = \"{def}\"\n"));
    }
    let p = dir.join("many.toml");
    std::fs::write(&p, text).unwrap();
    let (code, _, err) =
        run_within(&["simulate", "--model", s(&p), "--duration", "0.1"], Duration::from_secs(15), &[]);
    assert_eq!(code, 0, "{err}");
}

/// Items 11-14: Monte Carlo on a model without a plug-in, the spiral's angles, the refinement's
/// prior, and pipes as outputs.
#[test]
fn requests_are_honoured_or_refused_not_ignored() {
    let dir = Scratch::new("hostile2-honoured");
    // a generic model without covariance: Monte Carlo cannot draw, and says so
    refused(
        &["simulate", "--model", "models/lorenz.toml", "--duration", "1", "--monte-carlo", "10"],
        &["covariance"],
    );
    // the spiral holds whole steps up to its largest angle, within the rudder limit
    let out = succeeds(&["simulate", "-m", "spiral:30/20/60", "--out", s(&dir.join("sp.csv"))]);
    // the table's δ column (a scratch folder's name may hold "40": the process id)
    let angles: Vec<&str> = out.lines().filter_map(|l| l.split_whitespace().next()).collect();
    assert!(angles.contains(&"20.0") && !angles.iter().any(|a| a.trim_start_matches('-') == "40.0"), "{out}");
    let z = zigzag(&dir);
    for prior in ["-1", "nan", "1e300"] {
        refused(
            &[
                "identify",
                "--model",
                "models/oltmann1973.toml",
                "--data",
                s(&z),
                "--refine",
                "u,v,r",
                "--refine-prior",
                prior,
            ],
            &["prior weight"],
        );
    }
    // /dev/stdout into a pipe is written, not refused
    let (code, stdout, err) = run_within(
        &["simulate", "--model", "models/lorenz.toml", "--duration", "0.2", "--out", "/dev/stdout"],
        Duration::from_secs(30),
        &[],
    );
    assert_eq!(code, 0, "{err}");
    assert!(stdout.starts_with("t,"), "{stdout}");
    // negative numbers reach the option's own check
    refused(&["simulate", "--model", "models/lorenz.toml", "--duration", "1", "--dt", "-0.04"], &["-0.04"]);
}

/// Items 15-17: repeated names, settings that do nothing sensible, and a time column in other
/// units are refused, not accepted with a surprise.
#[test]
fn nonsense_settings_are_refused() {
    let dir = Scratch::new("hostile2-nonsense");
    let m = "models/lorenz.toml";
    refused(&["simulate", "--model", m, "--duration", "1", "--initial", "x=1", "x=2"], &["`x` twice"]);
    refused(&["simulate", "-m", "zigzag:20/20", "--param", "u0=1", "u0=2"], &["`u0` twice"]);
    refused(&["simulate", "--model", m, "--duration", "0"], &["--duration 0"]);
    refused(&["simulate", "--model", m, "--duration", "1", "--dt", "2"], &["longer than --duration"]);
    refused(&["simulate", "--model", m, "--duration", "1", "--dt", "1e-300"], &["1e-300"]);
    let csv = crate::common::lorenz_csv(&dir, "1");
    let one = dir.join("one.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    std::fs::write(&one, text.lines().take(2).collect::<Vec<_>>().join("\n") + "\n").unwrap();
    refused(&["simulate", "--model", m, "-m", &format!("replay:{}", s(&one))], &["at least two rows"]);
    refused(
        &["validate", "--model", m, "--data", s(&csv), "--dt", "1000"],
        &["too long for the shortest run"],
    );
    refused(
        &["scale", "--model", "models/mmg_kvlcc2.toml", "--factor", "1e300", "--out", s(&dir.join("x.toml"))],
        &["1e4"],
    );
    refused(&["identify", "--data", s(&csv), "--target", "dt/dt", "--terms", "x"], &["time column"]);
    refused(
        &["identify", "--data", s(&csv), "--target", "x_dot", "--terms", "x", "x_dot"],
        &["among the candidate"],
    );
    // one file column onto two variables
    std::fs::write(
        dir.join("two.toml"),
        "[columns]\nx = \"x\"\ny = \"x\"\n[[runs]]\nfile = \"lorenz.csv\"\n",
    )
    .unwrap();
    refused(
        &["identify", "--model", m, "--dataset", s(&dir.join("two.toml"))],
        &["one column is one variable"],
    );
    std::fs::write(
        dir.join("win.toml"),
        "[columns]\nx = \"x\"\n[track]\nheading = \"x\"\nu = \"y\"\nv = \"z\"\nhalf_window = 0\n[[runs]]\nfile = \"lorenz.csv\"\n",
    )
    .unwrap();
    refused(&["identify", "--model", m, "--dataset", s(&dir.join("win.toml"))], &["half_window = 0"]);
    // a ship whose rudder limit or rate no rudder has
    let ship = std::fs::read_to_string("models/oltmann1973.toml").unwrap();
    for (from, to, needle) in [
        ("rudder_limit = 35.0", "rudder_limit = 1e9", "rudder_limit"),
        ("rudder_rate = 12.65", "rudder_rate = 1e-300", "rudder_rate"),
    ] {
        let p = dir.join("ship.toml");
        std::fs::write(&p, ship.replace(from, to)).unwrap();
        refused(&["simulate", "--model", s(&p), "-m", "turning:20"], &[needle, "out of range"]);
    }
    // a model with nothing to identify
    let plain = dir.join("plain.toml");
    std::fs::write(&plain, std::fs::read_to_string(m).unwrap().replace("candidates = ", "old_candidates = "))
        .unwrap();
    if crate::common::termid(&["simulate", "--model", s(&plain), "--duration", "0.1"]).0 {
        refused(&["identify", "--model", s(&plain), "--data", s(&csv)], &["nothing to identify"]);
    }
    // the time column in milliseconds or minutes (item 17)
    let z = zigzag(&dir);
    let zz = std::fs::read_to_string(&z).unwrap();
    for (unit, factor) in [("milliseconds", 1000.0), ("minutes", 1.0 / 60.0)] {
        let mut lines = zz.lines();
        let header = lines.next().unwrap();
        let t = header.split(',').position(|h| h == "t").unwrap();
        let mut out = vec![header.to_string()];
        for l in lines {
            let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
            cells[t] = format!("{:?}", cells[t].parse::<f64>().unwrap() * factor);
            out.push(cells.join(","));
        }
        let p = dir.join(format!("{unit}.csv"));
        std::fs::write(&p, out.join("\n") + "\n").unwrap();
        refused(&["validate", "--data", s(&p)], &[unit, "the whole run"]);
    }
}

/// Items 18-20: messages that say what is wrong, and no echo of a file that is not data.
#[test]
fn messages_name_the_real_problem() {
    let dir = Scratch::new("hostile2-messages");
    let m = "models/lorenz.toml";
    let w = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let tabs = w("tabs.csv", "t\tx\n0\t1\n1\t2\n");
    // read as tab-separated (once refused, "convert the file"): its two rows are too few
    refused(&["identify", "--data", s(&tabs), "--target", "dx/dt", "--terms", "x"], &["2 rows are too few"]);
    let headless = w("headless.csv", "0.0,1.0\n0.1,2.0\n");
    refused(
        &["identify", "--data", s(&headless), "--target", "dx/dt", "--terms", "x"],
        &["holds numbers, not column names"],
    );
    let secret =
        w("secret.txt", "root:*:20228:0:99999:7:::\ndaemon:*:20228:0:99999:7:::\nbin:*:20228:0:99999:7:::\n");
    let err = refused(&["identify", "--model", m, "--data", s(&secret)], &["not a table of numbers"]);
    assert!(!err.contains("daemon") && !err.contains("root"), "{err}");
    let ds = w("ds.toml", &format!("[columns]\nx = \"x\"\n[[runs]]\nfile = \"{}\"\n", s(&secret)));
    let err = refused(&["identify", "--model", m, "--dataset", s(&ds)], &["not a table of numbers"]);
    assert!(!err.contains("daemon"), "{err}");
    for (folder, needle) in [("${X", "closing brace"), ("${X:-/tmp}", "no shell forms")] {
        let ds = w(
            "env.toml",
            &format!("folder = \"{folder}\"\n[columns]\nx = \"x\"\n[[runs]]\nfile = \"a.csv\"\n"),
        );
        refused(&["identify", "--model", m, "--dataset", s(&ds)], &[needle]);
    }
    let lorenz = std::fs::read_to_string(m).unwrap();
    // a Cyrillic х for the state x
    let cyr = w("cyr.toml", &lorenz.replacen("state = \"x\"", "state = \"\u{445}\"", 1));
    refused(&["simulate", "--model", s(&cyr), "--duration", "1"], &["looks like `x`", "U+0445"]);
    // a decomposed é (e + combining acute) for a composed one
    let nfd = w(
        "nfd.toml",
        &lorenz.replacen("name = \"x\"", "name = \"\u{e9}\"", 1).replacen(
            "state = \"x\"",
            "state = \"e\u{301}\"",
            1,
        ),
    );
    refused(&["simulate", "--model", s(&nfd), "--duration", "1"], &["looks like `\u{e9}`", "U+0301"]);
    // the time named as a state
    let timed = w("timed.toml", &lorenz.replacen("time = \"t\"", "time = \"x\"", 1));
    refused(
        &["simulate", "--model", s(&timed), "--duration", "1"],
        &["timed.toml", "also the time variable"],
    );
    // CR-only line ends
    let cr = w("cr.toml", &lorenz.replace('\n', "\r"));
    refused(&["simulate", "--model", s(&cr), "--duration", "1"], &["carriage return"]);
    // a huge term is not echoed whole
    let huge = "x*".repeat(50_000) + "x";
    let err = refused(
        &[
            "identify",
            "--data",
            s(&crate::common::lorenz_csv(&dir, "1")),
            "--target",
            "dx/dt",
            "--terms",
            &huge,
        ],
        &["longer than"],
    );
    assert!(err.len() < 2_000, "{} bytes of stderr", err.len());
    // the collinearity note names the terms in the combination only (c = 2a + 1, not b)
    let col = w(
        "col.csv",
        "a,b,c,y\n1,2,3,1.1\n2,1,5,2.3\n3,5,7,2.9\n4,3,9,4.2\n5,4,11,5.1\n6,8,13,5.8\n7,6,15,7.2\n",
    );
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
    ]);
    assert!(out.contains("`c` left out of the search: collinear with `a` (pivot"), "{out}");
    // a stepwise with every candidate excluded says so
    let out = succeeds(&[
        "identify",
        "--data",
        s(&dir.join("lorenz.csv")),
        "--target",
        "dx/dt",
        "--terms",
        "x",
        "y",
        "--exclude",
        "x",
        "y",
        "--backend",
        "stepwise",
        "--no-intercept",
    ]);
    assert!(
        out.contains("no candidate could enter") && !out.contains("every candidate had entered"),
        "{out}"
    );
}
