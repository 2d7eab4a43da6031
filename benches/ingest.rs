//! Ingest speed (issue 16): a run of 20 numeric columns × 200 000 rows read from CSV and from
//! Parquet into a frame, throughput counted in the numeric data's bytes (8 per value), and for
//! CSV also in the bytes of its text (`csv-text`); and the search of every column for spikes
//! that reading a rate's runs adds (`spikes`).
//! `cargo bench --bench ingest`.

use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use termid::data::Frame;

const ROWS: usize = 200_000;
const COLUMNS: usize = 20;

fn files() -> (std::path::PathBuf, std::path::PathBuf) {
    let dir = std::env::temp_dir().join(format!("termid-ingest-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let names: Vec<String> =
        std::iter::once("t".to_string()).chain((1..COLUMNS).map(|k| format!("c{k}"))).collect();
    let columns: Vec<Vec<f64>> = (0..COLUMNS)
        .map(|k| {
            (0..ROWS)
                .map(|r| if k == 0 { 0.05 * r as f64 } else { (0.001 * (r * k) as f64).sin() * 3.7 })
                .collect()
        })
        .collect();
    let mut csv = names.join(",");
    csv.push('\n');
    for r in 0..ROWS {
        let row: Vec<String> = columns.iter().map(|c| format!("{:?}", c[r])).collect();
        csv.push_str(&row.join(","));
        csv.push('\n');
    }
    let csv_path = dir.join("run.csv");
    std::fs::write(&csv_path, csv).unwrap();
    let fields: Vec<arrow_schema::Field> =
        names.iter().map(|n| arrow_schema::Field::new(n, arrow_schema::DataType::Float64, false)).collect();
    let arrays: Vec<arrow_array::ArrayRef> =
        columns.iter().map(|c| Arc::new(arrow_array::Float64Array::from(c.clone())) as _).collect();
    let batch =
        arrow_array::RecordBatch::try_new(Arc::new(arrow_schema::Schema::new(fields)), arrays).unwrap();
    let pq_path = dir.join("run.parquet");
    let mut w =
        parquet::arrow::ArrowWriter::try_new(std::fs::File::create(&pq_path).unwrap(), batch.schema(), None)
            .unwrap();
    w.write(&batch).unwrap();
    w.close().unwrap();
    (csv_path, pq_path)
}

fn ingest(c: &mut Criterion) {
    let (csv, pq) = files();
    let mut g = c.benchmark_group("ingest");
    g.sample_size(10);
    // CSV counted in its text, as it comes off the disk; both in the numbers they hold
    let text = std::fs::metadata(&csv).unwrap().len();
    g.throughput(Throughput::Bytes(text));
    g.bench_function("csv-text", |b| b.iter(|| Frame::read(&csv, "t").unwrap()));
    g.throughput(Throughput::Bytes((ROWS * COLUMNS * 8) as u64));
    g.bench_function("csv", |b| b.iter(|| Frame::read(&csv, "t").unwrap()));
    g.bench_function("parquet", |b| b.iter(|| Frame::read(&pq, "t").unwrap()));
    let frame = Frame::read(&pq, "t").unwrap();
    let columns: Vec<&str> = frame.names()[1..].iter().map(String::as_str).collect();
    g.bench_function("spikes", |b| b.iter(|| termid::data::despiked(&frame, &columns).unwrap()));
    g.finish();
    std::fs::remove_dir_all(csv.parent().unwrap()).ok();
}

criterion_group!(benches, ingest);
criterion_main!(benches);
