//! Uncertainty of a prediction from the uncertainty of the identified coefficients: models
//! drawn from each equation's stored covariance (Monte Carlo), the spread of any numbers
//! computed from them, and pointwise bands of simulated signals. Generic; the ship plug-in
//! and the CLI decide what to simulate with each draw.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::model::Model;

/// Seeded standard normal numbers (SplitMix64, Box-Muller): the same seed, the same draws.
#[derive(Clone, Debug)]
pub struct Normal(u64);

impl Normal {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Normal {
        Normal(seed)
    }

    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// The next standard normal number.
    pub fn sample(&mut self) -> f64 {
        let (a, b) = (self.uniform(), self.uniform());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    }
}

/// The largest share of failed draws with which the others still describe the model: beyond
/// it the draws that ran are those that happened to stay stable, not a sample of the model's
/// uncertainty, and no mean, sd or band may be made of them.
pub const MAX_FAILED: f64 = 0.05;

/// Whether `ran` of `draws` drawn models describe the model: some ran, and no more than
/// [`MAX_FAILED`] of the draws failed.
pub fn usable(draws: usize, ran: usize) -> bool {
    ran > 0 && draws.saturating_sub(ran) as f64 <= MAX_FAILED * draws as f64
}

/// Why no spread may be made of `ran` of `draws` drawn models, and what helps (`None` where
/// they are [`usable`]); `first_failure` says how the first failed draw failed.
pub fn refusal(draws: usize, ran: usize, first_failure: Option<&str>) -> Option<String> {
    if usable(draws, ran) {
        return None;
    }
    let failed = draws.saturating_sub(ran);
    Some(format!(
        "{failed} of {draws} draws failed ({:.0} %, more than the {:.0} % a spread can stand): no mean, sd or band is shown, since the draws that ran are only those that stayed stable. The drawn coefficients leave the region where the model can be simulated{}: the covariance is too wide for this manoeuvre. What helps: more or longer runs, or runs that excite the terms more (a wider rudder range), fewer candidate terms, or refining with --refine",
        100.0 * failed as f64 / draws.max(1) as f64,
        100.0 * MAX_FAILED,
        first_failure.map_or(String::new(), |f| format!(" (first failure: {f})"))
    ))
}

/// What a draw can perturb: the equations with a stored covariance, and `parameters` when the
/// file holds the free parameters' covariance (`[parameter_covariance]`).
pub fn uncertain_equations(model: &Model) -> Vec<String> {
    let mut out: Vec<String> =
        model.equations().iter().filter(|e| e.covariance.is_some()).map(|e| e.name.clone()).collect();
    if model.spec().parameter_covariance.is_some() {
        out.push("parameters".into());
    }
    out
}

/// A symmetric square root of a covariance (semi-definite matrices, as an exact fit or a term
/// with zero error gives, have no Cholesky factor; the eigen-decomposition serves for both).
fn square_root(sigma: nalgebra::DMatrix<f64>) -> nalgebra::DMatrix<f64> {
    let Some(eig) = crate::linalg::symmetric_eigen(sigma.clone()) else {
        // (a covariance the model file's check decomposed: not reached) the standard errors
        // alone, their correlations left out, rather than none
        return nalgebra::DMatrix::from_diagonal(&sigma.diagonal().map(|v| v.max(0.0).sqrt()));
    };
    &eig.eigenvectors
        * nalgebra::DMatrix::from_diagonal(&eig.eigenvalues.map(|l| l.max(0.0).sqrt()))
        * eig.eigenvectors.transpose()
}

/// Draws models whose coefficients come from N(b, τΣ) equation by equation (b the stored
/// coefficients, Σ their covariance, τ the residual correlation time); equations without a
/// covariance keep their values. The square roots of the covariances are taken once, here.
pub struct Sampler<'m> {
    model: &'m Model,
    /// (equation, its covariance's terms, a square root of τΣ).
    roots: Vec<(String, Vec<crate::term::Term>, nalgebra::DMatrix<f64>)>,
    /// The free parameters' names and a square root of their covariance (output error:
    /// already widened by the residuals' correlation time).
    parameters: Option<(Vec<String>, nalgebra::DMatrix<f64>)>,
}

impl<'m> Sampler<'m> {
    /// Prepares draws from `model`'s stored covariances.
    pub fn new(model: &'m Model) -> Sampler<'m> {
        let roots = model
            .equations()
            .iter()
            .filter_map(|eq| {
                let c = eq.covariance.as_ref()?;
                let k = c.terms.len();
                // rows of a time series are not independent: the effective covariance is τ
                // times s²(X'X)⁻¹
                let sigma = nalgebra::DMatrix::from_fn(k, k, |i, j| c.matrix[i][j] * c.correlation_time);
                Some((eq.name.clone(), c.terms.clone(), square_root(sigma)))
            })
            .collect();
        let parameters = model.spec().parameter_covariance.as_ref().map(|c| {
            let k = c.names.len();
            (c.names.clone(), square_root(nalgebra::DMatrix::from_fn(k, k, |i, j| c.matrix[i][j])))
        });
        Sampler { model, roots, parameters }
    }

    /// One drawn model.
    pub fn draw(&self, normal: &mut Normal) -> Model {
        let mut out = self.model.clone();
        for (name, terms, root) in &self.roots {
            let Some(eq) = self.model.equation(name) else { continue };
            let z = nalgebra::DVector::from_fn(terms.len(), |_, _| normal.sample());
            let shift = root * z;
            let coefficients = eq
                .coefficients
                .iter()
                .map(|(t, v, se)| {
                    let d = terms.iter().position(|u| u == t).map_or(0.0, |i| shift[i]);
                    (t.clone(), v + d, *se)
                })
                .collect();
            out.set_coefficients(name, coefficients, eq.intercept);
        }
        if let Some((names, root)) = &self.parameters {
            let values = self.model.parameter_values();
            let shift = root * nalgebra::DVector::from_fn(names.len(), |_, _| normal.sample());
            for (name, d) in names.iter().zip(shift.iter()) {
                if let Some(v) = values.get(name) {
                    out.set_parameter(name, v + d);
                }
            }
        }
        out
    }
}

/// The spread of one number over the draws.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spread {
    /// Draws that gave a value.
    pub count: usize,
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub sd: f64,
    /// 5th percentile.
    pub p05: f64,
    /// 95th percentile.
    pub p95: f64,
}

impl Spread {
    /// Whether `x` (a measured value) lies outside the 5-95 % range: one measurement in ten
    /// does by chance where the model's uncertainty is right.
    pub fn outside(&self, x: f64) -> bool {
        x < self.p05 || x > self.p95
    }
}

/// Linear-interpolated percentile of sorted values.
fn percentile(sorted: &[f64], p: f64) -> f64 {
    let x = p * (sorted.len() - 1) as f64;
    let (i, w) = (x.floor() as usize, x - x.floor());
    if i + 1 < sorted.len() {
        sorted[i] * (1.0 - w) + sorted[i + 1] * w
    } else {
        sorted[i]
    }
}

/// The spread of a set of values (`None` for none).
pub fn spread_of(values: &[f64]) -> Option<Spread> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sd = if v.len() > 1 {
        (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    Some(Spread { count: v.len(), mean, sd, p05: percentile(&v, 0.05), p95: percentile(&v, 0.95) })
}

/// Every number in a JSON record (e.g. a manoeuvre's metrics), by its dotted path; arrays are
/// left out.
pub fn numbers(record: &serde_json::Value) -> BTreeMap<String, f64> {
    fn leaves(prefix: &str, v: &serde_json::Value, out: &mut BTreeMap<String, f64>) {
        match v {
            serde_json::Value::Object(map) => {
                for (k, x) in map {
                    let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                    leaves(&key, x, out);
                }
            }
            serde_json::Value::Number(n) => {
                if let Some(x) = n.as_f64() {
                    out.insert(prefix.to_string(), x);
                }
            }
            _ => {}
        }
    }
    let mut out = BTreeMap::new();
    leaves("", record, &mut out);
    out
}

/// The spread of every number in a set of like JSON records (e.g. manoeuvre metrics), by
/// its dotted path ([`numbers`]).
pub fn spread(records: &[serde_json::Value]) -> BTreeMap<String, Spread> {
    let mut all: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for r in records {
        for (k, v) in numbers(r) {
            all.entry(k).or_default().push(v);
        }
    }
    all.into_iter().filter_map(|(k, v)| spread_of(&v).map(|s| (k, s))).collect()
}

/// One free parameter's effect on a prediction's numbers: half the change of each between the
/// model with the parameter one standard deviation above its estimate and one below, the
/// others at theirs. A central difference over the likely range: what a Monte-Carlo spread
/// comes from, and which parameter a further test (a captive test, a run that excites it)
/// would pin down.
#[derive(Clone, Debug, Serialize)]
pub struct ParameterEffect {
    /// The parameter.
    pub parameter: String,
    /// Its standard deviation (the stored covariance's).
    pub sd: f64,
    /// Each number's half change, by its dotted path ([`numbers`]).
    pub effects: BTreeMap<String, f64>,
    /// Why a model one sd away made no prediction (then `effects` is empty).
    pub failed: Option<String>,
}

/// Each free parameter's effect ([`ParameterEffect`]) on the numbers `predict` makes of a model
/// (a manoeuvre's metrics), from the free parameters' covariance `model` stores
/// (`[parameter_covariance]`); empty without one.
pub fn parameter_effects<E: std::fmt::Display>(
    model: &Model,
    predict: impl Fn(&Model) -> Result<serde_json::Value, E>,
) -> Vec<ParameterEffect> {
    let Some(c) = model.spec().parameter_covariance.as_ref() else { return Vec::new() };
    let values = model.parameter_values();
    c.names
        .iter()
        .enumerate()
        .filter_map(|(i, name)| {
            let (value, sd) = (*values.get(name)?, c.matrix[i][i].max(0.0).sqrt());
            let at = |v: f64| {
                let mut m = model.clone();
                m.set_parameter(name, v);
                predict(&m).map(|r| numbers(&r)).map_err(|e| e.to_string())
            };
            let (effects, failed) = match (at(value + sd), at(value - sd)) {
                (Ok(up), Ok(down)) => {
                    let half =
                        up.iter().filter_map(|(k, u)| Some((k.clone(), 0.5 * (u - down.get(k)?)))).collect();
                    (half, None)
                }
                (Err(e), _) | (_, Err(e)) => (BTreeMap::new(), Some(e)),
            };
            Some(ParameterEffect { parameter: name.clone(), sd, effects, failed })
        })
        .collect()
}

/// What the spread of one number comes from, linearised in the free parameters
/// ([`attribution`]).
#[derive(Clone, Debug, Serialize)]
pub struct Attribution {
    /// Its standard deviation from all the parameters' effects together, with their
    /// correlations (near the Monte-Carlo sd where the prediction is about linear in the
    /// parameters over their range).
    pub linearised_sd: f64,
    /// Each parameter's share of that variance that knowing it exactly would remove,
    /// (Σⱼ ρᵢⱼ eⱼ)² / Var (e the effects, ρ the correlations): between 0 and 1, the largest
    /// first; correlated parameters share theirs, so the shares need not sum to 1.
    pub explained: Vec<(String, f64)>,
}

/// What the spread of number `key` comes from ([`Attribution`]), from `effects` and the
/// parameters' correlations in `model`'s covariance. `None` where a parameter has no effect on
/// it (a failed prediction), it does not vary, or there is no covariance.
pub fn attribution(model: &Model, effects: &[ParameterEffect], key: &str) -> Option<Attribution> {
    let c = model.spec().parameter_covariance.as_ref()?;
    let index: Vec<usize> =
        effects.iter().map(|e| c.names.iter().position(|n| *n == e.parameter)).collect::<Option<_>>()?;
    let e: Vec<f64> = effects.iter().map(|x| x.effects.get(key).copied()).collect::<Option<_>>()?;
    let rho = |a: usize, b: usize| {
        let (sa, sb) = (effects[a].sd, effects[b].sd);
        if sa > 0.0 && sb > 0.0 {
            c.matrix[index[a]][index[b]] / (sa * sb)
        } else {
            f64::from(u8::from(a == b))
        }
    };
    // R e: each parameter's covariance with the number, in units of its sd
    let re: Vec<f64> = (0..e.len()).map(|a| (0..e.len()).map(|b| rho(a, b) * e[b]).sum()).collect();
    let variance: f64 = e.iter().zip(&re).map(|(x, y)| x * y).sum();
    if !(variance > 0.0 && variance.is_finite()) {
        return None;
    }
    let mut explained: Vec<(String, f64)> =
        effects.iter().zip(&re).map(|(x, r)| (x.parameter.clone(), (r * r / variance).min(1.0))).collect();
    explained.sort_by(|a, b| b.1.total_cmp(&a.1));
    Some(Attribution { linearised_sd: variance.sqrt(), explained })
}

/// Pointwise 5 % and 95 % curves of several signals sampled at the same times (shorter
/// signals, e.g. from runs that stopped, count where they have values).
pub fn band(signals: &[Vec<f64>]) -> (Vec<f64>, Vec<f64>) {
    let n = signals.iter().map(Vec::len).max().unwrap_or(0);
    (0..n)
        .map(|i| {
            let mut at: Vec<f64> =
                signals.iter().filter_map(|s| s.get(i).copied()).filter(|v| v.is_finite()).collect();
            at.sort_by(f64::total_cmp);
            if at.is_empty() {
                (f64::NAN, f64::NAN)
            } else {
                (percentile(&at, 0.05), percentile(&at, 0.95))
            }
        })
        .unzip()
}

/// Integrated autocorrelation time τ = 1 + 2 Σ ρₖ of residual series (pooled over the series),
/// summed up to the first lag where ρₖ falls to zero or below (Geyer's initial positive
/// sequence, simplified; at most 1000 lags), in samples. `None` without variance or with
/// series shorter than 4 samples. Independent residuals give τ ≈ 1; the effective number of
/// samples is n/τ.
pub fn correlation_time(residuals: &[Vec<f64>]) -> Option<f64> {
    let lag = |k: usize| -> f64 {
        residuals
            .iter()
            .filter(|e| e.len() > k)
            .map(|e| e.iter().zip(&e[k..]).map(|(a, b)| a * b).sum::<f64>())
            .sum()
    };
    let c0 = lag(0);
    let longest = residuals.iter().map(Vec::len).max().unwrap_or(0);
    if c0 <= 0.0 || !c0.is_finite() || longest < 4 {
        return None;
    }
    let mut tau = 1.0;
    for k in 1..(longest / 2).min(1000) {
        let rho = lag(k) / c0;
        if rho <= 0.0 {
            break;
        }
        tau += 2.0 * rho;
    }
    Some(tau)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Nomoto's K and T with a covariance (sd 0.01 and 0.5, correlation 0.1).
    fn nomoto_with_covariance() -> Model {
        let text = format!(
            "{}\n[parameter_covariance]\nnames = [\"K\", \"T\"]\nmatrix = [[1e-4, 5e-4], [5e-4, 0.25]]\n",
            include_str!("../models/nomoto.toml")
        );
        Model::parse(&text, "nomoto.toml").unwrap()
    }

    /// A step's yaw rate r(t) = Kδ(1 − e^(−t/T)) in closed form, at t = T's file value (10 s)
    /// and at 200 s (steady: T no longer matters).
    fn step_response(m: &Model) -> Result<serde_json::Value, String> {
        let p = m.parameter_values();
        let (k, t, delta) = (p["K"], p["T"], 0.1);
        let r = |time: f64| k * delta * (1.0 - (-time / t).exp());
        Ok(serde_json::json!({ "r": { "early": r(10.0), "steady": r(200.0) } }))
    }

    /// One sd of each parameter moves a prediction by half its central difference: the steady
    /// rate by sd_K·δ (it is linear in K) and not by T; the early one by both, as the closed
    /// form says; the linearised sd joins them with their correlation, and each one's share
    /// of the variance is what knowing it exactly would remove. A parameter whose model one sd
    /// away predicts nothing is named with why, and leaves no attribution.
    #[test]
    fn one_sd_of_each_parameter_moves_the_prediction_as_the_closed_form_says() {
        let model = nomoto_with_covariance();
        let effects = parameter_effects(&model, step_response);
        let (k, t) = (&effects[0], &effects[1]);
        assert_eq!((k.parameter.as_str(), t.parameter.as_str()), ("K", "T"));
        assert!((k.sd - 0.01).abs() < 1e-15 && (t.sd - 0.5).abs() < 1e-15);
        let steady_k = k.effects["r.steady"];
        assert!((steady_k - 0.01 * 0.1 * (1.0 - (-20.0f64).exp())).abs() < 1e-15, "{steady_k}");
        assert!(t.effects["r.steady"].abs() < 1e-9, "{:?}", t.effects);
        let early = |kk: f64, tt: f64| kk * 0.1 * (1.0 - (-10.0 / tt).exp());
        let early_t = 0.5 * (early(0.1, 10.5) - early(0.1, 9.5));
        assert!((t.effects["r.early"] - early_t).abs() < 1e-15, "{:?}", t.effects);
        let early_k = k.effects["r.early"];
        let variance = early_k.powi(2) + early_t.powi(2) + 2.0 * 0.1 * early_k * early_t;
        let early = attribution(&model, &effects, "r.early").unwrap();
        assert!((early.linearised_sd - variance.sqrt()).abs() < 1e-15, "{early:?}");
        // knowing K exactly removes (e_K + ρ e_T)² of the variance, T (e_T + ρ e_K)²
        let share = |name: &str| early.explained.iter().find(|(n, _)| n == name).unwrap().1;
        assert!((share("K") - (early_k + 0.1 * early_t).powi(2) / variance).abs() < 1e-12, "{early:?}");
        assert!((share("T") - (early_t + 0.1 * early_k).powi(2) / variance).abs() < 1e-12, "{early:?}");
        // the steady rate is K's alone: all of it K's, T's share its correlation's square
        let steady = attribution(&model, &effects, "r.steady").unwrap();
        assert_eq!(steady.explained[0].0, "K");
        let (all, t_share) = (steady.explained[0].1, steady.explained[1].1);
        assert!((all - 1.0).abs() < 1e-6 && (t_share - 0.01).abs() < 1e-6, "{steady:?}");
        // T below 9.6 s predicts nothing: T's effect is a failure, said as such
        let fragile = parameter_effects(&model, |m: &Model| {
            if m.parameter_values()["T"] < 9.6 {
                Err("the run diverges at t = 3 s".to_string())
            } else {
                step_response(m)
            }
        });
        assert!(
            fragile[1].effects.is_empty()
                && fragile[1].failed.as_deref() == Some("the run diverges at t = 3 s")
        );
        assert!(attribution(&model, &fragile, "r.early").is_none());
        // without a covariance, nothing to tell
        assert!(parameter_effects(
            &Model::parse(include_str!("../models/nomoto.toml"), "n.toml").unwrap(),
            step_response
        )
        .is_empty());
    }

    /// The values 0, 1, …, 100: the 5-95 % range is [5, 95], its ends inside.
    #[test]
    fn outside_is_beyond_the_five_to_ninety_five_percent_range() {
        let s = spread_of(&(0..=100).map(f64::from).collect::<Vec<_>>()).unwrap();
        assert_eq!((s.p05, s.p95), (5.0, 95.0));
        assert!(s.outside(4.9) && s.outside(95.1));
        assert!(!s.outside(5.0) && !s.outside(50.0) && !s.outside(95.0));
    }

    /// Up to 5 % of the draws may fail; beyond that, or with none that ran, the refusal says
    /// how many failed and how the first failed.
    #[test]
    fn a_spread_stands_five_percent_of_failed_draws() {
        assert!(usable(100, 95) && !usable(100, 94) && !usable(10, 0) && usable(1, 1));
        assert_eq!(refusal(100, 95, None), None);
        let why = refusal(100, 94, Some("diverged at t = 3 s")).unwrap();
        assert!(why.starts_with("6 of 100 draws failed (6 %, more than the 5 %"), "{why}");
        assert!(why.contains("(first failure: diverged at t = 3 s)"), "{why}");
    }

    #[test]
    fn normal_numbers_have_unit_variance() {
        let mut g = Normal::new(5);
        let v: Vec<f64> = (0..20000).map(|_| g.sample()).collect();
        let s = spread_of(&v).unwrap();
        assert!(s.mean.abs() < 0.03 && (s.sd - 1.0).abs() < 0.03, "{s:?}");
        assert!((s.p95 - 1.645).abs() < 0.05 && (s.p05 + 1.645).abs() < 0.05, "{s:?}");
    }

    /// Draws reproduce the stored covariance, correlations included.
    #[test]
    fn draws_have_the_stored_covariance() {
        // two equations, each with two coefficients (a generic model: no plug-in needed)
        let text = r#"
[model]
name = "two"
[[states]]
name = "u"
[[states]]
name = "r"
[equations.u_dot]
state = "u"
coefficients = { "u" = -0.4, "u^2" = 0.1 }
[equations.r_dot]
state = "r"
coefficients = { "r" = -1.0, "u*r" = 0.3 }
"#;
        let mut model = Model::parse(text, "two.toml").unwrap();
        let eq = model.equation("u_dot").unwrap().clone();
        let terms: Vec<_> = eq.coefficients.iter().take(2).map(|c| c.0.clone()).collect();
        let cov = [[4e-6, -3e-6], [-3e-6, 9e-6]];
        let c = crate::model::Covariance {
            terms: terms.clone(),
            matrix: cov.iter().map(|r| r.iter().map(|v| v / 4.0).collect()).collect(),
            correlation_time: 4.0,
        };
        model.set_covariance("u_dot", c).unwrap();
        let mut g = Normal::new(1);
        let sampler = Sampler::new(&model);
        let base: Vec<f64> = terms.iter().map(|t| model.equation("u_dot").unwrap().coefficient(t)).collect();
        let n = 20000;
        let mut d = vec![[0.0; 2]; n];
        for row in d.iter_mut() {
            let m = sampler.draw(&mut g);
            let e = m.equation("u_dot").unwrap();
            for (k, t) in terms.iter().enumerate() {
                row[k] = e.coefficient(t) - base[k];
            }
            // the other equations are untouched
            assert_eq!(
                m.equation("r_dot").unwrap().coefficients,
                model.equation("r_dot").unwrap().coefficients
            );
        }
        let c = |a: usize, b: usize| d.iter().map(|r| r[a] * r[b]).sum::<f64>() / n as f64;
        for (a, b) in [(0, 0), (0, 1), (1, 1)] {
            assert!((c(a, b) - cov[a][b]).abs() < 0.05 * 9e-6, "[{a}][{b}]: {} vs {}", c(a, b), cov[a][b]);
        }
        assert_eq!(uncertain_equations(&model), vec!["u_dot".to_string()]);
    }

    /// Draws of free parameters reproduce `[parameter_covariance]`.
    #[test]
    fn parameter_draws_have_the_stored_covariance() {
        let text = r#"
[model]
name = "nomoto"
[[states]]
name = "r"
[[inputs]]
name = "d"
[parameters.K]
value = 0.2
free = true
[parameters.T]
value = 8.0
free = true
[equations.r_dot]
state = "r"
identify = false
coefficients = { "K*d/T" = 1.0, "r/T" = -1.0 }
[parameter_covariance]
names = ["K", "T"]
matrix = [[1e-4, 2e-3], [2e-3, 0.25]]
"#;
        let model = Model::parse(text, "nomoto.toml").unwrap();
        assert_eq!(uncertain_equations(&model), vec!["parameters".to_string()]);
        let sampler = Sampler::new(&model);
        let mut g = Normal::new(2);
        let n = 20000;
        let d: Vec<[f64; 2]> = (0..n)
            .map(|_| {
                let p = sampler.draw(&mut g).parameter_values();
                [p["K"] - 0.2, p["T"] - 8.0]
            })
            .collect();
        let c = |a: usize, b: usize| d.iter().map(|r| r[a] * r[b]).sum::<f64>() / n as f64;
        let cov = [[1e-4, 2e-3], [2e-3, 0.25]];
        for (a, b) in [(0, 0), (0, 1), (1, 1)] {
            assert!((c(a, b) / cov[a][b] - 1.0).abs() < 0.05, "[{a}][{b}]: {} vs {}", c(a, b), cov[a][b]);
        }
    }

    #[test]
    fn spreads_and_bands() {
        let records: Vec<serde_json::Value> = (0..=10)
            .map(|i| serde_json::json!({"a": i as f64, "b": {"c": 2.0}, "d": null, "e": [1, 2]}))
            .collect();
        let s = spread(&records);
        assert_eq!(s.keys().collect::<Vec<_>>(), ["a", "b.c"]);
        assert!(
            (s["a"].mean - 5.0).abs() < 1e-12
                && (s["a"].p05 - 0.5).abs() < 1e-12
                && (s["a"].p95 - 9.5).abs() < 1e-12
        );
        let (lo, hi) = band(&[vec![0.0, 1.0], vec![2.0, 3.0], vec![4.0]]);
        assert_eq!(lo.len(), 2);
        assert!((lo[0] - 0.2).abs() < 1e-12 && (hi[0] - 3.8).abs() < 1e-12 && (hi[1] - 2.9).abs() < 1e-12);
    }
}
