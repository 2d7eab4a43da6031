//! Every text and file a user hands termid, from one fuzzer input: the first byte picks the
//! reader, the rest is the text. Any error is fine; a panic is a bug. Kind 5 reads a dataset
//! file and a ship's particulars (`new-ship`). Kind 7 is a model file's
//! back-end table (`backend = …`), loaded and then fitted on a short Lorenz run; kind 6 a
//! statistics file of `termid moments`. Kinds 8-10 are binary files seeded from valid ones:
//! a valid Arrow IPC file, Parquet file or statistics bytes (`EquationMoments::to_bytes`),
//! the input's bytes laid over it (pairs of position and XOR mask), read whole and in pieces.
#![no_main]

use libfuzzer_sys::fuzz_target;
use termid::data::{differentiator, Dataset, Frame};
use termid::model::Model;
use termid::ship::Manoeuvre;
use termid::term::Vocabulary;

/// A dependency's panic that termid contains ([`termid::contain::call`]) becomes an error, as
/// the binary's hook lets it: only a panic outside it reaches libFuzzer's hook (a crash).
fn contained_panics_pass() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let fuzzer = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !termid::contain::active() {
                fuzzer(info);
            }
        }));
    });
}

fuzz_target!(|data: &[u8]| {
    contained_panics_pass();
    let Some((&kind, rest)) = data.split_first() else { return };
    if kind % 11 >= 8 {
        return damaged_file(kind % 11, rest);
    }
    let Ok(text) = std::str::from_utf8(rest) else { return };
    match kind % 8 {
        0 => {
            // a candidate term in the ship's vocabulary
            let mut v = Vocabulary::new();
            for name in ["u", "v", "r", "δ", "ψ"] {
                let _ = v.variable(name);
            }
            let _ = v.parameter("u0");
            let _ = v.derive("Δu", "u - u0");
            let _ = v.alias("du", "Δu");
            if let Ok(t) = v.parse(text) {
                let _ = t.to_string();
                let _ = termid::term::Library::compile(&[t], &v);
            }
        }
        1 => {
            if let Ok(f) = Frame::parse_csv(text, "fuzz.csv", "t") {
                let _ = termid::data::resample(&f, 0.1);
            }
        }
        2 => {
            let _ = termid::plugins::parse(text, "fuzz.toml");
        }
        3 => {
            let _ = Manoeuvre::parse(text);
        }
        4 => {
            if let Ok(d) = differentiator(text) {
                let t: Vec<f64> = (0..40).map(|i| i as f64 * 0.05).collect();
                let x: Vec<f64> = t.iter().map(|t| t.sin()).collect();
                let _ = d.smooth(&t, &x);
            }
        }
        5 => {
            let _ = toml::from_str::<Dataset>(text);
            // a ship's particulars (`termid new-ship`): refused, or a model file that loads
            if let Ok(p) = toml::from_str::<termid::ship::particulars::Particulars>(text) {
                if let Ok(model) = p.model() {
                    let _ = termid::plugins::parse(&model.to_toml(), "new_ship.toml");
                }
            }
        }
        6 => {
            // an equation's statistics (`identify --moments`), read and fitted with the
            // Lorenz model's x_dot
            if let Ok(m) = termid::identify::EquationMoments::from_json(text, "fuzz.moments") {
                if let Ok(model) = Model::load(std::path::Path::new(concat!(
                    env!("CARGO_MANIFEST_DIR"),
                    "/../models/lorenz.toml"
                ))) {
                    let _ = m.fit(&model, true);
                    // and checked on its halves and noise, as `identify --moments` does
                    let all = std::slice::from_ref(&m);
                    if let Ok(found) = termid::identify::identify_from_merged(&model, all, true) {
                        let _ = termid::recipe::moments_checks(&found, all, &model, true, &[]);
                    }
                }
            }
        }
        _ => {
            let lorenz = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../models/lorenz.toml"))
                .expect("models/lorenz.toml");
            let line = lorenz.lines().find(|l| l.starts_with("backend = ")).expect("a backend line");
            let text = lorenz.replacen(line, &format!("backend = {text}"), 1);
            if let Ok(model) = termid::plugins::parse(&text, "fuzz.toml") {
                let frames = [lorenz_run(&model)];
                for eq in model.identifiable() {
                    let _ = termid::identify::fit_equation(
                        &model,
                        &eq,
                        &frames,
                        &termid::data::CentralDifference,
                        true,
                        None,
                    );
                }
            }
        }
    }
});

/// One second of the Lorenz system at 0.01 s, with its derivative columns.
fn lorenz_run(model: &Model) -> Frame {
    let system = termid::sim::System::new(model, &Default::default(), false).expect("lorenz compiles");
    let settings =
        termid::sim::Settings { integrator: termid::sim::Integrator::Rk4, dt: 0.01, duration: 1.0, sample: 0.01 };
    let x0: Vec<f64> = model.spec().states.iter().map(|s| s.initial).collect();
    let traj = termid::sim::simulate(&system, &x0, &mut termid::sim::Constant(vec![]), &settings).expect("runs");
    traj.to_frame("lorenz", "t").expect("a frame")
}

/// A valid file of `kind` (8: Arrow IPC, 9: Parquet, 10: statistics bytes) with `edits` laid
/// over it: each pair of input bytes picks a position (scaled to the file) and an XOR mask; a
/// third byte of 0xFF cuts the file there.
fn damaged_file(kind: u8, edits: &[u8]) {
    use std::sync::Arc;
    let t: Vec<f64> = (0..64).map(|k| 0.05 * k as f64).collect();
    let x: Vec<f64> = t.iter().map(|v| v.sin()).collect();
    let schema = Arc::new(arrow_schema::Schema::new(vec![
        arrow_schema::Field::new("t", arrow_schema::DataType::Float64, false),
        arrow_schema::Field::new("x", arrow_schema::DataType::Float64, false),
    ]));
    let batch = arrow_array::RecordBatch::try_new(
        schema.clone(),
        vec![Arc::new(arrow_array::Float64Array::from(t)), Arc::new(arrow_array::Float64Array::from(x))],
    )
    .expect("a batch");
    let mut bytes = Vec::new();
    let ext = match kind {
        8 => {
            let mut w = arrow_ipc::writer::FileWriter::try_new(&mut bytes, &schema).expect("writer");
            w.write(&batch).expect("write");
            w.finish().expect("finish");
            drop(w);
            "arrow"
        }
        9 => {
            let mut w = parquet::arrow::ArrowWriter::try_new(&mut bytes, schema, None).expect("writer");
            w.write(&batch).expect("write");
            w.close().expect("close");
            "parquet"
        }
        _ => {
            let model = Model::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../models/lorenz.toml")))
                .expect("models/lorenz.toml");
            let frames = [lorenz_run(&model)];
            let m = termid::identify::EquationMoments::of_runs(&model, "x_dot", &frames, &termid::data::CentralDifference, None)
                .expect("statistics");
            let mut b = m.to_bytes();
            for pair in edits.chunks(2) {
                if let [at, mask] = pair {
                    let k = (*at as usize * b.len()) / 256;
                    b[k] ^= mask;
                }
            }
            if let Ok(read) = termid::identify::EquationMoments::from_bytes(&b, "fuzz.bin") {
                let _ = read.fit(&model, true);
                let all = std::slice::from_ref(&read);
                if let Ok(found) = termid::identify::identify_from_merged(&model, all, true) {
                    let _ = termid::recipe::moments_checks(&found, all, &model, true, &[]);
                }
            }
            return;
        }
    };
    for e in edits.chunks(3) {
        let k = (e[0] as usize * bytes.len()) / 256;
        match e {
            [_, _, 0xFF] => bytes.truncate(k),
            [_, mask, ..] if k < bytes.len() => bytes[k] ^= mask,
            _ => {}
        }
    }
    let path = std::env::temp_dir().join(format!("termid-fuzz-{}.{ext}", std::process::id()));
    if std::fs::write(&path, &bytes).is_ok() {
        let _ = Frame::read(&path, "t");
        if let Ok(chunks) = termid::data::Chunks::open(&path, "t", 8, 2) {
            for c in chunks {
                if c.is_err() {
                    break;
                }
            }
        }
    }
}
