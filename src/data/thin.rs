//! A run read in pieces, kept small: consecutive rows averaged, twice as many to a kept row
//! each time the kept rows outgrow their bound ([`Coarsened`], which also keeps a run's
//! statistics as stretches whose halves can be told apart), so that a check that re-simulates the run
//! (whether identified equations retrace it) has it at a bounded cost, without the whole run
//! in memory. The average is a box filter over the rows it gathers: what it keeps of the
//! inputs is what a re-simulation at that step can follow.

use std::ops::Range;

use super::{DataError, Frame};

/// A long sequence kept as at most `most` items: consecutive ones merged, twice as many to a
/// kept item each time the kept ones outgrow their bound (every kept item but the last holds
/// [`Coarsened::each`] of the sequence's; the last gathers towards as many).
#[derive(Clone, Debug)]
pub struct Coarsened<T> {
    kept: Vec<T>,
    each: usize,
    /// The items of the sequence the last kept one holds.
    last: usize,
    most: usize,
}

impl<T> Coarsened<T> {
    /// Nothing kept yet, to keep at most `most` items (at least two).
    pub fn new(most: usize) -> Coarsened<T> {
        Coarsened { kept: Vec::new(), each: 1, last: 0, most: most.max(2) }
    }

    /// The sequence's next item, merged into the last kept one (`merge`) while that holds
    /// fewer than [`Coarsened::each`].
    pub fn push(&mut self, item: T, merge: impl Fn(&mut T, T)) {
        match self.kept.last_mut() {
            Some(open) if self.last < self.each => {
                merge(open, item);
                self.last += 1;
            }
            _ => {
                self.kept.push(item);
                self.last = 1;
            }
        }
        if self.kept.len() > self.most {
            // every kept item but the last holds `each`: merged in pairs, they hold twice as
            // many; of an odd number, the last (the new one, holding one) is left alone
            let all = std::mem::take(&mut self.kept);
            let mut all = all.into_iter();
            while let Some(mut a) = all.next() {
                if let Some(b) = all.next() {
                    merge(&mut a, b);
                }
                self.kept.push(a);
            }
            self.each *= 2;
        }
    }

    /// The items of the sequence each kept one holds (the last: [`Coarsened::last`]).
    pub fn each(&self) -> usize {
        self.each
    }

    /// The items of the sequence the last kept one holds.
    pub fn last(&self) -> usize {
        self.last
    }

    /// The kept items, in order.
    pub fn kept(&self) -> &[T] {
        &self.kept
    }

    /// The kept items, in order, by value.
    pub fn into_kept(self) -> Vec<T> {
        self.kept
    }
}

/// A run's columns as kept so far.
#[derive(Clone, Debug)]
pub struct Thinned {
    origin: String,
    time_name: String,
    /// The columns kept besides the time.
    names: Vec<String>,
    /// The sums of the run's rows each kept row gathers, the time first.
    rows: Coarsened<Vec<f64>>,
}

impl Thinned {
    /// Columns `names` of a run read from `origin` (their time named `time_name`), to be kept
    /// as at most `most` rows (at least two).
    pub fn new(origin: &str, time_name: &str, names: Vec<String>, most: usize) -> Thinned {
        Thinned { origin: origin.into(), time_name: time_name.into(), names, rows: Coarsened::new(most) }
    }

    /// Rows `rows` of `piece` (a piece of the run, in order), its columns by name; a column it
    /// lacks is refused.
    pub fn push(&mut self, piece: &Frame, rows: Range<usize>) -> Result<(), DataError> {
        let columns: Vec<&[f64]> = std::iter::once(Ok(piece.time()))
            .chain(self.names.iter().map(|n| piece.require(n)))
            .collect::<Result<_, _>>()?;
        let add = |sum: &mut Vec<f64>, row: Vec<f64>| sum.iter_mut().zip(row).for_each(|(s, v)| *s += v);
        for r in rows {
            let row = columns.iter().map(|c| c.get(r).copied().unwrap_or(f64::NAN)).collect();
            self.rows.push(row, add);
        }
        Ok(())
    }

    /// The run as kept, its samples evenly spaced: the rows gathered last, fewer than a kept
    /// row averages, left out (a re-simulation compares a run sample by sample), unless
    /// nothing else was kept.
    pub fn frame(self) -> Result<Frame, DataError> {
        let (each, last) = (self.rows.each(), self.rows.last());
        let mut sums = self.rows.into_kept();
        // (a run shorter than a kept row: its one row holds `last` of them)
        let mut count = each;
        if last < each {
            if sums.len() > 1 {
                sums.pop();
            } else {
                count = last;
            }
        }
        let count = count as f64;
        let width = self.names.len() + 1;
        let mut columns: Vec<Vec<f64>> = (0..width).map(|_| Vec::with_capacity(sums.len())).collect();
        for row in &sums {
            for (column, v) in columns.iter_mut().zip(row) {
                column.push(v / count);
            }
        }
        let mut columns = columns.into_iter();
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
