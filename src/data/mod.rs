//! Time series as a [`Frame`] of named f64 columns with a time column, read from and written
//! to CSV with errors that name the file, row and column; and numerical derivatives behind
//! the [`Differentiator`] interface.

mod angle;
mod breaks;
mod clipped;
mod clock;
#[cfg(feature = "columnar")]
mod columnar;
mod csv_io;
mod dataset;
mod delay;
mod derivative;
mod five_point;
mod geodetic;
mod hold;
mod in_si;
mod integral;
mod ito;
mod kalman;
mod long;
mod noise;
mod prepare;
mod repeated;
mod resample;
mod savitzky_golay;
mod search;
mod separator;
mod smoothing_spline;
mod spike;
mod stream;
mod thin;
mod weak;

pub use angle::{laid_on_turns, turn_of, unwrap_turns, unwrapped, unwrapped_dials, wrapped};
pub use breaks::{breaks, cut_at_breaks, cut_at_gaps, gaps, moving_breaks, Break, Gaps, Leaps};
pub use clipped::{clips, cut_at_clips, Clip};
pub use clock::{clock_seconds, epoch_note};
pub use dataset::{
    from_seconds, headers_in_si, in_seconds, read_as, seconds_of_unit, seconds_per, time_position,
    velocities_from_track, Dataset, Delimiter, RunSpec, Track,
};
pub use delay::{delayed, held_through_lag, lagged, mark_held_acting, SETTLED};
pub use derivative::{
    differentiator, CentralDifference, Differentiator, Smoothed, TestFunction, Window, DIFFERENTIATORS,
};
pub use five_point::FivePoint;
pub use geodetic::{north_east, radii_of_curvature};
pub use hold::{held, mark_held, staircase, stepped, switches, white, Hold, Intersample};
pub use in_si::{time_in_seconds, units_note};
pub use integral::{integral_rows, integral_rows_held, row_overlap, IntegralForm};
pub use ito::{first_stage, Ito};
pub use kalman::{KalmanSmoother, NoiseModel};
pub use long::{columns_of, interleaved, text_columns_of};
pub(crate) use noise::fourth_differences_over;
pub use noise::{quantum, white_noise, Noise, NoiseTally};
pub use prepare::{prepare, runs_of_rate, Preparation};
pub use repeated::{
    between_readings, fits_better_held, kinks_at_changes, read_at_readings, repeated, Repeats,
};
pub use resample::{
    check_gaps, cubic_at, evened, interpolate_at, median_step, on_sample, resample, run_step, sample_at,
    sample_step, uneven,
};
pub use savitzky_golay::SavitzkyGolay;
pub use smoothing_spline::SmoothingSpline;
pub use spike::{despiked, despiked_all, spikes, Spike};
pub use stream::{Chunk, Chunks, Labels, RowSource};
pub use thin::{Coarsened, Thinned};
pub use weak::WeakForm;

#[cfg(test)]
/// Uniform noise in [−½, ½) from a seeded LCG, for the tests of the derivative methods.
pub(crate) fn test_noise(seed: &mut u64) -> f64 {
    *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

#[cfg(test)]
/// RMS error of a rate estimate of sin(0.3 t) over samples 20..1980 (ends left out), the
/// shared yardstick of the derivative methods' noise tests.
pub(crate) fn sine_rate_error(t: &[f64], d: &[f64]) -> f64 {
    let sq: f64 = d.iter().zip(t).skip(20).take(1960).map(|(d, t)| (d - 0.3 * (0.3 * t).cos()).powi(2)).sum();
    (sq / 1960.0).sqrt()
}

/// What an empty cell (or NaN) most often is, and what to do: sensors of several rates merged,
/// the slower ones blank between their readings.
const NO_READING: &str = "no reading there; where a slower sensor's column is blank between its readings (sensors of several rates merged), fill it forward (pandas' `ffill`): a column that repeats its readings is read at them; where readings were lost, cut the run there";

/// Something wrong with a data set. Every variant names where.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DataError {
    /// The file could not be read or written.
    #[error("{file}: {message}")]
    Io {
        /// The file.
        file: String,
        /// What the system said.
        message: String,
    },
    /// Nothing at all, not even a header.
    #[error(
        "{file}: the file is empty: a CSV file needs a header row naming its columns, then rows of numbers"
    )]
    NoHeader {
        /// The file.
        file: String,
    },
    /// No data rows.
    #[error("{file}: no data rows")]
    Empty {
        /// The file.
        file: String,
    },
    /// A required column is absent.
    #[error("{file}: no column `{column}` (columns: {available})")]
    MissingColumn {
        /// The file.
        file: String,
        /// The missing column.
        column: String,
        /// The columns there are.
        available: String,
    },
    /// The time column is absent.
    #[error("{file}: no time column `{column}` (columns: {available}){hint}")]
    MissingTime {
        /// The file.
        file: String,
        /// The time column looked for.
        column: String,
        /// The columns there are.
        available: String,
        /// Where a column looks like time: which, and how to name it.
        hint: String,
    },
    /// A column name occurs twice.
    #[error("{file}: column `{column}` appears twice")]
    DuplicateColumn {
        /// The file.
        file: String,
        /// The column.
        column: String,
    },
    /// A cell is not a number.
    #[error("{file}: row {row}, column `{column}`: {}", not_a_number(cell))]
    NotNumeric {
        /// The file.
        file: String,
        /// 1-based data row (the header is row 0).
        row: usize,
        /// The column.
        column: String,
        /// The cell's text.
        cell: String,
    },
    /// NaN or infinite value.
    #[error("{file}: row {row}, column `{column}`: value {value} is not finite{}", if value.is_nan() { format!(" ({NO_READING})") } else { String::new() })]
    NonFinite {
        /// The file.
        file: String,
        /// 1-based data row.
        row: usize,
        /// The column.
        column: String,
        /// The value.
        value: f64,
    },
    /// A row with the wrong number of cells.
    #[error("{file}: row {row} has {found} cells, the header has {expected}")]
    Ragged {
        /// The file.
        file: String,
        /// 1-based data row.
        row: usize,
        /// Header width.
        expected: usize,
        /// Cells found.
        found: usize,
    },
    /// Time that does not increase.
    #[error("{file}: row {row}, column `{column}`: time {this} does not increase (previous row {previous}){}", if *restart { "; it starts again: runs one after another? each must be a run of its own" } else { "" })]
    TimeNotIncreasing {
        /// The file.
        file: String,
        /// 1-based data row.
        row: usize,
        /// The time column.
        column: String,
        /// This row's time.
        this: f64,
        /// The previous row's time.
        previous: f64,
        /// It goes back to the first row's time or before (a run that follows another).
        restart: bool,
    },
    /// Time that decreases at every row: the rows newest first.
    #[error("{file}: column `{column}`: time decreases at every row, from {first} to {last}: the rows are newest first (a log or a database export sorted descending); sort them by time, oldest first")]
    TimeDescending {
        /// The file.
        file: String,
        /// The time column.
        column: String,
        /// The first row's time.
        first: f64,
        /// The last row's time.
        last: f64,
    },
    /// A time printed too coarsely for its rows: many rows share each stamp, and it never
    /// decreases (a logger at 100 Hz writing its time to 0.1 s).
    #[error("{file}: row {row}, column `{column}`: time {this} repeats the row before's, as {counted}, and it never decreases: it is written to {interval}; write the time with more digits, or read the file through a dataset file with `regular_time = true` (the stamps' line over the row number)")]
    CoarseTime {
        /// The file.
        file: String,
        /// 1-based data row of the first repeat.
        row: usize,
        /// The time column.
        column: String,
        /// That row's time.
        this: f64,
        /// How many rows repeat their predecessor's time, of how many, said.
        counted: String,
        /// The smallest step between stamps (the time's last digit) and the rows' mean
        /// interval, said.
        interval: String,
    },
    /// A row that repeats the one before in every column (a logger's duplicate).
    #[error("{file}: row {row} repeats row {} in every column, its time too (a logger's duplicate): drop it (pandas' `df.drop_duplicates()`)", row - 1)]
    RepeatedRow {
        /// The file.
        file: String,
        /// 1-based data row of the repeat.
        row: usize,
    },
    /// A column of the wrong length.
    #[error("{file}: column `{column}` has {found} values, the time column {expected}")]
    Length {
        /// The file.
        file: String,
        /// The column.
        column: String,
        /// Rows of the frame.
        expected: usize,
        /// Values given.
        found: usize,
    },
    /// Too few rows for an operation.
    #[error("{file}: {rows} rows are too few for {what} (needs {needed})")]
    TooShort {
        /// The file.
        file: String,
        /// Rows there are.
        rows: usize,
        /// Rows needed.
        needed: usize,
        /// What needed them.
        what: String,
    },
    /// A unit that is unknown or contradicted by the values.
    #[error("{file}: {}column `{column}`: {message}", if *.row == 0 { "the whole run, ".to_string() } else { format!("row {row}, ") })]
    Unit {
        /// The file.
        file: String,
        /// 1-based data row (0: the whole run, or the declaration).
        row: usize,
        /// The column.
        column: String,
        /// What is wrong.
        message: String,
    },
    /// The rows of several runs interleaved (two vessels logged in turn), read as one run.
    #[error("{file}: the rows are those of {runs} runs interleaved (`{column}` changes at {changes} of {rows} rows, and the readings run smoothly along each value's rows, not along the file's): read each as a run of its own, `--by {column}` (a dataset file's run: `by = \"{column}\"`; Python: df.groupby('{column}'))")]
    Interleaved {
        /// The file.
        file: String,
        /// The column of text that names each row's run.
        column: String,
        /// How many values it takes.
        runs: usize,
        /// At how many rows it changes.
        changes: usize,
        /// The file's rows.
        rows: usize,
    },
    /// A step in time far beyond the run's usual spacing.
    #[error("{file}: row {row}, column `{column}`: time jumps by {step:.4} (usual step {median:.4}): a gap in the record")]
    TimeGap {
        /// The file.
        file: String,
        /// 1-based data row after the gap.
        row: usize,
        /// The time column.
        column: String,
        /// The step.
        step: f64,
        /// The median step.
        median: f64,
    },
    /// A setting out of its range (a resampling interval of 0 s).
    #[error("{0}")]
    Setting(String),
    /// Work too large for memory, refused before it started.
    #[error("{file}: {size}")]
    TooLarge {
        /// The file.
        file: String,
        /// How large (in the message, so not also a source that would print twice).
        size: crate::budget::TooLarge,
    },
    /// Unknown derivative method.
    #[error("unknown derivative method `{0}` (known: {1})")]
    UnknownMethod(String, String),
}

/// Whether a column's name says it holds the time: `time`, `Time [s]`, `timestamp`,
/// `seconds`, `t_s`, a unit of time's word or a header with one (`day`, `t [h]`), … (for an
/// error that names it where the time column was not found).
pub fn looks_like_time(name: &str) -> bool {
    let n = name.trim().to_lowercase();
    ["time", "timestamp", "sec", "secs", "seconds", "t_s", "t [s]", "t(s)"].iter().any(|w| {
        n == *w
            || n.starts_with(&format!("{w} "))
            || n.starts_with(&format!("{w}_"))
            || n.starts_with(&format!("{w}["))
    }) || seconds_per(name).is_some()
}

/// What a cell that gave no number is said to be: no reading (empty, `null`), a number beyond
/// the range of a double (`1e400`, which reads as infinite), or not a number.
fn not_a_number(cell: &str) -> String {
    if cell.trim().is_empty() || cell == "null" {
        NO_READING.to_string()
    } else if overflows(cell) {
        format!("`{cell}` is beyond the largest number a double holds (1.8e308)")
    } else {
        format!("`{cell}` is not a number")
    }
}

/// Whether a cell's text is digits whose number lies beyond the range of a double (`1e400`,
/// read as infinite), not an infinity spelled out (`inf`).
pub(crate) fn overflows(cell: &str) -> bool {
    cell.bytes().any(|b| b.is_ascii_digit()) && cell.trim().parse::<f64>().is_ok_and(f64::is_infinite)
}

impl DataError {
    /// A column of text (its first cell `cell`, row 1) asked for as numbers.
    pub fn text_column(file: &str, column: &str, cell: &str) -> DataError {
        DataError::NotNumeric { file: file.into(), row: 1, column: column.into(), cell: cell.into() }
    }

    /// No column `time` among `names` in `file`; a column that looks like time (`time`,
    /// `Time [s]`, `timestamp`, `seconds`) is named, with how to choose it.
    pub fn missing_time(file: &str, time: &str, names: &[impl AsRef<str>]) -> DataError {
        let hint = names
            .iter()
            .map(AsRef::as_ref)
            .find(|n| looks_like_time(n))
            .map(|n| {
                if crate::term::is_identifier(n) {
                    format!("; `{n}` looks like time: name it as the time column (`--time {n}`, a model file's `time`)")
                } else {
                    // a unit of time in its header ([ms], (min)) is read either way
                    format!(
                        "; `{n}` looks like time: name it as the time column (`--time \"{n}\"`; its header's unit of time, [ms] or (min), is read) or map it in a dataset file (`[columns] {time} = \"{n}\"`)"
                    )
                }
            })
            .unwrap_or_default();
        DataError::MissingTime {
            file: file.into(),
            column: time.into(),
            available: names.iter().map(AsRef::as_ref).collect::<Vec<_>>().join(", "),
            hint,
        }
    }

    /// The error of a piece of a file said of the whole file: its row numbers moved on by
    /// `rows` (the piece's first row in the file).
    pub fn shifted(self, rows: usize) -> DataError {
        self.renumbered(|row| row + rows)
    }

    /// The error of a run whose rows are `rows` of its file (from 0; a run among others in a
    /// long file) said of the file.
    pub fn at_file_rows(self, rows: &[usize]) -> DataError {
        self.renumbered(|row| rows.get(row.wrapping_sub(1)).map_or(row, |&i| i + 1))
    }

    /// The error of some rows of a file said of the whole file: each row number (from 1)
    /// `row` said as `file_row(row)`.
    pub fn renumbered(self, file_row: impl Fn(usize) -> usize) -> DataError {
        match self {
            DataError::NotNumeric { file, row, column, cell } => {
                DataError::NotNumeric { file, row: file_row(row), column, cell }
            }
            DataError::NonFinite { file, row, column, value } => {
                DataError::NonFinite { file, row: file_row(row), column, value }
            }
            DataError::Ragged { file, row, expected, found } => {
                DataError::Ragged { file, row: file_row(row), expected, found }
            }
            DataError::TimeNotIncreasing { file, row, column, this, previous, restart } => {
                DataError::TimeNotIncreasing { file, row: file_row(row), column, this, previous, restart }
            }
            DataError::RepeatedRow { file, row } => DataError::RepeatedRow { file, row: file_row(row) },
            DataError::CoarseTime { file, row, column, this, counted, interval } => {
                DataError::CoarseTime { file, row: file_row(row), column, this, counted, interval }
            }
            DataError::Unit { file, row, column, message } if row > 0 => {
                DataError::Unit { file, row: file_row(row), column, message }
            }
            DataError::TimeGap { file, row, column, step, median } => {
                DataError::TimeGap { file, row: file_row(row), column, step, median }
            }
            e => e,
        }
    }

    /// A signal-level "too short" said of a run: the file, and the signal when given (the
    /// derivative methods see bare signals and do not know where they came from).
    pub fn in_run(self, file: &str, signal: Option<&str>) -> DataError {
        match self {
            DataError::TooShort { rows, needed, what, .. } => DataError::TooShort {
                file: file.into(),
                rows,
                needed,
                what: match signal {
                    Some(s) => format!("{what} of `{s}`"),
                    None => what,
                },
            },
            e => e,
        }
    }
}

/// Whether every value is a number (not NaN, not ±∞): v − v is 0 for a number and NaN
/// otherwise, summed in eight independent lanes so that the compiler vectorises it.
#[allow(clippy::eq_op)] // v − v on purpose
fn all_finite(values: &[f64]) -> bool {
    let mut lanes = [0.0f64; 8];
    let chunks = values.chunks_exact(8);
    let rest = chunks.remainder();
    for c in chunks {
        for (l, v) in lanes.iter_mut().zip(c) {
            *l += v - v;
        }
    }
    lanes.iter().sum::<f64>() == 0.0 && rest.iter().all(|v| v.is_finite())
}

/// How a marked column behaves between its samples ([`Frame::hold`], [`Frame::switch`]).
#[derive(Clone, Copy)]
enum Between {
    Held,
    Switched,
}

/// Named f64 columns over a strictly increasing time column; each column either a line
/// between its samples (the default), held from each sample to the next ([`Frame::hold`]), or
/// switched at instants between two samples that the rows do not tell ([`Frame::switch`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    origin: String,
    time_name: String,
    names: Vec<String>,
    columns: Vec<Vec<f64>>,
    /// The columns held between samples (a zero-order hold).
    held: Vec<String>,
    /// The columns that switch somewhere between two samples (a relay, a step of a measured
    /// input): a fit leaves out the windows that hold a switch.
    switched: Vec<String>,
    /// How many rows of its file come before its first (a piece cut from a run, a trimmed
    /// window, a streamed chunk), so that what is said of a row names it as the file does.
    first_row: usize,
    /// Where its rows are not one stretch of its file (a run whose rows are interleaved with
    /// others' in a long file), each row's place in the file (from 0), `first_row` aside.
    file_rows: Option<Vec<usize>>,
    /// The file's columns of text left out (a run's label, a mode), with their first cell.
    text: Vec<(String, String)>,
    /// Where its rows were laid on an even grid with rows between the record's own samples
    /// (a sampling schedule's), which rows are samples: a re-simulation is compared at those
    /// only, as the rows between are the interpolation's. `None`: every row is a sample.
    recorded: Option<Vec<bool>>,
    /// The columns that repeated a slower sensor's readings, now read at them and
    /// interpolated between ([`read_at_readings`]), with the rows that are readings: their
    /// noise is the readings'.
    readings: Vec<(String, Repeats)>,
    /// The columns not recorded but estimated from others (a velocity from its position's
    /// record, [`crate::model::Model::estimated_rates`]), each with its standard error (root
    /// mean square): their noise, which their differences, smooth, do not show.
    estimated: Vec<(String, f64)>,
}

impl Frame {
    /// A frame with only its time column; `origin` names it in errors (usually the file).
    pub fn new(origin: &str, time_name: &str, time: Vec<f64>) -> Result<Frame, DataError> {
        if time.is_empty() {
            return Err(DataError::Empty { file: origin.into() });
        }
        let mut f = Frame {
            origin: origin.into(),
            time_name: time_name.into(),
            names: vec![],
            columns: vec![],
            held: vec![],
            switched: vec![],
            first_row: 0,
            file_rows: None,
            text: vec![],
            recorded: None,
            readings: vec![],
            estimated: vec![],
        };
        f.push(time_name, time)?;
        Ok(f)
    }

    /// Adds a column, refusing NaN/∞, a wrong length, a duplicate name and, for the time
    /// column, time that does not increase.
    pub fn push(&mut self, name: &str, values: Vec<f64>) -> Result<(), DataError> {
        if self.names.iter().any(|n| n == name) {
            return Err(DataError::DuplicateColumn { file: self.origin.clone(), column: name.into() });
        }
        self.check(name, &values)?;
        if self.columns.is_empty() {
            if let Some(i) = (1..values.len()).find(|&i| values[i] <= values[i - 1]) {
                if let Some(coarse) = coarse_time(&self.origin, name, &values) {
                    return Err(coarse);
                }
                if values.len() > 2 && values.windows(2).all(|w| w[1] < w[0]) {
                    return Err(DataError::TimeDescending {
                        file: self.origin.clone(),
                        column: name.into(),
                        first: values[0],
                        last: values[values.len() - 1],
                    });
                }
                return Err(DataError::TimeNotIncreasing {
                    file: self.origin.clone(),
                    row: i + 1,
                    column: name.into(),
                    this: values[i],
                    previous: values[i - 1],
                    // a repeated stamp is no restart; a time back at the first row's is
                    restart: values[i] < values[i - 1] && values[i] <= values[0],
                });
            }
        }
        self.names.push(name.into());
        self.columns.push(values);
        Ok(())
    }

    /// Refuses a column `name` of another length than the frame's, or with a value that is
    /// not finite (naming its row).
    fn check(&self, name: &str, values: &[f64]) -> Result<(), DataError> {
        if let Some(t) = self.columns.first() {
            if t.len() != values.len() {
                return Err(DataError::Length {
                    file: self.origin.clone(),
                    column: name.into(),
                    expected: t.len(),
                    found: values.len(),
                });
            }
        }
        // v − v is 0 for a number and NaN for NaN/±∞: one sum the compiler vectorises (the
        // row-by-row search ran at a fifth of the speed); the row only when there is one
        let finite = all_finite(values);
        if let Some((i, &v)) =
            (!finite).then(|| values.iter().enumerate().find(|(_, v)| !v.is_finite())).flatten()
        {
            return Err(DataError::NonFinite {
                file: self.origin.clone(),
                row: i + 1,
                column: name.into(),
                value: v,
            });
        }
        Ok(())
    }

    /// Replaces or adds a column.
    pub fn set(&mut self, name: &str, values: Vec<f64>) -> Result<(), DataError> {
        if let Some(i) = self.names.iter().position(|n| n == name) {
            if i == 0 {
                return Err(DataError::DuplicateColumn { file: self.origin.clone(), column: name.into() });
            }
            self.names.remove(i);
            self.columns.remove(i);
            self.held.retain(|h| h != name);
            self.switched.retain(|h| h != name);
        }
        self.push(name, values)
    }

    /// Replaces the values of column `name` where it stands (not the time column), checked as
    /// [`Frame::push`] checks them.
    pub fn overwrite(&mut self, name: &str, values: Vec<f64>) -> Result<(), DataError> {
        let i = match self.names.iter().position(|n| n == name) {
            Some(0) => {
                return Err(DataError::DuplicateColumn { file: self.origin.clone(), column: name.into() })
            }
            Some(i) => i,
            None => {
                return Err(DataError::MissingColumn {
                    file: self.origin.clone(),
                    column: name.into(),
                    available: self.names.join(", "),
                })
            }
        };
        self.check(name, &values)?;
        self.columns[i] = values;
        Ok(())
    }

    /// Gives column `from` the name `to` (the time column too); refused where `to` is taken.
    pub fn rename(&mut self, from: &str, to: &str) -> Result<(), DataError> {
        if self.names.iter().any(|n| n == to) {
            return Err(DataError::DuplicateColumn { file: self.origin.clone(), column: to.into() });
        }
        let i = self.names.iter().position(|n| n == from).ok_or_else(|| DataError::MissingColumn {
            file: self.origin.clone(),
            column: from.into(),
            available: self.names.join(", "),
        })?;
        if i == 0 {
            self.time_name = to.into();
        }
        self.names[i] = to.into();
        for h in self.held.iter_mut().chain(self.switched.iter_mut()).filter(|h| *h == from) {
            *h = to.into();
        }
        Ok(())
    }

    /// Adds column `name` estimated from the others (not recorded), with its standard error
    /// ([`Frame::estimated_error`]), as [`Frame::push`] adds a recorded one.
    pub fn push_estimated(&mut self, name: &str, values: Vec<f64>, error: f64) -> Result<(), DataError> {
        self.push(name, values)?;
        self.estimated.push((name.into(), error));
        Ok(())
    }

    /// The standard error of column `name` where it was estimated rather than recorded
    /// ([`Frame::push_estimated`]).
    pub fn estimated_error(&self, name: &str) -> Option<f64> {
        self.estimated.iter().find(|(n, _)| n == name).map(|(_, e)| *e)
    }

    /// Takes column `name` as held from each sample to the next (a zero-order hold: its
    /// integral and its replay into a simulation step, not a line, between samples); refused
    /// for the time column and a column the frame does not have.
    pub fn hold(&mut self, name: &str) -> Result<(), DataError> {
        self.mark(name, Between::Held)
    }

    /// Takes column `name` as switching somewhere between two samples where it jumps (a relay
    /// switched by the motion, a measured input stepped): the instant is not in the rows, so a
    /// rate's fit leaves out the windows that hold a switch ([`crate::data::switches`]); a
    /// replay draws a line across it. Refused as [`Frame::hold`] refuses.
    pub fn switch(&mut self, name: &str) -> Result<(), DataError> {
        self.mark(name, Between::Switched)
    }

    /// Marks column `name` (one the frame has, not its time) as `how` it behaves between
    /// samples, and as nothing else.
    fn mark(&mut self, name: &str, how: Between) -> Result<(), DataError> {
        match self.names.iter().position(|n| n == name) {
            Some(0) => {
                let what = match how {
                    Between::Held => "held",
                    Between::Switched => "switched",
                };
                Err(DataError::Setting(format!("{}: time `{name}` cannot be {what}", self.origin)))
            }
            Some(_) => {
                let already = match how {
                    Between::Held => self.is_held(name),
                    Between::Switched => self.is_switched(name),
                };
                if already {
                    // (kept where it was marked first)
                    return Ok(());
                }
                self.release(name);
                match how {
                    Between::Held => self.held.push(name.into()),
                    Between::Switched => self.switched.push(name.into()),
                }
                Ok(())
            }
            None => Err(DataError::MissingColumn {
                file: self.origin.clone(),
                column: name.into(),
                available: self.names.join(", "),
            }),
        }
    }

    /// Takes column `name` as a line between its samples again.
    pub fn release(&mut self, name: &str) {
        self.held.retain(|h| h != name);
        self.switched.retain(|h| h != name);
    }

    /// Whether column `name` is held between samples ([`Frame::hold`]).
    pub fn is_held(&self, name: &str) -> bool {
        self.held.iter().any(|h| h == name)
    }

    /// The columns held between samples, in the order they were marked.
    pub fn held(&self) -> &[String] {
        &self.held
    }

    /// Whether column `name` switches between samples ([`Frame::switch`]).
    pub fn is_switched(&self, name: &str) -> bool {
        self.switched.iter().any(|h| h == name)
    }

    /// The columns that switch between samples, in the order they were marked.
    pub fn switched(&self) -> &[String] {
        &self.switched
    }

    /// Where the frame came from (file name), for messages.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The columns of its file left out as text (a run's label, a mode), each with its first
    /// cell: no term can use them.
    pub fn text_columns(&self) -> &[(String, String)] {
        &self.text
    }

    /// What to say of the columns left out as text, where there are any.
    pub fn text_note(&self) -> Option<String> {
        let named: Vec<String> =
            self.text.iter().map(|(n, cell)| format!("`{n}` (`{cell}` in row 1)")).collect();
        (!named.is_empty()).then(|| {
            format!(
                "{}: {} {} text, not numbers: left out (no term or model can read {})",
                self.origin,
                named.join(", "),
                if named.len() == 1 { "holds" } else { "hold" },
                if named.len() == 1 { "it" } else { "them" }
            )
        })
    }

    /// The row of its file (counted from 1, as errors count them) that the frame's row `i`
    /// (from 0) is: a piece of a run keeps its file's numbering.
    pub fn row(&self, i: usize) -> usize {
        match &self.file_rows {
            Some(rows) => rows.get(i).map_or(self.first_row + i, |r| r + self.first_row) + 1,
            None => self.first_row + i + 1,
        }
    }

    /// The frame as the rows of its file from row `first_row + 1` on (a streamed chunk).
    pub fn starting_at(mut self, first_row: usize) -> Frame {
        self.first_row = first_row;
        self
    }

    /// The frame as the rows `rows` of its file (from 0, one per row of the frame: a run's
    /// rows among others' in a long file).
    pub(crate) fn at_file_rows(mut self, rows: Vec<usize>) -> Frame {
        let stretch = rows.windows(2).all(|w| w[1] == w[0] + 1);
        self.first_row = match stretch {
            true => rows.first().copied().unwrap_or(0),
            false => 0,
        };
        self.file_rows = (!stretch).then_some(rows);
        self
    }

    /// Which rows are the record's own samples where the frame was laid on an even grid with
    /// rows between them ([`evened`]); `None` where every row is one.
    pub fn recorded(&self) -> Option<&[bool]> {
        self.recorded.as_deref()
    }

    /// Whether row `k` is one of the record's own samples ([`Frame::recorded`]).
    pub fn is_sample(&self, k: usize) -> bool {
        self.recorded.as_ref().is_none_or(|r| r.get(k).copied().unwrap_or(true))
    }

    /// The frame with the rows `recorded` marks as the record's own samples, the rest
    /// interpolated between them (one flag a row; all marked is `None`).
    pub(crate) fn with_recorded(mut self, recorded: Vec<bool>) -> Frame {
        self.recorded = (recorded.len() == self.len() && recorded.iter().any(|r| !r)).then_some(recorded);
        self
    }

    /// Where column `name` repeated a slower sensor's readings and was read at them
    /// ([`read_at_readings`]), the rows that are readings.
    pub fn readings_of(&self, name: &str) -> Option<Repeats> {
        self.readings.iter().find(|(n, _)| n == name).map(|(_, r)| *r)
    }

    /// Column `name` as read at the rows `r` marks as a slower sensor's readings and
    /// interpolated between them.
    pub(crate) fn read_at(&mut self, name: &str, r: Repeats) {
        self.readings.retain(|(n, _)| n != name);
        self.readings.push((name.into(), r));
    }

    /// Name of the time column.
    pub fn time_name(&self) -> &str {
        &self.time_name
    }

    /// The time column.
    pub fn time(&self) -> &[f64] {
        &self.columns[0]
    }

    /// Seconds from the first row to row `k`.
    pub fn since_start(&self, k: usize) -> f64 {
        self.columns[0][k] - self.columns[0][0]
    }

    /// Seconds from the first row to the last.
    pub fn duration(&self) -> f64 {
        self.since_start(self.len() - 1)
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.columns[0].len()
    }

    /// Always false: a frame has at least one row.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Column names, time first.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// A column by name.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names.iter().position(|n| n == name).map(|i| self.columns[i].as_slice())
    }

    /// A column by name, or an error naming the file and the columns there are.
    pub fn require(&self, name: &str) -> Result<&[f64], DataError> {
        if let Some((_, cell)) = self.text.iter().find(|(n, _)| n == name) {
            return Err(DataError::text_column(&self.origin, name, cell));
        }
        self.column(name).ok_or_else(|| DataError::MissingColumn {
            file: self.origin.clone(),
            column: name.into(),
            available: self.names.join(", "),
        })
    }

    /// The frame cut into `count` pieces of equal length (fewer where a piece would have
    /// fewer than `shortest` rows; one at least), consecutive pieces sharing their boundary
    /// row so that each starts where the last ends; each named by its origin and "[k/count]".
    pub fn pieces(&self, count: usize, shortest: usize) -> Vec<Frame> {
        let n = self.len();
        let count = count.min(n / shortest.max(1)).max(1);
        if count == 1 {
            return vec![self.clone()];
        }
        (0..count)
            .map(|k| {
                let mut piece = self.slice(k * (n - 1) / count..(k + 1) * (n - 1) / count + 1);
                piece.origin = format!("{} [{}/{count}]", self.origin, k + 1);
                piece
            })
            .collect()
    }

    /// Rows `range` as a new frame.
    pub fn slice(&self, range: std::ops::Range<usize>) -> Frame {
        Frame {
            origin: self.origin.clone(),
            time_name: self.time_name.clone(),
            names: self.names.clone(),
            columns: self.columns.iter().map(|c| c[range.clone()].to_vec()).collect(),
            held: self.held.clone(),
            switched: self.switched.clone(),
            first_row: self.first_row + if self.file_rows.is_some() { 0 } else { range.start },
            file_rows: self.file_rows.as_ref().map(|r| r[range.clone()].to_vec()),
            text: self.text.clone(),
            recorded: self.recorded.as_ref().map(|r| r[range.clone()].to_vec()),
            readings: self
                .readings
                .iter()
                .map(|(name, r)| {
                    let phase = (r.phase + r.period - range.start % r.period) % r.period;
                    (name.clone(), Repeats { phase, ..*r })
                })
                .collect(),
            estimated: self.estimated.clone(),
        }
    }
}

/// The smallest step between successive distinct time stamps: the last digit they are
/// written to, where they are rounded (infinite where no stamp follows a smaller one).
fn stamps_digit(t: &[f64]) -> f64 {
    t.windows(2).map(|w| w[1] - w[0]).filter(|d| *d > 0.0).fold(f64::INFINITY, f64::min)
}

/// Rows that repeat their predecessor's time in at least this share of a time that never
/// decreases are a time written too coarsely, not a logger's odd duplicate.
const COARSE_SHARE: f64 = 0.25;

/// The refusal of a time written too coarsely for its rows ([`DataError::CoarseTime`]): it
/// never decreases and at least [`COARSE_SHARE`] of its rows (three at least) repeat the row
/// before's. A
/// repeated stamp read as a run that starts again sent the user looking for runs.
fn coarse_time(file: &str, column: &str, t: &[f64]) -> Option<DataError> {
    let steps = t.windows(2).map(|w| w[1] - w[0]);
    if steps.clone().any(|d| d < 0.0) {
        return None;
    }
    let repeats = steps.filter(|d| *d == 0.0).count();
    if repeats < 3 || (repeats as f64) < COARSE_SHARE * (t.len() - 1) as f64 {
        return None;
    }
    let first = t.windows(2).position(|w| w[1] == w[0])?;
    // the difference of two stamps carries their rounding: 0.09999999999999998 for 0.1
    let printed = stamps_digit(t);
    let printed = format!("{printed:.5e}").parse().unwrap_or(printed);
    let every = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    Some(DataError::CoarseTime {
        file: file.into(),
        row: first + 2,
        column: column.into(),
        this: t[first + 1],
        counted: format!("{repeats} of the {} rows do", t.len()),
        interval: format!(
            "{} s where the rows come every {} s on average",
            crate::output::sig(printed, 3),
            crate::output::sig(every, 3)
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_bad_columns() {
        let mut f = Frame::new("run.csv", "t", vec![0.0, 0.1, 0.2]).unwrap();
        assert!(matches!(f.push("u", vec![1.0, f64::NAN, 2.0]), Err(DataError::NonFinite { row: 2, .. })));
        assert!(matches!(f.push("u", vec![1.0]), Err(DataError::Length { .. })));
        assert!(matches!(
            Frame::new("run.csv", "t", vec![0.0, 0.1, 0.1]),
            Err(DataError::TimeNotIncreasing { row: 3, .. })
        ));
        f.push("u", vec![1.0, 2.0, 3.0]).unwrap();
        let e = f.require("v").unwrap_err().to_string();
        assert!(e.contains("run.csv") && e.contains("`v`") && e.contains("t, u"), "{e}");
    }
}
