//! Output-error refinement of a new ship's identified model on 13 basin records at 20 Hz (the
//! MMG KVLCC2 basin of `examples/mmg_basin.rs`: zigzags of several amplitudes to both sides,
//! ~90 s each, the tracking filter's prepared runs), as `identify --refine u,v,r,ψ` runs it:
//! the Jacobian from forward sensitivities, all 60-odd coefficients together. Issue 15's
//! target: under 1 s on this 2-core machine.

use std::path::Path;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use termid::data::{CentralDifference, Frame};
use termid::diagnose::{refine, RefineSettings, Runs};
use termid::identify::{identify_model, ModelIdentification};
use termid::select::Backend;
use termid::ship::basin::{Artefacts, Basin, Noise};
use termid::ship::Manoeuvre;
use termid::sim::Integrator;

const RUNS: [(&str, f64); 13] = [
    ("zigzag:10/10", 0.98),
    ("zigzag:10/10:port", 1.02),
    ("zigzag:20/20", 1.01),
    ("zigzag:20/20:port", 0.97),
    ("zigzag:15/5", 1.03),
    ("zigzag:15/5:port", 0.99),
    ("zigzag:35/5", 1.00),
    ("zigzag:35/5:port", 1.02),
    ("zigzag:25/10", 1.00),
    ("zigzag:25/10:port", 0.98),
    ("zigzag:30/5", 1.01),
    ("zigzag:20/10", 0.99),
    ("zigzag:20/10:port", 1.03),
];

fn bench(c: &mut Criterion) {
    let truth = termid::plugins::load(Path::new("models/mmg_kvlcc2.toml")).unwrap();
    let template = termid::plugins::load(Path::new("models/new_ship.toml"))
        .unwrap()
        .edit(|file| {
            for e in file.equations.values_mut().filter(|e| e.identify) {
                e.backend = Some(Backend::by_name("sparse").unwrap());
            }
        })
        .unwrap();
    let basin = Basin {
        noise: Noise {
            speed_m_s: 0.0,
            yaw_rate_deg_s: 0.05,
            heading_deg: 0.05,
            position_m: 0.002,
            rudder_deg: 0.05,
        },
        artefacts: Artefacts { rudder_offset_deg: 0.3, velocities_from_track: Some(2), midship_end_s: 5.0 },
        ..Basin::default()
    };
    let plugin = termid::plugins::with_derivative("kinematic").unwrap();
    let frames: Vec<Frame> = RUNS
        .iter()
        .enumerate()
        .map(|(k, (m, f))| {
            let rec = basin
                .record(&truth, &Manoeuvre::parse(m).unwrap(), f * 1.17248, 80.0, 7 + k as u64, m)
                .unwrap();
            plugin.prepare("kinematic", &template, &rec.measured, true).unwrap()
        })
        .collect();
    let how = ModelIdentification {
        equations: vec![],
        differentiator: &CentralDifference,
        intercept: false,
        target: None,
    };
    let model = identify_model(&template, &frames, &how, &mut |_| {}).unwrap().model;
    let states: Vec<String> = ["u", "v", "r", "ψ"].map(String::from).to_vec();
    let runs = Runs::new(&model, &frames, 0.05, Integrator::Rk4).unwrap().comparing(&states).unwrap();
    let mut g = c.benchmark_group("refine");
    g.sample_size(10);
    g.bench_function("mmg_basin_13_runs_20hz", |b| {
        b.iter(|| black_box(refine(&model, &runs, &RefineSettings::default()).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
