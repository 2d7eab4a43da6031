//! `termid diagnose`: where model and measurement disagree, which effect explains it, the
//! model with the effect added, and the gap before and after.

use anyhow::{Context, Result};
use termid::diagnose::{diagnose, Diagnosis, Settings};

use crate::args::{DiagnoseCommand, Format};
use termid::identify::{num, sig};
use termid::model::dimension::shown;

pub fn run(cmd: DiagnoseCommand) -> Result<()> {
    // outputs that cannot be written are refused before any work
    if let Some(out) = &cmd.out {
        termid::output::check_file(out)?;
        let mut inputs = crate::runs::input_files(&cmd.runs.data, &cmd.runs.dataset);
        inputs.extend(cmd.model.iter().map(|m| ("--model".to_string(), m.clone())));
        crate::runs::check_outputs(&[("--out", out)], &inputs)?;
    }
    if let Some(dir) = &cmd.resim.svg {
        termid::output::check_folder(dir)?;
    }
    let mut file = crate::simulate::load_model(&cmd.model)?;
    file.set_tolerances(cmd.resim.rtol, cmd.resim.atol)?;
    let runs = crate::runs::load_for(&file, &cmd.runs.data, cmd.runs.by.as_deref(), &cmd.runs.dataset)?;
    // runs tracked over ground carry the day's current: estimated first with the runs' other
    // nuisances (each run's own values), the model held; the model written is in still water
    let current = crate::runs::medium_to_free(&file, &cmd.runs.dataset, &cmd.runs.hold)?;
    let model = file.freed(&current, &[]).map_err(anyhow::Error::msg)?;
    let hypotheses = termid::plugins::hypotheses(&model);
    let (integrator, dt) = model.resimulation(cmd.resim.integrator, cmd.resim.dt, &runs);
    let settings =
        Settings { dt, integrator, with_intercepts: cmd.resim.with_intercept, ..Settings::default() };
    let label = format!("trying {} hypotheses on {} runs", hypotheses.len(), runs.len());
    let d = crate::progress::with_spinner(&label, || diagnose(&model, &runs, &hypotheses, &settings))
        .context("diagnosing")?;
    let mut outputs = termid::output::Outputs::new();
    if let Some(dir) = &cmd.resim.svg {
        let plane = termid::plugins::of(&model).and_then(|p| p.plane(&model));
        let figures = termid::plot::diagnosis_figures(&model, &d, &runs, plane.as_ref());
        crate::figures::write(&mut outputs, dir, "diagnose", figures)?;
    }
    if let (Some(out), Some(m)) = (&cmd.out, &d.model) {
        outputs.file(out, file.as_declared(m).to_toml().as_bytes())?;
    }
    outputs.commit()?;
    match cmd.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&json(&d))?),
        Format::Text => {
            print!("{}", own_values(&d, &model));
            print!("{}", text(&d, cmd.out.as_deref(), hypotheses.len(), &settings))
        }
    }
    Ok(())
}

fn json(d: &Diagnosis) -> serde_json::Value {
    serde_json::json!({
        "location": d.location,
        "effect": d.winner.map(|w| {
            let c = &d.candidates[w];
            serde_json::json!({"name": c.name, "terms": c.effect, "coefficients": c.estimate, "std_errors": c.std_error,
                               "explained": c.explained, "delta_bic": c.delta_bic})
        }),
        "kept": d.model.is_some(),
        "rejected": d.rejected,
        "gap_before": d.gap_before,
        "gap_after": d.gap_after,
        "candidates": d.candidates,
        "own_values": d.own_values,
        "one_value": d.one_value,
    })
}

/// The nuisances of each run or source the model file declares, as estimated before the
/// diagnosis (each in its unit, angles in degrees): one line each, or nothing.
fn own_values(d: &Diagnosis, model: &termid::model::Model) -> String {
    let mut s = String::new();
    let mut names: Vec<&str> = d.own_values.iter().map(|p| p.name.as_str()).collect();
    names.dedup();
    for name in names {
        let (f, unit) = shown(model.unit(name));
        let unit = termid::model::dimension::after_number(&unit);
        let values: Vec<f64> = d.own_values.iter().filter(|p| p.name == name).map(|p| p.value * f).collect();
        let (lo, hi) =
            values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(*v), b.max(*v)));
        let range = match values.len() {
            1 => format!("{}{unit}", sig(lo, 3)),
            n => format!("{n} values from {}{unit} to {}{unit}", sig(lo, 3), sig(hi, 3)),
        };
        s += &format!(
            "{name}, which the model file declares of each run or source, estimated first with the rest of the model held: {range}; each run is diagnosed with its own\n"
        );
    }
    for r in &d.one_value {
        let (f, unit) = shown(model.unit(&r.name));
        let unit = termid::model::dimension::after_number(&unit);
        s += &format!(
            "{}, which the model file declares of each run or source, agrees over the runs (their mean {}{unit}): estimated once for all first, the rest of the model held\n",
            r.name,
            sig(r.mean * f, 3)
        );
    }
    if !s.is_empty() {
        s += "\n";
    }
    s
}

fn text(d: &Diagnosis, out: Option<&std::path::Path>, tested: usize, settings: &Settings) -> String {
    let mut s = format!("where: {}\n\n", d.location.words);
    s += &format!("{tested} hypotheses tested (output error, recorded inputs replayed); best first: by ΔBIC, and among those that explain nearly as much as the best, the model's own candidate terms first:\n");
    s += &format!("{:<58} {:>10} {:>12}  estimate ± std. error\n", "hypothesis", "explained", "ΔBIC");
    for c in d.candidates.iter().take(8) {
        let mut est: Vec<String> = c
            .estimate
            .iter()
            .zip(&c.std_error)
            .map(|(e, se)| format!("{} ± {}", num(*e), num(*se)))
            .collect();
        // a term beyond the candidates: its own coefficient, the refitted ones counted
        if let termid::diagnose::Effect::Beyond { equation, refitted, .. } = &c.effect {
            est.truncate(1);
            est.push(format!("{equation}'s {} coefficients refitted", refitted.len()));
        }
        s += &format!(
            "{:<58} {:>9.1}% {:>12.1}  {}\n",
            c.name,
            100.0 * c.explained,
            c.delta_bic,
            est.join(", ")
        );
    }
    s += "\n";
    match d.winner {
        Some(w) => {
            let c = &d.candidates[w];
            s += &format!("verdict: {} explains {:.1} % of the gap", c.name, 100.0 * c.explained);
            if let Some(r) = d.candidates.get(w + 1) {
                s += &format!(" (runner-up: {}, {:.1} %)", r.name, 100.0 * r.explained);
            }
            s += ".\n";
            // what no effect closes, said where it is a good part of the gap
            if d.noise >= 0.05 {
                let share = match d.noise >= termid::diagnose::NOISE_AT_MOST - 1e-9 {
                    true => "half the gap or more".to_string(),
                    false => format!("{:.0} % of the gap", 100.0 * d.noise),
                };
                s += &format!("  The records' white noise is {share} (no effect closes it).\n");
            }
            // ranked above it, terms beyond the candidates that add too little to the refit
            if w > 0 {
                s += &format!(
                    "  Passed over, ranked above it: {w} term(s) beyond the candidates, each closing less than \
                     {:.0} % of the gap beyond the records' noise and its equation's coefficients refitted alone \
                     (`beyond_refit`): they fit what the refit leaves.\n",
                    100.0 * settings.min_explained
                );
            }
        }
        None => {
            s += "verdict: no hypothesis explains the gap significantly; the model is left unchanged.\n";
            // a best effect the data do hold but which closes too little of the gap: the cause
            // is not among those tested
            if let Some(c) = d.candidates.first().filter(|c| c.delta_bic <= -settings.min_bic_drop) {
                s += &format!(
                    "  The best, {}, is supported by the runs (ΔBIC {:.1}) but closes only {:.1} % of the gap \
                     (at least {:.0} % to be the missing effect): the missing effect is none of those tested.\n",
                    c.name,
                    c.delta_bic,
                    100.0 * c.explained,
                    100.0 * settings.min_explained
                );
            }
        }
    }
    s += &format!(
        "\n{:<8} {:>16} {:>16} {:>16} {:>16}\n",
        "state", "RMS before", "RMS after", "max before", "max after"
    );
    // each state in its unit, angles in degrees
    let unit_of = |state: &str| {
        let unit = d.gap_before.states.iter().find(|x| x.0 == state).map_or("", |x| x.1.as_str());
        shown(unit)
    };
    for (b, a) in d.gap_before.states.iter().zip(&d.gap_after.states) {
        let (f, unit) = unit_of(&b.0);
        s += &format!(
            "{:<8} {:>16} {:>16} {:>16} {:>16}  [{unit}]\n",
            b.0,
            sig(b.2 * f, 3),
            sig(a.2 * f, 3),
            sig(b.3 * f, 3),
            sig(a.3 * f, 3),
        );
    }
    s += "\nper run (RMS before → after):\n";
    for ((run, b), (_, a)) in d.gap_before.runs.iter().zip(&d.gap_after.runs) {
        let cells: Vec<String> = b
            .iter()
            .zip(a)
            .map(|(x, y)| {
                let (f, unit) = unit_of(&x.0);
                format!("{} {} → {} {unit}", x.0, sig(x.1 * f, 3), sig(y.1 * f, 3))
            })
            .collect();
        s += &format!("  {run}: {}\n", cells.join(", "));
    }
    if let (Some(p), Some(_)) = (out, &d.model) {
        s += &format!("\nwrote {} (the original is unchanged)\n", p.display());
    }
    if let Some(worse) = &d.rejected {
        let (f, unit) = unit_of(&d.location.leading_state);
        let runs: Vec<String> = worse
            .iter()
            .map(|(r, b, a)| format!("{r}: {} → {} {unit}", sig(b * f, 3), sig(a * f, 3)))
            .collect();
        s += &format!(
            "
warning: the repair was not kept{}: it makes the error of {}, the gap it was found for, grow on {} of {} runs ({}). The effect may be real but not alone, or the runs disagree; look at the runs it worsens.\n",
            if out.is_some() { " and nothing was written" } else { "" },
            d.location.leading_state,
            worse.len(),
            d.gap_before.runs.len(),
            runs.join("; ")
        );
    }
    s
}
