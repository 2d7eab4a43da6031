//! An input that acts later than recorded (a dead time the regression's scan found,
//! [`crate::identify::Lag`]) biases every coefficient fitted without it: a first-order plant
//! whose input acts 0.5 s late came back at 1 % noise with gain 0.62 for 0.8 and a spurious x³,
//! every check ok, the delay only in a note. Identified again with the input read that much
//! earlier (its `delay` in the model written, which its simulation feeds it by), the delayed
//! equations are kept where they fail no check the recorded ones pass; either way it is said.

use super::{retrace, Recipe, RecipeError};
use crate::data::{staircase, Frame};
use crate::identify::Lag;
use crate::model::Model;

/// `model` with each of `late`'s inputs acting that much later than it declares (`delay`
/// under its `[[inputs]]`), or through the first-order lag that explains it better (`lag`,
/// where the input declares none); `None` where that changes nothing or the model cannot be so
/// edited.
fn delayed(model: &Model, late: &[Lag]) -> Option<Model> {
    if late.is_empty() {
        return None;
    }
    // a whole number of the mean step, to six figures (the file reads 0.5, not
    // 0.4999999999999716)
    let rounded = |v: f64| format!("{v:.5e}").parse().unwrap_or(v);
    let edited = model
        .edit(|file| {
            for lag in late {
                if let Some(input) = file.inputs.iter_mut().find(|i| i.name == lag.column) {
                    match lag.first_order.filter(|_| input.lag == 0.0) {
                        Some(t) => input.lag = rounded(t),
                        None => input.delay = rounded(input.delay + lag.seconds),
                    }
                }
            }
        })
        .ok()?;
    // (a lag found without a dead time, where the input declares one already, changes nothing)
    (edited.spec().inputs != model.spec().inputs).then_some(edited)
}

/// How late input `name` acts in `model`: its dead time and its lag's time constant.
fn lateness(model: &Model, name: &str) -> f64 {
    model.spec().inputs.iter().find(|i| i.name == name).map_or(0.0, |i| i.delay + i.lag)
}

/// `frames` with each of `late`'s inputs read between its samples the other way where the dead
/// time may have decided it: one that moves from sample to sample yet was taken as held (a
/// state's rate fitted better so: a DAC's hold, or the dead time itself, half a sample of which
/// a hold makes) as a line; one that stays put between jumps yet was taken as switching between
/// samples (a held reading misfit the rate at some jumps: the jumps the dead time moves) as
/// held. The inputs so read again. A multisine acting 0.5 s late was taken as held (8 % less
/// left over) and its delay read a sample short; an APRBS acting 0.25 s late as switched, a
/// third of the weak form's windows left out, three spurious terms kept beside the delay.
fn reread(frames: &[Frame], late: &[String]) -> Result<(Vec<Frame>, Rereads), crate::data::DataError> {
    let mut out = frames.to_vec();
    let mut names: Rereads = Vec::new();
    for name in late.iter().map(String::as_str) {
        for frame in &mut out {
            let Some(column) = frame.column(name) else { continue };
            let smooth = !staircase(column);
            let how = match (smooth, frame.is_held(name), frame.is_switched(name)) {
                (true, true, _) => Reread::AsALine,
                (false, _, true) => Reread::AsHeld,
                _ => continue,
            };
            match how {
                Reread::AsALine => frame.release(name),
                Reread::AsHeld => frame.hold(name)?,
            }
            if !names.iter().any(|(n, _)| n == name) {
                names.push((name.to_string(), how));
            }
        }
    }
    Ok((out, names))
}

/// The inputs [`reread`] read again, each with how.
type Rereads = Vec<(String, Reread)>;

/// How a late input is read between its samples again ([`reread`]).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Reread {
    /// A smooth input taken as held.
    AsALine,
    /// A staircase taken as switching between samples.
    AsHeld,
}

impl Reread {
    /// Why, in words, for input `name`.
    fn said(self, name: &str) -> String {
        match self {
            Reread::AsALine => format!("`{name}` moves from sample to sample and was taken as held (a state's rate fitted better so), which a dead time makes it seem (a hold reads it half a sample late): read as a line between the samples"),
            Reread::AsHeld => format!("`{name}` stays put between jumps and was taken as switching between samples (a held reading misfit a state's rate at some jumps), which a dead time makes it seem (the jumps act later than recorded): read as held"),
        }
    }
}

/// The recipe as a stage runs it again: a model, its runs, and whether this stage runs within.
pub(super) type Identify<'a> = dyn Fn(&Model, &[Frame], bool) -> Result<Recipe, RecipeError> + 'a;

/// The dead times' stage after `recorded` (identified from `frames` by `identify`: a model, its
/// runs, and whether this stage runs within): `Ok` the recipe with its late inputs delayed
/// where kept, else `Err` the recipe as recorded, for the stages after this one; said either
/// way. A smooth input taken as held is read as a line first, its delay found again so (a
/// hold's half sample is the delay's own), where that keeps a delay.
pub(super) fn stage(
    recorded: Recipe,
    given: &Model,
    frames: &[Frame],
    identify: &Identify<'_>,
) -> Result<Recipe, Recipe> {
    let late = recorded.kept().late.clone();
    // the inputs whose reading between samples a dead time may have decided: the late ones;
    // where the scan found none but the equations miss their runs, every input (a staircase
    // taken as switching has the windows that would show its delay left out of the scan too:
    // random levels acting 0.25 s late, flagged, nothing said of a delay)
    let missed = recorded
        .kept()
        .checks
        .iter()
        .any(|c| !c.passed && (c.name == retrace::MISSED_NAME || c.name == retrace::CLOSE_NAME));
    let suspects: Vec<String> = match (late.is_empty(), missed) {
        (false, _) => late.iter().map(|l| l.column.clone()).collect(),
        (true, true) => given.spec().inputs.iter().map(|i| i.name.clone()).collect(),
        (true, false) => return Err(recorded),
    };
    let (lines, names) = reread(frames, &suspects).unwrap_or_else(|_| (Vec::new(), Vec::new()));
    if !names.is_empty() {
        if let Ok(mut again) = identify(given, &lines, true) {
            if names.iter().any(|(n, _)| lateness(&again.kept().model, n) > lateness(given, n)) {
                let said: Vec<String> = names.iter().map(|(n, how)| how.said(n)).collect();
                let note = format!("{}; its dead time found again so", said.join("; "));
                again.say(note);
                return Ok(again);
            }
        }
    }
    match delayed(given, &late) {
        Some(delayed) => kept(recorded, identify(&delayed, frames, false), &late, &delayed),
        None => Err(recorded),
    }
}

/// The late inputs in words, as `model` declares them: "`u` by 0.500 s", "`u` through a
/// first-order lag of 0.500 s".
fn named(late: &[Lag], model: &Model) -> String {
    late.iter()
        .filter_map(|l| model.spec().inputs.iter().find(|i| i.name == l.column))
        .map(|i| {
            let (name, sig) = (&i.name, |v: f64| crate::output::sig(v, 3));
            match (i.delay > 0.0, i.lag > 0.0) {
                (true, true) => {
                    format!("`{name}` by {} s through a first-order lag of {} s", sig(i.delay), sig(i.lag))
                }
                (false, true) => format!("`{name}` through a first-order lag of {} s", sig(i.lag)),
                _ => format!("`{name}` by {} s", sig(i.delay)),
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Which of the recipe as recorded (`recorded`) and the recipe with the `late` inputs delayed
/// (`with`, from `delayed`) to keep, said in a note of the kept start: the delayed one
/// (`Ok`) where its kept start fails no check the recorded one passes, else the recorded one
/// (`Err`), for the stages after this one.
fn kept(
    recorded: Recipe,
    with: Result<Recipe, RecipeError>,
    late: &[Lag],
    delayed: &Model,
) -> Result<Recipe, Recipe> {
    let failing = |r: &Recipe| -> Vec<String> {
        r.kept().checks.iter().filter(|c| !c.passed).map(|c| c.name.clone()).collect()
    };
    let tried = format!(
        "identified again with the inputs read as acting late, {} (a dead time, or a first-order lag, an actuator's, where one of the time constant explains the rates better over the same rows),",
        named(late, delayed)
    );
    let before = failing(&recorded);
    let (mut recipe, note) = match with {
        Ok(with) => {
            let lost: Vec<String> = failing(&with).into_iter().filter(|c| !before.contains(c)).collect();
            match lost.is_empty() {
                true => {
                    let checks = match failing(&with).is_empty() {
                        true => "every check ok".to_string(),
                        false => "no check failing that the inputs as recorded pass".to_string(),
                    };
                    let note = format!(
                        "{tried} the equations hold, {checks}: kept (each `delay` or `lag` under [[inputs]] in the model written, which its simulation feeds the input by). Where the inputs act as recorded, --no-dead-times (Python `dead_times=False`) keeps them so"
                    );
                    (Ok(with), note)
                }
                false => {
                    let lost = lost.iter().map(|c| format!("\"{c}\"")).collect::<Vec<_>>().join(", ");
                    let note = format!(
                        "{tried} the equations fail {lost}, which the inputs as recorded pass: the inputs kept as recorded, whose coefficients a real dead time biases"
                    );
                    (Err(recorded), note)
                }
            }
        }
        Err(e) => (
            Err(recorded),
            format!("{tried} the system could not be identified ({e}): the inputs kept as recorded"),
        ),
    };
    let (Ok(r) | Err(r)) = &mut recipe;
    r.say(note);
    recipe
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lag(column: &str) -> Lag {
        Lag { column: column.into(), seconds: 0.5, share: 0.01, longest: 20.0, first_order: None }
    }

    /// A late sine taken as held is read as a line again, a late staircase taken as switching
    /// as held; a late staircase held stays held; an input not late is left as it is.
    #[test]
    fn a_late_input_is_read_again_where_its_delay_may_have_decided_its_reading() {
        let t: Vec<f64> = (0..200).map(|k| 0.05 * k as f64).collect();
        let mut f = Frame::new("run.csv", "t", t.clone()).unwrap();
        f.push("u", t.iter().map(|t| (0.7 * t).sin()).collect()).unwrap();
        f.push("s", (0..200).map(|k| if (k / 40) % 2 == 0 { 1.0 } else { -1.0 }).collect()).unwrap();
        f.push("w", t.iter().map(|t| (1.3 * t).cos()).collect()).unwrap();
        f.push("r", (0..200).map(|k| if (k / 30) % 2 == 0 { 0.5 } else { -0.5 }).collect()).unwrap();
        for name in ["u", "s", "w"] {
            f.hold(name).unwrap();
        }
        f.switch("r").unwrap();
        let (out, names) = reread(&[f], &["u".into(), "s".into(), "r".into()]).unwrap();
        assert_eq!(names, vec![("u".to_string(), Reread::AsALine), ("r".to_string(), Reread::AsHeld)]);
        let f = &out[0];
        assert!(!f.is_held("u") && !f.is_switched("u") && f.is_held("s") && f.is_held("w"));
        assert!(f.is_held("r") && !f.is_switched("r"));
    }

    /// The delay written is the declared one plus the lag, to six figures.
    #[test]
    fn a_delay_is_written_to_six_figures() {
        let text = "[model]\nname = \"m\"\ntime = \"t\"\n[[states]]\nname = \"x\"\n[[inputs]]\nname = \"u\"\ndelay = 0.1\n[equations.x_dot]\nstate = \"x\"\ncandidates = [\"x\", \"u\"]\n";
        let model = Model::parse(text, "m.toml").unwrap();
        let late = Lag { seconds: 0.39999999999997, ..lag("u") };
        let delayed = delayed(&model, &[late]).unwrap();
        assert_eq!(delayed.spec().inputs[0].delay, 0.5);
    }
}
