//! Exact best-subset regression by branch and bound in the manner of Furnival & Wilson's
//! "leaps and bounds" (Technometrics 16, 1974): for every model size the subset with the
//! smallest residual sum of squares, forced terms always in, then the size chosen by a named
//! criterion. A node of the search is (terms in, terms undecided); every completion's RSS is
//! at least the RSS with all undecided terms in, so a node whose bound cannot beat the best
//! of any size it could still reach is pruned. Excluding a term is one sweep of the parent's
//! matrix (the sweep is its own inverse), so a node costs O(p²). The subtrees below the
//! choices of the first three terms are searched in parallel and merged so that the result
//! is exactly the sequential search's.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use rayon::prelude::*;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::stepwise::Stepwise;
use super::subset::{sweep, Scaled};
use super::{Moments, Problem, SelectError, Selection, Selector, Step, Stop};

/// How the model size is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Criterion {
    /// Bayesian information criterion n·ln(RSS/n) + k·ln(n).
    Bic,
    /// Akaike's n·ln(RSS/n) + 2k.
    Aic,
    /// Mallows' Cp = RSS/σ̂² − n + 2k, σ̂² from the largest model searched.
    Cp,
    /// Largest adjusted R².
    AdjustedR2,
    /// Smallest leave-one-run-out prediction error (each run predicted from the others;
    /// needs two runs or more).
    LeaveOneRunOut,
}

/// Which model sizes the search proves best.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Sizes {
    /// Every size's subset is the best of its size (the table of sizes is exact).
    #[default]
    All,
    /// Only the subset the criterion chooses is proven best: a subtree none of whose sizes
    /// can beat the best criterion value found is pruned too, which is much faster where the
    /// table is not read (a fold of a choice by prediction). Other sizes' subsets are then the
    /// best found. The leave-one-run-out criterion has no such bound and searches all sizes.
    Chosen,
}

/// Settings.
///
/// | setting | default | meaning |
/// |---|---|---|
/// | `criterion` | `bic` | chooses the size |
/// | `sizes` | `all` | `chosen`: only the chosen size proven best (faster) |
/// | `max_size` | all | largest model size searched (terms, forced included) |
/// | `node_limit` | 20 000 000 | stop the search after this many nodes, with a caveat |
/// | `time_limit` | 60 s | likewise for time |
/// | `pivot_tolerance` | 1e-10 | collinear candidates are left out |
///
/// An exact fit (RSS zero to round-off) breaks log-likelihood criteria, so RSS is floored at
/// 1e-13 of the total sum of squares (the same round-off level at which STPRG stops): among
/// exact fits the smallest wins.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BestSubset {
    /// Size criterion.
    pub criterion: Criterion,
    /// Which sizes are proven best.
    pub sizes: Sizes,
    /// Largest size searched.
    pub max_size: Option<usize>,
    /// Node limit.
    pub node_limit: u64,
    /// Time limit in seconds.
    pub time_limit: f64,
    /// Pivot tolerance.
    pub pivot_tolerance: f64,
}

impl Default for BestSubset {
    fn default() -> Self {
        BestSubset {
            criterion: Criterion::Bic,
            sizes: Sizes::All,
            max_size: None,
            node_limit: 20_000_000,
            time_limit: 60.0,
            pivot_tolerance: 1e-10,
        }
    }
}

const RSS_FLOOR: f64 = 1e-13;

/// A size criterion as a function of the size k and the relative RSS: for each criterion
/// but leave-one-run-out it rises with the RSS at a given size and with the size at a given
/// RSS, so no subset of a subtree scores below its fewest terms at its bound's RSS.
struct Score {
    criterion: Criterion,
    n: f64,
    n_eff: f64,
    total: f64,
    sigma2: f64,
    intercept: bool,
    /// The smallest size scored (smaller ones are never chosen).
    smallest: usize,
}

impl Score {
    /// `criterion` on the scaled problem `sc`, Cp's σ̂² given, sizes below `smallest` unscored.
    fn new(criterion: Criterion, sc: &Scaled, sigma2: f64, smallest: usize) -> Score {
        Score {
            criterion,
            n: sc.n as f64,
            n_eff: sc.n_eff,
            total: sc.total,
            sigma2,
            intercept: sc.intercept,
            smallest,
        }
    }

    fn of(&self, k: usize, rss: f64) -> f64 {
        let n = self.n;
        let kk = k as f64 + if self.intercept { 1.0 } else { 0.0 };
        match self.criterion {
            Criterion::Bic => n * (rss * self.total / n).ln() + kk * n.ln(),
            Criterion::Aic => n * (rss * self.total / n).ln() + 2.0 * kk,
            Criterion::Cp => rss / self.sigma2 - self.n_eff + 2.0 * kk,
            Criterion::AdjustedR2 => -(1.0 - rss * self.n_eff / (self.n_eff - k as f64).max(1e-300)),
            Criterion::LeaveOneRunOut => f64::NEG_INFINITY,
        }
    }

    /// The relative RSS at which size k scores `value` ([`Score::of`] solved for the RSS): a
    /// subset of size k with a larger RSS scores above it. Compared with instead of the score
    /// itself, it spares the search a logarithm per node.
    fn limit(&self, k: usize, value: f64) -> f64 {
        let n = self.n;
        let kk = k as f64 + if self.intercept { 1.0 } else { 0.0 };
        match self.criterion {
            Criterion::Bic => n / self.total * ((value - kk * n.ln()) / n).exp(),
            Criterion::Aic => n / self.total * ((value - 2.0 * kk) / n).exp(),
            Criterion::Cp => self.sigma2 * (value + self.n_eff - 2.0 * kk),
            Criterion::AdjustedR2 => (value + 1.0) * (self.n_eff - k as f64) / self.n_eff,
            Criterion::LeaveOneRunOut => f64::INFINITY,
        }
    }
}

/// With [`Sizes::Chosen`]: the criterion, the lowest value a region has found, and per size
/// the RSS above which that size scores higher.
struct Bound<'a> {
    score: &'a Score,
    lowest: f64,
    limits: Vec<f64>,
}

impl<'a> Bound<'a> {
    fn new(score: &'a Score, lowest: f64, kmax: usize) -> Self {
        let mut bound = Bound { score, lowest: f64::INFINITY, limits: vec![f64::INFINITY; kmax + 1] };
        bound.lower(lowest);
        bound
    }

    /// A subset scored `value`: where it is the lowest yet, the limits tighten.
    fn lower(&mut self, value: f64) {
        if value < self.lowest {
            self.lowest = value;
            for (k, l) in self.limits.iter_mut().enumerate() {
                *l = self.score.limit(k, value);
            }
        }
    }

    /// No size from `lo` up can score below the lowest with RSS ≥ `rss` (the score rises with
    /// the size; a tie is still searched).
    fn beaten(&self, lo: usize, rss: f64) -> bool {
        self.limits.get(lo.max(self.score.smallest)).is_none_or(|&l| rss > l)
    }
}

/// Per model size, the smallest relative RSS found and its set (sorted).
type Best = Vec<(f64, Vec<usize>)>;

/// Keeps the set made of `parts` if it is the best of its size (at most `kmax`) so far; the
/// size if kept. The set is only assembled then: most candidates do not improve on anything.
fn keep_if_better(best: &mut Best, kmax: usize, rss: f64, parts: &[&[usize]]) -> Option<usize> {
    let k = parts.iter().map(|p| p.len()).sum::<usize>();
    if k > kmax || rss >= best[k].0 {
        return None;
    }
    let mut set: Vec<usize> = parts.concat();
    set.sort_unstable();
    best[k] = (rss, set);
    Some(k)
}

/// One search over a region of the tree (the whole tree, or the subtree below a fixed choice
/// of the first terms, searched beside the others).
struct Search<'a> {
    sc: &'a Scaled,
    kmax: usize,
    best: Best,
    /// Nodes visited here and not yet added to `limits`.
    nodes: u64,
    limits: &'a Limits,
    stopped: bool,
    /// One matrix per depth of the tree, reused: a node's exclude branch sweeps into it.
    stack: Vec<Vec<f64>>,
    /// With [`Sizes::Chosen`], the criterion's bound from what this region has found.
    bound: Option<Bound<'a>>,
}

/// What the regions searched in parallel share: the limits, and per size the smallest RSS
/// any region has found (f64 bits; for non-negative floats their order is the integers').
struct Limits {
    found: Vec<AtomicU64>,
    nodes: AtomicU64,
    node_limit: u64,
    deadline: Instant,
    stopped: AtomicBool,
    /// With [`Sizes::Chosen`], the lowest criterion value any region has found ([`ordered`]).
    lowest: AtomicU64,
}

/// A float's bits as an integer that orders as the float does (negative ones included), for
/// an atomic minimum.
fn ordered(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | 1 << 63
    }
}

/// The inverse of [`ordered`].
fn from_ordered(o: u64) -> f64 {
    f64::from_bits(if o >> 63 == 1 { o & !(1 << 63) } else { !o })
}

/// Nodes a region visits between looks at the shared limits.
const CHECK_EVERY: u64 = 4096;

/// `b` = `a` swept on pivot `u`, but only the entries among `rest` and the target `t`: all
/// that the subtree below reads (its pivots come from `rest`, its RSS is the target's
/// diagonal). A node then costs (|rest| + 1)² instead of m², and nothing is allocated.
fn sweep_out(a: &[f64], b: &mut [f64], m: usize, u: usize, rest: &[usize], t: usize) {
    let d = a[u * m + u];
    let row_u = &a[u * m..(u + 1) * m];
    // row by row, the target's entry after the loop over `rest` (a chained iterator in the
    // inner loop had cost a tenth of the search)
    let mut row = |i: usize| {
        let f = a[i * m + u] / d;
        let (ai, bi) = (&a[i * m..(i + 1) * m], &mut b[i * m..(i + 1) * m]);
        for &j in rest {
            bi[j] = ai[j] - f * row_u[j];
        }
        bi[t] = ai[t] - f * row_u[t];
    };
    for &i in rest {
        row(i);
    }
    row(t);
}

impl Search<'_> {
    /// Keeps the set made of `parts` if it is this region's best of its size so far, and
    /// tells the other regions its RSS.
    fn record(&mut self, rss: f64, parts: &[&[usize]]) {
        if let Some(k) = keep_if_better(&mut self.best, self.kmax, rss, parts) {
            self.limits.found[k].fetch_min(rss.to_bits(), Ordering::Relaxed);
            if let Some(bound) = &mut self.bound {
                if k >= bound.score.smallest {
                    let value = bound.score.of(k, rss);
                    bound.lower(value);
                    self.limits.lowest.fetch_min(ordered(value), Ordering::Relaxed);
                }
            }
        }
    }

    /// Adds the nodes visited to the shared count and stops when a limit is reached (here or
    /// in another region).
    fn report(&mut self) {
        let total = self.limits.nodes.fetch_add(self.nodes, Ordering::Relaxed) + self.nodes;
        self.nodes = 0;
        if total >= self.limits.node_limit || Instant::now() > self.limits.deadline {
            self.limits.stopped.store(true, Ordering::Relaxed);
        }
        // the lowest criterion value any region has found bounds this one too: only the
        // chosen size is proven, so which region prunes what first changes nothing reported
        if let Some(bound) = &mut self.bound {
            bound.lower(from_ordered(self.limits.lowest.load(Ordering::Relaxed)));
        }
        self.stopped = self.limits.stopped.load(Ordering::Relaxed);
    }

    /// No size in `lo..=hi` (capped at the largest searched) can improve with RSS ≥ `rss`
    /// on this region's best, or with RSS > another region's: a tie with another region is
    /// still searched, so that the merge can keep the one a single search would have met
    /// first whatever the timing.
    /// With [`Sizes::Chosen`], also none of those sizes can score below the lowest criterion
    /// value found (a tie is still searched).
    fn hopeless(&self, lo: usize, hi: usize, rss: f64) -> bool {
        let hi = hi.min(self.kmax);
        lo > hi
            || self.bound.as_ref().is_some_and(|b| b.beaten(lo, rss))
            || (lo..=hi).all(|k| {
                rss >= self.best[k].0 || rss > f64::from_bits(self.limits.found[k].load(Ordering::Relaxed))
            })
    }

    /// `a` is swept on `inn ∪ undecided`.
    fn visit(&mut self, a: &[f64], inn: &mut Vec<usize>, undecided: &[usize]) {
        self.nodes += 1;
        if self.nodes == CHECK_EVERY {
            self.report();
        }
        if self.stopped {
            return;
        }
        let rss = self.sc.residual_share(a).max(RSS_FLOOR);
        self.record(rss, &[inn, undecided]);
        if undecided.is_empty() {
            return;
        }
        // every subset between inn and inn ∪ undecided has RSS ≥ rss
        let lo = inn.len();
        if self.hopeless(lo, lo + undecided.len() - 1, rss) {
            return;
        }
        let (u, rest) = (undecided[0], &undecided[1..]);
        // exclude u: the RSS rises by b_u²/c_uu (coefficient and inverse diagonal, both in
        // the swept matrix), so a hopeless subtree is known before its sweep is paid for
        let (m, t) = (self.sc.m, self.sc.p);
        let child = (rss + a[u * m + t].powi(2) / a[u * m + u]).max(RSS_FLOOR);
        if !self.hopeless(lo, lo + rest.len(), child) {
            // one sweep takes u out (into this depth's buffer)
            let depth = rest.len();
            let mut b = std::mem::take(&mut self.stack[depth]);
            sweep_out(a, &mut b, m, u, rest, t);
            self.visit(&b, inn, rest);
            self.stack[depth] = b;
        }
        // include u: same fitted set as this node, u decided in
        inn.push(u);
        self.visit(a, inn, rest);
        inn.pop();
    }
}

/// The roots of the subtrees below every choice (out, then in: the order one search visits
/// them) of the first `depth` undecided terms: (matrix swept on inn ∪ undecided, inn,
/// undecided). Depth 0 is the whole tree.
fn regions(
    sc: &Scaled,
    a: &[f64],
    inn: &[usize],
    undecided: &[usize],
    depth: usize,
) -> Vec<(Vec<f64>, Vec<usize>, Vec<usize>)> {
    if depth == 0 || undecided.is_empty() {
        return vec![(a.to_vec(), inn.to_vec(), undecided.to_vec())];
    }
    let (u, rest) = (undecided[0], &undecided[1..]);
    let (m, t) = (sc.m, sc.p);
    let mut out_of = vec![0.0; m * m];
    sweep_out(a, &mut out_of, m, u, rest, t);
    let mut all = regions(sc, &out_of, inn, rest, depth - 1);
    let mut with_u = inn.to_vec();
    with_u.push(u);
    all.extend(regions(sc, a, &with_u, rest, depth - 1));
    all
}

impl Selector for BestSubset {
    fn name(&self) -> &'static str {
        "best-subset"
    }

    fn select(&self, pb: &Problem<'_>) -> Result<Selection, SelectError> {
        self.search(pb, &[])
    }

    fn select_with_folds(&self, pb: &Problem<'_>, folds: &[Moments]) -> Result<Selection, SelectError> {
        self.search(pb, folds)
    }
}

impl BestSubset {
    /// Checks the settings: positive node and time limits.
    pub fn validate(&self) -> Result<(), SelectError> {
        if self.node_limit == 0 || self.time_limit.is_nan() || self.time_limit <= 0.0 {
            return Err(SelectError::Config("best-subset node_limit and time_limit must be positive".into()));
        }
        Ok(())
    }

    fn search(&self, pb: &Problem<'_>, folds: &[Moments]) -> Result<Selection, SelectError> {
        self.validate()?;
        let sc = Scaled::new(pb)?;
        let m = sc.m;
        let mut notes = Vec::new();
        // candidates: forced first; the others that are not collinear with everything else
        let mut free: Vec<usize> =
            (0..sc.p).filter(|j| !pb.forced.contains(j) && !pb.excluded.contains(j)).collect();
        let forced: Vec<usize> = pb.forced.to_vec();
        let mut a = sc.swept(&forced, self.pivot_tolerance).map_err(|j| SelectError::ForcedCollinear {
            term: pb.names[j].clone(),
            pivot: f64::NAN,
            tolerance: self.pivot_tolerance,
        })?;
        // order: most important last, so excluding it (the first branch) comes deep in the tree
        // and strong small models are found early; refuse terms collinear with the rest
        let mut kept = Vec::new();
        free.sort_by(|&x, &y| {
            let r = |j: usize| a[j * m + sc.p].powi(2) / a[j * m + j].max(1e-300);
            r(x).total_cmp(&r(y))
        });
        for j in free.drain(..) {
            let pivot = a[j * m + j];
            if pivot.is_nan() || pivot <= self.pivot_tolerance {
                // the terms in the combination: after the sweeps, the swept rows of column j
                // hold its regression on them (correlation scale); those not involved are ~0
                let before: Vec<String> = forced
                    .iter()
                    .chain(&kept)
                    .filter(|&&i| a[i * m + j].abs() > 1e-6)
                    .map(|&i| format!("`{}`", pb.names[i]))
                    .collect();
                let with = match before.len() {
                    0 => "it does not vary".to_string(),
                    1..=4 => format!("collinear with {}", before.join(", ")),
                    n => format!("collinear with {} and {} more terms", before[..3].join(", "), n - 3),
                };
                notes.push(format!(
                    "`{}` left out of the search: {with} (pivot {pivot:.2e}); the search uses the others",
                    pb.names[j]
                ));
                continue;
            }
            sweep(&mut a, m, j);
            kept.push(j);
        }
        let max_rows = (sc.n_eff as usize).saturating_sub(1);
        let kmax = self.max_size.unwrap_or(usize::MAX).min(forced.len() + kept.len()).min(max_rows);
        if kmax < forced.len() {
            return Err(SelectError::TooFewRows { rows: sc.n, terms: forced.len(), intercept: pb.intercept });
        }
        // first bounds: the forward stepwise path
        let mut best = vec![(f64::INFINITY, vec![]); kmax + 1];
        if let Ok(path) = (Stepwise { step_rule: super::StepRule::Last, ..Stepwise::default() }).select(pb) {
            // only sets the search itself could reach: not one with a term it left out
            let allowed = |j: &usize| forced.contains(j) || kept.contains(j);
            for st in path.steps.iter().filter(|st| st.set.iter().all(allowed)) {
                keep_if_better(&mut best, kmax, (1.0 - st.r2).max(RSS_FLOOR), &[&st.set]);
            }
        }
        let all = forced.len() + kept.len();
        let smallest = forced.len().max(1);
        // the pruning criterion: Cp's σ̂² is the full model's, known before the search only
        // when the full model is among the sizes searched
        let bound = (self.sizes == Sizes::Chosen
            && self.criterion != Criterion::LeaveOneRunOut
            && (self.criterion != Criterion::Cp || kmax == all))
            .then(|| {
                let sigma2 = sc.residual_share(&a).max(RSS_FLOOR) / (sc.n_eff - kmax as f64).max(1.0);
                Score::new(self.criterion, &sc, sigma2, smallest)
            });
        let lowest = bound.as_ref().map(|score| {
            best.iter()
                .enumerate()
                .filter(|(k, b)| *k >= score.smallest && b.0.is_finite())
                .map(|(k, b)| score.of(k, b.0))
                .fold(f64::INFINITY, f64::min)
        });
        let limits = Limits {
            found: best.iter().map(|b| AtomicU64::new(b.0.to_bits())).collect(),
            nodes: AtomicU64::new(0),
            node_limit: self.node_limit,
            deadline: Instant::now() + std::time::Duration::from_secs_f64(self.time_limit.max(0.0)),
            stopped: AtomicBool::new(false),
            lowest: AtomicU64::new(ordered(lowest.unwrap_or(f64::INFINITY))),
        };
        // the subtrees below each choice of the first three terms are searched in parallel,
        // each pruning on its own best sets and, strictly, on the others' (`hopeless`); merged
        // in the order one search would have met them (an earlier region keeps a tie), the
        // result is the sequential search's
        let split = if kept.len() > 10 { 3 } else { 0 };
        let regions = regions(&sc, &a, &forced, &kept, split);
        let found: Vec<(Best, bool)> = regions
            .par_iter()
            .map(|(a, inn, undecided)| {
                let mut search = Search {
                    sc: &sc,
                    kmax,
                    best: best.clone(),
                    nodes: 0,
                    limits: &limits,
                    stopped: false,
                    stack: vec![vec![0.0; m * m]; undecided.len() + 1],
                    bound: bound.as_ref().zip(lowest).map(|(score, lowest)| Bound::new(score, lowest, kmax)),
                };
                let mut inn = inn.clone();
                search.visit(a, &mut inn, undecided);
                search.report();
                (search.best, search.stopped)
            })
            .collect();
        let mut stopped = false;
        for (region, s) in found {
            stopped |= s;
            for (b, r) in best.iter_mut().zip(region) {
                if r.0 < b.0 {
                    *b = r;
                }
            }
        }
        let nodes = limits.nodes.load(Ordering::Relaxed);
        if stopped {
            notes.push(format!(
                "search stopped at its limit after {nodes} nodes: the subsets reported are the best found, not proven best"
            ));
        } else if bound.is_some() {
            notes.push(format!(
                "exact for the size chosen: {nodes} nodes searched; the other sizes' subsets are the best found before the criterion ruled them out (sizes = \"all\" proves each)"
            ));
        } else {
            notes.push(format!("exact: {nodes} nodes searched"));
        }
        // one step per size, chosen by the criterion
        let full_rss = best.iter().rev().find(|b| b.0.is_finite()).map_or(1.0, |b| b.0);
        let sigma2 = full_rss / (sc.n_eff - kmax as f64).max(1.0);
        let scoring = Score::new(self.criterion, &sc, sigma2, smallest);
        let mut steps = Vec::new();
        let mut scores = Vec::new();
        let validation = match self.criterion {
            Criterion::LeaveOneRunOut => Some(super::CrossValidation::new(pb, folds)?),
            _ => None,
        };
        for (k, (rss, set)) in best.iter().enumerate() {
            if !rss.is_finite() || set.len() != k || k < forced.len().max(1) {
                continue;
            }
            let Ok(sw) = sc.swept(set, 0.0) else { continue };
            let newest = set
                .iter()
                .copied()
                .find(|j| !steps.last().is_some_and(|s: &Step| s.set.contains(j)))
                .unwrap_or(0);
            let mut st = sc.step(&sw, set, pb.names, newest, false, forced.contains(&newest));
            st.step = k;
            let score = match self.criterion {
                Criterion::LeaveOneRunOut => validation.as_ref().map_or(f64::INFINITY, |cv| cv.error(set)),
                _ => scoring.of(k, *rss),
            };
            scores.push(score);
            steps.push(st);
        }
        let chosen = scores
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1).then(a.0.cmp(&b.0)))
            .map_or(0, |(i, _)| i + 1);
        for (i, st) in steps.iter_mut().enumerate() {
            st.step = i + 1;
        }
        let stop = if stopped { Stop::Limit { nodes } } else { Stop::AllEntered };
        Ok(Selection::from_steps(self.name(), sc.n, pb.names, steps, chosen, stop, notes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shared minimum of criterion values (of either sign) orders as the floats do.
    #[test]
    fn ordered_floats_order_as_floats() {
        let xs = [f64::NEG_INFINITY, -1e300, -2.5, -1e-300, -0.0, 0.0, 1e-300, 3.0, 1e300, f64::INFINITY];
        for w in xs.windows(2) {
            assert!(ordered(w[0]) <= ordered(w[1]), "{} {}", w[0], w[1]);
        }
        for x in xs {
            assert_eq!(from_ordered(ordered(x)).to_bits(), x.to_bits());
        }
    }
}
