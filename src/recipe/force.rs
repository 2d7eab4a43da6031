//! A state moved by a random force (process noise: an unmeasured white force, as in
//! Langevin's equation), told from a sensor's noise by a witness: another state whose equation
//! integrates it. A sensor's noise in the forced state is not in the witness's record, so the
//! witness's changes miss its integral by that noise, more the longer the stretch; a random
//! force's roughness is motion, which the witness's record holds, and its misses grow at a
//! quarter of that rate or less. Rates estimated on both sides of a sample take in the force
//! they explain (the damping of an oscillator under a random force came back halved by central
//! differences, left out by the weak form): such a system is identified by Itô's steps ([`crate::data::Ito`]).

use super::{noise, retrace, Recipe};
use crate::data::{Frame, NoiseTally};
use crate::identify::noise::tallies;
use crate::model::Model;
use crate::sim::System;

/// A state found moved by a random force.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Forced {
    /// The state.
    pub state: String,
    /// The state whose equation integrates it.
    pub witness: String,
    /// How fast the witness's misses of its equation's integral grow with the stretch, over
    /// what a sensor's noise of `state` as read would make them grow.
    pub ratio: f64,
    /// The state's roughness (its white noise as read), a share of its spread.
    pub share: f64,
}

/// The stretches, in samples, the witness's misses are read over.
const LADDER: [usize; 6] = [1, 2, 4, 8, 16, 32];

/// A roughness below this share of a state's spread is none to ask about.
const ROUGH: f64 = 1e-3;

/// Below this share of what a sensor's noise would make them grow, the witness's misses say
/// motion: a random force's roughness (a Brownian path, read over one or two samples) makes
/// them grow at 0.15-0.3 of it, a sensor's white noise at 1, a filtered sensor's noise faster.
const MOTION: f64 = 0.5;

/// The share of the witness's misses over one sample that a sensor's noise of the forced state
/// must add over the longest stretch for the witness to tell it.
const SEEN: f64 = 0.1;

/// Rows a run needs to be read: four stretches of the longest rung in each quarter.
const ROWS: usize = 16 * 32;

/// How much more a Brownian path's fourth differences spread over twice the stride, at
/// least, of 2: a random force's roughness is one, a sensor's noise (white, 1) or a rate
/// differenced from a noisy record (a ship's u and v from its track: 3 from one sample to
/// two, then 0.56) is not.
const BROWNIAN: f64 = 1.5;

/// How much more they spread over twice the stride, at most: the motion's fourth differences,
/// where it shows through the noise, grow up to 2⁸ times (cascaded tanks read each second
/// under a held input, a slower sensor's readings joined by cubics).
const FASTEST: f64 = 3.0;

/// Whether the roughness of column `name` over `runs` is a Brownian path's: its fourth
/// differences' squared median grows by [`BROWNIAN`] to [`FASTEST`] with each doubling of the
/// stride from one sample to eight, as a path of independent steps' does (a stationary
/// noise's stops growing within its correlation; the motion's grows faster: a heater's
/// temperature read every 2 s with 0.45 % noise grew 1.6, 1.9, then 7.2 times).
fn brownian(runs: &[Frame], name: &str) -> bool {
    // each stride's reading, its square pooled over the runs by their rows
    let reading = |stride: usize| {
        let (sum, rows) = runs
            .iter()
            .filter_map(|f| f.column(name))
            .filter_map(|x| Some((crate::data::fourth_differences_over(x, stride)?, x.len() as f64)))
            .fold((0.0, 0.0), |(s, n), (sd, rows)| (s + sd * sd * rows, n + rows));
        (rows > 0.0).then(|| sum / rows)
    };
    let readings: Option<Vec<f64>> = [1, 2, 4, 8].into_iter().map(reading).collect();
    readings.is_some_and(|r| r.windows(2).all(|w| w[1] >= BROWNIAN * w[0] && w[1] <= FASTEST * w[0]))
}

/// The share of its spread that the roughness of column `name` over `runs` (`tally`) is, where
/// it is measured at least [`ROUGH`] and grows as a Brownian path's ([`brownian`]).
fn brownian_share(runs: &[Frame], name: &str, tally: &NoiseTally) -> Option<f64> {
    let (share, measured) = tally.share()?;
    (measured && share >= ROUGH && brownian(runs, name)).then_some(share)
}

/// One witness `a` of one state `b`, summed over the runs: the witness's misses over each
/// stretch of [`LADDER`] in each quarter of the runs (Σ e, Σ e², count), and Σ over rows of
/// what the noise of `b` and of every other column the witness's equation reads would make
/// them grow by per sample.
#[derive(Clone, Debug, Default)]
struct Misses {
    quarters: [[(f64, f64, f64); LADDER.len()]; 4],
    own: f64,
    others: f64,
    rows: f64,
}

impl Misses {
    /// Every quarter of the runs.
    const ALL: [usize; 4] = [0, 1, 2, 3];

    /// The variance of the misses over the `l`th stretch of [`LADDER`], `quarters` pooled.
    fn variance(&self, l: usize, quarters: &[usize]) -> f64 {
        let (s, s2, n) = quarters.iter().fold((0.0, 0.0, 0.0), |(a, b, c), &q| {
            let (s, s2, n) = self.quarters[q][l];
            (a + s, b + s2, c + n)
        });
        s2 / n - (s / n) * (s / n)
    }

    /// The growth of the misses' variance per sample of stretch, `quarters` pooled (a line
    /// through the variances over the stretches of [`LADDER`]).
    fn growth(&self, quarters: &[usize]) -> Option<f64> {
        let n = LADDER.len() as f64;
        let variance: Vec<(f64, f64)> = LADDER
            .iter()
            .enumerate()
            .map(|(l, &length)| (length as f64, self.variance(l, quarters)))
            .collect();
        let (ml, mv) = variance.iter().fold((0.0, 0.0), |(a, b), (l, v)| (a + l / n, b + v / n));
        let (sxy, sxx) = variance
            .iter()
            .fold((0.0, 0.0), |(a, b), (l, v)| (a + (l - ml) * (v - mv), b + (l - ml) * (l - ml)));
        let slope = sxy / sxx;
        slope.is_finite().then_some(slope)
    }
}

/// The states of `model` whose roughness over `runs` is measured at least [`ROUGH`] of its
/// spread and grows as a Brownian path's ([`brownian`]), with that share: those a random force
/// may move.
pub(super) fn rough_states(model: &Model, runs: &[Frame]) -> Vec<(String, f64)> {
    // (a rate estimated by a smoother is smooth: it cannot show the force)
    let estimated = model.estimated_states();
    let states: Vec<String> = model
        .spec()
        .states
        .iter()
        .map(|s| s.name.clone())
        .filter(|s| !estimated.contains(&s.as_str()))
        .collect();
    tallies(&states, runs)
        .into_iter()
        .filter_map(|(state, tally)| {
            let share = brownian_share(runs, &state, &tally)?;
            Some((state, share))
        })
        .collect()
}

/// The states of the identified `model` that `runs` show moved by a random force: each of the
/// `rough` ones ([`rough_states`]) where another state's equation, which reads it, integrates it more closely
/// than that roughness in its sensor would allow (the witness's misses growing at under
/// [`MOTION`] of that, by two standard errors, where that noise would be most of their growth
/// and show beside the witness's own, [`SEEN`]). Runs of fewer than [`ROWS`] rows, or without
/// every column the equations read, are not read.
pub(super) fn forced_states(model: &Model, runs: &[Frame], rough: &[(String, f64)]) -> Vec<Forced> {
    let Ok(system) = System::new(model, &Default::default(), false) else {
        return Vec::new();
    };
    let states = system.states.clone();
    let columns: Vec<String> = states.iter().chain(&system.inputs).cloned().collect();
    let tallies: Vec<NoiseTally> = tallies(&columns, runs).into_iter().map(|(_, t)| t).collect();
    let rough: Vec<(usize, f64)> = rough
        .iter()
        .filter_map(|(state, share)| Some((states.iter().position(|s| s == state)?, *share)))
        .collect();
    if rough.is_empty() {
        return Vec::new();
    }
    // (witness, state) pairs, each summed over the runs
    let mut misses = vec![vec![Misses::default(); states.len()]; states.len()];
    for frame in runs.iter().filter(|f| f.len() >= ROWS) {
        let Some(read) = columns.iter().map(|c| frame.column(c)).collect::<Option<Vec<&[f64]>>>() else {
            continue;
        };
        let (state_columns, input_columns) = read.split_at(states.len());
        let rates = system.derivatives_on_columns(state_columns, input_columns);
        let t = frame.time();
        let n = frame.len();
        let steps: Vec<f64> = t.windows(2).map(|w| (w[1] - w[0]) * (w[1] - w[0])).collect();
        let step2 = steps.iter().sum::<f64>() / steps.len() as f64;
        // each column's noise in this run, and how each rate moves with the column
        let sd: Vec<f64> = columns
            .iter()
            .map(|c| NoiseTally::of(frame, c, 0..n).and_then(|t| t.sd()).unwrap_or(0.0))
            .collect();
        let sensitivity = |s: usize| -> Vec<Vec<f64>> {
            let noise = tallies[s].sd().unwrap_or(0.0).max(sd[s]).max(1e-12);
            let nudged = |by: f64| {
                let moved: Vec<f64> = read[s].iter().map(|v| v + by).collect();
                let mut all: Vec<&[f64]> = read.clone();
                all[s] = &moved;
                let (st, inp) = all.split_at(states.len());
                system.derivatives_on_columns(st, inp)
            };
            let delta = 1e-3 * noise;
            let (up, down) = (nudged(delta), nudged(-delta));
            up.iter()
                .zip(&down)
                .map(|(u, d)| u.iter().zip(d).map(|(u, d)| (u - d) / (2.0 * delta)).collect())
                .collect()
        };
        let gains: Vec<Vec<f64>> = (0..columns.len())
            .map(|s| sensitivity(s).iter().map(|c| c.iter().map(|c| c * c).sum::<f64>() / n as f64).collect())
            .collect();
        for a in 0..states.len() {
            // the witness's integral of its own equation (trapezoid)
            let mut integral = vec![0.0; n];
            for k in 1..n {
                integral[k] = integral[k - 1] + 0.5 * (t[k] - t[k - 1]) * (rates[a][k] + rates[a][k - 1]);
            }
            let x = state_columns[a];
            for &(b, _) in rough.iter().filter(|(b, _)| *b != a && gains[*b][a] > 0.0) {
                let m = &mut misses[a][b];
                for (l, &length) in LADDER.iter().enumerate() {
                    let span = n - length;
                    for k in 0..span {
                        let e = x[k + length] - x[k] - (integral[k + length] - integral[k]);
                        let q = &mut m.quarters[4 * k / span][l];
                        *q = (q.0 + e, q.1 + e * e, q.2 + 1.0);
                    }
                }
                let others: f64 =
                    (0..columns.len()).filter(|&s| s != b).map(|s| gains[s][a] * sd[s] * sd[s]).sum();
                m.own += n as f64 * step2 * gains[b][a] * sd[b] * sd[b];
                m.others += n as f64 * step2 * others;
                m.rows += n as f64;
            }
        }
    }
    let mut forced: Vec<Forced> = Vec::new();
    for &(b, share) in &rough {
        let witnessed = (0..states.len()).filter_map(|a| {
            let m = &misses[a][b];
            let (own, others) = (m.own / m.rows, m.others / m.rows);
            let growth = m.growth(&Misses::ALL)?;
            let quarters: Vec<f64> = (0..4).filter_map(|q| m.growth(&[q])).collect();
            let mean = quarters.iter().sum::<f64>() / quarters.len() as f64;
            let error = (quarters.iter().map(|g| (g - mean) * (g - mean)).sum::<f64>()
                / (quarters.len() as f64 - 1.0))
                .sqrt()
                / (quarters.len() as f64).sqrt();
            // the forced state's noise would be most of what the witness's misses grow by (a
            // witness that reads noisier columns more strongly tells nothing of it: the noise
            // of Chen's y and x, read to a few per cent, is 30 times what z's would add)
            // and would show over the longest stretch beside the witness's own noise (1 % on
            // a position beside its velocity read every 0.02 s: 3 % of it, which four
            // quarters' slopes do not tell from none)
            let longest = *LADDER.last().unwrap_or(&1) as f64;
            let told = own > 0.0
                && own >= others
                && longest * own >= SEEN * m.variance(0, &Misses::ALL)
                && quarters.len() == 4
                && growth + 2.0 * error < others + MOTION * own;
            told.then(|| (a, (growth - others) / own))
        });
        if let Some((a, ratio)) = witnessed.min_by(|x, y| x.1.total_cmp(&y.1)) {
            forced.push(Forced { state: states[b].clone(), witness: states[a].clone(), ratio, share });
        }
    }
    forced
}

/// The forced states, in words, for a note: how each was told.
pub(super) fn described(forced: &[Forced]) -> String {
    forced
        .iter()
        .map(|f| {
            format!(
                "`{s}`'s roughness ({:.2} % of its spread) is in `{w}`'s record too, whose changes miss its equation's integral {:.2} times as fast as a sensor's noise in `{s}` of that size would make them: motion, not a sensor's noise",
                100.0 * f.share,
                f.ratio.max(0.0),
                s = f.state,
                w = f.witness,
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The checks a random force fails whatever the terms: the re-simulations, which no equation
/// without the force follows for long, and the noise, which reads the force's roughness.
const FAILED_BY_FORCE: [&str; 3] = [retrace::MISSED_NAME, retrace::CLOSE_NAME, noise::NAME];

/// `recipe`, identified by Itô's steps where the records show `forced` states, with its kept
/// start's notes and flagged checks saying so.
pub(super) fn said(mut recipe: Recipe, forced: &[Forced], first: &str) -> Recipe {
    let states: Vec<String> = forced.iter().map(|f| format!("`{}`", f.state)).collect();
    let note = format!(
        "a random force moves {} (process noise, an unmeasured force): {}. Rates estimated over both sides of a sample ({first}) take in the force they explain, which biases the terms of the state it moves (a damping halved): identified by Itô's steps instead (--derivative ito: each interval's change against the candidates over it, the candidates as the intervals before predict them); --no-random-force keeps {first}",
        states.join(", "),
        described(forced)
    );
    let cause = format!(
        "; a random force moves {}: no equation without it follows such a record for long, and its roughness reads as noise, so this flag does not tell the terms wrong",
        states.join(", ")
    );
    recipe.say(note);
    let at = recipe.kept;
    let start = &mut recipe.starts[at];
    // the model file says it too: simulated, it follows such a record in the mean only
    let written = format!(
        "a random force (process noise) moves {}: identified by Itô's steps (--derivative ito); simulated without the force, the equations follow such a record in the mean only",
        states.join(", ")
    );
    if let Ok(noted) = start.model.edit(|file| file.model.notes.push(written)) {
        start.model = noted;
    }
    for check in start.checks.iter_mut().filter(|c| !c.passed && FAILED_BY_FORCE.contains(&c.name.as_str())) {
        check.detail.push_str(&cause);
    }
    recipe
}

/// `recipe`, whose records show no state moved by a random force ([`forced_states`]), with a
/// note on each of its `rough` states ([`rough_states`]), whose roughness nonetheless grows as
/// a Brownian path's (a state no other one integrates, as a first-order system's): a filtered
/// sensor's noise or a random force, which the records cannot tell apart, and the method the
/// force needs.
pub(super) fn untold(mut recipe: Recipe, rough: &[(String, f64)]) -> Recipe {
    if rough.is_empty() {
        return recipe;
    }
    let rough: Vec<String> = rough
        .iter()
        .map(|(state, share)| format!("`{state}` ({:.2} % of its spread)", 100.0 * share))
        .collect();
    let note = format!(
        "the roughness of {} grows as a Brownian path's (its fourth differences spread twice as much over twice the stride): a filtered sensor's noise, or a random force (process noise), whose terms rates estimated over both sides of a sample bias (an Ornstein-Uhlenbeck process's decay came back 24 % short, with two spurious terms); no other state's record holds it to tell which. Where a random force moves it, --derivative ito identifies the terms unbiased",
        rough.join(", ")
    );
    recipe.say(note);
    recipe
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Differentiator;
    use crate::uncertainty::Normal;

    /// An oscillator ẍ = −4x − 0.4ẋ + w, sampled every 0.02 s for `seconds` (Euler-Maruyama
    /// at 0.001 s), as a run of columns t, x, v; `force` the random force's intensity and
    /// `sensor` a white noise added to each column (a share of its spread).
    fn forced_oscillator(force: f64, sensor: f64, seconds: f64, seed: u64) -> Frame {
        let mut normal = Normal::new(seed);
        let (h, every) = (0.001, 20);
        let (mut x, mut v) = (1.0, 0.0);
        let (mut t, mut xs, mut vs) = (Vec::new(), Vec::new(), Vec::new());
        let steps = (seconds / h).round() as usize;
        for k in 0..steps {
            if k % every == 0 {
                t.push(k as f64 * h);
                xs.push(x);
                vs.push(v);
            }
            let a = -4.0 * x - 0.4 * v;
            x += h * v;
            v += h * a + force * h.sqrt() * normal.sample();
        }
        let mut frame = Frame::new("oscillator.csv", "t", t).unwrap();
        for (name, column) in [("x", xs), ("v", vs)] {
            let m = column.iter().sum::<f64>() / column.len() as f64;
            let spread = (column.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / column.len() as f64).sqrt();
            frame.push(name, column.iter().map(|v| v + sensor * spread * normal.sample()).collect()).unwrap();
        }
        frame
    }

    /// The states `runs` show moved by a random force, as the recipe reads them.
    fn told(model: &Model, runs: &[Frame]) -> Vec<Forced> {
        forced_states(model, runs, &rough_states(model, runs))
    }

    /// The oscillator's model with its true equations.
    fn oscillator() -> Model {
        Model::parse(
            "[model]\nname = \"oscillator\"\nintercept = false\n[[states]]\nname = \"x\"\n[[states]]\nname = \"v\"\n\
             [equations.x_dot]\nstate = \"x\"\ncandidates = [\"v\"]\ncoefficients = { \"v\" = 1.0 }\n\
             [equations.v_dot]\nstate = \"v\"\ncandidates = [\"x\", \"v\"]\ncoefficients = { \"x\" = -4.0, \"v\" = -0.4 }\n",
            "oscillator.toml",
        )
        .unwrap()
    }

    /// A random force on v is found, with x its witness, also under a sensor's noise of 1 %;
    /// a sensor's noise alone is not (at 1 % on both, x's own noise hides what v's would add
    /// to x's misses: not told either way, as at 5 %), nor a velocity differenced from the
    /// position's record, which the position's record holds too.
    #[test]
    fn a_random_force_is_told_from_a_sensor_s_noise() {
        let model = oscillator();
        let forced = told(&model, &[forced_oscillator(0.3, 0.0, 100.0, 1)]);
        assert_eq!(forced.len(), 1, "{forced:?}");
        assert_eq!((forced[0].state.as_str(), forced[0].witness.as_str()), ("v", "x"));
        assert!(forced[0].ratio < 0.4, "{forced:?}");
        // with a sensor's noise of 1 % on top, still the force
        let forced = told(&model, &[forced_oscillator(0.3, 0.01, 100.0, 2)]);
        assert_eq!(forced.iter().map(|f| f.state.as_str()).collect::<Vec<_>>(), ["v"], "{forced:?}");
        for sensor in [0.01, 0.05] {
            let forced = told(&model, &[forced_oscillator(0.0, sensor, 100.0, 3)]);
            assert!(forced.is_empty(), "{sensor}: {forced:?}");
        }
        // a velocity differenced from the noisy position's record (a ship's u and v from its
        // track): its roughness is in x's record too, but reads less over two samples than one
        let mut tracked = forced_oscillator(0.0, 0.01, 100.0, 4);
        let (t, x) = (tracked.time().to_vec(), tracked.column("x").unwrap().to_vec());
        let rate = crate::data::CentralDifference.differentiate(&t, &x).unwrap();
        tracked.overwrite("v", rate).unwrap();
        let forced = told(&model, &[tracked]);
        assert!(forced.is_empty(), "{forced:?}");
    }
}
