//! A 100 s zigzag at Δt = 0.04 s (2 500 steps, 76 candidate terms' worth of equations per
//! step) with the default model, as `termid simulate` runs it; one right-hand side; and
//! Robertson's stiff kinetics to 4·10⁵ s with the default method (which turns linearly
//! implicit there).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use termid::ship::{Manoeuvre, Ship};
use termid::sim::{simulate, Constant, Integrator, Settings, System};

fn bench(c: &mut Criterion) {
    let ship = Ship::new(&termid::ship::default_model(), false).unwrap();
    let start = ship.straight_run().unwrap();
    let zigzag = Manoeuvre::parse("zigzag:20/20").unwrap();
    let mut g = c.benchmark_group("simulate");
    for (name, integrator) in [
        ("zigzag_100s_b8", Integrator::ModifiedEuler),
        ("zigzag_100s_rk4", Integrator::Rk4),
        ("zigzag_100s_dopri5", Integrator::Dopri5),
    ] {
        let s = Settings { integrator, dt: 0.04, duration: 100.0, sample: 0.2 };
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut ctrl = zigzag.controller_for_bench(&ship, &start).unwrap();
                black_box(simulate(&ship.system, &start.x, ctrl.as_mut(), &s).unwrap())
            })
        });
    }
    let s = Settings { integrator: Integrator::ModifiedEuler, dt: 0.04, duration: 100.0, sample: 0.2 };
    g.bench_function("zigzag_100s_b8_with_metrics", |b| {
        b.iter(|| black_box(ship.run_from(&zigzag, &s, start.clone()).unwrap()))
    });
    let mut ws = ship.system.workspace();
    let mut dx = vec![0.0; ship.system.dim()];
    let input = start.input.clone();
    g.bench_function("rhs_one_evaluation", |b| {
        b.iter(|| {
            ship.system.derivatives(black_box(&start.x), black_box(&input), &mut ws, black_box(&mut dx))
        })
    });
    let robertson = termid::model::Model::load(std::path::Path::new("models/robertson.toml")).unwrap();
    let system = System::new(&robertson, &Default::default(), false).unwrap();
    let x0: Vec<f64> = robertson.spec().states.iter().map(|s| s.initial).collect();
    let s = Settings { integrator: Integrator::Dopri5, dt: 1000.0, duration: 4e5, sample: 1000.0 };
    g.bench_function("robertson_4e5s_default", |b| {
        b.iter(|| black_box(simulate(&system, &x0, &mut Constant(vec![]), &s).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
