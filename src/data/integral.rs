//! The integral form of an equation of motion (as in weak SINDy; Schaeffer & McCalla 2017):
//! instead of ẋ against θ(x) row by row, the change of x over a window against the integral
//! of every candidate over the same window, x(t+W) − x(t) = Σ c_j ∫ θ_j dt. No derivative is
//! estimated: the quadrature averages noise where differencing amplifies it, and Simpson's
//! rule leaves an error of O(h⁴) where central differences leave O(h²) that is smooth in the
//! states (and so fitted by spurious terms). Chosen as `--derivative integral[:W]`.

use super::{DataError, Differentiator, TestFunction, Window};

/// The integral form over windows of `window` sample intervals.
#[derive(Clone, Copy, Debug)]
pub struct IntegralForm {
    /// Sample intervals per window (even, for Simpson's rule on an even grid).
    pub window: usize,
}

impl Default for IntegralForm {
    fn default() -> Self {
        IntegralForm { window: 8 }
    }
}

impl Differentiator for IntegralForm {
    fn name(&self) -> &'static str {
        "integral"
    }

    /// No rate: the integral form's target is the signal itself, whose changes over windows
    /// the identification takes ([`Differentiator::window`]).
    fn differentiate(&self, _t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError> {
        Ok(x.to_vec())
    }

    fn smooth(&self, _t: &[f64], _x: &[f64]) -> Result<super::Smoothed, DataError> {
        Err(nothing_to_smooth("integral"))
    }

    /// A window reaches `window` samples ahead: a run read in pieces with that much context
    /// has every window of its own rows whole.
    fn reach(&self) -> Option<usize> {
        Some(self.window)
    }

    fn window(&self) -> Option<Window> {
        Some(Window { intervals: self.window, test: TestFunction::Flat, shrinks: false, instrumented: false })
    }
}

/// Refuses to smooth or draw the rates of a form that estimates none (`form`: its name).
pub(super) fn nothing_to_smooth(form: &str) -> DataError {
    DataError::Setting(format!(
        "the {form} form estimates no rate, so there is nothing to smooth or draw: leave out --smooth and --prepared-svg, or choose a derivative method"
    ))
}

/// The rows of the integral form: for every window of `window.intervals` intervals starting
/// at a sample, the left side (x at its end less x at its start; with a bump test function
/// −∫ φ′ x dt) and each column integrated over it weighed by φ. A flat window is integrated
/// by composite Simpson on an even grid with an even window, on uneven samples by the
/// quadratic through each pair of intervals, with an odd window by the trapezoid on the
/// samples' own spacing; a bump on an even grid by the trapezoid, whose error falls with every
/// derivative of the integrand that vanishes at the ends (Euler-Maclaurin), as φ's do, on
/// uneven samples by the quadratic through each pair of samples integrated against φ and φ′.
pub fn integral_rows(
    t: &[f64],
    x: &[f64],
    columns: &[Vec<f64>],
    window: Window,
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let (n, w) = (t.len(), window.intervals);
    if w == 0 || n <= w {
        return (Vec::new(), vec![Vec::new(); columns.len()]);
    }
    let h = (t[n - 1] - t[0]) / (n - 1) as f64;
    // (within the times' own rounding far from zero: a Unix time's 50 Hz steps read 2·10⁻⁵ apart)
    let close = super::on_sample(t);
    let even = t.windows(2).all(|p| ((p[1] - p[0]) - h).abs() <= close);
    let rows = n - w;
    let bump = match window.test {
        TestFunction::Flat => None,
        TestFunction::Bump(p) => Some(p),
    };
    let simpson = even && w.is_multiple_of(2);
    // (quadrature weights × φ, −quadrature weights × φ′) of the window from sample k
    let weights = |k: usize| -> (Vec<f64>, Vec<f64>) {
        let span = &t[k..=k + w];
        match bump {
            None if simpson => {
                let q = (0..=w)
                    .map(|i| {
                        h / 3.0
                            * match i {
                                0 => 1.0,
                                i if i == w => 1.0,
                                i if i % 2 == 1 => 4.0,
                                _ => 2.0,
                            }
                    })
                    .collect();
                (q, Vec::new())
            }
            None if w.is_multiple_of(2) => (uneven_simpson(span), Vec::new()),
            None => (trapezoid(span), Vec::new()),
            Some(p) if even => {
                let (q, (phi, slope)) = (trapezoid(span), bump_values(span, p));
                let left = q.iter().zip(&slope).map(|(q, d)| -q * d).collect();
                (q.iter().zip(&phi).map(|(q, f)| q * f).collect(), left)
            }
            // on uneven samples the trapezoid keeps only its O(h²): the quadratic through
            // each pair, its product with φ and φ′ integrated exactly
            Some(p) => {
                let (a, b) = (span[0], span[w]);
                let left = product_piece(span, &|x| -bump_at(x, a, b, p).1);
                (product_piece(span, &|x| bump_at(x, a, b, p).0), left)
            }
        }
    };
    let mut y = vec![0.0; rows];
    let mut out = vec![vec![0.0; rows]; columns.len()];
    if even {
        // one set of weights for every window: a convolution, summed weight by weight over
        // all rows (the same additions in the same order as window by window, vectorised)
        let (wk, lk) = weights(0);
        let convolve = |o: &mut [f64], c: &[f64], weights: &[f64]| {
            for (i, a) in weights.iter().enumerate() {
                for (o, c) in o.iter_mut().zip(&c[i..i + rows]) {
                    *o += a * c;
                }
            }
        };
        match bump {
            None => y.iter_mut().enumerate().for_each(|(k, y)| *y = x[k + w] - x[k]),
            Some(_) => convolve(&mut y, x, &lk),
        }
        for (o, c) in out.iter_mut().zip(columns) {
            convolve(o, c, &wk);
        }
        return (y, out);
    }
    for k in 0..rows {
        let (wk, lk) = weights(k);
        y[k] = match bump {
            None => x[k + w] - x[k],
            Some(_) => lk.iter().zip(&x[k..=k + w]).map(|(a, b)| a * b).sum(),
        };
        for (o, c) in out.iter_mut().zip(columns) {
            o[k] = wk.iter().zip(&c[k..=k + w]).map(|(a, b)| a * b).sum();
        }
    }
    (y, out)
}

/// Rows per independent row of a window form on an even grid: the left side's noise from
/// white noise in x is Σ aᵢ εₖ₊ᵢ with aᵢ = −φ′(tᵢ) h, so the rows k and k + m share it with
/// correlation ρₘ = Σ aᵢ aᵢ₊ₘ / Σ aᵢ²; their integrated correlation time 1 + 2 Σ ρₘ summed up
/// to the first negative ρₘ (Geyer's initial positive sequence). 1 for a flat window (its left
/// side x(b) − x(a) shares noise with no other row but the one a window away, negatively).
/// Without it, overlapping windows count each noise W-fold and the criteria keep spurious
/// terms (on the ODE benchmark's noisy runs, benches/odes: 16 of 37 recovered, 34 with it).
pub fn row_overlap(window: Window) -> f64 {
    let TestFunction::Bump(p) = window.test else { return 1.0 };
    let w = window.intervals;
    if w < 2 {
        return 1.0;
    }
    let t: Vec<f64> = (0..=w).map(|i| i as f64).collect();
    let (_, a) = bump_values(&t, p);
    let energy: f64 = a.iter().map(|v| v * v).sum();
    if energy <= 0.0 {
        return 1.0;
    }
    let mut tau = 1.0;
    for m in 1..=w {
        let rho = a.iter().zip(&a[m..]).map(|(x, y)| x * y).sum::<f64>() / energy;
        if rho < 0.0 {
            break;
        }
        tau += 2.0 * rho;
    }
    tau
}

/// φ = (1 − s²)^p and dφ/dt at samples `t` of one window, s running from −1 at its first
/// sample to 1 at its last.
fn bump_values(t: &[f64], p: u32) -> (Vec<f64>, Vec<f64>) {
    let (a, b) = (t[0], t[t.len() - 1]);
    t.iter().map(|x| bump_at(*x, a, b, p)).unzip()
}

/// [`integral_rows`] where some columns jump at samples (an input held between them:
/// `jumps[k]` where one changes at sample k). A window with a jump inside is integrated
/// piece by piece between its jumps, where every candidate is smooth: each piece from its
/// start sample's values (`columns`, the values after a jump) to its end sample's values
/// before the jump there (`before[j][k]`: candidate j at sample k with the held inputs at
/// sample k − 1). Across the jump instead, Simpson's rule and the trapezoid smear it over
/// the intervals beside it.
pub fn integral_rows_held(
    t: &[f64],
    x: &[f64],
    columns: &[Vec<f64>],
    before: &[Vec<f64>],
    jumps: &[bool],
    window: Window,
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let w = window.intervals;
    let (mut y, mut out) = integral_rows(t, x, columns, window);
    // jumps before each sample, to find the windows with one inside at a glance
    let mut count = vec![0usize; jumps.len() + 1];
    for (k, j) in jumps.iter().enumerate() {
        count[k + 1] = count[k] + usize::from(*j);
    }
    for k in 0..y.len() {
        if count[k + w + 1] == count[k + 1] {
            continue;
        }
        let mut a = k;
        for (o, _) in out.iter_mut().zip(columns) {
            o[k] = 0.0;
        }
        let (start, end) = (t[k], t[k + w]);
        if let TestFunction::Bump(_) = window.test {
            // x has a kink at each jump: −∫ φ′ x piece by piece too
            y[k] = 0.0;
        }
        for b in (k + 1..=k + w).filter(|&b| jumps[b] || b == k + w) {
            let weights = match window.test {
                TestFunction::Flat => piece(&t[a..=b]),
                TestFunction::Bump(p) => {
                    let slope = product_piece(&t[a..=b], &|x| bump_at(x, start, end, p).1);
                    y[k] -= slope.iter().zip(&x[a..=b]).map(|(w, v)| w * v).sum::<f64>();
                    product_piece(&t[a..=b], &|x| bump_at(x, start, end, p).0)
                }
            };
            for ((o, c), l) in out.iter_mut().zip(columns).zip(before) {
                let inside: f64 = weights[..b - a].iter().zip(&c[a..b]).map(|(w, v)| w * v).sum();
                o[k] += inside + weights[b - a] * l[b];
            }
            a = b;
        }
    }
    (y, out)
}

/// Weights wᵢ = ∫ g Lᵢ dt over one smooth piece of samples `t` for a weight g known in
/// closed form (the bump φ or its rate φ′): each pair of intervals by the quadratic through its
/// three samples (the last interval of an odd number by the line through two), the product
/// with g integrated by Gauss-Legendre of six points per interval (exact to degree 11, g·Lᵢ's
/// degree 2p + 2: exact to p = 4, beyond it an error of g's twelfth derivative over one
/// interval, far below the quadratic's). A held input is constant on its piece and a state
/// smooth on it, so their integrals keep the quadratic's accuracy however g curves, where a
/// rule on the samples of g·θ across a jump or a kink would not.
fn product_piece(t: &[f64], g: &dyn Fn(f64) -> f64) -> Vec<f64> {
    const NODES: [(f64, f64); 6] = [
        (-0.932_469_514_203_152, 0.171_324_492_379_170),
        (-0.661_209_386_466_265, 0.360_761_573_048_139),
        (-0.238_619_186_083_197, 0.467_913_934_572_691),
        (0.238_619_186_083_197, 0.467_913_934_572_691),
        (0.661_209_386_466_265, 0.360_761_573_048_139),
        (0.932_469_514_203_152, 0.171_324_492_379_170),
    ];
    let integrate = |a: f64, b: f64, l: &dyn Fn(f64) -> f64| -> f64 {
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        NODES.iter().map(|(x, w)| w * half * g(mid + half * x) * l(mid + half * x)).sum()
    };
    let m = t.len() - 1;
    let mut out = vec![0.0; m + 1];
    let paired = m - m % 2;
    for i in (0..paired).step_by(2) {
        let (a, b, c) = (t[i], t[i + 1], t[i + 2]);
        let basis: [&dyn Fn(f64) -> f64; 3] = [
            &|x| (x - b) * (x - c) / ((a - b) * (a - c)),
            &|x| (x - a) * (x - c) / ((b - a) * (b - c)),
            &|x| (x - a) * (x - b) / ((c - a) * (c - b)),
        ];
        for (j, l) in basis.iter().enumerate() {
            out[i + j] += integrate(a, b, *l) + integrate(b, c, *l);
        }
    }
    if m % 2 == 1 {
        let (a, b) = (t[m - 1], t[m]);
        out[m - 1] += integrate(a, b, &|x| (b - x) / (b - a));
        out[m] += integrate(a, b, &|x| (x - a) / (b - a));
    }
    out
}

/// φ = (1 − s²)^p and dφ/dt at time `x` of the window [`start`, `end`].
fn bump_at(x: f64, start: f64, end: f64, p: u32) -> (f64, f64) {
    let s = ((2.0 * x - start - end) / (end - start)).clamp(-1.0, 1.0);
    let base = 1.0 - s * s;
    (base.powi(p as i32), -2.0 * p as f64 * s * base.powi(p as i32 - 1) * 2.0 / (end - start))
}

/// Quadrature weights over one smooth piece of samples `t`: Simpson's rule over an even
/// number of intervals, with Simpson's 3/8 rule over the last three of an odd number (the
/// quadratic through each pair, and the trapezoid for the last interval, on uneven samples),
/// the trapezoid over one interval.
fn piece(t: &[f64]) -> Vec<f64> {
    let m = t.len() - 1;
    if m == 1 {
        return trapezoid(t);
    }
    let h = (t[m] - t[0]) / m as f64;
    let close = super::on_sample(t);
    let even = t.windows(2).all(|p| ((p[1] - p[0]) - h).abs() <= close);
    let odd = m % 2 == 1;
    let paired = if odd { m - 3 } else { m };
    let mut out = vec![0.0; m + 1];
    if even {
        for i in (0..paired).step_by(2) {
            out[i] += h / 3.0;
            out[i + 1] += 4.0 * h / 3.0;
            out[i + 2] += h / 3.0;
        }
        if odd {
            for (i, c) in [1.0, 3.0, 3.0, 1.0].into_iter().enumerate() {
                out[paired + i] += 3.0 * h / 8.0 * c;
            }
        }
    } else {
        let last = if odd { m - 1 } else { m };
        if last > 0 {
            out[..=last].copy_from_slice(&uneven_simpson(&t[..=last]));
        }
        if odd {
            let end = trapezoid(&t[m - 1..]);
            out[m - 1] += end[0];
            out[m] += end[1];
        }
    }
    out
}

/// Spacings of a pair of intervals whose ratio is beyond this get the trapezoid: the
/// quadratic through three unevenly spaced samples weighs an end sample negatively and
/// amplifies their noise (the weights' absolute sum 1.3 times the span at a ratio of 3, 3.3
/// times at 9).
const PAIR_RATIO: f64 = 3.0;

/// Quadrature weights over uneven samples `t` (an even number of intervals): each pair of
/// intervals by the quadratic through its three samples, Simpson's rule for uneven spacing
/// (exact for quadratics, an error of O(h⁴) per pair where the trapezoid leaves O(h³), which
/// is smooth in the states and so fitted by spurious terms), the trapezoid for a pair whose
/// spacings differ by more than [`PAIR_RATIO`].
fn uneven_simpson(t: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; t.len()];
    for pair in (0..t.len() - 1).step_by(2) {
        let (h0, h1) = (t[pair + 1] - t[pair], t[pair + 2] - t[pair + 1]);
        let ratio = h0.max(h1) / h0.min(h1);
        if ratio > PAIR_RATIO || !ratio.is_finite() {
            for (i, v) in trapezoid(&t[pair..=pair + 2]).into_iter().enumerate() {
                out[pair + i] += v;
            }
            continue;
        }
        let span = (h0 + h1) / 6.0;
        out[pair] += span * (2.0 - h1 / h0);
        out[pair + 1] += span * (h0 + h1) * (h0 + h1) / (h0 * h1);
        out[pair + 2] += span * (2.0 - h0 / h1);
    }
    out
}

/// The trapezoid's weights over samples `t`.
fn trapezoid(t: &[f64]) -> Vec<f64> {
    let w = t.len() - 1;
    (0..=w)
        .map(|i| {
            let left = if i > 0 { t[i] - t[i - 1] } else { 0.0 };
            let right = if i < w { t[i + 1] - t[i] } else { 0.0 };
            0.5 * (left + right)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn flat(intervals: usize) -> Window {
        Window { intervals, test: TestFunction::Flat, shrinks: false, instrumented: false }
    }

    /// Simpson's rule integrates cubics exactly: x = t⁴/4 with θ = t³ gives the window's
    /// change exactly; the trapezoid on uneven samples is exact for a linear θ.
    #[test]
    fn windows_integrate_exactly_where_the_rule_is_exact() {
        let t: Vec<f64> = (0..41).map(|k| 0.05 * k as f64).collect();
        let x: Vec<f64> = t.iter().map(|t| t.powi(4) / 4.0).collect();
        let theta = vec![t.iter().map(|t| t.powi(3)).collect::<Vec<f64>>()];
        let (y, cols) = integral_rows(&t, &x, &theta, flat(4));
        assert_eq!(y.len(), 37);
        for (a, b) in y.iter().zip(&cols[0]) {
            assert!((a - b).abs() < 1e-13, "{a} vs {b}");
        }
        let t: Vec<f64> = (0..30).map(|k| (k as f64).powf(1.3) * 0.01).collect();
        let x: Vec<f64> = t.iter().map(|t| 1.5 * t * t + 2.0 * t).collect();
        let theta = vec![t.iter().map(|t| 3.0 * t + 2.0).collect::<Vec<f64>>()];
        let (y, cols) = integral_rows(&t, &x, &theta, flat(3));
        for (a, b) in y.iter().zip(&cols[0]) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        // uneven samples, an even window: the quadratic through each pair is exact for θ = t²
        // where the trapezoid is not (and where the spacings differ by more than 3, the
        // trapezoid is kept: exact for θ linear only)
        let x: Vec<f64> = t.iter().map(|t| t.powi(3) / 3.0).collect();
        let theta = vec![t.iter().map(|t| t * t).collect::<Vec<f64>>()];
        let (y, cols) = integral_rows(&t, &x, &theta, flat(4));
        for (a, b) in y.iter().zip(&cols[0]) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        let trapezoid_error = (trapezoid(&t[0..=4]).iter().zip(&theta[0]).map(|(a, b)| a * b).sum::<f64>()
            - (x[4] - x[0]))
            .abs();
        assert!(trapezoid_error > 1e-6, "{trapezoid_error}");
        let wide = [0.0, 0.1, 0.5];
        assert_eq!(uneven_simpson(&wide), trapezoid(&wide));
    }

    /// ẋ = t·F with F held between samples, jumping at samples 5, 6, 12 and 19 (pieces of
    /// one, six, seven and more intervals, a jump at a window's start and at its end): each
    /// window's integral exactly the change of x, the closed form (every rule of a piece is
    /// exact for θ linear); the rule that takes F as a line between samples misses it by about
    /// a jump's integral over half an interval. The same on uneven samples with θ = F.
    #[test]
    fn held_inputs_integrate_piece_by_piece() {
        let level = |k: usize| match k {
            0..=4 => 1.0,
            5 => -2.0,
            6..=11 => 0.5,
            12..=18 => 3.0,
            _ => -1.0,
        };
        let jumps: Vec<bool> = (0..30).map(|k| k > 0 && level(k) != level(k - 1)).collect();
        for (t, power) in [
            ((0..30).map(|k| 0.1 * k as f64).collect::<Vec<f64>>(), 1),
            ((0..30).map(|k| (k as f64).powf(1.2) * 0.1).collect(), 0),
        ] {
            // x(t) summed over the pieces: ∫ F_k·t^p from t_k to t_(k+1)
            let prim = |a: f64, b: f64| (b.powi(power + 1) - a.powi(power + 1)) / (power + 1) as f64;
            let mut x = vec![0.0];
            for k in 0..29 {
                x.push(x[k] + level(k) * prim(t[k], t[k + 1]));
            }
            let theta =
                vec![t.iter().enumerate().map(|(k, t)| level(k) * t.powi(power)).collect::<Vec<f64>>()];
            let before = vec![t
                .iter()
                .enumerate()
                .map(|(k, t)| level(k.saturating_sub(1)) * t.powi(power))
                .collect::<Vec<f64>>()];
            for w in [4, 5, 8] {
                let (y, cols) = integral_rows_held(&t, &x, &theta, &before, &jumps, flat(w));
                for (k, (a, b)) in y.iter().zip(&cols[0]).enumerate() {
                    assert!((a - b).abs() < 1e-12, "w = {w}, window {k}: {a} vs {b}");
                }
                let (_, smeared) = integral_rows(&t, &x, &theta, flat(w));
                let worst = y.iter().zip(&smeared[0]).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
                assert!(worst > 1e-3, "w = {w}: {worst}");
            }
        }
    }
}
