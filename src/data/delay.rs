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
}
