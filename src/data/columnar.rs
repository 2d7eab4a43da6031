//! Runs in columnar files: Parquet (`.parquet`, `.pq`) and Arrow IPC (`.arrow`, `.feather`,
//! `.ipc`), read record batch by record batch into the numeric columns a [`Frame`] holds,
//! with the same located errors as CSV (file, row, column). Behind the `columnar` feature.

use std::path::Path;

use arrow_array::cast::AsArray;
use arrow_array::types::{
    Float32Type, Float64Type, Int16Type, Int32Type, Int64Type, Int8Type, UInt16Type, UInt32Type, UInt64Type,
    UInt8Type,
};
use arrow_array::{Array, RecordBatch};
use arrow_schema::DataType;

use super::DataError;

/// The column names and numeric columns of a Parquet or Arrow IPC file.
pub fn read_columns(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), DataError> {
    super::stream::read_all(Batches::open(path)?)
}

/// A Parquet or Arrow IPC file's rows, record batch by record batch.
pub(super) struct Batches {
    batches: Box<dyn Iterator<Item = Result<RecordBatch, String>>>,
    names: Vec<String>,
    file: String,
    rows: usize,
    /// The first batch, read to learn the names.
    first: Option<RecordBatch>,
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
        let mut batches: Box<dyn Iterator<Item = Result<RecordBatch, String>>> = if parquet {
            let reader = parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(handle)
                .and_then(|b| b.with_batch_size(65_536).build())
                .map_err(|e| io(&e))?;
            Box::new(reader.map(|b| b.map_err(|e| e.to_string())))
        } else {
            let reader = arrow_ipc::reader::FileReader::try_new(handle, None).map_err(|e| io(&e))?;
            Box::new(reader.map(|b| b.map_err(|e| e.to_string())))
        };
        let first =
            batches.next().ok_or_else(|| DataError::NoHeader { file: file.clone() })?.map_err(|m| io(&m))?;
        let names: Vec<String> = first.schema().fields().iter().map(|f| f.name().clone()).collect();
        for (i, h) in names.iter().enumerate() {
            if names[..i].contains(h) {
                return Err(DataError::DuplicateColumn { file: file.clone(), column: h.clone() });
            }
        }
        Ok(Batches { batches, names, file, rows: 0, first: Some(first) })
    }
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
            if schema.fields().iter().map(|f| f.name()).ne(self.names.iter()) {
                return Err(DataError::Io {
                    file: self.file.clone(),
                    message: format!("the columns change after row {}", self.rows),
                });
            }
            for (k, (array, name)) in batch.columns().iter().zip(&self.names).enumerate() {
                append(&mut columns[k], array.as_ref(), &self.file, name, self.rows)?;
            }
            self.rows += batch.num_rows();
            n += batch.num_rows();
        }
        Ok(n)
    }
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
    }
    match array.data_type() {
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
    /// IPC reads as the same frame as its CSV; nulls and text are refused with row and column.
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
            e.contains("null.parquet") && e.contains("row 5") && e.contains("`r`") && e.contains("null"),
            "{e}"
        );
        let text = batch(vec![
            ("t", Arc::new(Float64Array::from(vec![0.1])) as ArrayRef),
            ("name", Arc::new(StringArray::from(vec!["a"]))),
        ]);
        write_parquet(&dir.join("text.parquet"), &[text]);
        let e = Frame::read(&dir.join("text.parquet"), "t").unwrap_err().to_string();
        assert!(e.contains("`name`") && e.contains("Utf8"), "{e}");
        // not a Parquet file at all
        std::fs::write(dir.join("fake.parquet"), "t,r\n0,1\n").unwrap();
        let e = Frame::read(&dir.join("fake.parquet"), "t").unwrap_err().to_string();
        assert!(e.contains("fake.parquet"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
