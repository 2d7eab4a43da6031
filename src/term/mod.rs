//! The term language: candidate regressors written as text (`u*Δu`, `r*v^2/u`), parsed with
//! pest into a spanned [`Expr`], resolved against a [`Vocabulary`] into a canonical [`Term`]
//! (so `v*r` and `r*v` are one term), and compiled into a fast evaluator ([`Library`]).

mod canon;
mod compile;
mod error;
mod functions;
mod parse;
mod polynomial;
mod vocabulary;

pub use canon::{Atom, Monomial, Term};
pub use compile::{Library, RowScratch, Source, Tangents};
pub use error::TermError;
pub use functions::{Function, FUNCTIONS};
pub use parse::{parse_expr, BinOp, Expr, ExprKind};
pub use polynomial::{polynomial, polynomial_len};
pub use vocabulary::{code_points, is_identifier, Derived, Vocabulary};

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
