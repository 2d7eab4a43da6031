//! Sufficient statistics of a linear regression: the weighted means and the corrected sums
//! of cross-products a_jk = Σ w (z_j − z̄_j)(z_k − z̄_k) of the regressors and the target
//! (target last), accumulated in one pass over the rows. Rows arrive in blocks; each chunk
//! is shifted by its first row, its cross-products formed by the register-tiled kernel of
//! [`super::gram`] straight from the caller's columns, and chunks are merged with the pairwise
//! update of Chan, Golub & LeVeque (1979). Statistics of several files simply
//! [`Moments::merge`].

use std::ops::Range;

/// Most rows per chunk, i.e. per shift: the data's drift within a chunk stays small beside
/// the shifted values. For weighted rows it is also the scratch block's height: 512 rows of 30
/// columns stay below glibc's mmap threshold (128 KiB), above which every fit had paid page
/// faults.
const CHUNK: usize = 512;

/// Means and corrected cross-products of `p` regressors and one target. Serializable: the
/// statistics of a shard of rows are a value to write, send and merge (JSON numbers round-trip
/// exactly).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(into = "Packed", try_from = "Packed")]
pub struct Moments {
    p: usize,
    count: usize,
    weight: f64,
    mean: Vec<f64>,
    /// (p+1)² column-major; only the lower triangle (row ≥ column) is kept up to date: the
    /// matrix is symmetric, and mirroring every chunk's products cost more than reading
    /// (i, j) as (j, i).
    comoment: Vec<f64>,
    /// Rows per independent row: 1 where each row's noise is its own; more where the rows
    /// share their noise by construction (a weak form's overlapping windows), so that the
    /// back-ends count `count / overlap` rows' worth of evidence.
    overlap: f64,
}

/// How statistics are written: the regressors, the rows, and [`Moments::numbers`] (the lower
/// triangle only, so the text is canonical and half the size).
#[derive(serde::Serialize, serde::Deserialize)]
struct Packed {
    p: usize,
    count: usize,
    numbers: Vec<f64>,
    #[serde(default = "independent", skip_serializing_if = "is_independent")]
    overlap: f64,
}

fn independent() -> f64 {
    1.0
}

fn is_independent(overlap: &f64) -> bool {
    *overlap == 1.0
}

impl From<Moments> for Packed {
    fn from(m: Moments) -> Packed {
        Packed { p: m.p, count: m.count, numbers: m.numbers(), overlap: m.overlap }
    }
}

impl TryFrom<Packed> for Moments {
    type Error = String;
    fn try_from(p: Packed) -> Result<Moments, String> {
        let overlap = p.overlap;
        Moments::from_numbers(p.p, p.count, &p.numbers).map(|m| m.with_overlap(overlap)).ok_or_else(|| {
            format!("{} numbers do not make the statistics of {} regressors", p.numbers.len(), p.p)
        })
    }
}

impl PartialEq for Moments {
    fn eq(&self, other: &Moments) -> bool {
        let m = self.p + 1;
        let lower = |c: &[f64]| -> Vec<f64> {
            (0..m.min(c.len()))
                .flat_map(|j| (j..m).map(move |i| (i, j)))
                .filter_map(|(i, j)| c.get(i + j * m).copied())
                .collect()
        };
        self.p == other.p
            && self.count == other.count
            && self.overlap == other.overlap
            && self.weight == other.weight
            && self.mean == other.mean
            && lower(&self.comoment) == lower(&other.comoment)
    }
}

impl Moments {
    /// Empty statistics for `p` regressors.
    pub fn new(p: usize) -> Moments {
        let m = p + 1;
        Moments { p, count: 0, weight: 0.0, mean: vec![0.0; m], comoment: vec![0.0; m * m], overlap: 1.0 }
    }

    /// Empty statistics whose vectors are not allocated yet (an accumulator's, until its first
    /// chunk).
    fn unallocated(p: usize) -> Moments {
        Moments { p, count: 0, weight: 0.0, mean: Vec::new(), comoment: Vec::new(), overlap: 1.0 }
    }

    /// The numbers that determine the statistics, in a fixed order: the weight, the p + 1
    /// means, then the lower triangle of the comoments column by column ((p+1)(p+2)/2 values;
    /// the upper one is not kept). With [`Moments::count`] and [`Moments::regressors`] this is
    /// all [`Moments::from_numbers`] needs: a compact form to send between processes.
    pub fn numbers(&self) -> Vec<f64> {
        let m = self.p + 1;
        let mut out = Vec::with_capacity(1 + m + m * (m + 1) / 2);
        out.push(self.weight);
        if self.mean.is_empty() {
            // not allocated yet: no rows
            out.resize(1 + m + m * (m + 1) / 2, 0.0);
            return out;
        }
        out.extend_from_slice(&self.mean);
        for j in 0..m {
            out.extend_from_slice(&self.comoment[j * m + j..(j + 1) * m]);
        }
        out
    }

    /// Statistics from [`Moments::numbers`]; `None` if there are not as many as `p` needs.
    pub fn from_numbers(p: usize, count: usize, numbers: &[f64]) -> Option<Moments> {
        let m = p + 1;
        if numbers.len() != 1 + m + m * (m + 1) / 2 {
            return None;
        }
        let mut out = Moments::new(p);
        out.count = count;
        out.weight = numbers[0];
        out.mean.copy_from_slice(&numbers[1..1 + m]);
        let mut k = 1 + m;
        for j in 0..m {
            for i in j..m {
                out.comoment[j * m + i] = numbers[k];
                out.comoment[i * m + j] = numbers[k];
                k += 1;
            }
        }
        Some(out)
    }

    /// Whether the statistics are whole: vectors of their declared size, finite numbers, a
    /// weight that is not negative (statistics read from a file are checked before use).
    pub fn is_consistent(&self) -> bool {
        let m = self.p + 1;
        self.mean.len() == m
            && self.comoment.len() == m * m
            && self.weight >= 0.0
            && self.weight.is_finite()
            && self.mean.iter().chain(&self.comoment).all(|v| v.is_finite())
    }

    /// Number of regressors.
    pub fn regressors(&self) -> usize {
        self.p
    }

    /// Number of rows seen.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Rows per independent row (1 unless set by [`Moments::with_overlap`]).
    pub fn overlap(&self) -> f64 {
        self.overlap
    }

    /// These statistics with rows that share their noise over `overlap` rows each (≥ 1;
    /// anything else, 1): the back-ends take `count / overlap` rows as the evidence.
    pub fn with_overlap(mut self, overlap: f64) -> Moments {
        self.overlap = if overlap.is_finite() && overlap >= 1.0 { overlap } else { 1.0 };
        self
    }

    /// The rows' worth of independent evidence, `count / overlap`.
    pub fn independent_rows(&self) -> f64 {
        self.count as f64 / self.overlap
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
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        self.comoment[i + j * (self.p + 1)]
    }

    /// Cross-product about the origin, Σ w z_i z_j.
    pub fn raw(&self, i: usize, j: usize) -> f64 {
        self.corrected(i, j) + self.weight * self.mean[i] * self.mean[j]
    }

    /// Adds another set of statistics over the same variables (e.g. another file).
    pub fn merge(&mut self, other: &Moments) {
        assert_eq!(self.p, other.p, "moments of different regressor sets");
        let (rows, independent) =
            (self.count + other.count, self.independent_rows() + other.independent_rows());
        let overlap = if independent > 0.0 { rows as f64 / independent } else { 1.0 };
        self.merge_rows(other);
        self.overlap = overlap.max(1.0);
    }

    fn merge_rows(&mut self, other: &Moments) {
        if other.weight == 0.0 {
            self.count += other.count;
            return;
        }
        if self.weight == 0.0 {
            let count = self.count + other.count;
            self.clone_from(other);
            self.count = count;
            return;
        }
        let m = self.p + 1;
        let total = self.weight + other.weight;
        let f = self.weight * other.weight / total;
        let (a, b) = (&self.mean, &other.mean);
        for j in 0..m {
            let fdj = f * (b[j] - a[j]);
            let lower = j * m + j..(j + 1) * m;
            let (mine, theirs) = (&mut self.comoment[lower.clone()], &other.comoment[lower]);
            for ((c, o), (bi, ai)) in mine.iter_mut().zip(theirs).zip(b[j..].iter().zip(&a[j..])) {
                *c += o + fdj * (bi - ai);
            }
        }
        for (mu, o) in self.mean.iter_mut().zip(&other.mean) {
            *mu += (o - *mu) * other.weight / total;
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
        let independent = self.independent_rows() - part.independent_rows();
        rest.overlap = if independent > 0.0 { (rest.count as f64 / independent).max(1.0) } else { 1.0 };
        rest.weight = rest_w;
        if rest_w <= 0.0 {
            return rest;
        }
        for j in 0..m {
            rest.mean[j] = (self.weight * self.mean[j] - part.weight * part.mean[j]) / rest_w;
        }
        let f = rest_w * part.weight / self.weight;
        for j in 0..m {
            for i in j..m {
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

/// Accumulates [`Moments`] from blocks of rows without keeping them.
///
/// Each chunk of rows is shifted by its first row, its cross-products and the sums of the
/// shifted values formed by [`super::gram::gram_add`] straight from the caller's columns
/// (shifted in registers), then corrected to the chunk mean,
/// G − s sᵀ/W: the shifted-data algorithm, as accurate as centring on the mean when the shift
/// is a value of the data, with one pass fewer. Weighted rows are first copied as
/// (z − shift)·√w into a scratch block.
#[derive(Debug)]
pub struct Accumulator {
    moments: Moments,
    /// The statistics of the chunk being gathered; its comoment collects the lower triangle
    /// of the shifted cross-products until the chunk is flushed (the kernel's entries above
    /// the diagonal are never read).
    chunk: Moments,
    /// Per column, the chunk's shift and Σ w (z − shift) of the rows in the chunk.
    shift: Vec<f64>,
    sums: Vec<f64>,
    /// Σ w of the rows in the chunk.
    wsum: f64,
    /// Rows in the chunk.
    filled: usize,
    /// Weighted rows only: (z − shift)·√w, (p+1) columns of the piece's rows, from the
    /// thread's spare buffer; √w of the rows; zero shifts for the kernel and room for the
    /// kernel's sums, which are not the weighted ones.
    scratch: Vec<f64>,
    root_w: Vec<f64>,
    zeros: Vec<f64>,
    unused: Vec<f64>,
    /// The first column (p = target) whose sum was not finite.
    not_finite: Option<usize>,
}

impl Accumulator {
    /// An accumulator for `p` regressors.
    pub fn new(p: usize) -> Accumulator {
        // both allocated when first needed: a part of a run is often a single chunk, which
        // then simply becomes the statistics (allocating and zeroing them was a tenth of a fit)
        Accumulator {
            moments: Moments::unallocated(p),
            chunk: Moments::unallocated(p),
            shift: vec![0.0; p + 1],
            sums: vec![0.0; p + 1],
            wsum: 0.0,
            filled: 0,
            scratch: Vec::new(),
            root_w: Vec::new(),
            zeros: Vec::new(),
            unused: Vec::new(),
            not_finite: None,
        }
    }

    /// Adds `rows` rows: `x` column-major `rows × p`, target `y`, optional weights.
    pub fn push(&mut self, x: &[f64], y: &[f64], weights: Option<&[f64]>) {
        let rows = y.len();
        assert_eq!(x.len(), rows * self.moments.p, "block must hold rows × p values");
        if rows == 0 {
            return;
        }
        let columns: Vec<&[f64]> = x.chunks_exact(rows).take(self.moments.p).collect();
        self.push_columns(&columns, y, weights);
    }

    /// Adds `y.len()` rows given as one slice per regressor (each as long as `y`): the rows
    /// of a part of a larger column-major matrix, or a block of evaluated terms, read where
    /// they are.
    pub fn push_columns(&mut self, columns: &[&[f64]], y: &[f64], weights: Option<&[f64]>) {
        let p = self.moments.p;
        let rows = y.len();
        assert!(
            columns.len() == p && columns.iter().all(|c| c.len() == rows),
            "push_columns: p columns of y.len() rows"
        );
        assert!(weights.is_none_or(|w| w.len() == rows), "push_columns: one weight per row");
        let all = || columns.iter().copied().chain(std::iter::once(y));
        let mut piece: Vec<&[f64]> = Vec::with_capacity(p + 1);
        let mut done = 0;
        while done < rows {
            if self.filled == 0 {
                for (j, col) in all().enumerate() {
                    let c = col[done];
                    self.shift[j] = if c.is_finite() { c } else { 0.0 };
                }
                self.sums.fill(0.0);
                self.wsum = 0.0;
                if self.chunk.comoment.len() == (p + 1) * (p + 1) {
                    self.chunk.comoment.fill(0.0);
                } else {
                    self.chunk = Moments::new(p);
                }
            }
            let take = (CHUNK - self.filled).min(rows - done);
            let part = done..done + take;
            piece.clear();
            match weights {
                None => {
                    self.wsum += take as f64;
                    piece.extend(all().map(|col| &col[part.clone()]));
                    super::gram::gram_add(&piece, &self.shift, &mut self.chunk.comoment, &mut self.sums);
                }
                Some(ws) => {
                    let ws = &ws[part.clone()];
                    self.root_w.clear();
                    self.root_w.extend(ws.iter().map(|w| w.sqrt()));
                    self.wsum += ws.iter().sum::<f64>();
                    self.take_scratch(take);
                    for (j, col) in all().enumerate() {
                        // (z − c)·√w into the scratch block, Σ w (z − c) = Σ (z − c)·√w·√w
                        let dst = &mut self.scratch[j * take..(j + 1) * take];
                        let mut sum = 0.0;
                        for ((d, x), r) in dst.iter_mut().zip(&col[part.clone()]).zip(&self.root_w) {
                            *d = (x - self.shift[j]) * r;
                            sum += *d * r;
                        }
                        self.sums[j] += sum;
                    }
                    self.zeros.resize(p + 1, 0.0);
                    self.unused.resize(p + 1, 0.0);
                    let scaled: Vec<&[f64]> = self.scratch.chunks_exact(take).collect();
                    // the kernel's own sums of these values, Σ (z − c)·√w, are not needed
                    super::gram::gram_add(&scaled, &self.zeros, &mut self.chunk.comoment, &mut self.unused);
                }
            }
            if self.not_finite.is_none() {
                self.not_finite = self.sums.iter().position(|s| !s.is_finite());
            }
            self.filled += take;
            done += take;
            if self.filled == CHUNK {
                self.flush();
            }
        }
    }

    /// The first column (index p is the target) in which a value pushed so far was not finite
    /// or a sum overflowed; such statistics are meaningless.
    pub fn not_finite(&self) -> Option<usize> {
        self.not_finite
    }

    /// A scratch block of (p+1) × `rows`, from the thread's spare buffer when there is one
    /// (its old contents need no clearing: every value is written before it is read).
    fn take_scratch(&mut self, rows: usize) {
        let len = (self.moments.p + 1) * rows;
        if self.scratch.is_empty() {
            self.scratch = SPARE.with(|s| std::mem::take(&mut *s.borrow_mut()));
        }
        if self.scratch.len() >= len {
            self.scratch.truncate(len);
        } else {
            self.scratch.resize(len, 0.0);
        }
    }

    fn flush(&mut self) {
        let n = self.filled;
        if n == 0 {
            return;
        }
        self.filled = 0;
        let m = self.moments.p + 1;
        let chunk = &mut self.chunk;
        chunk.count = n;
        chunk.weight = self.wsum;
        if self.wsum > 0.0 {
            let inv = 1.0 / self.wsum;
            for j in 0..m {
                let sj = self.sums[j] * inv;
                chunk.mean[j] = self.shift[j] + sj;
                for (c, si) in chunk.comoment[j * m + j..(j + 1) * m].iter_mut().zip(&self.sums[j..]) {
                    *c -= si * sj;
                }
            }
        }
        if self.moments.weight == 0.0 && self.wsum > 0.0 {
            // the first chunk simply becomes the statistics
            let count = self.moments.count + n;
            std::mem::swap(&mut self.moments, chunk);
            self.moments.count = count;
        } else {
            self.moments.merge(chunk);
        }
    }

    /// The statistics of all rows pushed.
    pub fn finish(mut self) -> Moments {
        self.flush();
        let p = self.moments.p;
        let mut moments = std::mem::replace(&mut self.moments, Moments::unallocated(p));
        if moments.mean.len() != p + 1 {
            // no row with weight
            let count = moments.count;
            moments = Moments::new(p);
            moments.count = count;
        }
        moments
    }
}

/// Rows per part when statistics are gathered from a run of `rows` rows of `p` columns: about
/// 10⁶ multiply-adds (rows × (p+1)²) a part, at least 200 rows, at most 64 parts a run. A part
/// costs an accumulator and a merge (12 parts of 2 505 rows × 29 terms took 96 µs, 2 parts
/// 86 µs); smaller parts would not pay for themselves on the pool either. It depends on the
/// row and column counts alone, so the result, round-off included, is the same however many
/// threads there are.
fn part_rows(rows: usize, p: usize) -> usize {
    let per_part = (1.0e6 / (p as f64 + 1.0).powi(2)).max(200.0) as usize;
    let parts = (rows / per_part).clamp(1, 64);
    rows.div_ceil(parts).max(1)
}

/// Whether statistics of `rows` rows of `p` columns are worth gathering on the thread pool.
/// Handing the parts to the pool and waiting for them costs the calling thread tens of
/// microseconds (a worker's wake-up); below about 3·10⁶ multiply-adds (rows × (p+1)², e.g.
/// the paper's 2 505 rows × 29 terms) the calling thread is faster alone: 81 against 120 µs
/// there, while 5 000 rows take 205 µs alone and 156 µs on two cores (session 10, 2 cores).
pub fn in_parallel(rows: usize, p: usize) -> bool {
    rows as f64 * (p as f64 + 1.0).powi(2) >= 3.0e6 && rayon::current_num_threads() > 1
}

/// The statistics of several runs (`runs[k]` rows each), gathered in parallel: the rows are
/// cut into parts, `feed(run, rows, accumulator)` pushes the rows of one part, and the parts
/// are merged in row order. The first error, in run and row order, is returned.
///
/// (A fixed binary tree of `rayon::join`s that also merged the parts in parallel was tried:
/// 3 % slower per 2 505-row fit, the second thread joining later.)
pub fn gather<E: Send>(
    p: usize,
    runs: &[usize],
    feed: impl Fn(usize, Range<usize>, &mut Accumulator) -> Result<(), E> + Sync,
) -> Result<Vec<Moments>, E> {
    let parts = gathered_parts(p, runs, false, |k, rows, acc, _| feed(k, rows, acc))?;
    // a run's first part becomes its statistics, the others are merged into it
    let mut out: Vec<Option<Moments>> = runs.iter().map(|_| None).collect();
    for (k, _, part, _) in parts {
        match &mut out[k] {
            Some(m) => m.merge(&part),
            none => *none = Some(part),
        }
    }
    Ok(out.into_iter().map(|m| m.unwrap_or_else(|| Moments::new(p))).collect())
}

/// Where a part of a run holds the run's middle: the accumulators of its rows before the
/// middle and from it on, which `feed` fills besides the part's own ([`gather_halved`]).
pub struct Split<'a> {
    /// The run's row the second half starts on.
    pub middle: usize,
    /// The rows before it.
    pub first: &'a mut Accumulator,
    /// The rows from it on.
    pub second: &'a mut Accumulator,
}

/// [`gather`] with each run's halves (rows `0..n/2` and `n/2..n`): the run's statistics as
/// `gather` gives them, to the bit, and its halves merged from the same parts; the one part
/// that holds the middle is fed its [`Split`] too (its rows accumulated a second time), where
/// a separate pass over the halves would accumulate every row twice.
pub fn gather_halved<E: Send>(
    p: usize,
    runs: &[usize],
    feed: impl Fn(usize, Range<usize>, &mut Accumulator, Option<Split<'_>>) -> Result<(), E> + Sync,
) -> Result<Vec<(Moments, [Moments; 2])>, E> {
    let parts = gathered_parts(p, runs, true, feed)?;
    let mut out: Vec<[Option<Moments>; 3]> = runs.iter().map(|_| [None, None, None]).collect();
    let into = |slot: &mut Option<Moments>, m: &Moments| match slot {
        Some(all) => all.merge(m),
        none => *none = Some(m.clone()),
    };
    for (k, rows, part, split) in parts {
        let [whole, first, second] = &mut out[k];
        into(whole, &part);
        match split {
            Some([a, b]) => {
                into(first, &a);
                into(second, &b);
            }
            None if rows.end <= runs[k] / 2 => into(first, &part),
            None => into(second, &part),
        }
    }
    let or_none = |m: Option<Moments>| m.unwrap_or_else(|| Moments::new(p));
    Ok(out.into_iter().map(|[w, a, b]| (or_none(w), [or_none(a), or_none(b)])).collect())
}

/// Each part's statistics in run and row order, and, where `halves` asks and the part holds
/// its run's middle, those of its rows before and from the middle.
#[allow(clippy::type_complexity)]
fn gathered_parts<E: Send>(
    p: usize,
    runs: &[usize],
    halves: bool,
    feed: impl Fn(usize, Range<usize>, &mut Accumulator, Option<Split<'_>>) -> Result<(), E> + Sync,
) -> Result<Vec<(usize, Range<usize>, Moments, Option<[Moments; 2]>)>, E> {
    use rayon::prelude::*;
    let jobs: Vec<(usize, Range<usize>)> = runs
        .iter()
        .enumerate()
        .flat_map(|(k, &n)| {
            let step = part_rows(n, p);
            (0..n).step_by(step).map(move |s| (k, s..(s + step).min(n)))
        })
        .collect();
    let part = |(k, rows): &(usize, Range<usize>)| {
        let mut acc = Accumulator::new(p);
        let middle = runs[*k] / 2;
        if halves && rows.start < middle && middle < rows.end {
            let (mut first, mut second) = (Accumulator::new(p), Accumulator::new(p));
            feed(*k, rows.clone(), &mut acc, Some(Split { middle, first: &mut first, second: &mut second }))?;
            Ok((*k, rows.clone(), acc.finish(), Some([first.finish(), second.finish()])))
        } else {
            feed(*k, rows.clone(), &mut acc, None)?;
            Ok((*k, rows.clone(), acc.finish(), None))
        }
    };
    // the same parts in the same order either way: the same result, round-off included; the
    // first error in that order
    let parts: Vec<Result<_, E>> = if in_parallel(runs.iter().sum(), p) {
        jobs.par_iter().map(part).collect()
    } else {
        jobs.iter().map(part).collect()
    };
    parts.into_iter().collect()
}

impl Moments {
    /// The statistics of a column-major `n × p` matrix `x` (n = `y.len()`) against `y`,
    /// gathered in parallel (see [`gather`]).
    ///
    /// # Panics
    /// If `y` is empty or `x` is not whole columns of `y.len()` rows.
    pub fn of_columns(x: &[f64], y: &[f64], weights: Option<&[f64]>) -> Moments {
        let n = y.len();
        assert!(n > 0 && x.len().is_multiple_of(n), "of_columns: x must hold whole columns of y.len() rows");
        let p = x.len() / n;
        let parts = gather(p, &[n], |_, rows, acc| {
            let columns: Vec<&[f64]> = x.chunks_exact(n).map(|c| &c[rows.clone()]).collect();
            acc.push_columns(&columns, &y[rows.clone()], weights.map(|w| &w[rows]));
            Ok::<(), std::convert::Infallible>(())
        });
        match parts {
            Ok(mut m) => m.remove(0),
            Err(never) => match never {},
        }
    }
}

thread_local! {
    /// The last scratch block of weighted rows, kept for the next accumulator on this thread:
    /// a fit accumulates run after run, and a fresh 100 kB buffer each time came back from the
    /// system as fresh pages — page faults cost more than the products.
    static SPARE: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

impl Drop for Accumulator {
    fn drop(&mut self) {
        let buf = std::mem::take(&mut self.scratch);
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

    /// Rows that share their noise: runs of 100 rows at overlap 4 and 300 at overlap 1 are 325
    /// independent rows together (overlap 400 / 325), 300 without the first again; the overlap
    /// survives the JSON form, and the back-ends' row count is divided by it.
    #[test]
    fn overlapping_rows_count_as_their_independent_rows() {
        let run = |rows: usize, overlap: f64| {
            let x: Vec<f64> = (0..rows).map(|i| (i as f64 * 0.37).sin()).collect();
            let y: Vec<f64> = (0..rows).map(|i| (i as f64 * 0.11).cos()).collect();
            let mut acc = Accumulator::new(1);
            acc.push(&x, &y, None);
            acc.finish().with_overlap(overlap)
        };
        let (a, b) = (run(100, 4.0), run(300, 1.0));
        let mut both = a.clone();
        both.merge(&b);
        assert_eq!(both.count(), 400);
        assert!((both.independent_rows() - 325.0).abs() < 1e-9, "{}", both.independent_rows());
        assert!((both.without(&a).overlap() - 1.0).abs() < 1e-12);
        let text = serde_json::to_string(&a).unwrap();
        assert_eq!(serde_json::from_str::<Moments>(&text).unwrap(), a);
        assert!(!serde_json::to_string(&b).unwrap().contains("overlap"));
        assert_eq!(run(10, 0.5).overlap(), 1.0);
        let names = ["x".to_string()];
        let problem = |m: &Moments| {
            super::super::subset::Scaled::new(&super::super::Problem {
                moments: m,
                names: &names,
                forced: &[],
                excluded: &[],
                intercept: true,
            })
            .unwrap()
            .n_eff
        };
        assert_eq!(problem(&a), 99.0 / 4.0);
        assert_eq!(problem(&b), 299.0);
    }

    #[test]
    fn parts_gathered_in_parallel_equal_one_pass_and_the_two_pass_formula() {
        // 100 000 rows: 64 parts; a large mean and a small spread, where shifting matters
        let n = 100_000;
        let x: Vec<f64> = (0..n * 3).map(|i| 1e5 + ((i * 7919) % 1009) as f64 * 1e-3).collect();
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.01).sin() + 3.0).collect();
        let w: Vec<f64> = (0..n).map(|i| 0.5 + (i % 3) as f64).collect();
        for weights in [None, Some(&w[..])] {
            let parallel = Moments::of_columns(&x, &y, weights);
            let mut acc = Accumulator::new(3);
            acc.push(&x, &y, weights);
            let serial = acc.finish();
            let col = |j: usize| if j < 3 { &x[j * n..(j + 1) * n] } else { &y[..] };
            let wt = |r: usize| weights.map_or(1.0, |w| w[r]);
            let total: f64 = (0..n).map(wt).sum();
            for i in 0..4 {
                let mi = (0..n).map(|r| wt(r) * col(i)[r]).sum::<f64>() / total;
                assert!((parallel.means()[i] - mi).abs() < 1e-12 * mi.abs());
                for j in 0..4 {
                    let mj = (0..n).map(|r| wt(r) * col(j)[r]).sum::<f64>() / total;
                    let c: f64 = (0..n).map(|r| wt(r) * (col(i)[r] - mi) * (col(j)[r] - mj)).sum();
                    let tol = 1e-9 * (parallel.corrected(i, i) * parallel.corrected(j, j)).sqrt();
                    assert!(
                        (parallel.corrected(i, j) - c).abs() < tol,
                        "{i}{j}: {} vs {c}",
                        parallel.corrected(i, j)
                    );
                    assert!((serial.corrected(i, j) - c).abs() < tol);
                }
            }
            assert_eq!(parallel.count(), n);
        }
    }

    /// Runs gathered with their halves: each run's statistics are `gather`'s to the bit, its
    /// halves those of its rows before and from its middle (a run of one part, of many parts
    /// with the middle inside one, and of one row).
    #[test]
    fn runs_gathered_with_their_halves_keep_the_whole_to_the_bit() {
        let runs = [1_000usize, 250_001, 1];
        let x: Vec<Vec<f64>> =
            runs.iter().map(|&n| (0..n * 2).map(|i| ((i * 7919) % 1009) as f64 * 1e-3).collect()).collect();
        let y: Vec<Vec<f64>> =
            runs.iter().map(|&n| (0..n).map(|i| (i as f64 * 0.01).sin()).collect()).collect();
        let rows_of = |k: usize, rows: Range<usize>| -> (Vec<f64>, Vec<f64>) {
            let n = runs[k];
            let cols: Vec<f64> =
                (0..2).flat_map(|j| x[k][j * n + rows.start..j * n + rows.end].to_vec()).collect();
            (cols, y[k][rows].to_vec())
        };
        let feed = |k: usize, rows: Range<usize>, acc: &mut Accumulator| {
            let (cols, ys) = rows_of(k, rows);
            acc.push(&cols, &ys, None);
            Ok::<(), ()>(())
        };
        let whole = gather(2, &runs, feed).unwrap();
        let halved = gather_halved(2, &runs, |k, rows, acc, split| {
            feed(k, rows.clone(), acc)?;
            if let Some(Split { middle, first, second }) = split {
                feed(k, rows.start..middle, first)?;
                feed(k, middle..rows.end, second)?;
            }
            Ok::<(), ()>(())
        })
        .unwrap();
        for (k, ((w, [a, b]), expected)) in halved.iter().zip(&whole).enumerate() {
            assert_eq!(w, expected, "run {k}");
            let n = runs[k];
            assert_eq!((a.count(), b.count()), (n / 2, n - n / 2));
            for (half, rows) in [(a, 0..n / 2), (b, n / 2..n)] {
                let mut acc = Accumulator::new(2);
                let (cols, ys) = rows_of(k, rows);
                acc.push(&cols, &ys, None);
                let direct = acc.finish();
                for (u, v) in half.numbers().iter().zip(direct.numbers()) {
                    assert!((u - v).abs() <= 1e-9 * u.abs().max(1.0), "run {k}: {u} vs {v}");
                }
            }
        }
    }

    #[test]
    fn a_value_that_is_not_finite_is_noticed_with_its_column() {
        let mut acc = Accumulator::new(2);
        acc.push(&[1.0, 2.0, 3.0, 4.0], &[1.0, 2.0], None);
        assert_eq!(acc.not_finite(), None);
        acc.push(&[1.0, 2.0, 3.0, f64::NAN], &[1.0, 2.0], None);
        assert_eq!(acc.not_finite(), Some(1));
        let mut acc = Accumulator::new(1);
        acc.push(&[1.0], &[f64::INFINITY], None);
        assert_eq!(acc.not_finite(), Some(1), "the target is column p");
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
