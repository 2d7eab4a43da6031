//! Stage one of reading a term: text → spanned [`Expr`] (pest grammar + Pratt parser).
//! Names are not looked up here; that is [`super::Vocabulary::resolve`]'s job.

use std::sync::LazyLock;

use pest::iterators::Pairs;
use pest::pratt_parser::{Assoc, Op, PrattParser};
use pest::Parser;

use super::error::TermError;

#[derive(pest_derive::Parser)]
#[grammar = "grammars/term.pest"]
struct TermParser;

static PRATT: LazyLock<PrattParser<Rule>> = LazyLock::new(|| {
    PrattParser::new()
        .op(Op::infix(Rule::add, Assoc::Left) | Op::infix(Rule::sub, Assoc::Left))
        .op(Op::infix(Rule::mul, Assoc::Left) | Op::infix(Rule::div, Assoc::Left))
        .op(Op::prefix(Rule::neg))
});

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
}

/// A parsed term before names are resolved; every node keeps its byte span in the text.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// What the node is.
    pub kind: ExprKind,
    /// Byte range in the source text.
    pub span: (usize, usize),
}

/// The node kinds of [`Expr`].
#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// A number literal.
    Num(f64),
    /// A name (variable, parameter, derived variable or alias).
    Var(String),
    /// Unary minus.
    Neg(Box<Expr>),
    /// Binary operation.
    Bin(BinOp, Box<Expr>, Box<Expr>),
    /// Integer power.
    Pow(Box<Expr>, i32),
    /// Function call, with the span of the function's name.
    Call(String, (usize, usize), Vec<Expr>),
}

fn rename(rule: &Rule) -> String {
    match rule {
        Rule::EOI => "end of term".into(),
        Rule::expr | Rule::factor => "a variable, number, function call or `(`".into(),
        Rule::add | Rule::sub | Rule::mul | Rule::div => "an operator (+ - * /)".into(),
        Rule::neg => "a sign `-`".into(),
        Rule::exponent | Rule::int => "an integer exponent".into(),
        Rule::call => "a function call".into(),
        Rule::number => "a number".into(),
        Rule::ident => "a variable or function name".into(),
        other => format!("{other:?}"),
    }
}

/// Parses a term's text into a spanned expression (syntax only).
pub fn parse_expr(input: &str) -> Result<Expr, TermError> {
    check_size(input)?;
    let mut pairs = TermParser::parse(Rule::term, input).map_err(|e| syntax_error(input, e))?;
    let expr = pairs.next().ok_or_else(|| TermError::at(input, 0, 0, "expected a term"))?;
    build(expr.into_inner(), input)
}

/// pest's error made readable: an exponent that is not an integer says so; expected rules
/// that read the same (the four operators) are listed once.
fn syntax_error(input: &str, mut e: pest::error::Error<Rule>) -> TermError {
    let at = match e.location {
        pest::error::InputLocation::Pos(p) => p,
        pest::error::InputLocation::Span((p, _)) => p,
    };
    // `u^1.5`, `u^v`, `u^(1/2)`: the failure is at or just after the exponent
    let before = &input[..at.min(input.len())];
    if let Some(caret) = before.rfind('^') {
        let exponent = &input[caret + 1..];
        let end = if exponent.trim_start().starts_with('(') {
            exponent.find(')').map_or(exponent.len(), |i| i + 1)
        } else {
            exponent.find(|c: char| c.is_whitespace() || "*/+".contains(c)).unwrap_or(exponent.len())
        };
        if before[caret + 1..].chars().all(|c| c.is_ascii_digit() || "-( ".contains(c)) {
            return TermError::at(
                input,
                caret + 1,
                caret + 1 + end,
                format!(
                    "exponents are integers (`u^2`, `u^-1`), not `{}`: for a root write `sqrt(u)` or `u*sqrt(u)`",
                    &exponent[..end]
                ),
            );
        }
    }
    // what other languages write: Python's and Fortran's `**`, a module's `np.sin`
    let after = &input[at.min(input.len())..];
    if after.starts_with('*') && before.ends_with('*') {
        return TermError::at(input, at - 1, at + 1, "powers are written `u^2`, not `u**2`".to_string());
    }
    if after.starts_with('.') && before.ends_with(|c: char| c.is_alphanumeric() || c == '_') {
        let module = before.rsplit(|c: char| !(c.is_alphanumeric() || c == '_')).next().unwrap_or_default();
        return TermError::at(
            input,
            at - module.len(),
            at + 1,
            format!(
                "`{module}.`: functions are named alone (`sin(x)`, not `np.sin(x)`): {}",
                super::functions::FUNCTIONS.iter().map(|f| f.name).collect::<Vec<_>>().join(", ")
            ),
        );
    }
    if let pest::error::ErrorVariant::ParsingError { positives, .. } = &mut e.variant {
        let mut seen = Vec::new();
        positives.retain(|r| {
            let name = rename(r);
            let new = !seen.contains(&name);
            seen.push(name);
            new
        });
    }
    TermError::Invalid(Box::new(e.renamed_rules(rename)))
}

/// Longest term text, in characters (a caret block echoes the term; no regressor is longer).
pub const MAX_LENGTH: usize = 1000;

/// Deepest nesting of parentheses and calls in one term.
pub const MAX_DEPTH: usize = 32;
/// Most operators (`+ - * / ^ ,`) in one term.
pub const MAX_OPERATORS: usize = 256;

/// Refuses a term nested deeper than [`MAX_DEPTH`] or with more than [`MAX_OPERATORS`]
/// operators before it is parsed: parsing and every later pass over the tree recurse, and a
/// pathological text would otherwise exhaust the stack (an abort, not an error). No candidate
/// regressor comes near either limit.
fn check_size(input: &str) -> Result<(), TermError> {
    // the length first: a caret error would echo the whole text
    let length = input.chars().count();
    if length > MAX_LENGTH {
        let start: String = input.chars().take(40).collect();
        return Err(TermError::Declaration(format!(
            "a term of {length} characters (`{start}…`) is longer than the {MAX_LENGTH} a term may have"
        )));
    }
    let (mut depth, mut operators) = (0usize, 0usize);
    for (i, c) in input.char_indices() {
        match c {
            '(' => {
                depth += 1;
                if depth > MAX_DEPTH {
                    return Err(TermError::at(
                        input,
                        i,
                        i + 1,
                        format!("nested more than {MAX_DEPTH} deep: write the term more simply"),
                    ));
                }
            }
            ')' => depth = depth.saturating_sub(1),
            '+' | '-' | '*' | '/' | '^' | ',' => {
                operators += 1;
                if operators > MAX_OPERATORS {
                    return Err(TermError::at(
                        input,
                        i,
                        i + 1,
                        format!(
                            "more than {MAX_OPERATORS} operators in one term: split it into several terms"
                        ),
                    ));
                }
            }
            _ => {}
        }
    }
    Ok(())
}

fn build(pairs: Pairs<'_, Rule>, input: &str) -> Result<Expr, TermError> {
    PRATT
        .map_primary(|p| primary(p, input))
        .map_prefix(|op, rhs| {
            let rhs = rhs?;
            let span = (op.as_span().start(), rhs.span.1);
            Ok(Expr { kind: ExprKind::Neg(Box::new(rhs)), span })
        })
        .map_infix(|lhs, op, rhs| {
            let (lhs, rhs) = (lhs?, rhs?);
            let bin = match op.as_rule() {
                Rule::add => BinOp::Add,
                Rule::sub => BinOp::Sub,
                Rule::mul => BinOp::Mul,
                _ => BinOp::Div,
            };
            let span = (lhs.span.0, rhs.span.1);
            Ok(Expr { kind: ExprKind::Bin(bin, Box::new(lhs), Box::new(rhs)), span })
        })
        .parse(pairs)
}

fn primary(pair: pest::iterators::Pair<'_, Rule>, input: &str) -> Result<Expr, TermError> {
    let span = (pair.as_span().start(), pair.as_span().end());
    match pair.as_rule() {
        Rule::factor => {
            let mut inner = pair.into_inner();
            let base = inner.next().ok_or_else(|| TermError::at(input, span.0, span.1, "empty factor"))?;
            let base = primary(base, input)?;
            match inner.next() {
                None => Ok(base),
                Some(exp) => {
                    let (s, e) = (exp.as_span().start(), exp.as_span().end());
                    let digits = exp.as_str().trim_matches(|c| c == '(' || c == ')').trim();
                    let k: i32 = digits.parse().map_err(|_| {
                        TermError::at(input, s, e, "exponent out of range (at most ±2147483647)")
                    })?;
                    Ok(Expr { kind: ExprKind::Pow(Box::new(base), k), span })
                }
            }
        }
        Rule::expr => build(pair.into_inner(), input),
        Rule::number => {
            let v: f64 =
                pair.as_str().parse().map_err(|_| TermError::at(input, span.0, span.1, "not a number"))?;
            if !v.is_finite() {
                return Err(TermError::at(input, span.0, span.1, "number out of range"));
            }
            Ok(Expr { kind: ExprKind::Num(v), span })
        }
        Rule::ident => Ok(Expr { kind: ExprKind::Var(pair.as_str().to_string()), span }),
        Rule::call => {
            let mut inner = pair.into_inner();
            let name =
                inner.next().ok_or_else(|| TermError::at(input, span.0, span.1, "missing function name"))?;
            let name_span = (name.as_span().start(), name.as_span().end());
            let args = inner.map(|a| build(a.into_inner(), input)).collect::<Result<Vec<_>, _>>()?;
            Ok(Expr { kind: ExprKind::Call(name.as_str().to_string(), name_span, args), span })
        }
        other => Err(TermError::at(
            input,
            span.0,
            span.1,
            format!("internal: unexpected {other:?} where a factor belongs"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precedence_and_spans() {
        let e = parse_expr("-u^2").unwrap();
        match e.kind {
            ExprKind::Neg(inner) => assert!(matches!(inner.kind, ExprKind::Pow(_, 2))),
            k => panic!("{k:?}"),
        }
        let e = parse_expr("a + b*c").unwrap();
        assert!(matches!(e.kind, ExprKind::Bin(BinOp::Add, _, _)));
        assert_eq!(e.span, (0, 7));
        assert!(parse_expr("u^-1").is_ok());
        assert!(parse_expr("u^(-2)").is_ok());
        assert!(parse_expr("Δu*δ^3").is_ok());
        assert!(parse_expr("∆u").is_ok());
    }

    #[test]
    fn pathological_nesting_and_length_are_refused_on_a_small_stack() {
        // run where a rayon worker would (2 MiB): these used to overflow the stack
        std::thread::Builder::new()
            .stack_size(2 << 20)
            .spawn(|| {
                // below the length limit, so that these limits are the ones met
                let deep = format!("{}u{}", "(".repeat(400), ")".repeat(400));
                let err = parse_expr(&deep).unwrap_err();
                assert_eq!(err.line_col(), Some((1, MAX_DEPTH + 1)), "{err}");
                assert!(err.to_string().contains("nested more than"), "{err}");
                let calls = format!("{}u{}", "sin(".repeat(150), ")".repeat(150));
                assert!(parse_expr(&calls).is_err());
                for long in [format!("u{}", "*u".repeat(400)), format!("{}u", "-".repeat(400))] {
                    let err = parse_expr(&long).unwrap_err();
                    assert!(err.to_string().contains("operators in one term"), "{err}");
                }
                // at the limits a term still parses
                let ok = format!("{}u{}", "(".repeat(MAX_DEPTH), ")".repeat(MAX_DEPTH));
                assert!(parse_expr(&ok).is_ok());
                assert!(parse_expr(&format!("u{}", "*u".repeat(MAX_OPERATORS))).is_ok());
                // a long term is refused without echoing it whole
                let err = parse_expr(&"u".repeat(100_000)).unwrap_err().to_string();
                assert!(err.contains("100000 characters") && err.len() < 200, "{err}");
                // beyond the length, nesting and operators are not what is said (nor echoed)
                let err = parse_expr(&format!("u{}", "*u".repeat(50_000))).unwrap_err().to_string();
                assert!(err.contains("100001 characters") && err.len() < 200, "{err}");
            })
            .unwrap()
            .join()
            .unwrap();
    }

    #[test]
    fn syntax_errors_have_carets() {
        for (text, col) in [("u**v", 2), ("u*(v", 5), ("u^v", 3), ("", 1), ("u v", 3)] {
            let err = parse_expr(text).unwrap_err();
            let msg = err.to_string();
            assert!(msg.contains('^'), "{text}: {msg}");
            assert_eq!(err.line_col(), Some((1, col)), "{text}: {msg}");
        }
        let msg = parse_expr("u*)").unwrap_err().to_string();
        assert!(msg.contains("expected"), "{msg}");
        assert!(!msg.contains("Rule"), "{msg}");
        // what Python writes, said in termid's words
        let msg = parse_expr("x**2").unwrap_err().to_string();
        assert!(msg.contains("powers are written `u^2`, not `u**2`"), "{msg}");
        let err = parse_expr("2*np.sin(x)").unwrap_err();
        assert!(err.to_string().contains("`np.`: functions are named alone"), "{err}");
        assert_eq!(err.line_col(), Some((1, 3)));
    }
}
