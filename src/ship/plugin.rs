//! The manoeuvring plug-in as the core sees it: the `[ship]` table, the default ship, the
//! tracking filter as a derivative method, the ship's diagnosis hypotheses, manoeuvre metrics
//! of recorded runs and the standard manoeuvres as scenarios (registered in `crate::plugin`).

use super::observed::observe;
use super::{canonical_spec, Manoeuvre, Metrics, Ship, ShipError, ShipSpec};
use crate::data::Frame;
use crate::diagnose::Hypothesis;
use crate::model::{Model, ModelError};
use crate::plugin::{Check, Observation, Outcome, Plugin, PluginError, Scenario, ScenarioRequest};
use crate::sim::{Settings, Trajectory};

/// Ship manoeuvring (Oltmann 1973; IMO MSC.137(76)).
pub struct Manoeuvring;

/// `--derivative kinematic`: the ship's tracking filter (all states of a run at once).
const KINEMATIC: &str = "kinematic";

impl From<ShipError> for PluginError {
    fn from(e: ShipError) -> Self {
        PluginError::failed(e)
    }
}

impl Plugin for Manoeuvring {
    fn table(&self) -> &'static str {
        super::spec::TABLE
    }

    fn check(&self, model: &Model, text: &str) -> Result<(), ModelError> {
        ShipSpec::check(model, text)
    }

    fn default_model(&self) -> Option<Model> {
        Some(super::default_model())
    }

    fn set_parameter(&self, model: &mut Model, name: &str, value: f64) -> Result<bool, PluginError> {
        let Some(mut ship) = ShipSpec::of(model)?.filter(|_| name == "u0") else { return Ok(false) };
        if value <= 0.0 {
            return Err(PluginError::Refused(format!(
                "--param u0={value}: the approach speed must be positive"
            )));
        }
        ship.u0 = value;
        if let Some((key, why)) = ship.bounds_without_room(model) {
            return Err(PluginError::Refused(format!("--param u0={value}: {}: `{key}`: {why}", model.path)));
        }
        ship.store(model);
        Ok(true)
    }

    fn derivative_methods(&self) -> &'static [&'static str] {
        &[KINEMATIC]
    }

    fn recipe_defaults(&self, model: &Model) -> Option<crate::plugin::RecipeDefaults> {
        // the new-ship recipe ("Starting a new ship"): every preparation a start, the states
        // smoothed by it, refined on the velocities and heading (positions integrate every
        // earlier error and would dominate the cost)
        let states = model.spec().states.iter().map(|s| s.name.as_str()).collect::<Vec<_>>();
        Some(crate::plugin::RecipeDefaults {
            derivatives: [KINEMATIC, "kalman", "savitzky-golay", "central"].map(String::from).to_vec(),
            smooth: true,
            refine: Some(
                ["u", "v", "r", "ψ"].into_iter().filter(|s| states.contains(s)).map(String::from).collect(),
            ),
        })
    }

    fn prepare(
        &self,
        method: &str,
        model: &Model,
        frame: &Frame,
        smooth: bool,
    ) -> Result<Frame, PluginError> {
        if method != KINEMATIC {
            return Err(PluginError::Refused(format!("no derivative method `{method}`")));
        }
        let ship = canonical_spec(model).ok_or_else(|| {
            PluginError::Refused(format!(
                "--derivative kinematic is the ship plug-in's tracking filter: {} has no [ship] section",
                model.path
            ))
        })?;
        super::tracking::track(frame, &ship, smooth).map_err(PluginError::failed)
    }

    fn reference(&self, model: &Model) -> Option<(f64, f64, f64)> {
        let spec = ShipSpec::of(model).ok().flatten()?;
        Some((spec.lpp, spec.u0, spec.density.unwrap_or(1000.0)))
    }

    fn plane(&self, model: &Model) -> Option<crate::sim::Plane> {
        let spec = canonical_spec(model)?;
        let n = &spec.names;
        Some(crate::sim::Plane {
            across: (n.y0.clone(), format!("{}/L [-] (starboard)", n.y0)),
            up: (n.x0.clone(), format!("{}/L [-] (initial course)", n.x0)),
            length: spec.lpp,
            title: format!("track (L = {} m)", spec.lpp),
        })
    }

    fn coefficient_name(&self, model: &Model, equation: &str, term: &crate::term::Term) -> Option<String> {
        let spec = canonical_spec(model)?;
        let n = &spec.names;
        let state = model.equation(equation)?.state.clone();
        let letter = if state == n.u {
            "X"
        } else if state == n.v {
            "Y"
        } else if state == n.r {
            "N"
        } else {
            return None;
        };
        // the subscript names the motion variables, each as often as its power (the speed
        // that makes the term a force, u or U, is the prime system's, not a subscript)
        let mut sub = String::new();
        let m = term.monomials().first()?;
        for (atom, k) in &m.factors {
            let name = match atom {
                crate::term::Atom::Var(v) if *v == n.u || v == "U" => continue,
                crate::term::Atom::Var(v) if rudder_angle(model, v, &n.rudder) => "δ".to_string(),
                crate::term::Atom::Var(v) => v.clone(),
                crate::term::Atom::Call(f, args) if f == "abs" => format!("|{}|", args.first()?),
                _ => return None,
            };
            for _ in 0..k.unsigned_abs() {
                sub += &name;
            }
        }
        Some(if sub.is_empty() { format!("{letter}'_0") } else { format!("{letter}'_{sub}") })
    }

    fn rescale(&self, model: &mut Model, length: f64, time: f64, mass: f64) -> Result<(), PluginError> {
        let Some(mut spec) = ShipSpec::of(model)? else { return Ok(()) };
        spec.lpp *= length;
        spec.beam *= length;
        spec.draught *= length;
        // a volume; the mass factor is the volume's at equal density
        spec.displacement *= mass;
        spec.u0 *= length / time;
        spec.rudder_rate /= time;
        spec.rudder_delay *= time;
        spec.rudder_acceleration = spec.rudder_acceleration.map(|a| a / (time * time));
        spec.store(model);
        Ok(())
    }

    fn checks(&self, model: &Model, runs: &[Frame]) -> Vec<Check> {
        let Some(spec) = canonical_spec(model) else { return vec![] };
        // turning circles at the largest rudder angle the runs used (from each run's start,
        // its approach), the model's limit when there are no runs
        let used = runs
            .iter()
            .filter_map(|f| f.column(&spec.names.rudder))
            .map(|d| d.iter().map(|v| (v - d[0]).abs()).fold(0.0, f64::max).to_degrees())
            .fold(0.0, f64::max);
        let rudder = if used > 0.0 { used.min(spec.rudder_limit) } else { spec.rudder_limit };
        match super::checks::physical_checks(model, rudder) {
            Ok(mut checks) => {
                let each: Vec<(&Model, &Frame)> = runs.iter().map(|f| (model, f)).collect();
                checks.extend(self.run_checks(&each));
                checks
            }
            Err(e) => vec![Check {
                name: "the model simulates as a ship".into(),
                passed: false,
                refuses: true,
                detail: e.to_string(),
                measure: None,
            }],
        }
    }

    fn run_checks(&self, runs: &[(&Model, &Frame)]) -> Vec<Check> {
        super::checks::steering_check(runs).into_iter().collect()
    }

    fn metric_checks(&self, pairs: &[crate::plugin::MetricPair]) -> Vec<Check> {
        super::checks::overshoot_check(pairs).into_iter().collect()
    }

    fn hypotheses(&self, model: &Model) -> Option<Vec<Hypothesis>> {
        Some(super::hypotheses::hypotheses(model))
    }

    fn observe(&self, model: &Model, frame: &Frame, simulated: Option<&Trajectory>) -> Option<Observation> {
        let ship = canonical_spec(model)?;
        let n = &ship.names;
        // a simulation's track with the rudder it was given, the recorded one
        let seen = match simulated {
            None => {
                let col = |c: &str| frame.column(c);
                // a record without a track still has its zigzag's overshoots
                let track = |c: &str| col(c).unwrap_or(&[]);
                observe(frame.time(), col(&n.psi)?, col(&n.rudder)?, track(&n.x0), track(&n.y0))
            }
            Some(s) => {
                let state = |c: &str| s.state(c);
                observe(&s.time, state(&n.psi)?, frame.column(&n.rudder)?, state(&n.x0)?, state(&n.y0)?)
            }
        };
        let rows = [
            ("1st overshoot [°]", "first_overshoot_deg", seen.first_overshoot_deg),
            ("2nd overshoot [°]", "second_overshoot_deg", seen.second_overshoot_deg),
            ("advance [m]", "advance_m", seen.advance_m),
            ("transfer [m]", "transfer_m", seen.transfer_m),
            ("tactical diameter [m]", "tactical_diameter_m", seen.tactical_diameter_m),
        ];
        // a record knows no commanded switching heading: the one definition that applies to
        // measurement and model alike is the heading at the rudder's reversal
        let note = seen.first_overshoot_deg.is_some().then(|| {
            "overshoots are read off the samples, beyond the heading at each rudder reversal, for measurement and model alike; `simulate` reports a manoeuvre's beyond its commanded switching heading at every integration step (the heading moves on within the step in which it is reached, so the two differ by up to about a tenth of a degree)".to_string()
        });
        Some(Observation {
            json: serde_json::to_value(&seen).unwrap_or_default(),
            rows: rows.iter().map(|(l, k, v)| (l.to_string(), k.to_string(), *v)).collect(),
            note,
        })
    }

    fn scenario(
        &self,
        model: &Model,
        request: &ScenarioRequest<'_>,
    ) -> Result<Box<dyn Scenario>, PluginError> {
        // a manoeuvre starts from the straight approach and drives the rudder itself
        if request.initial_given {
            return Err(PluginError::Refused("--initial does not apply to a ship manoeuvre: it starts from the straight approach at u0 (set it with --param u0=…), v and δ of the straight run, r = ψ = 0".into()));
        }
        if request.inputs_given {
            return Err(PluginError::Refused("--input does not apply to a ship manoeuvre: the manoeuvre drives the rudder; for recorded inputs use --manoeuvre replay:FILE.csv".into()));
        }
        let ship = Ship::new(model, request.with_intercept)?;
        // the times a manoeuvre leaves to the ship, fixed at the nominal ship's scale: every
        // Monte-Carlo draw runs the same manoeuvre, and the label states them
        let manoeuvre = Manoeuvre::parse(request.text)?.at_scale(ship.time_scale());
        Ok(Box::new(ShipScenario { ship, manoeuvre, with_intercept: request.with_intercept }))
    }
}

/// A standard manoeuvre of a ship model.
struct ShipScenario {
    /// The nominal model's ship (its figure's roles, its time scale).
    ship: Ship,
    manoeuvre: Manoeuvre,
    with_intercept: bool,
}

impl Scenario for ShipScenario {
    fn label(&self) -> String {
        self.manoeuvre.label()
    }

    fn default_duration(&self) -> f64 {
        self.manoeuvre.default_duration(self.ship.time_scale())
    }

    fn run(&self, model: &Model, settings: &Settings) -> Result<Outcome, PluginError> {
        let ship = Ship::new(model, self.with_intercept)?;
        let run = ship.run(&self.manoeuvre, settings)?;
        let frame = ship.frame(&run.trajectory, "simulation").map_err(PluginError::failed)?;
        let metrics = serde_json::to_value(&run.metrics).map_err(PluginError::failed)?;
        let mut extra = serde_json::Map::new();
        extra.insert("delta0_deg".into(), run.start.delta0_deg.into());
        extra.insert("v0".into(), run.start.v0.into());
        let mut text = vec![format!(
            "straight run: δ0 = {:.3}°, v0 = {:.5} m/s (u̇ residual {:.2e} m/s²); {} steps of {} s",
            run.start.delta0_deg,
            run.start.v0,
            run.start.surge_residual,
            (settings.duration / settings.dt).round(),
            settings.dt
        )];
        if let Some(p) = ship.roles.propeller {
            let (name, n) = (&ship.system.inputs[p], run.start.input[p]);
            extra.insert("propeller".into(), n.into());
            text[0] += &format!("; self-propulsion point {name} = {n:.4} (holds u0 = {} m/s)", ship.spec.u0);
        }
        if let Some(map) = metrics.as_object() {
            for (k, v) in map {
                // a length in ship lengths goes beside the same length in metres
                if k == "manoeuvre" || k == "points" || k == "reversals_s" || k.ends_with("_lpp") {
                    continue;
                }
                let (label, unit, decimals) = crate::plugin::metric_label(k);
                let in_lengths = k
                    .strip_suffix("_m")
                    .and_then(|stem| map.get(&format!("{stem}_lpp")))
                    .and_then(serde_json::Value::as_f64)
                    .map_or(String::new(), |l| format!(" ({l:.2} L)"));
                let value = match (v.is_null(), v.as_f64()) {
                    // a spiral's branches that cross r = 0 within the sampling: no loop
                    (false, Some(w)) if k == "loop_width_deg" && w < 0.005 => {
                        "none: both branches cross r = 0 at one angle (course-stable)".to_string()
                    }
                    (true, _) => format!("not reached in {} s (a longer --duration)", settings.duration),
                    (false, Some(x)) => format!("{x:.decimals$} {unit}{in_lengths}"),
                    (false, None) => v.as_str().map_or_else(|| v.to_string(), str::to_string),
                };
                text.push(format!("  {label:<28} {}", value.trim_end()));
            }
        }
        if let Metrics::Replay(_) = &run.metrics {
            // a replay has no metrics of its own: say where it ended, and how to compare
            let (t, last) = (run.trajectory.time.last().copied().unwrap_or(0.0), run.trajectory.last_state());
            let r = &ship.roles;
            text.push(format!(
                "  ended at t = {t:.2} s: heading {:.2}°, yaw rate {:.3} °/s, speed {:.3} m/s",
                last[r.psi].to_degrees(),
                last[r.r].to_degrees(),
                last[r.u]
            ));
            text.push(
                "  a replay has no metrics of its own: `termid validate --data FILE.csv` sets the model beside the record, `--out` writes the run"
                    .into(),
            );
        }
        if let Metrics::Spiral(s) = &run.metrics {
            text.push(format!("  {:>8} {:>10} {:>6}", "δ [°]", "r [°/s]", "branch"));
            for p in &s.points {
                text.push(format!("  {:>8.1} {:>10.4} {:>6}", p.rudder_deg, p.yaw_rate_deg_s, p.branch));
            }
        }
        let imo = super::imo::criteria(&ship.spec, &self.manoeuvre, &run.metrics);
        if !imo.is_empty() {
            let lv = super::imo::length_over_speed(&ship.spec);
            let scale = match ship.spec.full_scale_lpp {
                Some(full) => format!("L/V = {lv:.1} s of the {full} m ship, Froude-scaled"),
                None => format!("L/V = {lv:.2} s of this model; set [ship] full_scale_lpp for a ship's"),
            };
            text.push(format!("IMO MSC.137(76) ({scale}):"));
            for c in &imo {
                let verdict = match c.passed {
                    Some(true) => "meets",
                    Some(false) => "FAILS",
                    None => "not reached",
                };
                let value = c.value.map_or("--".to_string(), |v| format!("{v:.2}"));
                text.push(format!(
                    "  {:<34} {value:>8} {} (limit {} {})  {verdict}",
                    c.name,
                    c.unit,
                    super::manoeuvre::hundredths(c.limit),
                    c.unit
                ));
            }
            extra.insert("imo".into(), serde_json::to_value(&imo).map_err(PluginError::failed)?);
        }
        Ok(Outcome { trajectory: run.trajectory, frame, metrics, extra, text })
    }

    #[cfg(feature = "plot")]
    fn figure(&self, title: &str, nominal: &Outcome, draws: &[&Trajectory]) -> crate::plot::Figure {
        use super::figure::{add_bands, manoeuvre_figure, spiral_figure};
        if let Manoeuvre::Spiral(_) = self.manoeuvre {
            return spiral_figure(title, &nominal.metrics);
        }
        let mut fig = manoeuvre_figure(&self.ship, title, &[("simulation", &nominal.trajectory)], true);
        if !draws.is_empty() {
            add_bands(&mut fig, &self.ship, draws);
        }
        fig
    }
}

/// Whether `name` is the rudder's angle: the rudder input itself, or a derived variable that
/// is the input less a parameter (the angle from its indicator's zero, `δ_t = δ - δ_0`).
fn rudder_angle(model: &Model, name: &str, rudder: &str) -> bool {
    use crate::term::Atom;
    if name == rudder {
        return true;
    }
    let Some(definition) = model.vocabulary.derived_definition(name) else { return false };
    let parameters = model.vocabulary.parameters();
    let single = |m: &crate::term::Monomial, want: &dyn Fn(&str) -> bool| matches!(m.factors.as_slice(), [(Atom::Var(v), 1)] if want(v));
    match definition.monomials() {
        [a, b] => {
            let (input, zero) = if single(a, &|v| v == rudder) { (a, b) } else { (b, a) };
            input.coef == 1.0
                && single(input, &|v| v == rudder)
                && zero.coef == -1.0
                && single(zero, &|v| parameters.iter().any(|p| p == v))
        }
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plugin::Plugin;

    /// The field's names of the template's coefficients: the rudder is δ whether a term reads
    /// the input or its angle from the indicator's zero (`δ_t = δ - δ_0`); u and U make the
    /// term a force and are no subscript.
    #[test]
    fn coefficients_are_named_as_the_field_names_them() {
        let model = Model::parse(include_str!("../../models/new_ship.toml"), "new_ship.toml").unwrap();
        let name = |equation: &str, term: &str| {
            let t = model.vocabulary.parse(term).unwrap();
            Manoeuvring.coefficient_name(&model, equation, &t)
        };
        assert_eq!(name("r_dot", "u^2*δ_t").as_deref(), Some("N'_δ"));
        assert_eq!(name("v_dot", "u^2*δ_t^3").as_deref(), Some("Y'_δδδ"));
        assert_eq!(name("r_dot", "u^2*δ").as_deref(), Some("N'_δ"));
        assert_eq!(name("v_dot", "U*v").as_deref(), Some("Y'_v"));
        assert_eq!(name("u_dot", "u^2").as_deref(), Some("X'_0"));
        // a derived variable that is not the rudder less a parameter keeps its own name
        assert!(!rudder_angle(&model, "U", "δ"));
    }
}
