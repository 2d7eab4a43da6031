//! How a plain text file separates its columns, told from its header line: commas, a European
//! spreadsheet's semicolons, a tab-separated export, or the blanks a Fortran program or
//! `save -ascii` aligns its columns with (read as semicolons, so decimal commas stay numbers).

use std::io::{BufRead, Read};

/// A plain file's column separator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Separator {
    Comma,
    Semicolon,
    Tab,
    /// One or more spaces or tabs, leading and trailing ones ignored.
    Blanks,
}

impl Separator {
    /// The separator of the file whose first lines of content are `header` and `row`: the
    /// first of comma, semicolon, tab found in the header; else blanks where they part two
    /// readings or more in the row (one column's name may hold a blank: `x [m]`).
    pub(super) fn of(header: &str, row: &str) -> Separator {
        let header = header.trim();
        if header.contains(',') {
            Separator::Comma
        } else if header.contains(';') {
            Separator::Semicolon
        } else if header.contains('\t') {
            Separator::Tab
        } else if row.split_ascii_whitespace().nth(1).is_some() {
            Separator::Blanks
        } else {
            Separator::Comma
        }
    }

    /// The byte the CSV reader splits on (blanks are rewritten to semicolons as they pass).
    pub(super) fn byte(self) -> u8 {
        match self {
            Separator::Comma => b',',
            Separator::Semicolon | Separator::Blanks => b';',
            Separator::Tab => b'\t',
        }
    }

    /// Whether a comma inside a cell is a decimal comma, as a spreadsheet set to a European
    /// language writes numbers: always with semicolons; with tabs or blanks where the first
    /// row `row` has commas and no point (else `1,234` may be a thousand and more).
    pub(super) fn decimal_commas(self, row: &str) -> bool {
        match self {
            Separator::Comma => false,
            Separator::Semicolon => true,
            Separator::Tab | Separator::Blanks => row.contains(',') && !row.contains('.'),
        }
    }
}

/// A file of blank-separated columns passed on as semicolon-separated lines (each run of
/// blanks one separator, none at the ends); comment lines pass as they are.
pub(super) struct Blanks<R> {
    inner: R,
    line: Vec<u8>,
    /// The rewritten line, read from its position.
    out: std::io::Cursor<Vec<u8>>,
}

impl<R: BufRead> Blanks<R> {
    pub(super) fn new(inner: R) -> Blanks<R> {
        Blanks { inner, line: Vec::new(), out: std::io::Cursor::new(Vec::new()) }
    }
}

impl<R: BufRead> Read for Blanks<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.out.position() == self.out.get_ref().len() as u64 {
            self.line.clear();
            self.out.set_position(0);
            let out = self.out.get_mut();
            out.clear();
            if self.inner.read_until(b'\n', &mut self.line)? == 0 {
                return Ok(0);
            }
            let text = self.line.trim_ascii();
            if text.first() == Some(&b'#') {
                out.extend_from_slice(text);
            } else {
                for (i, cell) in text.split(u8::is_ascii_whitespace).filter(|c| !c.is_empty()).enumerate() {
                    if i > 0 {
                        out.push(b';');
                    }
                    out.extend_from_slice(cell);
                }
            }
            out.push(b'\n');
        }
        self.out.read(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_tells_the_separator() {
        assert_eq!(Separator::of("t,x,y\n", "0 1 2"), Separator::Comma);
        assert_eq!(Separator::of("t;x;y", "0;1,5;2"), Separator::Semicolon);
        assert_eq!(Separator::of("t\tx\ty\r\n", "0\t1\t2"), Separator::Tab);
        assert_eq!(Separator::of("   t    x   y  ", " 0.0  1.5 2"), Separator::Blanks);
        assert_eq!(Separator::of("time [s],x [m]", "0,1"), Separator::Comma);
        // one column, its name with a blank: nothing to split
        assert_eq!(Separator::of("x [m]", "1.5"), Separator::Comma);
        assert_eq!(Separator::of("x", ""), Separator::Comma);
        // decimal commas where a comma cannot part cells and no point says otherwise
        assert!(Separator::Semicolon.decimal_commas("1.5;2"));
        assert!(Separator::Tab.decimal_commas("0,5\t1,25"));
        assert!(!Separator::Tab.decimal_commas("1,234.5\t2"));
        assert!(!Separator::Blanks.decimal_commas("0.5  1.25"));
        assert!(!Separator::Comma.decimal_commas("0,5"));
    }

    #[test]
    fn blanks_become_one_separator_each() {
        let text = "  t   x\ty \n# a comment  here\n 0.0  1,5   -2e3\n\n";
        let mut out = String::new();
        Blanks::new(text.as_bytes()).read_to_string(&mut out).unwrap();
        assert_eq!(out, "t;x;y\n# a comment  here\n0.0;1,5;-2e3\n\n");
    }
}
