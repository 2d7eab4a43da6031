//! Where a key of a model file stands: the line of a dotted key path such as
//! `equations.r_dot.coefficients."u*v"` or `states[2].name`, found in the parsed document's
//! spans, so an error points at the key itself and not at the first text that looks like it.

use toml_edit::{ImDocument, Item};

/// One step of a key path.
#[derive(Debug, PartialEq)]
enum Step {
    Name(String),
    Index(usize),
}

/// `a.b."c.d"[2].e` → a, b, c.d, 2, e.
fn steps(key: &str) -> Vec<Step> {
    let mut out = Vec::new();
    let mut chars = key.chars().peekable();
    let mut name = String::new();
    let flush = |name: &mut String, out: &mut Vec<Step>| {
        if !name.is_empty() {
            out.push(Step::Name(std::mem::take(name)));
        }
    };
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                for c in chars.by_ref() {
                    if c == '"' {
                        break;
                    }
                    name.push(c);
                }
            }
            '.' => flush(&mut name, &mut out),
            '[' => {
                flush(&mut name, &mut out);
                let digits: String = chars.by_ref().take_while(|c| *c != ']').collect();
                if let Ok(i) = digits.parse() {
                    out.push(Step::Index(i));
                }
            }
            c => name.push(c),
        }
    }
    flush(&mut name, &mut out);
    out
}

/// The 1-based line of the deepest part of `key` found in `text` (0 if none is).
pub fn line_of_key(text: &str, key: &str) -> usize {
    let Ok(doc) = ImDocument::parse(text) else { return 0 };
    let mut item: &Item = doc.as_item();
    let mut at = None;
    for step in steps(key) {
        let next = match &step {
            Step::Name(n) => item.as_table_like().and_then(|t| t.get_key_value(n)).map(|(k, v)| {
                // a key's own place; an implicit table (`[a.b]` makes `a`) has none
                at = k.span().map(|r| r.start).or(at);
                v
            }),
            Step::Index(i) => item.get(*i).inspect(|v| {
                at = v.span().map(|r| r.start).or(at);
            }),
        };
        match next {
            Some(v) => item = v,
            None => break,
        }
    }
    at.map_or(0, |i| text[..i].matches('\n').count() + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_found_where_they_stand() {
        let text = "# u and x here\n[[states]]\nname = \"u\"\n[[states]]\nname = \"u\"\nmin = 2\nmax = 1\n\n[equations.r_dot]\nstate = \"r\"\ncandidates = [\"x\", \"u*v\"]\n[equations.r_dot.coefficients]\n\"u*v\" = 1.0\n\"x\" = nan\n";
        assert_eq!(line_of_key(text, "states[1].name"), 5);
        assert_eq!(line_of_key(text, "states[1]"), 4);
        assert_eq!(line_of_key(text, "equations.r_dot.coefficients.\"x\""), 14);
        assert_eq!(line_of_key(text, "equations.r_dot.candidates[1]"), 11);
        assert_eq!(line_of_key(text, "equations.r_dot.state"), 10);
        // a key that is not there: the deepest part that is
        assert_eq!(line_of_key(text, "equations.r_dot.backend"), 9);
        assert_eq!(line_of_key(text, "nothing"), 0);
        assert_eq!(
            steps("a.\"b.c\"[2].d"),
            [Step::Name("a".into()), Step::Name("b.c".into()), Step::Index(2), Step::Name("d".into())]
        );
    }
}
