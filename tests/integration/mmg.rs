//! The MMG standard model of KVLCC2 (`models/mmg_kvlcc2.toml`), a second ship model family
//! written as a model file, against the independent implementation of the same equations in
//! the shipmmg package (0.0.11, its KVLCC2 L7 test case): the numbers below are shipmmg's,
//! simulated by `benches/peers/mmg.sh` with the rudder series termid's manoeuvre gave.

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
        [(35.0, 17.888, 18.927), (-35.0, 16.982, 17.171), (20.0, 23.163, 28.042), (-20.0, 21.166, 24.008)]
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
    for (manoeuvre, first, second) in [("zigzag:10/10", 4.574, 11.869), ("zigzag:20/20", 10.596, 15.754)] {
        let Metrics::ZigZag(z) = run(&ship, manoeuvre) else { unreachable!() };
        let (a, b) = (z.first_overshoot_deg.unwrap(), z.second_overshoot_deg.unwrap());
        assert!((a - first).abs() < 0.2, "{manoeuvre}: first overshoot {a}° vs shipmmg {first}°");
        assert!((b - second).abs() < 0.2, "{manoeuvre}: second overshoot {b}° vs shipmmg {second}°");
    }
}
