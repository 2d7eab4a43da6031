//! A 100 s zigzag at Δt = 0.04 s (2 500 steps, 76 candidate terms' worth of equations per
//! step) with the default model, as `termid simulate` runs it; and one right-hand side.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use termid::ship::{Manoeuvre, Ship};
use termid::sim::{simulate, Integrator, Settings};

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
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
