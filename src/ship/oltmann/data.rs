//! The analysed data: the five Z-manoeuvres simulated with the true model (100 s, B8 at
//! 0.04 s, 0.2 s samples; Oltmann 1973 §5) and their degraded versions, the five data
//! alternatives of the paper's Fig. 5 (NOTES.md §8).

use serde::Serialize;

use crate::data::{DataError, Frame};
use crate::ship::manoeuvre::ZigZag;
use crate::ship::{Manoeuvre, Ship, ShipError};
use crate::sim::{Integrator, Settings, Trajectory};

/// The five analysed Z-manoeuvres: (file stem, rudder °, heading °).
pub const MANOEUVRES: [(&str, f64, f64); 5] = [
    ("z15_10", 15.0, 10.0),
    ("z20_10", 20.0, 10.0),
    ("z25_10", 25.0, 10.0),
    ("z30_10", 30.0, 10.0),
    ("z20_20", 20.0, 20.0),
];

/// Integration step, s (eq. B8).
pub const DT: f64 = 0.04;
/// Sampling interval of the analysed data, s.
pub const SAMPLE: f64 = 0.2;
/// Length of each run, s.
pub const DURATION: f64 = 100.0;

/// Which rudder angle the "exact" accelerations belong to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum AccelerationTiming {
    /// ẋ(t) = f(x(t), δ(t)): consistent with the sampled rudder angle.
    RudderAtT,
    /// f(x(t), δ(t+Δt)): the acceleration the B8 integrator used for the step from t, paired
    /// with δ(t) in the data (what a program printing its integration variables produces).
    RudderAtTPlusDt,
}

/// The units in which r and ṙ are rounded for the degraded alternatives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RateUnit {
    /// °/s and °/s², as the paper printed them.
    Degrees,
    /// rad/s and rad/s².
    Radians,
}

/// The paper's data alternatives (Fig. 5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Alternative {
    /// 1: original values.
    Exact,
    /// 2: u, v, r and the accelerations cut by one decimal (5 → 4 decimals).
    CutOne,
    /// 3: cut by two decimals (3 decimals).
    CutTwo,
    /// 4: accelerations from central differences of the cut-by-two velocities.
    CutDifferentiated,
    /// 5: velocities rounded to 2 decimals and differentiated (Tables 4-6).
    RoundedDifferentiated,
}

impl Alternative {
    /// All five, in the paper's order.
    pub const ALL: [Alternative; 5] = [
        Alternative::Exact,
        Alternative::CutOne,
        Alternative::CutTwo,
        Alternative::CutDifferentiated,
        Alternative::RoundedDifferentiated,
    ];

    /// 1-based number as in Fig. 5.
    pub fn number(self) -> usize {
        Alternative::ALL.iter().position(|a| *a == self).unwrap_or(0) + 1
    }

    /// Whether the accelerations are numerical derivatives of the velocities.
    pub fn differentiated(self) -> bool {
        matches!(self, Alternative::CutDifferentiated | Alternative::RoundedDifferentiated)
    }

    /// Short description.
    pub fn label(self) -> &'static str {
        match self {
            Alternative::Exact => "1 exact",
            Alternative::CutOne => "2 cut 1 decimal",
            Alternative::CutTwo => "3 cut 2 decimals",
            Alternative::CutDifferentiated => "4 cut 2, differentiated",
            Alternative::RoundedDifferentiated => "5 rounded to 2, differentiated",
        }
    }
}

/// One simulated manoeuvre.
#[derive(Clone, Debug)]
pub struct Recorded {
    /// `z30_10` etc.
    pub name: String,
    /// Its zigzag.
    pub zigzag: ZigZag,
    /// The run at every integration step.
    pub fine: Trajectory,
    /// The analysed samples (0.2 s): t, u, v, r, ψ, x0, y0, δ and u_dot, v_dot, r_dot.
    pub frame: Frame,
    /// The zigzag's metrics (overshoots, period).
    pub metrics: crate::ship::Metrics,
}

/// Simulates the five manoeuvres with the true model.
pub fn simulate_manoeuvres(ship: &Ship, timing: AccelerationTiming) -> Result<Vec<Recorded>, ShipError> {
    let settings = Settings { integrator: Integrator::ModifiedEuler, dt: DT, duration: DURATION, sample: DT };
    let every = (SAMPLE / DT).round() as usize;
    MANOEUVRES
        .iter()
        .map(|(name, d, p)| {
            let zigzag = ZigZag { rudder_deg: *d, heading_deg: *p, starboard_first: true, about_deg: None };
            let run = ship.run(&Manoeuvre::ZigZag(zigzag.clone()), &settings)?;
            let frame = sample(ship, &run.trajectory, every, timing, name)?;
            Ok(Recorded { name: name.to_string(), zigzag, fine: run.trajectory, frame, metrics: run.metrics })
        })
        .collect()
}

fn sample(
    ship: &Ship,
    fine: &Trajectory,
    every: usize,
    timing: AccelerationTiming,
    name: &str,
) -> Result<Frame, DataError> {
    let rows: Vec<usize> = (0..fine.time.len()).step_by(every).collect();
    let pick = |c: &[f64]| rows.iter().map(|&i| c[i]).collect::<Vec<f64>>();
    let mut f = Frame::new(name, "t", pick(&fine.time))?;
    for (n, c) in fine.state_names.iter().zip(&fine.states) {
        f.push(n, pick(c))?;
    }
    for (n, c) in fine.input_names.iter().zip(&fine.inputs) {
        f.push(n, pick(c))?;
    }
    let mut ws = ship.system.workspace();
    let mut dx = vec![0.0; ship.system.dim()];
    let mut acc = vec![Vec::with_capacity(rows.len()); ship.system.dim()];
    for &i in &rows {
        let x: Vec<f64> = fine.states.iter().map(|c| c[i]).collect();
        let j = match timing {
            AccelerationTiming::RudderAtT => i,
            AccelerationTiming::RudderAtTPlusDt => (i + 1).min(fine.time.len() - 1),
        };
        let u: Vec<f64> = fine.inputs.iter().map(|c| c[j]).collect();
        ship.system.derivatives(&x, &u, &mut ws, &mut dx);
        for (a, d) in acc.iter_mut().zip(&dx) {
            a.push(*d);
        }
    }
    for (n, a) in fine.state_names.iter().zip(acc) {
        f.push(&format!("{n}_dot"), a)?;
    }
    Ok(f)
}

fn round_to(x: f64, decimals: i32, truncate: bool) -> f64 {
    let s = 10f64.powi(decimals);
    if truncate {
        (x * s).trunc() / s
    } else {
        (x * s).round() / s
    }
}

/// The data of one alternative. u, v [m/s] and u̇, v̇ [m/s²] are cut or rounded in SI; r and
/// ṙ in `rate_unit`; δ is never changed ("bis auf den Ruderwinkel δ"). The originals carry
/// 5 decimals (the paper's printout). For 4 and 5 the acceleration columns are removed: the
/// regression differentiates the velocities itself.
pub fn degrade(frame: &Frame, alt: Alternative, rate_unit: RateUnit) -> Result<Frame, DataError> {
    let (decimals, truncate) = match alt {
        Alternative::Exact => return Ok(frame.clone()),
        Alternative::CutOne => (4, true),
        Alternative::CutTwo | Alternative::CutDifferentiated => (3, true),
        Alternative::RoundedDifferentiated => (2, false),
    };
    // rates are rounded in the unit they are printed in
    let scale = match rate_unit {
        RateUnit::Degrees => 180.0 / std::f64::consts::PI,
        RateUnit::Radians => 1.0,
    };
    let mut out = frame.clone();
    for (col, rate) in
        [("u", false), ("v", false), ("r", true), ("u_dot", false), ("v_dot", false), ("r_dot", true)]
    {
        let Some(c) = frame.column(col) else { continue };
        let values: Vec<f64> = c
            .iter()
            .map(|x| {
                if rate {
                    round_to(x * scale, decimals, truncate) / scale
                } else {
                    round_to(*x, decimals, truncate)
                }
            })
            .collect();
        out.set(col, values)?;
    }
    if alt.differentiated() {
        let keep: Vec<String> = out.names().iter().filter(|n| !n.ends_with("_dot")).cloned().collect();
        let mut stripped = Frame::new(out.origin(), "t", out.time().to_vec())?;
        for n in keep.iter().skip(1) {
            stripped.push(n, out.require(n)?.to_vec())?;
        }
        out = stripped;
    }
    Ok(out)
}
