//! Runs read in pieces, for one pass over files larger than memory: the rows come in chunks
//! of a fixed size, each with some rows of its neighbours on either side, so that a local
//! derivative (central differences, five points, Savitzky-Golay) comes out at every row of a
//! chunk's own part exactly as on the whole run. Memory stays at a few chunks whatever the
//! file's size; errors name the file's own rows.

use std::io::{BufRead, BufReader, Read};
use std::ops::Range;
use std::path::Path;

use super::clock::Midnights;
use super::separator::{Blanks, Separator};
use super::{DataError, Frame};

/// Where rows come from: a file's header, then its numeric rows in order.
pub trait RowSource {
    /// The names of the numeric columns.
    fn names(&self) -> &[String];
    /// Appends up to `max` rows to `columns` (one vector per name); returns how many were
    /// read, 0 at the end of the file.
    fn read(&mut self, max: usize, columns: &mut [Vec<f64>]) -> Result<usize, DataError>;
    /// The columns left out as text (a run's label, a comment), each with its first cell.
    fn text(&self) -> &[(String, String)] {
        &[]
    }
    /// From now on, keeps each row's cell of column `name` (of numbers or of text) as a
    /// label ([`Labels`]), besides those asked for before; false where the source has no such
    /// column or cannot.
    fn label_by(&mut self, _name: &str) -> bool {
        false
    }
    /// The labels kept since [`RowSource::label_by`], by column.
    fn take_labels(&mut self) -> Vec<(String, Labels)> {
        Vec::new()
    }
}

/// One column's cells as labels (the run each row belongs to, in a file of several runs):
/// its distinct values in the order they first appear, and each row's as an index into them.
#[derive(Clone, Debug, Default)]
pub struct Labels {
    /// The distinct values, in the order they first appear.
    pub values: Vec<String>,
    /// Each row's value, as its place in `values`.
    pub rows: Vec<u32>,
    index: std::collections::HashMap<String, u32>,
}

impl Labels {
    /// Adds a row's cell.
    pub fn push(&mut self, cell: &str) {
        // most rows repeat the row before's value (a run's rows together): compared first,
        // then a value seen before looked up without a copy of its text
        if let Some(&last) = self.rows.last() {
            if self.values[last as usize] == cell {
                self.rows.push(last);
                return;
            }
        }
        let k = match self.index.get(cell) {
            Some(&k) => k,
            None => {
                let k = self.values.len() as u32;
                self.index.insert(cell.to_string(), k);
                self.values.push(cell.to_string());
                k
            }
        };
        self.rows.push(k);
    }
}

/// A file's columns read whole: the numeric ones by name, and those left out as text
/// ([`RowSource::text`]).
pub(super) struct Table {
    pub names: Vec<String>,
    pub columns: Vec<Vec<f64>>,
    pub text: Vec<(String, String)>,
    /// The cells of the columns of text, and of the column the rows are told apart by where
    /// one was asked for, by column.
    pub labels: Vec<(String, Labels)>,
}

/// A piece of a run.
#[derive(Clone, Debug)]
pub struct Chunk {
    /// The chunk's rows with their neighbours, as a frame (its origin is the file).
    pub frame: Frame,
    /// The rows of `frame` that are this chunk's own; the others belong to its neighbours.
    pub own: Range<usize>,
    /// The file's row number (0-based, data rows) of the frame's first row.
    pub first_row: usize,
}

/// The chunks of one run, in order (an iterator of [`Chunk`]s).
pub struct Chunks {
    source: Box<dyn RowSource>,
    origin: String,
    time: usize,
    time_name: String,
    /// The time column's header, whose unit of time its values are read in (`t [ms]`).
    time_header: String,
    size: usize,
    context: usize,
    /// Rows held, from the file's row `held_from` on.
    held: Vec<Vec<f64>>,
    held_from: usize,
    /// The file's rows before this one are in chunks already given out.
    given: usize,
    ended: bool,
}

impl Chunks {
    /// The run in `path` (CSV text, or Parquet / Arrow IPC by the extension) in chunks of
    /// `size` rows, each with `context` rows of its neighbours on either side; `time` names
    /// the time column. Headers that carry a unit are read by their bare names in SI
    /// ([`super::units_note`]).
    pub fn open(path: &Path, time: &str, size: usize, context: usize) -> Result<Chunks, DataError> {
        Chunks::new(
            super::in_si::InSi::wrap(rows_of(path)?),
            &path.display().to_string(),
            time,
            size,
            context,
        )
    }

    /// Chunks of rows from any source.
    pub fn new(
        source: Box<dyn RowSource>,
        origin: &str,
        time: &str,
        size: usize,
        context: usize,
    ) -> Result<Chunks, DataError> {
        let names = source.names();
        let time_index = time_index(origin, time, names, source.text())?;
        let time_header = names[time_index].clone();
        let held = vec![Vec::new(); names.len()];
        Ok(Chunks {
            source,
            origin: origin.into(),
            time: time_index,
            time_name: time.into(),
            time_header,
            size: size.max(1),
            context,
            held,
            held_from: 0,
            given: 0,
            ended: false,
        })
    }

    /// The next chunk, or `None` after the last.
    fn next_chunk(&mut self) -> Result<Option<Chunk>, DataError> {
        let held_to = |c: &Chunks| c.held_from + c.held.first().map_or(0, Vec::len);
        // hold two chunks beyond what was given (and the context after them), so that the
        // last chunk is never shorter than one chunk: the end formulas of a derivative need
        // their rows inside it
        while !self.ended && held_to(self) < self.given + 2 * self.size + self.context {
            let want = self.given + 2 * self.size + self.context - held_to(self);
            if self.source.read(want, &mut self.held)? == 0 {
                self.ended = true;
            }
        }
        let end = held_to(self);
        if self.given >= end {
            if self.given == 0 {
                return Err(DataError::Empty { file: self.origin.clone() });
            }
            return Ok(None);
        }
        // the rest when it is less than two chunks, else one chunk
        let own_end =
            if self.ended && end - self.given < 2 * self.size { end } else { self.given + self.size };
        let from = self.given.saturating_sub(self.context).max(self.held_from);
        let to = (own_end + self.context).min(end);
        let slice = |c: &Vec<f64>| c[from - self.held_from..to - self.held_from].to_vec();
        let shift = |e: DataError| e.shifted(from);
        let seconds = super::in_seconds(&self.time_header, slice(&self.held[self.time]));
        let mut frame = Frame::new(&self.origin, &self.time_name, seconds).map_err(shift)?;
        frame.text = self.source.text().to_vec();
        for (k, name) in self.source.names().iter().enumerate() {
            if k != self.time {
                frame.push(name, slice(&self.held[k])).map_err(shift)?;
            }
        }
        // a chunk's first row must come after the previous chunk's last (the frame checks only
        // its own rows)
        let chunk =
            Chunk { frame: frame.starting_at(from), own: self.given - from..own_end - from, first_row: from };
        self.given = own_end;
        // keep only what the next chunk's context needs
        let keep_from = self.given.saturating_sub(self.context).max(self.held_from);
        for c in &mut self.held {
            c.drain(..keep_from - self.held_from);
        }
        self.held_from = keep_from;
        Ok(Some(chunk))
    }
}

impl Iterator for Chunks {
    type Item = Result<Chunk, DataError>;

    fn next(&mut self) -> Option<Self::Item> {
        match self.next_chunk() {
            Ok(Some(c)) => Some(Ok(c)),
            Ok(None) => None,
            Err(e) => {
                // an error ends the run
                self.ended = true;
                self.given = usize::MAX / 2;
                self.held.iter_mut().for_each(Vec::clear);
                self.held_from = self.given;
                Some(Err(e))
            }
        }
    }
}

/// A line longer than this is no CSV row (`/dev/zero`, a binary file): refused, not buffered.
const LONGEST_LINE: usize = 1 << 20;

/// Refuses a line longer than [`LONGEST_LINE`] bytes, and a NUL byte (a binary file), as
/// they pass.
struct LineLimit<R> {
    inner: R,
    since_newline: usize,
    /// Bytes passed before this read.
    offset: usize,
}

/// The message for a line beyond [`LONGEST_LINE`]: the file is not CSV.
fn too_long() -> String {
    format!("a line longer than {} MiB without a line break: not a CSV file", LONGEST_LINE >> 20)
}

/// The message for a NUL byte at `offset`: the file is not text.
fn nul_at(offset: usize) -> String {
    format!("byte {offset} is NUL: this is not a text file")
}

impl<R: Read> Read for LineLimit<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        let part = &buf[..n];
        if let Some(i) = memchr::memchr(0, part) {
            return Err(std::io::Error::other(nul_at(self.offset + i)));
        }
        self.offset += n;
        let (longest, last) = match memchr::memchr(b'\n', part) {
            // only the first line can continue the previous one, only the last go on
            Some(first) => {
                let last = memchr::memrchr(b'\n', part).unwrap_or(first);
                (self.since_newline + first, n - 1 - last)
            }
            None => (self.since_newline + n, self.since_newline + n),
        };
        // a line inside the buffer, between two breaks, is shorter than the buffer
        if longest.max(last) > LONGEST_LINE {
            return Err(std::io::Error::other(too_long()));
        }
        self.since_newline = last;
        Ok(n)
    }
}

/// Whether the file `path` is Parquet or Arrow IPC by its extension (else CSV text).
pub(super) fn is_columnar(path: &Path) -> bool {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    matches!(ext.as_deref(), Some("parquet" | "pq" | "arrow" | "feather" | "ipc"))
}

/// The rows of the file `path`: Parquet or Arrow IPC by its extension, else CSV text.
pub(super) fn rows_of(path: &Path) -> Result<Box<dyn RowSource>, DataError> {
    if is_columnar(path) {
        #[cfg(feature = "columnar")]
        return Ok(Box::new(super::columnar::Batches::open(path)?));
        #[cfg(not(feature = "columnar"))]
        return Err(DataError::Io {
            file: path.display().to_string(),
            message: "a columnar file: termid was built without the `columnar` feature".into(),
        });
    }
    Ok(Box::new(csv_rows(path)?))
}

/// The CSV rows of the file at `path`, read as they are needed.
pub(super) fn csv_rows(path: &Path) -> Result<CsvRows<'static>, DataError> {
    let origin = path.display().to_string();
    let io = |e: std::io::Error| DataError::Io { file: origin.clone(), message: e.to_string() };
    // (a spreadsheet's "Unicode text" export is UTF-16: read as UTF-8)
    let file = crate::budget::utf16::decoded(std::fs::File::open(path).map_err(io)?).map_err(io)?;
    CsvRows::new(BufReader::with_capacity(1 << 18, file), &origin)
}

/// CSV rows read as they are needed: the one CSV reader of termid (a whole file is all its
/// rows), so a file reads the same in one piece or in chunks.
pub(super) struct CsvRows<'a> {
    reader: csv::Reader<Box<dyn Read + 'a>>,
    /// Every column's name in the file.
    header: Vec<String>,
    /// The numeric columns: their names, and where they are in a row.
    names: Vec<String>,
    keep: Vec<usize>,
    text: Vec<(String, String)>,
    origin: String,
    /// Whether a comma in a cell is a decimal comma ([`Separator::decimal_commas`]).
    decimal_commas: bool,
    /// For each numeric column of times of day, the midnights it has passed.
    midnights: Vec<Option<Midnights>>,
    row: usize,
    record: csv::ByteRecord,
    /// The first row, read to tell text columns from numbers, is in `record`, not yet given.
    pending: bool,
    /// The columns whose cells are kept as labels (where they are in a row), and those kept.
    labels: Vec<(usize, String, Labels)>,
}

/// Cells that say a reading is missing, not that the column holds text.
const MISSING: [&str; 8] = ["", "null", "NULL", "NA", "N/A", "#N/A", "None", "-"];

impl<'a> CsvRows<'a> {
    /// Reads the header. Its separator ([`Separator`]) is told from the first two lines that
    /// are neither empty nor a comment: a header of semicolons and no comma is a European
    /// spreadsheet's CSV, whose numbers may also have decimal commas.
    pub(super) fn new(mut input: impl BufRead + 'a, origin: &str) -> Result<CsvRows<'a>, DataError> {
        let io = |e: &dyn std::fmt::Display| DataError::Io { file: origin.into(), message: e.to_string() };
        let mut peeked = Vec::new();
        let mut content: Vec<String> = Vec::new();
        while content.len() < 2 {
            let mut line = Vec::new();
            let n = (&mut input)
                .take(LONGEST_LINE as u64 + 1)
                .read_until(b'\n', &mut line)
                .map_err(|e| io(&e))?;
            if let Some(i) = memchr::memchr(0, &line) {
                return Err(io(&nul_at(peeked.len() + i)));
            }
            if n > LONGEST_LINE {
                return Err(io(&too_long()));
            }
            peeked.extend_from_slice(&line);
            let text = String::from_utf8_lossy(&line);
            let text = text.trim();
            if n == 0 {
                break;
            }
            if !text.is_empty() && !text.starts_with('#') {
                content.push(text.to_string());
            }
        }
        let separator = Separator::of(
            content.first().map_or("", String::as_str),
            content.get(1).map_or("", String::as_str),
        );
        let decimal_commas = separator.decimal_commas(content.get(1).map_or("", String::as_str));
        let limited =
            LineLimit { inner: std::io::Cursor::new(peeked).chain(input), since_newline: 0, offset: 0 };
        let rest: Box<dyn Read + 'a> = match separator {
            Separator::Blanks => Box::new(Blanks::new(BufReader::new(limited))),
            _ => Box::new(limited),
        };
        let mut reader = csv::ReaderBuilder::new()
            .delimiter(separator.byte())
            // cells are trimmed where they are read as numbers, only if they need it
            .trim(csv::Trim::Headers)
            .flexible(true)
            .comment(Some(b'#'))
            .from_reader(rest);
        let names: Vec<String> = reader.headers().map_err(|e| io(&e))?.iter().map(str::to_string).collect();
        if names.iter().all(String::is_empty) {
            return Err(DataError::NoHeader { file: origin.into() });
        }
        let refuse = |message: &str| Err(DataError::Io { file: origin.into(), message: message.into() });
        if names.iter().all(|n| number(n.as_bytes(), decimal_commas).is_some()) {
            return refuse("the first row holds numbers, not column names: a CSV needs a header row naming its columns (or a dataset file's `header = [...]`)");
        }
        for (i, h) in names.iter().enumerate() {
            if names[..i].contains(h) {
                return Err(DataError::DuplicateColumn { file: origin.into(), column: h.clone() });
            }
        }
        // a column whose first cell is text (a run's label, a mode, a comment) is no reading:
        // left out, where a column of numbers refuses a cell that is not one, with its row
        let mut record = csv::ByteRecord::new();
        let pending = reader.read_byte_record(&mut record).map_err(|e| io(&e))?;
        if separator == Separator::Blanks && pending && record.len() != names.len() {
            return refuse(&format!(
                "the columns are separated by blanks, and the header's {} names are {} readings in \
                 the first row: a name holds a blank (`x [m]`)? Name the columns without blanks, or \
                 read the file through a dataset file with `header = [...]`",
                names.len(),
                record.len()
            ));
        }
        let is_text = |cell: &[u8]| {
            let cell = String::from_utf8_lossy(cell.trim_ascii()).into_owned();
            (!MISSING.contains(&cell.as_str()) && number(cell.as_bytes(), decimal_commas).is_none())
                .then_some(cell)
        };
        let text: Vec<(usize, String)> = match pending && record.len() == names.len() {
            true => record.iter().enumerate().filter_map(|(c, cell)| is_text(cell).map(|t| (c, t))).collect(),
            false => Vec::new(),
        };
        // over half the cells text, or units throughout: a second header row (units, descriptions), not
        // labels; the first row's error says so
        let units = text.iter().all(|(_, cell)| super::dataset::is_unit(cell));
        let text = if 2 * text.len() > names.len() || units { Vec::new() } else { text };
        // a column with neither name nor first reading: the empty cell after a trailing comma,
        // as spreadsheets export rows (it refused the file, "row 1, column ``: no reading")
        let unnamed_blank = |c: usize| {
            names[c].is_empty() && pending && record.get(c).is_some_and(|cell| cell.trim_ascii().is_empty())
        };
        let keep: Vec<usize> =
            (0..names.len()).filter(|&c| !text.iter().any(|(t, _)| *t == c) && !unnamed_blank(c)).collect();
        // columns of times of day (their first cell one) read on past midnight
        let midnights = keep
            .iter()
            .map(|&c| {
                (pending
                    && record
                        .get(c)
                        .and_then(|cell| std::str::from_utf8(cell).ok())
                        .is_some_and(|cell| super::clock::time_of_day(cell).is_some()))
                .then(Midnights::default)
            })
            .collect();
        Ok(CsvRows {
            reader,
            midnights,
            names: keep.iter().map(|&c| names[c].clone()).collect(),
            keep,
            text: text.into_iter().map(|(c, cell)| (names[c].clone(), cell)).collect(),
            header: names,
            origin: origin.into(),
            decimal_commas,
            row: 0,
            record,
            pending,
            labels: Vec::new(),
        })
    }
}

impl RowSource for CsvRows<'_> {
    fn names(&self) -> &[String] {
        &self.names
    }

    fn read(&mut self, max: usize, columns: &mut [Vec<f64>]) -> Result<usize, DataError> {
        let mut n = 0;
        while n < max {
            let more = std::mem::take(&mut self.pending)
                || self
                    .reader
                    .read_byte_record(&mut self.record)
                    .map_err(|e| DataError::Io { file: self.origin.clone(), message: e.to_string() })?;
            if !more {
                break;
            }
            self.row += 1;
            if self.record.len() != self.header.len() {
                return Err(DataError::Ragged {
                    file: self.origin.clone(),
                    row: self.row,
                    expected: self.header.len(),
                    found: self.record.len(),
                });
            }
            for (k, &c) in self.keep.iter().enumerate() {
                let cell = &self.record[c];
                let not_numeric = || DataError::NotNumeric {
                    file: self.origin.clone(),
                    row: self.row,
                    column: self.names[k].clone(),
                    cell: String::from_utf8_lossy(cell.trim_ascii()).into(),
                };
                let v = number(cell, self.decimal_commas).ok_or_else(not_numeric)?;
                // digits beyond a double's range read as infinite: said as written (`1e400`)
                if v.is_infinite() && super::overflows(&String::from_utf8_lossy(cell)) {
                    return Err(not_numeric());
                }
                columns[k].push(match &mut self.midnights[k] {
                    Some(clock) => clock.read_on(v),
                    None => v,
                });
            }
            for (c, _, labels) in &mut self.labels {
                labels.push(&String::from_utf8_lossy(self.record[*c].trim_ascii()));
            }
            n += 1;
        }
        Ok(n)
    }

    fn text(&self) -> &[(String, String)] {
        &self.text
    }

    fn label_by(&mut self, name: &str) -> bool {
        let Some(c) = self.header.iter().position(|h| h == name) else { return false };
        self.labels.push((c, name.to_string(), Labels::default()));
        true
    }

    fn take_labels(&mut self) -> Vec<(String, Labels)> {
        std::mem::take(&mut self.labels).into_iter().map(|(_, name, labels)| (name, labels)).collect()
    }
}

/// A cell's number. Read from the bytes (no UTF-8 check of the row: a number is ASCII), with
/// Rust's own reading of text as the rule wherever the fast reader declines (`NaN`, `inf`,
/// which the frame then refuses with their row, and anything that is not a number), in a
/// European file a decimal comma, and a time stamp as seconds ([`super::clock_seconds`]).
fn number(cell: &[u8], decimal_commas: bool) -> Option<f64> {
    if let Ok(v) = lexical_core::parse::<f64>(cell) {
        return Some(v);
    }
    // a cell padded with blanks (` 1.5`, as some writers align columns)
    let cell = cell.trim_ascii();
    if let Ok(v) = lexical_core::parse::<f64>(cell) {
        return Some(v);
    }
    let text = std::str::from_utf8(cell).ok()?;
    match text.parse::<f64>() {
        Err(_) if decimal_commas => {
            text.replace(',', ".").parse::<f64>().ok().or_else(|| super::clock_seconds(text))
        }
        // a logger's time stamp, in seconds (the run's time is read from its first)
        Err(_) => super::clock_seconds(text),
        Ok(v) => Some(v),
    }
}

/// Where the time column `time` is among the numeric columns `names` (or `time` with a unit
/// of time: [`super::time_position`]); refused where it is missing (a column that looks like
/// time named) or is one of the columns of `text`.
pub(super) fn time_index(
    origin: &str,
    time: &str,
    names: &[String],
    text: &[(String, String)],
) -> Result<usize, DataError> {
    if let Some((_, cell)) = text.iter().find(|(n, _)| n == time) {
        return Err(DataError::text_column(origin, time, cell));
    }
    super::time_position(names, time).ok_or_else(|| DataError::missing_time(origin, time, names))
}

/// Every row of a source, as whole columns, the cells of its columns of text kept as labels;
/// with `by`, those of that column too (refused where the source has no such column).
pub(super) fn read_all(
    source: &mut dyn RowSource,
    origin: &str,
    by: Option<&str>,
) -> Result<Table, DataError> {
    if let Some(by) = by {
        if !source.label_by(by) {
            let available: Vec<&str> = source
                .names()
                .iter()
                .chain(source.text().iter().map(|(n, _)| n))
                .map(String::as_str)
                .collect();
            return Err(DataError::MissingColumn {
                file: origin.into(),
                column: by.into(),
                available: available.join(", "),
            });
        }
    }
    let text: Vec<String> =
        source.text().iter().map(|(n, _)| n.clone()).filter(|n| Some(n.as_str()) != by).collect();
    for name in text {
        source.label_by(&name);
    }
    let mut columns = vec![Vec::new(); source.names().len()];
    while source.read(65_536, &mut columns)? > 0 {}
    let labels = source.take_labels();
    Ok(Table { names: source.names().to_vec(), columns, text: source.text().to_vec(), labels })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The byte reader gives what Rust's reading of the same text gives, bit for bit, and
    /// declines what it declines.
    #[test]
    fn cells_read_as_rust_reads_them() {
        let mut x = 0.123_456_789_f64;
        for k in 0..20_000 {
            x = (x * 3.987 + 0.1).fract();
            let v = (x - 0.5) * 10f64.powi((k % 40) - 20);
            for text in [format!("{v:?}"), format!("{v:e}"), format!("{v:.3}"), format!("{v}")] {
                let ours = number(text.as_bytes(), false).unwrap();
                assert_eq!(ours.to_bits(), text.parse::<f64>().unwrap().to_bits(), "{text}");
            }
        }
        for text in ["1.", ".5", "+2", "-0", "1e308", "4.9e-324", "2.2250738585072011e-308", "0.1e1", "007"] {
            assert_eq!(
                number(text.as_bytes(), false).map(f64::to_bits),
                text.parse::<f64>().ok().map(f64::to_bits)
            );
        }
        assert!(number(b"NaN", false).unwrap().is_nan());
        assert_eq!(number(b"inf", false), Some(f64::INFINITY));
        for bad in ["", "abc", "1,5", "1.2.3", "--1", "1e", "0x10"] {
            assert_eq!(number(bad.as_bytes(), false), None, "{bad}");
        }
        assert_eq!(number(b"1,5", true), Some(1.5));
        assert_eq!(number(b" 1.5\t", false), Some(1.5));
        assert_eq!(number(b" 1,5 ", true), Some(1.5));
        assert_eq!(number("\u{e9}".as_bytes(), false), None);
    }

    fn csv(rows: usize) -> String {
        let mut s = String::from("t,x\n");
        for i in 0..rows {
            s += &format!("{},{}\n", i as f64 * 0.1, (i as f64 * 0.3).sin());
        }
        s
    }

    fn chunks(text: &'static str, size: usize, context: usize) -> Chunks {
        let rows = CsvRows::new(text.as_bytes(), "a.csv").unwrap();
        Chunks::new(Box::new(rows), "a.csv", "t", size, context).unwrap()
    }

    /// Every row is in exactly one chunk's own part, in order, with its context around it,
    /// and the last chunk is never shorter than one chunk.
    #[test]
    fn chunks_cover_every_row_once_with_context() {
        let text: &'static str = Box::leak(csv(1003).into_boxed_str());
        for (size, context) in [(100, 2), (7, 3), (1000, 1), (5000, 4)] {
            let mut next = 0;
            let mut sizes = Vec::new();
            for c in chunks(text, size, context) {
                let c = c.unwrap();
                let t = c.frame.time();
                assert_eq!(c.first_row + c.own.start, next);
                assert!(c.own.start >= context.min(next) && t.len() - c.own.end <= context);
                for (k, row) in c.own.clone().enumerate() {
                    assert!((t[row] - (next + k) as f64 * 0.1).abs() < 1e-9);
                }
                next += c.own.len();
                sizes.push(c.own.len());
            }
            assert_eq!(next, 1003, "size {size}");
            assert!(sizes.len() == 1 || *sizes.last().unwrap() >= size, "{sizes:?}");
        }
    }

    /// A bad cell or time is named by its row in the file, not in its chunk.
    #[test]
    fn errors_name_the_files_row() {
        let mut lines: Vec<String> = csv(500).lines().map(String::from).collect();
        lines[303] = lines[303].replacen(',', "x,", 1);
        let text: &'static str = Box::leak(lines.join("\n").into_boxed_str());
        let e = chunks(text, 50, 2).find_map(Result::err).unwrap().to_string();
        assert!(e.starts_with("a.csv: row 303, column `t`"), "{e}");
        // a value that parses but is not finite: found by the chunk's frame, said of the file
        let time = lines[303].split(',').next().unwrap().trim_end_matches('x').to_string();
        lines[303] = format!("{time},inf");
        let text: &'static str = Box::leak(lines.join("\n").into_boxed_str());
        let e = chunks(text, 50, 2).find_map(Result::err).unwrap().to_string();
        assert!(e.starts_with("a.csv: row 303, column `x`") && e.contains("not finite"), "{e}");
        // digits beyond a double's range are said as written, not as the infinity they read as
        lines[303] = format!("{time},-1e400");
        let text: &'static str = Box::leak(lines.join("\n").into_boxed_str());
        let e = chunks(text, 50, 2).find_map(Result::err).unwrap().to_string();
        assert!(
            e.starts_with("a.csv: row 303, column `x`: `-1e400` is beyond the largest number a double holds"),
            "{e}"
        );
        let e = chunks("t,x\n0,1\n0,2\n", 50, 2).find_map(Result::err).unwrap().to_string();
        assert!(e.contains("row 2") && e.contains("does not increase"), "{e}");
        assert!(matches!(chunks("t,x\n", 50, 2).next(), Some(Err(DataError::Empty { .. }))));
    }

    #[test]
    fn a_line_without_end_is_refused_not_buffered() {
        let zeros = std::io::BufReader::new(std::io::repeat(b'0').take(3 << 20));
        let e = CsvRows::new(zeros, "/dev/zero").err().unwrap().to_string();
        assert!(e.contains("longer than 1 MiB"), "{e}");
        let mut text = String::from("t,x\n0,1\n");
        text.push_str(&"9".repeat(2 << 20));
        let mut rows = CsvRows::new(text.as_bytes(), "long.csv").unwrap();
        let mut columns = vec![Vec::new(); 2];
        let e = rows.read(10, &mut columns).unwrap_err().to_string();
        assert!(e.contains("longer than 1 MiB"), "{e}");
    }

    /// A NUL byte is a binary file, in the header or anywhere after it, read whole (a file
    /// read as it is parsed) or in chunks: refused with its offset.
    #[test]
    fn a_nul_byte_is_not_text() {
        let e = CsvRows::new(&b"t,\0x\n0,1\n"[..], "bin.csv").err().unwrap().to_string();
        assert!(e.contains("byte 2 is NUL") && e.contains("not a text file"), "{e}");
        let dir = std::env::temp_dir().join(format!("termid-nul-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("late.csv");
        let mut text = csv(5000).into_bytes();
        let at = text.len() - 10;
        text[at] = 0;
        std::fs::write(&path, &text).unwrap();
        let e = Frame::read(&path, "t").unwrap_err().to_string();
        assert!(e.contains(&format!("byte {at} is NUL")) && e.contains("late.csv"), "{e}");
        let e = Chunks::open(&path, "t", 100, 2).unwrap().find_map(Result::err).unwrap().to_string();
        assert!(e.contains(&format!("byte {at} is NUL")), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
