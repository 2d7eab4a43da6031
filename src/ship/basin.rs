//! A synthetic model basin: free-running runs of a known model recorded as a basin records
//! them — a straight approach at the run's own speed, then the manoeuvre; sampled at the
//! logging rate with Gaussian sensor noise; written with the basin's own column names, angles
//! in degrees, whitespace-separated with a file header. The truth is kept beside the
//! recording, so identification from the files can be judged against it (what the paper did
//! by rounding, §8, with realistic measurement errors instead).

use std::fmt::Write as _;
use std::path::Path;

use super::{Manoeuvre, Metrics, Ship, ShipError, StraightRun};
use crate::data::Frame;
use crate::model::Model;
use crate::sim::{Integrator, Settings};
use crate::uncertainty::Normal;

/// Standard deviations of the sensors' noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// Surge and sway speed, m/s.
    pub speed_m_s: f64,
    /// Yaw rate, °/s.
    pub yaw_rate_deg_s: f64,
    /// Heading, °.
    pub heading_deg: f64,
    /// Position, m.
    pub position_m: f64,
    /// Rudder angle, °.
    pub rudder_deg: f64,
}

impl Default for Noise {
    /// Sizes typical of a model basin's carriage-free tracking and gyro (issue 7's figures).
    fn default() -> Self {
        Noise { speed_m_s: 0.02, yaw_rate_deg_s: 0.05, heading_deg: 0.1, position_m: 0.02, rudder_deg: 0.05 }
    }
}

/// What real records have beyond sensor noise (all off by default, as in the Oltmann basin).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Artefacts {
    /// The rudder indicator reads this much more than the rudder's hydrodynamic angle, °.
    pub rudder_offset_deg: f64,
    /// u and v are not logged but computed from the tracked position (with its noise) and the
    /// measured heading, by central differences over ± this many samples, as in the SIMMAN
    /// KVLCC2 files.
    pub velocities_from_track: Option<usize>,
    /// The record ends with the rudder back at midship (the straight run's angle) for this
    /// many seconds after the manoeuvre.
    pub midship_end_s: f64,
}

/// How runs are recorded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Basin {
    /// Logging rate, Hz.
    pub rate_hz: f64,
    /// Straight approach before the rudder is put over, s.
    pub approach_s: f64,
    /// Sensor noise.
    pub noise: Noise,
    /// Integration step of the truth (RK4), s.
    pub dt: f64,
    /// Artefacts of real records.
    pub artefacts: Artefacts,
}

impl Default for Basin {
    fn default() -> Self {
        Basin {
            rate_hz: 20.0,
            approach_s: 5.0,
            noise: Noise::default(),
            dt: 0.01,
            artefacts: Artefacts::default(),
        }
    }
}

impl Basin {
    /// A basin with optical tracking, as the MMG basin records: 2 mm on the track, 0.05° on
    /// heading and rudder, 0.05 °/s on the gyro, no log (u and v from the track), a rudder
    /// indicator that reads 0.3° more than the true angle, 5 s back at midship at the end.
    pub fn tracked() -> Basin {
        Basin {
            noise: Noise {
                speed_m_s: 0.0,
                yaw_rate_deg_s: 0.05,
                heading_deg: 0.05,
                position_m: 0.002,
                rudder_deg: 0.05,
            },
            artefacts: Artefacts {
                rudder_offset_deg: 0.3,
                velocities_from_track: Some(2),
                midship_end_s: 5.0,
            },
            ..Basin::default()
        }
    }

    /// Records `runs` (manoeuvre, approach speed × `u0`) of `model`, each `duration` s after
    /// its approach, with seeds `seed`, `seed + 1`, …; written into `dir` (when given) as
    /// `<manoeuvre>.dat`, the names returned with the recordings.
    pub fn record_all(
        &self,
        model: &Model,
        runs: &[(&str, f64)],
        u0: f64,
        duration: f64,
        seed: u64,
        dir: Option<&Path>,
    ) -> Result<Vec<(String, Recording)>, ShipError> {
        runs.iter()
            .enumerate()
            .map(|(k, (m, f))| {
                let name = format!("{}.dat", m.replace([':', '/'], "_"));
                let rec =
                    self.record(model, &Manoeuvre::parse(m)?, f * u0, duration, seed + k as u64, &name)?;
                if let Some(dir) = dir {
                    self.write(&rec, model, &dir.join(&name))
                        .map_err(|e| ShipError::Model(format!("{}: {e}", dir.join(&name).display())))?;
                }
                Ok((name, rec))
            })
            .collect()
    }
}

/// One recorded run.
#[derive(Clone, Debug)]
pub struct Recording {
    /// Noise-free states and inputs (SI, radians, model names), time from the start of the approach.
    pub truth: Frame,
    /// The same with sensor noise.
    pub measured: Frame,
    /// The manoeuvre's metrics from the noise-free run.
    pub metrics: Metrics,
    /// The run's approach speed, m/s.
    pub u0: f64,
}

/// The paper's five Z-manoeuvres (NOTES.md §4), each with the approach speed (× the nominal
/// u0) the synthetic-basin study gives it; the study identifies from the first four and
/// holds the last out.
pub const PAPER_RUNS: [(&str, f64); 5] = [
    ("zigzag:15/10", 0.97),
    ("zigzag:20/10:port", 1.02),
    ("zigzag:30/10", 0.99),
    ("zigzag:20/20:port", 1.03),
    ("zigzag:25/10", 0.98),
];

/// Zigzags of several amplitudes to both sides, each with its approach speed (× the nominal
/// u0): the training set of the MMG basin (`examples/mmg_basin.rs`).
pub const ZIGZAGS_BOTH_SIDES: [(&str, f64); 8] = [
    ("zigzag:10/10", 0.98),
    ("zigzag:10/10:port", 1.02),
    ("zigzag:20/20", 1.01),
    ("zigzag:20/20:port", 0.97),
    ("zigzag:15/5", 1.03),
    ("zigzag:15/5:port", 0.99),
    ("zigzag:35/5", 1.00),
    ("zigzag:35/5:port", 1.02),
];

/// The basin's column names and units for the ship's roles, as a dataset file maps them.
pub const COLUMNS: [(&str, &str); 8] = [
    ("t", "time [s]"),
    ("u", "u_log [m/s]"),
    ("v", "v_log [m/s]"),
    ("r", "yaw_rate [deg/s]"),
    ("ψ", "heading [deg]"),
    ("x0", "x_track [m]"),
    ("y0", "y_track [m]"),
    ("δ", "rudder [deg]"),
];

/// The basin's columns for `model`: [`COLUMNS`] and one per further input (a propeller's
/// rate), by its own name and unit.
pub fn columns(model: &Model) -> Vec<(String, String)> {
    let rudder = super::canonical_spec(model).map_or_else(|| "δ".to_string(), |s| s.names.rudder);
    COLUMNS
        .iter()
        .map(|(v, c)| (v.to_string(), c.to_string()))
        .chain(model.spec().inputs.iter().filter(|i| i.name != rudder).map(|i| {
            let unit = if i.unit.is_empty() { "-" } else { i.unit.as_str() };
            (i.name.clone(), format!("{} [{unit}]", i.name))
        }))
        .collect()
}

/// The model run at another approach speed: the ship's u0 and every parameter taken from the
/// run's surge speed in identification (`first:u`, `mean:u…`), so that Δu = u − u0 is
/// measured from this run's own speed, as it is in identification.
pub fn at_approach_speed(model: &Model, u0: f64) -> Model {
    let mut m = model.clone();
    let ship = super::ShipSpec::of(&m).ok().flatten();
    let surge = ship.as_ref().map(|s| s.names.u.clone()).unwrap_or_else(|| "u".into());
    if let Some(mut ship) = ship {
        ship.u0 = u0;
        ship.store(&mut m);
    }
    let reading_surge: Vec<String> = m
        .spec()
        .parameters
        .iter()
        .filter(|(_, p)| {
            p.per_run.as_deref().is_some_and(|rule| rule.split(':').nth(1) == Some(surge.as_str()))
        })
        .map(|(name, _)| name.clone())
        .collect();
    for name in reading_surge {
        m.set_parameter(&name, u0);
    }
    m
}

impl Basin {
    /// Runs `manoeuvre` with `model` at approach speed `u0` for `duration` s after the
    /// approach, and records it; `seed` fixes the noise.
    pub fn record(
        &self,
        model: &Model,
        manoeuvre: &Manoeuvre,
        u0: f64,
        duration: f64,
        seed: u64,
        origin: &str,
    ) -> Result<Recording, ShipError> {
        let model = at_approach_speed(model, u0);
        let ship = Ship::new(&model, false)?;
        let sample = 1.0 / self.rate_hz;
        let settings = Settings { integrator: Integrator::Rk4, dt: self.dt, duration, sample };
        let mut run = ship.run(manoeuvre, &settings)?;
        if self.artefacts.midship_end_s > 0.0 {
            // the rudder back to the straight run's angle, the record going on
            let tr = &run.trajectory;
            let last = |c: &Vec<Vec<f64>>| c.iter().map(|s| s[s.len() - 1]).collect::<Vec<f64>>();
            let start = StraightRun { x: last(&tr.states), input: last(&tr.inputs), ..run.start.clone() };
            let back = Manoeuvre::parse(&format!("turning:{}", run.start.delta0_deg))?;
            let end = Settings { duration: self.artefacts.midship_end_s, ..settings };
            let more = ship.run_from(&back, &end, start)?.trajectory;
            let t_end = tr.time[tr.time.len() - 1];
            let tr = &mut run.trajectory;
            tr.time.extend(more.time[1..].iter().map(|t| t + t_end));
            for (a, b) in tr.states.iter_mut().zip(&more.states) {
                a.extend(&b[1..]);
            }
            for (a, b) in tr.inputs.iter_mut().zip(&more.inputs) {
                a.extend(&b[1..]);
            }
            for (a, b) in tr.derivatives.iter_mut().zip(&more.derivatives) {
                a.extend(&b[1..]);
            }
        }
        let tr = &run.trajectory;
        let r = &ship.roles;
        // the approach: steady straight running (ψ = 0) at the straight run's u0, v0, δ0
        let before = (self.approach_s * self.rate_hz).round() as usize;
        let mut time: Vec<f64> = (0..before).map(|i| i as f64 * sample).collect();
        let shift = before as f64 * sample;
        time.extend(tr.time.iter().map(|t| t + shift));
        let states: Vec<Vec<f64>> = (0..tr.states.len())
            .map(|i| {
                let (x, rate) = match i {
                    _ if i == r.x0 => (run.start.x[i], run.start.x[r.u]),
                    _ if i == r.y0 => (run.start.x[i], run.start.x[r.v]),
                    _ => (run.start.x[i], 0.0),
                };
                let mut c: Vec<f64> = (0..before).map(|k| x + rate * (k as f64 * sample - shift)).collect();
                c.extend(&tr.states[i]);
                c
            })
            .collect();
        let inputs: Vec<Vec<f64>> = (0..tr.inputs.len())
            .map(|i| {
                let mut c = vec![run.start.input[i]; before];
                c.extend(&tr.inputs[i]);
                c
            })
            .collect();
        // the track continues from where the approach ended: put the origin at its start
        let (ox, oy) = (states[r.x0][0], states[r.y0][0]);
        let mut truth = Frame::new(origin, "t", time)?;
        let mut measured = truth.clone();
        let mut gauss = Normal::new(seed);
        let n = &self.noise;
        let mut clean_states = Vec::with_capacity(tr.state_names.len());
        let mut noisy_states = Vec::with_capacity(tr.state_names.len());
        for (i, state) in states.iter().enumerate() {
            let (offset, sd) = match i {
                _ if i == r.u || i == r.v => (0.0, n.speed_m_s),
                _ if i == r.r => (0.0, n.yaw_rate_deg_s.to_radians()),
                _ if i == r.psi => (0.0, n.heading_deg.to_radians()),
                _ if i == r.x0 => (ox, n.position_m),
                _ if i == r.y0 => (oy, n.position_m),
                _ => (0.0, 0.0),
            };
            let clean: Vec<f64> = state.iter().map(|v| v - offset).collect();
            noisy_states.push(clean.iter().map(|v| v + sd * gauss.sample()).collect::<Vec<f64>>());
            clean_states.push(clean);
        }
        if let Some(half) = self.artefacts.velocities_from_track {
            let (u, v) = crate::data::velocities_from_track(
                truth.time(),
                &noisy_states[r.x0],
                &noisy_states[r.y0],
                &noisy_states[r.psi],
                half.max(1),
            );
            (noisy_states[r.u], noisy_states[r.v]) = (u, v);
        }
        for ((name, clean), noisy) in tr.state_names.iter().zip(clean_states).zip(noisy_states) {
            measured.push(name, noisy)?;
            truth.push(name, clean)?;
        }
        for (i, name) in tr.input_names.iter().enumerate() {
            let (offset, sd) = if i == r.rudder {
                (self.artefacts.rudder_offset_deg.to_radians(), n.rudder_deg.to_radians())
            } else {
                (0.0, 0.0)
            };
            measured.push(name, inputs[i].iter().map(|v| v + offset + sd * gauss.sample()).collect())?;
            truth.push(name, inputs[i].clone())?;
        }
        Ok(Recording { truth, measured, metrics: run.metrics, u0 })
    }

    /// Writes the measured run as the basin's data file: three header lines, then the
    /// columns of [`columns`] separated by spaces, angles in degrees.
    pub fn write(&self, rec: &Recording, model: &Model, path: &Path) -> std::io::Result<()> {
        let canon = |n: &str| model.vocabulary.canonical(n).unwrap_or_else(|| n.to_string());
        let mut text = format!(
            "# synthetic basin run {}\n# logged at {} Hz; approach {} s at u0 = {:.4} m/s\n# noise sd: speed {} m/s, yaw rate {} deg/s, heading {} deg, position {} m, rudder {} deg\n",
            rec.measured.origin(),
            self.rate_hz,
            self.approach_s,
            rec.u0,
            self.noise.speed_m_s,
            self.noise.yaw_rate_deg_s,
            self.noise.heading_deg,
            self.noise.position_m,
            self.noise.rudder_deg
        );
        let columns = columns(model);
        let header: Vec<&str> = columns.iter().map(|(_, c)| c.split(" [").next().unwrap_or(c)).collect();
        text += &header.join(" ");
        text.push('\n');
        let cols: Vec<(&[f64], bool)> = columns
            .iter()
            .map(|(var, spec)| {
                let c = if var == "t" { Some(rec.measured.time()) } else { rec.measured.column(&canon(var)) };
                (c.unwrap_or(&[]), spec.contains("[deg"))
            })
            .collect();
        for k in 0..rec.measured.len() {
            let row: Vec<String> = cols
                .iter()
                .map(|(c, deg)| {
                    let v = c.get(k).copied().unwrap_or(f64::NAN);
                    format!("{:.6}", if *deg { v.to_degrees() } else { v })
                })
                .collect();
            let _ = writeln!(text, "{}", row.join(" "));
        }
        std::fs::write(path, text)
    }
}

/// A dataset file (see [`crate::data::Dataset`]) listing basin files written by [`Basin::write`]
/// for a model with no inputs beyond the rudder.
pub fn dataset_toml(files: &[&str]) -> String {
    let columns: Vec<(String, String)> =
        COLUMNS.iter().map(|(v, c)| (v.to_string(), c.to_string())).collect();
    dataset_file(&columns, files)
}

/// A dataset file listing basin files written by [`Basin::write`] with `columns` (those of
/// [`columns`] for the model).
pub fn dataset_file(columns: &[(String, String)], files: &[&str]) -> String {
    let mut s = String::from("# runs from the synthetic basin\n[columns]\n");
    for (var, spec) in columns {
        let _ = writeln!(s, "\"{var}\" = \"{spec}\"");
    }
    for f in files {
        let _ = write!(s, "\n[[runs]]\nfile = \"{f}\"\ndelimiter = \"whitespace\"\nskip = 3\n");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_has_the_declared_size_and_the_approach_is_straight() {
        let model = crate::ship::default_model();
        let basin = Basin::default();
        let m = Manoeuvre::parse("zigzag:20/20").unwrap();
        let rec = basin.record(&model, &m, 1.95, 40.0, 1, "zz.dat").unwrap();
        let (t, mp) = (rec.truth.column("ψ").unwrap(), rec.measured.column("ψ").unwrap());
        let sd = (t.iter().zip(mp).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / t.len() as f64).sqrt();
        assert!((sd.to_degrees() / 0.1 - 1.0).abs() < 0.1, "heading noise {}°", sd.to_degrees());
        let u = rec.truth.column("u").unwrap();
        assert!((u[0] - 1.95).abs() < 1e-12 && (u[99] - 1.95).abs() < 1e-12);
        assert_eq!(rec.truth.len(), 100 + 801);
        assert!((rec.truth.time()[100] - 5.0).abs() < 1e-12);
        // Δu = u − u0 is zero on the approach at this run's speed: the surge balance holds
        let faster = at_approach_speed(&model, 1.95);
        assert_eq!(faster.parameter_values()["u0"], 1.95);
    }

    /// Overshoots read off a noisy record (rudder jittering at its extremes) are those of the
    /// noise-free run, up to the heading noise's maximum.
    #[test]
    fn metrics_read_off_a_noisy_record_match_the_truth() {
        let model = crate::ship::default_model();
        let m = Manoeuvre::parse("zigzag:25/10").unwrap();
        for seed in [11, 99] {
            let rec = Basin::default().record(&model, &m, 1.97, 100.0, seed, "zz.dat").unwrap();
            let o = |f: &Frame| {
                let c = |n: &str| f.column(n).unwrap();
                crate::ship::observed::observe(f.time(), c("ψ"), c("δ"), c("x0"), c("y0"))
            };
            let Metrics::ZigZag(z) = &rec.metrics else { panic!("a zigzag") };
            let (truth, measured) = (o(&rec.truth), o(&rec.measured));
            for (a, b) in [
                (z.first_overshoot_deg, measured.first_overshoot_deg),
                (z.second_overshoot_deg, measured.second_overshoot_deg),
                (z.first_overshoot_deg, truth.first_overshoot_deg),
            ] {
                let (a, b) = (a.unwrap(), b.unwrap());
                assert!((a - b).abs() < 0.4, "seed {seed}: {a}° vs {b}°");
            }
        }
    }

    /// The artefacts of real records: velocities from the track equal the true ones where the
    /// track is exact, the rudder indicator reads its offset, the record ends at midship.
    #[test]
    fn artefacts_are_recorded_as_declared() {
        let model = crate::ship::default_model();
        let basin = Basin {
            noise: Noise {
                speed_m_s: 0.0,
                yaw_rate_deg_s: 0.0,
                heading_deg: 0.0,
                position_m: 0.0,
                rudder_deg: 0.0,
            },
            artefacts: Artefacts {
                rudder_offset_deg: 0.5,
                velocities_from_track: Some(2),
                midship_end_s: 6.0,
            },
            ..Basin::default()
        };
        let rec = basin
            .record(&model, &Manoeuvre::parse("zigzag:20/20").unwrap(), 2.01, 40.0, 1, "zz.dat")
            .unwrap();
        // 5 s of approach, 40 s of zigzag, 6 s back at midship, at 20 Hz
        assert_eq!(rec.truth.len(), 100 + 801 + 120);
        let (d, dm) = (rec.truth.column("δ").unwrap(), rec.measured.column("δ").unwrap());
        assert!(d.iter().zip(dm).all(|(a, b)| (b - a - 0.5f64.to_radians()).abs() < 1e-12));
        // the straight run's rudder (0 for this symmetric-at-rest ship up to its asymmetry)
        // is reached at the rudder rate and held to the end
        let delta0 = d[0];
        assert!((d[d.len() - 1] - delta0).abs() < 1e-12 && (d[d.len() - 40] - delta0).abs() < 1e-12);
        // central differences over ±0.1 s of the exact track: u and v to their truncation error
        for name in ["u", "v"] {
            let (a, b) = (rec.truth.column(name).unwrap(), rec.measured.column(name).unwrap());
            let worst = a[2..a.len() - 2].iter().zip(&b[2..]).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            assert!(worst < 2e-3, "{name}: {worst} m/s");
        }
    }

    #[test]
    fn velocities_from_a_straight_track_are_exact() {
        let t: Vec<f64> = (0..50).map(|i| i as f64 * 0.05).collect();
        let psi = vec![0.3; t.len()];
        // u = 2, v = −0.5 in the body frame, turned by ψ into the earth frame
        let (xd, yd) = (2.0 * 0.3f64.cos() + 0.5 * 0.3f64.sin(), 2.0 * 0.3f64.sin() - 0.5 * 0.3f64.cos());
        let x: Vec<f64> = t.iter().map(|t| xd * t).collect();
        let y: Vec<f64> = t.iter().map(|t| yd * t).collect();
        let (u, v) = crate::data::velocities_from_track(&t, &x, &y, &psi, 2);
        assert!(u.iter().all(|u| (u - 2.0).abs() < 1e-12) && v.iter().all(|v| (v + 0.5).abs() < 1e-12));
    }
}
