//! Evaluating the paper's 29 candidate terms (v̇ and ṙ, Oltmann 1973 §3) on 10⁶ rows:
//! termid's compiled library against a hand-written Rust loop computing the same columns.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use termid::term::{parse_terms, Library};

mod common;
use common::{bind, signals, vocab, TERMS_29, U0};

/// The hand-written reference: one pass, all 29 columns per row.
fn hand(u: &[f64], v: &[f64], r: &[f64], d: &[f64], u0: f64, out: &mut [f64]) {
    let n = u.len();
    for i in 0..n {
        let (u, v, r, d) = (u[i], v[i], r[i], d[i]);
        let du = u - u0;
        let iu = 1.0 / u;
        let cols = [
            u * u,
            u * v,
            u * r,
            u * u * d,
            v * v * v * iu,
            v * v * r * iu,
            v * r * r * iu,
            r * r * r * iu,
            v * v * d,
            u * v * d * d,
            r * r * d,
            u * r * d * d,
            u * u * d * d * d,
            v * du,
            r * du,
            u * du * d,
            v * du * du * iu,
            r * du * du * iu,
            d * du * du,
            v * r * d,
            v * r,
            v * v,
            r * r,
            u * u * d * d,
            u * v * d,
            u * r * d,
            v * r * du * iu,
            r * du * d,
            v * du * d,
        ];
        for (j, c) in cols.iter().enumerate() {
            out[j * n + i] = *c;
        }
    }
}

fn bench(c: &mut Criterion) {
    let n = 1_000_000;
    let sig = signals(n, 0.01);
    let [u, v, r, d] = &sig;
    let vocab = vocab();
    let terms = parse_terms(&TERMS_29, &vocab).unwrap();
    let lib = Library::compile(&terms, &vocab).unwrap();
    let sources = bind(&lib, &sig);
    let mut out = vec![0.0; n * 29];
    // the two must agree before their speed is compared
    let mut check = vec![0.0; n * 29];
    lib.fill(&sources, n, &mut out);
    hand(u, v, r, d, U0, &mut check);
    for (j, t) in terms.iter().enumerate() {
        let k = TERMS_29.iter().position(|s| vocab.parse(s).unwrap() == *t).unwrap();
        for i in (0..n).step_by(9973) {
            let (a, b) = (out[j * n + i], check[k * n + i]);
            assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-9), "{t}: {a} vs {b}");
        }
    }
    let mut g = c.benchmark_group("design_29_terms");
    g.throughput(Throughput::Elements(n as u64));
    g.sample_size(20);
    g.bench_with_input(BenchmarkId::new("termid_compiled", n), &n, |b, &n| {
        b.iter(|| lib.fill(black_box(&sources), n, black_box(&mut out)))
    });
    g.bench_with_input(BenchmarkId::new("hand_written_loop", n), &n, |b, _| {
        b.iter(|| hand(black_box(u), black_box(v), black_box(r), black_box(d), U0, black_box(&mut out)))
    });
    g.finish();

    let mut g = c.benchmark_group("row_29_terms");
    let inputs: Vec<f64> = lib
        .inputs()
        .iter()
        .map(|n| match n.as_str() {
            "u" => 1.9,
            "v" => -0.1,
            "r" => 0.05,
            "δ" => 0.2,
            _ => 2.01,
        })
        .collect();
    let mut scratch = lib.scratch();
    let mut row = vec![0.0; 29];
    g.bench_function("eval_row", |b| {
        b.iter(|| lib.eval_row(black_box(&inputs), &mut scratch, black_box(&mut row)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
