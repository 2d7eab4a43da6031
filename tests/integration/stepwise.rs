//! STPRG against numbers from outside the code: the Hald cement data (Hald 1952; Draper &
//! Smith, *Applied Regression Analysis*), an independent QR least-squares solve at every step,
//! and synthetic data whose true equation is known.

use proptest::prelude::*;
use termid::data::Frame;
use termid::select::{Problem, SelectError, Selector, StepRule, Stepwise, Stop};

use crate::common::{close, moments_of, qr_fit, Lcg};

fn hald() -> (Vec<Vec<f64>>, Vec<f64>) {
    let f = Frame::read_csv_untimed(std::path::Path::new("tests/data/hald.csv")).unwrap();
    let cols = ["x1", "x2", "x3", "x4"].iter().map(|c| f.require(c).unwrap().to_vec()).collect();
    (cols, f.require("y").unwrap().to_vec())
}

fn names(p: usize) -> Vec<String> {
    (1..=p).map(|i| format!("x{i}")).collect()
}

#[test]
fn hald_order_statistics_and_coefficients() {
    let (cols, y) = hald();
    let m = moments_of(&cols, &y);
    let names = names(4);
    let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept: true };
    let sel = Stepwise { step_rule: StepRule::Last, ..Stepwise::default() }.select(&pb).unwrap();
    let order: Vec<&str> = sel.steps.iter().map(|s| s.term.as_str()).collect();
    assert_eq!(order, ["x4", "x1", "x2", "x3"]); // Draper & Smith's forward selection
                                                 // Draper & Smith: y = 117.57 − 0.7382 x4, s = 8.964, F = 22.80, R² = 0.6745
    let s1 = &sel.steps[0];
    assert!(close(sel.terms_at(1)[0].coefficient, -0.738162, 1e-5));
    assert!(close(s1.intercept.as_ref().unwrap().value, 117.5679, 1e-6));
    assert!(close(s1.standard_error, 8.96390, 1e-5));
    assert!(close(s1.f, 22.7985, 1e-5));
    assert!(close(s1.r2, 0.674542, 1e-5));
    // y = 103.10 + 1.440 x1 − 0.6140 x4, R² = 0.9725
    let s2 = &sel.steps[1];
    assert!(close(sel.terms_at(2)[1].coefficient, 1.43996, 1e-5));
    assert!(close(sel.terms_at(2)[0].coefficient, -0.613954, 1e-5));
    assert!(close(s2.r2, 0.972471, 1e-5));
    // full model: 62.405 + 1.5511 x1 + 0.5102 x2 + 0.1019 x3 − 0.1441 x4, s = 2.446
    let s4 = &sel.steps[3];
    let b0 = s4.intercept.as_ref().unwrap();
    assert!(close(b0.value, 62.4054, 1e-5) && close(b0.std_error, 70.0710, 1e-5));
    let se: Vec<f64> = sel.terms_at(4).iter().map(|t| t.std_error).collect();
    for (got, want) in se.iter().zip([0.709052, 0.744770, 0.723788, 0.754709]) {
        assert!(close(*got, want, 1e-5), "{got} vs {want}");
    }
    assert!(close(s4.standard_error, 2.44601, 1e-5));
    // every step against an independent QR solve of the same subset
    for st in &sel.steps {
        let terms = sel.terms_at(st.step);
        let sub: Vec<Vec<f64>> = terms.iter().map(|t| cols[t.index].clone()).collect();
        let (b0, b) = qr_fit(&sub, &y, true);
        assert!(close(st.intercept.as_ref().unwrap().value, b0.unwrap(), 1e-9));
        for (t, want) in terms.iter().zip(b) {
            assert!(close(t.coefficient, want, 1e-9), "step {}: {} vs {want}", st.step, t.coefficient);
        }
    }
}

#[test]
fn forced_terms_enter_first_and_the_threshold_stops() {
    let (cols, y) = hald();
    let m = moments_of(&cols, &y);
    let names = names(4);
    let pb = Problem { moments: &m, names: &names, forced: &[2, 1], excluded: &[], intercept: true };
    let sel = Stepwise { min_proportion: 0.01, step_rule: StepRule::Last, ..Stepwise::default() }
        .select(&pb)
        .unwrap();
    let order: Vec<&str> = sel.steps.iter().map(|s| s.term.as_str()).collect();
    assert_eq!(&order[..2], ["x2", "x3"]); // forced, larger reduction first: x2 explains more than x3
    assert!(sel.steps[..2].iter().all(|s| s.forced));
    assert!(matches!(sel.stop, Stop::BelowThreshold { .. } | Stop::AllEntered));
    let excluded = Problem { moments: &m, names: &names, forced: &[], excluded: &[3], intercept: true };
    let sel = Stepwise::default().select(&excluded).unwrap();
    assert!(sel.steps.iter().all(|s| s.term != "x4"));
}

#[test]
fn refuses_too_few_rows_and_constant_targets() {
    let cols = vec![vec![1.0, 2.0], vec![3.0, 1.0]];
    let m = moments_of(&cols, &[1.0, 2.0]);
    let two = names(2);
    let pb = Problem { moments: &m, names: &two, forced: &[0, 1], excluded: &[], intercept: true };
    let e = Stepwise::default().select(&pb).unwrap_err();
    assert!(matches!(e, SelectError::TooFewRows { rows: 2, .. }), "{e}");
    assert!(e.to_string().contains("2 rows cannot determine"));
    let m = moments_of(&[vec![1.0, 2.0, 3.0]], &[5.0, 5.0, 5.0]);
    let one = names(1);
    let pb = Problem { moments: &m, names: &one, forced: &[], excluded: &[], intercept: true };
    assert!(matches!(Stepwise::default().select(&pb), Err(SelectError::NoVariance)));
}

#[test]
fn synthetic_known_equation_exact_fit_is_reported() {
    let mut g = Lcg(7);
    let n = 200;
    let x1: Vec<f64> = (0..n).map(|_| g.next() * 2.0 - 1.0).collect();
    let x2: Vec<f64> = (0..n).map(|_| g.next() * 2.0 - 1.0).collect();
    let cols = vec![
        x1.clone(),
        x2.clone(),
        x1.iter().zip(&x2).map(|(a, b)| a * b).collect(),
        x1.iter().map(|a| a * a).collect(),
        x2.iter().map(|b| b * b * b).collect(),
    ];
    // y = 2 + 3 x1 − 0.5 x1·x2 + 0.25 x2³
    let y: Vec<f64> = (0..n).map(|i| 2.0 + 3.0 * cols[0][i] - 0.5 * cols[2][i] + 0.25 * cols[4][i]).collect();
    let m = moments_of(&cols, &y);
    let names = names(5);
    let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept: true };
    let sel = Stepwise::default().select(&pb).unwrap();
    assert!(matches!(sel.stop, Stop::ExactFit { .. }), "{:?}", sel.stop);
    assert!(sel.notes.iter().any(|n| n.contains("round-off")));
    let mut got: Vec<(usize, f64)> = sel.terms.iter().map(|t| (t.index, t.coefficient)).collect();
    got.sort_by_key(|t| t.0);
    assert_eq!(got.iter().map(|t| t.0).collect::<Vec<_>>(), [0, 2, 4]);
    for ((_, b), want) in got.iter().zip([3.0, -0.5, 0.25]) {
        assert!((b - want).abs() < 1e-9, "{b} vs {want}");
    }
    assert!((sel.intercept.unwrap().value - 2.0).abs() < 1e-9);
}

#[test]
fn collinear_candidates_are_refused_not_divided_by() {
    let x1: Vec<f64> = (0..30).map(|i| (i as f64 * 0.37).sin()).collect();
    let x2: Vec<f64> = (0..30).map(|i| (i as f64 * 0.11).cos()).collect();
    let x3: Vec<f64> = x1.iter().zip(&x2).map(|(a, b)| 2.0 * a - b).collect();
    let y: Vec<f64> = (0..30).map(|i| x1[i] + 0.3 * (i as f64).sqrt()).collect();
    let m = moments_of(&[x1, x2, x3], &y);
    let names = names(3);
    let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept: true };
    let sel = Stepwise { step_rule: StepRule::Last, ..Stepwise::default() }.select(&pb).unwrap();
    assert_eq!(sel.steps.len(), 2);
    assert!(sel.notes.iter().any(|n| n.contains("refused: collinear")), "{:?}", sel.notes);
    assert!(sel.steps.iter().all(|s| s.standard_error.is_finite()));
}

fn problem_strategy() -> impl Strategy<Value = (Vec<Vec<f64>>, Vec<f64>)> {
    (2usize..8, 15usize..60, any::<u64>()).prop_map(|(p, n, seed)| {
        let mut g = Lcg(seed);
        let cols: Vec<Vec<f64>> =
            (0..p).map(|j| (0..n).map(|_| g.normal() * (1.0 + j as f64)).collect()).collect();
        let y = (0..n)
            .map(|i| cols.iter().enumerate().map(|(j, c)| c[i] * (j as f64 - 2.0)).sum::<f64>() + g.normal())
            .collect();
        (cols, y)
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn sse_never_rises_and_steps_equal_qr((cols, y) in problem_strategy(), intercept in any::<bool>()) {
        let m = moments_of(&cols, &y);
        let names = names(cols.len());
        let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept };
        let sel = Stepwise { step_rule: StepRule::Last, ..Stepwise::default() }.select(&pb).unwrap();
        for w in sel.steps.windows(2) {
            prop_assert!(w[1].r2 >= w[0].r2 - 1e-12, "R² fell: {} → {}", w[0].r2, w[1].r2);
        }
        for st in &sel.steps {
            let terms = sel.terms_at(st.step);
            let sub: Vec<Vec<f64>> = terms.iter().map(|t| cols[t.index].clone()).collect();
            let (b0, b) = qr_fit(&sub, &y, intercept);
            // relative to the coefficient, or to its standard error where the coefficient is
            // statistically zero (there, relative digits of a tiny number mean nothing)
            for (t, want) in terms.iter().zip(&b) {
                let scale = want.abs().max(t.std_error);
                prop_assert!((t.coefficient - want).abs() <= 1e-9 * scale, "step {}: {} vs {}", st.step, t.coefficient, want);
            }
            if let (Some(i), Some(w)) = (&st.intercept, b0) {
                prop_assert!((i.value - w).abs() <= 1e-9 * w.abs().max(1.0));
            }
        }
    }

    #[test]
    fn reordering_and_renaming_does_not_change_what_enters((cols, y) in problem_strategy(), rot in 0usize..8) {
        let p = cols.len();
        let perm: Vec<usize> = (0..p).map(|i| (i + rot) % p).rev().collect();
        let m1 = moments_of(&cols, &y);
        let n1 = names(p);
        let pb1 = Problem { moments: &m1, names: &n1, forced: &[], excluded: &[], intercept: true };
        let s1 = Stepwise::default().select(&pb1).unwrap();
        let cols2: Vec<Vec<f64>> = perm.iter().map(|&j| cols[j].clone()).collect();
        let n2: Vec<String> = perm.iter().map(|&j| format!("renamed_{j}")).collect();
        let m2 = moments_of(&cols2, &y);
        let pb2 = Problem { moments: &m2, names: &n2, forced: &[], excluded: &[], intercept: true };
        let s2 = Stepwise::default().select(&pb2).unwrap();
        let o1: Vec<usize> = s1.steps.iter().map(|s| s.index).collect();
        let o2: Vec<usize> = s2.steps.iter().map(|s| perm[s.index]).collect();
        prop_assert_eq!(o1, o2);
        prop_assert_eq!(s1.chosen_step, s2.chosen_step);
    }
}

/// Rows as borrowed columns (an embedding's arrays) fit as the same rows in a frame: Hald's
/// order and Draper & Smith's last step, bit for bit; a NaN named by row and term; columns of
/// unequal length and per-run rules refused.
#[test]
fn borrowed_columns_fit_as_a_frame() {
    use std::collections::BTreeMap;
    use termid::data::CentralDifference;
    use termid::identify::{Design, Identification, ParamValue, Target};
    use termid::term::{parse_terms, Vocabulary};

    let f = Frame::read_csv_untimed(std::path::Path::new("tests/data/hald.csv")).unwrap();
    let mut vocabulary = Vocabulary::new();
    for x in ["x1", "x2", "x3", "x4"] {
        vocabulary.variable(x).unwrap();
    }
    let candidates = parse_terms(&["x1", "x2", "x3", "x4", "x1*x4"], &vocabulary).unwrap();
    let design = Design::new(&candidates, &vocabulary).unwrap();
    let none = BTreeMap::new();
    let how = Identification {
        vocabulary: &vocabulary,
        parameters: &none,
        differentiator: &CentralDifference,
        intercept: true,
        weights: None,
    };
    let stepwise = Stepwise { step_rule: StepRule::Last, ..Stepwise::default() };
    let framed = how
        .fit_design(&Target::Column("y".into()), &design, &[], &[], std::slice::from_ref(&f), &stepwise)
        .unwrap();
    let columns: Vec<(&str, &[f64])> =
        ["x1", "x2", "x3", "x4", "y"].iter().map(|c| (*c, f.require(c).unwrap())).collect();
    let borrowed = how.fit_columns("hald", &columns, "y", &design, &[], &[], &stepwise).unwrap();
    let order =
        |f: &termid::identify::Fit| f.selection.steps.iter().map(|s| s.term.clone()).collect::<Vec<_>>();
    assert_eq!(order(&borrowed)[..3], ["x4", "x1", "x2"]); // Draper & Smith's first three
    assert_eq!(order(&borrowed), order(&framed));
    assert_eq!(borrowed.selection.terms.len(), framed.selection.terms.len());
    for (a, b) in borrowed.selection.terms.iter().zip(&framed.selection.terms) {
        assert_eq!((a.index, a.coefficient.to_bits()), (b.index, b.coefficient.to_bits()));
    }
    // a NaN in x2 at row 4: named by its row and the terms it enters
    let mut x2 = f.require("x2").unwrap().to_vec();
    x2[3] = f64::NAN;
    let mut bad = columns.clone();
    bad[1] = ("x2", &x2);
    let e = how.fit_columns("hald", &bad, "y", &design, &[], &[], &stepwise).unwrap_err().to_string();
    assert!(e.contains("hald") && e.contains("row 4") && e.contains("x2"), "{e}");
    let short = &x2[..5];
    bad[1] = ("x2", short);
    let e = how.fit_columns("hald", &bad, "y", &design, &[], &[], &stepwise).unwrap_err().to_string();
    assert!(e.contains("x2") && e.contains('5'), "{e}");
    let rules = BTreeMap::from([("c".to_string(), ParamValue::Rule("first:x1".into()))]);
    let with_rule = Identification { parameters: &rules, ..how };
    let e =
        with_rule.fit_columns("hald", &columns, "y", &design, &[], &[], &stepwise).unwrap_err().to_string();
    assert!(e.contains("`c`") && e.contains("rule"), "{e}");
}
