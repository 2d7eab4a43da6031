//! An input that acts later than it is recorded (a dead time: a transport delay, an actuator
//! or a logger that stamps a command before it takes effect): the run read with the column
//! at `t − d` against the rest at `t`.

use super::{DataError, Frame};

/// `frame` with column `name` read `seconds` earlier: each row at time t takes the column's
/// value at t − `seconds` (a line between samples, or the sample before where the column is
/// held, [`Frame::hold`]); the rows from `from` seconds after the run's start (at least
/// `seconds`, so that every row has a value; a common start makes runs delayed by different
/// amounts compare row for row). Refused where no row is left or the delay is negative.
pub fn delayed(frame: &Frame, name: &str, seconds: f64, from: f64) -> Result<Frame, DataError> {
    if !(seconds >= 0.0 && seconds.is_finite()) {
        return Err(DataError::Setting(format!(
            "a delay of {seconds} s for `{name}`: give 0 or more seconds"
        )));
    }
    let column = frame.require(name)?;
    let t = frame.time();
    let start = t[0] + from.max(seconds);
    let first = t.iter().position(|&s| s >= start - 1e-9 * (t[t.len() - 1] - t[0]).max(1.0));
    let Some(first) = first.filter(|&f| f + 1 < t.len()) else {
        return Err(DataError::Setting(format!(
            "{}: `{name}` delayed by {seconds} s leaves fewer than two rows of the run's {} s",
            frame.origin(),
            crate::output::sig(frame.duration(), 4)
        )));
    };
    let mut out = frame.slice(first..t.len());
    let (mut cursor, mut sample, close) = (0, 0, super::on_sample(t));
    let values: Vec<f64> = t[first..]
        .iter()
        .map(|&s| {
            let at = s - seconds;
            if frame.is_held(name) {
                column[super::sample_at(t, at, close, &mut sample)]
            } else {
                super::interpolate_at(t, column, at, &mut cursor)
            }
        })
        .collect();
    out.overwrite(name, values)?;
    Ok(out)
}

/// [`super::mark_held`] of `columns` where some act late, each `(name, seconds)` of `late`:
/// those are judged as the equations read them, `seconds` earlier against the states'
/// `motion` and the other columns (a hold test on the record as logged takes a smooth input
/// acting late for a DAC's hold, which reads it half a sample late too, and a staircase whose
/// jumps act later than logged for one switching between samples), and marked so in `frame`
/// itself; the rest as logged. A staircase keeps its steps where it is read late (the sample
/// before); a smooth column is read by a line. All judged as logged where a run is too short
/// for its dead times. What was found, said as the model reads it.
pub fn mark_held_acting(
    frame: &mut Frame,
    columns: &[&str],
    late: &[(&str, f64)],
    motion: &[&str],
    intersample: super::Intersample,
) -> Result<Vec<String>, DataError> {
    let late: Vec<(&str, f64)> = late
        .iter()
        .copied()
        .filter(|(n, d)| *d > 0.0 && columns.contains(n) && frame.column(n).is_some())
        .collect();
    if late.is_empty() || intersample != super::Intersample::Auto {
        return super::mark_held(frame, columns, motion, intersample);
    }
    let longest = late.iter().map(|(_, d)| *d).fold(0.0, f64::max);
    let mut acting = frame.clone();
    for (name, seconds) in &late {
        let column = acting.require(name)?;
        if super::staircase(column) {
            acting.hold(name)?;
        }
        match delayed(&acting, name, *seconds, longest) {
            Ok(read) => acting = read,
            Err(_) => return super::mark_held(frame, columns, motion, intersample),
        }
        acting.release(name);
    }
    let names: Vec<&str> = late.iter().map(|(n, _)| *n).collect();
    let on_time: Vec<&str> = columns.iter().copied().filter(|c| !names.contains(c)).collect();
    let mut notes = super::hold::mark_held_among(frame, &on_time, columns, motion, intersample)?;
    let said = super::hold::mark_held_among(&mut acting, &names, columns, motion, intersample)?;
    for name in &names {
        if acting.is_held(name) {
            frame.hold(name)?;
        } else if acting.is_switched(name) {
            frame.switch(name)?;
        } else {
            frame.release(name);
        }
    }
    let read: Vec<String> =
        late.iter().map(|(n, d)| format!("`{n}` {} s late", crate::output::sig(*d, 3))).collect();
    let read = read.join(", ");
    notes.extend(
        said.into_iter().map(|n| format!("{n} (judged as the equations read it: {read}, its dead time)")),
    );
    Ok(notes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ramp delayed by 0.25 s reads the ramp 0.25 s back (between samples by a line); a
    /// held step reads the step a sample later where the delay is a whole sample.
    #[test]
    fn a_column_read_earlier() {
        let t: Vec<f64> = (0..11).map(|k| 0.1 * k as f64).collect();
        let mut f = Frame::new("run.csv", "t", t.clone()).unwrap();
        f.push("u", t.iter().map(|t| 2.0 * t).collect()).unwrap();
        f.push("F", (0..11).map(|k| if k < 5 { 0.0 } else { 1.0 }).collect()).unwrap();
        f.hold("F").unwrap();
        let d = delayed(&f, "u", 0.25, 0.0).unwrap();
        assert_eq!(d.len(), 8);
        assert!((d.time()[0] - 0.3).abs() < 1e-12);
        for (t, u) in d.time().iter().zip(d.column("u").unwrap()) {
            assert!((u - 2.0 * (t - 0.25)).abs() < 1e-12, "{t}: {u}");
        }
        assert_eq!(d.column("F").unwrap(), &f.column("F").unwrap()[3..]);
        let held = delayed(&f, "F", 0.1, 0.5).unwrap();
        assert_eq!(held.column("F").unwrap(), &[0.0, 1.0, 1.0, 1.0, 1.0, 1.0]);
        assert!(held.is_held("F"));
        assert!(delayed(&f, "u", 1.0, 0.0).is_err());
        assert!(delayed(&f, "u", -0.1, 0.0).is_err());
    }

    /// A first-order state driven by three sines acting 0.5 s late, logged every 0.05 s: as
    /// logged, its rate fits better with the input held (a hold reads half a sample late, as
    /// the delay does), judged as it acts the input is a line between its samples; a late
    /// square wave on a clock is held either way.
    #[test]
    fn a_late_input_is_judged_as_it_acts() {
        let sines = |t: f64| 1.5 * (0.31 * t).sin() + (0.83 * t + 1.0).sin() + 0.5 * (2.1 * t + 2.0).sin();
        let square = |t: f64| if t.rem_euclid(20.0) < 10.0 { 1.0 } else { -1.0 };
        let inputs: [&dyn Fn(f64) -> f64; 2] = [&sines, &square];
        for (k, u) in inputs.into_iter().enumerate() {
            let late = |t: f64| if t >= 0.5 { u(t - 0.5) } else { 0.0 };
            let rate = |t: f64, x: f64| -0.5 * x + 0.8 * late(t);
            let (mut x, h) = (0.0, 0.005);
            let mut xs = Vec::new();
            for i in 0..4_000 {
                xs.push(x);
                for j in 0..10 {
                    let t = 0.05 * i as f64 + h * j as f64;
                    let k1 = rate(t, x);
                    let k2 = rate(t + h / 2.0, x + h / 2.0 * k1);
                    let k3 = rate(t + h / 2.0, x + h / 2.0 * k2);
                    // (the square's value before a jump at the step's end)
                    let k4 = rate(t + h - 1e-9, x + h * k3);
                    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                }
            }
            let t: Vec<f64> = (0..4_000).map(|i| 0.05 * i as f64).collect();
            let mut logged = Frame::new("run.csv", "t", t.clone()).unwrap();
            logged.push("x", xs).unwrap();
            logged.push("u", t.iter().map(|&t| u(t)).collect()).unwrap();
            let mut acting = logged.clone();
            crate::data::mark_held(&mut logged, &["u"], &["x"], crate::data::Intersample::Auto).unwrap();
            let notes =
                mark_held_acting(&mut acting, &["u"], &[("u", 0.5)], &["x"], crate::data::Intersample::Auto)
                    .unwrap();
            assert!(logged.is_held("u"), "{k}: as logged");
            assert_eq!(acting.is_held("u"), k == 1, "{k}: as it acts, {notes:?}");
            assert!(notes
                .iter()
                .all(|n| n.ends_with("(judged as the equations read it: `u` 0.500 s late, its dead time)")));
            assert_eq!(acting.len(), 4_000);
        }
    }
}
