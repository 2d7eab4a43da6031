//! One suite, every back-end (pysindy's parametrised optimizer tests): a planted support on
//! noise-free data, forced terms kept, too few rows refused, determinism. Then what is
//! particular to each: best subset against brute force, Efroymson against MATLAB's example.

use proptest::prelude::*;
use termid::select::{Backend, BestSubset, Criterion, Efroymson, Problem, SelectError, Selector, Sizes};

use crate::common::{moments_of, qr_fit, Lcg};

fn backends() -> Vec<(String, Box<dyn Selector>)> {
    Backend::NAMES.iter().map(|n| (n.to_string(), Backend::by_name(n).unwrap().build())).collect()
}

fn names(p: usize) -> Vec<String> {
    (1..=p).map(|i| format!("x{i}")).collect()
}

/// Random columns, y = Σ true coefficients × columns (+ noise).
fn planted(seed: u64, n: usize, p: usize, truth: &[(usize, f64)], noise: f64) -> (Vec<Vec<f64>>, Vec<f64>) {
    let mut g = Lcg(seed);
    let cols: Vec<Vec<f64>> = (0..p).map(|_| (0..n).map(|_| g.normal()).collect()).collect();
    let y = (0..n)
        .map(|i| 0.5 + truth.iter().map(|(j, b)| b * cols[*j][i]).sum::<f64>() + noise * g.normal())
        .collect();
    (cols, y)
}

#[test]
fn every_backend_recovers_a_planted_support() {
    let truth = [(1, 2.0), (4, -1.5), (6, 0.75)];
    let (cols, y) = planted(11, 80, 8, &truth, 0.0);
    let m = moments_of(&cols, &y);
    let names = names(8);
    let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept: true };
    for (name, b) in backends() {
        let s = b.select(&pb).unwrap();
        let mut got: Vec<(usize, f64)> = s.terms.iter().map(|t| (t.index, t.coefficient)).collect();
        got.sort_by_key(|x| x.0);
        assert_eq!(got.iter().map(|x| x.0).collect::<Vec<_>>(), [1, 4, 6], "{name}: {:?}", s.notes);
        for ((_, g), (_, w)) in got.iter().zip(truth) {
            assert!((g - w).abs() < 1e-9, "{name}: {g} vs {w}");
        }
        assert!((s.intercept.unwrap().value - 0.5).abs() < 1e-9, "{name}");
    }
}

#[test]
fn every_backend_keeps_forced_terms() {
    let (cols, y) = planted(12, 60, 6, &[(0, 1.0), (3, 2.0)], 0.1);
    let m = moments_of(&cols, &y);
    let names = names(6);
    let pb = Problem { moments: &m, names: &names, forced: &[5], excluded: &[0], intercept: true };
    for (name, b) in backends() {
        let s = b.select(&pb).unwrap();
        assert!(s.terms.iter().any(|t| t.index == 5), "{name}: forced term dropped");
        assert!(s.terms.iter().all(|t| t.index != 0), "{name}: excluded term entered");
        assert!(s.terms.iter().any(|t| t.index == 3), "{name}");
    }
}

#[test]
fn every_backend_refuses_fewer_rows_than_terms() {
    let (cols, y) = planted(13, 4, 6, &[(0, 1.0)], 0.1);
    let m = moments_of(&cols, &y);
    let names = names(6);
    let pb = Problem { moments: &m, names: &names, forced: &[0, 1, 2, 3], excluded: &[], intercept: true };
    for (name, b) in backends() {
        let e = b.select(&pb).unwrap_err();
        assert!(matches!(e, SelectError::TooFewRows { rows: 4, .. }), "{name}: {e}");
        assert!(e.to_string().contains("4 rows cannot determine"), "{name}: {e}");
    }
}

#[test]
fn every_backend_is_deterministic() {
    let (cols, y) = planted(14, 50, 9, &[(2, 1.0), (7, -1.0)], 0.3);
    let m = moments_of(&cols, &y);
    let names = names(9);
    let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept: true };
    for (name, b) in backends() {
        // Debug text: steps of non-STPRG back-ends carry NaN (no A2 reduction), and NaN ≠ NaN
        assert_eq!(
            format!("{:?}", b.select(&pb).unwrap()),
            format!("{:?}", b.select(&pb).unwrap()),
            "{name}"
        );
    }
}

/// MATLAB's `stepwisefit` documentation runs the Hald data with the default p-values:
/// "Step 1, added column 4, p=0.000576232; Step 2, added column 1, p=1.10528e-06;
/// Final columns included: 1 4", coefficients 1.4400 and −0.6140.
#[test]
fn efroymson_matches_matlabs_hald_example() {
    let f = termid::data::Frame::read_csv_untimed(std::path::Path::new("tests/data/hald.csv")).unwrap();
    let cols: Vec<Vec<f64>> =
        ["x1", "x2", "x3", "x4"].iter().map(|c| f.require(c).unwrap().to_vec()).collect();
    let m = moments_of(&cols, f.require("y").unwrap());
    let names = names(4);
    let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept: true };
    let s = Efroymson::default().select(&pb).unwrap();
    let order: Vec<&str> = s.steps.iter().map(|st| st.term.as_str()).collect();
    assert_eq!(order, ["x4", "x1"]);
    let mut coef: Vec<(usize, f64)> = s.terms.iter().map(|t| (t.index, t.coefficient)).collect();
    coef.sort_by_key(|c| c.0);
    assert!((coef[0].1 - 1.4400).abs() < 5e-5 && (coef[1].1 - -0.6140).abs() < 5e-5, "{coef:?}");
    // the p-values MATLAB prints, from the steps' F (1 and n − k − 1 degrees of freedom)
    let p1 = fdist_upper(s.steps[0].f, 1.0, 11.0);
    // MATLAB prints 6 significant digits
    assert!((p1 / 0.000576232 - 1.0).abs() < 1e-5, "{p1}");
    let t = s.terms.iter().find(|t| t.term == "x1").unwrap().t;
    let p2 = fdist_upper(t * t, 1.0, 10.0);
    assert!((p2 / 1.10528e-06 - 1.0).abs() < 1e-5, "{p2}");
}

/// Upper tail of F(d1, d2) by numerical integration of the density (independent of the
/// library's continued fraction): P(F > f) = 1 − ∫₀^x Beta(d1/2, d2/2) with x = d1 f / (d1 f + d2).
fn fdist_upper(f: f64, d1: f64, d2: f64) -> f64 {
    let (a, b) = (d1 / 2.0, d2 / 2.0);
    let x = d1 * f / (d1 * f + d2);
    // ∫ₓ¹ t^(a−1) (1−t)^(b−1) dt / B(a, b), with t = 1 − s², removing the end singularities
    let dens = |t: f64| t.powf(a - 1.0) * (1.0 - t).powf(b - 1.0);
    let simpson = |lo: f64, hi: f64, k: usize, g: &dyn Fn(f64) -> f64| {
        let h = (hi - lo) / k as f64;
        (0..=k)
            .map(|i| {
                g(lo + i as f64 * h)
                    * if i == 0 || i == k {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    }
            })
            .sum::<f64>()
            * h
            / 3.0
    };
    // substitute t = 1 − u² on [x, 1] (b ≥ 1 here, so the integrand is smooth in u)
    let upper = simpson(0.0, (1.0 - x).sqrt(), 20000, &|u: f64| dens(1.0 - u * u) * 2.0 * u);
    // B(a, b) with a = 1/2: substitute t = s² on [0, 1]
    let total = simpson(0.0, 1.0, 200000, &|s: f64| {
        if s == 0.0 {
            0.0
        } else {
            2.0 * s.powf(2.0 * a - 1.0) * (1.0 - s * s).powf(b - 1.0)
        }
    });
    upper / total
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn best_subset_equals_brute_force(p in 2usize..=14, seed in any::<u64>(), forced_first in any::<bool>()) {
        let n = 40;
        let mut g = Lcg(seed);
        let cols: Vec<Vec<f64>> = (0..p).map(|_| (0..n).map(|_| g.normal()).collect()).collect();
        let y: Vec<f64> = (0..n).map(|i| cols.iter().enumerate().map(|(j, c)| c[i] * ((j % 3) as f64 - 1.0)).sum::<f64>() + g.normal()).collect();
        let m = moments_of(&cols, &y);
        let names = names(p);
        let forced: Vec<usize> = if forced_first { vec![0] } else { vec![] };
        let pb = Problem { moments: &m, names: &names, forced: &forced, excluded: &[], intercept: true };
        let s = BestSubset::default().select(&pb).unwrap();
        prop_assert!(s.notes.iter().any(|n| n.starts_with("exact")), "{:?}", s.notes);
        // brute force: every subset (containing the forced term) by QR
        let mut best = vec![f64::INFINITY; p + 1];
        for mask in 0u32..(1 << p) {
            if forced_first && mask & 1 == 0 {
                continue;
            }
            let set: Vec<usize> = (0..p).filter(|j| mask >> j & 1 == 1).collect();
            let sub: Vec<Vec<f64>> = set.iter().map(|&j| cols[j].clone()).collect();
            let (b0, b) = qr_fit(&sub, &y, true);
            let rss: f64 = (0..n).map(|i| { let f = b0.unwrap() + set.iter().zip(&b).map(|(&j, bj)| bj * cols[j][i]).sum::<f64>(); (y[i] - f).powi(2) }).sum();
            best[set.len()] = best[set.len()].min(rss);
        }
        let ybar = y.iter().sum::<f64>() / n as f64;
        let tss: f64 = y.iter().map(|v| (v - ybar).powi(2)).sum();
        for st in &s.steps {
            let k = st.set.len();
            let rss = (1.0 - st.r2) * tss;
            prop_assert!((rss - best[k]).abs() <= 1e-8 * tss, "size {}: {} vs brute force {}", k, rss, best[k]);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Proving only the chosen size chooses what proving every size chooses, for every
    /// criterion with a bound, and that subset is brute force's best of its size.
    #[test]
    fn best_subset_of_the_chosen_size_alone_chooses_the_same(p in 2usize..=14, seed in any::<u64>(), forced_first in any::<bool>(), noise in 0.05f64..3.0) {
        let n = 40;
        let mut g = Lcg(seed);
        let cols: Vec<Vec<f64>> = (0..p).map(|_| (0..n).map(|_| g.normal()).collect()).collect();
        let y: Vec<f64> = (0..n).map(|i| cols.iter().enumerate().map(|(j, c)| c[i] * ((j % 3) as f64 - 1.0)).sum::<f64>() + noise * g.normal()).collect();
        let m = moments_of(&cols, &y);
        let names = names(p);
        let forced: Vec<usize> = if forced_first { vec![0] } else { vec![] };
        let pb = Problem { moments: &m, names: &names, forced: &forced, excluded: &[], intercept: true };
        let ybar = y.iter().sum::<f64>() / n as f64;
        let tss: f64 = y.iter().map(|v| (v - ybar).powi(2)).sum();
        for criterion in [Criterion::Bic, Criterion::Aic, Criterion::Cp, Criterion::AdjustedR2] {
            let all = BestSubset { criterion, ..BestSubset::default() }.select(&pb).unwrap();
            let chosen = BestSubset { criterion, sizes: Sizes::Chosen, ..BestSubset::default() }.select(&pb).unwrap();
            let set = |s: &termid::select::Selection| s.steps[s.chosen_step - 1].set.clone();
            prop_assert_eq!(set(&all), set(&chosen), "{:?}", criterion);
            let (a, c) = (&all.steps[all.chosen_step - 1], &chosen.steps[chosen.chosen_step - 1]);
            prop_assert!(((a.r2 - c.r2) * tss).abs() <= 1e-8 * tss, "{:?}: {} vs {}", criterion, a.r2, c.r2);
            prop_assert!(chosen.notes.iter().any(|n| n.starts_with("exact for the size chosen")), "{:?}", chosen.notes);
        }
    }
}

/// Coordinate-descent LASSO on the correlation matrix, written independently of the library:
/// minimise ½βᵀRβ − rᵀβ + λ Σ|βⱼ| (Friedman, Hastie & Tibshirani 2010, covariance updates).
fn coordinate_descent(r: &[Vec<f64>], ry: &[f64], lambda: f64) -> Vec<f64> {
    let p = ry.len();
    let mut b = vec![0.0; p];
    for _ in 0..100_000 {
        let mut change: f64 = 0.0;
        for j in 0..p {
            let z = ry[j] - (0..p).filter(|&k| k != j).map(|k| r[j][k] * b[k]).sum::<f64>();
            let new = z.signum() * (z.abs() - lambda).max(0.0) / r[j][j];
            change = change.max((new - b[j]).abs());
            b[j] = new;
        }
        if change < 1e-15 {
            break;
        }
    }
    b
}

#[test]
fn sparse_fit_equals_coordinate_descent() {
    use termid::select::SparseFit;
    let (cols, y) = planted(21, 60, 7, &[(0, 1.0), (2, -0.5), (5, 0.25)], 0.3);
    let m = moments_of(&cols, &y);
    let names = names(7);
    let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept: true };
    // correlations from the data, independently of the library
    let all: Vec<&Vec<f64>> = cols.iter().chain(std::iter::once(&y)).collect();
    let centred: Vec<Vec<f64>> = all
        .iter()
        .map(|c| {
            let mu = c.iter().sum::<f64>() / c.len() as f64;
            c.iter().map(|v| v - mu).collect()
        })
        .collect();
    let norm: Vec<f64> = centred.iter().map(|c| c.iter().map(|v| v * v).sum::<f64>().sqrt()).collect();
    let corr = |i: usize, j: usize| {
        centred[i].iter().zip(&centred[j]).map(|(a, b)| a * b).sum::<f64>() / (norm[i] * norm[j])
    };
    let r: Vec<Vec<f64>> = (0..7).map(|i| (0..7).map(|j| corr(i, j)).collect()).collect();
    let ry: Vec<f64> = (0..7).map(|j| corr(j, 7)).collect();
    for lambda in [0.3, 0.05, 0.005] {
        let got = SparseFit::default().lasso(&pb, lambda).unwrap();
        let want = coordinate_descent(&r, &ry, lambda);
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() < 1e-6, "λ = {lambda}: {got:?} vs {want:?}");
        }
    }
}

#[test]
fn sparse_fit_honours_constraints_and_reports_solver_failure() {
    use termid::select::{Equality, SparseFit};
    let (cols, y) = planted(22, 60, 5, &[(0, 1.0), (1, 0.5), (3, -0.7)], 0.2);
    let m = moments_of(&cols, &y);
    let names = names(5);
    let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept: true };
    let sd = |c: &Vec<f64>| {
        let mu = c.iter().sum::<f64>() / c.len() as f64;
        c.iter().map(|v| (v - mu).powi(2)).sum::<f64>().sqrt()
    };
    let to_raw = |j: usize, beta: f64| beta * sd(&y) / sd(&cols[j]);
    // a coefficient fixed to a raw value
    let fixing = SparseFit { fixed: vec![("x2".into(), 0.8)], ..SparseFit::default() };
    let fixed = fixing.lasso(&pb, 0.01).unwrap();
    assert!((to_raw(1, fixed[1]) - 0.8).abs() < 1e-7, "{}", to_raw(1, fixed[1]));
    // the least-squares refit the path reports keeps it fixed too
    let selection = fixing.select(&pb).unwrap();
    let x2 = selection.terms.iter().find(|t| t.term == "x2").expect("a fixed term is in");
    assert!((x2.coefficient - 0.8).abs() < 1e-7 && x2.std_error == 0.0, "{x2:?}");
    // a sign constraint against the data
    let signed = SparseFit { signs: vec![(3.into(), 1.0)], ..SparseFit::default() }.lasso(&pb, 0.01).unwrap();
    assert!(signed[3] >= -1e-9, "{}", signed[3]);
    // b0 = b1 (raw units)
    let eq = Equality { terms: vec![("x1".into(), 1.0), (1.into(), -1.0)], value: 0.0 };
    let tied = SparseFit { equalities: vec![eq], ..SparseFit::default() }.lasso(&pb, 0.01).unwrap();
    assert!((to_raw(0, tied[0]) - to_raw(1, tied[1])).abs() < 1e-7);
    // contradictory constraints: a typed error, not a number
    let bad = SparseFit {
        fixed: vec![("x3".into(), 1.0)],
        signs: vec![("x3".into(), -1.0)],
        ..SparseFit::default()
    };
    let e = bad.lasso(&pb, 0.01).unwrap_err();
    assert!(matches!(e, SelectError::Infeasible { .. }), "{e}");
    assert!(e.to_string().contains("x3 = 1, x3 ≤ 0"), "{e}");
    // a candidate that is not there, by text or by column: an error naming it, not a panic
    for bad in [
        SparseFit { fixed: vec![(99.into(), 2.0)], ..SparseFit::default() },
        SparseFit { signs: vec![(5.into(), 1.0)], ..SparseFit::default() },
        SparseFit {
            equalities: vec![Equality { terms: vec![("x9".into(), 1.0)], value: 0.0 }],
            ..SparseFit::default()
        },
    ] {
        let e = bad.lasso(&pb, 0.01).unwrap_err().to_string();
        assert!(e.contains("not a candidate") && e.contains("x1, x2"), "{e}");
        let e = bad.select(&pb).unwrap_err().to_string();
        assert!(e.contains("not a candidate"), "{e}");
    }
}

/// Three runs of one planted problem: each run's columns and target, their statistics per
/// run, and all together.
struct ThreeRuns {
    cols: Vec<Vec<Vec<f64>>>,
    ys: Vec<Vec<f64>>,
    folds: Vec<termid::select::Moments>,
    total: termid::select::Moments,
}

fn three_runs(seed: u64, noise: f64) -> ThreeRuns {
    let truth = [(1, 2.0), (4, -1.5), (6, 0.75)];
    let mut cols = Vec::new();
    let mut ys = Vec::new();
    let mut folds = Vec::new();
    for k in 0..3 {
        let (c, y) = planted(seed + k, 40, 8, &truth, noise);
        folds.push(moments_of(&c, &y));
        cols.push(c);
        ys.push(y);
    }
    let mut total = folds[0].clone();
    total.merge(&folds[1]);
    total.merge(&folds[2]);
    ThreeRuns { cols, ys, folds, total }
}

#[test]
fn leave_one_run_out_error_equals_direct_computation() {
    let ThreeRuns { cols, ys, folds, total } = three_runs(31, 0.2);
    let names = names(8);
    let pb = Problem { moments: &total, names: &names, forced: &[], excluded: &[], intercept: true };
    let set = [1usize, 4, 5];
    let got = termid::select::cross_validation_error(&pb, &folds, &set).unwrap();
    // directly: fit on the raw rows of the other two runs by QR, predict the third
    let mut want = 0.0;
    for out in 0..3 {
        let train: Vec<usize> = (0..3).filter(|k| *k != out).collect();
        let sub: Vec<Vec<f64>> =
            set.iter().map(|&j| train.iter().flat_map(|&k| cols[k][j].clone()).collect()).collect();
        let y: Vec<f64> = train.iter().flat_map(|&k| ys[k].clone()).collect();
        let (b0, b) = qr_fit(&sub, &y, true);
        for i in 0..ys[out].len() {
            let f = b0.unwrap() + set.iter().zip(&b).map(|(&j, bj)| bj * cols[out][j][i]).sum::<f64>();
            want += (ys[out][i] - f).powi(2);
        }
    }
    assert!((got - want).abs() < 1e-9 * want, "{got} vs {want}");
}

#[test]
fn cross_validated_choices_recover_the_support() {
    use termid::select::{Criterion, LambdaChoice, SparseFit};
    let ThreeRuns { folds, total, .. } = three_runs(41, 0.05);
    let names = names(8);
    let pb = Problem { moments: &total, names: &names, forced: &[], excluded: &[], intercept: true };
    let bs = BestSubset { criterion: Criterion::LeaveOneRunOut, ..BestSubset::default() };
    let sp = SparseFit { choice: LambdaChoice::LeaveOneRunOut, ..SparseFit::default() };
    for (name, s) in
        [("best subset", bs.select_with_folds(&pb, &folds)), ("sparse", sp.select_with_folds(&pb, &folds))]
    {
        let s = s.unwrap();
        let mut got: Vec<usize> = s.terms.iter().map(|t| t.index).collect();
        got.sort();
        assert_eq!(got, [1, 4, 6], "{name}: {:?}", s.notes);
    }
    // without runs to leave out, a clear error
    let e = bs.select(&pb).unwrap_err();
    assert!(e.to_string().contains("cross-validation needs at least two runs"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]
    /// Sequential thresholding with as many candidates as rows or more (their noise shared
    /// over `overlap` rows): a support the rows determine, never one with as many terms as
    /// their independent evidence, and no refusal where they hold a few rows' worth (the least
    /// BIC of the threshold path was once a support the final fit could not determine).
    #[test]
    fn stlsq_keeps_to_what_the_rows_determine(
        n in 12usize..60, extra in 0usize..30, seed in any::<u64>(), noise in 0.0f64..2.0, overlap in 1.0f64..6.0
    ) {
        let p = n + extra - 9;
        let (cols, y) = planted(seed, n, p, &[(0, 2.0), (2, -1.0)], noise);
        let m = moments_of(&cols, &y).with_overlap(overlap);
        let names = names(p);
        let pb = Problem { moments: &m, names: &names, forced: &[], excluded: &[], intercept: true };
        match Backend::by_name("stlsq").unwrap().build().select(&pb) {
            Ok(s) => prop_assert!((s.terms.len() as f64) <= (n as f64 - 1.0) / overlap - 1.0 + 1e-9, "{} terms: {:?}", s.terms.len(), s.notes),
            Err(e) => prop_assert!((n as f64 - 1.0) / overlap < 4.0 && matches!(e, SelectError::TooFewRows { .. }), "{e}"),
        }
    }
}
