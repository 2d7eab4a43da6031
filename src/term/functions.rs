//! Built-in functions of the term language: one table, one row per function. Adding a
//! function is adding a row; the grammar's `call` rule is generic.

/// A function usable in terms, e.g. `abs(v)*v`.
#[derive(Debug)]
pub struct Function {
    /// Name as written in terms.
    pub name: &'static str,
    /// Number of arguments.
    pub arity: usize,
    /// Evaluation on one set of arguments.
    pub eval: fn(&[f64]) -> f64,
    /// Its partial derivatives at the arguments (given its value there), one per argument:
    /// the forward-mode derivatives of a compiled program chain through them.
    pub grad: fn(&[f64], f64, &mut [f64]),
    /// One line for the help text.
    pub doc: &'static str,
}

/// The most arguments a built-in function takes.
pub const MAX_ARITY: usize = 2;

/// The built-in functions.
pub static FUNCTIONS: &[Function] = &[
    Function {
        name: "abs",
        arity: 1,
        eval: |a| a[0].abs(),
        grad: |a, _, g| g[0] = sign(a[0]),
        doc: "absolute value, e.g. abs(v)*v",
    },
    Function {
        name: "sign",
        arity: 1,
        eval: |a| sign(a[0]),
        grad: |_, _, g| g[0] = 0.0,
        doc: "-1, 0 or 1 (0 at 0)",
    },
    Function {
        name: "sqrt",
        arity: 1,
        eval: |a| a[0].sqrt(),
        grad: |_, f, g| g[0] = 0.5 / f,
        doc: "square root",
    },
    Function {
        name: "sin",
        arity: 1,
        eval: |a| a[0].sin(),
        grad: |a, _, g| g[0] = a[0].cos(),
        doc: "sine (radians)",
    },
    Function {
        name: "cos",
        arity: 1,
        eval: |a| a[0].cos(),
        grad: |a, _, g| g[0] = -a[0].sin(),
        doc: "cosine (radians)",
    },
    Function {
        name: "tanh",
        arity: 1,
        eval: |a| a[0].tanh(),
        grad: |_, f, g| g[0] = 1.0 - f * f,
        doc: "hyperbolic tangent",
    },
    Function { name: "exp", arity: 1, eval: |a| a[0].exp(), grad: |_, f, g| g[0] = f, doc: "exponential" },
    Function {
        name: "atan",
        arity: 1,
        eval: |a| a[0].atan(),
        grad: |a, _, g| g[0] = 1.0 / (1.0 + a[0] * a[0]),
        doc: "arc tangent (radians)",
    },
    Function {
        name: "atan2",
        arity: 2,
        // signed zeros folded to +0: the canonical form may compute a zero as −0 where the
        // text gives +0 (u − u), and atan2 would then jump from π to −π
        eval: |a| (a[0] + 0.0).atan2(a[1] + 0.0),
        // ∂/∂y = x/(x² + y²), ∂/∂x = −y/(x² + y²)
        grad: |a, _, g| {
            let r2 = a[0] * a[0] + a[1] * a[1];
            g[0] = a[1] / r2;
            g[1] = -a[0] / r2;
        },
        doc: "angle of the point (x, y) as atan2(y, x), radians in (−π, π], e.g. atan2(v, u) the drift angle",
    },
];

fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Looks a function up by name.
pub fn function(name: &str) -> Option<(usize, &'static Function)> {
    FUNCTIONS.iter().enumerate().find(|(_, f)| f.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_function_takes_more_than_max_arity_arguments() {
        assert!(FUNCTIONS.iter().all(|f| f.arity <= MAX_ARITY));
    }

    /// Every function's partial derivatives equal central differences of its values, at
    /// points away from its kinks (abs and sign at 0).
    #[test]
    fn gradients_equal_central_differences() {
        let points: [[f64; MAX_ARITY]; 4] = [[0.7, 1.3], [-0.4, 2.1], [2.5, -0.6], [-1.2, -0.9]];
        for f in FUNCTIONS {
            for p in points {
                let args = &p[..f.arity];
                let value = (f.eval)(args);
                if !value.is_finite() {
                    continue; // sqrt of a negative
                }
                let mut g = [0.0; MAX_ARITY];
                (f.grad)(args, value, &mut g[..f.arity]);
                for k in 0..f.arity {
                    let h = 1e-6;
                    let (mut up, mut down) = (p, p);
                    up[k] += h;
                    down[k] -= h;
                    let fd = ((f.eval)(&up[..f.arity]) - (f.eval)(&down[..f.arity])) / (2.0 * h);
                    assert!(
                        (g[k] - fd).abs() < 1e-7 * fd.abs().max(1.0),
                        "{} at {args:?}: ∂{k} {} vs {fd}",
                        f.name,
                        g[k]
                    );
                }
            }
        }
    }
}
