//! Helpers shared by the integration tests.

use nalgebra::{DMatrix, DVector};
use termid::select::{Accumulator, Moments};

/// Least squares by Householder QR on [1 | X] (or X alone): the independent reference.
pub fn qr_fit(columns: &[Vec<f64>], y: &[f64], intercept: bool) -> (Option<f64>, Vec<f64>) {
    let n = y.len();
    let k = columns.len() + usize::from(intercept);
    let mut a = DMatrix::<f64>::zeros(n, k);
    let mut c = 0;
    if intercept {
        a.column_mut(0).fill(1.0);
        c = 1;
    }
    for (j, col) in columns.iter().enumerate() {
        a.column_mut(c + j).copy_from_slice(col);
    }
    let qr = a.qr();
    let qty = qr.q().transpose() * DVector::from_column_slice(y);
    let b = qr.r().solve_upper_triangular(&qty).expect("full rank");
    if intercept {
        (Some(b[0]), b.iter().skip(1).copied().collect())
    } else {
        (None, b.iter().copied().collect())
    }
}

/// Moments of column vectors and a target.
pub fn moments_of(columns: &[Vec<f64>], y: &[f64]) -> Moments {
    let flat: Vec<f64> = columns.iter().flatten().copied().collect();
    let mut acc = Accumulator::new(columns.len());
    acc.push(&flat, y, None);
    acc.finish()
}

/// Relative closeness with a floor for values near zero.
pub fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

/// Samples of ẋ = f(x, t) by classical RK4 with `sub` steps per sample interval `h`.
pub fn trajectory(
    x0: &[f64],
    h: f64,
    samples: usize,
    sub: usize,
    mut f: impl FnMut(f64, &[f64]) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let mut x = x0.to_vec();
    let mut out = vec![x.clone()];
    let dt = h / sub as f64;
    let mut t = 0.0;
    for _ in 1..samples {
        for _ in 0..sub {
            let k1 = f(t, &x);
            let at = |k: &[f64], w: f64| x.iter().zip(k).map(|(a, b)| a + w * dt * b).collect::<Vec<_>>();
            let k2 = f(t + 0.5 * dt, &at(&k1, 0.5));
            let k3 = f(t + 0.5 * dt, &at(&k2, 0.5));
            let k4 = f(t + dt, &at(&k3, 1.0));
            for i in 0..x.len() {
                x[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            t += dt;
        }
        out.push(x.clone());
    }
    out
}

/// A run of named columns with Gaussian noise of `sd[i]` on column i.
pub fn noisy_frame(
    name: &str,
    h: f64,
    names: &[&str],
    rows: &[Vec<f64>],
    sd: &[f64],
    rng: &mut Lcg,
) -> termid::data::Frame {
    let t: Vec<f64> = (0..rows.len()).map(|i| i as f64 * h).collect();
    let mut f = termid::data::Frame::new(name, "t", t).unwrap();
    for (i, n) in names.iter().enumerate() {
        f.push(n, rows.iter().map(|r| r[i] + sd[i] * rng.normal()).collect()).unwrap();
    }
    f
}

/// Each column's spread over `rows` (population sd) times `share`: the records' noise.
pub fn noise(rows: &[Vec<f64>], share: f64) -> Vec<f64> {
    (0..rows[0].len())
        .map(|i| {
            let m = rows.iter().map(|r| r[i]).sum::<f64>() / rows.len() as f64;
            share * (rows.iter().map(|r| (r[i] - m).powi(2)).sum::<f64>() / rows.len() as f64).sqrt()
        })
        .collect()
}

/// Lorenz's σ, ρ, β.
pub const LORENZ_TRUTH: (f64, f64, f64) = (10.0, 28.0, 8.0 / 3.0);

/// `samples` of Lorenz's system every `h` seconds from (−8, 7, 27), ten RK4 steps a sample.
pub fn lorenz_rows(h: f64, samples: usize) -> Vec<Vec<f64>> {
    let (sigma, rho, beta) = LORENZ_TRUTH;
    trajectory(&[-8.0, 7.0, 27.0], h, samples, 10, |_, x| {
        vec![sigma * (x[1] - x[0]), x[0] * (rho - x[2]) - x[1], x[0] * x[1] - beta * x[2]]
    })
}

/// Lorenz's model with σ, ρ, β free, started 20 % off.
pub const LORENZ_FREE: &str = r#"
[model]
name = "Lorenz system, σ, ρ and β free"
intercept = false

[[states]]
name = "x"
initial = -8.0
[[states]]
name = "y"
initial = 7.0
[[states]]
name = "z"
initial = 27.0

[parameters."σ"]
value = 8.0
free = true
bounds = [0.0, 100.0]
[parameters."ρ"]
value = 22.4
free = true
[parameters."β"]
value = 3.2
free = true
bounds = [0.0, 10.0]

[equations.x_dot]
state = "x"
identify = false
coefficients = { "σ*y" = 1.0, "σ*x" = -1.0 }
[equations.y_dot]
state = "y"
identify = false
coefficients = { "ρ*x" = 1.0, "x*z" = -1.0, "y" = -1.0 }
[equations.z_dot]
state = "z"
identify = false
coefficients = { "x*y" = 1.0, "β*z" = -1.0 }
"#;

/// A small deterministic pseudo-random generator (tests must not depend on a seed source).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.next().max(1e-300), self.next());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

/// A scratch folder for one test, unique to this process, removed when it goes out of scope.
pub struct Scratch(std::path::PathBuf);

impl Scratch {
    pub fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("termid-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }
}

impl std::ops::Deref for Scratch {
    type Target = std::path::Path;
    fn deref(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

/// Runs the `termid` binary: (success, stdout, stderr).
pub fn termid(args: &[&str]) -> (bool, String, String) {
    let out =
        std::process::Command::new(env!("CARGO_BIN_EXE_termid")).args(args).output().expect("run termid");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// The terms an `identify --format json` report chose, with their coefficients, by term.
pub fn chosen_terms(report: &serde_json::Value) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> = report["terms"]
        .as_array()
        .unwrap_or_else(|| panic!("{report}"))
        .iter()
        .map(|t| (t["term"].as_str().unwrap().to_string(), t["coefficient"].as_f64().unwrap()))
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// The physical check of a JSON report whose name holds `part`, or a panic that shows the report.
pub fn check_named<'a>(report: &'a serde_json::Value, part: &str) -> &'a serde_json::Value {
    report["physical_checks"]
        .as_array()
        .and_then(|checks| checks.iter().find(|c| c["name"].as_str().is_some_and(|n| n.contains(part))))
        .unwrap_or_else(|| panic!("no check named like `{part}`: {report}"))
}

/// A command's JSON report, or a panic that shows it.
pub fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap_or_else(|e| panic!("{e}: {text}"))
}

/// Simulates the Lorenz model with `termid simulate` (RK4, Δt = 0.001) into `dir/lorenz.csv`.
pub fn lorenz_csv(dir: &std::path::Path, duration: &str) -> std::path::PathBuf {
    let csv = dir.join("lorenz.csv");
    let (ok, _, err) = termid(&[
        "simulate",
        "--model",
        "models/lorenz.toml",
        "--integrator",
        "rk4",
        "--dt",
        "0.001",
        "--sample",
        "0.001",
        "--duration",
        duration,
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    csv
}

/// `termid identify` on the shipped sample records (`examples/data`: four noisy zigzags) with
/// the `derivative` method(s), smoothed states and no intercept, writing the model to `out`;
/// `extra` adds arguments.
pub fn identify_sample_records(
    out: &std::path::Path,
    derivative: &str,
    extra: &[&str],
) -> (bool, String, String) {
    let out = out.to_str().unwrap();
    let mut args = vec![
        "identify",
        "--model",
        "examples/data/ship.toml",
        "--dataset",
        "examples/data/runs.toml",
        "--derivative",
        derivative,
        "--smooth",
        "--no-intercept",
        "--out",
        out,
    ];
    args.extend(extra);
    termid(&args)
}
