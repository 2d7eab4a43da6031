//! Output-error refinement of a new ship's identified model on 13 basin records at 20 Hz (the
//! MMG KVLCC2 basin of `examples/mmg_basin.rs`: zigzags of several amplitudes to both sides,
//! ~90 s each, the tracking filter's prepared runs), as `identify --refine u,v,r,ψ` runs it:
//! the Jacobian from forward sensitivities, all 60-odd coefficients together. Issue 15's
//! target: under 1 s on this 2-core machine. Beside it the grey-box estimate of the same ship
//! from its particulars on the basin's eight zigzags, as `termid estimate --states u,v,r,ψ`
//! runs it (30 parameters and each run's initial state), and the whole new-ship recipe on the
//! 13 records.

use std::path::Path;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use termid::data::{CentralDifference, Frame};
use termid::diagnose::{estimate, refine, EstimateSettings, RefineSettings, Runs};
use termid::identify::{identify_model, ModelIdentification};
use termid::recipe::{ParameterOptions, RecipeSettings, RefineOptions};
use termid::select::Backend;
use termid::ship::basin::{Basin, ZIGZAGS_BOTH_SIDES};
use termid::sim::Integrator;

/// Five more zigzags beside the MMG basin's eight.
const MORE: [(&str, f64); 5] = [
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
        .with_backend(&Backend::by_name("sparse").unwrap())
        .unwrap();
    let plugin = termid::plugins::with_derivative("kinematic").unwrap();
    let runs_of_13: Vec<(&str, f64)> = ZIGZAGS_BOTH_SIDES.iter().chain(&MORE).copied().collect();
    let records: Vec<Frame> = Basin::tracked()
        .record_all(&truth, &runs_of_13, 1.17248, 80.0, 7, None)
        .unwrap()
        .into_iter()
        .map(|(_, rec)| rec.measured)
        .collect();
    let frames: Vec<Frame> =
        records.iter().map(|f| plugin.prepare("kinematic", &template, f, true).unwrap()).collect();
    let how = ModelIdentification {
        equations: vec![],
        differentiator: &CentralDifference,
        intercept: false,
        target: None,
    };
    let model = identify_model(&template, &frames, &how, &mut |_| {}).unwrap().model;
    let states: Vec<String> = ["u", "v", "r", "ψ"].map(String::from).to_vec();
    let runs = Runs::new(&model, &frames, 0.05, Integrator::Rk4).unwrap().comparing(&model, &states).unwrap();
    let mut g = c.benchmark_group("refine");
    g.sample_size(10);
    g.bench_function("mmg_basin_13_runs_20hz", |b| {
        b.iter(|| black_box(refine(&model, &runs, &RefineSettings::default()).unwrap()))
    });
    g.finish();

    // the whole recipe on the same 13 records, as README's new-ship command runs it: four
    // derivative starts side by side, each choosing among four back-ends by leave-one-run-out
    // prediction, refined with each run's rudder zero (the template declares it free) and
    // checked (issue 26's target: under 5 s for 13 runs)
    let ship = termid::plugins::load(Path::new("models/new_ship.toml")).unwrap();
    let settings = RecipeSettings {
        derivatives: ["kinematic", "kalman", "savitzky-golay", "central"].map(String::from).to_vec(),
        smooth: true,
        intercept: false,
        choose: ["sparse", "best-subset", "efroymson", "stepwise"]
            .iter()
            .map(|name| (name.to_string(), ship.with_backend(&Backend::by_name(name).unwrap()).unwrap()))
            .collect(),
        compare: states.clone(),
        refine: Some(RefineOptions {
            states: Some(states.clone()),
            prior: 1e-4,
            iterations: 100,
            step: None,
        }),
        parameters: ParameterOptions::asked(&ship, None, true, vec![], vec![], vec![]),
        ..Default::default()
    };
    let mut g = c.benchmark_group("recipe");
    g.sample_size(10);
    g.bench_function("mmg_basin_13_runs_four_starts", |b| {
        b.iter(|| black_box(termid::recipe::identify(&ship, &records, None, &settings).unwrap()))
    });
    g.finish();

    let particulars: termid::ship::particulars::Particulars =
        toml::from_str(&std::fs::read_to_string("examples/kvlcc2_particulars.toml").unwrap()).unwrap();
    let start = particulars.model().unwrap();
    let measured: Vec<Frame> = Basin::tracked()
        .record_all(&truth, &ZIGZAGS_BOTH_SIDES, 1.17248, 80.0, 7, None)
        .unwrap()
        .into_iter()
        .map(|(_, rec)| rec.measured)
        .collect();
    let runs = Runs::new(&start, &measured, termid::data::sample_step(&measured), Integrator::Rk4)
        .unwrap()
        .comparing(&start, &states)
        .unwrap();
    let mut g = c.benchmark_group("estimate");
    g.sample_size(10);
    g.bench_function("mmg_basin_8_zigzags_greybox", |b| {
        b.iter(|| black_box(estimate(&start, &runs, &EstimateSettings::default()).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
