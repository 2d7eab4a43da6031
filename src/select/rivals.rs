//! How firmly the rows chose each term: every chosen term swapped for every candidate left
//! out, least squares on the swapped set, and the rise of the residual sum of squares in units
//! of the fit's residual variance. A rise within the noise says the back-end's pick between
//! the two is the noise's, not the system's (Hald's x2 and x4; `y*z` for `y` in a noisy Lorenz).

use serde::{Deserialize, Serialize};

use super::subset::Scaled;
use super::{Problem, Selection};

/// A chosen term's closest rival among the candidates left out.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rival {
    /// The chosen term.
    pub chosen: String,
    /// The candidate left out that fits best in its place.
    pub instead: String,
    /// Rise of the residual sum of squares when `instead` replaces `chosen` (the others
    /// refitted), in units of the chosen fit's residual variance s²; negative where the rival
    /// fits better (a greedy path passed it by).
    pub rise: f64,
}

/// A pivot at most this (in correlation scale) is a candidate collinear with the terms kept:
/// no rival, whatever its residual.
const PIVOT: f64 = 1e-10;

/// Each chosen term that was not forced, with its best rival (none where no candidate can
/// take its place). Least squares throughout: a back-end's shrunk or constrained
/// coefficients are compared by the sets they chose.
pub fn rivals(problem: &Problem<'_>, selection: &Selection) -> Vec<Rival> {
    let Ok(scaled) = Scaled::new(problem) else { return Vec::new() };
    let set: Vec<usize> = selection.terms.iter().map(|t| t.index).collect();
    let Ok(full) = scaled.swept(&set, PIVOT) else { return Vec::new() };
    let dof = scaled.n_eff - set.len() as f64;
    if dof < 1.0 {
        return Vec::new();
    }
    let (p, m) = (scaled.p, scaled.m);
    // s² in units of the total sum of squares, floored at round-off as the steps' s is (an
    // exact fit's rivals then rise by ~1/ε, never by 0/0)
    let variance = scaled.residual_share(&full).max(m as f64 * f64::EPSILON) / dof;
    let chosen_share = scaled.residual_share(&full);
    let rivals: Vec<usize> = (0..p)
        .filter(|c| !set.contains(c) && !problem.excluded.contains(c) && !problem.forced.contains(c))
        .collect();
    let mut out = Vec::new();
    for (k, term) in selection.terms.iter().enumerate() {
        if problem.forced.contains(&term.index) {
            continue;
        }
        let rest: Vec<usize> = set.iter().enumerate().filter(|&(i, _)| i != k).map(|(_, &c)| c).collect();
        let Ok(a) = scaled.swept(&rest, PIVOT) else { continue };
        let base = scaled.residual_share(&a);
        // sweeping one more column c lowers the residual share by a_cp² / a_cc; a candidate
        // that is a combination of the chosen terms (`F*x` where F = 1 in every run) fits as
        // they do by construction, and its rise is rounding alone: no rival
        let best = rivals
            .iter()
            .filter(|&&c| a[c * m + c] > PIVOT && full[c * m + c] > PIVOT)
            .map(|&c| (c, base - a[c * m + p].powi(2) / a[c * m + c]))
            .min_by(|x, y| x.1.total_cmp(&y.1));
        if let Some((c, share)) = best {
            out.push(Rival {
                chosen: term.term.clone(),
                instead: problem.names[c].clone(),
                rise: (share - chosen_share) / variance,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::select::{FittedTerm, Moments, Selector, StepRule, Stepwise};

    fn hald() -> (Moments, Vec<String>) {
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/hald.csv")).unwrap();
        let rows: Vec<Vec<f64>> =
            text.lines().skip(1).map(|l| l.split(',').map(|v| v.trim().parse().unwrap()).collect()).collect();
        // whole columns, one after another
        let x: Vec<f64> = (0..4).flat_map(|j| rows.iter().map(move |r| r[j])).collect();
        let y: Vec<f64> = rows.iter().map(|r| r[4]).collect();
        (Moments::of_columns(&x, &y, None), ["x1", "x2", "x3", "x4"].map(String::from).to_vec())
    }

    fn rival<'a>(rivals: &'a [Rival], chosen: &str) -> &'a Rival {
        rivals.iter().find(|s| s.chosen == chosen).unwrap()
    }

    /// The candidates at `indices` as a selection's terms (rivals compare sets, not values).
    fn chosen(names: &[String], indices: &[usize]) -> Vec<FittedTerm> {
        indices
            .iter()
            .map(|&i| FittedTerm {
                term: names[i].clone(),
                index: i,
                coefficient: 0.0,
                std_error: 1.0,
                t: 0.0,
            })
            .collect()
    }

    /// Hald's cement, against the residual sums of squares of its pairs in Draper & Smith
    /// (Applied Regression Analysis, 1998, §15): {x1, x2} 57.90, {x1, x4} 74.76, {x3, x4}
    /// 175.74, {x2, x3} 415.44 (n − 3 = 10 degrees of freedom).
    #[test]
    fn hald_pairs_against_their_published_sums_of_squares() {
        let (moments, names) = hald();
        let problem =
            Problem { moments: &moments, names: &names, forced: &[], excluded: &[], intercept: true };
        let stepwise = Stepwise { step_rule: StepRule::Last, ..Stepwise::default() };
        let mut selection = stepwise.select(&problem).unwrap();
        // forward stepping's second step is {x4, x1}: x2 in x4's place fits better
        selection.terms = selection.terms_at(2);
        let s = rivals(&problem, &selection);
        let x4 = rival(&s, "x4");
        assert_eq!(x4.instead, "x2");
        assert!((x4.rise - (57.90 - 74.76) / (74.76 / 10.0)).abs() < 2e-3, "{x4:?}");
        let x1 = rival(&s, "x1");
        assert_eq!(x1.instead, "x3");
        assert!((x1.rise - (175.74 - 74.76) / (74.76 / 10.0)).abs() < 2e-3, "{x1:?}");
        // {x1, x2}: x2 could as well be x4, within three residual variances
        selection.terms = chosen(&names, &[0, 1]);
        let s = rivals(&problem, &selection);
        let x2 = rival(&s, "x2");
        assert_eq!(x2.instead, "x4");
        assert!((x2.rise - (74.76 - 57.90) / 5.790).abs() < 2e-3, "{x2:?}");
        let x1 = rival(&s, "x1");
        assert_eq!(x1.instead, "x3");
        assert!((x1.rise - (415.44 - 57.90) / 5.790).abs() < 2e-2, "{x1:?}");
        // a forced term has no rival, and a forced or excluded candidate is none
        let forced = Problem { forced: &[1], excluded: &[3], ..problem };
        let s = rivals(&forced, &selection);
        assert_eq!(s.len(), 1);
        assert_eq!(rival(&s, "x1").instead, "x3");
    }

    /// A candidate that is a chosen term over again (`F*x` where F = 1 in every run) fits
    /// exactly as it does: no rival, where rounding alone made it "fit clearly better" by
    /// fifteen residual variances of a noise-free fit.
    #[test]
    fn a_chosen_term_over_again_is_no_rival() {
        let n = 200;
        let x: Vec<f64> = (0..n).map(|i| (0.1 * i as f64).sin()).collect();
        let v: Vec<f64> = (0..n).map(|i| (0.23 * i as f64).cos()).collect();
        let w: Vec<f64> = (0..n).map(|i| (0.05 * i as f64).powi(2)).collect();
        let y: Vec<f64> = (0..n).map(|i| -4.0 * x[i] - 0.2 * v[i]).collect();
        let columns: Vec<f64> = [&x, &v, &x, &w].iter().flat_map(|c| c.iter().copied()).collect();
        let moments = Moments::of_columns(&columns, &y, None);
        let names = ["x", "v", "F*x", "w"].map(String::from).to_vec();
        let problem =
            Problem { moments: &moments, names: &names, forced: &[], excluded: &[], intercept: false };
        let selection =
            Selection { terms: chosen(&names, &[0, 1]), ..Stepwise::default().select(&problem).unwrap() };
        let s = rivals(&problem, &selection);
        assert!(s.iter().all(|r| r.instead == "w"), "{s:?}");
    }
}
