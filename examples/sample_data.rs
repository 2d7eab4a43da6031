//! Writes `examples/data/`: what the measured-data commands of README and docs/guide/ship-records.md read, so that every README
//! block runs on a fresh clone. Four training zigzags and one held-out zigzag of the default
//! ship recorded in the synthetic basin (20 Hz, the basin's sensor noise, per-run approach
//! speeds; the paper's five Z-manoeuvres, `PAPER_RUNS`), the dataset files `runs.toml` and
//! `held_out.toml` that map the basin's columns and units, and `ship.toml`: the default model
//! with each run's u0 averaged over its first 4 s (`mean:u:4`, right for noisy records).
//!
//! `cargo run --release --example sample_data [-- FOLDER]` (default `examples/data`)

use std::path::PathBuf;

use termid::ship::basin::{dataset_toml, Basin, PAPER_RUNS};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args().nth(1).map_or_else(|| PathBuf::from("examples/data"), PathBuf::from);
    std::fs::create_dir_all(&dir)?;
    let truth = termid::ship::default_model();
    let u0 = termid::ship::ShipSpec::of(&truth)?.map_or(2.01, |s| s.u0);
    // 60 s after the approach: two periods of each zigzag, files of ~100 kB
    let recorded = Basin::default().record_all(&truth, &PAPER_RUNS, u0, 60.0, 11, Some(&dir))?;
    let names: Vec<&str> = recorded.iter().map(|(n, _)| n.as_str()).collect();
    std::fs::write(dir.join("runs.toml"), dataset_toml(&names[..4]))?;
    std::fs::write(dir.join("held_out.toml"), dataset_toml(&names[4..]))?;
    let model = std::fs::read_to_string("models/oltmann1973.toml")?;
    let ship = model.replacen("per_run = \"first:u\"", "per_run = \"mean:u:4\"", 1);
    assert_ne!(ship, model, "the default model's u0 rule was not found");
    std::fs::write(dir.join("ship.toml"), ship)?;
    println!("wrote {} runs, runs.toml, held_out.toml and ship.toml to {}", names.len(), dir.display());
    Ok(())
}
