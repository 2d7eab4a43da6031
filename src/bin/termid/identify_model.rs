//! `termid identify --model`: every identifiable equation of a model file from its runs by
//! the library's recipe (`termid::recipe`: starts, choice by prediction, refinement, the
//! model file's free parameters, checks, the starts' agreement); this file reads the command
//! line, prints and writes.

use anyhow::{bail, Context, Result};
use termid::identify::Target;
use termid::recipe::{ParameterOptions, RecipeSettings, RefineOptions};
use termid::select::Backend;

use crate::args::{Format, IdentifyCommand};
use crate::identify::{configure_backend, intercept_of};

/// The parameter stage as the command asks for it: on, off, or as the model file says.
fn asked_parameters(cmd: &IdentifyCommand) -> Option<bool> {
    match (cmd.parameters, cmd.no_parameters) {
        (true, _) => Some(true),
        (_, true) => Some(false),
        _ => None,
    }
}

/// `identify --model`: every identifiable equation (or the chosen ones) from the runs, each
/// with the model's candidates, forced terms and back-end; optionally written back. Several
/// `--derivative` methods (with `--refine`) are several starts: each prepares the runs its
/// way, is identified and refined, and the one whose refined model re-simulates the runs best
/// (the validation runs where given) is kept — output error finds different local minima from
/// different starts.
pub fn run(cmd: IdentifyCommand) -> Result<()> {
    // outputs that cannot be written are refused before any work
    if let Some(out) = &cmd.out {
        termid::output::check_file(out)?;
    }
    let mut model = match &cmd.model {
        Some(path) => crate::simulate::load_model(&Some(path.clone()))?,
        None => crate::outline::model(&cmd)?,
    }
    .keeping_spikes(cmd.keep_spikes)
    .with_intersample(cmd.intersample);
    if !(cmd.delays.is_empty() && cmd.lags.is_empty()) {
        // --states' inputs acting late or through a lag, as a model file would declare them
        let read = |given: &[String], flag: &str| -> Result<Vec<(String, f64)>> {
            let inputs: Vec<String> = model.spec().inputs.iter().map(|i| i.name.clone()).collect();
            given
                .iter()
                .map(|d| {
                    let (name, seconds) = crate::identify::seconds_of(d, flag)?;
                    if !inputs.iter().any(|i| i == name) {
                        bail!("{flag} {name}=…: `{name}` is no input (the inputs: {})", inputs.join(", "));
                    }
                    Ok((name.to_string(), seconds))
                })
                .collect()
        };
        let (delays, lags) = (read(&cmd.delays, "--delay")?, read(&cmd.lags, "--lag")?);
        let of = |given: &[(String, f64)], name: &str| given.iter().find(|(n, _)| n == name).map(|(_, s)| *s);
        model = model.edit(|file| {
            for input in &mut file.inputs {
                input.delay = of(&delays, &input.name).unwrap_or(input.delay);
                input.lag = of(&lags, &input.name).unwrap_or(input.lag);
            }
        })?;
    }
    if !(cmd.forced.is_empty() && cmd.exclude.is_empty()) {
        // the command line's terms join the file's (each equation's that has them)
        let vocabulary = model.vocabulary.clone();
        let parse = |texts: &[String], flag: &str| {
            termid::term::parse_terms(texts, &vocabulary).with_context(|| format!("in {flag}"))
        };
        model = model.with_terms(&parse(&cmd.forced, "--forced")?, &parse(&cmd.exclude, "--exclude")?)?;
    }
    if cmd.backend.is_some() {
        // the command line's back-end (with its stepwise options) replaces the file's
        model = model.with_backend(&configure_backend(&cmd)?)?;
    }
    let refine = cmd.refine.as_deref().map(|list| compared_states("--refine", list, &model)).transpose()?;
    let methods: Vec<String> =
        cmd.derivative.split(',').map(str::trim).filter(|m| !m.is_empty()).map(String::from).collect();
    if methods.len() > 1 && refine.is_none() {
        bail!(
            "--derivative {}: several derivative methods are several starts of the output-error refinement, judged by its cost: give --refine too",
            cmd.derivative
        );
    }
    let recipe = match crate::moments::in_pieces(&cmd, refine.is_some())? {
        Some(rows) => termid::recipe::Recipe::of(
            vec![crate::moments::identify_in_pieces(&cmd, &model, rows)?],
            vec![],
            false,
            STARTS_AGREE,
        )?,
        None => {
            let (frames, sources) =
                crate::runs::load_sources(&model, &cmd.data, cmd.by.as_deref(), &cmd.dataset)?;
            crate::runs::warn_over_ground(&cmd.dataset);
            if let Some(first) = frames.first().filter(|_| cmd.model.is_none()) {
                // a model made from columns: simulated from where the first run starts
                model = model.starting_as(first)?;
            }
            let held = cmd
                .refine_validation
                .as_ref()
                .map(|p| crate::runs::load_for(&model, &[], None, std::slice::from_ref(p)))
                .transpose()?;
            let settings = RecipeSettings {
                equations: cmd.equation.clone(),
                derivatives: methods,
                resample: cmd.resample,
                smooth: cmd.smooth,
                figures: cmd.prepared_svg.is_some(),
                intercept: intercept_of(&cmd, model.spec().model.intercept),
                target: cmd.target.as_deref().map(Target::parse),
                choose: match &cmd.choose {
                    Some(list) => backend_variants(&model, list)?,
                    None => vec![],
                },
                compare: match cmd
                    .compare
                    .as_deref()
                    .map(|l| compared_states("--compare", l, &model))
                    .transpose()?
                {
                    Some(Some(states)) => states,
                    _ => vec![],
                },
                refine: refine.clone().map(|states| RefineOptions {
                    states,
                    prior: cmd.refine_prior,
                    iterations: cmd.refine_iterations,
                    step: cmd.refine_step,
                }),
                agree: STARTS_AGREE,
                parameters: ParameterOptions::asked(
                    &model,
                    asked_parameters(&cmd),
                    refine.is_some(),
                    sources,
                    cmd.per_source.clone(),
                    cmd.per_run.clone(),
                ),
                laws: !cmd.no_laws,
                random_force: !cmd.no_random_force,
                dead_times: !cmd.no_dead_times,
            };
            let label = format!(
                "identifying ({} start{})",
                settings.derivatives.len(),
                if settings.derivatives.len() == 1 { "" } else { "s" }
            );
            let recipe = crate::progress::with_spinner(&label, || {
                termid::recipe::identify(&model, &frames, held.as_deref(), &settings)
            })?;
            if let Some(dir) = &cmd.prepared_svg {
                // the states of the identified equations, as each start prepared them
                let names = if cmd.equation.is_empty() { model.identifiable() } else { cmd.equation.clone() };
                let signals: Vec<String> =
                    names.iter().filter_map(|n| model.equation(n).map(|e| e.state.clone())).collect();
                crate::identify::prepared_figures(
                    dir,
                    &frames,
                    &recipe.kept().prepared,
                    &signals,
                    Some(&model),
                )?;
            }
            recipe
        }
    };
    if recipe.starts.len() > 1 && matches!(cmd.format, Format::Text) {
        print!("{}", recipe.starts_text());
    }
    for why in recipe.warnings() {
        eprintln!("warning: {why}");
    }
    let kept = recipe.kept();
    // checked before anything is written
    let refused = recipe.refusals();
    let write = refused.is_empty() || cmd.keep_unphysical;
    if let Some(out) = cmd.out.as_ref().filter(|_| write) {
        let mut model = kept.model.clone();
        let sources: Vec<String> =
            cmd.data.iter().chain(&cmd.dataset).map(|p| p.display().to_string()).collect();
        model.mark_identified(&sources.join(", "));
        termid::output::write_file(out, model.to_toml().as_bytes())?;
    }
    // a refinement that failed loses nothing: the regression's model is written first
    if let Some(e) = &kept.refine_error {
        let kept = cmd
            .out
            .as_ref()
            .map_or(String::new(), |o| format!("; {} holds the regression's model", o.display()));
        return Err(anyhow::anyhow!("{e}").context(format!("output-error refinement failed{kept}")));
    }
    match cmd.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&recipe.json()?)?),
        Format::Text => {
            print!("{}", recipe.text());
            if kept.parameters.as_ref().and_then(|s| s.estimate()).is_some_and(|e| e.per_source_values()) {
                print!("{}", crate::runs::source_labels(&cmd.data, &cmd.dataset));
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

/// The states `--refine` or `--compare` (`flag`) names (`None`: all), each checked to be one
/// of the model's states or derived variables (compared with the runs' column of its name).
fn compared_states(flag: &str, list: &str, model: &termid::model::Model) -> Result<Option<Vec<String>>> {
    if list.trim() == "all" {
        return Ok(None);
    }
    let names: Vec<String> =
        list.split(',').map(str::trim).filter(|n| !n.is_empty()).map(String::from).collect();
    if names.is_empty() {
        bail!("{flag} `{list}` names no state: list the states to compare, e.g. {flag} u,v,r, or `all`");
    }
    termid::recipe::compared_known(model, &format!("{flag} {list}"), &names)?;
    Ok(Some(names))
}
