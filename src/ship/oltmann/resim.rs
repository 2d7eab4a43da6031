//! Re-simulation with identified coefficients against the original runs (the paper's
//! "modified" manoeuvres: the recorded rudder history replayed, Figs. 6-17, 21-24), and the
//! heading-drift cure (Figs. 28-34): B0·u² and C0·u² estimated from the straight run.

use serde::Serialize;

use super::data::{Recorded, DT, DURATION, SAMPLE};
use super::tables::EquationTable;
use crate::model::Model;
use crate::ship::{Ship, ShipError};
use crate::sim::{simulate, Integrator, Replay, Settings, Trajectory};

/// Which coefficients of a table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Column {
    /// The Mittelwert column (terms without one are left out).
    Mittelwert,
    /// The combined regression.
    Komb,
}

/// The default model with its u̇, v̇, ṙ coefficients replaced by a table column's.
pub fn identified_model(base: &Model, tables: &[EquationTable], column: Column) -> Model {
    let mut m = base.clone();
    for t in tables {
        let coefs = t
            .rows
            .iter()
            .filter_map(|row| {
                let value = match column {
                    Column::Mittelwert => row.mittelwert?,
                    Column::Komb => row.komb?.1,
                };
                Some((m.vocabulary.parse(&row.term).ok()?, value, None))
            })
            .collect();
        m.set_coefficients(&t.equation, coefs, None);
    }
    m
}

/// Errors of a re-simulation against the original, at the samples: heading and drift
/// angle in degrees, yaw rate in °/s, speed as U/U0.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Errors {
    /// max |Δψ|, °.
    pub psi_max_deg: f64,
    /// RMS Δψ, °.
    pub psi_rms_deg: f64,
    /// max |Δr|, °/s.
    pub r_max_deg_s: f64,
    /// RMS Δr, °/s.
    pub r_rms_deg_s: f64,
    /// max |Δβ|, °.
    pub beta_max_deg: f64,
    /// RMS Δβ, °.
    pub beta_rms_deg: f64,
    /// max |Δ(U/U0)|.
    pub speed_max: f64,
    /// RMS Δ(U/U0).
    pub speed_rms: f64,
    /// Δψ = ψ(re-simulated) − ψ(original) at the end of the run, °.
    pub psi_final_deg: f64,
}

/// Compares two runs sampled at the same times.
pub fn errors(ship: &Ship, original: &Trajectory, resim: &Trajectory) -> Errors {
    let r = &ship.roles;
    let n = original.time.len().min(resim.time.len());
    let (u1, b1) = ship.speed_and_drift(original);
    let (u2, b2) = ship.speed_and_drift(resim);
    let stat = |a: &[f64], b: &[f64], scale: f64| {
        // re-simulated minus original
        let d: Vec<f64> = (0..n).map(|i| (b[i] - a[i]) * scale).collect();
        let max = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let rms = (d.iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
        (max, rms, d.last().copied().unwrap_or(0.0))
    };
    let deg = 180.0 / std::f64::consts::PI;
    let (psi_max_deg, psi_rms_deg, psi_final_deg) = stat(&original.states[r.psi], &resim.states[r.psi], deg);
    let (r_max_deg_s, r_rms_deg_s, _) = stat(&original.states[r.r], &resim.states[r.r], deg);
    let (beta_max_deg, beta_rms_deg, _) = stat(&b1, &b2, deg);
    let (speed_max, speed_rms, _) = stat(&u1, &u2, 1.0 / ship.spec.u0);
    Errors {
        psi_max_deg,
        psi_rms_deg,
        r_max_deg_s,
        r_rms_deg_s,
        beta_max_deg,
        beta_rms_deg,
        speed_max,
        speed_rms,
        psi_final_deg,
    }
}

/// The original run at the analysed samples.
pub fn original_samples(rec: &Recorded) -> Trajectory {
    let every = (SAMPLE / DT).round() as usize;
    let keep: Vec<usize> = (0..rec.fine.time.len()).step_by(every).collect();
    let pick = |c: &Vec<f64>| keep.iter().map(|&i| c[i]).collect::<Vec<f64>>();
    Trajectory {
        time: pick(&rec.fine.time),
        state_names: rec.fine.state_names.clone(),
        input_names: rec.fine.input_names.clone(),
        states: rec.fine.states.iter().map(pick).collect(),
        inputs: rec.fine.inputs.iter().map(pick).collect(),
        derivatives: rec.fine.derivatives.iter().map(pick).collect(),
        observed: rec.fine.observed.iter().map(|(n, c)| (n.clone(), pick(c))).collect(),
        stiff_from: rec.fine.stiff_from,
    }
}

/// The recorded rudder (0.2 s samples, linearly interpolated) replayed into `ship` from the
/// original's initial state.
pub fn replay(ship: &Ship, rec: &Recorded) -> Result<Trajectory, ShipError> {
    let settings =
        Settings { integrator: Integrator::ModifiedEuler, dt: DT, duration: DURATION, sample: SAMPLE };
    let mut controller = Replay::new(&rec.frame, &ship.system.inputs)?;
    let x0: Vec<f64> = rec.fine.states.iter().map(|c| c[0]).collect();
    Ok(simulate(&ship.system, &x0, &mut controller, &settings)?)
}

/// The paper's cure: add ΔB0·u² to v̇ and ΔC0·u² to ṙ such that the identified model is in
/// equilibrium at the recorded straight run (the first sample: u0, v0, r = 0, δ0), which the
/// true model is. Returns the corrected model and (B0, C0) as they stand in it afterwards.
pub fn balance_straight_run(
    model: &Model,
    straight: &[f64],
    input: &[f64],
) -> Result<(Model, f64, f64), ShipError> {
    let ship = Ship::new(model, false)?;
    let r = ship.roles;
    let mut ws = ship.system.workspace();
    let mut dx = vec![0.0; ship.system.dim()];
    ship.system.derivatives(straight, input, &mut ws, &mut dx);
    let u0 = straight[r.u];
    let u2 = model.vocabulary.parse("u^2").map_err(|e| ShipError::Model(e.to_string()))?;
    let mut out = model.clone();
    let mut result = [0.0; 2];
    for (k, (eq, residual)) in [("v_dot", dx[r.v]), ("r_dot", dx[r.r])].into_iter().enumerate() {
        let e = out.equation(eq).ok_or_else(|| ShipError::Model(format!("no equation {eq}")))?.clone();
        let old = e.coefficient(&u2);
        let new = old - residual / (u0 * u0);
        let mut coefs: Vec<_> = e.coefficients.into_iter().filter(|(t, _, _)| *t != u2).collect();
        coefs.push((u2.clone(), new, None));
        out.set_coefficients(eq, coefs, e.intercept);
        result[k] = new;
    }
    Ok((out, result[0], result[1]))
}
