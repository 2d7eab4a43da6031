//! Measured runs from `--data` files (CSV, model names, SI) and/or a `--dataset` file (own
//! column names and units); every unit conversion is stated on standard error.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use termid::data::{Dataset, Frame};
use termid::model::Model;

/// The runs of a command with a model: as [`load`], then each dataset mapping checked to name
/// one of the model's variables and each run checked against the model's known kinematics.
pub fn load_for(
    model: &Model,
    data: &[PathBuf],
    by: Option<&str>,
    datasets: &[PathBuf],
) -> Result<Vec<Frame>> {
    for path in datasets {
        let ds = Dataset::load(path)?;
        let known = model.data_names();
        if let Some(var) = ds.columns.keys().find(|v| !known.contains(v)) {
            bail!(
                "{}: `columns.{var}` maps a column onto `{var}`, which is not a variable of {} (states, inputs, parameters: {}); a record only some models name goes under [extra]",
                path.display(),
                model.path,
                model.vocabulary.variables().iter().chain(model.vocabulary.parameters()).cloned().collect::<Vec<_>>().join(", ")
            );
        }
    }
    let mut frames = load(data, by, datasets, &model.spec().model.time)?;
    for f in &mut frames {
        for note in model.admit(f)? {
            say(&note);
        }
    }
    let (frames, notes) = model.cut_at_breaks(frames)?;
    notes.iter().for_each(|n| say(n));
    let (frames, notes) = model.estimated_rates(frames)?;
    notes.iter().for_each(|n| say(n));
    // a per-run rule that reads one sample of a noisy record: said once, for the first such run
    for (name, rule) in model.parameter_rules() {
        let noisy: Vec<String> = frames.iter().filter_map(|f| rule.noisy_first_sample(&name, f)).collect();
        if let Some(first) = noisy.first() {
            eprintln!("warning: {first} ({} of {} runs so)", noisy.len(), frames.len());
        }
    }
    Ok(frames)
}

/// The runs of a command with a model, each with its source: every `--dataset` file a source
/// of its own (a basin, a campaign), the `--data` files together another, in the order
/// [`source_labels`] names them.
pub fn load_sources(
    model: &Model,
    data: &[PathBuf],
    by: Option<&str>,
    datasets: &[PathBuf],
) -> Result<(Vec<Frame>, Vec<usize>)> {
    check_once(&input_files(data, datasets))?;
    let (mut frames, mut sources) = (Vec::new(), Vec::new());
    let data_source = (!data.is_empty()).then_some((data, &[][..]));
    let dataset_sources = datasets.iter().map(|d| (&[][..], std::slice::from_ref(d)));
    for (k, (data, datasets)) in data_source.into_iter().chain(dataset_sources).enumerate() {
        let more = load_for(model, data, by, datasets)?;
        sources.extend(std::iter::repeat_n(k, more.len()));
        frames.extend(more);
    }
    Ok((frames, sources))
}

/// The dataset files whose runs are tracked over ground (by a satellite receiver): their velocities
/// carry the current the body moves in.
pub fn over_ground(datasets: &[PathBuf]) -> Vec<String> {
    datasets
        .iter()
        .filter(|d| Dataset::load(d).is_ok_and(|d| d.over_ground()))
        .map(|d| d.display().to_string())
        .collect()
}

/// Where `datasets` track the runs by satellite fixes, a warning that a model without a
/// velocity of the medium (a polynomial one) takes any current they carry for the body's own
/// motion.
pub fn warn_over_ground(datasets: &[PathBuf]) {
    let over = over_ground(datasets);
    if !over.is_empty() {
        eprintln!(
            "warning: the runs of {} are tracked over ground (by a satellite receiver): their velocities carry any current the ship moved in, which a model that reads them and declares no current (`medium = true`) takes for the ship's own motion, every term biased by it (a grey-box model from `termid new-ship` declares one, which `termid estimate` estimates with the ship)",
            over.join(", ")
        );
    }
}

/// The dataset files that track their runs over ground, and the model's held velocity of the
/// medium (a current) but those `hold` names, which must be among them: no names where no
/// dataset is tracked over ground.
fn medium_over_ground(
    model: &Model,
    datasets: &[PathBuf],
    hold: &[String],
) -> Result<(Vec<String>, Vec<String>)> {
    let medium = model.held_medium();
    if let Some(name) = hold.iter().find(|n| !medium.contains(n)) {
        bail!("--hold {name}: {} declares no velocity of the medium `{name}` (`medium = true`)", model.path);
    }
    let over = over_ground(datasets);
    let names = match over.is_empty() {
        true => vec![],
        false => medium.into_iter().filter(|n| !hold.contains(n)).collect(),
    };
    Ok((over, names))
}

/// Where `datasets` track the runs by satellite fixes, the model's held velocity of the medium
/// (a current) but those `hold` names: to be estimated with the runs' other nuisances, said.
pub fn medium_to_free(model: &Model, datasets: &[PathBuf], hold: &[String]) -> Result<Vec<String>> {
    let (over, names) = medium_over_ground(model, datasets, hold)?;
    if names.is_empty() {
        return Ok(vec![]);
    }
    eprintln!(
        "note: the runs of {} are tracked over ground (by a satellite receiver), so they carry the current they moved in: {} estimated from them first, with the runs' own values, the model held (`--hold {}` keeps the file's value)",
        over.join(", "),
        names.join(", "),
        names.join(",")
    );
    Ok(names)
}

/// Where `datasets` track the runs by satellite fixes, the model's held velocity of the medium
/// (a current; but those `hold` names) estimated alone from them, the model held
/// (`termid::diagnose::medium`), and said: each run's value, as `Runs::with_initial` takes
/// them. Empty where there is none to estimate.
pub fn medium_of_runs(
    model: &Model,
    frames: &[Frame],
    sources: &[usize],
    datasets: &[PathBuf],
    hold: &[String],
) -> Result<Vec<(usize, String, f64)>> {
    let (over, names) = medium_over_ground(model, datasets, hold)?;
    if names.is_empty() {
        return Ok(vec![]);
    }
    let day = match termid::diagnose::medium(model, &names, frames, sources) {
        Ok(Some(day)) => day,
        Ok(None) => return Ok(vec![]),
        Err(e) => {
            eprintln!(
                "warning: the runs of {} are tracked over ground (by a satellite receiver), but the current they moved in could not be estimated ({e}): each run is simulated in the file's {}, which its errors below include",
                over.join(", "),
                names.join(", ")
            );
            return Ok(vec![]);
        }
    };
    let values: Vec<String> = day
        .per_source
        .iter()
        .map(|p| {
            let unit = model.spec().parameters.get(&p.name).map_or("", |q| q.unit.as_str());
            let (value, se) = (termid::identify::sig(p.value, 3), termid::identify::sig(p.std_error, 2));
            format!("{} = {value} ± {se} {unit} ({})", p.name, p.whose())
        })
        .collect();
    eprintln!(
        "note: the runs of {} are tracked over ground (by a satellite receiver), so they carry the current they moved in: estimated alone from them, the model held, each run simulated with it ({}; `--hold {}` keeps the file's value)",
        over.join(", "),
        values.join(", "),
        names.join(",")
    );
    Ok(day.own_values().into_iter().map(|(r, n, v)| (r, n.to_string(), v)).collect())
}

/// The sources of [`load_sources`] as the per-source estimates number them (`source 1: …`),
/// a line each.
pub fn source_labels(data: &[PathBuf], datasets: &[PathBuf]) -> String {
    let data_label = (!data.is_empty()).then(|| "--data".to_string());
    let labels = data_label.into_iter().chain(datasets.iter().map(|d| d.display().to_string()));
    labels.enumerate().map(|(k, label)| format!("source {}: {label}\n", k + 1)).collect()
}

/// Every file a command reads runs from, named as the user named it: the `--data` files, the
/// dataset file and the runs it lists (where it can be read; its errors come later, in their
/// place). For [`termid::output::check_distinct`].
pub fn input_files(data: &[PathBuf], datasets: &[PathBuf]) -> Vec<(String, PathBuf)> {
    let mut out: Vec<(String, PathBuf)> =
        data.iter().map(|p| (format!("--data {}", p.display()), p.clone())).collect();
    for path in datasets {
        out.push((format!("--dataset {}", path.display()), path.to_path_buf()));
        if let Ok(ds) = Dataset::load(path) {
            if let Ok(folder) = ds.folder(path) {
                for r in &ds.runs {
                    out.push((
                        format!("run file {} of {}", r.file.display(), path.display()),
                        folder.join(&r.file),
                    ));
                }
            }
        }
    }
    out
}

/// Refuses outputs that are inputs (or one another) before any work; `outputs` as (flag, path).
pub fn check_outputs(outputs: &[(&str, &Path)], inputs: &[(String, PathBuf)]) -> Result<()> {
    let inputs: Vec<(&str, &Path)> = inputs.iter().map(|(w, p)| (w.as_str(), p.as_path())).collect();
    termid::output::check_distinct(outputs, &inputs)?;
    Ok(())
}

/// Refuses a NAME=VALUE option that names one NAME twice (`--param u0=1 u0=2`): one of the
/// values would be dropped without a word.
pub fn check_names_once(flag: &str, pairs: &[String]) -> Result<()> {
    let names: Vec<&str> =
        pairs.iter().map(|p| p.split_once('=').map_or(p.as_str(), |(n, _)| n).trim()).collect();
    for (k, n) in names.iter().enumerate() {
        if names[..k].contains(n) {
            bail!(
                "{flag} gives `{n}` twice ({}): say each name once",
                pairs
                    .iter()
                    .filter(|p| p.split_once('=').map_or(p.as_str(), |(a, _)| a).trim() == *n)
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    Ok(())
}

/// Refuses a file given twice (by identity): its runs would count twice without a word.
pub fn check_once(inputs: &[(String, PathBuf)]) -> Result<()> {
    for (k, (what, path)) in inputs.iter().enumerate() {
        if let Some((first, _)) = inputs[..k].iter().find(|(_, p)| termid::output::same_file(p, path)) {
            bail!("{what} is the same file as {first}: its runs would be counted twice; give each file once");
        }
    }
    Ok(())
}

/// A recorded run whose inputs are replayed (`simulate -m replay:FILE`, `compare --replay`):
/// refused below two rows, where a replay would take no step and report nothing.
pub fn replay_frame(path: &Path, time: &str) -> Result<Frame> {
    let frame = Frame::read(path, time)?;
    if frame.len() < 2 {
        bail!(
            "{}: a replay needs at least two rows (its inputs over time); it has {}",
            path.display(),
            frame.len()
        );
    }
    Ok(frame)
}

/// The runs of `data` files (each a run, or with `by` the runs its column `by` names) and of
/// `datasets` files, each cut at a logger's dropout, what reading did said.
/// The time column of plain files that have no column `time` (`t`, when no `--time` names
/// another): the one whose name says it holds the time (`time`, `Time [s]`, `timestamp`,
/// `day`), to be taken and said. `None` where `time` is there, or no column or several look
/// like time (the missing time's error names them).
pub fn time_by_name(data: &[PathBuf], time: &str) -> Option<String> {
    let names = termid::data::columns_of(data.first()?).ok()?;
    if termid::data::time_position(&names, time).is_some() {
        return None;
    }
    let mut like = names.iter().filter(|n| termid::data::looks_like_time(n));
    match (like.next(), like.next()) {
        (Some(name), None) => Some(name.clone()),
        _ => None,
    }
}

pub fn load(data: &[PathBuf], by: Option<&str>, datasets: &[PathBuf], time: &str) -> Result<Vec<Frame>> {
    check_once(&input_files(data, datasets))?;
    let mut frames = Vec::new();
    for path in data {
        // a file without the model's time whose one column named as a time is it (`time`,
        // `Time [s]`, `day`): read as the model's, said, as Python reads a dataframe's
        let own = time_by_name(std::slice::from_ref(path), time);
        if let Some(name) = &own {
            say(&format!(
                "{}: the time `{time}` is column `{name}`, the one whose name says it is the time",
                path.display()
            ));
        }
        let column = own.as_deref().unwrap_or(time);
        if let Some(note) = termid::data::units_note(path, column) {
            say(&note);
        }
        let mut runs = match by {
            Some(by) => {
                let (runs, note) = Frame::read_by(path, column, by)?;
                say(&note);
                runs
            }
            None => vec![Frame::read(path, column).map_err(|e| with_remedy(e, path))?],
        };
        if own.is_some() {
            for frame in &mut runs {
                frame.rename(column, time)?;
            }
        }
        if let Some(note) = runs.first().and_then(Frame::text_note) {
            say(&note);
        }
        for frame in runs {
            // a logging dropout would be integrated or differentiated across as if the motion
            // in it were a line: each piece a run (dataset files are cut as they are read)
            let (pieces, notes) = termid::data::cut_at_gaps(frame, 0)?;
            notes.iter().for_each(|n| say(n));
            frames.extend(pieces);
        }
    }
    for path in datasets {
        let ds = Dataset::load(path)?;
        let (more, notes) = ds
            .read(&ds.folder(path)?, time)
            .with_context(|| format!("reading the runs of {}", path.display()))?;
        for n in notes {
            say(&n);
        }
        frames.extend(more);
    }
    if frames.is_empty() {
        bail!("no runs: give --data FILE… or --dataset FILE");
    }
    Ok(frames)
}

/// A time that starts again in a file read as one run: the file's columns of text named as
/// what `--by` would tell its runs apart by.
fn with_remedy(e: termid::data::DataError, path: &Path) -> anyhow::Error {
    if !matches!(e, termid::data::DataError::TimeNotIncreasing { restart: true, .. }) {
        return e.into();
    }
    let remedy = match termid::data::text_columns_of(path).as_slice() {
        [] => "`--by COLUMN` reads each value of a column that names the row's run as a run of its own"
            .to_string(),
        [one] => format!("`--by {one}` reads each value of `{one}` as a run of its own"),
        many => format!("`--by COLUMN` reads each value of one ({}) as a run of its own", many.join(", ")),
    };
    anyhow::anyhow!("{e}; {remedy}")
}

/// Every run's spikes in any of its columns mended ([`termid::data::despiked_all`]), each said:
/// the runs of a command without a model, which cannot tell its states from other columns.
pub fn mend_spikes(frames: &mut [Frame]) -> Result<()> {
    for f in frames {
        if let Some((mended, notes)) = termid::data::despiked_all(f)? {
            *f = mended;
            notes.iter().for_each(|n| say(n));
        }
    }
    Ok(())
}

/// Says what reading each of the plain files `data` in SI does to its headers
/// ([`termid::data::units_note`]), `time` the time column's name.
pub fn say_units(data: &[PathBuf], time: &str) {
    data.iter().filter_map(|p| termid::data::units_note(p, time)).for_each(|n| say(&n));
}

/// Says on standard error what reading a run did to it: a unit conversion as `unit:`, any
/// other change (an alias, a negated column, velocities from the track) as `note:`.
pub fn say(note: &str) {
    let kind = if note.contains(" in SI (×") { "unit" } else { "note" };
    eprintln!("{kind}: {note}");
}
