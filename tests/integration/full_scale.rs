//! A ship at full scale through the defaults that were set at model scale: the grey-box model
//! `new-ship` writes for a 320 m ship (and for one at 24 knots, and for a container ship), the
//! manoeuvres' default times, a model file whose bounds leave no room for its ship, and a zigzag
//! whose rudder indicator reads a stop a little past the ship's limit. Froude's law is the
//! reference: a ship λ times its model turns the same circle in ship lengths, √λ times slower.

use termid::model::Model;
use termid::ship::manoeuvre::Spiral;
use termid::ship::particulars::Particulars;
use termid::ship::{Manoeuvre, Metrics, Ship};
use termid::sim::{Integrator, Settings};

/// KVLCC2 from the SIMMAN model (L = 7 m) to the ship (L = 320 m).
const LAMBDA: f64 = 320.0 / 7.0;

fn model_scale() -> Particulars {
    toml::from_str(&std::fs::read_to_string("examples/kvlcc2_particulars.toml").unwrap()).unwrap()
}

/// The particulars Froude-scaled by `lambda`: lengths × λ, areas × λ², speeds × √λ, the rudder's
/// rate ÷ √λ.
fn froude(p: &Particulars, lambda: f64) -> Particulars {
    let s = lambda.sqrt();
    Particulars {
        name: format!("{} × {lambda:.1}", p.name),
        lpp: p.lpp * lambda,
        beam: p.beam * lambda,
        draught: p.draught * lambda,
        x_g: p.x_g * lambda,
        rudder_area: p.rudder_area * lambda * lambda,
        rudder_span: p.rudder_span * lambda,
        propeller_diameter: p.propeller_diameter * lambda,
        u0: p.u0 * s,
        rudder_rate: p.rudder_rate / s,
        ..p.clone()
    }
}

/// A manoeuvre over the duration the ship plug-in gives it by default (as `termid simulate`
/// does without `--duration`).
fn run(model: &Model, text: &str) -> Metrics {
    let ship = Ship::new(model, false).unwrap();
    let manoeuvre = Manoeuvre::parse(text).unwrap();
    let duration = manoeuvre.default_duration(ship.time_scale());
    // the step the 7 m model is simulated at, at the ship's own time scale (Froude's law)
    let dt = 0.04 * ship.time_scale() / (7.0 / 1.17248);
    let settings = Settings { integrator: Integrator::Rk4, dt, duration, sample: dt };
    ship.run(&manoeuvre, &settings).unwrap().metrics
}

fn tactical_diameter_in_lengths(model: &Model, lpp: f64, rudder: f64) -> f64 {
    let Metrics::Turning(t) = run(model, &format!("turning:{rudder}")) else { unreachable!() };
    t.tactical_diameter_m.expect("the circle completes in the default time") / lpp
}

/// `new-ship` at 320 m writes a model that simulates as its 7 m model does, in ship lengths:
/// its bounds are the ship's (a 7 m model's 10 m/s surge bound stopped a 24-knot ship at its
/// first step), and the turning circle's default time is long enough for the ship's 35° turn.
#[test]
fn a_ship_from_its_particulars_at_full_scale_turns_as_its_model() {
    let small = model_scale();
    let at_model = tactical_diameter_in_lengths(&small.model().unwrap(), small.lpp, 35.0);
    let big = froude(&small, LAMBDA);
    let at_ship = tactical_diameter_in_lengths(&big.model().unwrap(), big.lpp, 35.0);
    assert!(
        (at_ship / at_model - 1.0).abs() < 2e-3,
        "{at_ship} L at full scale, {at_model} L at model scale"
    );
    // a faster ship of the same hull: 24 knots, beyond the template's 10 m/s
    let fast = Particulars { u0: 12.35, ..big };
    let model = fast.model().unwrap();
    let u = model.spec().states.iter().find(|s| s.name == "u").unwrap();
    assert!(u.max.unwrap() >= 10.0 * fast.u0 && u.min.unwrap() <= 0.01 * fast.u0 + 1e-12, "{u:?}");
    assert!(tactical_diameter_in_lengths(&model, fast.lpp, 35.0) > 2.0);
}

/// A spiral's holds and a pull-out's times, left to the defaults, are so many of the ship's own
/// time scale L/U (never less than the model-scale defaults): at full scale a 120 s hold left
/// the yaw rate unsettled and drew a hysteresis loop of 2.3° for a course-stable ship.
#[test]
fn a_manoeuvres_default_times_follow_the_ships_time_scale() {
    let big = froude(&model_scale(), LAMBDA);
    let ship = Ship::new(&big.model().unwrap(), false).unwrap();
    let scale = ship.time_scale();
    assert!((scale - 320.0 / (1.17248 * LAMBDA.sqrt())).abs() < 1e-9);
    let spiral = Spiral::default();
    assert_eq!(spiral.hold(scale), (20.0 * scale).ceil());
    assert_eq!(spiral.hold(320.0 / 7.0 / 8.0), 120.0, "at model scale the hold stays 120 s");
    let label = Manoeuvre::Spiral(spiral).at_scale(scale).label();
    assert!(label.contains(&format!("{} s each", (20.0 * scale).ceil())), "{label}");
    // the pull-out steadies in its turn and decays after it
    let Metrics::PullOut(p) = run(&big.model().unwrap(), "pullout:20") else { unreachable!() };
    assert!(
        p.decay_time_s.is_some() && p.residual_yaw_rate_deg_s.abs() < 0.05 * p.turning_yaw_rate_deg_s.abs(),
        "{p:?}"
    );
    // a spiral about a small rudder angle, each hold the default: the course-stable hull
    // draws no loop (the model-scale default 120 s drew 2.3° over ±20°)
    let Metrics::Spiral(s) = run(&big.model().unwrap(), "spiral") else { unreachable!() };
    assert!(s.loop_width_deg.unwrap_or(0.0) < 0.2 && s.unsettled_deg_s < 0.01, "{s:?}");
}

/// The MMG KVLCC2 file (L = 7 m) edited for the 320 m ship, its bounds left at the 7 m model's:
/// the sway speed's ±5 m/s would stop a sound turn of a ship at 7.9 m/s, and the surge speed's
/// 10 m/s a ship at 12 m/s at once. Refused at load, naming the key, and so is `--param u0=12`
/// on the 7 m file. The polynomial template's bounds hold any ship's manoeuvres (u to 30 m/s):
/// it loads for both.
#[test]
fn a_ship_model_whose_bounds_leave_no_room_for_its_manoeuvres_is_refused_with_its_key() {
    let text = std::fs::read_to_string("models/mmg_kvlcc2.toml").unwrap();
    let ship = text.replace("lpp = 7.0", "lpp = 320.0");
    let full = ship.replace("u0 = 1.17248 ", "u0 = 7.91 ");
    let e = termid::plugins::parse(&full, "full.toml").unwrap_err().to_string();
    assert!(e.contains("full.toml:") && e.contains("`states[1].min`") && e.contains("sway speed"), "{e}");
    let fast = ship.replace("u0 = 1.17248 ", "u0 = 12.0 ");
    let e = termid::plugins::parse(&fast, "fast.toml").unwrap_err().to_string();
    assert!(e.contains("`states[0].max`") && e.contains("u0 = 12 m/s"), "{e}");
    // widened, it loads
    let widened = full.replacen("min = -5.0\nmax = 5.0", "min = -40.0\nmax = 40.0", 1);
    termid::plugins::parse(&widened, "widened.toml").unwrap();
    // an approach speed given on the command line is held to the same rule
    let (ok, _, err) = crate::common::termid(&[
        "simulate",
        "--model",
        "models/mmg_kvlcc2.toml",
        "-m",
        "turning:35",
        "--param",
        "u0=12",
    ]);
    assert!(!ok && err.contains("--param u0=12") && err.contains("`states[0].max`"), "{err}");
    let template =
        std::fs::read_to_string("models/new_ship.toml").unwrap().replace("lpp = 7.0", "lpp = 320.0");
    for u0 in ["7.91", "12.0"] {
        termid::plugins::parse(&template.replace("u0 = 1.17 ", &format!("u0 = {u0} ")), "ship.toml").unwrap();
    }
}

/// A basin's 35°/5° zigzag, its rudder indicator 0.3° off: the rudder at its 35° stop reads
/// 35.3°, and the angles it held read 35.001° about +0.3°, a noise past the ship's limit. The
/// check that the model steers its runs as recorded lays them as recorded (it refused the run:
/// "beyond the ship's rudder limit").
#[test]
fn a_zigzag_laid_to_the_rudder_stop_is_steered_as_recorded() {
    let truth = termid::plugins::load(std::path::Path::new("models/mmg_kvlcc2.toml")).unwrap();
    let basin = termid::ship::basin::Basin::tracked();
    let frames: Vec<_> = ["zigzag:35/5", "zigzag:35/5:port", "zigzag:20/20"]
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let manoeuvre = Manoeuvre::parse(m).unwrap();
            basin
                .record(&truth, &manoeuvre, 1.17248, 60.0, 1 + k as u64, &format!("{k}.dat"))
                .unwrap()
                .measured
        })
        .collect();
    let each: Vec<_> = frames.iter().map(|f| (&truth, f)).collect();
    let check = termid::ship::checks::steering_check(&each).unwrap();
    assert!(check.passed && check.detail.contains("of 3 records'"), "{check:?}");
}

/// A container ship nobody has tested (KCS's particulars, 230 m at 24 knots) from `new-ship` to
/// IMO's criteria: the 10°/10° first overshoot's limit at L/V = 18.6 s is 5 + L/V/2 = 14.31°
/// (MSC.137(76) 5.4.1), printed as such (it printed 14.31174089068826).
#[test]
fn a_container_ship_from_its_particulars_meets_imos_limits_as_printed() {
    let dir = crate::common::Scratch::new("kcs");
    let particulars = dir.join("kcs.toml");
    std::fs::write(
        &particulars,
        "name = \"KCS\"\nlpp = 230.0\nbeam = 32.2\ndraught = 10.8\nblock_coefficient = 0.651\nx_g = -3.4\n\
         rudder_area = 54.45\nrudder_span = 9.9\npropeller_diameter = 7.9\nu0 = 12.35\nrudder_rate = 2.32\n\
         rudder_limit = 35.0\n",
    )
    .unwrap();
    let model = dir.join("kcs_greybox.toml");
    let (ok, _, err) = crate::common::termid(&[
        "new-ship",
        "--particulars",
        particulars.to_str().unwrap(),
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, text, err) =
        crate::common::termid(&["simulate", "--model", model.to_str().unwrap(), "-m", "zigzag:10/10"]);
    assert!(ok, "{err}");
    let limit = 5.0 + 0.5 * 230.0 / 12.35;
    assert!(text.contains(&format!("(limit {limit:.2} °)")) && !text.contains("14.311"), "{text}");
    assert!(text.contains("first overshoot") && !text.contains("not reached"), "{text}");
}

/// A sea trial of the MMG KVLCC2 Froude-scaled to 320 m as a ship logs it, written to `dir` as
/// eight CSVs and `trial.toml`: the eight zigzags of both sides, satellite fixes as latitude and
/// longitude about 54° N at 1 Hz (5 cm; the ellipsoid's radii of curvature at the first fix), a
/// gyrocompass in [0°, 360°) on a course of 355°, so that every zigzag swings through north, no
/// log (u and v from the track), the propeller's rate; the ship in a steady `current` (m/s
/// towards north and east), which carries the fixes; the receiver's antenna `antenna` m
/// forward of midship (the dataset file says where). Returns the truth.
fn sea_trial(dir: &std::path::Path, current: (f64, f64), antenna: f64) -> Model {
    use termid::ship::basin::{Artefacts, Basin, Noise, ZIGZAGS_BOTH_SIDES};

    let small = termid::plugins::load(std::path::Path::new("models/mmg_kvlcc2.toml")).unwrap();
    let s = LAMBDA.sqrt();
    let truth = termid::plugins::rescaled(&small, LAMBDA, s, LAMBDA.powi(3)).unwrap();
    let u0 = 1.17248 * s;
    let trial = Basin {
        rate_hz: 1.0,
        approach_s: 60.0,
        noise: Noise {
            speed_m_s: 0.0,
            yaw_rate_deg_s: 0.02,
            heading_deg: 0.05,
            position_m: 0.05,
            rudder_deg: 0.1,
        },
        dt: 0.1,
        artefacts: Artefacts { midship_end_s: 60.0, ..Artefacts::default() },
    };
    let runs = trial.record_all(&truth, &ZIGZAGS_BOTH_SIDES, u0, 700.0, 5, None).unwrap();
    let (course, lat0, lon0) = (355f64.to_radians(), 54f64.to_radians(), 7f64.to_radians());
    let (m, n) = termid::data::radii_of_curvature(lat0);
    let mut set = String::from(
        "[columns]\nt = \"time [s]\"\n\"ψ\" = \"gyro [deg]\"\nr = \"rot [deg/s]\"\n\"δ\" = \"rudder [deg]\"\nn = \"rpm [1/min]\"\n\
         [track]\nlatitude = \"lat [deg]\"\nlongitude = \"lon [deg]\"\nx = \"x0\"\ny = \"y0\"\nheading = \"ψ\"\nu = \"u\"\nv = \"v\"\n",
    );
    for (name, rec) in &runs {
        let f = &rec.measured;
        let col = |c: &str| f.column(c).unwrap();
        let mut text = String::from("time,lat,lon,gyro,rot,rudder,rpm\n");
        for k in 0..f.len() {
            // the fix is the antenna's, on the ship's centre line
            let (t, psi) = (f.time()[k], rec.truth.column("ψ").unwrap()[k]);
            let (x, y) = (col("x0")[k] + antenna * psi.cos(), col("y0")[k] + antenna * psi.sin());
            // the track through the water turned onto the course, and carried by the current
            let north = x * course.cos() - y * course.sin() + current.0 * t;
            let east = x * course.sin() + y * course.cos() + current.1 * t;
            let (lat, lon) = (lat0 + north / m, lon0 + east / (n * lat0.cos()));
            text.push_str(&format!(
                "{t},{:.9},{:.9},{:.3},{:.4},{:.2},{:.2}\n",
                lat.to_degrees(),
                lon.to_degrees(),
                (col("ψ")[k] + course).to_degrees().rem_euclid(360.0),
                col("r")[k].to_degrees(),
                col("δ")[k].to_degrees(),
                col("n")[k] * 60.0
            ));
        }
        let file = name.replace(".dat", ".csv");
        std::fs::write(dir.join(&file), text).unwrap();
        set.push_str(&format!("[[runs]]\nfile = \"{file}\"\n"));
    }
    let set = set.replace("[track]\n", &format!("[track]\nantenna = [{antenna:?}, 0.0]\n"));
    std::fs::write(dir.join("trial.toml"), set).unwrap();
    truth
}

/// The same trial in a current of 0.5 m/s (a knot) setting south-west (from 40°): satellite
/// fixes give the velocity over ground, which carries it. Held at still water, the grey-box
/// fits the runs as well as it can by bending the hull and misses the +35° circle by 16 % (its
/// check of the runs' overshoots flags it, but blames the structure). `termid estimate` on a
/// dataset tracked by latitude and longitude estimates the current `new-ship`'s model declares
/// (`c_N`, `c_E`, once for the trial) with the ship, says so, and writes the model in still
/// water: the current within 0.02 m/s, the ±35° circles within 5 % (−3.5 %, −4.0 %).
/// `validate` on the same runs estimates the day's current alone first (the model held): each
/// first overshoot within 0.7° where in still water they miss by up to 3.8°.
#[test]
fn a_sea_trial_in_a_current_estimates_the_current_with_the_ship() {
    use crate::common::{json, termid};

    let dir = crate::common::Scratch::new("sea-trial-current");
    let from = 40f64.to_radians();
    let current = (-0.5 * from.cos(), -0.5 * from.sin());
    let truth = sea_trial(&dir, current, 0.0);
    let start = froude(&model_scale(), LAMBDA).model().unwrap();
    std::fs::write(dir.join("start.toml"), start.to_toml()).unwrap();
    let path = |f: &str| dir.join(f).display().to_string();
    let estimated = |hold: &[&str]| {
        let (start, dataset, out) = (path("start.toml"), path("trial.toml"), path("estimated.toml"));
        let mut args = vec!["estimate", "--model", &start, "--dataset", &dataset, "--states", "u,v,r,ψ"];
        args.extend(["--format", "json", "--out", &out]);
        args.extend(hold);
        let (ok, out, err) = termid(&args);
        assert!(ok, "{err}");
        (json(&out), err, termid::plugins::load(&dir.join("estimated.toml")).unwrap())
    };
    let error = |model: &Model, rudder: f64| {
        tactical_diameter_in_lengths(model, 320.0, rudder)
            / tactical_diameter_in_lengths(&truth, 320.0, rudder)
            - 1.0
    };

    let (report, said, model) = estimated(&[]);
    assert!(
        said.contains("tracked over ground (by a satellite receiver)")
            && said.contains("c_E, c_N are estimated"),
        "{said}"
    );
    let value = |name: &str| {
        report["per_source"].as_array().unwrap().iter().find(|p| p["name"] == name).unwrap()["value"]
            .as_f64()
            .unwrap()
    };
    assert!((value("c_N") - current.0).abs() < 0.02 && (value("c_E") - current.1).abs() < 0.02, "{report}");
    // the model written is the ship's in still water, its current held for the next estimate
    assert_eq!(model.parameter_values()["c_N"], 0.0);
    assert!(!model.free_parameters().iter().any(|p| p.name == "c_N"));
    for rudder in [35.0, -35.0] {
        assert!(error(&model, rudder).abs() < 0.05, "δ = {rudder}°: {:+.3}", error(&model, rudder));
    }

    // the model validated on the trial's runs in the day's current, estimated alone (the model
    // held), each run's first overshoot within 1°; in still water they miss by degrees
    let first_overshoots_missed_by = |extra: &[&str]| {
        let (est, dataset) = (path("estimated.toml"), path("trial.toml"));
        let mut args = vec!["validate", "--model", &est, "--dataset", &dataset, "--format", "json"];
        args.extend(extra);
        let (ok, out, err) = termid(&args);
        assert!(ok, "{err}");
        let worst = json(&out)["metrics"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| {
                let first = |side: &str| m[side]["first_overshoot_deg"].as_f64().unwrap();
                (first("simulated") - first("measured")).abs()
            })
            .fold(0.0, f64::max);
        (worst, err)
    };
    let (worst, said) = first_overshoots_missed_by(&[]);
    assert!(said.contains("so they carry the current they moved in: estimated alone"), "{said}");
    assert!(worst < 1.0, "validated in the day's current: first overshoots within {worst:.2}°");
    let (worst, _) = first_overshoots_missed_by(&["--hold", "c_N,c_E"]);
    assert!(worst > 2.0, "validated in still water: first overshoots within {worst:.2}°");

    // a polynomial model takes the velocities over ground for the ship's own: said
    let (_, _, said) =
        termid(&["identify", "--model", "models/new_ship.toml", "--dataset", &path("trial.toml")]);
    assert!(said.contains("tracked over ground") && said.contains("every term biased by it"), "{said}");

    let (_, said, held) = estimated(&["--hold", "c_N,c_E"]);
    assert!(!said.contains("tracked over ground"), "{said}");
    assert!(error(&held, 35.0).abs() > 0.10, "held at still water: {:+.3}", error(&held, 35.0));
}

/// A sea trial of the 320 m ship as a ship logs it ([`sea_trial`], in still water, the
/// receiver's antenna on the bridge 130 m aft). Read through a dataset file (`[track]
/// latitude`, `longitude`, `antenna`), the fixes moved to midship and the heading made one
/// continuous angle, `new-ship`'s model from the ship's particulars estimated on the eight
/// zigzags predicts the ±35° circles within 3 % (−2.1 % and −2.5 %; with the fixes at midship
/// −2.2 % and −2.5 %, logged at 4 Hz −1.2 % and −1.4 %: the model basin's 20 Hz gives 1.0-1.5
/// %). The truth is `termid::plugins::rescaled`, which rescales the ship's table too (the
/// coefficients alone left the ship at the basin's speed and rudder rate).
#[test]
fn a_sea_trial_logged_by_satellite_and_gyrocompass_predicts_the_ships_turning_circles() {
    use termid::data::Dataset;
    use termid::diagnose::{estimate, Runs};

    let dir = crate::common::Scratch::new("sea-trial");
    let truth = sea_trial(&dir, (0.0, 0.0), -130.0);
    let start = froude(&model_scale(), LAMBDA).model().unwrap();
    let (mut frames, _) = Dataset::load(&dir.join("trial.toml")).unwrap().read(&dir, "t").unwrap();
    let mut said = Vec::new();
    for f in &mut frames {
        said.extend(start.admit(f).unwrap());
    }
    assert!(said.iter().filter(|n| n.contains("`ψ` jumps by a full turn")).count() == 8, "{said:?}");
    let runs = Runs::new(&start, &frames, 1.0, Integrator::Rk4)
        .unwrap()
        .comparing(&start, &["u", "v", "r", "ψ"].map(String::from))
        .unwrap();
    let fit = estimate(&start, &runs, &Default::default()).unwrap();
    // the fixes moved from the bridge's antenna: the fit leaves the records' noise (taken as
    // midship's, 0.80 % of their variance against 0.19 %, the hull bent to absorb it)
    assert!(fit.follows() && fit.unexplained < 1.5 * fit.noise, "{}", fit.text());
    for rudder in [35.0, -35.0] {
        let (got, want) = (
            tactical_diameter_in_lengths(&fit.model, 320.0, rudder),
            tactical_diameter_in_lengths(&truth, 320.0, rudder),
        );
        assert!(
            (got / want - 1.0).abs() < 0.03,
            "δ = {rudder}°: {got:.3} L against the truth's {want:.3} L\n{}",
            fit.text()
        );
    }
}
