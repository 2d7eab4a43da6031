//! The term language: candidate regressors written as text (`u*Δu`, `r*v^2/u`), parsed with
//! pest into a spanned [`Expr`], resolved against a [`Vocabulary`] into a canonical [`Term`]
//! (so `v*r` and `r*v` are one term), and compiled into a fast evaluator ([`Library`]).

mod canon;
mod compile;
mod error;
mod functions;
mod laws;
mod parse;
mod polynomial;
mod vocabulary;

pub use canon::{Atom, Monomial, Term};
pub use compile::{Library, RowScratch, Source, Tangents};
pub use error::TermError;
pub use functions::{Function, FUNCTIONS};
pub use laws::{laws, odd_saturation, saturations};
pub use parse::{parse_expr, BinOp, Expr, ExprKind};
pub use polynomial::{polynomial, polynomial_len};
pub use vocabulary::{code_points, is_identifier, Derived, Vocabulary};

/// Candidate terms as a user lists them: each text split at its commas outside parentheses
/// (a term never holds one there; a call's arguments do), each trimmed, blanks dropped:
/// `["x, x*y", "atan2(y, x)"]` is three terms.
pub fn listed<S: AsRef<str>>(texts: &[S]) -> Vec<String> {
    let mut out = Vec::new();
    for text in texts {
        let (mut depth, mut from) = (0i32, 0);
        let text = text.as_ref();
        for (k, c) in text.char_indices() {
            match c {
                '(' => depth += 1,
                ')' => depth -= 1,
                ',' if depth == 0 => {
                    out.push(text[from..k].trim().to_string());
                    from = k + 1;
                }
                _ => {}
            }
        }
        out.push(text[from..].trim().to_string());
    }
    out.retain(|t| !t.is_empty());
    out
}

/// Parses and resolves a list of candidate terms, refusing a duplicate (two spellings of
/// one canonical term, e.g. `v*r` and `r*v`) with an error that names both.
///
/// ```
/// use termid::term::{parse_terms, Vocabulary};
///
/// let mut vocabulary = Vocabulary::new();
/// vocabulary.variable("u")?.variable("v")?.variable("r")?;
/// let terms = parse_terms(&["r*v^2/u", "u^2"], &vocabulary)?;
/// // canonical: the same term however it is spelt
/// assert_eq!(terms[0], vocabulary.parse("v*v*r/u")?);
/// // a typo is located with its line, column and a caret
/// let error = vocabulary.parse("u*w").unwrap_err().to_string();
/// assert!(error.contains('^') && error.contains('w'), "{error}");
/// assert!(parse_terms(&["v*r", "r*v"], &vocabulary).is_err());
/// # Ok::<(), termid::term::TermError>(())
/// ```
pub fn parse_terms<S: AsRef<str>>(texts: &[S], vocab: &Vocabulary) -> Result<Vec<Term>, TermError> {
    let mut terms: Vec<Term> = Vec::with_capacity(texts.len());
    for (i, text) in texts.iter().enumerate() {
        let term = vocab.parse(text.as_ref())?;
        if let Some(j) = terms.iter().position(|t| *t == term) {
            return Err(TermError::Duplicate {
                first: texts[j].as_ref().to_string(),
                second: texts[i].as_ref().to_string(),
                canonical: term.to_string(),
            });
        }
        terms.push(term);
    }
    Ok(terms)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_list_splits_at_commas_outside_calls() {
        assert_eq!(
            listed(&["x, x*y", "atan2(y, x)", " ", "sin(x),cos(max(x, y))"]),
            ["x", "x*y", "atan2(y, x)", "sin(x)", "cos(max(x, y))"]
        );
        // a comma too many is a blank, dropped; an unbalanced parenthesis is the parser's to locate
        assert_eq!(listed(&["x,,y,", "f(x"]), ["x", "y", "f(x"]);
    }
}
