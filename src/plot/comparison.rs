//! Measured runs beside their simulations: one figure per run, a row per measured state with
//! the model's simulation (and a second one, e.g. with a diagnosed effect) on the left and the
//! residual on the right, each in the model's unit (angles in degrees).

use super::{labelled, Figure, Panel, Series};
use crate::data::Frame;
use crate::diagnose::Diagnosis;
use crate::model::dimension::shown;
use crate::model::Model;
use crate::sim::Trajectory;
use crate::uncertainty::band;

/// Figures of a diagnosis, one per run: each measured state against the simulation before
/// (and after) the winning effect, and the residual.
pub fn diagnosis_figures(model: &Model, d: &Diagnosis, runs: &[Frame]) -> Vec<(String, Figure)> {
    comparison_figures(model, runs, &d.before, &d.after, &[], "diagnose")
}

/// One figure per run: every measured state with the model's simulation (and a second
/// simulation, if given; and the pointwise 5-95 % band of Monte-Carlo `draws`, the
/// simulations of every run with each drawn model), and their residuals, side by side.
pub fn comparison_figures(
    model: &Model,
    runs: &[Frame],
    sims: &[Trajectory],
    other: &[Trajectory],
    draws: &[&[Trajectory]],
    title: &str,
) -> Vec<(String, Figure)> {
    runs.iter()
        .enumerate()
        .filter_map(|(k, f)| {
            let before = sims.get(k)?;
            let t = f.time();
            let mut panels = Vec::new();
            for (i, name) in before.state_names.iter().enumerate() {
                let Some(meas) = f.column(name) else { continue };
                let (factor, shown) = shown(model.unit(name));
                let n = meas.len().min(before.states[i].len()).min(t.len());
                let time = t[..n].to_vec();
                let scaled = |v: &[f64]| v[..n].iter().map(|x| x * factor).collect::<Vec<f64>>();
                let gap = |sim: &[f64]| (0..n).map(|j| (sim[j] - meas[j]) * factor).collect::<Vec<f64>>();
                let mut series = vec![
                    Series::line("measured", time.clone(), scaled(meas)),
                    Series::dashed("model", time.clone(), scaled(&before.states[i])),
                ];
                // a residual in the colour of its simulation
                let mut residual =
                    vec![Series::line("model − measured", time.clone(), gap(&before.states[i])).colored(1)];
                if let Some(after) = other.get(k) {
                    series.push(Series::dashed("with the effect", time.clone(), scaled(&after.states[i])));
                    residual.push(
                        Series::line("with the effect − measured", time.clone(), gap(&after.states[i]))
                            .colored(2),
                    );
                }
                let signals: Vec<Vec<f64>> =
                    draws.iter().filter_map(|d| d.get(k)).map(|s| s.states[i].clone()).collect();
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
            let mut fig = Figure::new(&format!("{title}: {}", f.origin()), panels);
            fig.columns = 2;
            fig.shared_legend = true;
            fig.width = 1100;
            fig.panel_height = 200;
            Some((f.origin().to_string(), fig))
        })
        .collect()
}
