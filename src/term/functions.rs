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
    /// One line for the help text.
    pub doc: &'static str,
}

/// The built-in functions.
pub static FUNCTIONS: &[Function] = &[
    Function { name: "abs", arity: 1, eval: |a| a[0].abs(), doc: "absolute value, e.g. abs(v)*v" },
    Function { name: "sign", arity: 1, eval: |a| sign(a[0]), doc: "-1, 0 or 1 (0 at 0)" },
    Function { name: "sqrt", arity: 1, eval: |a| a[0].sqrt(), doc: "square root" },
    Function { name: "sin", arity: 1, eval: |a| a[0].sin(), doc: "sine (radians)" },
    Function { name: "cos", arity: 1, eval: |a| a[0].cos(), doc: "cosine (radians)" },
    Function { name: "tanh", arity: 1, eval: |a| a[0].tanh(), doc: "hyperbolic tangent" },
    Function { name: "exp", arity: 1, eval: |a| a[0].exp(), doc: "exponential" },
    Function { name: "atan", arity: 1, eval: |a| a[0].atan(), doc: "arc tangent (radians)" },
    Function {
        name: "atan2",
        arity: 2,
        // signed zeros folded to +0: the canonical form may compute a zero as −0 where the
        // text gives +0 (u − u), and atan2 would then jump from π to −π
        eval: |a| (a[0] + 0.0).atan2(a[1] + 0.0),
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
