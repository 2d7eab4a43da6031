//! Sufficient statistics of a linear regression: the weighted means and the corrected sums
//! of cross-products a_jk = Σ w (z_j − z̄_j)(z_k − z̄_k) of the regressors and the target
//! (target last), accumulated in one pass over the rows. Rows arrive in blocks; each chunk
//! is centred on its own mean, its cross-products formed by a BLAS-class product (matrixmultiply
//! through nalgebra on a transposed view), and chunks are merged with the pairwise update of
//! Chan, Golub & LeVeque (1979). Statistics of several files simply [`Moments::merge`].

/// Most rows per chunk handed to the Gram kernel (the buffer grows to this as rows come).
/// 512 rows of 30 columns stay below glibc's mmap threshold (128 KiB): larger chunks were
/// mapped and unmapped on every fit, and the page faults cost more than the products.
const CHUNK: usize = 512;

/// Means and corrected cross-products of `p` regressors and one target.
#[derive(Clone, Debug, PartialEq)]
pub struct Moments {
    p: usize,
    count: usize,
    weight: f64,
    mean: Vec<f64>,
    /// (p+1)² column-major, symmetric.
    comoment: Vec<f64>,
}

impl Moments {
    /// Empty statistics for `p` regressors.
    pub fn new(p: usize) -> Moments {
        let m = p + 1;
        Moments { p, count: 0, weight: 0.0, mean: vec![0.0; m], comoment: vec![0.0; m * m] }
    }

    /// Number of regressors.
    pub fn regressors(&self) -> usize {
        self.p
    }

    /// Number of rows seen.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Sum of the weights (= rows when unweighted).
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// Weighted means; the target's is last.
    pub fn means(&self) -> &[f64] {
        &self.mean
    }

    /// Corrected cross-product of variables `i` and `j` (index `p` is the target).
    pub fn corrected(&self, i: usize, j: usize) -> f64 {
        self.comoment[i + j * (self.p + 1)]
    }

    /// Cross-product about the origin, Σ w z_i z_j.
    pub fn raw(&self, i: usize, j: usize) -> f64 {
        self.corrected(i, j) + self.weight * self.mean[i] * self.mean[j]
    }

    /// Adds another set of statistics over the same variables (e.g. another file).
    pub fn merge(&mut self, other: &Moments) {
        assert_eq!(self.p, other.p, "moments of different regressor sets");
        if other.weight == 0.0 {
            self.count += other.count;
            return;
        }
        let m = self.p + 1;
        let total = self.weight + other.weight;
        let f = self.weight * other.weight / total;
        let delta: Vec<f64> = other.mean.iter().zip(&self.mean).map(|(b, a)| b - a).collect();
        for j in 0..m {
            for i in 0..m {
                self.comoment[i + j * m] += other.comoment[i + j * m] + f * delta[i] * delta[j];
            }
        }
        for (mu, d) in self.mean.iter_mut().zip(&delta) {
            *mu += d * other.weight / total;
        }
        self.weight = total;
        self.count += other.count;
    }
}

impl Moments {
    /// The statistics of all rows except those of `part` (which must be among them): the
    /// inverse of [`Moments::merge`], for leaving one run out.
    pub fn without(&self, part: &Moments) -> Moments {
        assert_eq!(self.p, part.p, "moments of different regressor sets");
        let m = self.p + 1;
        let rest_w = self.weight - part.weight;
        let mut rest = Moments::new(self.p);
        rest.count = self.count.saturating_sub(part.count);
        rest.weight = rest_w;
        if rest_w <= 0.0 {
            return rest;
        }
        for j in 0..m {
            rest.mean[j] = (self.weight * self.mean[j] - part.weight * part.mean[j]) / rest_w;
        }
        let f = rest_w * part.weight / self.weight;
        for j in 0..m {
            for i in 0..m {
                let (di, dj) = (part.mean[i] - rest.mean[i], part.mean[j] - rest.mean[j]);
                rest.comoment[i + j * m] = self.comoment[i + j * m] - part.comoment[i + j * m] - f * di * dj;
            }
        }
        rest
    }

    /// Σ w (y − b0 − Σ bⱼ xⱼ)² over these rows for a given linear predictor (`set` columns,
    /// `coefficients` aligned): the squared error of a model fitted elsewhere.
    pub fn squared_error(&self, set: &[usize], coefficients: &[f64], intercept: f64) -> f64 {
        let p = self.p;
        let c = |i: usize, j: usize| self.corrected(i, j);
        let mut sse = c(p, p);
        for (a, &i) in set.iter().enumerate() {
            sse -= 2.0 * coefficients[a] * c(i, p);
            for (b, &j) in set.iter().enumerate() {
                sse += coefficients[a] * coefficients[b] * c(i, j);
            }
        }
        let bias = self.mean[p]
            - intercept
            - set.iter().zip(coefficients).map(|(&i, b)| b * self.mean[i]).sum::<f64>();
        (sse + self.weight * bias * bias).max(0.0)
    }
}

/// Σ x with four independent partial sums: a single running sum is a dependent chain of
/// additions (latency-bound, ~4× slower), and the compiler may not reorder it itself.
fn sum4(x: &[f64]) -> f64 {
    let mut lanes = [0.0f64; 4];
    let chunks = x.chunks_exact(4);
    let rest: f64 = chunks.remainder().iter().sum();
    for c in chunks {
        for l in 0..4 {
            lanes[l] += c[l];
        }
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + rest
}

/// Σ x·w, four partial sums (see [`sum4`]).
fn dot4(x: &[f64], w: &[f64]) -> f64 {
    let mut lanes = [0.0f64; 4];
    let (xc, wc) = (x.chunks_exact(4), w.chunks_exact(4));
    let rest: f64 = xc.remainder().iter().zip(wc.remainder()).map(|(a, b)| a * b).sum();
    for (a, b) in xc.zip(wc) {
        for l in 0..4 {
            lanes[l] += a[l] * b[l];
        }
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + rest
}

/// Accumulates [`Moments`] from blocks of rows without keeping them.
#[derive(Debug)]
pub struct Accumulator {
    moments: Moments,
    /// Chunk buffer, (p+1) columns of `ld` rows, column-major.
    buf: Vec<f64>,
    ld: usize,
    w: Vec<f64>,
    filled: usize,
    weighted: bool,
}

impl Accumulator {
    /// An accumulator for `p` regressors.
    pub fn new(p: usize) -> Accumulator {
        Accumulator {
            moments: Moments::new(p),
            buf: Vec::new(),
            ld: 0,
            w: Vec::new(),
            filled: 0,
            weighted: false,
        }
    }

    /// Adds `rows` rows: `x` column-major `rows × p`, target `y`, optional weights.
    pub fn push(&mut self, x: &[f64], y: &[f64], weights: Option<&[f64]>) {
        let p = self.moments.p;
        let rows = y.len();
        assert_eq!(x.len(), rows * p, "block must hold rows × p values");
        let mut done = 0;
        while done < rows {
            if self.filled == self.ld && self.ld < CHUNK {
                self.grow(CHUNK);
            }
            let ld = self.ld;
            let take = (ld - self.filled).min(rows - done);
            for j in 0..p {
                let src = &x[j * rows + done..j * rows + done + take];
                self.buf[j * ld + self.filled..j * ld + self.filled + take].copy_from_slice(src);
            }
            self.buf[p * ld + self.filled..p * ld + self.filled + take]
                .copy_from_slice(&y[done..done + take]);
            let w = &mut self.w[self.filled..self.filled + take];
            match weights {
                Some(ws) => {
                    self.weighted = true;
                    w.copy_from_slice(&ws[done..done + take]);
                }
                None => w.fill(1.0),
            }
            self.filled += take;
            done += take;
            if self.filled == CHUNK {
                self.flush();
            }
        }
    }

    /// Re-lays the chunk buffer out for `ld` rows per column, in the thread's spare buffer
    /// when there is one (its old contents need no clearing: rows are written before they
    /// are read).
    fn grow(&mut self, ld: usize) {
        let m = self.moments.p + 1;
        let mut buf = SPARE.with(|s| std::mem::take(&mut *s.borrow_mut()));
        if buf.len() >= m * ld {
            buf.truncate(m * ld);
        } else {
            buf.resize(m * ld, 0.0);
        }
        for j in 0..m {
            buf[j * ld..j * ld + self.filled]
                .copy_from_slice(&self.buf[j * self.ld..j * self.ld + self.filled]);
        }
        self.buf = buf;
        self.w.resize(ld, 0.0);
        self.ld = ld;
    }

    fn flush(&mut self) {
        let n = self.filled;
        if n == 0 {
            return;
        }
        let m = self.moments.p + 1;
        let w = &self.w[..n];
        let wsum: f64 = w.iter().sum();
        let mut chunk = Moments::new(self.moments.p);
        chunk.count = n;
        chunk.weight = wsum;
        // centre each column on the chunk mean, scale rows by √w
        let ld = self.ld;
        for j in 0..m {
            let col = &mut self.buf[j * ld..j * ld + n];
            let mean = if self.weighted { dot4(col, w) / wsum } else { sum4(col) / n as f64 };
            chunk.mean[j] = mean;
            if self.weighted {
                for (x, w) in col.iter_mut().zip(w) {
                    *x = (*x - mean) * w.sqrt();
                }
            } else {
                col.iter_mut().for_each(|x| *x -= mean);
            }
        }
        if wsum > 0.0 {
            super::gram::gram(&self.buf, ld, n, m, &mut chunk.comoment);
        }
        self.moments.merge(&chunk);
        self.filled = 0;
    }

    /// The statistics of all rows pushed.
    pub fn finish(mut self) -> Moments {
        self.flush();
        std::mem::replace(&mut self.moments, Moments::new(0))
    }
}

thread_local! {
    /// The last chunk buffer, kept for the next accumulator on this thread: a fit accumulates
    /// run after run, and a fresh 100 kB buffer each time came back from the system as fresh
    /// pages — page faults cost more than the products (half of a 2 505-row fit).
    static SPARE: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

impl Drop for Accumulator {
    fn drop(&mut self) {
        let buf = std::mem::take(&mut self.buf);
        SPARE.with(|s| {
            let mut spare = s.borrow_mut();
            if buf.capacity() > spare.capacity() {
                *spare = buf;
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_two_pass_formula_and_merges() {
        let n = 5000;
        let x: Vec<f64> = (0..n * 2).map(|i| ((i * 7919) % 1000) as f64 / 100.0 + 1e6).collect();
        let y: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut acc = Accumulator::new(2);
        acc.push(&x, &y, None);
        let m = acc.finish();
        let col = |j: usize| -> Vec<f64> {
            if j < 2 {
                x[j * n..(j + 1) * n].to_vec()
            } else {
                y.clone()
            }
        };
        for i in 0..3 {
            for j in 0..3 {
                let (a, b) = (col(i), col(j));
                let (ma, mb) = (a.iter().sum::<f64>() / n as f64, b.iter().sum::<f64>() / n as f64);
                let c: f64 = a.iter().zip(&b).map(|(a, b)| (a - ma) * (b - mb)).sum();
                assert!((m.corrected(i, j) - c).abs() <= 1e-9 * c.abs().max(1.0), "{i}{j}");
            }
        }
        // two halves merged = whole
        let (mut a1, mut a2) = (Accumulator::new(2), Accumulator::new(2));
        let half = n / 2;
        let xa: Vec<f64> = (0..2).flat_map(|j| x[j * n..j * n + half].to_vec()).collect();
        let xb: Vec<f64> = (0..2).flat_map(|j| x[j * n + half..(j + 1) * n].to_vec()).collect();
        a1.push(&xa, &y[..half], None);
        a2.push(&xb, &y[half..], None);
        let mut merged = a1.finish();
        merged.merge(&a2.finish());
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    (merged.corrected(i, j) - m.corrected(i, j)).abs()
                        <= 1e-9 * m.corrected(i, j).abs().max(1.0)
                );
            }
        }
    }

    #[test]
    fn without_is_the_inverse_of_merge_and_squared_error_is_direct() {
        let x: Vec<f64> = (0..60).map(|i| ((i * 37 % 11) as f64) * 0.3 + 1.0).collect();
        let y: Vec<f64> = (0..30).map(|i| (i as f64 * 0.7).sin() * 3.0 + 5.0).collect();
        let cols = |r: std::ops::Range<usize>| -> Vec<f64> {
            (0..2).flat_map(|j| x[j * 30 + r.start..j * 30 + r.end].to_vec()).collect()
        };
        let (mut a, mut b, mut all) = (Accumulator::new(2), Accumulator::new(2), Accumulator::new(2));
        a.push(&cols(0..12), &y[..12], None);
        b.push(&cols(12..30), &y[12..], None);
        all.push(&x, &y, None);
        let (a, b, all) = (a.finish(), b.finish(), all.finish());
        let rest = all.without(&a);
        for i in 0..3 {
            assert!((rest.means()[i] - b.means()[i]).abs() < 1e-12);
            for j in 0..3 {
                assert!(
                    (rest.corrected(i, j) - b.corrected(i, j)).abs()
                        < 1e-9 * b.corrected(i, j).abs().max(1.0)
                );
            }
        }
        // squared error of y ≈ 0.5 + 0.3 x1 − 0.2 x2 on rows 12..30, directly
        let direct: f64 = (12..30).map(|r| (y[r] - 0.5 - 0.3 * x[r] + 0.2 * x[30 + r]).powi(2)).sum();
        assert!((b.squared_error(&[0, 1], &[0.3, -0.2], 0.5) - direct).abs() < 1e-9 * direct);
    }

    #[test]
    fn integer_weights_equal_repeated_rows() {
        let x = vec![1.0, 2.0, 4.0];
        let y = vec![1.0, 3.0, 2.0];
        let mut a = Accumulator::new(1);
        a.push(&x, &y, Some(&[1.0, 2.0, 1.0]));
        let a = a.finish();
        let mut b = Accumulator::new(1);
        b.push(&[1.0, 2.0, 2.0, 4.0], &[1.0, 3.0, 3.0, 2.0], None);
        let b = b.finish();
        for (i, j) in [(0, 0), (0, 1), (1, 1)] {
            assert!((a.corrected(i, j) - b.corrected(i, j)).abs() < 1e-12);
        }
    }
}
