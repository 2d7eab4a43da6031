//! How a fit reads: the step table, the equation and the coefficient table as text, and the
//! same numbers as a plain serde record ([`FitReport`]) for JSON. The CLI, the examples and a
//! binding print fits with these, so every fit reads the same.

use serde::Serialize;

use super::Fit;
use crate::select::Stop;

/// Significant-figure formatting that stays fixed-point where a reader expects it.
pub fn num(x: f64) -> String {
    if x == 0.0 || (1e-4..1e6).contains(&x.abs()) {
        let digits = (5 - x.abs().log10().floor() as i32).clamp(0, 9) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.4e}")
    }
}

pub use crate::output::sig;

/// One step of the table, as reported.
#[derive(Clone, Debug, Serialize)]
pub struct StepReport {
    /// 1-based step number.
    pub step: usize,
    /// The term entered (or removed).
    pub term: String,
    /// Entered because forced.
    pub forced: bool,
    /// Standard error of estimate s (A7).
    pub standard_error: f64,
    /// F-value (A8); `null` in JSON at an exact fit.
    pub f: f64,
    /// Cumulative share R² (A5).
    pub r2: f64,
    /// Its share of the total sum of squares (A3).
    pub proportion: f64,
}

/// A chosen term, as reported.
#[derive(Clone, Debug, Serialize)]
pub struct TermReport {
    /// The term's canonical text.
    pub term: String,
    /// The coefficient.
    pub coefficient: f64,
    /// Its standard error (0: held fixed).
    pub std_error: f64,
    /// t-value.
    pub t: f64,
}

/// A fit as `identify --format json` reports it.
#[derive(Clone, Debug, Serialize)]
pub struct FitReport {
    /// What was explained.
    pub target: String,
    /// The back-end's name.
    pub backend: String,
    /// Rows fitted.
    pub rows: usize,
    /// The candidates, in column order.
    pub candidates: Vec<String>,
    /// The step table (back-ends that take steps).
    pub steps: Vec<StepReport>,
    /// The step chosen.
    pub chosen_step: usize,
    /// The chosen terms.
    pub terms: Vec<TermReport>,
    /// The intercept b0, if fitted.
    pub intercept: Option<f64>,
    /// Its standard error.
    pub intercept_std_error: Option<f64>,
    /// Why the back-end stopped.
    pub stop: Stop,
    /// The back-end's notes and the fit's ([`Fit::notes`]).
    pub notes: Vec<String>,
    /// The residuals' correlation time, rows.
    pub correlation_time: Option<f64>,
    /// How many times larger the residuals are where the fit is largest than where it is
    /// smallest (a quarter of the rows each).
    pub residual_growth: Option<f64>,
    /// Each chosen term's closest rival and the rise of the residual sum of squares in its
    /// place, in residual variances.
    pub rivals: Vec<crate::select::Rival>,
    /// The chosen coefficients' covariance.
    pub covariance: Option<Vec<Vec<f64>>>,
}

impl Fit {
    /// The fit as a plain record (for JSON).
    pub fn report(&self) -> FitReport {
        let s = &self.selection;
        FitReport {
            target: self.target.clone(),
            backend: s.backend.clone(),
            rows: s.rows,
            candidates: self.candidates.clone(),
            steps: s
                .steps
                .iter()
                .map(|st| StepReport {
                    step: st.step,
                    term: st.term.clone(),
                    forced: st.forced,
                    standard_error: st.standard_error,
                    f: st.f,
                    r2: st.r2,
                    proportion: st.proportion,
                })
                .collect(),
            chosen_step: s.chosen_step,
            terms: s
                .terms
                .iter()
                .map(|t| TermReport {
                    term: t.term.clone(),
                    coefficient: t.coefficient,
                    std_error: t.std_error,
                    t: t.t,
                })
                .collect(),
            intercept: s.intercept.as_ref().map(|b| b.value),
            intercept_std_error: s.intercept.as_ref().map(|b| b.std_error),
            stop: s.stop.clone(),
            notes: self.notes(),
            correlation_time: self.correlation_time,
            residual_growth: self.residual_growth,
            rivals: self.rivals.clone(),
            covariance: self.covariance.clone(),
        }
    }

    /// The fit as a person reads it: the step table, the equation, the coefficient table and
    /// the notes.
    pub fn text(&self) -> String {
        let fit = self;
        let s = &fit.selection;
        let mut out = format!(
            "{} on {} rows, {} candidates, back-end {}\n\n",
            fit.target,
            s.rows,
            fit.candidates.len(),
            s.backend
        );
        if !s.steps.is_empty() {
            out += &format!(
                "{:>4}  {:<22} {:>12} {:>12} {:>10}\n",
                "step", "term entered", "std. error", "F", "R²"
            );
            for st in &s.steps {
                let mark = if st.step == s.chosen_step { " ← chosen" } else { "" };
                let forced = if st.forced { " (forced)" } else { "" };
                out += &format!(
                    "{:>4}  {:<22} {:>12} {:>12} {:>10.6}{forced}{mark}\n",
                    st.step,
                    st.term,
                    num(st.standard_error),
                    num(st.f),
                    st.r2
                );
            }
            out += "\n";
        }
        out += &format!("{} =", fit.target);
        let mut first = true;
        if let Some(b0) = &s.intercept {
            out += &format!(" {}", num(b0.value));
            first = false;
        }
        for t in &s.terms {
            let sign = if t.coefficient < 0.0 {
                "-"
            } else if first {
                ""
            } else {
                "+"
            };
            out += &format!("\n    {sign} {}{}", num(t.coefficient.abs()), times(&t.term));
            first = false;
        }
        out += "\n\n";
        out += &format!("{:<22} {:>12} {:>12} {:>9}\n", "term", "coefficient", "std. error", "t");
        if let Some(b0) = &s.intercept {
            out += &format!(
                "{:<22} {:>12} {:>12} {:>9.2}\n",
                "(intercept)",
                num(b0.value),
                num(b0.std_error),
                b0.t
            );
        }
        for t in &s.terms {
            // a coefficient the back-end was told to hold (sparse `fixed`) is not estimated
            let t_value = if t.std_error == 0.0 { "fixed".to_string() } else { format!("{:.2}", t.t) };
            out += &format!(
                "{:<22} {:>12} {:>12} {:>9}\n",
                t.term,
                num(t.coefficient),
                num(t.std_error),
                t_value
            );
        }
        out += &format!("\nstepping ended: {} (chosen: step {})\n", s.stop, s.chosen_step);
        if let Some(tau) = fit.correlation_time.filter(|t| *t > 1.5) {
            out += &format!(
            "note: the residuals are correlated over τ = {tau:.1} rows; the standard errors above assume independent rows, honest ones are about √τ = {:.1} times larger\n",
            tau.sqrt()
        );
        }
        for n in fit.notes() {
            out += &format!("note: {n}\n");
        }
        out
    }

    /// The back-end's notes, then what the rows leave open: chosen terms a candidate left out
    /// would replace within the noise (a rise of the residual sum of squares below
    /// 4·τ residual variances: the choice between the two is the noise's), and
    /// any that would fit clearly better (a path that passed them by).
    pub fn notes(&self) -> Vec<String> {
        let mut notes = self.selection.notes.clone();
        let tau = self.correlation_time.unwrap_or(1.0).max(1.0);
        let within = RIVAL_RISE * tau;
        let pair =
            |w: &crate::select::Rival| format!("`{}` from `{}` ({:+.2} s²)", w.chosen, w.instead, w.rise);
        let close: Vec<String> = self.rivals.iter().filter(|w| w.rise.abs() < within).map(pair).collect();
        if !close.is_empty() {
            let noise = if tau > 1.5 {
                format!("{}·τ with τ = {tau:.1}, about two standard errors of the noise", sig(RIVAL_RISE, 2))
            } else {
                "about two standard errors of the noise".into()
            };
            notes.push(format!(
                "the rows hardly tell {}: swapped, the residual sum of squares changes by less than \
                 {} residual variances s² ({noise}); the choice is the noise's, either may be the \
                 system's term",
                close.join(", "),
                sig(within, 2),
            ));
        }
        if let Some(g) = self.residual_growth.filter(|g| *g > RESIDUAL_GROWTH) {
            notes.push(format!(
                "the residuals grow with the size of `{}`: {} times larger (root mean square) in the \
                 quarter of rows where the fit is largest than in the quarter where it is smallest; \
                 least squares weighs every row alike, so the largest rows decide the terms and \
                 coefficients. Where the records' error grows with their size (a percentage error, \
                 counts), weight the rows by 1/size² (a column of weights: `--weight`, Python \
                 `weights=`)",
                self.target,
                sig(g, 2)
            ));
        }
        let better: Vec<String> = self
            .rivals
            .iter()
            .filter(|w| w.rise <= -within)
            .map(|w| format!("`{}` in place of `{}` ({:+.2} s²)", w.instead, w.chosen, w.rise))
            .collect();
        if !better.is_empty() {
            notes.push(format!(
                "a candidate left out fits clearly better than a chosen term: {} (the back-end's \
                 path passed it by; best-subset compares whole sets)",
                better.join(", ")
            ));
        }
        notes
    }
}

/// How many times larger the residuals may be where the fit is largest than where it is
/// smallest before the fit says the largest rows decide it (noise of one size everywhere gives
/// about 1; Lotka-Volterra with 5 % relative noise 2.3).
const RESIDUAL_GROWTH: f64 = 10.0;

/// A rival whose swap changes the residual sum of squares by less than this many residual
/// variances (times τ) is within the noise: about two standard errors (χ²₁'s 95 % point 3.84).
const RIVAL_RISE: f64 = 4.0;

/// `*term` as a factor after a coefficient: nothing for the constant, a sum (a candidate
/// such as `x*(z - 10000)`, multiplied out) or a negative term in parentheses, so the printed
/// equation reads as it computes.
fn times(term: &str) -> String {
    if term == "1" {
        return String::new();
    }
    let mut depth = 0i32;
    let mut sum = term.starts_with('-');
    for (i, c) in term.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            '+' | '-' if depth == 0 && i > 0 && term[..i].ends_with(' ') => sum = true,
            _ => {}
        }
    }
    if sum {
        format!("*({term})")
    } else {
        format!("*{term}")
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_sum_or_negative_term_is_parenthesised_after_its_coefficient() {
        assert_eq!(super::times("x*z"), "*x*z");
        assert_eq!(super::times("1"), "");
        assert_eq!(super::times("-10000*x + x*z"), "*(-10000*x + x*z)");
        assert_eq!(super::times("-x"), "*(-x)");
        assert_eq!(super::times("1/(u + v)"), "*1/(u + v)");
        assert_eq!(super::times("x^-1"), "*x^-1");
    }

    use super::sig;

    #[test]
    fn significant_figures_read_as_the_data_support() {
        assert_eq!(sig(0.0206417, 3), "0.0206");
        assert_eq!(sig(1.55125, 3), "1.55");
        assert_eq!(sig(2992.74, 3), "2993");
        assert_eq!(sig(-9.5213e-5, 3), "-9.52e-5");
        assert_eq!(sig(0.0, 3), "0");
    }
}
