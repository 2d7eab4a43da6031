//! Tables 1-6: each manoeuvre regressed alone, their "Mittelwert", the regression on all
//! five together ("Komb. Daten"), the true value and the paper's printed numbers beside them.

use serde::Serialize;

use super::data::Alternative;
use crate::data::{CentralDifference, Frame};
use crate::identify::{equation_design, fit_equation_design, Fit, IdentifyError, Target};
use crate::model::Model;
use crate::term::Vocabulary;

/// The Mittelwert rule (the paper: "only where the term was found in all or nearly all runs
/// with the same sign and magnitude"): at least this many of the five runs ...
pub const MEAN_MIN_RUNS: usize = 4;
/// ... all of one sign, the largest magnitude at most this many times the smallest.
pub const MEAN_MAX_RATIO: f64 = 10.0;

/// A printed row of one of the paper's tables.
#[derive(Clone, Debug, Default, Serialize)]
pub struct PaperRow {
    /// Coefficients per manoeuvre (15/10, 20/10, 25/10, 30/10, 20/20).
    pub runs: [Option<f64>; 5],
    /// Printed Mittelwert.
    pub mittelwert: Option<f64>,
    /// Printed Komb. Daten.
    pub komb: Option<f64>,
    /// Printed true value.
    pub truth: Option<f64>,
    /// Confidence of the OCR row.
    pub confidence: String,
}

/// The paper's Table N as (canonical term, row), from the embedded CSV.
pub fn paper_table(csv_text: &str, vocab: &Vocabulary) -> Vec<(String, PaperRow)> {
    let num = |s: &str| s.trim().parse::<f64>().ok();
    csv_text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .filter_map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            if f.len() < 10 {
                return None;
            }
            let term = vocab.parse(f[0]).ok()?.to_string();
            Some((
                term,
                PaperRow {
                    runs: [num(f[1]), num(f[2]), num(f[3]), num(f[4]), num(f[5])],
                    mittelwert: num(f[6]),
                    komb: num(f[7]),
                    truth: num(f[8]),
                    confidence: f[9].to_string(),
                },
            ))
        })
        .collect()
}

/// The embedded paper tables: (u̇, v̇, ṙ) for exact data and for alternative 5.
pub fn paper_tables(alt5: bool) -> [&'static str; 3] {
    if alt5 {
        [
            include_str!("../../../models/oltmann1973-tables/table4_udot.csv"),
            include_str!("../../../models/oltmann1973-tables/table5_vdot.csv"),
            include_str!("../../../models/oltmann1973-tables/table6_rdot.csv"),
        ]
    } else {
        [
            include_str!("../../../models/oltmann1973-tables/table1_udot.csv"),
            include_str!("../../../models/oltmann1973-tables/table2_vdot.csv"),
            include_str!("../../../models/oltmann1973-tables/table3_rdot.csv"),
        ]
    }
}

/// One row of our table.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Canonical term.
    pub term: String,
    /// (step of entry, coefficient) per manoeuvre, at each regression's chosen step.
    pub runs: Vec<Option<(usize, f64)>>,
    /// Our Mittelwert (see [`MEAN_MIN_RUNS`], [`MEAN_MAX_RATIO`]).
    pub mittelwert: Option<f64>,
    /// (step, coefficient) of the combined regression.
    pub komb: Option<(usize, f64)>,
    /// The true coefficient of the default model.
    pub truth: f64,
    /// What the paper printed for this term, if it has a row.
    pub paper: Option<PaperRow>,
}

/// One equation's regressions on one data alternative.
#[derive(Clone, Debug, Serialize)]
pub struct EquationTable {
    /// `u_dot`, `v_dot`, `r_dot`.
    pub equation: String,
    /// The data alternative.
    pub alternative: Alternative,
    /// Each manoeuvre alone, in [`MANOEUVRES`](super::data::MANOEUVRES) order.
    pub runs: Vec<Fit>,
    /// All five together.
    pub komb: Fit,
    /// The table.
    pub rows: Vec<Row>,
}

/// The Mittelwert of five optional coefficients by the stated rule.
pub fn mittelwert(values: &[Option<f64>]) -> Option<f64> {
    let v: Vec<f64> = values.iter().flatten().copied().collect();
    if v.len() < MEAN_MIN_RUNS {
        return None;
    }
    let same_sign = v.iter().all(|x| *x > 0.0) || v.iter().all(|x| *x < 0.0);
    let (lo, hi) = v.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), x| (lo.min(x.abs()), hi.max(x.abs())));
    (same_sign && hi <= MEAN_MAX_RATIO * lo).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

fn entry(fit: &Fit, term: &str) -> Option<(usize, f64)> {
    let t = fit.selection.terms.iter().find(|t| t.term == term)?;
    let step = fit.selection.steps.iter().find(|s| s.term == term).map_or(0, |s| s.step);
    Some((step, t.coefficient))
}

/// Regresses one equation on each run and on all runs, and lays out the table.
pub fn equation_table(
    model: &Model,
    equation: &str,
    frames: &[Frame],
    alternative: Alternative,
    paper: &[(String, PaperRow)],
) -> Result<EquationTable, IdentifyError> {
    let eq =
        model.equation(equation).ok_or_else(|| IdentifyError::Setup(format!("no equation {equation}")))?;
    let target = if alternative.differentiated() {
        Target::Derivative(eq.state.clone())
    } else {
        Target::Column(format!("{}_dot", eq.state))
    };
    // six fits of one equation (each run, then all together): its terms compiled once
    let design = equation_design(model, equation)?;
    let fit = |f: &[Frame]| {
        fit_equation_design(model, equation, Some(&design), f, &CentralDifference, true, Some(target.clone()))
    };
    let runs = frames.iter().map(|f| fit(std::slice::from_ref(f))).collect::<Result<Vec<_>, _>>()?;
    let komb = fit(frames)?;
    // rows: every term selected anywhere, every term with a true value, every printed row
    let mut terms: Vec<String> = Vec::new();
    let mut add = |t: String| {
        if !terms.contains(&t) {
            terms.push(t);
        }
    };
    for f in runs.iter().chain(std::iter::once(&komb)) {
        f.selection.terms.iter().for_each(|t| add(t.term.clone()));
    }
    eq.coefficients.iter().filter(|(_, c, _)| *c != 0.0).for_each(|(t, _, _)| add(t.to_string()));
    paper.iter().for_each(|(t, _)| add(t.clone()));
    let rows = terms
        .into_iter()
        .map(|term| {
            let per: Vec<Option<(usize, f64)>> = runs.iter().map(|f| entry(f, &term)).collect();
            let truth = eq.coefficients.iter().find(|(t, _, _)| t.to_string() == term).map_or(0.0, |c| c.1);
            Row {
                mittelwert: mittelwert(&per.iter().map(|e| e.map(|x| x.1)).collect::<Vec<_>>()),
                komb: entry(&komb, &term),
                runs: per,
                truth,
                paper: paper.iter().find(|(t, _)| *t == term).map(|(_, r)| r.clone()),
                term,
            }
        })
        .collect();
    Ok(EquationTable { equation: equation.into(), alternative, runs, komb, rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mean_rule_matches_the_papers_clear_cases() {
        // Table 1 r^2*du/u: four values of one sign → printed −0.7857
        let m = mittelwert(&[Some(-0.7917), None, Some(-1.0310), Some(-0.8690), Some(-0.4512)]).unwrap();
        assert!((m - -0.7857).abs() < 1e-4);
        // Table 1 r^2: signs disagree → no value
        assert!(
            mittelwert(&[Some(0.2906), Some(-0.0463), Some(-0.2820), Some(-0.7333), Some(0.0054)]).is_none()
        );
        // Table 3 r*du: one sign but magnitudes 0.007 … 0.76 → no value
        assert!(mittelwert(&[Some(0.2297), Some(0.7578), Some(0.0099), Some(0.0073), Some(0.1143)]).is_none());
        // Table 3 u*r*delta^2: only 3 runs → no value
        assert!(mittelwert(&[Some(-0.0746), Some(-0.1897), None, Some(-0.0137), None]).is_none());
    }
}
