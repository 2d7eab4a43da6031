//! Whether identified equations retrace the runs they came from: a system whose rates fit
//! its rows may still run away when integrated (too coarse samples, a near-degenerate
//! library: spurious terms that cancel on the data and nowhere else). A check for any
//! system; a plug-in's field adds its own physical checks.

use crate::data::Frame;
use crate::model::Model;
use crate::plugin::Check;
use crate::sim::Integrator;

/// How far beyond a run's range, in spans of it, a re-simulated state may go before the
/// equations are said to run away: an exact model of an unstable or chaotic system stays
/// within the run's range, give or take its noise.
const REACH: f64 = 10.0;

/// How closely, in spans of each state's recorded range, a re-simulation is said to follow
/// its run.
const FOLLOWED: f64 = 0.1;

/// The most samples of a run re-simulated: a longer run is resampled to as many (its inputs
/// low-pass filtered first), which cannot hide a state running away by ten spans, and bounds
/// the check's cost on a long record (a million rows: 0.2 s where every row took 0.6 s, on
/// an identification of 0.9 s).
const MOST_SAMPLES: usize = 20_000;

/// The check that `model`, re-simulated from each run's first sample under its recorded
/// inputs (adaptive steps, as `validate` does), stays within ten spans of each state's
/// recorded range over the run. An equation without terms is a rate of 0: an identification
/// that chose none (a forcing the candidates lack) is re-simulated as it stands, so how long
/// it follows its runs is said. `None` where it cannot apply: a run that lacks a state or an
/// input.
pub fn retrace_check(model: &Model, runs: &[Frame]) -> Option<Check> {
    // the states and inputs
    let names = model.vocabulary.variables();
    if runs.is_empty() || runs.iter().any(|r| names.iter().any(|n| r.column(n).is_none())) {
        return None;
    }
    let check = |passed: bool, detail: String| Check {
        name: "the equations retrace their runs without running away".into(),
        passed,
        refuses: true,
        detail,
        measure: None,
    };
    let remedy = "the rates fit the rows but not the motion: sample faster, fewer candidates, or refine by output error (--refine)";
    // how long each run is followed (s, of s), reported: a model that stays bounded may still
    // drift off its run (a polynomial standing in for a sine), as an exact chaotic one does
    // after a few Lyapunov times, so it is said, not judged
    let mut followed: Vec<(String, f64, f64)> = Vec::new();
    for whole in runs {
        let step = crate::data::sample_step(std::slice::from_ref(whole));
        let (run, step) = match whole.len().div_ceil(MOST_SAMPLES) {
            0 | 1 => (whole.clone(), step),
            k => (crate::data::resample(whole, step * k as f64).ok()?, step * k as f64),
        };
        let one =
            crate::diagnose::Runs::new(model, std::slice::from_ref(&run), step, Integrator::Dopri5).ok()?;
        let sim = match crate::diagnose::simulate_runs(&one, model) {
            Ok(mut s) if s.len() == 1 => s.remove(0),
            Ok(_) => return None,
            Err(e) => {
                return Some(check(
                    false,
                    format!("{}: re-simulated from its start, {e}: {remedy}", run.origin()),
                ))
            }
        };
        let mut left = sim.time.len();
        for (name, values) in sim.state_names.iter().zip(&sim.states) {
            let Some(recorded) = run.column(name) else { continue };
            let (lo, hi) =
                recorded.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
            let span = (hi - lo).max(f64::EPSILON * hi.abs().max(lo.abs()).max(1.0));
            if let Some(k) = values.iter().zip(recorded).position(|(v, r)| (v - r).abs() > FOLLOWED * span) {
                left = left.min(k);
            }
            let away = values.iter().position(|v| !(*v >= lo - REACH * span && *v <= hi + REACH * span));
            if let Some(k) = away {
                return Some(check(
                    false,
                    format!(
                        "{}: re-simulated from its start, `{name}` reaches {} at t = {} s where the run keeps within {} … {}: {remedy}",
                        run.origin(),
                        crate::identify::num(values[k]),
                        crate::identify::num(sim.time[k]),
                        crate::identify::num(lo),
                        crate::identify::num(hi)
                    ),
                ));
            }
        }
        let (start, end) = (sim.time[0], sim.time[sim.time.len() - 1]);
        let until = sim.time.get(left).map_or(end, |&t| t);
        followed.push((run.origin().to_string(), until - start, end - start));
    }
    // the run followed for the least share of its length
    let least = followed
        .iter()
        .min_by(|a, b| (a.1 / a.2.max(f64::MIN_POSITIVE)).total_cmp(&(b.1 / b.2.max(f64::MIN_POSITIVE))));
    let follow = match least {
        Some((origin, until, of)) if until < of => format!(
            "; they follow them within a tenth of each state's span for {} s of {} s ({origin}{})",
            crate::output::sig(*until, 3),
            crate::output::sig(*of, 3),
            if runs.len() > 1 { ", the least of the runs" } else { "" }
        ),
        _ => "; they follow them within a tenth of each state's span throughout".to_string(),
    };
    Some(check(
        true,
        format!(
            "{} run(s) re-simulated from their starts stay within {REACH} spans of their records{follow}",
            runs.len()
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    const GROWTH: &str = "[model]\nname = \"growth\"\nintercept = false\n[[states]]\nname = \"x\"\n\
        [equations.x_dot]\nstate = \"x\"\ncandidates = [\"x\"]\ncoefficients = { \"x\" = 0.5 }\n";

    fn run(x: impl Fn(f64) -> f64) -> Frame {
        let t: Vec<f64> = (0..=200).map(|k| k as f64 * 0.1).collect();
        let mut f = Frame::new("run.csv", "t", t.clone()).unwrap();
        f.push("x", t.iter().map(|&t| x(t)).collect()).unwrap();
        f
    }

    /// ẋ = x/2 retraces its own exponential run (e^10 at the end: unstable, not running
    /// away), but runs away from a run that stays near 1: beyond ten spans of it.
    #[test]
    fn equations_that_leave_their_runs_far_behind_are_said_to() {
        let model = Model::parse(GROWTH, "growth.toml").unwrap();
        let own = retrace_check(&model, &[run(|t| (t / 2.0).exp())]).unwrap();
        assert!(own.passed, "{}", own.detail);
        assert!(own.detail.ends_with("within a tenth of each state's span throughout"), "{}", own.detail);
        // a run that stops growing at 19 s: followed (within a tenth of its span, e^9.5 − 1)
        // until e^(t/2) − e^9.5 exceeds it, after t = 2 ln(1.1 e^9.5 − 0.1) = 19.19 s
        let stops = retrace_check(&model, &[run(|t| (t.min(19.0) / 2.0).exp())]).unwrap();
        assert!(stops.passed && stops.detail.ends_with("for 19.2 s of 20.0 s (run.csv)"), "{}", stops.detail);
        let flat = retrace_check(&model, &[run(|t| 1.0 + 0.01 * t.sin())]).unwrap();
        // a long run too, re-simulated at fewer samples
        let t: Vec<f64> = (0..=50_000).map(|k| k as f64 * 4e-4).collect();
        let mut long = Frame::new("long.csv", "t", t.clone()).unwrap();
        long.push("x", t.iter().map(|t| 1.0 + 0.01 * t.sin()).collect()).unwrap();
        let away = retrace_check(&model, &[long]).unwrap();
        assert!(!away.passed && away.detail.starts_with("long.csv"), "{}", away.detail);
        assert!(!flat.passed && flat.refuses, "{}", flat.detail);
        assert!(flat.detail.contains("run.csv: re-simulated from its start, `x` reaches"), "{}", flat.detail);
        // an equation that chose no term is a rate of 0, followed while the run stays within a
        // tenth of its span of its start: x = t/20 over 20 s leaves 0 by more than 0.1 after t = 2 s (the next sample, 2.1 s)
        let bare =
            Model::parse(&GROWTH.replace("coefficients = { \"x\" = 0.5 }\n", ""), "bare.toml").unwrap();
        let none = retrace_check(&bare, &[run(|t| t / 20.0)]).unwrap();
        assert!(none.passed && none.detail.ends_with("for 2.10 s of 20.0 s (run.csv)"), "{}", none.detail);
        // a run without its state is not judged
        let mut other = Frame::new("y.csv", "t", vec![0.0, 1.0, 2.0]).unwrap();
        other.push("y", vec![0.0; 3]).unwrap();
        assert!(retrace_check(&model, &[other]).is_none());
    }
}
