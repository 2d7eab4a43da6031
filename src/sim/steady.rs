//! Steady states: values of chosen unknowns (states or inputs) for which chosen derivatives
//! vanish, by Newton's method with a finite-difference Jacobian and step halving. Used for
//! the straight-run rudder angle δ0 and for checking steady turning.

use nalgebra::{DMatrix, DVector};

use super::system::System;
use super::SimError;

/// An unknown of a steady-state problem.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unknown {
    /// A state, by index.
    State(usize),
    /// An input, by index.
    Input(usize),
}

/// Find `unknowns` such that the derivatives of `zero` (state indices) vanish.
#[derive(Clone, Debug)]
pub struct SteadyProblem<'a> {
    /// The system.
    pub system: &'a System,
    /// States: fixed values and the initial guess of unknown ones.
    pub x: Vec<f64>,
    /// Inputs: likewise.
    pub input: Vec<f64>,
    /// What may change.
    pub unknowns: Vec<Unknown>,
    /// Which derivatives must vanish (as many as unknowns).
    pub zero: Vec<usize>,
}

fn residual(p: &SteadyProblem<'_>, z: &[f64], ws: &mut super::system::Workspace) -> Vec<f64> {
    let (mut x, mut u) = (p.x.clone(), p.input.clone());
    for (v, k) in z.iter().zip(&p.unknowns) {
        match *k {
            Unknown::State(i) => x[i] = *v,
            Unknown::Input(i) => u[i] = *v,
        }
    }
    let mut dx = vec![0.0; p.system.dim()];
    p.system.derivatives(&x, &u, ws, &mut dx);
    p.zero.iter().map(|&i| dx[i]).collect()
}

/// Solves a steady-state problem; returns (states, inputs) at the solution.
pub fn solve_steady(p: &SteadyProblem<'_>) -> Result<(Vec<f64>, Vec<f64>), SimError> {
    let n = p.unknowns.len();
    if n != p.zero.len() || n == 0 {
        return Err(SimError::NoSteadyState(format!("{n} unknowns for {} conditions", p.zero.len())));
    }
    let mut ws = p.system.workspace();
    let mut z: Vec<f64> = p
        .unknowns
        .iter()
        .map(|k| match *k {
            Unknown::State(i) => p.x[i],
            Unknown::Input(i) => p.input[i],
        })
        .collect();
    let norm = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut r = residual(p, &z, &mut ws);
    for _ in 0..100 {
        if norm(&r) < 1e-14 {
            break;
        }
        let mut jac = DMatrix::<f64>::zeros(n, n);
        for j in 0..n {
            let h = 1e-7 * z[j].abs().max(1e-3);
            let (mut zp, mut zm) = (z.clone(), z.clone());
            zp[j] += h;
            zm[j] -= h;
            let (rp, rm) = (residual(p, &zp, &mut ws), residual(p, &zm, &mut ws));
            for i in 0..n {
                jac[(i, j)] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        let step = jac
            .lu()
            .solve(&DVector::from_column_slice(&r))
            .ok_or_else(|| SimError::NoSteadyState("singular Jacobian".into()))?;
        let mut lambda = 1.0;
        loop {
            let trial: Vec<f64> = z.iter().zip(step.iter()).map(|(a, d)| a - lambda * d).collect();
            let rt = residual(p, &trial, &mut ws);
            if norm(&rt) < norm(&r) || lambda < 1e-6 {
                z = trial;
                r = rt;
                break;
            }
            lambda *= 0.5;
        }
    }
    let residual = norm(&r);
    if residual.is_nan() || residual >= 1e-9 {
        return Err(SimError::NoSteadyState(format!("residual {residual:.3e} after 100 Newton steps")));
    }
    let (mut x, mut u) = (p.x.clone(), p.input.clone());
    for (v, k) in z.iter().zip(&p.unknowns) {
        match *k {
            Unknown::State(i) => x[i] = *v,
            Unknown::Input(i) => u[i] = *v,
        }
    }
    Ok((x, u))
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use crate::model::Model;

    /// ẋ = u − k·x with x held at 2: the input that keeps it there is u = 2k; and ẏ = x·y − 1
    /// with x = 2: y = ½.
    #[test]
    fn newton_finds_the_input_and_the_state_that_hold_still() {
        let text = r#"
[model]
name = "two lags"
[[states]]
name = "x"
[[states]]
name = "y"
[[inputs]]
name = "u"
[parameters.k]
value = 0.7
[equations.x_dot]
state = "x"
coefficients = { "u" = 1.0, "k*x" = -1.0 }
[equations.y_dot]
state = "y"
coefficients = { "x*y" = 1.0, "1" = -1.0 }
"#;
        let model = Model::parse(text, "lags.toml").unwrap();
        let system = System::new(&model, &BTreeMap::new(), false).unwrap();
        let p = SteadyProblem {
            system: &system,
            x: vec![2.0, 1.0],
            input: vec![0.0],
            unknowns: vec![Unknown::Input(0), Unknown::State(1)],
            zero: vec![0, 1],
        };
        let (x, u) = solve_steady(&p).unwrap();
        assert!((u[0] - 1.4).abs() < 1e-9 && (x[1] - 0.5).abs() < 1e-9, "u = {u:?}, x = {x:?}");
        assert_eq!(x[0], 2.0);
    }
}
