//! `termid identify`: data files + candidate terms → the chosen equation.

use std::collections::BTreeMap;

use anyhow::{bail, Context, Result};
use termid::data::Frame;
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
/// table (a ship: the paper's own), else no derivative at all (whole or in pieces): the
/// weak form ([`termid::recipe::ANY_SYSTEM_DERIVATIVE`]), which recovers polynomial systems
/// from noise-free and noisy samples alike where central differences leave an error that is
/// smooth in the states and that spurious terms then fit (Lorenz at 1 % noise: every equation
/// exact without a derivative, x's with a dozen spurious terms from central differences or the
/// Kalman smoother).
fn resolve_derivative(cmd: &mut IdentifyCommand) -> Result<()> {
    if cmd.derivative != "auto" {
        return Ok(());
    }
    let model = cmd.model.as_ref().and_then(|path| termid::plugins::load(path).ok());
    // the weak form reads in pieces as well as whole (its windows reach a fixed number of
    // samples ahead)
    cmd.derivative = termid::recipe::default_derivative(model.as_ref()).into();
    Ok(())
}

/// Whether the equations fit a forced intercept: the flags, else `default` (a model file's
/// `intercept`; without one, only where the target is not a rate, as in classical regression:
/// for a rate the constant is a candidate term instead).
pub fn intercept_of(cmd: &IdentifyCommand, default: bool) -> bool {
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
    cmd.refuse_conflicts().map_err(anyhow::Error::msg)?;
    // `--terms x,x*y` as `--states x,y` lists names
    cmd.terms = termid::term::listed(&cmd.terms);
    (cmd.forced, cmd.exclude) = (termid::term::listed(&cmd.forced), termid::term::listed(&cmd.exclude));
    resolve_derivative(&mut cmd)?;
    if let Some(dir) = &cmd.prepared_svg {
        termid::output::check_folder(dir)?;
    }
    for (flag, list) in [("--param", &cmd.params), ("--derive", &cmd.derived), ("--alias", &cmd.aliases)] {
        crate::runs::check_names_once(flag, list)?;
    }
    // plain files with a column `time` (or `Time [s]`, `timestamp`) and no `t`, as most
    // loggers and dataframes write them: their time, said, not a refusal to be answered
    if cmd.time == "t" && cmd.model.is_none() && !cmd.no_time {
        if let Some(name) = crate::runs::time_by_name(&cmd.data, &cmd.time) {
            crate::runs::say(&format!(
                "the time is column `{name}` (there is no column `t`; `--time NAME` names another)"
            ));
            cmd.time = name;
        }
    }
    let mut inputs = crate::runs::input_files(&cmd.data, &cmd.dataset);
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
        return crate::moments::identify_from_files(cmd);
    }
    if cmd.model.is_some() || !cmd.states.is_empty() {
        if !(cmd.delays.is_empty() && cmd.lags.is_empty()) && cmd.model.is_some() {
            bail!("--delay and --lag read columns of plain runs earlier or through a lag, or declare them of --states' inputs; with --model declare them in the model file (`delay = SECONDS` or `lag = SECONDS` in the input's [[inputs]] entry), as its simulation needs them too");
        }
        return crate::identify_model::run(cmd);
    }
    if cmd.refine.is_some() {
        bail!("--refine re-simulates the identified equations: it needs a --model that declares them");
    }
    let mut frames = if cmd.no_time {
        let mut frames =
            cmd.data.iter().map(|p| Frame::read_csv_untimed(p)).collect::<Result<Vec<_>, _>>()?;
        if !cmd.dataset.is_empty() {
            frames.extend(crate::runs::load(&[], None, &cmd.dataset, &cmd.time)?);
        }
        frames
    } else {
        // the same reading (and check for gaps in time) as every other command
        crate::runs::load(&cmd.data, cmd.by.as_deref(), &cmd.dataset, &cmd.time)?
    };
    let target = Target::parse(cmd.target.as_deref().unwrap_or_default());
    if !cmd.keep_spikes && is_rate(&target, &frames, cmd.no_time) {
        // the rows are a time series whose rates are taken: a glitch would be one
        crate::runs::mend_spikes(&mut frames)?;
    }
    let late = cmd.delays.iter().map(|d| seconds_of(d, "--delay")).collect::<Result<Vec<_>>>()?;
    let lags = cmd.lags.iter().map(|d| seconds_of(d, "--lag")).collect::<Result<Vec<_>>>()?;
    if let Target::Derivative(state) = &target {
        // every column but the state may be an input held between samples (a late one judged
        // as it acts); any column a slower sensor's readings; the state's leap a cut between
        // runs joined in one file
        let intersample = cmd.intersample.unwrap_or_default();
        let mut runs = Vec::new();
        for f in frames {
            let all: Vec<String> = f.names()[1..].to_vec();
            let all: Vec<&str> = all.iter().map(String::as_str).collect();
            let (cut, notes) = termid::data::runs_of_rate(vec![f], state, &all, &late, &lags, intersample)?;
            notes.iter().for_each(|n| crate::runs::say(n));
            runs.extend(cut);
        }
        frames = runs;
    }
    // after the marking: a held column is read back sample for sample
    for (name, seconds) in &late {
        for f in &mut frames {
            *f = termid::data::delayed(f, name, *seconds, 0.0)?;
        }
    }
    if !lags.is_empty() {
        for f in &mut frames {
            *f = termid::data::lagged(f, &lags, 0.0)?;
        }
    }
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
    let diff = termid::recipe::derivative_method(&cmd.derivative)?;
    if let Target::Derivative(state) = &target {
        let signals = std::slice::from_ref(state);
        let prepared = termid::recipe::prepare_runs(
            &frames,
            signals,
            None,
            &cmd.derivative,
            cmd.resample,
            cmd.smooth,
            cmd.prepared_svg.is_some(),
        )?;
        if let Some(dir) = &cmd.prepared_svg {
            prepared_figures(dir, &frames, &prepared, signals, None)?;
        }
        frames = prepared;
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
    let texts = candidate_texts(&cmd, &vocab)?;
    if texts.is_empty() {
        bail!("no candidate terms: give --terms or --terms-file");
    }
    let candidates = parse_terms(&texts, &vocab)?;
    let forced = parse_terms(&cmd.forced, &vocab)?;
    let excluded = parse_terms(&cmd.exclude, &vocab)?;
    // an ODE's defaults (a rate as target): sequential thresholding, scale-free, and the
    // constant as a candidate like any other rather than a forced intercept
    let ode = is_rate(&target, &frames, cmd.no_time);
    let backend = if ode && cmd.backend.is_none() { Backend::for_rates() } else { configure_backend(&cmd)? };
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
        identification.describe_residuals(&target, &candidates, &frames, &mut fit)?;
        // a column acting later than recorded leaves its mark on the residuals
        if let Target::Derivative(state) = &target {
            let columns: Vec<String> =
                frames[0].names()[1..].iter().filter(|n| *n != state).cloned().collect();
            identification
                .say_delays(&target, &candidates, &frames, &columns, &mut fit, &|l| l.plain_remedy())?;
            // noise on a variable a candidate holds nonlinearly biases the fit itself
            let chosen: Vec<String> = fit.selection.terms.iter().map(|t| t.term.clone()).collect();
            fit.selection.notes.extend(termid::identify::noise_note(&candidates, &chosen, &vocab, &frames));
        }
    }
    match cmd.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&serde_json::to_value(fit.report())?)?),
        Format::Text => print!("{}", fit.text()),
    }
    Ok(())
}

/// The candidate terms of `--terms` and then of `--terms-file` (one a line, `#` a comment),
/// the file's each checked against `vocab` here so that an error names the file and line.
pub fn candidate_texts(cmd: &IdentifyCommand, vocab: &Vocabulary) -> Result<Vec<String>> {
    let mut texts = cmd.terms.clone();
    if let Some(path) = &cmd.terms_file {
        let text = termid::budget::read_text(path).with_context(|| format!("reading {}", path.display()))?;
        for (k, line) in text.lines().enumerate() {
            let term = line.split('#').next().unwrap_or("").trim();
            if term.is_empty() {
                continue;
            }
            vocab.parse(term).map_err(|e| anyhow::anyhow!("{}:{}:\n{e}", path.display(), k + 1))?;
            texts.push(term.to_string());
        }
    }
    Ok(texts)
}

/// A figure per run of each prepared signal against the raw one (angles in degrees where
/// the model says a signal is one), into `dir`.
pub fn prepared_figures(
    dir: &std::path::Path,
    raw: &[Frame],
    prepared: &[Frame],
    signals: &[String],
    model: Option<&termid::model::Model>,
) -> Result<()> {
    let scale = |name: &str| match model {
        Some(m) => termid::model::dimension::shown(m.unit(name)),
        None => (1.0, String::new()),
    };
    let mut outputs = termid::output::Outputs::new();
    outputs.folder(dir)?;
    for (k, (raw, p)) in raw.iter().zip(prepared).enumerate() {
        let stem = std::path::Path::new(raw.origin())
            .file_stem()
            .map_or(format!("run{k}"), |s| s.to_string_lossy().into_owned());
        let path = dir.join(format!("prepared_{k}_{stem}.svg"));
        let svg =
            termid::plot::prepared_figure(raw, p, signals, &scale).to_svg().map_err(anyhow::Error::msg)?;
        outputs.file(&path, svg.as_bytes())?;
    }
    outputs.commit()?;
    Ok(())
}

pub fn configure_backend(cmd: &IdentifyCommand) -> Result<Backend> {
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

/// One `--delay NAME=SECONDS` or `--lag NAME=SECONDS` (`flag`): the column and its dead time
/// or lag, s (0 or more).
pub fn seconds_of<'a>(d: &'a str, flag: &str) -> Result<(&'a str, f64)> {
    let (name, seconds) = split_pair(d, flag)?;
    let seconds: f64 =
        seconds.parse().ok().filter(|s: &f64| s.is_finite() && *s >= 0.0).with_context(|| {
            format!("{flag} `{d}`: `{seconds}` is no time; give seconds, 0 or more (`F=0.2`)")
        })?;
    Ok((name, seconds))
}
