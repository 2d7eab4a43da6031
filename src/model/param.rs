//! Parameters whose value may differ from run to run (Oltmann's approach speed u0): a number,
//! or a rule read off each run (`first:u`, `mean:u`, `mean:u:4`).

use serde::{Deserialize, Serialize};

use crate::data::{DataError, Frame};

/// Where a parameter's value comes from in each run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParamValue {
    /// The same value for every run.
    Value(f64),
    /// A rule evaluated on each run: `first:u` is the run's first value of `u`.
    Rule(String),
}

/// A parameter value or rule that cannot be.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// A number that is not finite.
    #[error("parameter `{name}`: {value} is not a finite number")]
    NotFinite {
        /// The parameter.
        name: String,
        /// The value.
        value: f64,
    },
    /// `mean:COLUMN:SECONDS` without a positive number of seconds.
    #[error("parameter `{name}`: `{rule}`: write mean:COLUMN:SECONDS with SECONDS > 0")]
    MeanWindow {
        /// The parameter.
        name: String,
        /// The rule as written.
        rule: String,
    },
    /// Neither a number nor a known rule.
    #[error("parameter `{name}`: `{rule}` is neither a number nor `first:COLUMN`, `mean:COLUMN` or `mean:COLUMN:SECONDS`")]
    Unknown {
        /// The parameter.
        name: String,
        /// The rule as written.
        rule: String,
    },
}

impl ParamValue {
    /// A value as written on the command line or in a file: a finite number, or a rule that
    /// [`ParamValue::check_rule`] accepts.
    pub fn from_text(name: &str, text: &str) -> Result<ParamValue, ParamError> {
        let text = text.trim();
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(ParamValue::Value(v)),
            Ok(value) => Err(ParamError::NotFinite { name: name.into(), value }),
            Err(_) => {
                let rule = ParamValue::Rule(text.to_string());
                rule.check_rule(name)?;
                Ok(rule)
            }
        }
    }

    /// Checks a rule's syntax without data.
    pub fn check_rule(&self, name: &str) -> Result<(), ParamError> {
        match self {
            ParamValue::Value(_) => Ok(()),
            ParamValue::Rule(rule) => match rule.split_once(':') {
                Some(("first", col)) if !col.is_empty() => Ok(()),
                Some(("mean", rest)) if !rest.is_empty() => match rest.split_once(':') {
                    Some((c, secs)) if !c.is_empty() && secs.parse::<f64>().is_ok_and(|s| s > 0.0) => Ok(()),
                    Some(_) => Err(ParamError::MeanWindow { name: name.into(), rule: rule.clone() }),
                    None => Ok(()),
                },
                _ => Err(ParamError::Unknown { name: name.into(), rule: rule.clone() }),
            },
        }
    }

    /// For a `first:COLUMN` rule on a noisy record, why the rule is fragile: its one sample
    /// carries the noise (σ of the first two time units from their second differences, above
    /// 10⁻⁴ of the signal), which `mean:COLUMN:SECONDS` averages away. `None` for other rules,
    /// clean records and runs too short to tell.
    pub fn noisy_first_sample(&self, name: &str, frame: &Frame) -> Option<String> {
        let ParamValue::Rule(rule) = self else { return None };
        let ("first", col) = rule.split_once(':')? else { return None };
        let x = frame.column(col)?;
        let t = frame.time();
        let n = t.iter().take_while(|ti| **ti - t[0] <= 2.0).count();
        if n < 8 {
            return None;
        }
        let x = &x[..n];
        // noise: the scatter about a parabola over the first 2 s, which follows a smooth start
        // (the ship slowing as the rudder goes over) where second differences of coarse
        // samples read its curvature as noise
        let sigma = scatter_about_parabola(&t[..n], x);
        let mean = x.iter().sum::<f64>() / n as f64;
        // a noise-free start that no parabola follows exactly (the rudder's ramp) scatters
        // about 1e-4 of the value; sensors and printed digits 1e-3 and more
        (sigma > 5e-4 * mean.abs().max(1e-12)).then(|| {
            format!(
                "{}: `{name} = {rule}` reads one noisy sample ({:.6}; noise σ ≈ {sigma:.2e} from the first 2 s): `mean:{col}:2` averages the approach",
                frame.origin(),
                x[0]
            )
        })
    }

    /// The value in one run.
    pub fn resolve(&self, name: &str, frame: &Frame) -> Result<f64, DataError> {
        match self {
            ParamValue::Value(v) => Ok(*v),
            ParamValue::Rule(rule) => match rule.split_once(':') {
                _ if self.check_rule(name).is_err() => Err(DataError::Setting(
                    self.check_rule(name).err().map(|e| e.to_string()).unwrap_or_default(),
                )),
                Some(("first", col)) => Ok(frame.require(col)?[0]),
                Some(("mean", rest)) => {
                    // `mean:u` over the run, `mean:u:2` over its first 2 time units (the approach)
                    let (col, span) = match rest.split_once(':') {
                        Some((c, secs)) => (c, secs.parse::<f64>().ok().filter(|s| *s > 0.0)),
                        None => (rest, None),
                    };
                    let c = frame.require(col)?;
                    let t = frame.time();
                    let n = span.map_or(c.len(), |s| t.iter().take_while(|ti| **ti - t[0] <= s).count().max(1));
                    Ok(c[..n].iter().sum::<f64>() / n as f64)
                }
                _ => Err(DataError::Setting(format!(
                    "parameter `{name}`: `{rule}` is neither a number nor `first:COLUMN`, `mean:COLUMN` or `mean:COLUMN:SECONDS`"
                ))),
            },
        }
    }
}

/// The residual standard deviation of `x` about its least-squares parabola in `t`.
fn scatter_about_parabola(t: &[f64], x: &[f64]) -> f64 {
    let n = t.len().min(x.len());
    if n < 4 {
        return 0.0;
    }
    // centred and scaled time keeps the normal equations well conditioned
    let (t0, span) = (t[0], (t[n - 1] - t[0]).max(f64::MIN_POSITIVE));
    let a = nalgebra::DMatrix::from_fn(n, 3, |i, j| ((t[i] - t0) / span).powi(j as i32));
    let b = nalgebra::DVector::from_column_slice(&x[..n]);
    let Some(Ok(fit)) = crate::linalg::svd(a.clone()).map(|svd| svd.solve(&b, 1e-12)) else { return 0.0 };
    ((&a * fit - b).norm_squared() / (n - 3) as f64).sqrt()
}
