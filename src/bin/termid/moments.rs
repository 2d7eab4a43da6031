//! `termid moments`: an equation's sufficient statistics over a shard of runs, written for
//! `identify --moments` to merge (the one pass over the rows done where the rows are); and
//! `identify --model` on runs too large to read whole, by the same pass.

use anyhow::{bail, Context, Result};
use termid::data::{differentiator, Chunks};
use termid::identify::EquationMoments;
use termid::recipe::Start;

use crate::args::MomentsCommand;
use crate::args::{Format, IdentifyCommand};

pub fn run(cmd: MomentsCommand) -> Result<()> {
    termid::output::check_file(&cmd.out)?;
    let mut inputs = crate::runs::input_files(&cmd.data, &cmd.dataset);
    crate::runs::check_once(&inputs)?;
    inputs.push(("--model".into(), cmd.model.clone()));
    crate::runs::check_outputs(&[("--out", &cmd.out)], &inputs)?;
    let model = termid::plugins::load(&cmd.model)?;
    let diff = differentiator(&cmd.derivative)?;
    let moments = match diff.reach() {
        // plain files with a local derivative: read in pieces, one pass, bounded memory
        Some(reach) if cmd.chunk_rows > 0 && cmd.dataset.is_empty() && cmd.by.is_none() => {
            let runs = cmd
                .data
                .iter()
                .map(|p| Chunks::open(p, &model.spec().model.time, cmd.chunk_rows, 2 * reach + 2))
                .collect::<Result<Vec<_>, _>>()?;
            crate::runs::say_units(&cmd.data, &model.spec().model.time);
            let (moments, notes) = EquationMoments::of_chunks(&model, &cmd.equation, runs, diff.as_ref())?;
            for n in notes {
                crate::runs::say(&n);
            }
            moments
        }
        _ => {
            let frames = crate::runs::load_for(&model, &cmd.data, cmd.by.as_deref(), &cmd.dataset)?;
            EquationMoments::of_runs(&model, &cmd.equation, &frames, diff.as_ref(), None)?
        }
    };
    termid::output::write_file(&cmd.out, moments.to_json().as_bytes())?;
    let rows: usize = moments.runs.iter().map(|r| r.moments.count()).sum();
    println!(
        "wrote {}: `{}` ({}), {} candidates over {} run(s), {rows} rows",
        cmd.out.display(),
        moments.equation,
        moments.target,
        moments.candidates.len(),
        moments.runs.len()
    );
    Ok(())
}

/// `identify --moments`: the statistics files read, then merged per equation (in the order
/// given), identified by the library and checked.
pub fn identify(
    model: &termid::model::Model,
    files: &[std::path::PathBuf],
    equations: &[String],
    intercept: bool,
) -> Result<(termid::identify::IdentifiedModel, Vec<termid::plugin::Check>)> {
    let parts = files
        .iter()
        .map(|path| {
            let text =
                termid::budget::read_json(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
            let origin = path.display().to_string();
            Ok((origin.clone(), EquationMoments::from_json(&text, &origin)?))
        })
        .collect::<Result<Vec<_>>>()?;
    // --equation picks among the statistics; each one named must have some
    for eq in equations {
        if model.equation(eq).is_none() {
            anyhow::bail!(
                "--equation {eq}: {} has no equation `{eq}` (equations: {})",
                model.path,
                model.identifiable().join(", ")
            );
        }
        if !parts.iter().any(|(_, m)| &m.equation == eq) {
            anyhow::bail!("--equation {eq}: none of the --moments files holds statistics of `{eq}`");
        }
    }
    let parts: Vec<_> =
        parts.into_iter().filter(|(_, m)| equations.is_empty() || equations.contains(&m.equation)).collect();
    let merged = termid::identify::merged_by_equation(parts)?;
    identified_and_checked(model, merged, intercept, &[])
}

/// The model identified from each equation's merged statistics, with the checks a model of no
/// field's takes from them and from the runs as kept (`runs`, if any; a field's model, its own
/// physical checks).
fn identified_and_checked(
    model: &termid::model::Model,
    merged: Vec<EquationMoments>,
    intercept: bool,
    runs: &[termid::data::Frame],
) -> Result<(termid::identify::IdentifiedModel, Vec<termid::plugin::Check>)> {
    let identified = termid::identify::identify_from_merged(model, &merged, intercept)?;
    let checks = match termid::plugins::of(&identified.model) {
        Some(plugin) => plugin.checks(&identified.model, &[]),
        None => termid::recipe::moments_checks(&identified, &merged, model, intercept, runs),
    };
    Ok((identified, checks))
}

/// `identify --model M --moments FILES`: equations identified from merged statistics, as
/// from the runs they were computed on (no residual pass: no correlation time), checked as
/// statistics allow (their halves, their noise; not whether they retrace the runs).
pub fn identify_from_files(cmd: IdentifyCommand) -> Result<()> {
    let path = cmd.model.clone().context("--model")?;
    if let Some(out) = &cmd.out {
        termid::output::check_file(out)?;
    }
    let mut model = termid::plugins::load(&path)?;
    if cmd.backend.is_some() {
        model = model.with_backend(&crate::identify::configure_backend(&cmd)?)?;
    }
    let intercept = crate::identify::intercept_of(&cmd, model.spec().model.intercept);
    let (identified, checks) = crate::moments::identify(&model, &cmd.moments, &cmd.equation, intercept)?;
    let (mut model, fits) = (identified.model, identified.fits);
    if termid::plugins::of(&model).is_none() {
        // what runs read whole are checked for and statistics cannot be: said, not passed over
        crate::runs::say(
            "whether the equations retrace their runs is not checked: the statistics hold no rows (`termid validate --model <out> --data <the runs>` re-simulates them)",
        );
    }
    if let Some(out) = &cmd.out {
        let sources = cmd.moments.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ");
        model.mark_identified(&format!("the statistics {sources}"));
        termid::output::write_file(out, model.to_toml().as_bytes())?;
    }
    match cmd.format {
        Format::Json => {
            let mut all: serde_json::Map<String, serde_json::Value> = fits
                .iter()
                .map(|(n, f)| Ok((n.clone(), serde_json::to_value(f.report())?)))
                .collect::<Result<_>>()?;
            if !checks.is_empty() {
                // (the key a recipe's report gives every check)
                all.insert("physical_checks".into(), serde_json::to_value(&checks)?);
            }
            println!("{}", serde_json::to_string_pretty(&all)?);
        }
        Format::Text => {
            for (name, fit) in &fits {
                println!("== {name} ==");
                print!("{}", fit.text());
                println!();
            }
            if !checks.is_empty() {
                let physical = termid::plugins::of(&model).is_some();
                println!("{}", if physical { "== physical checks ==" } else { "== checks ==" });
                for c in &checks {
                    println!("{}", c.line());
                }
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
pub fn in_pieces(cmd: &IdentifyCommand, refine: bool) -> Result<Option<usize>> {
    let local = differentiator(&cmd.derivative).ok().and_then(|d| d.reach()).is_some();
    let whole_runs_needed = [
        (!cmd.dataset.is_empty(), "--dataset"),
        (cmd.by.is_some(), "--by"),
        (cmd.resample.is_some(), "--resample"),
        (cmd.smooth, "--smooth"),
        (cmd.prepared_svg.is_some(), "--prepared-svg"),
        (refine, "--refine"),
        // (the stage by default comes with --refine, above)
        (cmd.parameters || !cmd.per_source.is_empty() || !cmd.per_run.is_empty(), "--parameters"),
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
/// checked (the physical checks at the model's rudder limit; a model of no field's on the
/// runs as kept, averaged to at most 20 000 rows, and on its statistics).
pub fn identify_in_pieces(cmd: &IdentifyCommand, model: &termid::model::Model, rows: usize) -> Result<Start> {
    let diff = differentiator(&cmd.derivative)?;
    let reach = diff.reach().context("a derivative of fixed reach")?;
    let names: Vec<String> =
        if cmd.equation.is_empty() { model.identifiable() } else { cmd.equation.clone() };
    // a model made from columns of variables far from 0: its library about reference values
    // read from the first piece (a mean within a few spreads serves, and a whole pass would
    // read the files twice)
    let (model, note) = match (model.outline(), cmd.data.first()) {
        (Some(_), Some(first)) => {
            match termid::data::Chunks::open(first, &model.spec().model.time, rows.max(1), 0)?.next() {
                Some(piece) => model.about_references(&[piece?.frame])?,
                None => (model.clone(), None),
            }
        }
        _ => (model.clone(), None),
    };
    let model = &model;
    let runs = cmd
        .data
        .iter()
        .map(|p| termid::data::Chunks::open(p, &model.spec().model.time, rows.max(1), 2 * reach + 2))
        .collect::<Result<Vec<_>, _>>()?;
    crate::runs::say_units(&cmd.data, &model.spec().model.time);
    let label = format!("statistics of {} in pieces of {rows} rows ({})", names.join(", "), cmd.derivative);
    let pieces = crate::progress::with_spinner(&label, || {
        termid::identify::EquationMoments::of_chunks_each(model, &names, runs, diff.as_ref())
    })?;
    for n in &pieces.notes {
        crate::runs::say(n);
    }
    let intercept = crate::identify::intercept_of(cmd, model.spec().model.intercept);
    let (identified, checks) = identified_and_checked(model, pieces.moments, intercept, &pieces.runs)?;
    let mut fits = identified.fits;
    for (_, fit) in &mut fits {
        fit.selection.notes.extend(note.clone());
    }
    Ok(Start {
        derivative: cmd.derivative.clone(),
        model: identified.model,
        fits,
        chosen_text: None,
        refined: None,
        rejected: None,
        refine_error: None,
        parameters: None,
        late: vec![],
        checks,
        prepared: vec![],
    })
}
