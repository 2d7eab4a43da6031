//! The reproduction of Oltmann (1973): the five Z-manoeuvres simulated with the true model,
//! identified by stepwise regression from exact and from degraded data, re-simulated, and
//! laid beside the paper's tables and figures (`termid reproduce`). [`run`] computes
//! everything into a [`Study`]; [`report`] writes it as Markdown, SVG, CSV and JSON.

pub mod data;
#[cfg(feature = "plot")]
pub mod report;
pub mod resim;
pub mod tables;

use serde::Serialize;

use data::{degrade, simulate_manoeuvres, AccelerationTiming, Alternative, RateUnit, Recorded};
use resim::{balance_straight_run, errors, identified_model, original_samples, replay, Column, Errors};
use tables::{equation_table, paper_table, paper_tables, EquationTable};

use crate::identify::IdentifyError;
use crate::model::Model;
use crate::ship::{Manoeuvre, Metrics, Ship, ShipError};
use crate::sim::{Integrator, Settings, Trajectory};

/// The equations the paper identified.
pub const EQUATIONS: [&str; 3] = ["u_dot", "v_dot", "r_dot"];

/// Why the reproduction failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReproduceError {
    /// Simulation or ship model.
    #[error(transparent)]
    Ship(#[from] ShipError),
    /// Regression.
    #[error(transparent)]
    Identify(#[from] IdentifyError),
    /// Data handling.
    #[error(transparent)]
    Data(#[from] crate::data::DataError),
    /// Writing the report.
    #[error("{0}")]
    Io(String),
}

/// Settings of the reproduction.
#[derive(Clone, Debug, Serialize)]
pub struct Options {
    /// Acceleration timing of the "exact" data (the default is consistent: δ(t)).
    pub timing: AccelerationTiming,
    /// Units in which r and ṙ are rounded for alternatives 2-5.
    pub rate_unit: RateUnit,
}

impl Default for Options {
    fn default() -> Self {
        Options { timing: AccelerationTiming::RudderAtT, rate_unit: RateUnit::Degrees }
    }
}

/// A re-simulation against an original run.
#[derive(Clone, Debug, Serialize)]
pub struct Resimulation {
    /// The manoeuvre (`z30_10`).
    pub run: String,
    /// Which coefficients (`exact/Komb` …).
    pub coefficients: String,
    /// The errors (None if the re-simulation diverged; see `failure`).
    pub errors: Errors,
    /// Why the re-simulation failed, if it did.
    pub failure: Option<String>,
    /// The re-simulated samples.
    #[serde(skip)]
    pub trajectory: Trajectory,
}

/// One point of Fig. 5: an alternative's regression of the 30°/10° run at its chosen step.
#[derive(Clone, Debug, Serialize)]
pub struct AlternativePoint {
    /// Equation.
    pub equation: String,
    /// Alternative number 1-5.
    pub alternative: usize,
    /// Units r was rounded in.
    pub rate_unit: RateUnit,
    /// Chosen step.
    pub chosen_step: usize,
    /// F at the chosen step.
    pub f: f64,
    /// Standard error at the chosen step.
    pub standard_error: f64,
}

/// A manoeuvre's metrics with the true and with identified coefficients.
#[derive(Clone, Debug, Serialize)]
pub struct Prediction {
    /// Which manoeuvre.
    pub manoeuvre: String,
    /// Which coefficients.
    pub coefficients: String,
    /// Metrics, or why the run failed (an identified model may diverge).
    pub metrics: Result<Metrics, String>,
    /// The run (samples).
    #[serde(skip)]
    pub trajectory: Trajectory,
}

/// The heading drift before and after adding B0·u² and C0·u².
#[derive(Clone, Debug, Serialize)]
pub struct DriftCure {
    /// Which coefficients.
    pub coefficients: String,
    /// Estimated B0 (v̇ coefficient of u²) in the corrected model.
    pub b0: f64,
    /// Estimated C0 (ṙ coefficient of u²).
    pub c0: f64,
    /// Re-simulations without the correction.
    pub before: Vec<Resimulation>,
    /// And with it.
    pub after: Vec<Resimulation>,
}

/// Everything the reproduction computed.
#[derive(Clone, Debug, Serialize)]
pub struct Study {
    /// Settings used.
    pub options: Options,
    /// δ0 of the true model's straight run, degrees.
    pub delta0_deg: f64,
    /// The five manoeuvres.
    #[serde(skip)]
    pub recorded: Vec<Recorded>,
    /// Their zigzag metrics.
    pub manoeuvre_metrics: Vec<(String, Metrics)>,
    /// Tables 1-3 (exact data).
    pub exact: Vec<EquationTable>,
    /// Tables 1-3 again with δ(t+Δt) accelerations, for the comparison of step counts.
    pub exact_other_timing: Vec<EquationTable>,
    /// Tables 4-6 (alternative 5).
    pub alt5: Vec<EquationTable>,
    /// Fig. 5 points.
    pub alternatives: Vec<AlternativePoint>,
    /// Replayed zigzags with identified coefficients.
    pub resimulations: Vec<Resimulation>,
    /// Spiral, turning circles and ordinary zigzags: true and identified.
    pub predictions: Vec<Prediction>,
    /// The B0/C0 story.
    pub drift: Vec<DriftCure>,
    /// termid's own discrepancy workflow on the alternative-5 Komb. model and the five runs.
    pub diagnosis: Option<crate::diagnose::Diagnosis>,
}

impl Study {
    /// The original run `name` (`z30_10`) at the analysed samples.
    pub fn original(&self, name: &str) -> Option<Trajectory> {
        self.recorded.iter().find(|r| r.name == name).map(original_samples)
    }
}

fn tables_for(
    model: &Model,
    frames: &[crate::data::Frame],
    alt: Alternative,
) -> Result<Vec<EquationTable>, ReproduceError> {
    EQUATIONS
        .iter()
        .enumerate()
        .map(|(k, eq)| {
            let paper = paper_table(paper_tables(alt != Alternative::Exact)[k], &model.vocabulary);
            Ok(equation_table(model, eq, frames, alt, &paper)?)
        })
        .collect()
}

fn resimulate(
    ship: &Ship,
    set: &str,
    identified: &Ship,
    recorded: &[Recorded],
    runs: &[usize],
) -> Result<Vec<Resimulation>, ReproduceError> {
    runs.iter()
        .map(|&k| {
            let orig = original_samples(&recorded[k]);
            let (errors, failure, trajectory) = match replay(identified, &recorded[k]) {
                Ok(t) => (errors(ship, &orig, &t), None, t),
                Err(e) => (Errors::default(), Some(e.to_string()), Trajectory::default()),
            };
            Ok(Resimulation {
                run: recorded[k].name.clone(),
                coefficients: set.into(),
                errors,
                failure,
                trajectory,
            })
        })
        .collect()
}

/// Runs the whole study; `progress(stage)` is told what is being done.
pub fn run(
    model: &Model,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Study, ReproduceError> {
    let ship = Ship::new(model, false)?;
    progress("simulating the five Z-manoeuvres");
    let recorded = simulate_manoeuvres(&ship, options.timing)?;
    let delta0_deg = ship.straight_run()?.delta0_deg;
    let manoeuvre_metrics = recorded.iter().map(|r| (r.name.clone(), r.metrics.clone())).collect();

    progress("regressions on exact data (Tables 1-3)");
    let frames =
        |alt, unit| recorded.iter().map(|r| degrade(&r.frame, alt, unit)).collect::<Result<Vec<_>, _>>();
    let exact = tables_for(model, &frames(Alternative::Exact, options.rate_unit)?, Alternative::Exact)?;
    let other_timing = match options.timing {
        AccelerationTiming::RudderAtT => AccelerationTiming::RudderAtTPlusDt,
        AccelerationTiming::RudderAtTPlusDt => AccelerationTiming::RudderAtT,
    };
    let other = simulate_manoeuvres(&ship, other_timing)?;
    let other_frames: Vec<_> = other.iter().map(|r| r.frame.clone()).collect();
    let exact_other_timing = tables_for(model, &other_frames, Alternative::Exact)?;

    progress("regressions on rounded, differentiated data (Tables 4-6)");
    let alt5 = tables_for(
        model,
        &frames(Alternative::RoundedDifferentiated, options.rate_unit)?,
        Alternative::RoundedDifferentiated,
    )?;

    progress("data alternatives (Fig. 5)");
    let mut alternatives = Vec::new();
    for unit in [RateUnit::Degrees, RateUnit::Radians] {
        for alt in Alternative::ALL {
            let f = degrade(&recorded[3].frame, alt, unit)?;
            for t in tables_for(model, std::slice::from_ref(&f), alt)? {
                let s = &t.runs[0].selection;
                let step = &s.steps[s.chosen_step.max(1) - 1];
                alternatives.push(AlternativePoint {
                    equation: t.equation.clone(),
                    alternative: alt.number(),
                    rate_unit: unit,
                    chosen_step: s.chosen_step,
                    f: step.f,
                    standard_error: step.standard_error,
                });
            }
        }
    }

    progress("re-simulating with identified coefficients");
    let sets = [
        ("exact/Mittelwert", identified_model(model, &exact, Column::Mittelwert)),
        ("exact/Komb", identified_model(model, &exact, Column::Komb)),
        ("alt5/Mittelwert", identified_model(model, &alt5, Column::Mittelwert)),
        ("alt5/Komb", identified_model(model, &alt5, Column::Komb)),
    ];
    let ships = sets.iter().map(|(_, m)| Ship::new(m, false)).collect::<Result<Vec<_>, _>>()?;
    let mut resimulations = Vec::new();
    for ((name, _), s) in sets.iter().zip(&ships) {
        resimulations.extend(resimulate(&ship, name, s, &recorded, &[3, 4])?);
    }

    progress("spiral, turning circles and ordinary zigzags");
    let mut predictions = Vec::new();
    let manoeuvres = ["zigzag:30/10", "zigzag:20/20", "turning:20", "turning:-35", "spiral:20/2/100"];
    let komb = sets.iter().zip(&ships).filter(|((n, _), _)| n.ends_with("Komb")).map(|((n, _), s)| (*n, s));
    for (name, s) in std::iter::once(("true", &ship)).chain(komb) {
        for text in manoeuvres {
            let man = Manoeuvre::parse(text)?;
            let settings = Settings {
                integrator: Integrator::ModifiedEuler,
                dt: data::DT,
                duration: man.default_duration(s.time_scale()),
                sample: data::SAMPLE,
            };
            let (metrics, trajectory) = match s.run(&man, &settings) {
                Ok(run) => (Ok(run.metrics), run.trajectory),
                Err(e) => (Err(e.to_string()), Trajectory::default()),
            };
            predictions.push(Prediction {
                manoeuvre: text.into(),
                coefficients: name.to_string(),
                metrics,
                trajectory,
            });
        }
    }

    progress("heading drift and its cure (B0, C0)");
    let mut drift = Vec::new();
    for (name, m) in sets.iter().filter(|(n, _)| n.starts_with("alt5")) {
        // the paper's way: the identified model must hold the recorded straight run (first sample)
        let first = &recorded[3];
        let x0: Vec<f64> = first.fine.states.iter().map(|c| c[0]).collect();
        let u0: Vec<f64> = first.fine.inputs.iter().map(|c| c[0]).collect();
        let (cured, b0, c0) = balance_straight_run(m, &x0, &u0)?;
        drift.push(DriftCure {
            coefficients: name.to_string(),
            b0,
            c0,
            // the uncorrected re-simulations are those of the section above
            before: resimulations.iter().filter(|r| r.coefficients == *name).cloned().collect(),
            after: resimulate(
                &ship,
                &format!("{name} + B0, C0"),
                &Ship::new(&cured, false)?,
                &recorded,
                &[3, 4],
            )?,
        });
    }
    progress("termid diagnose on the alternative-5 model");
    let diagnosis = sets.iter().find(|(n, _)| *n == "alt5/Komb").and_then(|(_, m)| {
        let runs: Vec<crate::data::Frame> = recorded
            .iter()
            .filter_map(|r| degrade(&r.frame, Alternative::RoundedDifferentiated, options.rate_unit).ok())
            .collect();
        let hypotheses = crate::ship::hypotheses::hypotheses(m);
        crate::diagnose::diagnose(m, &runs, &hypotheses, &crate::diagnose::Settings::default()).ok()
    });
    Ok(Study {
        diagnosis,
        options: options.clone(),
        delta0_deg,
        recorded,
        manoeuvre_metrics,
        exact,
        exact_other_timing,
        alt5,
        alternatives,
        resimulations,
        predictions,
        drift,
    })
}
