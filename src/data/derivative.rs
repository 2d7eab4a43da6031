//! Numerical time derivatives of sampled signals. Central differences are the paper's
//! choice (Oltmann 1973, §8 alternative 4); smoothing methods for noisy measurements plug in
//! as further implementations of [`Differentiator`] and one row of [`DIFFERENTIATORS`].

use super::DataError;

/// A signal as a smoothing method sees it: its value and its rate at every sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Smoothed {
    /// The smoothed signal (the measured one for methods that only differentiate).
    pub value: Vec<f64>,
    /// d/dt of the signal.
    pub rate: Vec<f64>,
}

/// Differentiates one signal sampled at strictly increasing times.
pub trait Differentiator: Send + Sync {
    /// Stable name used on the CLI and in model files.
    fn name(&self) -> &'static str;
    /// dx/dt at every sample.
    fn differentiate(&self, t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError>;
    /// How many samples on either side a derivative depends on, when that is a fixed number
    /// (a local stencil): such a method gives the same rates on a run read in pieces with
    /// that many rows of context ([`super::Chunks`]). `None` (the default): the method needs
    /// the whole run (a spline, a smoother).
    fn reach(&self) -> Option<usize> {
        None
    }
    /// `Some` for the integral forms ([`super::IntegralForm`], [`super::WeakForm`]): no rate
    /// is estimated; the identification regresses the target's change over each window
    /// (weighed by the window's test function) on the candidates' integrals over it. `None`
    /// for every derivative method.
    fn window(&self) -> Option<Window> {
        None
    }
    /// The signal as the method estimates it, with its rate. Methods that smooth (spline,
    /// Kalman) return their smoothed curve, so the regressors can be the smoothed states too.
    fn smooth(&self, t: &[f64], x: &[f64]) -> Result<Smoothed, DataError> {
        Ok(Smoothed { value: x.to_vec(), rate: self.differentiate(t, x)? })
    }
}

/// The windows of an integral form: their length and the test function every row is
/// weighed with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// Sample intervals per window.
    pub intervals: usize,
    /// The function of time each window weighs the equation with.
    pub test: TestFunction,
    /// Whether a run shorter than four windows takes the integral form's windows instead (a
    /// default window; one the user chose is kept, and a run too short for it refused).
    pub shrinks: bool,
    /// Whether each window's candidates are fitted as the windows before it predict them
    /// ([`super::Ito`]'s instruments) rather than as they are.
    pub instrumented: bool,
}

impl Window {
    /// The window on a run of `rows` samples: where it [`Window::shrinks`] and four windows
    /// do not fit, the integral form's default ([`super::IntegralForm`]): a bump over a few
    /// coarse samples resolves neither φ nor the run (Lotka-Volterra at ten samples a period,
    /// 40 samples: a wrong model that stays bounded, where the integral form's runs away and
    /// is refused).
    pub fn on_rows(self, rows: usize) -> Window {
        if !self.shrinks || rows > 4 * self.intervals {
            return self;
        }
        Window::fallback()
    }

    /// The integral form's default windows, which a default window gives way to on a run it
    /// does not suit.
    pub fn fallback() -> Window {
        Window {
            intervals: super::IntegralForm::default().window,
            test: TestFunction::Flat,
            shrinks: false,
            instrumented: false,
        }
    }
}

/// The test function φ of a window [a, b]: the equation ẋ = Σ c_j θ_j multiplied by φ and
/// integrated over the window, ∫ φ ẋ dt = Σ c_j ∫ φ θ_j dt.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TestFunction {
    /// φ = 1: the left side is x(b) − x(a), the integral form.
    Flat,
    /// φ = (1 − s²)^p with s = (2t − a − b)/(b − a): φ vanishes at both ends, so the left side
    /// is −∫ φ′ x dt, a smooth average of x where x(b) − x(a) takes two noisy samples (the
    /// weak form; Messenger & Bortz 2021).
    Bump(u32),
}

/// Second-order central differences, exact for quadratics also on uneven spacing; the
/// end points use the second-order one-sided three-point formula.
#[derive(Clone, Copy, Debug, Default)]
pub struct CentralDifference;

/// Weights of the three-point derivative at `t[k]` from samples `i0, i0+1, i0+2`.
fn three_point(t: &[f64], i0: usize, k: usize) -> [f64; 3] {
    let (a, b, c) = (t[i0], t[i0 + 1], t[i0 + 2]);
    let x = t[k];
    // derivative of the Lagrange basis polynomials at x
    [
        ((x - b) + (x - c)) / ((a - b) * (a - c)),
        ((x - a) + (x - c)) / ((b - a) * (b - c)),
        ((x - a) + (x - b)) / ((c - a) * (c - b)),
    ]
}

impl Differentiator for CentralDifference {
    fn name(&self) -> &'static str {
        "central"
    }

    fn reach(&self) -> Option<usize> {
        Some(1)
    }

    fn differentiate(&self, t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError> {
        let n = t.len();
        if n < 3 || x.len() != n {
            return Err(DataError::TooShort {
                file: "signal".into(),
                rows: n.min(x.len()),
                needed: 3,
                what: "central differences".into(),
            });
        }
        let d = |i0: usize, k: usize| {
            let w = three_point(t, i0, k);
            w[0] * x[i0] + w[1] * x[i0 + 1] + w[2] * x[i0 + 2]
        };
        let mut out = Vec::with_capacity(n);
        out.push(d(0, 0));
        for k in 1..n - 1 {
            out.push(d(k - 1, k));
        }
        out.push(d(n - 3, n - 1));
        Ok(out)
    }
}

/// Makes a differentiator from its options (the `:`-separated words after its name).
pub type MakeDifferentiator = fn(&[f64]) -> Option<Box<dyn Differentiator>>;

/// The derivative methods by name, with the options each takes.
pub static DIFFERENTIATORS: &[(&str, &str, MakeDifferentiator)] = &[
    ("central", "", |o| o.is_empty().then(|| Box::new(CentralDifference) as Box<dyn Differentiator>)),
    ("five-point", "", |o| o.is_empty().then(|| Box::new(super::FivePoint) as Box<dyn Differentiator>)),
    ("savitzky-golay", "[:WINDOW:ORDER] (default 11:3)", |o| match o {
        [] => Some(Box::new(super::SavitzkyGolay::default())),
        [w, q] if w.fract() == 0.0 && q.fract() == 0.0 && *w >= 1.0 && *q >= 1.0 => {
            Some(Box::new(super::SavitzkyGolay { window: *w as usize, order: *q as usize }))
        }
        _ => None,
    }),
    ("spline", "[:ALPHA] (default: chosen by GCV)", |o| match o {
        [] => Some(Box::new(super::SmoothingSpline { alpha: None })),
        [a] => Some(Box::new(super::SmoothingSpline { alpha: Some(*a) })),
        _ => None,
    }),
    ("integral", "[:WINDOW] (default 8 sample intervals; no derivative, the integral form)", |o| match o {
        [] => Some(Box::new(super::IntegralForm::default())),
        [w] if w.fract() == 0.0 && *w >= 1.0 && *w <= 10_000.0 => {
            Some(Box::new(super::IntegralForm { window: *w as usize }))
        }
        _ => None,
    }),
    ("weak", "[:WINDOW[:POWER]] (default 32:8, the integral form's on runs under 129 samples or of dense switches; no derivative, the weak form)", |o| {
        let whole = |v: f64, low: f64, high: f64| v.fract() == 0.0 && v >= low && v <= high;
        let d = super::WeakForm::default();
        match o {
            [] => Some(Box::new(d)),
            [w] if whole(*w, 2.0, 10_000.0) => Some(Box::new(super::WeakForm { window: Some(*w as usize), ..d })),
            [w, p] if whole(*w, 2.0, 10_000.0) && whole(*p, 1.0, 64.0) => {
                Some(Box::new(super::WeakForm { window: Some(*w as usize), power: *p as u32 }))
            }
            _ => None,
        }
    }),
    ("ito", "(no derivative: each interval's change, the candidates instrumented; a record moved by a random force)", |o| {
        o.is_empty().then(|| Box::new(super::Ito) as Box<dyn Differentiator>)
    }),
    ("kalman", "[:RATIO] (default: maximum likelihood)", |o| match o {
        [] => Some(Box::new(super::KalmanSmoother { ratio: None })),
        [r] => Some(Box::new(super::KalmanSmoother { ratio: Some(*r) })),
        _ => None,
    }),
];

/// A derivative method from `NAME[:OPTION…]`, e.g. `savitzky-golay:21:3`, `spline`, `kalman`.
pub fn differentiator(spec: &str) -> Result<Box<dyn Differentiator>, DataError> {
    let mut words = spec.split(':');
    let name = words.next().unwrap_or("");
    let known = || DIFFERENTIATORS.iter().map(|(n, o, _)| format!("{n}{o}")).collect::<Vec<_>>().join(", ");
    let Some((_, _, make)) = DIFFERENTIATORS.iter().find(|(n, _, _)| *n == name) else {
        return Err(DataError::UnknownMethod(spec.into(), known()));
    };
    let options: Option<Vec<f64>> = words.map(|w| w.trim().parse::<f64>().ok()).collect();
    options
        .and_then(|o| make(&o))
        .ok_or_else(|| DataError::UnknownMethod(spec.into(), format!("options are: {}", known())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_on_quadratics_even_on_uneven_grids() {
        let t = [0.0, 0.1, 0.25, 0.3, 0.7, 1.0];
        let x: Vec<f64> = t.iter().map(|t| 3.0 * t * t - 2.0 * t + 1.0).collect();
        let d = CentralDifference.differentiate(&t, &x).unwrap();
        for (ti, di) in t.iter().zip(d) {
            assert!((di - (6.0 * ti - 2.0)).abs() < 1e-12, "{ti}: {di}");
        }
        assert!(CentralDifference.differentiate(&t[..2], &x[..2]).is_err());
    }

    #[test]
    fn methods_by_name_with_options() {
        for ok in [
            "central",
            "savitzky-golay",
            "savitzky-golay:21:3",
            "spline",
            "spline:1e4",
            "kalman",
            "kalman:1e-3",
        ] {
            assert!(differentiator(ok).is_ok(), "{ok}");
        }
        for bad in
            ["centra", "central:3", "savitzky-golay:21", "savitzky-golay:2.5:1", "spline:x", "kalman:1:2"]
        {
            let e = differentiator(bad).err().map(|e| e.to_string()).unwrap_or_default();
            assert!(e.contains(bad) && e.contains("savitzky-golay[:WINDOW:ORDER]"), "{bad}: {e}");
        }
    }
}
