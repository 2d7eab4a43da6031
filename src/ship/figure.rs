//! Figures in the paper's layout: δ and ψ over time, U/U0, β and r, and the track in ship
//! lengths; the spiral test's steady yaw rate against the rudder angle.

use crate::plot::{Figure, Panel, Series};
use crate::sim::Trajectory;

use super::Ship;

const RUDDER_HEADING: &str = "rudder δ and heading ψ";
const RUDDER: &str = "rudder δ";
const HEADING: &str = "heading ψ";
const SPEED: &str = "speed U/U0";
const DRIFT: &str = "drift angle β and yaw rate r";
const DRIFT_ONLY: &str = "drift angle β";
const YAW: &str = "yaw rate r";
const TRACK: &str = "track";

/// One curve set per run: (legend, trajectory). As in the paper, δ and ψ share a panel over
/// time, β and r another, U/U0 a third, and the track (in ship lengths, equal scale) the last;
/// where the heading runs far beyond the rudder angle (a turning circle's ψ reaches 1000°
/// and more, which would flatten δ to a line) δ and ψ get a panel each. Several runs (a true
/// model and identified ones) get a panel per quantity instead, each run in one colour and
/// style in every panel, named once in a legend under the title.
pub fn manoeuvre_figure(ship: &Ship, title: &str, runs: &[(&str, &Trajectory)], track: bool) -> Figure {
    let r = &ship.roles;
    let deg = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<f64>>();
    let span = |v: &[f64]| {
        let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)));
        if hi >= lo {
            hi - lo
        } else {
            0.0
        }
    };
    let (rudder_span, heading_span) = runs.iter().fold((0f64, 0f64), |(a, b), (_, t)| {
        (a.max(span(&t.inputs[r.rudder])), b.max(span(&t.states[r.psi])))
    });
    let several = runs.len() > 1;
    let apart = several || heading_span > 4.0 * rudder_span.max(1f64.to_radians());
    let panel = |title: &str, y_label: &str| Panel {
        title: title.into(),
        x_label: "t [s]".into(),
        y_label: y_label.into(),
        ..Panel::default()
    };
    let mut rudder =
        panel(if apart { RUDDER } else { RUDDER_HEADING }, if apart { "δ [°]" } else { "δ, ψ [°]" });
    let mut heading = panel(HEADING, "ψ [°]");
    let mut speed = panel(SPEED, "U/U0 [-]");
    let mut drift =
        panel(if several { DRIFT_ONLY } else { DRIFT }, if several { "β [°]" } else { "β [°], r [°/s]" });
    let mut yaw = panel(YAW, "r [°/s]");
    let lpp = ship.spec.lpp;
    let mut path = Panel {
        title: format!("{TRACK} (L = {lpp} m)"),
        x_label: "y0/L [-] (starboard)".into(),
        y_label: "x0/L [-] (initial course)".into(),
        equal_axes: true,
        unit_ticks: true,
        height: Some(460),
        ..Panel::default()
    };
    for (k, (name, t)) in runs.iter().enumerate() {
        // one run: the quantities are the series; several: the runs are, by colour
        let mk = |label: &str, y: Vec<f64>| {
            let n = if several { name.to_string() } else { label.to_string() };
            let s = if k == 0 {
                Series::line(&n, t.time.clone(), y)
            } else {
                Series::dashed(&n, t.time.clone(), y)
            };
            if several {
                s.colored(k)
            } else {
                s
            }
        };
        let (speed_v, drift_v) = ship.speed_and_drift(t);
        rudder.series.push(mk("δ", deg(&t.inputs[r.rudder])));
        let psi = mk("ψ", deg(&t.states[r.psi]));
        if apart {
            heading.series.push(psi);
        } else {
            rudder.series.push(psi);
        }
        speed.series.push(mk("U/U0", speed_v.iter().map(|u| u / ship.spec.u0).collect()));
        drift.series.push(mk("β", deg(&drift_v)));
        let yaw_rate = mk("r", deg(&t.states[r.r]));
        if several {
            yaw.series.push(yaw_rate);
        } else {
            drift.series.push(yaw_rate);
        }
        let (y, x) = track_in_lengths(ship, t);
        let line = if k == 0 { Series::line(name, y, x) } else { Series::dashed(name, y, x) };
        path.series.push(line.colored(k));
    }
    let mut panels = vec![rudder];
    if apart {
        panels.push(heading);
    }
    panels.extend([speed, drift]);
    if several {
        panels.push(yaw);
    }
    if track {
        panels.push(path);
    }
    let mut figure = Figure::new(title, panels);
    figure.shared_legend = several;
    figure
}

/// A run's track in ship lengths: (y0/L, x0/L), across and up as the figures draw it.
fn track_in_lengths(ship: &Ship, t: &Trajectory) -> (Vec<f64>, Vec<f64>) {
    let lpp = ship.spec.lpp;
    let r = &ship.roles;
    let in_lengths = |v: &[f64]| v.iter().map(|x| x / lpp).collect();
    (in_lengths(&t.states[r.y0]), in_lengths(&t.states[r.x0]))
}

/// Adds Monte-Carlo prediction bands (pointwise 5-95 %) of ψ, U/U0, β and r to a figure made
/// by [`manoeuvre_figure`], and up to ten of the drawn tracks.
pub fn add_bands(fig: &mut Figure, ship: &Ship, draws: &[&Trajectory]) {
    let Some(first) = draws.first() else { return };
    let r = &ship.roles;
    let time = draws.iter().max_by_key(|t| t.time.len()).map_or(first.time.clone(), |t| t.time.clone());
    let deg = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<f64>>();
    let signal = |f: &dyn Fn(usize) -> Vec<f64>| {
        crate::uncertainty::band(&(0..draws.len()).map(f).collect::<Vec<_>>())
    };
    let series = |name: &str, (lo, hi): (Vec<f64>, Vec<f64>)| Series::band(name, time.clone(), lo, hi);
    let label = format!("90 % band ({} draws)", draws.len());
    // U and β of each draw, once
    let speed_drift: Vec<(Vec<f64>, Vec<f64>)> = draws.iter().map(|t| ship.speed_and_drift(t)).collect();
    let bands: [(&[&str], Series); 4] = [
        (
            &[HEADING, RUDDER_HEADING],
            series(&format!("ψ {label}"), signal(&|k| deg(&draws[k].states[r.psi]))),
        ),
        (
            &[SPEED],
            series(
                &format!("U/U0 {label}"),
                signal(&|k| speed_drift[k].0.iter().map(|u| u / ship.spec.u0).collect()),
            ),
        ),
        (&[DRIFT], series(&format!("β {label}"), signal(&|k| deg(&speed_drift[k].1)))),
        (&[DRIFT], series(&format!("r {label}"), signal(&|k| deg(&draws[k].states[r.r])))),
    ];
    for (titles, band) in bands {
        if let Some(p) = fig.panels.iter_mut().find(|p| titles.contains(&p.title.as_str())) {
            p.series.push(band);
        }
    }
    if let Some(track) = fig.panels.iter_mut().find(|p| p.title.starts_with(TRACK)) {
        for (k, t) in draws.iter().take(10).enumerate() {
            let name = if k == 0 { "drawn models".to_string() } else { String::new() };
            // one colour for every drawn model, the one its legend entry shows; under the
            // nominal track, which stays in sight
            track.series.insert(k, {
                let (y, x) = track_in_lengths(ship, t);
                Series::dashed(&name, y, x).colored(2)
            });
        }
    }
}

/// The spiral test: steady yaw rate against rudder angle, the branch from +δ down and the one
/// back from −δ, from the metrics' `points` (`rudder_deg`, `yaw_rate_deg_s`, `branch`).
pub fn spiral_figure(title: &str, metrics: &serde_json::Value) -> Figure {
    let points = metrics.get("points").and_then(|p| p.as_array()).cloned().unwrap_or_default();
    let branch = |b: &str| -> (Vec<f64>, Vec<f64>) {
        points
            .iter()
            .filter(|p| p.get("branch").and_then(|v| v.as_str()) == Some(b))
            .filter_map(|p| Some((p.get("rudder_deg")?.as_f64()?, p.get("yaw_rate_deg_s")?.as_f64()?)))
            .unzip()
    };
    let (dx, dy) = branch("down");
    let (ux, uy) = branch("up");
    Figure::new(
        title,
        vec![Panel {
            title: "spiral: steady yaw rate against rudder angle".into(),
            x_label: "δ [°]".into(),
            y_label: "r [°/s]".into(),
            series: vec![Series::line("from +δ", dx, dy), Series::points("back from −δ", ux, uy)],
            ..Panel::default()
        }],
    )
}
