//! Sufficient statistics and back-ends: the one-pass cross-product accumulation on 10⁶ × 30
//! against a BLAS-class XᵀX (nalgebra's gemm through a transposed view), and STPRG on the
//! paper's combined-data size (2 505 rows × 29 candidates) including the design.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use termid::select::{Accumulator, Backend, BestSubset, Moments, Problem, Selector, StepRule, Stepwise};
use termid::term::{parse_terms, Library};

mod common;
use common::{bind, gemm_xtx, signals, vocab, TERMS_29};

fn lcg(seed: &mut u64) -> f64 {
    *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

fn bench(c: &mut Criterion) {
    // 10⁶ × 30 cross products
    let (n, p) = (1_000_000usize, 29usize);
    let mut seed = 1;
    let x: Vec<f64> = (0..n * p).map(|_| lcg(&mut seed)).collect();
    let y: Vec<f64> = (0..n).map(|_| lcg(&mut seed)).collect();
    let mut g = c.benchmark_group("cross_products_1e6x30");
    g.sample_size(10);
    g.bench_function("termid_accumulator", |b| {
        b.iter(|| {
            let mut acc = Accumulator::new(p);
            acc.push(black_box(&x), black_box(&y), None);
            black_box(acc.finish())
        })
    });
    g.bench_function("termid_parallel", |b| {
        b.iter(|| black_box(Moments::of_columns(black_box(&x), &y, None)))
    });
    let mut z = x.clone();
    z.extend_from_slice(&y);
    g.bench_function("nalgebra_gemm_xtx", |b| b.iter(|| black_box(gemm_xtx(&z, n, p + 1))));
    g.finish();

    // STPRG on 2 505 × 29 including the design (the paper's Komb. Daten size)
    let rows = 2505;
    let sig = signals(rows, 0.2);
    let [u, v, r, d] = &sig;
    let target: Vec<f64> = (0..rows)
        .map(|i| {
            -0.28 * u[i] * r[i] - 0.18 * u[i] * v[i] + 0.03 * u[i] * u[i] * d[i] + 1e-3 * (i as f64).sin()
        })
        .collect();
    let vocab = vocab();
    let terms = parse_terms(&TERMS_29, &vocab).unwrap();
    let lib = Library::compile(&terms, &vocab).unwrap();
    let names: Vec<String> = terms.iter().map(|t| t.to_string()).collect();
    let stepwise = Stepwise { step_rule: StepRule::Last, ..Stepwise::default() };
    let mut g = c.benchmark_group("stepwise");
    g.bench_with_input(BenchmarkId::new("design_and_stprg", rows), &rows, |b, &rows| {
        b.iter(|| {
            let sources = bind(&lib, &sig);
            let mut acc = Accumulator::new(lib.len());
            lib.for_each_block(&sources, 0..rows, |start, columns| {
                acc.push_columns(columns, &target[start..start + columns[0].len()], None)
            });
            let m = acc.finish();
            let pb =
                Problem { moments: &m, names: &names, forced: &[1, 2, 3], excluded: &[], intercept: true };
            black_box(stepwise.select(&pb).unwrap())
        })
    });
    // where the time goes
    let sources = bind(&lib, &sig);
    let mut design = vec![0.0; rows * lib.len()];
    // filled here, not only inside a bench: a filtered run may skip that bench
    lib.fill(&sources, rows, &mut design);
    g.bench_function("design_only_2505", |b| {
        b.iter(|| lib.fill(black_box(&sources), rows, black_box(&mut design)))
    });
    g.bench_function("moments_only_2505", |b| {
        b.iter(|| {
            let mut acc = Accumulator::new(lib.len());
            acc.push(black_box(&design), &target, None);
            black_box(acc.finish())
        })
    });
    let mut zc = design.clone();
    zc.extend_from_slice(&target);
    let mut cm = vec![0.0; 30 * 30];
    g.bench_function("gram_kernel_only_2505", |b| {
        b.iter(|| termid::select::gram::gram(black_box(&zc), rows, rows, 30, black_box(&mut cm)))
    });
    let mut acc = Accumulator::new(lib.len());
    acc.push(&design, &target, None);
    let m = acc.finish();
    g.bench_function("stprg_only_2505", |b| {
        b.iter(|| {
            let pb =
                Problem { moments: &m, names: &names, forced: &[1, 2, 3], excluded: &[], intercept: true };
            black_box(stepwise.select(&pb).unwrap())
        })
    });
    g.finish();

    // every back-end on the paper's combined-data size (statistics already accumulated)
    let mut g = c.benchmark_group("backends_2505x29");
    for name in Backend::NAMES {
        let backend = Backend::by_name(name).unwrap().build();
        g.bench_function(*name, |b| {
            b.iter(|| {
                let pb = Problem {
                    moments: &m,
                    names: &names,
                    forced: &[1, 2, 3],
                    excluded: &[],
                    intercept: true,
                };
                black_box(backend.select(&pb).unwrap())
            })
        });
    }
    g.finish();

    // the large problem: 10⁶ rows × 100 candidates, the pass over the rows included
    let (n, p) = (1_000_000usize, 100usize);
    let mut seed = 7;
    let x: Vec<f64> = (0..n * p).map(|_| lcg(&mut seed)).collect();
    let y: Vec<f64> = (0..n)
        .map(|i| 2.0 * x[i] - 1.0 * x[3 * n + i] + 0.5 * x[50 * n + i] + 0.1 * lcg(&mut seed))
        .collect();
    let big_names: Vec<String> = (0..p).map(|j| format!("x{j}")).collect();
    let mut g = c.benchmark_group("backends_1e6x100");
    g.sample_size(10);
    // every back-end; best subset searched exactly up to five terms (all 2¹⁰⁰ subsets are out of
    // reach of any exact method)
    let backends: Vec<(&str, Box<dyn Selector>)> = vec![
        ("stepwise", Backend::by_name("stepwise").unwrap().build()),
        ("efroymson", Backend::by_name("efroymson").unwrap().build()),
        ("best-subset_max5", Box::new(BestSubset { max_size: Some(5), ..BestSubset::default() })),
        ("sparse", Backend::by_name("sparse").unwrap().build()),
    ];
    for (name, backend) in &backends {
        g.bench_function(*name, |b| {
            b.iter(|| {
                let m = Moments::of_columns(black_box(&x), &y, None);
                let pb =
                    Problem { moments: &m, names: &big_names, forced: &[], excluded: &[], intercept: true };
                black_box(backend.select(&pb).unwrap())
            })
        });
    }
    let mut z = x.clone();
    z.extend_from_slice(&y);
    g.bench_function("nalgebra_gemm_xtx", |b| b.iter(|| black_box(gemm_xtx(&z, n, p + 1))));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
