//! A slower sensor's readings repeated between its updates: a log written ten times as often
//! as a position fix arrives, or sensors of several rates merged and filled forward. Such a
//! column of a moving quantity is a staircase: its rate is zero between readings and a spike
//! at each, and every fit through it is biased (Lorenz with `x` read every 10th row of 1 ms:
//! −0.958 for −1 and two spurious terms). Read at its readings and interpolated between them
//! instead, it is the quantity again.

use super::hold::{gcd, isolated_changes, CLOCK_JUMPS};
use super::{DataError, Frame, Intersample};

/// What shows a column repeated between a slower sensor's readings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Repeats {
    /// The rows from one reading to the next (2 or more).
    pub period: usize,
    /// The first row that is a reading (below `period`).
    pub phase: usize,
    /// The share of readings that differ from the one before.
    pub moving: f64,
}

impl Repeats {
    /// The rows of a column of `len` rows that are readings.
    pub fn readings(&self, len: usize) -> impl Iterator<Item = usize> {
        (self.phase..len).step_by(self.period)
    }
}

/// The share of readings at least that must differ from the last: a moving quantity changes
/// at nearly every reading; a command held by a controller on its clock for several periods
/// at a time changes at a few.
const MOVING: f64 = 0.5;

/// Whether `x` is a slower sensor's readings repeated between its updates: it changes at
/// isolated rows only (no two changing intervals side by side, but for 5 %), those rows keep
/// a clock of two rows or more (nine changes at least, as for a held command), and at half
/// of the clock's ticks or more between its first change and its last it changes. `None`
/// otherwise (a record that moves from row to row, a constant, a command stepped now and
/// then).
pub fn repeated(x: &[f64]) -> Option<Repeats> {
    // the rows where a new reading shows
    let at: Vec<usize> = isolated_changes(x)?.into_iter().map(|i| i + 1).collect();
    if at.len() < CLOCK_JUMPS {
        return None;
    }
    let period = at.windows(2).fold(0, |g, w| gcd(g, w[1] - w[0]));
    if period < 2 {
        return None;
    }
    let ticks = (at[at.len() - 1] - at[0]) / period + 1;
    let moving = at.len() as f64 / ticks as f64;
    (moving >= MOVING).then_some(Repeats { period, phase: at[0] % period, moving })
}

/// `x` at its readings (the rows `phase`, `phase + period`, …) and, between them and beyond the
/// first and last, the cubic through the four nearest readings (at their own times `t`): what
/// a sensor read at those instants says of the rows in between, to O(h⁴) of a smooth quantity.
pub fn between_readings(t: &[f64], x: &[f64], r: Repeats) -> Vec<f64> {
    let nodes: Vec<usize> = r.readings(x.len()).collect();
    if nodes.len() < 4 {
        return x.to_vec();
    }
    let mut out = Vec::with_capacity(x.len());
    let mut i = 0;
    for (row, &s) in t.iter().enumerate() {
        // the reading at or before the row (the first where the row comes before it)
        while i + 1 < nodes.len() && nodes[i + 1] <= row {
            i += 1;
        }
        let first = i.saturating_sub(1).min(nodes.len() - 4);
        let four = &nodes[first..first + 4];
        // Lagrange's cubic through the four readings
        let value: f64 = four
            .iter()
            .map(|&a| {
                let weight: f64 =
                    four.iter().filter(|&&b| b != a).map(|&b| (s - t[b]) / (t[a] - t[b])).product();
                weight * x[a]
            })
            .sum();
        out.push(value);
    }
    out
}

/// The columns of `frame` named in `columns` that are a slower sensor's readings repeated
/// between its updates ([`repeated`]) read at their readings and interpolated between them
/// ([`between_readings`]), and what to say of each; none where `intersample` is `linear` (the
/// record as its rows have it). A column held between samples (a command:
/// [`Frame::is_held`]) and the columns a frame does not have are passed over.
pub fn read_at_readings(
    frame: &mut Frame,
    columns: &[&str],
    intersample: Intersample,
) -> Result<Vec<String>, DataError> {
    let mut notes = Vec::new();
    if intersample == Intersample::Linear {
        return Ok(notes);
    }
    for name in columns {
        if frame.is_held(name) {
            continue;
        }
        let Some(column) = frame.column(name) else { continue };
        let Some(r) = repeated(column) else { continue };
        let mended = between_readings(frame.time(), column, r);
        let readings = r.readings(column.len()).count();
        frame.overwrite(name, mended)?;
        notes.push(format!(
            "{}: `{name}` changes only every {} rows and repeats itself in between ({:.0} % of its {readings} readings differ from the one before): a slower sensor's readings written again until the next (a log kept faster than the sensor reads, or several sensors merged and filled forward), whose rate would read zero between readings and a spike at each; read at its readings and interpolated between them by cubics. Where it truly steps so, say so (identify --intersample linear; a model file's `intersample = \"linear\"`; Python `intersample=\"linear\"`)",
            frame.origin(),
            r.period,
            100.0 * r.moving,
        ));
    }
    Ok(notes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// sin t read every 10th row of 0.01 s and repeated between: found (period 10 from row 3),
    /// and rebuilt to within the cubic's error between readings h = 0.1 s apart (at most
    /// h⁴/24 = 4.2e-6 with sin's fourth derivative, in the first and last intervals; 9/16 of
    /// that between), and within 1e-4 beyond the first and last reading; the readings kept.
    #[test]
    fn a_repeated_sine_is_found_and_rebuilt() {
        let t: Vec<f64> = (0..2000).map(|k| 0.01 * k as f64).collect();
        let x: Vec<f64> = (0..2000).map(|k| (t[if k < 3 { 0 } else { k - (k - 3) % 10 }]).sin()).collect();
        let r = repeated(&x).unwrap();
        assert_eq!((r.period, r.phase), (10, 3));
        assert!(r.moving > 0.99, "{r:?}");
        let rebuilt = between_readings(&t, &x, r);
        let error: Vec<f64> = rebuilt.iter().zip(&t).map(|(v, t)| (v - t.sin()).abs()).collect();
        let worst = |e: &[f64]| e.iter().copied().fold(0.0, f64::max);
        assert!(worst(&error[13..1983]) < 4.2e-6, "{}", worst(&error[13..1983]));
        assert!(worst(&error[23..1973]) < 2.35e-6, "{}", worst(&error[23..1973]));
        assert!(worst(&error) < 1e-4, "{}", worst(&error));
        assert_eq!(rebuilt[13], x[13]);
    }

    /// Not repeated: a record that moves from row to row, a constant, a command stepped every
    /// 50 rows to one of two levels, now and then (few of the clock's ticks change it), a
    /// ramp in counts off any clock, a switch at every row.
    #[test]
    fn motion_commands_and_counts_are_not_repeats() {
        let moving: Vec<f64> = (0..500).map(|k| (0.01 * k as f64).sin()).collect();
        assert_eq!(repeated(&moving), None);
        assert_eq!(repeated(&[2.0; 500]), None);
        let mut seed = 4u64;
        let mut level = 1.0;
        let command: Vec<f64> = (0..5000)
            .map(|k| {
                if k % 50 == 0 && crate::data::test_noise(&mut seed) > 0.3 {
                    level = -level;
                }
                level
            })
            .collect();
        assert!(command.windows(2).filter(|w| w[0] != w[1]).count() >= 9);
        assert_eq!(repeated(&command), None);
        let counts: Vec<f64> = (0..1000).map(|k| (k as f64 / 3.3).floor()).collect();
        assert_eq!(repeated(&counts), None);
        let every: Vec<f64> = (0..100).map(|k| if k % 2 == 0 { 1.0 } else { -1.0 }).collect();
        assert_eq!(repeated(&every), None);
    }

    /// A reading that happens to equal the last (a quantity at rest for one period) is still a
    /// reading: the clock stands, and the cubic goes through it.
    #[test]
    fn an_unchanged_reading_keeps_the_clock() {
        let t: Vec<f64> = (0..400).map(|k| 0.01 * k as f64).collect();
        let reading = |k: usize| ((k / 5) as f64 * 0.05).cos();
        let mut x: Vec<f64> = (0..400).map(reading).collect();
        // the reading at row 100 equal to the one at row 95
        for v in &mut x[100..105] {
            *v = reading(95);
        }
        let r = repeated(&x).unwrap();
        assert_eq!((r.period, r.phase), (5, 0));
        assert_eq!(between_readings(&t, &x, r)[100], reading(95));
    }

    /// In a frame: the repeated column re-read and said, a held one and a moving one left.
    #[test]
    fn a_frame_reads_its_repeated_columns_at_their_readings() {
        let t: Vec<f64> = (0..300).map(|k| 0.1 * k as f64).collect();
        let mut f = Frame::new("log.csv", "t", t.clone()).unwrap();
        f.push("x", (0..300).map(|k| t[k - k % 4].sin()).collect()).unwrap();
        f.push("y", t.iter().map(|t| t.cos()).collect()).unwrap();
        f.push("F", (0..300).map(|k| t[k - k % 4].sin()).collect()).unwrap();
        f.hold("F").unwrap();
        let mut g = f.clone();
        assert!(read_at_readings(&mut g, &["x"], Intersample::Linear).unwrap().is_empty());
        assert_eq!(g.column("x"), f.column("x"));
        let notes = read_at_readings(&mut f, &["x", "y", "F", "absent"], Intersample::Auto).unwrap();
        assert_eq!(notes.len(), 1);
        assert!(notes[0].starts_with("log.csv: `x` changes only every 4 rows"), "{}", notes[0]);
        assert!((f.column("x").unwrap()[2] - t[2].sin()).abs() < 1e-3);
        assert_eq!(f.column("y").unwrap()[2], t[2].cos());
        assert_eq!(f.column("F").unwrap()[2], t[0].sin());
    }
}
