//! Shared by the benches: the paper's 29 candidate terms, the ship vocabulary and synthetic
//! zigzag-like signals bound to a compiled library.

#![allow(dead_code)]

use nalgebra::{DMatrix, DMatrixView, Dyn};
use termid::term::{Library, Source, Vocabulary};

/// The 29 candidates of v̇ and ṙ (Oltmann 1973 §3).
pub const TERMS_29: [&str; 29] = [
    "u^2",
    "u*v",
    "u*r",
    "u^2*delta",
    "v^3/u",
    "v^2*r/u",
    "v*r^2/u",
    "r^3/u",
    "v^2*delta",
    "u*v*delta^2",
    "r^2*delta",
    "u*r*delta^2",
    "u^2*delta^3",
    "v*du",
    "r*du",
    "u*du*delta",
    "v*du^2/u",
    "r*du^2/u",
    "delta*du^2",
    "v*r*delta",
    "v*r",
    "v^2",
    "r^2",
    "u^2*delta^2",
    "u*v*delta",
    "u*r*delta",
    "v*r*du/u",
    "r*du*delta",
    "v*du*delta",
];

/// u0 of the synthetic signals.
pub const U0: f64 = 2.01;

/// u, v, r, δ with u0, Δu = u − u0 and the ASCII aliases.
pub fn vocab() -> Vocabulary {
    let mut v = Vocabulary::new();
    for n in ["u", "v", "r", "δ"] {
        v.variable(n).unwrap();
    }
    v.parameter("u0").unwrap();
    v.derive("Δu", "u - u0").unwrap();
    v.alias("du", "Δu").unwrap().alias("delta", "δ").unwrap();
    v
}

/// Smooth zigzag-like u, v, r, δ at `n` samples `dt` apart.
pub fn signals(n: usize, dt: f64) -> [Vec<f64>; 4] {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
    [
        t.iter().map(|t| 1.9 + 0.1 * (0.05 * t).cos()).collect(),
        t.iter().map(|t| 0.1 * (0.11 * t).sin()).collect(),
        t.iter().map(|t| 0.05 * (0.13 * t).sin()).collect(),
        t.iter().map(|t| 0.3 * (0.07 * t).sin()).collect(),
    ]
}

/// Binds a library's inputs to the signals and u0.
pub fn bind<'a>(lib: &Library, s: &'a [Vec<f64>; 4]) -> Vec<Source<'a>> {
    lib.bind(
        &|name| match name {
            "u" => Some(s[0].as_slice()),
            "v" => Some(s[1].as_slice()),
            "r" => Some(s[2].as_slice()),
            "δ" => Some(s[3].as_slice()),
            _ => None,
        },
        &|name| (name == "u0").then_some(U0),
    )
    .unwrap()
}

/// The BLAS-class reference XᵀX of [X | y] (n rows, p + 1 columns, column-major): nalgebra's
/// gemm through a transposed view, which reaches matrixmultiply's packed kernel.
pub fn gemm_xtx(z: &[f64], n: usize, cols: usize) -> DMatrix<f64> {
    let zv = DMatrixView::from_slice(z, n, cols);
    let zt = DMatrixView::from_slice_with_strides_generic(z, Dyn(cols), Dyn(n), Dyn(n), Dyn(1));
    let mut c = DMatrix::<f64>::zeros(cols, cols);
    c.gemm(1.0, &zt, &zv, 0.0);
    c
}
