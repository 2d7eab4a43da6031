//! CSV in and out. A header row names the columns; a column whose first cell is text (a run's
//! label, a mode) is left out, and every other cell must be a finite number.

use std::path::Path;

use super::stream::{RowSource, Table};
use super::{DataError, Frame};

impl Frame {
    /// Reads a CSV file whose header names the columns; `time` names the time column.
    pub fn read_csv(path: &Path, time: &str) -> Result<Frame, DataError> {
        let file = path.display().to_string();
        let text = crate::budget::read_text(path)
            .map_err(|e| DataError::Io { file: file.clone(), message: e.to_string() })?;
        Frame::parse_csv(&text, &file, time)
    }

    /// Reads a CSV file of rows that are not a time series (e.g. the Hald cement data):
    /// a column `row` numbered 1..n stands in for time.
    pub fn read_csv_untimed(path: &Path) -> Result<Frame, DataError> {
        let file = path.display().to_string();
        let text = crate::budget::read_text(path)
            .map_err(|e| DataError::Io { file: file.clone(), message: e.to_string() })?;
        Frame::parse_csv_untimed(&text, &file)
    }

    /// Parses CSV text without a time column (rows numbered 1..n in a column `row`).
    pub fn parse_csv_untimed(text: &str, origin: &str) -> Result<Frame, DataError> {
        let table = parse_table(text, origin, None)?;
        if table.names.iter().chain(table.text.iter().map(|t| &t.0)).any(|h| h == "row") {
            return Err(DataError::DuplicateColumn { file: origin.into(), column: "row".into() });
        }
        let rows = table.columns.first().map_or(0, Vec::len);
        let mut frame = Frame::new(origin, "row", (1..=rows).map(|r| r as f64).collect())?;
        for (name, values) in table.names.iter().zip(table.columns) {
            frame.push(name, values)?;
        }
        frame.text = table.text;
        Ok(frame)
    }

    /// Reads a run by its file's extension: Parquet (`.parquet`, `.pq`) and Arrow IPC
    /// (`.arrow`, `.feather`, `.ipc`) with the `columnar` feature, CSV otherwise.
    /// Rows of several runs interleaved (told by a column of text) are refused, naming it.
    pub fn read(path: &Path, time: &str) -> Result<Frame, DataError> {
        let (table, file) = (read_plain_table(path, None)?, path.display().to_string());
        super::long::refuse_interleaved(&table, &file)?;
        Frame::from_table(table, &file, time)
    }

    /// Parses CSV text; `origin` names it in errors.
    pub fn parse_csv(text: &str, origin: &str, time: &str) -> Result<Frame, DataError> {
        Frame::from_table(parse_table(text, origin, None)?, origin, time)
    }

    /// A frame of a table's named columns, `time` among them, knowing its columns of text.
    pub(super) fn from_table(table: Table, origin: &str, time: &str) -> Result<Frame, DataError> {
        let Table { names, mut columns, text, .. } = table;
        let time_index = super::stream::time_index(origin, time, &names, &text)?;
        let seconds = super::in_seconds(&names[time_index], std::mem::take(&mut columns[time_index]));
        let mut frame =
            Frame::new(origin, time, seconds).map_err(|e| repeated_row(e, &columns, time_index))?;
        for (k, (name, values)) in names.iter().zip(columns).enumerate() {
            if k != time_index {
                frame.push(name, values)?;
            }
        }
        frame.text = text;
        Ok(frame)
    }

    /// Writes the frame as CSV (time first), numbers in shortest round-trip form; atomically
    /// (the old file stays until the new one is whole).
    pub fn write_csv(&self, path: &Path) -> Result<(), DataError> {
        crate::output::write_file(path, self.to_csv().as_bytes())
            .map_err(|e| DataError::Io { file: path.display().to_string(), message: e.reason() })
    }

    /// The frame as CSV text.
    pub fn to_csv(&self) -> String {
        let mut out = self.names().join(",");
        out.push('\n');
        // the time in the unit its header says, as it is read back
        let time = super::from_seconds(self.time_name(), self.time().to_vec());
        let mut cols: Vec<&[f64]> = self.names().iter().filter_map(|n| self.column(n)).collect();
        cols[0] = &time;
        for r in 0..self.len() {
            let row: Vec<String> = cols.iter().map(|c| format!("{:?}", c[r])).collect();
            out.push_str(&row.join(","));
            out.push('\n');
        }
        out
    }
}

/// The numeric columns of a file by name, and its columns of text: columnar by its
/// extension, else CSV text; with `by`, each row's cell of that column as its label.
pub(super) fn read_table(path: &Path, by: Option<&str>) -> Result<Table, DataError> {
    table_of(path, by, |rows| rows)
}

/// [`read_table`] of a plain file (not one a dataset file maps): headers that carry a unit
/// read by their bare names in SI ([`super::units_note`]).
pub(super) fn read_plain_table(path: &Path, by: Option<&str>) -> Result<Table, DataError> {
    table_of(path, by, super::in_si::InSi::wrap)
}

fn table_of(
    path: &Path,
    by: Option<&str>,
    read: impl Fn(Box<dyn RowSource>) -> Box<dyn RowSource>,
) -> Result<Table, DataError> {
    let file = path.display().to_string();
    if super::stream::is_columnar(path) {
        return super::stream::read_all(read(super::stream::rows_of(path)?).as_mut(), &file, by);
    }
    // read as it is parsed: the numbers in memory, not the text as well
    crate::budget::file_size(path)
        .map_err(|e| DataError::Io { file: file.clone(), message: e.to_string() })?;
    super::stream::read_all(read(Box::new(super::stream::csv_rows(path)?)).as_mut(), &file, by).map_err(|e| {
        let head = || {
            use std::io::Read;
            let mut head = Vec::new();
            let _ = std::fs::File::open(path).map(|f| f.take(HEAD).read_to_end(&mut head));
            head
        };
        not_data(e, &file, head)
    })
}

/// How much of a file is looked at to tell whether it is data at all.
const HEAD: u64 = 16 << 10;

/// An error found early in a file that holds no number in its first rows (a password file,
/// a script, a document) is said as "not a table of numbers", without echoing its lines: of
/// a file that is not data, no more than its name and the reason.
pub(super) fn not_data(e: DataError, file: &str, head: impl FnOnce() -> Vec<u8>) -> DataError {
    let early = match &e {
        DataError::NotNumeric { row, .. } | DataError::Ragged { row, .. } => *row <= 5,
        DataError::DuplicateColumn { .. } => true,
        _ => false,
    };
    if !early {
        return e;
    }
    let head = head();
    let text = String::from_utf8_lossy(&head);
    let any_number = text.lines().skip(1).take(5).any(|l| {
        l.split([',', ';', '\t', ' '])
            .any(|c| c.trim().replace(',', ".").parse::<f64>().is_ok_and(f64::is_finite))
    });
    if any_number {
        return e;
    }
    DataError::Io {
        file: file.into(),
        message: "not a table of numbers: no number in its first rows (is it a data file? a CSV has a header row and numbers below it)".into(),
    }
}

/// [`Frame::new`]'s refusal of a time that does not increase said as a repeated row where the
/// whole row repeats the one before (a logger's duplicate): `columns` the table's, the time's
/// own (at `time_index`, taken out) left aside.
pub(super) fn repeated_row(e: DataError, columns: &[Vec<f64>], time_index: usize) -> DataError {
    match e {
        DataError::TimeNotIncreasing { file, row, this, previous, .. }
            if this == previous
                && row >= 2
                && columns
                    .iter()
                    .enumerate()
                    .all(|(c, v)| c == time_index || v.get(row - 1) == v.get(row - 2)) =>
        {
            DataError::RepeatedRow { file, row }
        }
        e => e,
    }
}

/// The header and the numeric columns of CSV text, every cell checked.
pub(super) fn parse_table(text: &str, origin: &str, by: Option<&str>) -> Result<Table, DataError> {
    super::stream::CsvRows::new(text.as_bytes(), origin)
        .and_then(|mut rows| super::stream::read_all(&mut rows, origin, by))
        .map_err(|e| not_data(e, origin, || text.as_bytes()[..text.len().min(HEAD as usize)].to_vec()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_errors() {
        let f = Frame::parse_csv("t,u\n0,1.5\n0.2,2\n", "a.csv", "t").unwrap();
        assert_eq!(Frame::parse_csv(&f.to_csv(), "a.csv", "t").unwrap(), f);
        let e = Frame::parse_csv("t,u\n0,1\n0.2,x\n", "a.csv", "t").unwrap_err().to_string();
        assert_eq!(e, "a.csv: row 2, column `u`: `x` is not a number");
        let e = Frame::parse_csv("t,u\n0,1\n0.2,NaN\n", "a.csv", "t").unwrap_err().to_string();
        assert!(e.contains("row 2, column `u`") && e.contains("not finite"), "{e}");
        let e = Frame::parse_csv("t,u\n0,1\n0,2\n", "a.csv", "t").unwrap_err().to_string();
        assert!(e.contains("row 2") && e.contains("does not increase"), "{e}");
        let e = Frame::parse_csv("t,u\n0,1\n0.1,2\n0.1,2\n0.2,3\n", "a.csv", "t").unwrap_err().to_string();
        assert_eq!(e, "a.csv: row 3 repeats row 2 in every column, its time too (a logger's duplicate): drop it (pandas' `df.drop_duplicates()`)");
        // a clock of the time of day read on past midnight (it was a run starting again); one
        // that falls back by an hour is refused still
        let f = Frame::parse_csv("t,u\n23:59:59.5,1\n00:00:00.0,2\n00:00:00.5,3\n", "a.csv", "t").unwrap();
        assert_eq!(f.time(), [86_399.5, 86_400.0, 86_400.5]);
        let e = Frame::parse_csv("t,u\n10:00:00,1\n09:00:00,2\n", "a.csv", "t").unwrap_err().to_string();
        assert!(e.contains("row 2") && e.contains("does not increase"), "{e}");
        // a stamp repeated is no run starting again
        let e = Frame::parse_csv("t,u\n0,1\n0,2\n", "a.csv", "t").unwrap_err().to_string();
        assert!(!e.contains("starts again"), "{e}");
        // rows at 100 Hz, their time written to 0.1 s: said as such, not as runs that start again
        let rows: String = (0..40).map(|i| format!("{:.1},{}\n", 0.01 * i as f64, i)).collect();
        let e = Frame::parse_csv(&format!("t,u\n{rows}"), "a.csv", "t").unwrap_err().to_string();
        assert!(
            e.contains("row 2, column `t`: time 0 repeats the row before's, as 35 of the 40 rows do")
                && e.contains("written to 0.100 s where the rows come every 0.0103 s"),
            "{e}"
        );
        assert!(matches!(Frame::parse_csv("t,u\n", "a.csv", "t"), Err(DataError::Empty { .. })));
        assert!(matches!(Frame::parse_csv("", "a.csv", "t"), Err(DataError::NoHeader { .. })));
        // without time: the file's own cells counted, no column of termid's own named
        let e = Frame::parse_csv_untimed("x,y\n1,2\n3\n", "h.csv").unwrap_err().to_string();
        assert_eq!(e, "h.csv: row 2 has 1 cells, the header has 2");
        let f = Frame::parse_csv_untimed("# c\nx,y\n1,2\n\n3,4\n", "h.csv").unwrap();
        assert_eq!(f.column("row").unwrap(), [1.0, 2.0]);
        assert_eq!(f.column("y").unwrap(), [2.0, 4.0]);
        let missing = Frame::parse_csv("time,u\n0,1\n", "a.csv", "t").unwrap_err();
        assert!(matches!(missing, DataError::MissingTime { .. }));
        assert!(missing.to_string().contains("`time` looks like time"), "{missing}");
        let missing = Frame::parse_csv("Time [s],u\n0,1\n", "a.csv", "t").unwrap_err().to_string();
        assert!(missing.contains("map it in a dataset file (`[columns] t = \"Time [s]\"`)"), "{missing}");
        let missing = Frame::parse_csv("time,u\n0,1\n", "a.csv", "t").unwrap_err().to_string();
        assert!(missing.contains("(`--time time`, a model file's `time`)"), "{missing}");
        let missing = Frame::parse_csv("timer,u\n0,1\n", "a.csv", "t").unwrap_err().to_string();
        assert!(!missing.contains("looks like time"), "{missing}");
        assert!(matches!(
            Frame::parse_csv("t,u\n0,1,2\n", "a.csv", "t"),
            Err(DataError::Ragged { row: 1, .. })
        ));
        // a trailing comma on every row (a spreadsheet's export): the empty column is no column
        let f = Frame::parse_csv("t,u,\n0,1,\n0.2,2,\n", "a.csv", "t").unwrap();
        assert_eq!(
            (f.names(), f.column("u").unwrap()),
            (&["t".to_string(), "u".to_string()][..], &[1.0, 2.0][..])
        );
        // a time that starts again: runs one after another, said
        let e = Frame::parse_csv("t,u\n0,1\n0.1,2\n0,3\n", "a.csv", "t").unwrap_err().to_string();
        assert!(e.contains("row 3") && e.contains("it starts again: runs one after another?"), "{e}");
        // newest first (a database export sorted descending): said so, not a restart at row 2
        let e = Frame::parse_csv("t,u\n0.2,1\n0.1,2\n0,3\n", "a.csv", "t").unwrap_err().to_string();
        assert!(
            e.contains("time decreases at every row, from 0.2 to 0: the rows are newest first")
                && !e.contains("starts again"),
            "{e}"
        );
    }

    /// A column whose first cell is text (a run's label, a mode) is left out and said, and
    /// refused with that cell where it is asked for; a row of units, a second header row
    /// (most cells text), or a missing reading (`NA`) leave nothing out: their errors stand.
    #[test]
    fn text_columns_are_left_out() {
        let f = Frame::parse_csv("t,u,run,mode\n0,1,a,ok\n0.1,2,a,ok\n0.2,3,b,3\n", "a.csv", "t").unwrap();
        assert_eq!(f.names(), ["t", "u"]);
        assert_eq!(f.column("u").unwrap(), [1.0, 2.0, 3.0]);
        let note = f.text_note().unwrap();
        assert!(note.contains("`run` (`a` in row 1), `mode` (`ok` in row 1) hold text"), "{note}");
        assert_eq!(
            f.require("run").unwrap_err().to_string(),
            "a.csv: row 1, column `run`: `a` is not a number"
        );
        let f = Frame::parse_csv("t,u\n0,1\n", "a.csv", "t").unwrap();
        assert_eq!(f.text_note(), None);
        for (text, cell) in [
            ("t,u,v,w\ns,m,m/s,N\n0,1,2,3\n", "`s` is not a number"),
            ("t,u,v,w\n0,m,m/s,N\n0.1,1,2,3\n", "`m` is not a number"),
            ("t,u,v,w\n,speed,heading,w\n0,1,2,3\n", "no reading there"),
            ("t,u,v,w\n0,NA,1,2\n0.1,1,2,3\n", "`NA` is not a number"),
            // asked for, a label column is refused at its first cell
            ("t,u,v,w\n0,1,2,x\n0.1,1,2,3\n", "row 1, column `w`: `x` is not a number"),
        ] {
            let e = Frame::parse_csv(text, "a.csv", "t").map(|f| f.require("w").map(<[f64]>::to_vec));
            let e = match e {
                Err(e) | Ok(Err(e)) => e.to_string(),
                Ok(Ok(w)) => panic!("{text}: read {w:?}"),
            };
            assert!(e.contains(cell), "{text}: {e}");
        }
    }
}
