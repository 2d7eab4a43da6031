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
