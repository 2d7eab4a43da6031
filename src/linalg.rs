//! Matrix decompositions that end: nalgebra's default SVD, symmetric eigen-decomposition and
//! Schur form iterate until they converge, which on some matrices they never do (a finite 4×4
//! Jacobian of a model made from columns held `identify` for good). These stop after a bound,
//! `None` where they did not converge; each caller says what it does without.

use nalgebra::{Complex, DMatrix, Dyn, SymmetricEigen, SVD};

/// The most iterations a decomposition of `a` may take: far more than converging takes (a few
/// per singular value or eigenvalue), far fewer than a second's work; `None` where `a` holds a
/// value that is not finite (nalgebra's SVD panics on the NaN it makes of one).
fn most_iterations(a: &DMatrix<f64>) -> Option<usize> {
    a.iter().all(|v| v.is_finite()).then(|| 10_000.max(100 * a.nrows().min(a.ncols())))
}

/// The singular value decomposition of `a` (U and Vᵀ too), as `a.svd(true, true)` gives it
/// where that converges (its tolerance, five machine epsilons, too).
pub fn svd(a: DMatrix<f64>) -> Option<SVD<f64, Dyn, Dyn>> {
    let most = most_iterations(&a)?;
    a.try_svd(true, true, 5.0 * f64::EPSILON, most)
}

/// The eigen-decomposition of the symmetric matrix `a`, as `a.symmetric_eigen()` gives it where
/// that converges.
pub fn symmetric_eigen(a: DMatrix<f64>) -> Option<SymmetricEigen<f64, Dyn>> {
    let most = most_iterations(&a)?;
    a.try_symmetric_eigen(f64::EPSILON, most)
}

/// The eigenvalues of the square matrix `a`, complex, by its real Schur form; where that does
/// not converge, by its transpose's (the same eigenvalues by another sequence of rotations,
/// which converged on the Jacobian the matrix's own did not).
pub fn eigenvalues(a: DMatrix<f64>) -> Option<Vec<Complex<f64>>> {
    let most = most_iterations(&a)?;
    let transposed = a.transpose();
    let schur = a.try_schur(f64::EPSILON, most).or_else(|| transposed.try_schur(f64::EPSILON, most))?;
    Some(schur.complex_eigenvalues().iter().copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Jacobian whose real Schur form nalgebra's QR sweeps never reach (ẋ = 0.99983v,
    /// v̇ = −3.5453x + 0.85210u + 0.41223w, u̇ = −0.57054v, ẇ = 0.71912v: four columns taken for
    /// states): its eigenvalues are ±i·√−(ab + ce + df) and 0 twice, in closed form.
    #[test]
    fn eigenvalues_end_where_the_schur_sweeps_do_not() {
        let (a, b, c, d, e, f) = (
            0.9998308004073485,
            -3.545261672128756,
            0.8520970267916446,
            0.41223426487186543,
            -0.5705432704228557,
            0.7191185621087307,
        );
        let m = DMatrix::from_row_slice(
            4,
            4,
            &[0.0, a, 0.0, 0.0, b, 0.0, c, d, 0.0, e, 0.0, 0.0, 0.0, f, 0.0, 0.0],
        );
        assert!(
            m.clone().try_schur(f64::EPSILON, 100_000).is_none(),
            "nalgebra converges now: the retry may go"
        );
        let mut found = eigenvalues(m).unwrap();
        found.sort_by(|p, q| p.im.total_cmp(&q.im));
        let w = (-(a * b + c * e + d * f)).sqrt();
        let truth =
            [Complex::new(0.0, -w), Complex::new(0.0, 0.0), Complex::new(0.0, 0.0), Complex::new(0.0, w)];
        for (l, t) in found.iter().zip(truth) {
            assert!((l - t).norm() < 1e-9, "{found:?}");
        }
    }

    /// Where they converge, the bounded decompositions are nalgebra's own to the last bit (the
    /// same tolerances: a model identified through them is the file it was).
    #[test]
    fn bounded_decompositions_are_the_unbounded_ones() {
        let a = DMatrix::from_fn(20, 5, |i, j| ((i * 7 + j * 3) as f64).sin() + 0.1 * (i * j) as f64);
        let (mine, theirs) = (svd(a.clone()).unwrap(), a.clone().svd(true, true));
        assert_eq!(mine.singular_values, theirs.singular_values);
        assert_eq!(mine.u, theirs.u);
        let s = a.transpose() * &a;
        let (mine, theirs) = (symmetric_eigen(s.clone()).unwrap(), s.clone().symmetric_eigen());
        assert_eq!(mine.eigenvalues, theirs.eigenvalues);
        let square = DMatrix::from_fn(5, 5, |i, j| ((i * 5 + j) as f64).cos());
        let mine = eigenvalues(square.clone()).unwrap();
        assert_eq!(mine.as_slice(), square.complex_eigenvalues().as_slice());
    }

    /// A matrix holding NaN (which no caller should pass, but a product of huge values makes)
    /// is no decomposition, not a loop without end or a panic.
    #[test]
    fn a_matrix_of_nan_is_no_decomposition() {
        let m = DMatrix::from_row_slice(2, 2, &[f64::NAN, 1.0, 1.0, 2.0]);
        assert!(svd(m.clone()).is_none());
        assert!(symmetric_eigen(m.clone()).is_none());
        assert!(eigenvalues(m).is_none());
    }
}
