//! An equation's sufficient statistics as a value (issue 16): the candidates' means and
//! cross-products against the target, per run, for one equation of a model. Computed where
//! the rows are (`termid moments`, a worker of a distributed engine), written, merged
//! associatively (runs are appended; merging is concatenation) and identified as the rows
//! together would be — per-run statistics are kept because back-ends that cross-validate
//! leave one run out.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::model::{default_target, model_equation};
use super::noise::held_nonlinearly;
use super::{fit_folds, Design, Fit, Identification, IdentifyError, ParamValue, Target};
use crate::data::{Differentiator, Frame, NoiseTally};
use crate::model::Model;
use crate::select::Moments;

/// One run's statistics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunMoments {
    /// Where the run came from (its file).
    pub run: String,
    /// Its statistics, candidates in the order of [`EquationMoments::candidates`].
    pub moments: Moments,
    /// The white noise and spread of each recorded variable the candidates hold nonlinearly,
    /// for the check that the noise leaves the terms unbiased
    /// ([`crate::recipe::noise_check_of_moments`]); empty in
    /// statistics written before termid gathered them.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub noise: BTreeMap<String, NoiseTally>,
}

/// The statistics of one equation's candidates over a set of runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EquationMoments {
    /// The equation of the model file.
    pub equation: String,
    /// What is explained (`r_dot`, `dr/dt`).
    pub target: String,
    /// The candidate terms, canonical text, in column order.
    pub candidates: Vec<String>,
    /// Each run's statistics.
    pub runs: Vec<RunMoments>,
    /// The statistics of the first and of the second half of every run (a run read in pieces
    /// cut at the boundary of half a piece nearest its middle), each pooled over the runs
    /// gathered together (a shard: merging appends them, as it appends runs): for the check
    /// that the terms hold on each half of the runs
    /// ([`crate::recipe::halves_check_of_moments`]). `None` in statistics written before
    /// termid gathered them, and in those merged with such.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub halves: Option<Vec<[Moments; 2]>>,
}

/// Whether statistics of `model` gather their runs' halves: for a model of no field's, whose
/// checks read them ([`crate::recipe::halves_check_of_moments`]); a field's model (a table of a
/// plug-in in its file) is checked by its field, which reads no halves, and its statistics
/// (fleets of short runs, where the halves cost a fifth more) are spared them.
fn halved(model: &Model) -> bool {
    model.spec().plugins.is_empty()
}

/// `run`'s halves pooled into `all`'s.
fn pool(all: &mut Option<[Moments; 2]>, run: &[Moments; 2]) {
    match all {
        Some([a, b]) => {
            a.merge(&run[0]);
            b.merge(&run[1]);
        }
        none => *none = Some(run.clone()),
    }
}

/// A run read in pieces, as far as it has been read.
struct RunSoFar {
    /// Its name (its file).
    name: String,
    /// Its own parameters, from its first piece.
    fixed: BTreeMap<String, ParamValue>,
    /// Each equation's statistics so far.
    moments: Vec<Stretches>,
    /// Each equation's noise tallies so far.
    noise: Vec<BTreeMap<String, NoiseTally>>,
    /// The columns held and switched between samples as its first piece found them
    /// ([`crate::data::Frame::hold`], [`crate::data::Frame::switch`]).
    between: (Vec<String>, Vec<String>),
    /// The model's variables over the run, kept small.
    kept: crate::data::Thinned,
}

/// The most rows of a run read in pieces kept for a check that re-simulates it: what that
/// check re-simulates of a run read whole (`crate::recipe::retrace`).
const KEPT_ROWS: usize = 20_000;

/// What a pass over runs read in pieces gathers ([`EquationMoments::of_chunks_each`]).
pub struct Pieces {
    /// Each equation's statistics, in the order asked for.
    pub moments: Vec<EquationMoments>,
    /// What admitting the runs said.
    pub notes: Vec<String>,
    /// Each run's states and inputs as kept: at most 20 000 rows, each the average of as many
    /// consecutive rows of the run ([`crate::data::Thinned`]), for a check that re-simulates
    /// the runs.
    pub runs: Vec<Frame>,
}

/// A run's statistics as it is read in pieces: those of consecutive stretches of its rows
/// (halves of pieces at first; as they grow many, neighbours merged in pairs, and later
/// pieces gathered as many to a stretch), so that its halves can be told apart once its
/// length is known.
struct Stretches(crate::data::Coarsened<Moments>);

impl Default for Stretches {
    fn default() -> Self {
        Stretches(crate::data::Coarsened::new(Self::MOST))
    }
}

impl Stretches {
    /// The most stretches kept: the halves are then cut within a 64th of the run's middle.
    const MOST: usize = 64;

    fn push(&mut self, m: Moments) {
        self.0.push(m, |a, b| a.merge(&b));
    }

    /// The run's first and second half, cut at the boundary of stretches nearest its middle;
    /// `None` where nothing was read.
    fn halves(self) -> Option<[Moments; 2]> {
        let stretches = self.0.into_kept();
        let total: usize = stretches.iter().map(Moments::count).sum();
        let mut before = 0;
        let cut = (0..=stretches.len())
            .map(|k| {
                let at = (k, before);
                before += stretches.get(k).map_or(0, Moments::count);
                at
            })
            .min_by_key(|&(_, rows)| rows.abs_diff(total - rows))
            .map(|(k, _)| k)?;
        let merged = |part: &[Moments]| {
            let mut all =
                part.first().cloned().or_else(|| stretches.first().map(|m| Moments::new(m.regressors())))?;
            for m in part.iter().skip(1) {
                all.merge(m);
            }
            Some(all)
        };
        Some([merged(&stretches[..cut])?, merged(&stretches[cut..])?])
    }
}

impl EquationMoments {
    /// The statistics of `equation` of `model` over `frames` (the target as
    /// [`super::fit_equation`] takes it).
    pub fn of_runs(
        model: &Model,
        equation: &str,
        frames: &[Frame],
        differentiator: &dyn Differentiator,
        target: Option<Target>,
    ) -> Result<EquationMoments, IdentifyError> {
        if frames.is_empty() {
            return Err(IdentifyError::Setup("no data: give at least one run".into()));
        }
        let eq = model_equation(model, equation)?;
        let target = target.unwrap_or_else(|| default_target(eq, frames));
        // inputs with a dead time read back as they act
        let frames = &*model.acting(frames)?;
        let rules = model.parameter_rules();
        let how = Identification {
            vocabulary: &model.vocabulary,
            parameters: &rules,
            differentiator,
            intercept: true,
            weights: None,
        };
        let design = Design::new(&eq.candidates, &model.vocabulary)?;
        // the whole runs' statistics gathered as a fit of the rows gathers them (statistics
        // identify as the rows, to the bit), with their halves' where the model's checks read
        // them
        let (library, candidates) = (&design.library, design.candidates());
        let all: Vec<(Moments, Option<[Moments; 2]>)> = if halved(model) {
            let all = how.moments_and_halves_of_runs(library, candidates, &target, frames)?;
            all.into_iter().map(|(m, h)| (m, Some(h))).collect()
        } else {
            how.moments_of_runs(library, candidates, &target, frames)?
                .into_iter()
                .map(|m| (m, None))
                .collect()
        };
        let noisy = held_nonlinearly(&eq.candidates, &model.vocabulary);
        let mut halves = None;
        let runs = frames
            .iter()
            .zip(all)
            .map(|(f, (moments, run_halves))| {
                if let Some(run_halves) = &run_halves {
                    pool(&mut halves, run_halves);
                }
                RunMoments {
                    run: f.origin().into(),
                    moments,
                    noise: noisy
                        .iter()
                        .filter_map(|v| Some((v.clone(), NoiseTally::of(f, v, 0..f.len())?)))
                        .collect(),
                }
            })
            .collect();
        Ok(EquationMoments {
            equation: equation.into(),
            target: target.to_string(),
            candidates: design.names().to_vec(),
            runs,
            halves: halved(model).then(|| halves.into_iter().collect()),
        })
    }

    /// The statistics of `equation` over runs read in chunks: one pass, memory bounded by
    /// the chunk size whatever the files' size. The same as [`EquationMoments::of_runs`] on
    /// the whole runs to round-off, for a derivative method with a fixed reach (central
    /// differences, five points, Savitzky-Golay; the chunks must carry at least that many
    /// rows of context). Each chunk is admitted by the model ([`Model::admitted`]) and checked
    /// for gaps in time; per-run parameters (`first:u`, `mean:u:4`) and the inputs held between
    /// samples ([`crate::data::mark_held`]) are read off each run's first chunk. Returns the
    /// notes of the runs' admission too.
    pub fn of_chunks(
        model: &Model,
        equation: &str,
        runs: Vec<crate::data::Chunks>,
        differentiator: &dyn Differentiator,
    ) -> Result<(EquationMoments, Vec<String>), IdentifyError> {
        let mut pieces = Self::of_chunks_each(model, &[equation.to_string()], runs, differentiator)?;
        Ok((pieces.moments.remove(0), pieces.notes))
    }

    /// [`EquationMoments::of_chunks`] for several equations in the same pass over the rows
    /// (each chunk read, admitted and checked once): one statistics value per equation, in
    /// the order given, and each run's states and inputs kept small.
    pub fn of_chunks_each(
        model: &Model,
        equations: &[String],
        runs: Vec<crate::data::Chunks>,
        differentiator: &dyn Differentiator,
    ) -> Result<Pieces, IdentifyError> {
        if differentiator.reach().is_none() {
            return Err(IdentifyError::Setup(format!(
                "the derivative method `{}` needs whole runs: read in chunks, use central, five-point or savitzky-golay",
                differentiator.name()
            )));
        }
        if runs.is_empty() {
            return Err(IdentifyError::Setup("no data: give at least one run".into()));
        }
        if let Some(late) = model.spec().inputs.iter().find(|i| i.delay > 0.0) {
            return Err(IdentifyError::Setup(format!(
                "{}: `{}` acts {} s late (its `delay`), which a piece of a run cannot read back without the rows before it: read the runs whole (--chunk-rows 0)",
                model.path, late.name, late.delay
            )));
        }
        if let Some(lagging) = model.spec().inputs.iter().find(|i| i.lag > 0.0) {
            return Err(IdentifyError::Setup(format!(
                "{}: `{}` acts through a first-order lag of {} s (its `lag`), whose state a piece of a run cannot carry over from the rows before it: read the runs whole (--chunk-rows 0)",
                model.path, lagging.name, lagging.lag
            )));
        }
        if let Some(state) = model.spec().states.iter().find(|s| s.rate_of.is_some()) {
            return Err(IdentifyError::Setup(format!(
                "{}: `{}` is estimated from each run's whole record of `{}` (its `rate_of`), which a piece of a run does not hold: read the runs whole (--chunk-rows 0)",
                model.path,
                state.name,
                state.rate_of.as_deref().unwrap_or_default()
            )));
        }
        let eqs = equations.iter().map(|e| model_equation(model, e)).collect::<Result<Vec<_>, _>>()?;
        let designs = eqs
            .iter()
            .map(|eq| Design::new(&eq.candidates, &model.vocabulary))
            .collect::<Result<Vec<_>, _>>()?;
        let noisy: Vec<Vec<String>> =
            eqs.iter().map(|eq| held_nonlinearly(&eq.candidates, &model.vocabulary)).collect();
        let rules = model.parameter_rules();
        let (mut out, mut notes) = (vec![Vec::new(); eqs.len()], Vec::new());
        let mut halves: Vec<Option<[Moments; 2]>> = vec![None; eqs.len()];
        let mut kept_runs = Vec::new();
        let mut targets: Option<Vec<Target>> = None;
        let (states, _) = model.recorded_motion();
        for chunks in runs {
            let mut run: Option<RunSoFar> = None;
            // the file's row where the next piece's own rows start, and the variables' values
            // there as this piece has them
            let mut boundary: Option<(usize, Vec<(String, f64)>)> = None;
            for chunk in chunks {
                let mut chunk = chunk?;
                let shift = |e: IdentifyError| e.shifted(chunk.first_row);
                // a run read whole is cut at its gaps (before admission evens its samples); a
                // piece of one cannot be
                crate::data::check_gaps(&chunk.frame).map_err(|e| {
                    IdentifyError::Setup(format!(
                        "{}, where a run read whole is cut into runs of its own; a piece of one cannot be: read the runs whole (--chunk-rows 0), or cut the file there",
                        e.shifted(chunk.first_row)
                    ))
                })?;
                let admitted = model.admitted(&mut chunk.frame).map_err(|e| shift(e.into()))?;
                // an angle unwrapped piece by piece (on a dial, a compass's heading in rad) starts
                // each piece within half a turn of 0: laid onto the piece before by whole turns
                if let Some((row, values)) = boundary.take() {
                    if let Some(at) = row.checked_sub(chunk.first_row) {
                        crate::data::laid_on_turns(&mut chunk.frame, at, &values)
                            .map_err(|e| shift(e.into()))?;
                    }
                }
                let end = chunk.own.end;
                boundary = Some((
                    chunk.first_row + end,
                    model
                        .vocabulary
                        .variables()
                        .iter()
                        .filter_map(|v| Some((v.clone(), *chunk.frame.column(v)?.get(end)?)))
                        .collect(),
                ));
                // a piece of a run is not cut into runs (the whole run is, where a state breaks;
                // an input's step cuts nothing)
                if let Some((row, name, leap)) =
                    crate::data::moving_breaks(&chunk.frame, &states).found.first()
                {
                    return Err(IdentifyError::Setup(format!(
                        "{}: `{name}` leaps by {} from row {} to row {} and stays (records joined in one file, a sensor re-zeroed, a motion reset at each of many: a bounce), where a run read whole is cut into runs of its own; a piece of one cannot be: read the runs whole (--chunk-rows 0), or cut the file there",
                        chunk.frame.origin(),
                        crate::output::sig(*leap, 3),
                        chunk.frame.row(row - 1),
                        chunk.frame.row(*row)
                    )));
                }
                // a chunk's spikes are its own; what else admission says, every chunk repeats
                notes.extend(admitted.spikes);
                if let Some(RunSoFar { between: (held, switched), .. }) = &run {
                    // the inputs held or switched between samples as the run's first chunk found
                    // them, so that no chunk takes an input otherwise for lack of jumps of its own
                    // (or a clock its few jumps keep by chance)
                    for input in &model.spec().inputs {
                        let name = input.name.as_str();
                        if held.iter().any(|h| h == name) {
                            chunk.frame.hold(name).map_err(|e| shift(e.into()))?;
                        } else if switched.iter().any(|h| h == name) {
                            chunk.frame.switch(name).map_err(|e| shift(e.into()))?;
                        } else {
                            chunk.frame.release(name);
                        }
                    }
                }
                if run.is_none() {
                    notes.extend(admitted.notes);
                    // a run's own parameters come from its start, which only its first chunk holds
                    let fixed = rules
                        .iter()
                        .map(|(n, r)| Ok((n.clone(), ParamValue::Value(r.resolve(n, &chunk.frame)?))))
                        .collect::<Result<BTreeMap<_, _>, crate::data::DataError>>()?;
                    targets.get_or_insert_with(|| {
                        eqs.iter().map(|eq| default_target(eq, std::slice::from_ref(&chunk.frame))).collect()
                    });
                    let between = (chunk.frame.held().to_vec(), chunk.frame.switched().to_vec());
                    let variables: Vec<String> = model
                        .vocabulary
                        .variables()
                        .iter()
                        .filter(|v| chunk.frame.column(v).is_some())
                        .cloned()
                        .collect();
                    let kept = crate::data::Thinned::new(
                        chunk.frame.origin(),
                        chunk.frame.time_name(),
                        variables,
                        KEPT_ROWS,
                    );
                    run = Some(RunSoFar {
                        name: chunk.frame.origin().to_string(),
                        fixed,
                        moments: (0..eqs.len()).map(|_| Stretches::default()).collect(),
                        noise: vec![BTreeMap::new(); eqs.len()],
                        between,
                        kept,
                    });
                }
                let (Some(RunSoFar { fixed, moments, noise, kept, .. }), Some(targets)) =
                    (run.as_mut(), targets.as_ref())
                else {
                    unreachable!("set by the run's first chunk")
                };
                kept.push(&chunk.frame, chunk.own.clone()).map_err(|e| shift(e.into()))?;
                // each piece's noise read across its neighbours' rows, its spread over its own;
                // a variable once a piece, whichever equations hold it
                let mut read: BTreeMap<&str, Option<NoiseTally>> = BTreeMap::new();
                for (variables, tallies) in noisy.iter().zip(noise.iter_mut()) {
                    for v in variables {
                        let piece = read
                            .entry(v)
                            .or_insert_with(|| NoiseTally::of(&chunk.frame, v, chunk.own.clone()));
                        if let Some(piece) = piece {
                            tallies.entry(v.clone()).or_default().merge(piece);
                        }
                    }
                }
                let how = Identification {
                    vocabulary: &model.vocabulary,
                    parameters: fixed,
                    differentiator,
                    intercept: true,
                    weights: None,
                };
                // each piece in halves, so that the run's halves can be told apart at its end
                let own = chunk.own.clone();
                let middle = own.start + own.len() / 2;
                for ((design, target), so_far) in designs.iter().zip(targets).zip(moments.iter_mut()) {
                    let halves = how
                        .moments_of_parts(
                            &design.library,
                            design.candidates(),
                            target,
                            &chunk.frame,
                            &[own.start..middle, middle..own.end],
                        )
                        .map_err(shift)?;
                    for m in halves {
                        so_far.push(m);
                    }
                }
            }
            if let Some(RunSoFar { name, moments, noise, kept, .. }) = run {
                kept_runs.push(kept.frame()?);
                for (((list, pooled), m), noise) in out.iter_mut().zip(&mut halves).zip(moments).zip(noise) {
                    if let Some(run_halves) = m.halves() {
                        pool(pooled, &run_halves);
                        let [mut moments, second] = run_halves;
                        moments.merge(&second);
                        list.push(RunMoments { run: name.clone(), moments, noise });
                    }
                }
            }
        }
        let targets = targets.ok_or_else(|| IdentifyError::Setup("no data: the runs hold no rows".into()))?;
        let all = equations
            .iter()
            .zip(targets)
            .zip(designs)
            .zip(out)
            .zip(halves)
            .map(|((((equation, target), design), runs), halves)| EquationMoments {
                equation: equation.clone(),
                target: target.to_string(),
                candidates: design.names().to_vec(),
                runs,
                halves: halved(model).then(|| halves.into_iter().collect()),
            })
            .collect();
        Ok(Pieces { moments: all, notes, runs: kept_runs })
    }

    /// The equation, target and candidates of these statistics, without runs.
    pub(crate) fn clone_empty(&self) -> EquationMoments {
        EquationMoments {
            equation: self.equation.clone(),
            target: self.target.clone(),
            candidates: self.candidates.clone(),
            runs: Vec::new(),
            halves: None,
        }
    }

    /// The statistics of both sets of runs: refused where they are of another equation,
    /// target or candidate list.
    pub fn merge(mut self, other: EquationMoments) -> Result<EquationMoments, IdentifyError> {
        if (&self.equation, &self.target, &self.candidates)
            != (&other.equation, &other.target, &other.candidates)
        {
            return Err(IdentifyError::Setup(format!(
                "statistics of `{}` ({}, {} candidates) cannot be merged with those of `{}` ({}, {} candidates): other equation, target or candidates",
                self.equation,
                self.target,
                self.candidates.len(),
                other.equation,
                other.target,
                other.candidates.len()
            )));
        }
        self.runs.extend(other.runs);
        self.halves = match (self.halves.take(), other.halves) {
            (Some(mut a), Some(b)) => {
                a.extend(b);
                Some(a)
            }
            // (statistics written before termid gathered halves: the halves of only some runs)
            _ => None,
        };
        self.check("merged statistics")?;
        Ok(self)
    }

    /// Reads statistics written as JSON, checked to be whole; `origin` names them in errors.
    pub fn from_json(text: &str, origin: &str) -> Result<EquationMoments, IdentifyError> {
        let m: EquationMoments = serde_json::from_str(text).map_err(|e| {
            IdentifyError::Setup(format!("{origin}: not termid's statistics of an equation: {e}"))
        })?;
        if let Some(bad) =
            m.runs.iter().find(|r| !r.moments.is_consistent() || r.moments.regressors() != m.candidates.len())
        {
            return Err(IdentifyError::Setup(format!(
                "{origin}: the statistics of run `{}` are not whole (sizes or numbers do not fit {} candidates)",
                bad.run,
                m.candidates.len()
            )));
        }
        m.check(origin)?;
        Ok(m)
    }

    /// Refuses statistics that no rows could have given (read from a file, they may have
    /// been edited or damaged): per run, as many rows as weight (termid's statistics are
    /// unweighted), sums of squares not negative, cross-products within Cauchy-Schwarz,
    /// numbers whose squares stay finite; and no run twice.
    fn check(&self, origin: &str) -> Result<(), IdentifyError> {
        let refuse = |run: &str, why: String| {
            Err(IdentifyError::Setup(format!(
                "{origin}: the statistics of run `{run}` cannot come from data: {why}"
            )))
        };
        let m = self.candidates.len() + 1;
        for (k, r) in self.runs.iter().enumerate() {
            let s = &r.moments;
            if s.count() == 0 || s.weight() != s.count() as f64 {
                return refuse(&r.run, format!("{} rows but a weight of {}", s.count(), s.weight()));
            }
            let name = |i: usize| self.candidates.get(i).map_or(self.target.as_str(), String::as_str);
            if let Some(i) = (0..m).find(|&i| s.means()[i].abs() > 1e150) {
                return refuse(
                    &r.run,
                    format!("the mean of `{}` is {:e}, beyond any measurement", name(i), s.means()[i]),
                );
            }
            for i in 0..m {
                let cii = s.corrected(i, i);
                let scale = 1.0 + s.weight() * s.means()[i].powi(2);
                if cii.is_nan() || cii < -1e-9 * scale || cii > 1e300 {
                    return refuse(&r.run, format!("the sum of squares of `{}` is {cii:e}", name(i)));
                }
                for j in 0..i {
                    let (cij, cjj) = (s.corrected(i, j), s.corrected(j, j));
                    if cij.abs() > (cii.max(0.0) * cjj.max(0.0)).sqrt() * (1.0 + 1e-6) + 1e-9 * scale {
                        return refuse(
                            &r.run,
                            format!(
                                "the cross-product of `{}` and `{}` ({cij:e}) exceeds what their sums of squares allow",
                                name(i),
                                name(j)
                            ),
                        );
                    }
                }
            }
            if let Some((v, _)) = r.noise.iter().find(|(_, t)| !t.is_consistent()) {
                return refuse(&r.run, format!("the noise tally of `{v}` is not whole"));
            }
            if let Some(first) = self.runs[..k].iter().find(|o| o.run == r.run && o.moments == r.moments) {
                return Err(IdentifyError::Setup(format!(
                    "{origin}: run `{}` appears twice with the same statistics: it would be counted twice",
                    first.run
                )));
            }
        }
        if let Some(halves) = &self.halves {
            let whole = |m: &Moments| {
                m.is_consistent() && m.regressors() == self.candidates.len() && m.weight() == m.count() as f64
            };
            let sum = |rows: &mut dyn Iterator<Item = usize>| rows.fold(0usize, usize::saturating_add);
            let rows = sum(&mut self.runs.iter().map(|r| r.moments.count()));
            let halved = sum(&mut halves.iter().flatten().map(Moments::count));
            if !halves.iter().flatten().all(whole) || halved != rows {
                return Err(IdentifyError::Setup(format!(
                    "{origin}: the statistics of the runs' halves ({halved} rows) cannot come from their {rows} rows"
                )));
            }
        }
        Ok(())
    }

    /// The statistics as JSON (every number round-trips exactly).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// The statistics as bytes: a JSON header (equation, target, candidates, each run's name
    /// and row count) after its length, then every run's [`Moments::numbers`] as little-endian
    /// f64 — exact, and several times smaller and faster than the JSON of
    /// [`EquationMoments::to_json`] (what pickling sends between processes).
    pub fn to_bytes(&self) -> Vec<u8> {
        let header = serde_json::json!({
            "equation": self.equation,
            "target": self.target,
            "candidates": self.candidates,
            "runs": self.runs.iter().map(|r| (&r.run, r.moments.count())).collect::<Vec<_>>(),
            "overlaps": self.runs.iter().map(|r| r.moments.overlap()).collect::<Vec<_>>(),
            "noise": self.runs.iter().map(|r| &r.noise).collect::<Vec<_>>(),
            "halves": self.halves.as_ref().map(|all| all.iter().map(|h| h.each_ref().map(|m| (m.count(), m.overlap()))).collect::<Vec<_>>()),
        })
        .to_string();
        let mut out =
            Vec::with_capacity(8 + header.len() + self.runs.len() * 8 * (self.candidates.len() + 2).pow(2));
        out.extend_from_slice(&(header.len() as u64).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        let halves = self.halves.iter().flatten().flatten();
        for v in self.runs.iter().map(|r| &r.moments).chain(halves).flat_map(Moments::numbers) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }

    /// Reads [`EquationMoments::to_bytes`], checked to be whole; `origin` names them in errors.
    pub fn from_bytes(bytes: &[u8], origin: &str) -> Result<EquationMoments, IdentifyError> {
        let broken = |why: &str| {
            IdentifyError::Setup(format!("{origin}: not termid's statistics of an equation: {why}"))
        };
        let (size, rest) = bytes.split_first_chunk::<8>().ok_or_else(|| broken("too short"))?;
        let size = usize::try_from(u64::from_le_bytes(*size)).map_err(|_| broken("header size"))?;
        let (header, mut numbers) = (rest.get(..size), rest.get(size..).unwrap_or_default());
        #[derive(Deserialize)]
        struct Header {
            equation: String,
            target: String,
            candidates: Vec<String>,
            runs: Vec<(String, usize)>,
            /// Each run's rows per independent row (a weak form's windows; 1 where absent).
            #[serde(default)]
            overlaps: Vec<f64>,
            /// Each run's noise tallies (none where absent).
            #[serde(default)]
            noise: Vec<BTreeMap<String, NoiseTally>>,
            /// The halves' rows and overlaps, their numbers after the runs' (none where absent).
            #[serde(default)]
            halves: Option<Vec<[(usize, f64); 2]>>,
        }
        let header: Header = header
            .and_then(|h| serde_json::from_slice(h).ok())
            .ok_or_else(|| broken("the header is not readable"))?;
        let p = header.candidates.len();
        let per_set = 1 + (p + 1) + (p + 1) * (p + 2) / 2;
        let sets =
            header.runs.len().saturating_add(header.halves.as_ref().map_or(0, |h| h.len().saturating_mul(2)));
        if numbers.len() != sets * per_set * 8 {
            return Err(broken("the numbers do not fit the candidates and runs"));
        }
        let mut next = |count: usize, overlap: f64, whose: &str| {
            let (these, rest) = numbers.split_at(per_set * 8);
            numbers = rest;
            let values: Vec<f64> =
                these.chunks_exact(8).map(|b| f64::from_le_bytes(b.try_into().unwrap_or_default())).collect();
            Moments::from_numbers(p, count, &values)
                .filter(Moments::is_consistent)
                .map(|m| m.with_overlap(overlap))
                .ok_or_else(|| broken(&format!("the statistics of {whose} are not whole")))
        };
        let mut runs = Vec::with_capacity(header.runs.len());
        let overlaps = header.overlaps.iter().copied().chain(std::iter::repeat(1.0));
        let noises = header.noise.into_iter().chain(std::iter::repeat_with(BTreeMap::new));
        for (((run, count), overlap), noise) in header.runs.into_iter().zip(overlaps).zip(noises) {
            let moments = next(count, overlap, &format!("run `{run}`"))?;
            runs.push(RunMoments { run, moments, noise });
        }
        let halves = match header.halves {
            Some(all) => Some(
                all.into_iter()
                    .map(|[(a, oa), (b, ob)]| {
                        Ok([next(a, oa, "the runs' halves")?, next(b, ob, "the runs' halves")?])
                    })
                    .collect::<Result<Vec<_>, IdentifyError>>()?,
            ),
            None => None,
        };
        let m = EquationMoments {
            equation: header.equation,
            target: header.target,
            candidates: header.candidates,
            runs,
            halves,
        };
        m.check(origin)?;
        Ok(m)
    }

    /// The model's inputs that hold one value through every run, with it, as far as the
    /// statistics tell: no spread in the tallies of the recorded input (where the candidates
    /// hold it nonlinearly), or a spread of its noise alone, else none in its own candidate
    /// column (exact where the rows are the samples; a weak form's windows weigh even a
    /// constant unevenly at a run's ends). Fits from statistics say of them what
    /// [`super::identify_model`] says of runs read whole.
    pub fn held_inputs(&self, model: &Model) -> Vec<super::model::Held> {
        let held = |name: &str| -> Option<(f64, bool)> {
            if self.runs.iter().all(|r| r.noise.contains_key(name)) {
                let tally = NoiseTally::pooled(self.runs.iter().filter_map(|r| r.noise.get(name)).cloned());
                if tally.rows > 0 && tally.m2 == 0.0 {
                    return Some((tally.mean, false));
                }
                return super::model::noise_alone(&tally).then_some((tally.mean, true));
            }
            // (the runs' statistics merged only where an input needs them)
            let k = self.candidates.iter().position(|c| c == name)?;
            let (first, rest) = self.runs.split_first()?;
            let mut all = first.moments.clone();
            for r in rest {
                all.merge(&r.moments);
            }
            (all.corrected(k, k) == 0.0).then(|| (all.means()[k], false))
        };
        model
            .spec()
            .inputs
            .iter()
            .filter_map(|i| held(&i.name).map(|(value, noisy)| (i.name.clone(), value, noisy)))
            .collect()
    }

    /// Identifies the equation from the statistics with the model's forced and excluded terms
    /// and back-end, as [`super::fit_equation`] would from the rows.
    pub fn fit(&self, model: &Model, intercept: bool) -> Result<Fit, IdentifyError> {
        let eq = model_equation(model, &self.equation)?;
        let design = Design::new(&eq.candidates, &model.vocabulary)?;
        if design.names() != self.candidates.as_slice() {
            return Err(IdentifyError::Setup(format!(
                "{}: the candidates of `{}` are not those the statistics were computed for",
                model.path, self.equation
            )));
        }
        if self.runs.is_empty() {
            return Err(IdentifyError::Setup("no data: the statistics hold no run".into()));
        }
        let targets = [format!("{}_dot", eq.state), format!("d{}/dt", eq.state)];
        if !targets.contains(&self.target) {
            return Err(IdentifyError::Setup(format!(
                "the statistics of `{}` explain `{}`, but equation `{}` of {} is the rate of `{}` ({} or {}): they belong to another equation",
                self.equation, self.target, self.equation, model.path, eq.state, targets[0], targets[1]
            )));
        }
        let index = |t: &crate::term::Term| design.candidates().iter().position(|c| c == t);
        let forced: Vec<usize> = eq.forced.iter().filter_map(index).collect();
        let excluded: Vec<usize> = eq.excluded.iter().filter_map(index).collect();
        let folds: Vec<Moments> = self.runs.iter().map(|r| r.moments.clone()).collect();
        fit_folds(
            &self.target,
            design.names(),
            &forced,
            &excluded,
            intercept,
            &folds,
            eq.backend.build().as_ref(),
        )
    }
}

/// Identifies a model's equations from statistics: the parts of each equation are merged in
/// the order given (shards of runs, from any number of machines: [`merged_by_equation`]),
/// then each equation is fitted with the model's forced and excluded terms and back-end and
/// stored in a copy of the model, as [`super::identify_model`] would from the rows. Each part
/// comes with the name an error calls it by (its file).
pub fn identify_from_moments(
    model: &Model,
    parts: Vec<(String, EquationMoments)>,
    intercept: bool,
) -> Result<super::IdentifiedModel, IdentifyError> {
    identify_from_merged(model, &merged_by_equation(parts)?, intercept)
}

/// [`identify_from_moments`] of statistics merged already, one value per equation.
pub fn identify_from_merged(
    model: &Model,
    merged: &[EquationMoments],
    intercept: bool,
) -> Result<super::IdentifiedModel, IdentifyError> {
    let mut identified = model.clone();
    let mut fits = Vec::new();
    for m in merged {
        let in_equation = |e: IdentifyError| e.in_equation(&m.equation);
        let mut fit = m.fit(model, intercept).map_err(in_equation)?;
        fit.selection.notes.extend(super::model::held_note(model, &m.equation, &m.held_inputs(model)));
        super::model::store_fit(&mut identified, &m.equation, &fit).map_err(in_equation)?;
        fits.push((m.equation.clone(), fit));
    }
    Ok(super::IdentifiedModel { model: identified, fits })
}

/// The parts of each equation's statistics merged in the order given, one value per
/// equation (in the order the equations first come); each part named as errors call it.
pub fn merged_by_equation(
    parts: Vec<(String, EquationMoments)>,
) -> Result<Vec<EquationMoments>, IdentifyError> {
    let mut merged: Vec<EquationMoments> = Vec::new();
    for (origin, m) in parts {
        match merged.iter().position(|e| e.equation == m.equation) {
            Some(k) => {
                let old = merged.remove(k);
                let both = old.merge(m).map_err(|e| IdentifyError::Setup(format!("{origin}: {e}")))?;
                merged.insert(k, both);
            }
            None => merged.push(m),
        }
    }
    Ok(merged)
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;
    use std::path::Path;

    use super::*;
    use crate::data::CentralDifference;
    use crate::identify::fit_equation;
    use crate::select::Backend;
    use crate::sim::{simulate, Constant, Integrator, Settings, System};

    /// Three Lorenz runs with a little noise, as frames of states.
    fn runs(model: &Model) -> Vec<Frame> {
        let settings = Settings { integrator: Integrator::Rk4, dt: 0.001, duration: 3.0, sample: 0.005 };
        let system = System::new(model, &BTreeMap::new(), false).unwrap();
        [[-8.0, 7.0, 27.0], [1.0, 1.0, 1.0], [10.0, -5.0, 20.0]]
            .iter()
            .enumerate()
            .map(|(k, x0)| {
                let run = simulate(&system, x0, &mut Constant(vec![]), &settings).unwrap();
                let mut f = Frame::new(&format!("run{k}"), "t", run.time.clone()).unwrap();
                for (i, (name, column)) in run.state_names.iter().zip(&run.states).enumerate() {
                    // a deterministic wiggle, so the fits are not exact
                    let noisy =
                        column.iter().enumerate().map(|(j, v)| v + 1e-3 * ((j * (i + 3)) as f64).sin());
                    f.push(name, noisy.collect()).unwrap();
                }
                f
            })
            .collect()
    }

    /// Statistics of shards, written, read, merged in either grouping, fit exactly as the
    /// rows together — with the paper's stepwise regression and with the sparse fit whose λ
    /// is chosen by leaving one run out (it needs the per-run statistics).
    #[test]
    fn merged_statistics_fit_as_the_rows_together() {
        let lorenz = Model::load(Path::new("models/lorenz.toml")).unwrap();
        let frames = runs(&lorenz);
        for backend in ["stepwise", "sparse"] {
            let model = lorenz.with_backend(&Backend::by_name(backend).unwrap()).unwrap();
            for eq in ["x_dot", "z_dot"] {
                let whole = fit_equation(&model, eq, &frames, &CentralDifference, true, None).unwrap();
                let shard = |range: std::ops::Range<usize>| {
                    let m = EquationMoments::of_runs(&model, eq, &frames[range], &CentralDifference, None)
                        .unwrap();
                    let read = EquationMoments::from_json(&m.to_json(), "shard").unwrap();
                    // the bytes a worker sends carry the same statistics exactly
                    assert_eq!(EquationMoments::from_bytes(&m.to_bytes(), "shard").unwrap(), read);
                    read
                };
                let (a, b, c) = (shard(0..1), shard(1..2), shard(2..3));
                let left = a.clone().merge(b.clone()).unwrap().merge(c.clone()).unwrap();
                let right = a.merge(b.merge(c).unwrap()).unwrap();
                assert_eq!(left, right, "merging is associative");
                let merged = left.fit(&model, true).unwrap();
                let (w, m) = (&whole.selection, &merged.selection);
                assert!(!w.terms.is_empty(), "{backend} {eq}: no terms");
                assert_eq!(
                    w.terms.iter().map(|t| &t.term).collect::<Vec<_>>(),
                    m.terms.iter().map(|t| &t.term).collect::<Vec<_>>(),
                    "{backend} {eq}"
                );
                for (x, y) in w.terms.iter().zip(&m.terms) {
                    assert!(
                        (x.coefficient - y.coefficient).abs() <= 1e-12 * x.coefficient.abs().max(1.0),
                        "{backend} {eq} {}: {} vs {}",
                        x.term,
                        x.coefficient,
                        y.coefficient
                    );
                }
            }
        }
    }

    /// A fold identified from each run's statistics is the model identified on the fold's
    /// runs, to the bit, for every back-end.
    #[test]
    fn a_fold_of_run_statistics_is_the_model_identified_on_its_runs() {
        let lorenz = Model::load(Path::new("models/lorenz.toml")).unwrap();
        let frames = runs(&lorenz);
        let how = crate::identify::ModelIdentification {
            equations: vec![],
            differentiator: &CentralDifference,
            intercept: true,
            target: None,
        };
        for backend in Backend::NAMES {
            let model = lorenz.with_backend(&Backend::by_name(backend).unwrap()).unwrap();
            let statistics = crate::identify::RunStatistics::of(&model, &frames, &how).unwrap();
            for left_out in 0..frames.len() {
                let fold = statistics.identify_without(&model, left_out).unwrap();
                let rest: Vec<Frame> = frames
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| *k != left_out)
                    .map(|(_, f)| f.clone())
                    .collect();
                let direct = crate::identify::identify_model(&model, &rest, &how, &mut |_| {}).unwrap();
                for (a, b) in fold.model.equations().iter().zip(direct.model.equations()) {
                    let values = |e: &crate::model::Equation| {
                        e.coefficients
                            .iter()
                            .map(|(t, v, _)| (t.to_string(), v.to_bits()))
                            .collect::<Vec<_>>()
                    };
                    assert_eq!(values(a), values(b), "{backend}, run {left_out} left out: {}", a.name);
                    assert_eq!(a.intercept.map(f64::to_bits), b.intercept.map(f64::to_bits));
                }
            }
        }
    }

    /// A run read in pieces carries its halves' statistics: those of the run read whole (to
    /// round-off, the middle on a boundary of half a piece), through bytes and JSON, appended
    /// as statistics merge; a long run keeps few stretches, its halves cut within a 64th of
    /// its middle.
    #[test]
    fn a_run_read_in_pieces_carries_its_halves() {
        let lorenz = Model::load(Path::new("models/lorenz.toml")).unwrap();
        let frame = runs(&lorenz).remove(0).slice(0..600);
        let whole = EquationMoments::of_runs(
            &lorenz,
            "y_dot",
            std::slice::from_ref(&frame),
            &CentralDifference,
            None,
        )
        .unwrap();
        let path = std::env::temp_dir().join(format!("termid-halves-{}.csv", std::process::id()));
        frame.write_csv(&path).unwrap();
        let chunks = crate::data::Chunks::open(&path, "t", 100, 4).unwrap();
        let (pieces, _) =
            EquationMoments::of_chunks(&lorenz, "y_dot", vec![chunks], &CentralDifference).unwrap();
        let (a, b) = (&whole.halves.as_ref().unwrap()[0], &pieces.halves.as_ref().unwrap()[0]);
        assert_eq!(frame.len() % 100, 0);
        for (x, y) in a.iter().zip(b.iter()) {
            assert_eq!((x.count(), y.count()), (frame.len() / 2, frame.len() / 2));
            for (u, v) in x.numbers().iter().zip(y.numbers()) {
                assert!((u - v).abs() <= 1e-9 * u.abs().max(1.0), "{u} vs {v}");
            }
        }
        std::fs::remove_file(&path).ok();
        assert_eq!(EquationMoments::from_bytes(&pieces.to_bytes(), "p").unwrap(), pieces);
        assert_eq!(EquationMoments::from_json(&pieces.to_json(), "p").unwrap(), pieces);
        // halves that do not add up to their runs are refused
        let mut broken = pieces.clone();
        broken.halves.as_mut().unwrap()[0][1] = a[1].without(&a[1]);
        let e = EquationMoments::from_json(&broken.to_json(), "p").unwrap_err().to_string();
        assert!(e.contains("the statistics of the runs' halves"), "{e}");
        // merged with statistics that lack them (written before termid gathered them): none
        let old = EquationMoments { halves: None, ..whole.clone() };
        let renamed = EquationMoments {
            runs: vec![RunMoments { run: "other".into(), ..pieces.runs[0].clone() }],
            ..pieces.clone()
        };
        assert!(old.merge(renamed.clone()).unwrap().halves.is_none());
        let both = whole.clone().merge(renamed).unwrap();
        assert_eq!(both.halves.unwrap().iter().map(|h| h[0].count()).sum::<usize>(), 600);
        let mut stretches = Stretches::default();
        let one = |v: f64| Moments::of_columns(&[v], &[2.0 * v], None);
        for k in 0..1001 {
            stretches.push(one(k as f64));
        }
        assert!(stretches.0.kept().len() <= Stretches::MOST);
        let [first, second] = stretches.halves().unwrap();
        assert!(first.count().abs_diff(second.count()) <= 1001 / 32, "{} {}", first.count(), second.count());
        assert!(first.means()[0] < 500.0 && second.means()[0] > 500.0);
    }

    #[test]
    fn broken_bytes_are_refused() {
        let lorenz = Model::load(Path::new("models/lorenz.toml")).unwrap();
        let frames = runs(&lorenz);
        let bytes =
            EquationMoments::of_runs(&lorenz, "x_dot", &frames, &CentralDifference, None).unwrap().to_bytes();
        for cut in [0, 5, 40, bytes.len() - 8, bytes.len() - 1] {
            let e = EquationMoments::from_bytes(&bytes[..cut], "x.moments").unwrap_err().to_string();
            assert!(e.starts_with("x.moments: not termid's statistics"), "{e}");
        }
        let mut nan = bytes.clone();
        let n = nan.len();
        nan[n - 8..].copy_from_slice(&f64::NAN.to_le_bytes());
        let e = EquationMoments::from_bytes(&nan, "x.moments").unwrap_err().to_string();
        assert!(e.contains("not whole"), "{e}");
    }

    #[test]
    fn statistics_of_another_equation_or_broken_are_refused() {
        let lorenz = Model::load(Path::new("models/lorenz.toml")).unwrap();
        let frames = runs(&lorenz);
        let x = EquationMoments::of_runs(&lorenz, "x_dot", &frames[..1], &CentralDifference, None).unwrap();
        let z = EquationMoments::of_runs(&lorenz, "z_dot", &frames[..1], &CentralDifference, None).unwrap();
        let e = x.clone().merge(z).unwrap_err().to_string();
        assert!(e.contains("cannot be merged"), "{e}");
        let text = x.to_json().replacen("\"numbers\":[", "\"numbers\":[1.0,", 1);
        let e = EquationMoments::from_json(&text, "s.moments").unwrap_err().to_string();
        assert!(e.contains("s.moments") && e.contains("do not make the statistics of 10 regressors"), "{e}");
        let e = EquationMoments::from_json("{\"equation\": 3}", "s.moments").unwrap_err().to_string();
        assert!(e.contains("s.moments"), "{e}");
        let text = x.to_json().replacen("\"m2\":", "\"m2\":-", 1);
        let e = EquationMoments::from_json(&text, "s.moments").unwrap_err().to_string();
        assert!(e.contains("s.moments") && e.contains("the noise tally of `x` is not whole"), "{e}");
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 200, failure_persistence: None, ..Default::default() })]
        /// Damaged statistics (bytes flipped in the binary form, numbers changed in the JSON)
        /// are read and fitted, or refused with the file's name; never a panic.
        #[test]
        fn damaged_statistics_are_errors_not_panics(
            flips in proptest::collection::vec((0.0f64..1.0, 1u8..=255), 1..4),
            numbers in proptest::collection::vec((0.0f64..1.0, proptest::num::f64::ANY), 1..3),
        ) {
            let lorenz = Model::load(Path::new("models/lorenz.toml")).unwrap();
            let frames = runs(&lorenz);
            let m = EquationMoments::of_runs(&lorenz, "x_dot", &frames[..1], &CentralDifference, None).unwrap();
            let mut bytes = m.to_bytes();
            for (at, x) in &flips {
                let k = ((at * bytes.len() as f64) as usize).min(bytes.len() - 1);
                bytes[k] ^= x;
            }
            let read = std::panic::catch_unwind(|| EquationMoments::from_bytes(&bytes, "s.bin").map(|r| r.fit(&lorenz, true).map(|_| ())));
            proptest::prop_assert!(read.is_ok(), "from_bytes panicked");
            if let Ok(Err(e)) = read {
                proptest::prop_assert!(e.to_string().contains("s.bin"), "{e}");
            }
            let mut v: serde_json::Value = serde_json::from_str(&m.to_json()).unwrap();
            let list = v["runs"][0]["moments"]["numbers"].as_array_mut().unwrap();
            for (at, x) in &numbers {
                let k = ((at * list.len() as f64) as usize).min(list.len() - 1);
                list[k] = serde_json::Value::from(*x);
            }
            // and the noise tallies' numbers, counts included
            let tallies = v["runs"][0]["noise"].as_object_mut().unwrap();
            for (at, x) in &numbers {
                let field = ["m2", "rows", "noise_rows", "mean", "noise"][(at * 15.0) as usize % 5];
                let tally = tallies.values_mut().nth((at * 3.0) as usize).unwrap();
                tally[field] = if field.ends_with("rows") {
                    serde_json::Value::from(x.abs().min(u64::MAX as f64) as u64)
                } else {
                    serde_json::Value::from(*x)
                };
            }
            let text = v.to_string();
            let read = std::panic::catch_unwind(|| {
                EquationMoments::from_json(&text, "s.json")
                    .map(|r| (crate::recipe::noise_check_of_moments(std::slice::from_ref(&r), &lorenz), r.fit(&lorenz, true).map(|_| ()), r.clone().merge(r).map(|b| crate::recipe::noise_check_of_moments(&[b], &lorenz))))
            });
            proptest::prop_assert!(read.is_ok(), "from_json panicked");
        }
    }
}
