//! IMO's standards for ship manoeuvrability (Resolution MSC.137(76), 2002; explanatory notes
//! MSC/Circ.1053) applied to a manoeuvre's metrics: turning ability (advance ≤ 4.5 L,
//! tactical diameter ≤ 5 L at the largest rudder angle), initial turning (≤ 2.5 L to a 10°
//! heading change with 10° rudder), yaw checking (10°/10° first overshoot ≤ 10°, 5 + ½·L/V or
//! 20° by L/V in seconds; second overshoot ≤ 15° more; 20°/20° first overshoot ≤ 25°). The
//! standards are for full-scale ships: where a model's `[ship]` gives `full_scale_lpp`, the
//! time-based limits use the Froude-scaled L/V of the ship, else the model's own.

use serde::Serialize;

use super::manoeuvre::{Manoeuvre, Metrics};
use super::ShipSpec;

/// One criterion applied.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Criterion {
    /// What is judged, e.g. `advance`.
    pub name: String,
    /// The value (`None`: not reached in the run).
    pub value: Option<f64>,
    /// The largest value the standard allows.
    pub limit: f64,
    /// Unit of value and limit (`L`, `°`).
    pub unit: String,
    /// Whether the value is within the limit (`None` when not reached).
    pub passed: Option<bool>,
}

impl Criterion {
    fn new(name: &str, value: Option<f64>, limit: f64, unit: &str) -> Criterion {
        Criterion { name: name.into(), value, limit, unit: unit.into(), passed: value.map(|v| v <= limit) }
    }
}

/// L/V in seconds for the time-based limits: the full-scale ship's by Froude scaling where
/// `full_scale_lpp` is given (V scales with √L), else the model's own.
pub fn length_over_speed(ship: &ShipSpec) -> f64 {
    let own = ship.lpp / ship.u0;
    match ship.full_scale_lpp {
        Some(full) => own * (full / ship.lpp).sqrt(),
        None => own,
    }
}

/// The yaw-checking limit on the first overshoot of the 10°/10° zigzag, degrees.
pub fn first_overshoot_limit_10(l_over_v: f64) -> f64 {
    if l_over_v < 10.0 {
        10.0
    } else if l_over_v < 30.0 {
        5.0 + 0.5 * l_over_v
    } else {
        20.0
    }
}

/// The criteria that apply to `manoeuvre` (none for manoeuvres the standard does not name).
pub fn criteria(ship: &ShipSpec, manoeuvre: &Manoeuvre, metrics: &Metrics) -> Vec<Criterion> {
    let lengths = |m: Option<f64>| m.map(|m| m / ship.lpp);
    let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
    match (manoeuvre, metrics) {
        (Manoeuvre::Turning(t), Metrics::Turning(m))
            if t.rudder_deg.abs() >= ship.rudder_limit.min(35.0) - 1e-9 =>
        {
            vec![
                Criterion::new("advance", lengths(m.advance_m), 4.5, "L"),
                Criterion::new("tactical diameter", lengths(m.tactical_diameter_m), 5.0, "L"),
            ]
        }
        (Manoeuvre::InitialTurning(i), Metrics::InitialTurning(m))
            if close(i.rudder_deg.abs(), 10.0) && close(i.heading_deg, 10.0) =>
        {
            vec![Criterion::new("track reach at 10° heading change", m.track_reach_lpp, 2.5, "L")]
        }
        (Manoeuvre::ZigZag(z), Metrics::ZigZag(m))
            if close(z.rudder_deg, 10.0) && close(z.heading_deg, 10.0) =>
        {
            let first = first_overshoot_limit_10(length_over_speed(ship));
            vec![
                Criterion::new("10°/10° first overshoot", m.first_overshoot_deg, first, "°"),
                Criterion::new("10°/10° second overshoot", m.second_overshoot_deg, first + 15.0, "°"),
            ]
        }
        (Manoeuvre::ZigZag(z), Metrics::ZigZag(m))
            if close(z.rudder_deg, 20.0) && close(z.heading_deg, 20.0) =>
        {
            vec![Criterion::new("20°/20° first overshoot", m.first_overshoot_deg, 25.0, "°")]
        }
        _ => vec![],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaw_checking_limit_runs_through_its_three_ranges() {
        assert_eq!(first_overshoot_limit_10(5.0), 10.0);
        assert_eq!(first_overshoot_limit_10(20.0), 15.0);
        assert_eq!(first_overshoot_limit_10(29.999), 5.0 + 0.5 * 29.999);
        assert_eq!(first_overshoot_limit_10(45.0), 20.0);
    }

    /// A turning circle at the largest rudder angle is judged by its own advance and tactical
    /// diameter in ship lengths; at 20° no criterion applies; a 10°/10° zigzag gets two.
    #[test]
    fn criteria_read_the_runs_metrics() {
        use crate::sim::{Integrator, Settings};
        let model = crate::ship::default_model();
        let ship = crate::ship::Ship::new(&model, false).unwrap();
        let spec = ShipSpec::of(&model).unwrap().unwrap();
        let settings = Settings { integrator: Integrator::Rk4, dt: 0.04, duration: 200.0, sample: 0.04 };
        let judge = |text: &str| {
            let m = Manoeuvre::parse(text).unwrap();
            let run = ship.run(&m, &settings).unwrap();
            (criteria(&spec, &m, &run.metrics), run.metrics)
        };
        let (c, metrics) = judge("turning:35");
        let Metrics::Turning(t) = metrics else { panic!("turning metrics") };
        assert_eq!(c.len(), 2);
        assert_eq!(c[0].value, t.advance_lpp);
        assert_eq!(c[1].value, t.tactical_diameter_lpp);
        assert_eq!(c[0].passed, t.advance_lpp.map(|a| a <= 4.5));
        assert!(judge("turning:20").0.is_empty());
        let (z, _) = judge("zigzag:10/10");
        assert_eq!(z.iter().map(|c| c.limit).collect::<Vec<_>>(), [10.0, 25.0]);
    }

    /// The default model (HSVA 1512, L = 4.572 m, 2.01 m/s) at the scale of a 150 m ship:
    /// L/V = 2.275 s × √(150/4.572) = 13.0 s.
    #[test]
    fn froude_scaled_length_over_speed() {
        let mut ship = ShipSpec::of(&crate::ship::default_model()).unwrap().unwrap();
        assert!((length_over_speed(&ship) - 4.572 / 2.01).abs() < 1e-12);
        ship.full_scale_lpp = Some(150.0);
        let lv = length_over_speed(&ship);
        assert!((lv - 4.572 / 2.01 * (150.0f64 / 4.572).sqrt()).abs() < 1e-12 && (lv - 13.03).abs() < 0.01);
    }
}
