//! `identify --states`: the model file of a system named by its runs' columns
//! ([`termid::model::Outline`]), which `identify_model` then identifies as it does any file.

use anyhow::{bail, Result};
use termid::data::Dataset;
use termid::model::{Model, Outline};
use termid::term::is_identifier;

use crate::args::IdentifyCommand;

/// The model of the states `--states` names: the inputs `--inputs` names, or every other
/// column of the first file (said); the candidates `--terms`/`--terms-file`, or the
/// polynomial library to `--degree`.
pub fn model(cmd: &IdentifyCommand) -> Result<Model> {
    let (first, columns) = columns(cmd)?;
    // refused before any column is taken for an input (a time column by another name would be)
    let Some(time) = termid::data::time_position(&columns, &cmd.time) else {
        return Err(termid::data::DataError::missing_time(&first, &cmd.time, &columns).into());
    };
    let time = columns[time].clone();
    let column = |name: &str, flag: &str| -> Result<()> {
        if !columns.iter().any(|c| c == name) {
            // a header that carries its unit in brackets is read by its bare name already: this
            // one's is in parentheses and not a unit termid knows (`C (mg/L)`; `f(x)` is a name)
            let headed = columns
                .iter()
                .find(|c| c.strip_prefix(name).is_some_and(|rest| rest.trim_start().starts_with('(')));
            let hint = headed.map_or_else(String::new, |c| {
                format!(
                    "; `{c}` carries in parentheses a unit termid does not know: head it `{name} [unit]` (read as written) or `{name}`"
                )
            });
            bail!("{flag}: `{name}` is not a column of {first} (its columns: {}){hint}", columns.join(", "));
        }
        Ok(())
    };
    // `v=dx/dt`: a state the runs do not record, estimated as the rate of one they do
    let (states, rates) = Outline::states_named(&cmd.states);
    for s in states.iter().filter(|s| !rates.contains_key(*s)) {
        column(s, "--states")?;
    }
    let inputs = match &cmd.inputs {
        Some(named) => {
            // `--inputs ""` (a script's empty list) names none, as `--inputs` alone does
            let named: Vec<String> = named.iter().filter(|i| !i.trim().is_empty()).cloned().collect();
            for i in &named {
                column(i, "--inputs")?;
            }
            named
        }
        None => {
            let dots: Vec<String> = states.iter().map(|s| format!("{s}_dot")).collect();
            let others = columns.iter().filter(|c| {
                **c != time
                    && !states.contains(c)
                    && !dots.contains(c)
                    && Some(c.as_str()) != cmd.by.as_deref()
            });
            let (usable, unnamed): (Vec<&String>, Vec<&String>) = others.partition(|c| is_identifier(c));
            if !unnamed.is_empty() {
                let list: Vec<String> = unnamed.iter().map(|c| format!("`{c}`")).collect();
                eprintln!(
                    "note: {} left out of the inputs: not a name a term can use (a dataset file maps a column onto a name)",
                    list.join(", ")
                );
            }
            if !usable.is_empty() {
                let list: Vec<&str> = usable.iter().map(|c| c.as_str()).collect();
                eprintln!(
                    "note: the inputs are {} (every other column of {first}): --inputs names them, `--inputs` alone takes none",
                    list.join(", ")
                );
            }
            usable.into_iter().cloned().collect()
        }
    };
    // a time headed with its unit (`t [h]`, `Time (ms)`) names the model's time, so that the
    // model is simulated, and writes its runs, in that unit as a `day` model is: named `t`, a
    // study's 24 hours were simulated by `--duration 24` for 24 seconds
    let model_time = match termid::data::seconds_per(&time) {
        Some(per) if per != 1.0 && time != cmd.time => time.clone(),
        _ => cmd.time.clone(),
    };
    let mut outline = Outline {
        name: cmd.states.join(", "),
        time: model_time,
        states,
        rates,
        inputs,
        candidates: Vec::new(),
        degree: cmd.degree.unwrap_or(termid::model::DEFAULT_DEGREE),
        backend: None,
    };
    let origin = format!("--states {}", cmd.states.join(","));
    let vocabulary = outline.vocabulary(&origin)?;
    for t in &cmd.terms {
        vocabulary.parse(t).map_err(|e| anyhow::anyhow!("--terms `{t}`:\n{e}"))?;
    }
    outline.candidates = crate::identify::candidate_texts(cmd, &vocabulary)?;
    Ok(outline.model(&origin)?)
}

/// The first source's name and the names of its columns: a `--data` file's numeric
/// columns, a dataset file's variables.
fn columns(cmd: &IdentifyCommand) -> Result<(String, Vec<String>)> {
    if let Some(path) = cmd.data.first() {
        return Ok((path.display().to_string(), termid::data::columns_of(path)?));
    }
    let Some(path) = cmd.dataset.first() else {
        bail!("--states needs runs: give --data or --dataset");
    };
    let dataset = Dataset::load(path)?;
    let mut names: Vec<String> = vec![cmd.time.clone()];
    names.extend(dataset.columns.keys().cloned());
    Ok((path.display().to_string(), names))
}
