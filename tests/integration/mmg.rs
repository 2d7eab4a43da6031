//! The MMG standard model of KVLCC2 (`models/mmg_kvlcc2.toml`), a second ship model family
//! written as a model file, against the independent implementation of the same equations in
//! the shipmmg package (0.0.11, its KVLCC2 L7 test case): the numbers below are shipmmg's,
//! simulated by `benches/peers/mmg.sh` with the rudder and propeller series termid's
//! manoeuvre gave (from the self-propulsion point at u0 = 1.17248 m/s).

use std::path::Path;

use termid::ship::{Manoeuvre, Metrics, Ship};
use termid::sim::{Integrator, Settings};

fn ship() -> Ship {
    let model = termid::plugins::load(Path::new("models/mmg_kvlcc2.toml")).unwrap();
    Ship::new(&model, false).unwrap()
}

fn run(ship: &Ship, manoeuvre: &str) -> Metrics {
    let s = Settings { integrator: Integrator::Rk4, dt: 0.01, duration: 200.0, sample: 0.01 };
    ship.run(&Manoeuvre::parse(manoeuvre).unwrap(), &s).unwrap().metrics
}

#[test]
fn turning_circles_equal_shipmmgs() {
    let ship = ship();
    // (rudder, shipmmg's advance, shipmmg's tactical diameter), metres
    for (rudder, advance, tactical) in
        [(35.0, 21.451, 21.121), (-35.0, 20.428, 19.279), (20.0, 27.309, 30.123), (-20.0, 25.119, 25.983)]
    {
        let Metrics::Turning(t) = run(&ship, &format!("turning:{rudder}")) else { unreachable!() };
        // MMG's convention (z down): positive rudder turns to starboard
        assert_eq!(t.direction, if rudder > 0.0 { "starboard" } else { "port" });
        let (a, d) = (t.advance_m.unwrap(), t.tactical_diameter_m.unwrap());
        assert!((a / advance - 1.0).abs() < 0.005, "δ = {rudder}°: advance {a} vs shipmmg {advance}");
        assert!(
            (d / tactical - 1.0).abs() < 0.005,
            "δ = {rudder}°: tactical diameter {d} vs shipmmg {tactical}"
        );
    }
}

#[test]
fn zigzag_overshoots_equal_shipmmgs() {
    let ship = ship();
    for (manoeuvre, first, second) in [("zigzag:10/10", 4.895, 13.043), ("zigzag:20/20", 10.463, 15.094)] {
        let Metrics::ZigZag(z) = run(&ship, manoeuvre) else { unreachable!() };
        let (a, b) = (z.first_overshoot_deg.unwrap(), z.second_overshoot_deg.unwrap());
        assert!((a - first).abs() < 0.2, "{manoeuvre}: first overshoot {a}° vs shipmmg {first}°");
        assert!((b - second).abs() < 0.2, "{manoeuvre}: second overshoot {b}° vs shipmmg {second}°");
    }
}

#[test]
fn the_straight_run_finds_the_self_propulsion_point() {
    let ship = ship();
    let start = ship.straight_run().unwrap();
    let n = start.input[ship.roles.propeller.unwrap()];
    // K_T(J) = 0.2931 − 0.2753 J − 0.1385 J² with J = (1 − w_P0) u / (n D_p) must balance the
    // resistance ½ρLdU²R'_0 = 0.5·1025·7·0.46·1.17248²·0.022 = 49.95 N through (1 − t_P) ρ n² D_p⁴ K_T
    let j = 0.6 * 1.17248 / (n * 0.216);
    let thrust = 0.78 * 1025.0 * n * n * 0.216f64.powi(4) * (0.2931 - 0.2753 * j - 0.1385 * j * j);
    let resistance = 0.5 * 1025.0 * 7.0 * 0.46 * 1.17248f64.powi(2) * 0.022;
    assert!(
        (thrust / resistance - 1.0).abs() < 1e-9,
        "n = {n}: thrust {thrust} N, resistance {resistance} N"
    );
    assert!(start.surge_residual.abs() < 1e-12 && start.v0 == 0.0 && start.delta0_deg == 0.0);
}

#[test]
fn a_propeller_that_is_not_an_input_is_refused_with_its_key() {
    let text = std::fs::read_to_string("models/mmg_kvlcc2.toml").unwrap();
    let text = text.replace("names = { propeller = \"n\" }", "names = { propeller = \"ρ\" }");
    let e = termid::plugins::parse(&text, "mmg.toml").unwrap_err().to_string();
    assert!(e.contains("ship.names.propeller") && e.contains("not an input"), "{e}");
}
