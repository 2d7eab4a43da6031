//! A file of several runs in one table (a long table, as a data-frame library writes it): the
//! runs one after another or interleaved row by row, told apart by a column that names each
//! row's run. Each run becomes a frame of its own, its rows numbered as the file numbers them.

use std::path::Path;

use super::stream::Table;
use super::{DataError, Frame};

impl Frame {
    /// The runs of the file `path`, told apart by its column `by` (text or numbers): a frame
    /// per value, in the order the values first appear, with that value's rows in the file's
    /// order, named `FILE [by=value]`, the label itself not among its columns. A row without
    /// a label is refused, and every error names the file's row.
    /// Returns the runs and what to say of them (how many, their labels and lengths).
    pub fn read_by(path: &Path, time: &str, by: &str) -> Result<(Vec<Frame>, String), DataError> {
        let file = path.display().to_string();
        if by == time {
            return Err(DataError::Io {
                file,
                message: format!("`{by}` is the time column: the runs are told apart by a column that names each row's run"),
            });
        }
        let table = super::csv_io::read_plain_table(path, Some(by))?;
        let (parts, note) = split(table, by, &file)?;
        let runs = parts
            .into_iter()
            .map(|(origin, run, rows)| {
                let frame = Frame::from_table(run, &origin, time).map_err(|e| e.at_file_rows(&rows))?;
                Ok(frame.at_file_rows(rows))
            })
            .collect::<Result<_, DataError>>()?;
        Ok((runs, note))
    }
}

/// A table's rows told apart by its column `by`, whose labels it holds: a table per value, in
/// the order the values first appear, named `FILE [by=value]`, with the rows of the file it
/// holds (from 0), the label column left out; and what to say of them. A row without a label
/// is refused.
#[allow(clippy::type_complexity)]
pub(super) fn split(
    mut table: Table,
    by: &str,
    file: &str,
) -> Result<(Vec<(String, Table, Vec<usize>)>, String), DataError> {
    let labels = match table.labels.iter().position(|(n, _)| n == by) {
        Some(k) => table.labels.remove(k).1,
        None => Default::default(),
    };
    if let Some(k) = table.names.iter().position(|n| n == by) {
        table.names.remove(k);
        table.columns.remove(k);
    }
    table.text.retain(|(n, _)| n != by);
    if let Some(row) = labels.rows.iter().position(|&k| labels.values[k as usize].is_empty()) {
        return Err(DataError::Io {
            file: file.into(),
            message: format!(
                "row {}, column `{by}`: no label, so no run to put the row in (every row of a file of several runs names its run)",
                row + 1
            ),
        });
    }
    let groups = rows_of_each(&labels.rows, labels.values.len());
    let named: Vec<String> = groups
        .iter()
        .zip(&labels.values)
        .take(6)
        .map(|(rows, value)| format!("{value} ({} rows)", rows.len()))
        .collect();
    let more = match groups.len() > named.len() {
        true => format!(", and {} more", groups.len() - named.len()),
        false => String::new(),
    };
    let count = if groups.len() == 1 { "1 run".to_string() } else { format!("{} runs", groups.len()) };
    let note = format!("{file}: {count} told apart by `{by}`: {}{more}", named.join(", "));
    let parts = groups
        .into_iter()
        .zip(&labels.values)
        .map(|(rows, value)| {
            let run = Table {
                names: table.names.clone(),
                columns: table.columns.iter().map(|c| rows.iter().map(|&i| c[i]).collect()).collect(),
                text: table.text.clone(),
                labels: Vec::new(),
            };
            (format!("{file} [{by}={value}]"), run, rows)
        })
        .collect();
    Ok((parts, note))
}

/// Refuses the rows of several runs interleaved in one table read as one run (two vessels
/// logged in turn, time increasing throughout), naming the column of text that tells them
/// apart ([`interleaved`]).
pub(super) fn refuse_interleaved(table: &Table, file: &str) -> Result<(), DataError> {
    let columns: Vec<&[f64]> = table.columns.iter().map(Vec::as_slice).collect();
    for (column, labels) in &table.labels {
        if let Some((runs, changes)) = interleaved(&labels.rows, &columns) {
            let rows = labels.rows.len();
            return Err(DataError::Interleaved {
                file: file.into(),
                column: column.clone(),
                runs,
                changes,
                rows,
            });
        }
    }
    Ok(())
}

/// Whether rows labelled `labels` (each row's value, as an index) are those of several runs
/// interleaved: a few values that change at over a tenth of the rows, and the readings
/// (`columns`; a column that always increases, the time, aside) far smoother along each
/// value's rows than along all of them, which a mode or a status that flips within one run
/// does not make them. The number of runs and of changes where they are.
pub fn interleaved(labels: &[u32], columns: &[&[f64]]) -> Option<(usize, usize)> {
    let rows = labels.len();
    let runs = labels.iter().max().map_or(0, |&k| k as usize + 1);
    let changes = labels.windows(2).filter(|w| w[0] != w[1]).count();
    if runs < 2 || runs > 50.min(rows / 20) || changes * 10 < rows {
        return None;
    }
    // Σ of squared second differences: a reading's roughness along some of its rows
    let rough = |x: &[f64], at: &mut dyn Iterator<Item = usize>| {
        let v: Vec<f64> = at.map(|i| x[i]).collect();
        v.windows(3).map(|w| (w[2] - 2.0 * w[1] + w[0]).powi(2)).sum::<f64>()
    };
    let groups = rows_of_each(labels, runs);
    let readings: Vec<&[f64]> =
        columns.iter().copied().filter(|c| c.len() == rows && c.windows(2).any(|w| w[1] <= w[0])).collect();
    let smoother = readings
        .iter()
        .filter(|x| {
            let along_file = rough(x, &mut (0..rows));
            let along_runs: f64 = groups.iter().map(|g| rough(x, &mut g.iter().copied())).sum();
            along_file > 100.0 * along_runs
        })
        .count();
    (!readings.is_empty() && 2 * smoother > readings.len()).then_some((runs, changes))
}

/// The rows (from 0) of each of `values` labels, in order, from each row's label.
fn rows_of_each(labels: &[u32], values: usize) -> Vec<Vec<usize>> {
    let mut rows = vec![Vec::new(); values];
    for (i, &k) in labels.iter().enumerate() {
        rows[k as usize].push(i);
    }
    rows
}

/// The columns of numbers in the file `path`, the time among them, as its header has them
/// (what a model made from the file's columns may name).
pub fn columns_of(path: &Path) -> Result<Vec<String>, DataError> {
    Ok(super::in_si::InSi::wrap(super::stream::rows_of(path)?).names().to_vec())
}

/// The columns of text in the file `path` (a run's label, a mode: what the runs of a file
/// of several could be told apart by); none where it cannot be read.
pub fn text_columns_of(path: &Path) -> Vec<String> {
    super::stream::rows_of(path)
        .map_or_else(|_| Vec::new(), |rows| rows.text().iter().map(|(n, _)| n.clone()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(name: &str, text: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("termid-long-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    /// Runs one after another and runs interleaved row by row come apart alike, each in the
    /// file's order, the label left out, every row named as the file numbers it.
    #[test]
    fn a_long_file_comes_apart_by_its_label() {
        let after = file("after.csv", "run,t,x\na,0,1\na,1,2\na,2,3\nb,0,10\nb,1,20\n");
        let (runs, note) = Frame::read_by(&after, "t", "run").unwrap();
        assert!(note.ends_with("after.csv: 2 runs told apart by `run`: a (3 rows), b (2 rows)"), "{note}");
        assert_eq!(runs.len(), 2);
        assert!(runs[0].origin().ends_with("after.csv [run=a]"), "{}", runs[0].origin());
        assert_eq!(runs[0].names(), ["t", "x"]);
        assert_eq!(runs[0].column("x").unwrap(), [1.0, 2.0, 3.0]);
        assert_eq!(runs[1].column("x").unwrap(), [10.0, 20.0]);
        assert_eq!((runs[1].row(0), runs[1].row(1)), (4, 5));
        assert!(runs[0].text_columns().is_empty());

        // two vessels logged at each time stamp, a numeric label
        let mixed =
            file("mixed.csv", "t,ship,x,note\n0,1,1,calm\n0,2,5,calm\n1,1,2,calm\n1,2,6,calm\n2,1,3,calm\n");
        let (runs, _) = Frame::read_by(&mixed, "t", "ship").unwrap();
        assert!(runs[1].origin().ends_with("[ship=2]"));
        assert_eq!(runs[0].column("x").unwrap(), [1.0, 2.0, 3.0]);
        assert_eq!(runs[1].column("x").unwrap(), [5.0, 6.0]);
        assert_eq!((runs[0].row(2), runs[1].row(1)), (5, 4));
        assert_eq!(runs[1].slice(1..2).row(0), 4);
        assert_eq!(runs[0].text_columns()[0].0, "note");
    }

    /// Two runs logged in turn, time increasing throughout, are refused as one run, their
    /// label column named; a status that flips within one run is no such label.
    #[test]
    fn runs_interleaved_are_refused_as_one() {
        let mut two = String::from("t,x,ship\n");
        let mut flips = String::from("t,x,status\n");
        for i in 0..400 {
            let t = i as f64 * 0.01;
            two += &format!("{t},{},a\n{},{},b\n", t.sin(), t + 0.005, 5.0 + (t + 0.005).cos());
            flips += &format!("{t},{},{}\n", t.sin(), if (i * 7) % 3 == 0 { "ok" } else { "slow" });
        }
        let e = Frame::read(&file("two.csv", &two), "t").unwrap_err().to_string();
        assert!(
            e.contains("2 runs interleaved (`ship` changes at 799 of 800 rows") && e.contains("--by ship"),
            "{e}"
        );
        let (runs, _) = Frame::read_by(&file("two.csv", &two), "t", "ship").unwrap();
        assert_eq!(runs.len(), 2);
        let one = Frame::read(&file("flips.csv", &flips), "t").unwrap();
        assert_eq!(one.len(), 400);
    }

    /// What is wrong in one run is said at the file's row; a missing label, or no such
    /// column, is refused.
    #[test]
    fn errors_name_the_files_rows() {
        let back = file("back.csv", "t,run,x\n0,a,1\n0,b,1\n1,a,2\n0.5,a,3\n1,b,2\n");
        let e = Frame::read_by(&back, "t", "run").unwrap_err().to_string();
        assert!(e.contains("[run=a]: row 4, column `t`"), "{e}");
        let nan = file("nan.csv", "t,run,x\n0,a,1\n0,b,1\n1,a,2\n1,b,NaN\n");
        let e = Frame::read_by(&nan, "t", "run").unwrap_err().to_string();
        assert!(e.contains("[run=b]: row 4, column `x`"), "{e}");
        let blank = file("blank.csv", "t,run,x\n0,a,1\n1,,2\n");
        let e = Frame::read_by(&blank, "t", "run").unwrap_err().to_string();
        assert!(e.contains("row 2, column `run`: no label"), "{e}");
        let e = Frame::read_by(&blank, "t", "experiment").unwrap_err().to_string();
        assert!(e.contains("no column `experiment` (columns: t, x, run)"), "{e}");
        assert!(Frame::read_by(&blank, "t", "t").is_err());
    }
}
