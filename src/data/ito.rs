//! A record moved by a random force (process noise: an unmeasured white force on a state, as
//! in Langevin's equation). A rate estimated on both sides of a sample, or a window's
//! integral, takes in the force of the very interval it explains, and so do the candidates
//! over that window: the damping of an oscillator under a random force came back halved by
//! central differences and left out by the weak form. Itô's steps instead: each interval's change against the candidates' trapezoid
//! over it, the candidates fitted as those of the interval two before predict them (two-stage
//! least squares), which neither that interval's force nor a sensor's white noise at its
//! samples reaches. Chosen as `--derivative ito`, and by the recipe where a random force is
//! found ([`crate::recipe`]).

use super::{DataError, Differentiator, TestFunction, Window};

/// Itô's one-interval steps with instrumented candidates.
#[derive(Clone, Copy, Debug, Default)]
pub struct Ito;

impl Differentiator for Ito {
    fn name(&self) -> &'static str {
        "ito"
    }

    /// No rate: the target is the signal itself, whose change over each interval the
    /// identification takes ([`Differentiator::window`]).
    fn differentiate(&self, _t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError> {
        Ok(x.to_vec())
    }

    fn smooth(&self, _t: &[f64], _x: &[f64]) -> Result<super::Smoothed, DataError> {
        Err(super::integral::nothing_to_smooth("Itô"))
    }

    /// `None`: the instruments' fit takes the run whole.
    fn reach(&self) -> Option<usize> {
        None
    }

    fn window(&self) -> Option<Window> {
        Some(Window { intervals: 1, test: TestFunction::Flat, shrinks: false, instrumented: true })
    }
}

/// Below this share of the largest singular value of the instruments' (equilibrated) cross
/// products, a direction is collinear and left out of the prediction.
const COLLINEAR: f64 = 1e-12;

/// Two-stage least squares' first stage over the rows of one run, each starting at sample
/// `starts[i]`: which rows have an instrument, the row starting `lag` samples before theirs,
/// and those rows' `columns` as predicted by least squares from a constant and the columns of
/// their instrument rows. A row's own noise, and a force over its interval, are in none of the
/// rows that end before it starts, so the prediction keeps only what they foresee of it.
pub fn first_stage(columns: &[Vec<f64>], starts: &[usize], lag: usize) -> (Vec<bool>, Vec<Vec<f64>>) {
    let of_start = |s: usize| starts.binary_search(&s).ok();
    let pairs: Vec<(usize, Option<usize>)> =
        (0..starts.len()).map(|i| (i, starts[i].checked_sub(lag).and_then(of_start))).collect();
    let has: Vec<bool> = pairs.iter().map(|(_, j)| j.is_some()).collect();
    let rows: Vec<(usize, usize)> = pairs.iter().filter_map(|&(i, j)| Some((i, j?))).collect();
    let p = columns.len();
    // the instruments, each scaled to unit root mean square so that the cut reads directions
    let scale: Vec<f64> = columns
        .iter()
        .map(|c| {
            let ms = rows.iter().map(|&(_, j)| c[j] * c[j]).sum::<f64>() / rows.len().max(1) as f64;
            if ms > 0.0 && ms.is_finite() {
                ms.sqrt()
            } else {
                1.0
            }
        })
        .collect();
    let z = |j: usize, k: usize| if k == 0 { 1.0 } else { columns[k - 1][j] / scale[k - 1] };
    let q = p + 1;
    let mut gram = nalgebra::DMatrix::<f64>::zeros(q, q);
    let mut cross = nalgebra::DMatrix::<f64>::zeros(q, p);
    for &(i, j) in &rows {
        for a in 0..q {
            let za = z(j, a);
            for b in a..q {
                gram[(a, b)] += za * z(j, b);
            }
            for (c, column) in columns.iter().enumerate() {
                cross[(a, c)] += za * column[i];
            }
        }
    }
    for a in 0..q {
        for b in 0..a {
            gram[(a, b)] = gram[(b, a)];
        }
    }
    let largest = gram.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let coefficients = crate::linalg::svd(gram)
        .and_then(|svd| svd.solve(&cross, COLLINEAR * largest).ok())
        .unwrap_or_else(|| nalgebra::DMatrix::zeros(q, p));
    let predicted = (0..p)
        .map(|c| rows.iter().map(|&(_, j)| (0..q).map(|k| z(j, k) * coefficients[(k, c)]).sum()).collect())
        .collect();
    (has, predicted)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A column the instruments foresee exactly (a line in time, and its lag) is predicted as
    /// it is; white noise, which they cannot foresee, is predicted as its mean; rows without a
    /// row `lag` before them (the first two, and after a left-out window) have no prediction.
    #[test]
    fn the_prediction_keeps_what_the_rows_before_foresee() {
        let starts: Vec<usize> = (0..400).filter(|&s| s != 100).collect();
        let mut normal = crate::uncertainty::Normal::new(3);
        let line: Vec<f64> = starts.iter().map(|&s| 2.0 + 0.01 * s as f64).collect();
        let noise: Vec<f64> = starts.iter().map(|_| 5.0 + normal.sample()).collect();
        let (has, predicted) = first_stage(&[line.clone(), noise.clone()], &starts, 2);
        let missing: Vec<usize> = (0..starts.len()).filter(|&i| !has[i]).map(|i| starts[i]).collect();
        assert_eq!(missing, vec![0, 1, 102]);
        let kept: Vec<usize> = (0..starts.len()).filter(|&i| has[i]).collect();
        for (k, &i) in kept.iter().enumerate() {
            assert!((predicted[0][k] - line[i]).abs() < 1e-9, "{k}: {} vs {}", predicted[0][k], line[i]);
        }
        // the noise: its prediction varies far less than it does (a line fitted to white noise)
        let spread = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt()
        };
        let own: Vec<f64> = kept.iter().map(|&i| noise[i]).collect();
        assert!(spread(&predicted[1]) < 0.2 * spread(&own), "{} vs {}", spread(&predicted[1]), spread(&own));
    }
}
