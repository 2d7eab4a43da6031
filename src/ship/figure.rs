//! Figures in the paper's layout: δ, ψ and U/U0 over time; β and r over time; the track.

use crate::plot::{Figure, Panel, Series};
use crate::sim::Trajectory;

use super::Ship;

/// One curve set per run: (legend, trajectory).
pub fn manoeuvre_figure(ship: &Ship, title: &str, runs: &[(&str, &Trajectory)], track: bool) -> Figure {
    let r = &ship.roles;
    let deg = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<f64>>();
    let mut top = Panel {
        title: "rudder δ and heading ψ".into(),
        x_label: "t [s]".into(),
        y_label: "[°]".into(),
        ..Panel::default()
    };
    let mut speed = Panel {
        title: "speed U/U0".into(),
        x_label: "t [s]".into(),
        y_label: "U/U0 [-]".into(),
        ..Panel::default()
    };
    let mut drift = Panel {
        title: "drift angle β and yaw rate r".into(),
        x_label: "t [s]".into(),
        y_label: "β [°], r [°/s]".into(),
        ..Panel::default()
    };
    let mut path = Panel {
        title: "track".into(),
        x_label: "y0 [m] (starboard)".into(),
        y_label: "x0 [m] (initial course)".into(),
        equal_axes: true,
        ..Panel::default()
    };
    for (k, (name, t)) in runs.iter().enumerate() {
        let mk = |label: &str, y: Vec<f64>| {
            let n = if runs.len() > 1 { format!("{label} {name}") } else { label.to_string() };
            if k == 0 {
                Series::line(&n, t.time.clone(), y)
            } else {
                Series::dashed(&n, t.time.clone(), y)
            }
        };
        let (speed_v, drift_v) = ship.speed_and_drift(t);
        top.series.push(mk("δ", deg(&t.inputs[r.rudder])));
        top.series.push(mk("ψ", deg(&t.states[r.psi])));
        speed.series.push(mk("U/U0", speed_v.iter().map(|u| u / ship.spec.u0).collect()));
        drift.series.push(mk("β", deg(&drift_v)));
        drift.series.push(mk("r", deg(&t.states[r.r])));
        path.series.push(Series::line(name, t.states[r.y0].clone(), t.states[r.x0].clone()));
    }
    let mut panels = vec![top, speed, drift];
    if track {
        panels.push(path);
    }
    Figure::new(title, panels)
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
    let bands: [(usize, Series); 4] = [
        (0, series(&format!("ψ {label}"), signal(&|k| deg(&draws[k].states[r.psi])))),
        (
            1,
            series(
                &format!("U/U0 {label}"),
                signal(&|k| speed_drift[k].0.iter().map(|u| u / ship.spec.u0).collect()),
            ),
        ),
        (2, series(&format!("β {label}"), signal(&|k| deg(&speed_drift[k].1)))),
        (2, series(&format!("r {label}"), signal(&|k| deg(&draws[k].states[r.r])))),
    ];
    for (panel, band) in bands {
        if let Some(p) = fig.panels.get_mut(panel) {
            p.series.push(band);
        }
    }
    if let Some(track) = fig.panels.get_mut(3) {
        for (k, t) in draws.iter().take(10).enumerate() {
            let name = if k == 0 { "drawn models".to_string() } else { String::new() };
            track.series.push(Series::dashed(&name, t.states[r.y0].clone(), t.states[r.x0].clone()));
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
