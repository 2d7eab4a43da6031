//! Measured runs beside their simulations: one figure per run, a row per measured state with
//! the model's simulation (and a second one, e.g. with a diagnosed effect) on the left and the
//! residual on the right, each in the model's unit (angles in degrees); positions in a plane
//! (a ship's track) as one track at equal scale, with the distance between them over time.

use super::{labelled, Figure, Panel, Series};
use crate::data::Frame;
use crate::diagnose::Diagnosis;
use crate::model::dimension::shown;
use crate::model::Model;
use crate::sim::{Plane, Trajectory};
use crate::uncertainty::band;

/// Figures of a diagnosis, one per run: each measured state against the simulation before
/// (and after) the winning effect, and the residual.
pub fn diagnosis_figures(
    model: &Model,
    d: &Diagnosis,
    runs: &[Frame],
    plane: Option<&Plane>,
) -> Vec<(String, Figure)> {
    comparison_figures(model, runs, (&d.before, &d.after), &[], ("diagnose", LABELS), plane)
}

/// The two simulations' names in a figure where the second one adds an effect to the model.
pub const LABELS: [&str; 2] = ["model", "with the effect"];

/// One figure per run: every measured state with the model's simulation (and a second
/// simulation, if given; and the pointwise 5-95 % band of Monte-Carlo `draws`, the
/// simulations of every run with each drawn model), and their residuals, side by side; the
/// figures titled `title` and the two simulations named by `labels`. The states of a `plane`
/// are drawn as one track instead, beside the distance between the tracks.
pub fn comparison_figures(
    model: &Model,
    runs: &[Frame],
    (sims, other): (&[Trajectory], &[Trajectory]),
    draws: &[&[Trajectory]],
    (title, labels): (&str, [&str; 2]),
    plane: Option<&Plane>,
) -> Vec<(String, Figure)> {
    runs.iter()
        .enumerate()
        .filter_map(|(k, f)| {
            let before = sims.get(k)?;
            let t = f.time();
            let mut panels = Vec::new();
            let in_plane = |name: &str| plane.is_some_and(|p| p.across.0 == name || p.up.0 == name);
            // the states, then what was observed along the run (derived variables compared
            // with their records)
            let names = before.state_names.iter().chain(before.observed.iter().map(|(n, _)| n));
            for name in names {
                let (Some(meas), Some(simulated)) = (f.column(name), before.column(name)) else { continue };
                if in_plane(name) {
                    continue;
                }
                let (factor, shown) = shown(model.unit(name));
                let n = meas.len().min(simulated.len()).min(t.len());
                let time = t[..n].to_vec();
                let scaled = |v: &[f64]| v[..n].iter().map(|x| x * factor).collect::<Vec<f64>>();
                let gap = |sim: &[f64]| (0..n).map(|j| (sim[j] - meas[j]) * factor).collect::<Vec<f64>>();
                let mut series = vec![
                    Series::line("measured", time.clone(), scaled(meas)),
                    Series::dashed(labels[0], time.clone(), scaled(simulated)),
                ];
                // a residual in the colour of its simulation
                let mut residual =
                    vec![Series::line(&format!("{} − measured", labels[0]), time.clone(), gap(simulated))
                        .colored(1)];
                if let Some(after) = other.get(k).and_then(|o| o.column(name)).filter(|c| c.len() >= n) {
                    series.push(Series::dashed(labels[1], time.clone(), scaled(after)));
                    // dashed over the first residual, which stays in sight under it
                    residual.push(
                        Series::dashed(&format!("{} − measured", labels[1]), time.clone(), gap(after))
                            .colored(2),
                    );
                }
                let signals: Vec<Vec<f64>> =
                    draws.iter().filter_map(|d| d.get(k)?.column(name)).map(|c| c.to_vec()).collect();
                if !signals.is_empty() {
                    let (lo, hi) = band(&signals);
                    let m = n.min(lo.len());
                    series.push(Series::band(
                        &format!("model 90 % band ({} draws)", signals.len()),
                        time[..m].to_vec(),
                        lo[..m].iter().map(|x| x * factor).collect(),
                        hi[..m].iter().map(|x| x * factor).collect(),
                    ));
                }
                panels.push(Panel {
                    title: format!("{name}: measured and model"),
                    x_label: "t [s]".into(),
                    y_label: labelled(name, &shown),
                    series,
                    ..Panel::default()
                });
                panels.push(Panel {
                    title: format!("{name}: residual"),
                    x_label: "t [s]".into(),
                    y_label: labelled(&format!("Δ{name}"), &shown),
                    series: residual,
                    ..Panel::default()
                });
            }
            if let Some(track) = plane.and_then(|p| track_panels(p, f, before, other.get(k), labels)) {
                panels.extend(track);
            }
            let mut fig = Figure::new(&format!("{title}: {}", f.origin()), panels);
            fig.columns = 2;
            fig.shared_legend = true;
            fig.width = 1100;
            fig.panel_height = 200;
            Some((f.origin().to_string(), fig))
        })
        .collect()
}

/// The measured track and the simulated ones at equal scale, and the distance between them
/// over time; `None` where the run does not hold both positions.
fn track_panels(
    plane: &Plane,
    f: &Frame,
    sim: &Trajectory,
    other: Option<&Trajectory>,
    labels: [&str; 2],
) -> Option<[Panel; 2]> {
    let (across, up) = (f.column(&plane.across.0)?, f.column(&plane.up.0)?);
    let l = plane.length;
    let n = across.len().min(up.len()).min(f.time().len());
    let scaled = |v: &[f64], m: usize| v[..m].iter().map(|x| x / l).collect::<Vec<f64>>();
    let mut track = vec![Series::line("measured", scaled(across, n), scaled(up, n))];
    let time = f.time()[..n].to_vec();
    let mut distance = Vec::new();
    for (k, (label, t)) in [(labels[0], Some(sim)), (labels[1], other)].into_iter().enumerate() {
        let Some(t) = t else { continue };
        let (x, y) = (state(t, &plane.across.0)?, state(t, &plane.up.0)?);
        let m = n.min(x.len()).min(y.len());
        track.push(Series::dashed(label, scaled(x, m), scaled(y, m)).colored(k + 1));
        let gap = (0..m).map(|j| (x[j] - across[j]).hypot(y[j] - up[j]) / l).collect();
        let name = format!("{label} − measured");
        let s = if k == 0 {
            Series::line(&name, time[..m].to_vec(), gap)
        } else {
            Series::dashed(&name, time[..m].to_vec(), gap)
        };
        distance.push(s.colored(k + 1));
    }
    Some([
        Panel {
            title: plane.title.clone(),
            x_label: plane.across.1.clone(),
            y_label: plane.up.1.clone(),
            series: track,
            equal_axes: true,
            unit_ticks: true,
            height: Some(420),
            ..Panel::default()
        },
        Panel {
            title: "distance between the tracks".into(),
            x_label: "t [s]".into(),
            y_label: "distance/L [-]".into(),
            series: distance,
            ..Panel::default()
        },
    ])
}

/// A simulated state by name.
fn state<'a>(t: &'a Trajectory, name: &str) -> Option<&'a [f64]> {
    t.state_names.iter().position(|n| n == name).map(|i| t.states[i].as_slice())
}
