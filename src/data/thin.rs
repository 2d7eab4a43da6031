//! A run read in pieces, kept small: consecutive rows averaged, twice as many to a kept row
//! each time the kept rows outgrow their bound, so that a check that re-simulates the run
//! (whether identified equations retrace it) has it at a bounded cost, without the whole run
//! in memory. The average is a box filter over the rows it gathers: what it keeps of the
//! inputs is what a re-simulation at that step can follow.

use std::ops::Range;

use super::{DataError, Frame};

/// A run's columns as kept so far.
#[derive(Clone, Debug)]
pub struct Thinned {
    origin: String,
    time_name: String,
    /// The columns kept besides the time.
    names: Vec<String>,
    /// The kept rows, column by column, the time first.
    columns: Vec<Vec<f64>>,
    /// The run's rows each kept row averages.
    each: usize,
    /// The sums of the rows gathered for the next kept row, the time first, and how many.
    partial: Vec<f64>,
    gathered: usize,
    /// The most rows kept.
    most: usize,
}

impl Thinned {
    /// Columns `names` of a run read from `origin` (their time named `time_name`), to be kept
    /// as at most `most` rows (at least two).
    pub fn new(origin: &str, time_name: &str, names: Vec<String>, most: usize) -> Thinned {
        let width = names.len() + 1;
        Thinned {
            origin: origin.into(),
            time_name: time_name.into(),
            names,
            columns: vec![Vec::new(); width],
            each: 1,
            partial: vec![0.0; width],
            gathered: 0,
            most: most.max(2),
        }
    }

    /// Rows `rows` of `piece` (a piece of the run, in order), its columns by name; a column it
    /// lacks is refused.
    pub fn push(&mut self, piece: &Frame, rows: Range<usize>) -> Result<(), DataError> {
        let columns: Vec<&[f64]> = std::iter::once(Ok(piece.time()))
            .chain(self.names.iter().map(|n| piece.require(n)))
            .collect::<Result<_, _>>()?;
        for r in rows {
            for (sum, c) in self.partial.iter_mut().zip(&columns) {
                *sum += c.get(r).copied().unwrap_or(f64::NAN);
            }
            self.gathered += 1;
            if self.gathered == self.each {
                self.keep();
            }
        }
        Ok(())
    }

    /// The gathered rows' average kept; the kept rows averaged in pairs where they outgrow
    /// their bound (an odd last one gathered on towards the next pair).
    fn keep(&mut self) {
        let n = self.gathered as f64;
        for (column, sum) in self.columns.iter_mut().zip(self.partial.iter_mut()) {
            column.push(*sum / n);
            *sum = 0.0;
        }
        self.gathered = 0;
        if self.columns[0].len() > self.most {
            let odd = self.columns[0].len() % 2 == 1;
            for (column, sum) in self.columns.iter_mut().zip(self.partial.iter_mut()) {
                if odd {
                    *sum = column.pop().unwrap_or(0.0) * self.each as f64;
                }
                *column = column.chunks_exact(2).map(|p| 0.5 * (p[0] + p[1])).collect();
            }
            if odd {
                self.gathered = self.each;
            }
            self.each *= 2;
        }
    }

    /// The run as kept, its samples evenly spaced: the rows gathered last, fewer than a kept
    /// row averages, left out (a re-simulation compares a run sample by sample), unless
    /// nothing else was kept.
    pub fn frame(mut self) -> Result<Frame, DataError> {
        if self.gathered > 0 && self.columns[0].is_empty() {
            self.keep();
        }
        let mut columns = self.columns.into_iter();
        let mut frame = Frame::new(&self.origin, &self.time_name, columns.next().unwrap_or_default())?;
        for (name, values) in self.names.iter().zip(columns) {
            frame.push(name, values)?;
        }
        Ok(frame)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run of 1001 rows read in pieces of 97, kept as at most 100 rows: between 50 and 100
    /// kept, each the average of the rows it gathers (a line stays the line, its time evenly
    /// spaced, the last few rows that fill no kept row left out), and the same however the
    /// run is cut into pieces; a run shorter than a kept row is kept as one.
    #[test]
    fn a_long_run_is_kept_as_averages_of_its_rows() {
        let n = 1001;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.1).collect();
        let mut run = Frame::new("run.csv", "t", t.clone()).unwrap();
        run.push("x", t.iter().map(|t| 3.0 * t - 1.0).collect()).unwrap();
        run.push("u", t.iter().map(|t| (0.3 * t).sin()).collect()).unwrap();
        let kept = |piece: usize| {
            let mut thin = Thinned::new("run.csv", "t", vec!["x".into(), "u".into()], 100);
            for start in (0..n).step_by(piece) {
                thin.push(&run, start..(start + piece).min(n)).unwrap();
            }
            thin.frame().unwrap()
        };
        let frame = kept(97);
        assert!((50..=101).contains(&frame.len()), "{}", frame.len());
        for (t, x) in frame.time().iter().zip(frame.column("x").unwrap()) {
            assert!((x - (3.0 * t - 1.0)).abs() < 1e-9, "{t} {x}");
        }
        let dt: Vec<f64> = frame.time().windows(2).map(|w| w[1] - w[0]).collect();
        assert!(dt.iter().all(|d| (d - dt[0]).abs() < 1e-9), "{dt:?}");
        assert!((n - 1) as f64 * 0.1 - frame.time()[frame.len() - 1] < 1.5 * dt[0], "{dt:?}");
        assert_eq!(kept(1).column("u"), frame.column("u"));
        assert_eq!(kept(n).time(), frame.time());
        let mut one = Thinned::new("run.csv", "t", vec!["x".into()], 100);
        one.push(&run, 0..1).unwrap();
        assert_eq!(one.frame().unwrap().len(), 1);
        // a piece without a kept column is refused
        let mut thin = Thinned::new("run.csv", "t", vec!["y".into()], 100);
        assert!(thin.push(&run, 0..10).is_err());
    }
}
