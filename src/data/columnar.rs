//! Runs in columnar files: Parquet (`.parquet`, `.pq`) and Arrow IPC (`.arrow`, `.feather`,
//! `.ipc`), read record batch by record batch into the numeric columns a [`Frame`] holds,
//! with the same located errors as CSV (file, row, column). Behind the `columnar` feature.

use std::path::Path;

use arrow_array::cast::AsArray;
use arrow_array::types::{
    DurationMicrosecondType, DurationMillisecondType, DurationNanosecondType, DurationSecondType,
    Float32Type, Float64Type, Int16Type, Int32Type, Int64Type, Int8Type, TimestampMicrosecondType,
    TimestampMillisecondType, TimestampNanosecondType, TimestampSecondType, UInt16Type, UInt32Type,
    UInt64Type, UInt8Type,
};
use arrow_array::{Array, RecordBatch};
use arrow_schema::{DataType, TimeUnit};

use super::DataError;

/// A Parquet or Arrow IPC file's rows, record batch by record batch.
pub(super) struct Batches {
    batches: Box<dyn Iterator<Item = Result<RecordBatch, String>>>,
    /// Every column's name in the file.
    header: Vec<String>,
    /// The numeric columns: their names, and where they are in a batch.
    names: Vec<String>,
    keep: Vec<usize>,
    /// The columns of text (strings, a dictionary of them), with their type: left out.
    text: Vec<(String, String)>,
    file: String,
    rows: usize,
    /// The first batch, read to learn the names.
    first: Option<RecordBatch>,
    /// The columns whose cells are kept as labels (where they are in a batch), and those kept.
    labels: Vec<(usize, String, super::stream::Labels)>,
}

impl Batches {
    pub(super) fn open(path: &Path) -> Result<Batches, DataError> {
        let file = path.display().to_string();
        let io = |e: &dyn std::fmt::Display| DataError::Io { file: file.clone(), message: e.to_string() };
        let handle = std::fs::File::open(path).map_err(|e| io(&e))?;
        let parquet = matches!(
            path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(),
            Some("parquet" | "pq")
        );
        // the readers panic on some corrupt files (a buffer offset beyond its length): every
        // call into them is contained, and a panic is the file's error like any other
        let corrupt = |m: String| format!("the file is damaged ({m})");
        let mut batches: Box<dyn Iterator<Item = Result<RecordBatch, String>>> = if parquet {
            let reader = crate::contain::call(|| {
                parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(handle)
                    .and_then(|b| b.with_batch_size(65_536).build())
            })
            .map_err(|m| io(&corrupt(m)))?
            .map_err(|e| io(&e))?;
            Box::new(Contained(reader.map(|b| b.map_err(|e| e.to_string()))))
        } else {
            // the reader allocates what the footer declares before reading it: a damaged
            // footer is refused here, against the file's own size
            check_ipc_footer(path).map_err(|m| io(&corrupt(m)))?;
            let reader = crate::contain::call(|| arrow_ipc::reader::FileReader::try_new(handle, None))
                .map_err(|m| io(&corrupt(m)))?
                .map_err(|e| io(&e))?;
            Box::new(Contained(reader.map(|b| b.map_err(|e| e.to_string()))))
        };
        let first = batches
            .next()
            .ok_or_else(|| DataError::Io {
                file: file.clone(),
                message: "the file holds no rows (no record batch)".into(),
            })?
            .map_err(|m| io(&m))?;
        let schema = first.schema();
        let header: Vec<String> = schema.fields().iter().map(|f| f.name().clone()).collect();
        for (i, h) in header.iter().enumerate() {
            if header[..i].contains(h) {
                return Err(DataError::DuplicateColumn { file: file.clone(), column: h.clone() });
            }
        }
        // a column of text (a run's label, a mode) is no reading: left out, as CSV's
        let is_text = |t: &DataType| match t {
            DataType::Utf8 | DataType::LargeUtf8 | DataType::Utf8View => true,
            DataType::Dictionary(_, value) => {
                matches!(**value, DataType::Utf8 | DataType::LargeUtf8 | DataType::Utf8View)
            }
            _ => false,
        };
        let keep: Vec<usize> = (0..header.len()).filter(|&c| !is_text(schema.field(c).data_type())).collect();
        let text = (0..header.len())
            .filter(|c| !keep.contains(c))
            .map(|c| (header[c].clone(), format!("a column of type {}", schema.field(c).data_type())))
            .collect();
        let names = keep.iter().map(|&c| header[c].clone()).collect();
        Ok(Batches {
            batches,
            header,
            names,
            keep,
            text,
            file,
            rows: 0,
            first: Some(first),
            labels: Vec::new(),
        })
    }
}

/// Checks an Arrow IPC file's footer: its length, and every block (dictionaries, record
/// batches) within the file.
fn check_ipc_footer(path: &Path) -> Result<(), String> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let len = f.metadata().map_err(|e| e.to_string())?.len();
    if len < 18 {
        return Err(format!("{len} bytes are too few for an Arrow IPC file"));
    }
    let mut trailer = [0u8; 10];
    f.seek(SeekFrom::End(-10)).and_then(|_| f.read_exact(&mut trailer)).map_err(|e| e.to_string())?;
    if &trailer[4..] != b"ARROW1" {
        return Err("no Arrow IPC end marker (ARROW1)".into());
    }
    let footer_len = i32::from_le_bytes([trailer[0], trailer[1], trailer[2], trailer[3]]);
    let footer_len = u64::try_from(footer_len)
        .ok()
        .filter(|n| n + 10 + 8 <= len)
        .ok_or_else(|| format!("its footer declares {footer_len} bytes in a file of {len}"))?;
    let mut footer = vec![0u8; footer_len as usize];
    f.seek(SeekFrom::End(-10 - footer_len as i64))
        .and_then(|_| f.read_exact(&mut footer))
        .map_err(|e| e.to_string())?;
    let footer = crate::contain::call(|| {
        arrow_ipc::root_as_footer(&footer).map(|ft| {
            ft.dictionaries()
                .into_iter()
                .flatten()
                .chain(ft.recordBatches().into_iter().flatten())
                .map(|b| (b.offset(), i64::from(b.metaDataLength()), b.bodyLength()))
                .collect::<Vec<_>>()
        })
    })?
    .map_err(|e| format!("its footer is not readable: {e}"))?;
    for (offset, meta, body) in footer {
        let end = offset.checked_add(meta).and_then(|v| v.checked_add(body));
        if offset < 0 || meta < 0 || body < 0 || end.is_none_or(|e| e as u64 > len) {
            return Err(format!(
                "a block at byte {offset} declares {meta} + {body} bytes, beyond the file's {len}"
            ));
        }
    }
    Ok(())
}

/// A reader's batches, each read under [`crate::contain::call`]; a panic ends the iteration
/// as an error.
struct Contained<I>(I);

impl<I: Iterator<Item = Result<RecordBatch, String>>> Iterator for Contained<I> {
    type Item = Result<RecordBatch, String>;
    fn next(&mut self) -> Option<Self::Item> {
        crate::contain::call(|| self.0.next())
            .unwrap_or_else(|m| Some(Err(format!("the file is damaged ({m})"))))
            .map(|b| {
                // a batch that does not hold together (lengths, offsets) is refused before use
                b.and_then(|b| {
                    crate::contain::call(|| validate(&b))
                        .map_err(|m| format!("the file is damaged ({m})"))?
                        .map(|()| b)
                })
            })
    }
}

/// Checks a batch's arrays against their own lengths and offsets (the IPC reader trusts the
/// file's; a damaged one would make a later read index out of bounds).
fn validate(batch: &RecordBatch) -> Result<(), String> {
    for c in batch.columns() {
        c.to_data().validate_full().map_err(|e| format!("the file is damaged: {e}"))?;
        if c.len() != batch.num_rows() {
            return Err("the file is damaged: a column's length differs from its batch's".into());
        }
    }
    Ok(())
}

impl super::stream::RowSource for Batches {
    fn names(&self) -> &[String] {
        &self.names
    }

    /// Whole record batches until at least `max` rows (or the end).
    fn read(&mut self, max: usize, columns: &mut [Vec<f64>]) -> Result<usize, DataError> {
        let mut n = 0;
        while n < max {
            let batch = match self.first.take() {
                Some(b) => b,
                None => match self.batches.next() {
                    None => break,
                    Some(b) => b.map_err(|m| DataError::Io {
                        file: self.file.clone(),
                        message: format!("after row {}: {m}", self.rows),
                    })?,
                },
            };
            let schema = batch.schema();
            if schema.fields().iter().map(|f| f.name()).ne(self.header.iter()) {
                return Err(DataError::Io {
                    file: self.file.clone(),
                    message: format!("the columns change after row {}", self.rows),
                });
            }
            for (k, (&c, name)) in self.keep.iter().zip(&self.names).enumerate() {
                append(&mut columns[k], batch.column(c).as_ref(), &self.file, name, self.rows)?;
            }
            for (c, name, labels) in &mut self.labels {
                label_cells(labels, batch.column(*c).as_ref(), &self.file, name, self.rows)?;
            }
            self.rows += batch.num_rows();
            n += batch.num_rows();
        }
        Ok(n)
    }

    fn text(&self) -> &[(String, String)] {
        &self.text
    }

    fn label_by(&mut self, name: &str) -> bool {
        let Some(c) = self.header.iter().position(|h| h == name) else { return false };
        self.labels.push((c, name.to_string(), Default::default()));
        true
    }

    fn take_labels(&mut self) -> Vec<(String, super::stream::Labels)> {
        std::mem::take(&mut self.labels).into_iter().map(|(_, name, labels)| (name, labels)).collect()
    }
}

/// One batch's cells of a label column (text, a dictionary of text, or numbers) appended to
/// `labels`; a null is a blank label.
fn label_cells(
    labels: &mut super::stream::Labels,
    array: &dyn Array,
    file: &str,
    column: &str,
    first_row: usize,
) -> Result<(), DataError> {
    let text = |i: usize| -> Option<String> {
        match array.data_type() {
            DataType::Utf8 => Some(array.as_string::<i32>().value(i).to_string()),
            DataType::LargeUtf8 => Some(array.as_string::<i64>().value(i).to_string()),
            DataType::Utf8View => Some(array.as_string_view().value(i).to_string()),
            _ => None,
        }
    };
    match array.data_type() {
        DataType::Utf8 | DataType::LargeUtf8 | DataType::Utf8View => {
            for i in 0..array.len() {
                labels.push(&if array.is_null(i) { String::new() } else { text(i).unwrap_or_default() });
            }
        }
        DataType::Dictionary(..) => {
            let dict = array.as_any_dictionary();
            let mut values = super::stream::Labels::default();
            label_cells(&mut values, dict.values().as_ref(), file, column, first_row)?;
            for (i, k) in dict.normalized_keys().into_iter().enumerate() {
                let cell = match array.is_null(i) {
                    true => "",
                    false => values.rows.get(k).map_or("", |&v| values.values[v as usize].as_str()),
                };
                labels.push(cell);
            }
        }
        _ => {
            let mut numbers = Vec::with_capacity(array.len());
            append(&mut numbers, array, file, column, first_row)?;
            numbers.iter().for_each(|v| labels.push(&v.to_string()));
        }
    }
    Ok(())
}

/// One batch's values of a column as f64, refusing nulls and non-numeric types with the row.
fn append(
    out: &mut Vec<f64>,
    array: &dyn Array,
    file: &str,
    column: &str,
    first_row: usize,
) -> Result<(), DataError> {
    if let Some(i) = (0..array.len()).find(|&i| array.is_null(i)) {
        return Err(DataError::NotNumeric {
            file: file.into(),
            row: first_row + i + 1,
            column: column.into(),
            cell: "null".into(),
        });
    }
    macro_rules! push {
        ($t:ty) => {
            out.extend(array.as_primitive::<$t>().values().iter().map(|v| *v as f64))
        };
        // a time stamp or a duration in seconds (since 1970 UTC for a stamp: a run's time is
        // only used from its first), whole seconds and their fraction apart so that a
        // nanosecond stamp's seconds keep their fraction
        ($t:ty, $per_second:expr) => {
            out.extend(array.as_primitive::<$t>().values().iter().map(|v| {
                let (whole, part) = (v.div_euclid($per_second), v.rem_euclid($per_second));
                whole as f64 + part as f64 / $per_second as f64
            }))
        };
    }
    match array.data_type() {
        DataType::Timestamp(TimeUnit::Second, _) => push!(TimestampSecondType, 1i64),
        DataType::Timestamp(TimeUnit::Millisecond, _) => push!(TimestampMillisecondType, 1_000i64),
        DataType::Timestamp(TimeUnit::Microsecond, _) => push!(TimestampMicrosecondType, 1_000_000i64),
        DataType::Timestamp(TimeUnit::Nanosecond, _) => push!(TimestampNanosecondType, 1_000_000_000i64),
        DataType::Duration(TimeUnit::Second) => push!(DurationSecondType, 1i64),
        DataType::Duration(TimeUnit::Millisecond) => push!(DurationMillisecondType, 1_000i64),
        DataType::Duration(TimeUnit::Microsecond) => push!(DurationMicrosecondType, 1_000_000i64),
        DataType::Duration(TimeUnit::Nanosecond) => push!(DurationNanosecondType, 1_000_000_000i64),
        DataType::Float64 => out.extend_from_slice(array.as_primitive::<Float64Type>().values()),
        DataType::Float32 => push!(Float32Type),
        DataType::Int64 => push!(Int64Type),
        DataType::Int32 => push!(Int32Type),
        DataType::Int16 => push!(Int16Type),
        DataType::Int8 => push!(Int8Type),
        DataType::UInt64 => push!(UInt64Type),
        DataType::UInt32 => push!(UInt32Type),
        DataType::UInt16 => push!(UInt16Type),
        DataType::UInt8 => push!(UInt8Type),
        other => {
            return Err(DataError::NotNumeric {
                file: file.into(),
                row: first_row + 1,
                column: column.into(),
                cell: format!("a column of type {other}"),
            })
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use arrow_array::{ArrayRef, Float32Array, Float64Array, Int64Array, StringArray};
    use arrow_schema::{Field, Schema};

    use super::*;
    use crate::data::Frame;

    fn batch(columns: Vec<(&str, ArrayRef)>) -> RecordBatch {
        let schema = Schema::new(
            columns.iter().map(|(n, a)| Field::new(*n, a.data_type().clone(), true)).collect::<Vec<_>>(),
        );
        RecordBatch::try_new(Arc::new(schema), columns.into_iter().map(|(_, a)| a).collect()).unwrap()
    }

    fn write_parquet(path: &Path, batches: &[RecordBatch]) {
        let file = std::fs::File::create(path).unwrap();
        let mut w = parquet::arrow::ArrowWriter::try_new(file, batches[0].schema(), None).unwrap();
        for b in batches {
            w.write(b).unwrap();
        }
        w.close().unwrap();
    }

    /// A run written as Parquet (two row groups, f64, f32 and integer columns) and as Arrow
    /// IPC reads as the same frame as its CSV; nulls are refused with row and column, a column
    /// of text left out (refused with its type where it is asked for).
    /// A logger's time as Parquet keeps it: stamps in nanoseconds since 1970 (pandas'
    /// datetime64), and a duration in milliseconds, read as seconds (they were refused as "not a
    /// number"); 20 Hz stamps keep their twentieths at the epoch's magnitude.
    #[test]
    fn time_stamps_and_durations_read_as_seconds() {
        use arrow_array::{DurationMillisecondArray, TimestampNanosecondArray};
        let dir = std::env::temp_dir().join(format!("termid-stamps-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let start: i64 = 1_795_780_800_000_000_000; // 2026-11-27T12:00:00Z
        let stamps: Vec<i64> = (0..40).map(|k| start + k * 50_000_000).collect();
        let since: Vec<i64> = (0..40).map(|k| k * 50).collect();
        write_parquet(
            &dir.join("stamped.parquet"),
            &[batch(vec![
                ("t", Arc::new(TimestampNanosecondArray::from(stamps).with_timezone("UTC")) as ArrayRef),
                ("elapsed", Arc::new(DurationMillisecondArray::from(since))),
            ])],
        );
        let f = Frame::read(&dir.join("stamped.parquet"), "t").unwrap();
        let t = f.time();
        assert_eq!(t[0], 1_795_780_800.0);
        for k in 1..40 {
            assert!((t[k] - t[0] - 0.05 * k as f64).abs() < 1e-6, "row {k}: {}", t[k] - t[0]);
            assert!((f.column("elapsed").unwrap()[k] - 0.05 * k as f64).abs() < 1e-12);
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn parquet_and_arrow_read_as_csv_does() {
        let dir = std::env::temp_dir().join(format!("termid-columnar-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let t: Vec<f64> = (0..10).map(|k| 0.1 * k as f64).collect();
        let r: Vec<f64> = t.iter().map(|t| (3.0 * t).sin()).collect();
        let part = |a: usize, b: usize| {
            batch(vec![
                ("t", Arc::new(Float64Array::from(t[a..b].to_vec())) as ArrayRef),
                ("r", Arc::new(Float32Array::from(r[a..b].iter().map(|v| *v as f32).collect::<Vec<_>>()))),
                ("n", Arc::new(Int64Array::from((a as i64..b as i64).collect::<Vec<_>>()))),
            ])
        };
        write_parquet(&dir.join("run.parquet"), &[part(0, 4), part(4, 10)]);
        let f = Frame::read(&dir.join("run.parquet"), "t").unwrap();
        assert_eq!(f.time(), t.as_slice());
        assert_eq!(f.column("n").unwrap()[7], 7.0);
        assert!((f.column("r").unwrap()[9] - r[9]).abs() < 1e-6);
        // through a dataset file: its unit mapping applies as to CSV
        std::fs::write(
            dir.join("set.toml"),
            "[columns]\nt = \"t [s]\"\nr = \"r [deg/s]\"\n[[runs]]\nfile = \"run.parquet\"\n",
        )
        .unwrap();
        let set = crate::data::Dataset::load(&dir.join("set.toml")).unwrap();
        let (frames, _) = set.read(&dir, "t").unwrap();
        assert!((frames[0].column("r").unwrap()[9] - (r[9] as f32 as f64).to_radians()).abs() < 1e-12);
        // Arrow IPC
        let file = std::fs::File::create(dir.join("run.arrow")).unwrap();
        let mut w = arrow_ipc::writer::FileWriter::try_new(file, &part(0, 10).schema()).unwrap();
        w.write(&part(0, 10)).unwrap();
        w.finish().unwrap();
        let g = Frame::read(&dir.join("run.arrow"), "t").unwrap();
        assert_eq!(g.column("n").unwrap(), f.column("n").unwrap());
        // a null in the second row group: its row counted over the whole file
        let with_null = batch(vec![
            ("t", Arc::new(Float64Array::from(vec![0.5, 0.6])) as ArrayRef),
            ("r", Arc::new(Float64Array::from(vec![Some(1.0), None]))),
        ]);
        let first = batch(vec![
            ("t", Arc::new(Float64Array::from(vec![0.1, 0.2, 0.3])) as ArrayRef),
            ("r", Arc::new(Float64Array::from(vec![1.0, 2.0, 3.0]))),
        ]);
        write_parquet(&dir.join("null.parquet"), &[first, with_null]);
        let e = Frame::read(&dir.join("null.parquet"), "t").unwrap_err().to_string();
        assert!(
            e.contains("null.parquet")
                && e.contains("row 5")
                && e.contains("`r`")
                && e.contains("no reading there"),
            "{e}"
        );
        let text = batch(vec![
            ("t", Arc::new(Float64Array::from(vec![0.1])) as ArrayRef),
            ("name", Arc::new(StringArray::from(vec!["a"]))),
        ]);
        write_parquet(&dir.join("text.parquet"), &[text]);
        // a column of text is left out, said; asked for, refused with its type
        let f = Frame::read(&dir.join("text.parquet"), "t").unwrap();
        assert_eq!(f.names(), ["t"]);
        assert!(f.text_note().unwrap().contains("`name` (`a column of type Utf8` in row 1) holds text"));
        let e = f.require("name").unwrap_err().to_string();
        assert!(e.contains("`name`") && e.contains("Utf8"), "{e}");
        // an Arrow file with its columns but no rows: said so, not "a CSV needs a header row"
        let file = std::fs::File::create(dir.join("empty.arrow")).unwrap();
        let mut w = arrow_ipc::writer::FileWriter::try_new(file, &part(0, 1).schema()).unwrap();
        w.finish().unwrap();
        let e = Frame::read(&dir.join("empty.arrow"), "t").unwrap_err().to_string();
        assert!(e.contains("empty.arrow") && e.contains("no rows") && !e.contains("CSV"), "{e}");
        // not a Parquet file at all
        std::fs::write(dir.join("fake.parquet"), "t,r\n0,1\n").unwrap();
        let e = Frame::read(&dir.join("fake.parquet"), "t").unwrap_err().to_string();
        assert!(e.contains("fake.parquet"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A valid run as Arrow IPC and as Parquet bytes.
    fn valid_files() -> [(&'static str, Vec<u8>); 2] {
        let t: Vec<f64> = (0..200).map(|k| 0.1 * k as f64).collect();
        let b = batch(vec![
            ("t", Arc::new(Float64Array::from(t.clone())) as ArrayRef),
            ("x", Arc::new(Float32Array::from(t.iter().map(|v| v.sin() as f32).collect::<Vec<_>>()))),
            ("n", Arc::new(Int64Array::from((0..200).collect::<Vec<i64>>()))),
        ]);
        let mut arrow = Vec::new();
        {
            let mut w = arrow_ipc::writer::FileWriter::try_new(&mut arrow, &b.schema()).unwrap();
            w.write(&b).unwrap();
            w.write(&b.slice(0, 50)).unwrap();
            w.finish().unwrap();
        }
        let mut parquet = Vec::new();
        {
            let mut w = parquet::arrow::ArrowWriter::try_new(&mut parquet, b.schema(), None).unwrap();
            w.write(&b).unwrap();
            w.close().unwrap();
        }
        [("arrow", arrow), ("parquet", parquet)]
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 300, failure_persistence: None, ..Default::default() })]
        /// A damaged Arrow or Parquet file (bytes flipped, cut short) is an error that names
        /// the file, whole or in pieces; never a panic.
        #[test]
        fn damaged_columnar_files_are_errors_not_panics(
            flips in proptest::collection::vec((0.0f64..1.0, 1u8..=255), 1..4),
            cut in proptest::option::of(0.0f64..1.0),
            which in 0usize..2,
        ) {
            let dir = std::env::temp_dir().join(format!("termid-damaged-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            let (ext, mut bytes) = valid_files().into_iter().nth(which).unwrap();
            for (at, x) in &flips {
                let k = ((*at * bytes.len() as f64) as usize).min(bytes.len() - 1);
                bytes[k] ^= x;
            }
            if let Some(c) = cut {
                bytes.truncate((c * bytes.len() as f64) as usize);
            }
            let path = dir.join(format!("run{}.{ext}", std::thread::current().name().map_or(0, str::len)));
            std::fs::write(&path, &bytes).unwrap();
            let whole = std::panic::catch_unwind(|| Frame::read(&path, "t").map(|_| ()));
            proptest::prop_assert!(whole.is_ok(), "reading {ext} whole panicked");
            if let Ok(Err(e)) = whole {
                proptest::prop_assert!(e.to_string().contains(&*path.to_string_lossy()), "{e}");
            }
            let pieces = std::panic::catch_unwind(|| -> Result<(), DataError> {
                for c in crate::data::Chunks::open(&path, "t", 16, 2)? {
                    c?;
                }
                Ok(())
            });
            proptest::prop_assert!(pieces.is_ok(), "reading {ext} in pieces panicked");
        }
    }
}
