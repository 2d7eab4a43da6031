//! Model files: the default model against the paper, errors that point at file/line/key,
//! and the identify → write → read round trip.

use termid::model::Covariance;
use termid::model::ModelError;
use termid::term::Term;

/// The paper's sample state (NOTES.md §3) evaluated with the printed true coefficients.
/// Independent check: the same sums computed by hand from the CSV tables gave
/// u̇ = −0.024336, v̇ = −0.038710 m/s², ṙ = 0.0078496 rad/s² (0.44975 °/s²), against the
/// printed −0.02364, −0.04247 m/s² and 0.87020 °/s². The model file and README report this.
#[test]
fn sample_state_accelerations() {
    let m = termid::ship::default_model();
    let lib = m.compile_rhs(false).unwrap();
    let value = |n: &str| match n {
        "u" => 1.88895,
        "v" => -0.13450,
        "r" => 5.63990f64.to_radians(),
        "δ" => (-30.0f64).to_radians(),
        "u0" => 2.010,
        "ψ" => 0.0,
        other => panic!("unexpected input {other}"),
    };
    let inputs: Vec<f64> = lib.inputs().iter().map(|n| value(n)).collect();
    let mut out = vec![0.0; lib.len()];
    lib.eval_row(&inputs, &mut lib.scratch(), &mut out);
    let (udot, vdot, rdot) = (out[0], out[1], out[2]);
    assert!((udot - -0.024336).abs() < 2e-6, "{udot}");
    assert!((vdot - -0.038710).abs() < 2e-6, "{vdot}");
    assert!((rdot.to_degrees() - 0.44975).abs() < 2e-4, "{}", rdot.to_degrees());
    // and how far that is from what the paper printed
    assert!(((udot / -0.02364) - 1.0).abs() < 0.04);
    assert!(((vdot / -0.04247) - 1.0).abs() > 0.08);
    assert!((rdot.to_degrees() / 0.87020) < 0.55);
}

#[test]
fn default_model_has_the_papers_sets() {
    let m = termid::ship::default_model();
    let u = m.equation("u_dot").unwrap();
    let forced: Vec<String> = u.forced.iter().map(Term::to_string).collect();
    assert_eq!(forced, ["u*Δu", "v^2", "r^2", "u^2*δ^2"]);
    let v = m.equation("v_dot").unwrap();
    assert_eq!(v.candidates.len(), 29);
    assert_eq!(v.coefficient(&m.vocabulary.parse("u^2*delta").unwrap()), 0.0308);
    let r = m.equation("r_dot").unwrap();
    assert_eq!(r.coefficient(&m.vocabulary.parse("u^2").unwrap()), -0.0014); // C0
    assert_eq!(r.coefficient(&m.vocabulary.parse("v^2*delta").unwrap()), -0.1472); // from Table 6
    assert_eq!(r.candidates, v.candidates);
}

fn with(original: &str, replacement: &str) -> String {
    let text = termid::ship::DEFAULT_MODEL;
    assert!(text.contains(original), "fixture drifted: {original}");
    text.replacen(original, replacement, 1)
}

#[test]
fn errors_name_file_line_and_key() {
    let text = with("\"u*r\", \"u*r*delta\",", "\"u*r\", \"u*r**delta\",");
    let e = termid::plugins::parse(&text, "ship.toml").unwrap_err();
    let msg = e.to_string();
    let line = text.lines().position(|l| l.contains("u*r**delta")).unwrap() + 1;
    assert!(matches!(e, ModelError::Term { .. }));
    assert!(msg.starts_with(&format!("ship.toml:{line}: `equations.u_dot.candidates[")), "{msg}");
    assert!(msg.contains('^') && msg.contains("1:4"), "{msg}");

    let e = termid::plugins::parse(&with("rudder_rate = 12.65", "rudder_rate = \"fast\""), "ship.toml")
        .unwrap_err();
    assert!(e.to_string().contains("ship.toml") && e.to_string().contains("rudder_rate"), "{e}");

    let e =
        termid::plugins::parse(&with("lpp = 4.572", "lpp = 4.572\nlength = 5.0"), "ship.toml").unwrap_err();
    assert!(e.to_string().contains("unknown field `length`"), "{e}");

    let e = termid::plugins::parse(&with("state = \"r\"", "state = \"w\""), "ship.toml").unwrap_err();
    assert!(e.to_string().contains("`equations.r_dot.state`") && e.to_string().contains("`w`"), "{e}");

    let e = termid::plugins::parse(
        &with("\"v*r\", \"u*v\", \"u*r\",", "\"v*r\", \"r*v\", \"u*r\","),
        "ship.toml",
    )
    .unwrap_err();
    assert!(e.to_string().contains("same term"), "{e}");

    let e =
        termid::plugins::parse(&with("\"du^2\" = -0.1429", "\"du^2\" = -0.1429\n\"u*w\" = 1.0"), "ship.toml")
            .unwrap_err();
    assert!(
        e.to_string().contains("coefficients.\"u*w\"") && e.to_string().contains("unknown variable `w`"),
        "{e}"
    );
}

#[test]
fn written_model_reads_back_unchanged() {
    let mut m = termid::ship::default_model();
    let t = m.vocabulary.parse("u*v").unwrap();
    m.set_coefficients("v_dot", vec![(t.clone(), -0.18312345678901234, Some(1.5e-3))], Some(1e-4));
    let text = m.to_toml();
    let back = termid::plugins::parse(&text, "written.toml").unwrap();
    assert_eq!(back.spec(), m.spec());
    let eq = back.equation("v_dot").unwrap();
    assert_eq!(eq.coefficients, vec![(t, -0.18312345678901234, Some(1.5e-3))]);
    assert_eq!(eq.intercept, Some(1e-4));
    // and once more: a fixed point
    assert_eq!(termid::plugins::parse(&back.to_toml(), "again.toml").unwrap().spec(), back.spec());
}

#[test]
fn covariances_are_checked_and_read_back() {
    let mut m = termid::ship::default_model();
    let (uv, ur) = (m.vocabulary.parse("u*v").unwrap(), m.vocabulary.parse("u*r").unwrap());
    let matrix = vec![vec![4e-6, 1e-6], vec![1e-6, 9e-6]];
    let cov = |matrix: Vec<Vec<f64>>, tau: f64| Covariance {
        terms: vec![uv.clone(), ur.clone()],
        matrix,
        correlation_time: tau,
    };
    m.set_covariance("v_dot", cov(matrix.clone(), 12.5)).unwrap();
    let back = termid::plugins::parse(&m.to_toml(), "written.toml").unwrap();
    assert_eq!(back.equation("v_dot").unwrap().covariance, Some(cov(matrix.clone(), 12.5)));
    // refused: not symmetric, not positive semi-definite, τ < 1, a term without coefficient
    for (bad, what) in [
        (cov(vec![vec![4e-6, 1e-6], vec![2e-6, 9e-6]], 1.0), "not symmetric"),
        (cov(vec![vec![4e-6, 9e-6], vec![9e-6, 4e-6]], 1.0), "positive semi-definite"),
        (cov(matrix.clone(), 0.5), "≥ 1"),
        (
            Covariance {
                terms: vec![uv.clone(), m.vocabulary.parse("r^3/u").unwrap()],
                ..cov(matrix.clone(), 1.0)
            },
            "not a coefficient",
        ),
    ] {
        let e = m.clone().set_covariance("v_dot", bad).unwrap_err();
        assert!(e.to_string().contains(what), "{e}");
    }
    // and in a file: the key is named
    let mut asym = m.spec().clone();
    asym.equations.get_mut("v_dot").unwrap().covariance.as_mut().unwrap().matrix[0][1] = 2e-6;
    let text = toml::to_string_pretty(&asym).unwrap();
    let e = termid::plugins::parse(&text, "cov.toml").err().map(|e| e.to_string()).unwrap_or_default();
    assert!(
        e.contains("cov.toml") && e.contains("equations.v_dot.covariance") && e.contains("not symmetric"),
        "{e}"
    );
    // new coefficients void the old covariance
    m.set_coefficients("v_dot", vec![(uv, -0.18, None)], None);
    assert_eq!(m.equation("v_dot").unwrap().covariance, None);
    assert!(!m.to_toml().contains("covariance"));
}

#[test]
fn plug_in_tables_are_checked_by_the_registry() {
    // a table no plug-in reads: kept by the core, refused (located) by the registry
    let text = format!("{}\n[shipp]\nlpp = 4.0\n", termid::ship::DEFAULT_MODEL);
    assert!(termid::model::Model::parse(&text, "m.toml").is_ok());
    let e = termid::plugins::parse(&text, "m.toml").unwrap_err().to_string();
    let line = text.lines().position(|l| l == "[shipp]").unwrap() + 1;
    assert!(e.starts_with(&format!("m.toml:{line}: `shipp`: no plug-in reads this table")), "{e}");
    assert!(e.contains("[ship]"), "{e}");
    // the ship plug-in's own checks, located
    let e = termid::plugins::parse(&with("rudder_limit = 35.0", "rudder_limit = -35.0"), "m.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("`ship.rudder_limit`: must be a positive number"), "{e}");
    let e = termid::plugins::parse(
        &with("u0 = 2.010\n", "u0 = 2.010\nnames = { rudder = \"rudder\" }\n"),
        "m.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("`ship.names.rudder`") && e.contains("not a state or input"), "{e}");
    // the registry finds the model's plug-in and the one with a derivative method
    let m = termid::plugins::default_model();
    assert_eq!(termid::plugins::of(&m).map(|p| p.table()), Some("ship"));
    assert_eq!(termid::plugins::with_derivative("kinematic").map(|p| p.table()), Some("ship"));
    assert!(termid::plugins::with_derivative("spline").is_none());
}
