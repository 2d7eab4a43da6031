//! `termid identify`: data files + candidate terms → the chosen equation.

use std::collections::BTreeMap;

use anyhow::{bail, Context, Result};
use termid::data::{
    differentiator, prepare, resample, CentralDifference, Differentiator, Frame, Preparation,
};
use termid::identify::{Identification, ParamValue, Target};
use termid::select::{Backend, BackendName, StepRule};
use termid::term::{parse_terms, Vocabulary};

use crate::args::{Format, IdentifyCommand, RuleName};

fn split_pair<'a>(text: &'a str, what: &str) -> Result<(&'a str, &'a str)> {
    text.split_once('=')
        .map(|(a, b)| (a.trim(), b.trim()))
        .with_context(|| format!("{what} `{text}` must have the form NAME=VALUE"))
}

/// The derivative method `auto` stands for: central differences for a model with a plug-in's
/// table (a ship: the paper's own), five-point differences for files read in pieces, else no
/// derivative at all: the integral form, which recovers polynomial systems from noise-free
/// and noisy samples alike where central differences leave an error that is smooth in the
/// states and that spurious terms then fit (Lorenz at 1 % noise: every equation exact with
/// it, x's with a dozen spurious terms from central differences or the Kalman smoother).
fn resolve_derivative(cmd: &mut IdentifyCommand) -> Result<()> {
    if cmd.derivative != "auto" {
        return Ok(());
    }
    let plugin = match &cmd.model {
        Some(path) => termid::plugins::load(path).map(|m| termid::plugins::of(&m).is_some()).unwrap_or(false),
        None => false,
    };
    // the integral form reads in pieces as well as whole (its windows reach a fixed number
    // of samples ahead)
    cmd.derivative = if plugin { "central" } else { "integral" }.into();
    Ok(())
}

/// Whether the equations fit a forced intercept: the flags, else `default` (a model file's
/// `intercept`; without one, only where the target is not a rate, as in classical regression:
/// for a rate the constant is a candidate term instead).
fn intercept_of(cmd: &IdentifyCommand, default: bool) -> bool {
    !cmd.no_intercept && (cmd.intercept || default)
}

/// Whether a target without a model file is a state's rate, so that an equation of motion is
/// fitted: `dX/dt`, or a column `X_dot` beside a column `X` of timed runs (termid's own name
/// for a measured rate, as model files and `simulate` write it).
fn is_rate(target: &Target, frames: &[Frame], no_time: bool) -> bool {
    match target {
        Target::Derivative(_) => true,
        Target::Column(c) => {
            !no_time
                && c.strip_suffix("_dot")
                    .is_some_and(|s| frames.iter().all(|f| f.names().iter().any(|n| n == s)))
        }
    }
}

pub fn run(mut cmd: IdentifyCommand) -> Result<()> {
    resolve_derivative(&mut cmd)?;
    if let Some(dir) = &cmd.prepared_svg {
        termid::output::check_folder(dir)?;
    }
    for (flag, list) in [("--param", &cmd.params), ("--derive", &cmd.derived), ("--alias", &cmd.aliases)] {
        crate::runs::check_names_once(flag, list)?;
    }
    let mut inputs = crate::runs::input_files(&cmd.data, cmd.dataset.as_deref());
    crate::runs::check_once(&inputs)?;
    for (k, m) in cmd.moments.iter().enumerate() {
        if let Some(first) = cmd.moments[..k].iter().find(|o| termid::output::same_file(o, m)) {
            bail!(
                "--moments {} is the same file as {}: its runs would be counted twice; give each file once",
                m.display(),
                first.display()
            );
        }
    }
    if let Some(out) = &cmd.out {
        let named = |flag: &str, p: &std::path::PathBuf| (format!("{flag} {}", p.display()), p.clone());
        inputs.extend(cmd.model.iter().map(|p| named("--model", p)));
        inputs.extend(cmd.moments.iter().map(|p| named("--moments", p)));
        inputs.extend(cmd.terms_file.iter().map(|p| named("--terms-file", p)));
        inputs.extend(cmd.refine_validation.iter().map(|p| named("--refine-validation", p)));
        crate::runs::check_outputs(&[("--out", out)], &inputs)?;
    }
    if !cmd.moments.is_empty() {
        return run_moments(cmd);
    }
    if cmd.model.is_some() {
        return run_model(cmd);
    }
    if cmd.refine.is_some() {
        bail!("--refine re-simulates the identified equations: it needs a --model that declares them");
    }
    let mut frames = if cmd.no_time {
        let mut frames =
            cmd.data.iter().map(|p| Frame::read_csv_untimed(p)).collect::<Result<Vec<_>, _>>()?;
        if let Some(ds) = &cmd.dataset {
            frames.extend(crate::runs::load(&[], Some(ds), &cmd.time)?);
        }
        frames
    } else {
        // the same reading (and check for gaps in time) as every other command
        crate::runs::load(&cmd.data, cmd.dataset.as_deref(), &cmd.time)?
    };
    let target = Target::parse(cmd.target.as_deref().unwrap_or_default());
    match &target {
        Target::Derivative(s) if *s == cmd.time => {
            bail!("--target d{s}/dt: `{s}` is the time column, whose rate is 1; name a measured quantity")
        }
        Target::Column(c) if cmd.terms.iter().any(|t| t.trim() == c) => {
            bail!("--target {c} is among the candidate terms: it would explain itself exactly; leave it out of --terms")
        }
        _ => {}
    }
    if let Some(plugin) = termid::plugins::with_derivative(&cmd.derivative) {
        bail!(
            "--derivative {} is the {} plug-in's: it needs a --model with a [{}] section",
            cmd.derivative,
            plugin.table(),
            plugin.table()
        );
    }
    let diff = derivative_method(&cmd)?;
    if let Target::Derivative(state) = &target {
        frames = prepare_runs(&cmd, frames, std::slice::from_ref(state), None, diff.as_ref(), &|_| {
            (1.0, String::new())
        })?;
    }
    let mut vocab = Vocabulary::new();
    let mut params = BTreeMap::new();
    for p in &cmd.params {
        let (name, value) = split_pair(p, "parameter")?;
        let value = ParamValue::from_text(name, value).map_err(|m| anyhow::anyhow!("--param {p}: {m}"))?;
        params.insert(name.to_string(), value);
    }
    if cmd.no_time && matches!(target, Target::Derivative(_)) {
        bail!("--no-time data have no time axis, so `{target}` cannot be differentiated");
    }
    for name in frames[0].names() {
        if cmd.no_time && name == "row" {
            continue;
        }
        if !params.contains_key(name) {
            vocab.variable(name)?;
        }
    }
    for name in params.keys() {
        vocab.parameter(name)?;
    }
    for d in &cmd.derived {
        let (name, def) = split_pair(d, "derived variable")?;
        vocab.derive(name, def).with_context(|| format!("in --derive `{d}`"))?;
    }
    for a in &cmd.aliases {
        let (alias, target) = split_pair(a, "alias")?;
        vocab.alias(alias, target)?;
    }
    let mut texts = cmd.terms.clone();
    if let Some(path) = &cmd.terms_file {
        let text = termid::budget::read_text(path).with_context(|| format!("reading {}", path.display()))?;
        for (k, line) in text.lines().enumerate() {
            let term = line.split('#').next().unwrap_or("").trim();
            if term.is_empty() {
                continue;
            }
            // each line checked here, so an error names the file and line
            vocab.parse(term).map_err(|e| anyhow::anyhow!("{}:{}:\n{e}", path.display(), k + 1))?;
            texts.push(term.to_string());
        }
    }
    if texts.is_empty() {
        bail!("no candidate terms: give --terms or --terms-file");
    }
    let candidates = parse_terms(&texts, &vocab)?;
    let forced = parse_terms(&cmd.forced, &vocab)?;
    let excluded = parse_terms(&cmd.exclude, &vocab)?;
    // an ODE's defaults (a rate as target): sequential thresholding, scale-free, and the
    // constant as a candidate like any other rather than a forced intercept
    let ode = is_rate(&target, &frames, cmd.no_time);
    let backend = if ode && cmd.backend.is_none() {
        Backend::from(BackendName::Stlsq)
    } else {
        configure_backend(&cmd)?
    };
    let intercept = intercept_of(&cmd, !ode);
    let mut candidates = candidates;
    let one = vocab.parse("1")?;
    if ode && !intercept && !cmd.no_intercept && !candidates.contains(&one) {
        candidates.push(one);
    }
    let selector = backend.build();
    let identification = Identification {
        vocabulary: &vocab,
        parameters: &params,
        differentiator: diff.as_ref(),
        intercept,
        weights: cmd.weight.clone(),
    };
    let mut fit = crate::progress::with_spinner(&format!("{} on {}", selector.name(), target), || {
        identification.fit(&target, &candidates, &forced, &excluded, &frames, selector.as_ref())
    })?;
    if !cmd.no_time {
        // rows of a time series are not independent; rows without time have no order to test
        fit.correlation_time =
            identification.correlation_time(&target, &candidates, &frames, &fit.selection)?;
    }
    match cmd.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&serde_json::to_value(fit.report())?)?),
        Format::Text => print!("{}", fit.text()),
    }
    Ok(())
}

/// The `--derivative` method. A plug-in's method (the ship's `kinematic` tracking filter)
/// writes every rate as a column in `prepare_runs`, so central differences stand in for it:
/// nothing is left to differentiate then.
fn derivative_method(cmd: &IdentifyCommand) -> Result<Box<dyn Differentiator>> {
    Ok(if termid::plugins::with_derivative(&cmd.derivative).is_some() {
        Box::new(CentralDifference)
    } else {
        differentiator(&cmd.derivative)?
    })
}

/// Resampling and smoothing of the runs where asked for: each differentiated signal gets its
/// rate as `<signal>_dot` (which identification then takes as the target), and a figure.
fn prepare_runs(
    cmd: &IdentifyCommand,
    frames: Vec<Frame>,
    signals: &[String],
    model: Option<&termid::model::Model>,
    method: &dyn Differentiator,
    scale: &dyn Fn(&str) -> (f64, String),
) -> Result<Vec<Frame>> {
    let plugin = termid::plugins::with_derivative(&cmd.derivative);
    if cmd.resample.is_none() && !cmd.smooth && cmd.prepared_svg.is_none() && plugin.is_none() {
        return Ok(frames);
    }
    let prepared = if let Some(plugin) = plugin {
        // a plug-in's preparation (the ship's tracking filter: all states of a run at once)
        let Some(model) = model else {
            bail!("--derivative {} needs a --model", cmd.derivative);
        };
        frames
            .iter()
            .map(|f| {
                let f = match cmd.resample {
                    Some(dt) => resample(f, dt)?,
                    None => f.clone(),
                };
                Ok(plugin.prepare(&cmd.derivative, model, &f, cmd.smooth)?)
            })
            .collect::<Result<Vec<_>>>()?
    } else {
        let how =
            Preparation { resample: cmd.resample, method, signals: signals.to_vec(), smooth: cmd.smooth };
        frames.iter().map(|f| prepare(f, &how)).collect::<Result<Vec<_>, _>>()?
    };
    if let Some(dir) = &cmd.prepared_svg {
        let mut outputs = termid::output::Outputs::new();
        outputs.folder(dir)?;
        for (k, (raw, p)) in frames.iter().zip(&prepared).enumerate() {
            let stem = std::path::Path::new(raw.origin())
                .file_stem()
                .map_or(format!("run{k}"), |s| s.to_string_lossy().into_owned());
            let path = dir.join(format!("prepared_{k}_{stem}.svg"));
            let svg =
                termid::plot::prepared_figure(raw, p, signals, scale).to_svg().map_err(anyhow::Error::msg)?;
            outputs.file(&path, svg.as_bytes())?;
        }
        outputs.commit()?;
    }
    Ok(prepared)
}

fn configure_backend(cmd: &IdentifyCommand) -> Result<Backend> {
    let mut backend = Backend::from(cmd.backend.unwrap_or(BackendName::Stepwise));
    // the stepwise stop and step-rule options do not apply to the other back-ends
    if let Backend::Stepwise(s) = &mut backend {
        s.min_proportion = cmd.min_proportion;
        s.step_rule = match cmd.step_rule {
            RuleName::FMax => StepRule::FirstFMaximum { tolerance: cmd.step_tolerance },
            RuleName::SePlateau => StepRule::StandardErrorPlateau { tolerance: cmd.step_tolerance },
            RuleName::Last => StepRule::Last,
        };
    }
    Ok(backend)
}

/// `identify --model M --moments FILES`: equations identified from merged statistics, as
/// from the runs they were computed on (no residual pass: no correlation time, no checks).
fn run_moments(cmd: IdentifyCommand) -> Result<()> {
    let path = cmd.model.clone().context("--model")?;
    if let Some(out) = &cmd.out {
        termid::output::check_file(out)?;
    }
    let mut model = termid::plugins::load(&path)?;
    if cmd.backend.is_some() {
        model = model.with_backend(&configure_backend(&cmd)?)?;
    }
    let intercept = intercept_of(&cmd, model.spec().model.intercept);
    let (mut model, fits) = crate::moments::identify(&model, &cmd.moments, &cmd.equation, intercept)?;
    if let Some(out) = &cmd.out {
        let sources = cmd.moments.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ");
        model.set_provenance(format!(
            "identified by termid from the statistics {sources} ({})",
            model.spec().model.provenance
        ));
        termid::output::write_file(out, model.to_toml().as_bytes())?;
    }
    match cmd.format {
        Format::Json => {
            let all: serde_json::Map<String, serde_json::Value> = fits
                .iter()
                .map(|(n, f)| Ok((n.clone(), serde_json::to_value(f.report())?)))
                .collect::<Result<_>>()?;
            println!("{}", serde_json::to_string_pretty(&all)?);
        }
        Format::Text => {
            for (name, fit) in &fits {
                println!("== {name} ==");
                print!("{}", fit.text());
                println!();
            }
            if let Some(out) = &cmd.out {
                println!("wrote {}", out.display());
            }
        }
    }
    Ok(())
}

/// Files together larger than this are read in pieces by `identify --model` where they can be.
const WHOLE_LIMIT: u64 = 256 << 20;

/// Rows a piece when `--chunk-rows` is not given.
const PIECE_ROWS: usize = 262_144;

/// Whether `identify --model` reads its runs in pieces, and in how many rows: asked for with
/// `--chunk-rows`, or files beyond [`WHOLE_LIMIT`] where nothing needs whole runs.
fn in_pieces(cmd: &IdentifyCommand, refine: bool) -> Result<Option<usize>> {
    let local = differentiator(&cmd.derivative).ok().and_then(|d| d.reach()).is_some();
    let whole_runs_needed = [
        (cmd.dataset.is_some(), "--dataset"),
        (cmd.resample.is_some(), "--resample"),
        (cmd.smooth, "--smooth"),
        (cmd.prepared_svg.is_some(), "--prepared-svg"),
        (refine, "--refine"),
        (cmd.choose.is_some(), "--choose"),
        (cmd.target.is_some(), "--target"),
        (!local, "a --derivative that needs whole runs"),
    ];
    let needs: Vec<&str> = whole_runs_needed.iter().filter(|(yes, _)| *yes).map(|(_, what)| *what).collect();
    match cmd.chunk_rows {
        Some(0) => Ok(None),
        Some(_) if !needs.is_empty() => bail!(
            "--chunk-rows reads runs in pieces, which {} cannot work on: leave it out",
            needs.join(", ")
        ),
        Some(rows) => Ok(Some(rows)),
        None => {
            let size: u64 = cmd.data.iter().filter_map(|p| std::fs::metadata(p).ok()).map(|m| m.len()).sum();
            if size > WHOLE_LIMIT && needs.is_empty() {
                eprintln!(
                    "note: the runs are {} MiB together: read in pieces of {PIECE_ROWS} rows (bounded memory; --chunk-rows 0 reads them whole)",
                    size >> 20
                );
                Ok(Some(PIECE_ROWS))
            } else {
                Ok(None)
            }
        }
    }
}

/// `identify --model` on runs read in pieces: each equation's statistics in one pass over
/// the files (as `termid moments` writes them), identified as `identify --moments` would, and
/// checked (the physical checks at the model's rudder limit: the runs are not kept).
fn identify_in_pieces(cmd: &IdentifyCommand, model: &termid::model::Model, rows: usize) -> Result<Start> {
    let diff = differentiator(&cmd.derivative)?;
    let reach = diff.reach().context("a derivative of fixed reach")?;
    let names: Vec<String> =
        if cmd.equation.is_empty() { model.identifiable() } else { cmd.equation.clone() };
    let runs = cmd
        .data
        .iter()
        .map(|p| termid::data::Chunks::open(p, &model.spec().model.time, rows.max(1), 2 * reach + 2))
        .collect::<Result<Vec<_>, _>>()?;
    let label = format!("statistics of {} in pieces of {rows} rows ({})", names.join(", "), cmd.derivative);
    let (all, notes) = crate::progress::with_spinner(&label, || {
        termid::identify::EquationMoments::of_chunks_each(model, &names, runs, diff.as_ref())
    })?;
    for n in notes {
        eprintln!("unit: {n}");
    }
    let origin = cmd.data.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ");
    let parts = all.into_iter().map(|m| (origin.clone(), m)).collect();
    let identified = termid::identify::identify_from_moments(
        model,
        parts,
        intercept_of(cmd, model.spec().model.intercept),
    )?;
    let checks =
        termid::plugins::of(&identified.model).map(|p| p.checks(&identified.model, &[])).unwrap_or_default();
    Ok(Start {
        derivative: cmd.derivative.clone(),
        model: identified.model,
        fits: identified.fits,
        chosen_text: None,
        refined: None,
        rejected: None,
        refine_error: None,
        checks,
    })
}

/// One start of `identify --model`: the runs prepared by one derivative method, the
/// regression (or the choice among back-ends), the refinement and the physical checks.
struct Start {
    /// The derivative method.
    derivative: String,
    /// The model as it will be written.
    model: termid::model::Model,
    /// The regression's fits, per equation.
    fits: Vec<(String, termid::identify::Fit)>,
    /// The table `--choose` chose from.
    chosen_text: Option<String>,
    /// The refinement kept.
    refined: Option<termid::diagnose::Refined>,
    /// A refinement rejected by the checks, with the checks it lost.
    rejected: Option<(termid::diagnose::Refined, Vec<String>)>,
    /// A refinement that failed.
    refine_error: Option<anyhow::Error>,
    /// The physical checks of `model`.
    checks: Vec<termid::plugin::Check>,
}

impl Start {
    /// What the start is judged by: the re-simulation cost of the model it keeps, on the
    /// validation runs where there are any, else on the training runs.
    fn cost(&self) -> f64 {
        match (&self.refined, &self.rejected) {
            (Some(r), _) => r.validation.map_or(r.cost_after, |v| v.1),
            (None, Some((r, _))) => r.validation.map_or(r.cost_before, |v| v.0),
            _ => f64::INFINITY,
        }
    }

    fn refused(&self) -> usize {
        self.checks.iter().filter(|c| !c.passed && c.refuses).count()
    }
}

/// `identify --model`: every identifiable equation (or the chosen ones) from the runs, each
/// with the model's candidates, forced terms and back-end; optionally written back. Several
/// `--derivative` methods (with `--refine`) are several starts: each prepares the runs its
/// way, is identified and refined, and the one whose refined model re-simulates the runs best
/// (the validation runs where given) is kept — output error finds different local minima from
/// different starts.
fn run_model(cmd: IdentifyCommand) -> Result<()> {
    let path = cmd.model.clone().context("--model")?;
    // outputs that cannot be written are refused before any work
    if let Some(out) = &cmd.out {
        termid::output::check_file(out)?;
    }
    let mut model = termid::plugins::load(&path)?;
    if cmd.backend.is_some() {
        // the command line's back-end (with its stepwise options) replaces the file's
        model = model.with_backend(&configure_backend(&cmd)?)?;
    }
    let refine = cmd.refine.as_deref().map(|list| refine_states(list, &model)).transpose()?;
    let methods: Vec<String> =
        cmd.derivative.split(',').map(str::trim).filter(|m| !m.is_empty()).map(String::from).collect();
    if methods.len() > 1 && refine.is_none() {
        bail!(
            "--derivative {}: several derivative methods are several starts of the output-error refinement, judged by its cost: give --refine too",
            cmd.derivative
        );
    }
    let mut starts = Vec::new();
    let held = match in_pieces(&cmd, refine.is_some())? {
        Some(rows) => {
            starts.push(identify_in_pieces(&cmd, &model, rows)?);
            None
        }
        None => {
            let frames = crate::runs::load_for(&model, &cmd.data, cmd.dataset.as_deref())?;
            let held = cmd
                .refine_validation
                .as_ref()
                .map(|p| crate::runs::load_for(&model, &[], Some(p)))
                .transpose()?;
            for method in &methods {
                let one = IdentifyCommand { derivative: method.clone(), ..cmd.clone() };
                match identify_start(&one, &model, &frames, held.as_deref(), refine.as_ref()) {
                    Ok(s) => starts.push(s),
                    Err(e) if methods.len() > 1 => {
                        eprintln!("warning: the start from --derivative {method} fails: {e:#}")
                    }
                    Err(e) => return Err(e),
                }
            }
            held
        }
    };
    let kept = (0..starts.len())
        .min_by(|&a, &b| {
            let (x, y) = (&starts[a], &starts[b]);
            x.refused().cmp(&y.refused()).then(x.cost().total_cmp(&y.cost()))
        })
        .context("no start could be identified")?;
    if starts.len() > 1 && matches!(cmd.format, Format::Text) {
        print!("{}", starts_table(&starts, kept, held.is_some()));
    }
    // the starts that pass their checks are models the runs cannot tell apart: where they
    // disagree on a manoeuvre the runs did not cover, that prediction is that uncertain
    let plausible: Vec<(&str, &[termid::plugin::Check])> = starts
        .iter()
        .enumerate()
        .filter(|(k, s)| *k == kept || s.refused() == 0)
        .map(|(_, s)| (s.derivative.as_str(), s.checks.as_slice()))
        .collect();
    let at = plausible.iter().position(|(d, _)| *d == starts[kept].derivative).unwrap_or(0);
    let agreement = termid::plugin::disagreement(&plausible, at, STARTS_AGREE);
    for c in agreement.iter().filter(|c| !c.passed) {
        eprintln!("warning: {}", c.line());
    }
    let Start { model: kept_model, fits, chosen_text, refined, rejected, refine_error, mut checks, .. } =
        starts.swap_remove(kept);
    checks.extend(agreement);
    let mut model = kept_model;
    let names_fitted: Vec<String> = fits.iter().map(|(n, _)| n.clone()).collect();
    if matches!(cmd.format, Format::Text) {
        if let Some(text) = &chosen_text {
            print!("{text}");
        }
        if let Some((r, lost)) = &rejected {
            print!("{}", r.text());
            eprintln!(
                "warning: the refinement is rejected: the refined model fails physical checks the regression's passes ({}); the regression's model is kept",
                lost.join("; ")
            );
        }
    }
    // the coefficients in the field's nondimensional form, where it has reference scales
    let primes = termid::plugins::of(&model).and_then(|p| {
        let (length, speed, density) = p.reference(&model)?;
        let rows = termid::model::dimension::nondimensional(&model, length, speed, density).ok()?;
        let named: Vec<(String, termid::model::dimension::Nondimensional)> = rows
            .into_iter()
            .filter(|c| names_fitted.contains(&c.equation))
            .map(|c| {
                let term = model.vocabulary.parse(&c.term).ok();
                let name = term.and_then(|t| p.coefficient_name(&model, &c.equation, &t)).unwrap_or_default();
                (name, c)
            })
            .collect();
        let head = format!(
            "== nondimensional coefficients (prime system: lengths / L, times / (L/U), masses / ρL³ with L = {length} m, U = {speed} m/s, ρ = {density} kg/m³; the equations are accelerations: v̇' = v̇·L/U², ṙ' = ṙ·L²/U²) ==\n{:<10} {:<16} {:<10} {:>14} {:>14}",
            "equation", "term", "name", "coefficient", "prime"
        );
        Some((head, named))
    });
    // checked before anything is written: an equation that used up the rows' degrees of
    // freedom interpolates them, whatever it simulates
    let mut refused: Vec<String> = fits
        .iter()
        .filter(|(_, f)| {
            f.selection.stop == termid::select::Stop::NoDegreesOfFreedom
                && f.selection.chosen_step == f.selection.steps.len()
        })
        .map(|(name, f)| {
            format!(
                "FAIL `{name}`: {} rows for {} terms{}: no degrees of freedom are left, the coefficients interpolate the rows (give more or longer runs, or fewer candidates)",
                f.selection.rows,
                f.selection.terms.len(),
                if f.selection.intercept.is_some() { " and an intercept" } else { "" }
            )
        })
        .collect();
    refused.extend(checks.iter().filter(|c| !c.passed && c.refuses).map(|c| c.line()));
    let write = refused.is_empty() || cmd.keep_unphysical;
    if let Some(out) = cmd.out.as_ref().filter(|_| write) {
        let provenance = format!(
            "identified by termid from {} ({})",
            cmd.data.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "),
            model.spec().model.provenance
        );
        model.set_provenance(provenance);
        termid::output::write_file(out, model.to_toml().as_bytes())?;
    }
    if let Some(e) = refine_error {
        let kept = cmd
            .out
            .as_ref()
            .map_or(String::new(), |o| format!("; {} holds the regression's model", o.display()));
        return Err(e.context(format!("output-error refinement failed{kept}")));
    }
    match cmd.format {
        Format::Json => {
            let mut all: serde_json::Map<String, serde_json::Value> = fits
                .iter()
                .map(|(n, f)| Ok((n.clone(), serde_json::to_value(f.report())?)))
                .collect::<Result<_>>()?;
            if let Some(r) = &refined {
                all.insert("output_error_refinement".into(), serde_json::to_value(r)?);
            }
            if !checks.is_empty() {
                all.insert("physical_checks".into(), serde_json::to_value(&checks)?);
            }
            if let Some((_, rows)) = &primes {
                all.insert("nondimensional".into(), serde_json::to_value(rows)?);
            }
            println!("{}", serde_json::to_string_pretty(&all)?);
        }
        Format::Text => {
            for (name, fit) in &fits {
                println!("== {name} ==");
                print!("{}", fit.text());
                println!();
            }
            if let Some(r) = &refined {
                print!("{}", r.text());
            }
            if let Some((head, rows)) = &primes {
                println!("{head}");
                for (name, c) in rows {
                    println!(
                        "{:<10} {:<16} {:<10} {:>14} {:>14}",
                        c.equation,
                        c.term,
                        name,
                        termid::identify::num(c.value),
                        termid::identify::num(c.prime)
                    );
                }
                println!();
            }
            if !checks.is_empty() {
                println!("== physical checks ==");
                for c in &checks {
                    println!("{}", c.line());
                }
                println!();
            }
            if let Some(out) = cmd.out.as_ref().filter(|_| write) {
                println!("wrote {}", out.display());
            }
        }
    }
    if !refused.is_empty() {
        let what = if cmd.keep_unphysical {
            "written anyway (--keep-unphysical)".to_string()
        } else {
            match &cmd.out {
                Some(out) => format!("not written to {} (--keep-unphysical writes it)", out.display()),
                None => "refused".to_string(),
            }
        };
        if !cmd.keep_unphysical {
            bail!("the identified model fails its checks, {what}:\n  {}", refused.join("\n  "));
        }
        eprintln!("warning: the identified model fails its checks, {what}:\n  {}", refused.join("\n  "));
    }
    Ok(())
}

/// How far (relative) the plausible starts may disagree on a measure of a manoeuvre the runs
/// did not cover before the prediction is flagged as uncertain.
const STARTS_AGREE: f64 = 0.10;

/// The table of starts: each derivative method's costs and checks, the kept one marked.
fn starts_table(starts: &[Start], kept: usize, validation: bool) -> String {
    let num = termid::identify::num;
    let mut out = format!(
        "== starts: one identification per derivative method, each refined; kept: the lowest {} re-simulation cost among those that pass the checks ==\n{:<22} {:>6} {:>16} {:>16} {:>8}\n",
        if validation { "validation runs'" } else { "training runs'" },
        "derivative",
        "terms",
        "regression cost",
        "refined cost",
        "refused"
    );
    for (k, s) in starts.iter().enumerate() {
        let terms: usize =
            s.model.equations().iter().filter(|e| e.identify).map(|e| e.coefficients.len()).sum();
        let (before, after) = match (&s.refined, &s.rejected) {
            (Some(r), _) | (None, Some((r, _))) => match r.validation {
                Some((b, a)) => (b, a),
                None => (r.cost_before, r.cost_after),
            },
            _ => (f64::INFINITY, f64::INFINITY),
        };
        let after = if s.refined.is_some() { num(after) } else { "rejected".into() };
        let mark = if k == kept { "  ← kept" } else { "" };
        out += &format!(
            "{:<22} {terms:>6} {:>16} {after:>16} {:>8}{mark}\n",
            s.derivative,
            num(before),
            s.refused()
        );
    }
    for s in starts {
        let lines: Vec<String> = s.checks.iter().map(|c| c.line()).collect();
        out += &format!("{}:\n  {}\n", s.derivative, lines.join("\n  "));
    }
    out.push('\n');
    out
}

/// One start: the runs prepared with `cmd.derivative`, identified (or chosen among
/// back-ends), refined where asked, and checked.
fn identify_start(
    cmd: &IdentifyCommand,
    model: &termid::model::Model,
    frames: &[Frame],
    held: Option<&[Frame]>,
    refine: Option<&Option<Vec<String>>>,
) -> Result<Start> {
    let names: Vec<String> =
        if cmd.equation.is_empty() { model.identifiable() } else { cmd.equation.clone() };
    if names.is_empty() {
        bail!("{}: no equation has candidate terms, so there is nothing to identify (an equation's `candidates` list them)", model.path);
    }
    let states: Vec<String> =
        names.iter().filter_map(|n| model.equation(n).map(|e| e.state.clone())).collect();
    let diff = derivative_method(cmd)?;
    // angles are read in degrees
    let scale = |name: &str| termid::model::dimension::shown(model.unit(name));
    let frames = prepare_runs(cmd, frames.to_vec(), &states, Some(model), diff.as_ref(), &scale)?;
    // runs that stop the refinement, prepared as the training runs are
    let validation = match held {
        Some(held) => Some(prepare_runs(cmd, held.to_vec(), &states, Some(model), diff.as_ref(), &scale)?),
        None => None,
    };
    if cmd.target.is_some() && names.len() != 1 {
        bail!("--target applies to one equation: name it with --equation");
    }
    let label = format!("identifying {} ({})", names.join(", "), cmd.derivative);
    let how = termid::identify::ModelIdentification {
        equations: names,
        differentiator: diff.as_ref(),
        intercept: intercept_of(cmd, model.spec().model.intercept),
        target: cmd.target.as_deref().map(Target::parse),
    };
    let (identified, chosen_text) = match &cmd.choose {
        None => (
            crate::progress::with_spinner(&label, || {
                termid::identify::identify_model(model, &frames, &how, &mut |_| {})
            })?,
            None,
        ),
        Some(list) => {
            let configurations = backend_variants(model, list)?;
            let prediction = termid::diagnose::Prediction {
                states: match cmd.compare.as_deref().map(|l| refine_states(l, model)).transpose()? {
                    Some(Some(states)) => states,
                    _ => vec![],
                },
                ..Default::default()
            };
            let chosen = crate::progress::with_spinner(
                &format!("choosing by prediction (leave one run out; {})", cmd.derivative),
                || {
                    termid::diagnose::choose_by_prediction(
                        &configurations,
                        &frames,
                        &how,
                        &prediction,
                        &mut |_| {},
                    )
                },
            )?;
            let text = chosen.text();
            (chosen.identified, Some(text))
        }
    };
    let fits = identified.fits;
    let mut model = identified.model;
    let how_refined = RefineHow {
        states: refine.cloned().flatten(),
        intercept: intercept_of(cmd, model.spec().model.intercept),
        prior: cmd.refine_prior,
        validation: validation.as_deref(),
        iterations: cmd.refine_iterations,
    };
    // what the field knows must hold: the plug-in's physical checks of a model
    let checks_of =
        |m: &termid::model::Model| termid::plugins::of(m).map(|p| p.checks(m, &frames)).unwrap_or_default();
    let failing = |checks: &[termid::plugin::Check]| -> Vec<String> {
        checks.iter().filter(|c| !c.passed && c.refuses).map(|c| c.name.clone()).collect()
    };
    // a refinement that fails loses nothing: the regression's model is still written, and
    // the command ends with the refinement's error
    let mut start = Start {
        derivative: cmd.derivative.clone(),
        model: model.clone(),
        fits,
        chosen_text,
        refined: None,
        rejected: None,
        refine_error: None,
        checks: vec![],
    };
    if refine.is_some() {
        match crate::progress::with_spinner(&format!("refining by output error ({})", cmd.derivative), || {
            refine_by_output_error(&model, &frames, &how_refined)
        }) {
            Ok(r) => {
                // a refinement must not make a model fail what its field knows it passed
                let (before, after) = (checks_of(&model), checks_of(&r.model));
                let was = failing(&before);
                let lost: Vec<String> = failing(&after).into_iter().filter(|c| !was.contains(c)).collect();
                if lost.is_empty() {
                    model = r.model.clone();
                    start.checks = after;
                    start.refined = Some(r);
                } else {
                    start.checks = before;
                    start.rejected = Some((r, lost));
                }
            }
            Err(e) => start.refine_error = Some(e),
        }
    } else {
        start.checks = checks_of(&model);
    }
    if start.checks.is_empty() && start.refine_error.is_some() {
        start.checks = checks_of(&model);
    }
    start.model = model;
    Ok(start)
}

/// `identify --refine`: every identified coefficient refined by output error on the runs as
/// they were prepared for the regression (smoothed initial states: a noisy first sample of a
/// rate would otherwise drift through its integral).
/// `--choose`: the configurations to choose from — a back-end's name (the model with that
/// back-end in every identified equation) or a model file (another candidate library, step
/// rule or set of forced terms for the same equations).
fn backend_variants(model: &termid::model::Model, list: &str) -> Result<Vec<(String, termid::model::Model)>> {
    let names: Vec<&str> = if list.trim() == "all" {
        Backend::NAMES.to_vec()
    } else {
        list.split(',').map(str::trim).filter(|n| !n.is_empty()).collect()
    };
    if names.is_empty() {
        bail!("--choose `{list}` names no back-end or model file (back-ends: {})", Backend::NAMES.join(", "));
    }
    names
        .into_iter()
        .map(|name| {
            if name.ends_with(".toml") {
                let variant = termid::plugins::load(std::path::Path::new(name))?;
                for e in model.identifiable() {
                    if variant.equation(&e).is_none() {
                        bail!("--choose: {name} has no equation `{e}` of {}", model.path);
                    }
                }
                return Ok((name.to_string(), variant));
            }
            let backend = Backend::by_name(name).map_err(|e| anyhow::anyhow!("--choose: {e}"))?;
            Ok((name.to_string(), model.with_backend(&backend)?))
        })
        .collect()
}

/// The states `--refine` names (`None`: all), each checked to be one of the model's.
fn refine_states(list: &str, model: &termid::model::Model) -> Result<Option<Vec<String>>> {
    if list.trim() == "all" {
        return Ok(None);
    }
    let known: Vec<&str> = model.spec().states.iter().map(|s| s.name.as_str()).collect();
    let names: Vec<String> =
        list.split(',').map(str::trim).filter(|n| !n.is_empty()).map(String::from).collect();
    if names.is_empty() {
        bail!("--refine `{list}` names no state: list the states to compare, e.g. --refine u,v,r, or `all`");
    }
    if let Some(name) = names.iter().find(|n| !known.contains(&n.as_str())) {
        bail!("--refine {list}: `{name}` is not a state of the model ({})", known.join(", "));
    }
    Ok(Some(names))
}

/// How `--refine` refines.
struct RefineHow<'a> {
    /// The compared states (`None`: all).
    states: Option<Vec<String>>,
    intercept: bool,
    /// Weight of the regression's estimates as a prior.
    prior: f64,
    /// Prepared runs that stop it.
    validation: Option<&'a [Frame]>,
    /// Most iterations.
    iterations: usize,
}

fn refine_by_output_error(
    model: &termid::model::Model,
    frames: &[Frame],
    how: &RefineHow<'_>,
) -> Result<termid::diagnose::Refined> {
    let runs_of = |frames: &[Frame]| -> Result<termid::diagnose::Runs> {
        let sample = frames.iter().map(|f| termid::data::median_step(f.time())).fold(f64::INFINITY, f64::min);
        // one RK4 step per sample: the recorded input is known only at the samples
        let runs = termid::diagnose::Runs::new(model, frames, sample, termid::sim::Integrator::Rk4)?
            .with_intercepts(how.intercept);
        Ok(match &how.states {
            Some(names) => runs.comparing(names)?,
            None => runs,
        })
    };
    let runs = runs_of(frames)?;
    let validation = how.validation.map(runs_of).transpose()?;
    let settings = termid::diagnose::RefineSettings {
        prior_weight: how.prior,
        validation: validation.as_ref(),
        iterations: how.iterations,
    };
    Ok(termid::diagnose::refine(model, &runs, &settings)?)
}
