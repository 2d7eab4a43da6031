//! Errors of the term language. Syntax and meaning errors alike carry pest's caret block
//! (line, column, the text and a `^` under the culprit), so a user sees where to look.

use super::parse::Rule;

/// An error in a term's text or meaning.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TermError {
    /// Syntax or meaning error, shown as pest's caret block with a readable message.
    #[error("{0}")]
    Invalid(Box<pest::error::Error<Rule>>),
    /// Two texts in one candidate set are the same term after canonicalisation.
    #[error("duplicate candidate term: `{first}` and `{second}` are both `{canonical}`")]
    Duplicate {
        /// The first spelling.
        first: String,
        /// The second spelling.
        second: String,
        /// Their common canonical form.
        canonical: String,
    },
    /// A name the vocabulary does not declare (raised when compiling, not parsing).
    #[error("term `{term}` uses `{name}`, which is not declared")]
    Undeclared {
        /// The term's text.
        term: String,
        /// The unknown name.
        name: String,
    },
    /// A derived variable or alias definition is inconsistent.
    #[error("{0}")]
    Declaration(String),
    /// An input the evaluator needs was not bound.
    #[error("no data for `{0}`: it is neither a column of the data nor a parameter")]
    Unbound(String),
}

impl TermError {
    /// Builds a caret error over `start..end` of `input`.
    pub(crate) fn at(input: &str, start: usize, end: usize, message: impl Into<String>) -> Self {
        let message = message.into();
        let start = start.min(input.len());
        let end = end.clamp(start, input.len());
        let err = match pest::Span::new(input, start, end) {
            Some(span) => {
                pest::error::Error::new_from_span(pest::error::ErrorVariant::CustomError { message }, span)
            }
            None => pest::error::Error::new_from_pos(
                pest::error::ErrorVariant::CustomError { message },
                pest::Position::from_start(input),
            ),
        };
        TermError::Invalid(Box::new(err))
    }

    /// Adds a file name (and key) to a caret error, for terms read from model files.
    pub fn with_path(self, path: &str) -> Self {
        match self {
            TermError::Invalid(e) => TermError::Invalid(Box::new(e.with_path(path))),
            other => other,
        }
    }

    /// The 1-based (line, column) of a caret error.
    pub fn line_col(&self) -> Option<(usize, usize)> {
        match self {
            TermError::Invalid(e) => Some(match e.line_col {
                pest::error::LineColLocation::Pos(p) => p,
                pest::error::LineColLocation::Span(p, _) => p,
            }),
            _ => None,
        }
    }
}
