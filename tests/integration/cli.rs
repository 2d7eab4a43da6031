//! The `termid` binary end to end.

use std::process::Command;

fn termid(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_termid")).args(args).output().expect("run termid");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[test]
fn identify_hald_json() {
    let (ok, out, err) = termid(&[
        "identify",
        "--data",
        "tests/data/hald.csv",
        "--no-time",
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
    let (ok, out, _) = termid(&[
        "identify",
        "--data",
        "tests/data/hald.csv",
        "--no-time",
        "--target",
        "y",
        "--terms",
        "x1",
        "x2",
        "x4",
    ]);
    assert!(ok);
    assert!(out.contains("term entered") && out.contains("← chosen"), "{out}");
    let (ok, _, err) = termid(&[
        "identify",
        "--data",
        "tests/data/hald.csv",
        "--no-time",
        "--target",
        "y",
        "--terms",
        "x1",
        "x2**x4",
    ]);
    assert!(!ok);
    assert!(err.contains("1:4") && err.contains('^'), "{err}");
    let (ok, _, err) =
        termid(&["identify", "--data", "tests/data/hald.csv", "--no-time", "--target", "z", "--terms", "x1"]);
    assert!(!ok);
    assert!(err.contains("hald.csv") && err.contains("`z`"), "{err}");
    let (ok, _, err) = termid(&[
        "identify",
        "--data",
        "tests/data/hald.csv",
        "--no-time",
        "--target",
        "y",
        "--terms",
        "x1",
        "x2*x1",
        "x1*x2",
    ]);
    assert!(!ok);
    assert!(err.contains("duplicate"), "{err}");
}
