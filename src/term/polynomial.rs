//! A polynomial library of candidate terms: every monomial of some names up to a degree, the
//! constant among them (SINDy's `PolynomialLibrary`), for systems whose terms nobody has
//! written down yet.

/// Every monomial of `names` of degree 0 to `degree` in graded order — `1`, then each name,
/// then each product of two (`x^2`, `x*y`, `y^2`), and so on — as term text.
///
/// ```
/// let terms = termid::term::polynomial(&["x", "y"], 2);
/// assert_eq!(terms, ["1", "x", "y", "x^2", "x*y", "y^2"]);
/// assert_eq!(termid::term::polynomial(&["x", "y", "z"], 3).len(), 20); // C(3 + 3, 3)
/// ```
pub fn polynomial<S: AsRef<str>>(names: &[S], degree: u32) -> Vec<String> {
    let mut terms = vec!["1".to_string()];
    // the exponents of each monomial of the degree before, raised one name at a time from
    // the last name raised on, so each product is made once
    let mut previous: Vec<(Vec<u32>, usize)> = vec![(vec![0; names.len()], 0)];
    for _ in 0..degree {
        let mut next = Vec::new();
        for (powers, from) in &previous {
            for k in *from..names.len() {
                let mut p = powers.clone();
                p[k] += 1;
                terms.push(text(names, &p));
                next.push((p, k));
            }
        }
        previous = next;
    }
    terms
}

/// The number of monomials [`polynomial`] makes: C(n + d, d).
pub fn polynomial_len(names: usize, degree: u32) -> u128 {
    (1..=u128::from(degree)).fold(1u128, |c, k| c.saturating_mul(names as u128 + k) / k)
}

fn text<S: AsRef<str>>(names: &[S], powers: &[u32]) -> String {
    let factors: Vec<String> = names
        .iter()
        .zip(powers)
        .filter(|(_, &p)| p > 0)
        .map(|(n, &p)| if p == 1 { n.as_ref().to_string() } else { format!("{}^{p}", n.as_ref()) })
        .collect();
    factors.join("*")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The count is the binomial C(n + d, d) and every monomial is a different term once
    /// canonical.
    #[test]
    fn each_monomial_once() {
        let names = ["x", "y", "z", "F"];
        for degree in 0..=4 {
            let terms = polynomial(&names, degree);
            assert_eq!(terms.len() as u128, polynomial_len(names.len(), degree), "degree {degree}");
            let mut vocabulary = crate::term::Vocabulary::new();
            for n in names {
                vocabulary.variable(n).unwrap();
            }
            // a duplicate (two spellings of one term) would be refused
            crate::term::parse_terms(&terms, &vocabulary).unwrap();
        }
        assert_eq!(polynomial(&names, 3)[5..9], ["x^2", "x*y", "x*z", "x*F"]);
        assert_eq!(polynomial_len(10, 3), 286);
        assert_eq!(polynomial::<&str>(&[], 3), ["1"]);
    }
}
