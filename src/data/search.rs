//! The one-dimensional search the smoothing methods share to choose their smoothing from the
//! data (GCV for the spline, the likelihood for the Kalman smoother): a coarse grid in
//! log-space finds the basin, golden-section search refines it.

/// The point of `grid` (ascending, e.g. decades) where `score` is smallest, refined by
/// golden-section search between its neighbours to `tolerance`. Non-finite scores lose.
pub fn minimise(grid: &[f64], tolerance: f64, score: impl Fn(f64) -> f64) -> f64 {
    let score = |x: f64| {
        let s = score(x);
        if s.is_nan() {
            f64::INFINITY
        } else {
            s
        }
    };
    let scores: Vec<f64> = grid.iter().map(|&x| score(x)).collect();
    let best = (0..grid.len()).min_by(|&a, &b| scores[a].total_cmp(&scores[b])).unwrap_or(0);
    let (mut a, mut b) = (grid[best.saturating_sub(1)], grid[(best + 1).min(grid.len() - 1)]);
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - phi * (b - a), a + phi * (b - a));
    let (mut fc, mut fd) = (score(c), score(d));
    while b - a > tolerance {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - phi * (b - a);
            fc = score(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + phi * (b - a);
            fd = score(d);
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    #[test]
    fn finds_the_minimum_of_a_bumpy_function() {
        // the global minimum at 2.3; a local one at −3 the grid must not be fooled by
        let f = |x: f64| (x - 2.3).powi(2) * ((x + 3.0).powi(2) + 0.1);
        let grid: Vec<f64> = (-6..=6).map(f64::from).collect();
        let x = super::minimise(&grid, 1e-6, f);
        assert!((x - 2.3).abs() < 1e-5, "{x}");
        // NaN scores lose instead of winning
        let x = super::minimise(&grid, 1e-6, |x| if x < 0.0 { f64::NAN } else { (x - 1.0).powi(2) });
        assert!((x - 1.0).abs() < 1e-5, "{x}");
    }
}
