//! An input that acts later than it is recorded (a dead time: a transport delay, an actuator
//! or a logger that stamps a command before it takes effect): the run read with the column
//! at `t − d` against the rest at `t`; or one that follows its record through a first-order
//! lag (an actuator's), the run read with the column passed through it.

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
    let Some(first) = first_row_from(t, start) else {
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

/// The first of the rows `t` at or after `start` (to a part in 10⁹ of the run's span), where
/// it leaves at least two rows.
fn first_row_from(t: &[f64], start: f64) -> Option<usize> {
    let first = t.iter().position(|&s| s >= start - 1e-9 * (t[t.len() - 1] - t[0]).max(1.0));
    first.filter(|&f| f + 1 < t.len())
}

/// Whether an input read through a first-order lag is held between its samples (`intersample`
/// as asked; `Auto`: where a staircase, [`super::staircase`], else a line: the rates' fits,
/// which read it through a lag that makes it seem late, would take a smooth one for a DAC's
/// hold).
pub fn held_through_lag(column: &[f64], intersample: super::Intersample) -> bool {
    match intersample {
        super::Intersample::Linear => false,
        super::Intersample::Held => column.windows(2).any(|w| w[1] != w[0]),
        super::Intersample::Auto => super::staircase(column),
    }
}

/// How many time constants of a lag a run is read from ([`lagged`]): the lag is started at rest
/// at the column's first value, which an actuator moving at the record's start is not (a
/// mass-spring whose actuator of 0.5 s started from 0 under a command of 1.3 was followed for
/// 0.25 s of 200 s); after five, e⁻⁵ = 0.7 % of that start is left.
pub const SETTLED: f64 = 5.0;

/// `frame` with each column of `lags` (`(name, seconds)`) read through a first-order lag of
/// that time constant (an actuator, a valve, a sensor that follows its command as
/// ẏ = (u − y)/T): each row takes the lag's output there, at rest at the column's first value
/// at the run's start, exact between samples for the column as it is read there (a line, or
/// held from each sample to the next where [`Frame::hold`] says so); the rows from `from`
/// seconds after the run's start, at least five of the slowest lag's time constants
/// ([`SETTLED`]: what the lag's start at rest leaves has died away). A lag's output moves
/// smoothly, so its column is read as a line between its samples afterwards. Refused where no
/// row is left or a time constant is negative.
pub fn lagged(frame: &Frame, lags: &[(&str, f64)], from: f64) -> Result<Frame, DataError> {
    if let Some((name, seconds)) = lags.iter().find(|(_, s)| !(*s >= 0.0 && s.is_finite())) {
        return Err(DataError::Setting(format!(
            "a first-order lag of {seconds} s for `{name}`: give a time constant of 0 or more seconds"
        )));
    }
    let slowest = lags.iter().map(|(_, s)| *s).fold(0.0, f64::max);
    let t = frame.time();
    let start = t[0] + from.max(SETTLED * slowest);
    let Some(first) = first_row_from(t, start) else {
        let names: Vec<String> = lags.iter().map(|(n, s)| format!("`{n}` through a lag of {s} s")).collect();
        return Err(DataError::Setting(format!(
            "{}: {}, read from {} s on (where the lags' start at rest has died away), leaves fewer than two rows of the run's {} s",
            frame.origin(),
            names.join(", "),
            crate::output::sig(start - t[0], 3),
            crate::output::sig(frame.duration(), 4)
        )));
    };
    let mut out = frame.slice(first..t.len());
    for &(name, seconds) in lags.iter().filter(|(_, s)| *s > 0.0) {
        let (column, held) = (frame.require(name)?, frame.is_held(name));
        let mut y = column[0];
        let mut values = Vec::with_capacity(column.len());
        values.push(y);
        for k in 1..column.len() {
            let h = t[k] - t[k - 1];
            // the exact response over the interval to u₀ held, or to the line from u₀ to u₁
            // (u = u₀ + b s: y₁ = u₁ − bT + (y₀ − u₀ + bT) e^(−h/T))
            let (u0, u1) = (column[k - 1], if held { column[k - 1] } else { column[k] });
            let bt = if h > 0.0 { (u1 - u0) / h * seconds } else { 0.0 };
            y = u1 - bt + (y - u0 + bt) * (-h / seconds).exp();
            values.push(y);
        }
        out.overwrite(name, values.split_off(first))?;
        out.release(name);
    }
    Ok(out)
}

/// [`super::mark_held`] of `columns` where some act late, each `(name, seconds)` of `late`:
/// those are judged as the equations read them, `seconds` earlier against the states'
/// `motion` and the other columns (a hold test on the record as logged takes a smooth input
/// acting late for a DAC's hold, which reads it half a sample late too, and a staircase whose
/// jumps act later than logged for one switching between samples), and marked so in `frame`
/// itself; the rest as logged. A staircase keeps its steps where it is read late (the sample
/// before); a smooth column is read by a line. All judged as logged where a run is too short
/// for its dead times. One of `lags` (`(name, seconds)`, a first-order lag it acts through)
/// is judged by its record alone ([`held_through_lag`]: an actuator's lag of 0.5 s made a
/// smooth command fit 10 % better held). What was found, said as the model reads it.
pub fn mark_held_acting(
    frame: &mut Frame,
    columns: &[&str],
    late: &[(&str, f64)],
    lags: &[(&str, f64)],
    motion: &[&str],
    intersample: super::Intersample,
) -> Result<Vec<String>, DataError> {
    let lagged: Vec<&str> = lags
        .iter()
        .filter(|(n, t)| *t > 0.0 && columns.contains(n) && frame.column(n).is_some())
        .map(|(n, _)| *n)
        .collect();
    for name in &lagged {
        match held_through_lag(frame.require(name)?, intersample) {
            true => frame.hold(name)?,
            false => frame.release(name),
        }
    }
    let unlagged: Vec<&str> = columns.iter().copied().filter(|c| !lagged.contains(c)).collect();
    let late: Vec<(&str, f64)> = late
        .iter()
        .copied()
        .filter(|(n, d)| *d > 0.0 && unlagged.contains(n) && frame.column(n).is_some())
        .collect();
    if late.is_empty() || intersample != super::Intersample::Auto {
        return super::hold::mark_held_among(frame, &unlagged, columns, motion, intersample);
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
            Err(_) => return super::hold::mark_held_among(frame, &unlagged, columns, motion, intersample),
        }
        acting.release(name);
    }
    let names: Vec<&str> = late.iter().map(|(n, _)| *n).collect();
    let on_time: Vec<&str> = unlagged.iter().copied().filter(|c| !names.contains(c)).collect();
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

    /// A unit step through a lag of 0.5 s is 1 − e^(−t/0.5) at every sample; a ramp 2t is
    /// 2(t − T(1 − e^(−t/T))) (a line between samples is read exactly); a held staircase is
    /// exact too, and the output is a line between its samples; the rows from five time
    /// constants on, or later where asked.
    #[test]
    fn a_column_read_through_a_first_order_lag() {
        let t: Vec<f64> = (0..121).map(|k| 0.05 * k as f64).collect();
        let mut f = Frame::new("run.csv", "t", t.clone()).unwrap();
        f.push("step", t.iter().map(|&t| if t > 0.0 { 1.0 } else { 0.0 }).collect()).unwrap();
        f.push("ramp", t.iter().map(|t| 2.0 * t).collect()).unwrap();
        f.hold("step").unwrap();
        let (tau, e) = (0.5, |t: f64| (-t / 0.5f64).exp());
        let ramp = lagged(&f, &[("ramp", tau)], 0.0).unwrap();
        assert_eq!(ramp.len(), 71);
        assert!((ramp.time()[0] - 2.5).abs() < 1e-12);
        assert_eq!(ramp.column("step"), Some(&f.column("step").unwrap()[50..]));
        for (t, y) in ramp.time().iter().zip(ramp.column("ramp").unwrap()) {
            let want = 2.0 * (t - tau * (1.0 - e(*t)));
            assert!((y - want).abs() < 1e-12, "{t}: {y} for {want}");
        }
        // held: 0 up to the first sample, 1 from it on (the step acts from t = 0.05)
        let step = lagged(&f, &[("step", tau), ("ramp", 0.0)], 3.0).unwrap();
        assert!((step.time()[0] - 3.0).abs() < 1e-12);
        for (t, y) in step.time().iter().zip(step.column("step").unwrap()) {
            let want = if *t > 0.0 { 1.0 - e(t - 0.05) } else { 0.0 };
            assert!((y - want).abs() < 1e-12, "{t}: {y} for {want}");
        }
        assert!(!step.is_held("step"));
        assert_eq!(step.column("ramp"), Some(&f.column("ramp").unwrap()[60..]));
        // both at once: each from the run's start, the rows from the slower's five
        let both = lagged(&f, &[("ramp", 0.2), ("step", tau)], 0.0).unwrap();
        assert!((both.column("step").unwrap()[0] - (1.0 - e(2.5 - 0.05))).abs() < 1e-12);
        assert!((both.time()[0] - 2.5).abs() < 1e-12);
        let t0 = both.time()[0];
        let want = 2.0 * (t0 - 0.2 * (1.0 - (-t0 / 0.2f64).exp()));
        assert!((both.column("ramp").unwrap()[0] - want).abs() < 1e-12);
        assert_eq!(lagged(&f, &[("ramp", 0.0)], 0.0).unwrap().column("ramp"), f.column("ramp"));
        assert!(
            lagged(&f, &[("ramp", -0.1)], 0.0).is_err() && lagged(&f, &[("ramp", f64::NAN)], 0.0).is_err()
        );
        assert!(lagged(&f, &[("nope", 0.1)], 0.0).is_err());
        assert!(
            lagged(&f, &[("ramp", 1.2)], 0.0).is_err(),
            "six seconds hold no five time constants of 1.2 s"
        );
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
            let notes = mark_held_acting(
                &mut acting,
                &["u"],
                &[("u", 0.5)],
                &[],
                &["x"],
                crate::data::Intersample::Auto,
            )
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
