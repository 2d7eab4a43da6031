//! Measured runs beside their simulations: one figure per run, every measured state with
//! the model's simulation (and a second one, e.g. with a diagnosed effect), and the residuals.

use super::{Figure, Panel, Series};
use crate::data::Frame;
use crate::diagnose::Diagnosis;
use crate::sim::Trajectory;

/// Figures of a diagnosis, one per run: each measured state against the simulation before
/// (and after) the winning effect, and the residual.
pub fn diagnosis_figures(d: &Diagnosis, runs: &[Frame]) -> Vec<(String, Figure)> {
    comparison_figures(runs, &d.before, &d.after, "diagnose")
}

/// One figure per run: every measured state with the model's simulation (and a second
/// simulation, if given), and their residuals.
pub fn comparison_figures(
    runs: &[Frame],
    model: &[Trajectory],
    other: &[Trajectory],
    title: &str,
) -> Vec<(String, Figure)> {
    runs.iter()
        .enumerate()
        .filter_map(|(k, f)| {
            let before = model.get(k)?;
            let mut panels = Vec::new();
            for (i, name) in before.state_names.iter().enumerate() {
                let Some(meas) = f.column(name) else { continue };
                let t = f.time().to_vec();
                let n = meas.len().min(before.states[i].len());
                let mut series = vec![
                    Series::line("measured", t[..n].to_vec(), meas[..n].to_vec()),
                    Series::dashed("model", t[..n].to_vec(), before.states[i][..n].to_vec()),
                ];
                let mut residual = vec![Series::line(
                    "model − measured",
                    t[..n].to_vec(),
                    (0..n).map(|j| before.states[i][j] - meas[j]).collect(),
                )];
                if let Some(after) = other.get(k) {
                    series.push(Series::dashed(
                        "with the effect",
                        t[..n].to_vec(),
                        after.states[i][..n].to_vec(),
                    ));
                    residual.push(Series::line(
                        "with the effect − measured",
                        t[..n].to_vec(),
                        (0..n).map(|j| after.states[i][j] - meas[j]).collect(),
                    ));
                }
                panels.push(Panel {
                    title: name.clone(),
                    x_label: "t".into(),
                    y_label: name.clone(),
                    series,
                    ..Panel::default()
                });
                panels.push(Panel {
                    title: format!("{name}: residual"),
                    x_label: "t".into(),
                    y_label: "Δ".into(),
                    series: residual,
                    ..Panel::default()
                });
            }
            let mut fig = Figure::new(&format!("{title}: {}", f.origin()), panels);
            fig.panel_height = 170;
            Some((f.origin().to_string(), fig))
        })
        .collect()
}
