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

#[cfg(test)]
mod tests {
    use super::*;

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
