//! The laws a polynomial library only approximates, each of one variable: a dry friction or a
//! relay (sign), quadratic drag (x·|x|), outflow through an orifice (√|x|, Torricelli's), a
//! pendulum's gravity (sin x). A cubic fitted for them follows the runs it was fitted on and
//! fails beyond (a Coulomb oscillator's viscous stand-in never stops).

/// The laws of variable `name`, as candidate terms.
pub fn laws(name: &str) -> [String; 4] {
    [
        format!("sign({name})"),
        format!("{name}*abs({name})"),
        format!("sqrt(abs({name}))"),
        format!("sin({name})"),
    ]
}

/// The saturating forms of variable `name` (positive in every row) at half-saturation `k`:
/// an enzyme's turnover x/(x + K) (Michaelis-Menten), a predator's intake of prey x with each
/// of `others` x·y/(x + K) (Holling's type II), a switch's x²/(x² + K²) (Hill's, of order
/// two). Beside the library's constant they hold their repressing twins too: K/(x + K) is
/// 1 − x/(x + K), and 1/(1 + (x/K)²) is 1 − x²/(x² + K²).
pub fn saturations(name: &str, k: f64, others: &[String]) -> Vec<String> {
    // five figures: the term reads 1.2483, not 1.2482871090235
    let k = format!("{k:.4e}").parse().unwrap_or(k);
    let k2 = format!("{:.4e}", k * k).parse().unwrap_or(k * k);
    std::iter::once(format!("{name}/({name} + {k})"))
        .chain(others.iter().filter(|o| *o != name).map(|o| format!("{name}*{o}/({name} + {k})")))
        .chain(std::iter::once(format!("{name}^2/({name}^2 + {k2})")))
        .collect()
}

/// The odd saturation of variable `name` (of either sign) at scale `k`: tanh(x/K), an
/// actuator's or an amplifier's limit, a neuron's firing; written with its gain 1/K, which
/// the term keeps (`tanh(2*u)`, not `tanh(u/0.5)`).
pub fn odd_saturation(name: &str, k: f64) -> String {
    let gain = format!("{:.4e}", 1.0 / k).parse().unwrap_or(1.0 / k);
    format!("tanh({gain}*{name})")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each saturating form parses, of its variable (and one other) alone, and is half its
    /// most at x = K.
    #[test]
    fn every_saturation_is_half_its_most_at_its_constant() {
        let mut vocabulary = crate::term::Vocabulary::new();
        vocabulary.variable("x").unwrap().variable("y").unwrap();
        let forms = saturations("x", 1.25, &["x".into(), "y".into()]);
        assert_eq!(forms.len(), 3, "{forms:?}");
        for form in &forms {
            let term = vocabulary.parse(form).unwrap();
            assert!(term.variables().contains(&"x".to_string()), "{form}");
            let at = |x: f64| {
                vocabulary.interpret(&crate::term::parse_expr(form).unwrap(), &|n: &str| match n {
                    "x" => x,
                    _ => 1.0,
                })
            };
            assert!((at(1.25) - 0.5).abs() < 1e-12, "{form}: {}", at(1.25));
            assert!((at(1e9) - 1.0).abs() < 1e-6, "{form}: {}", at(1e9));
        }
        let odd = crate::term::parse_expr(&odd_saturation("x", 0.5)).unwrap();
        let at = |x: f64| vocabulary.interpret(&odd, &|_: &str| x);
        assert!((at(0.5) - 1f64.tanh()).abs() < 1e-15 && (at(-0.5) + 1f64.tanh()).abs() < 1e-15);
    }

    /// Each law parses as a term of its variable alone.
    #[test]
    fn every_law_is_a_term_of_its_variable() {
        let mut vocabulary = crate::term::Vocabulary::new();
        vocabulary.variable("h1").unwrap();
        for law in laws("h1") {
            let term = vocabulary.parse(&law).unwrap();
            assert_eq!(term.variables(), vec!["h1".to_string()], "{law}");
        }
    }
}
