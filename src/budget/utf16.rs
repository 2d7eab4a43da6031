//! Text files written in UTF-16 with a byte-order mark (a spreadsheet's "Unicode text" export,
//! Windows PowerShell's `>`), read as the UTF-8 every reader of termid expects: they were
//! refused as binary at their first NUL byte (the high byte of every ASCII character).

use std::io::Read;

/// `inner` as UTF-8 text: transcoded where it starts with a UTF-16 byte-order mark (little- or
/// big-endian; the mark itself dropped), else its bytes as they are.
pub fn decoded<'a, R: Read + 'a>(mut inner: R) -> std::io::Result<Box<dyn Read + 'a>> {
    let mut head = [0u8; 2];
    let mut got = 0;
    while got < head.len() {
        match inner.read(&mut head[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    let big_endian = match (got, head) {
        (2, [0xFF, 0xFE]) => false,
        (2, [0xFE, 0xFF]) => true,
        _ => return Ok(Box::new(std::io::Cursor::new(head[..got].to_vec()).chain(inner))),
    };
    Ok(Box::new(Utf16 {
        inner,
        big_endian,
        raw: Vec::new(),
        out: std::io::Cursor::new(Vec::new()),
        ended: false,
    }))
}

/// A UTF-16 stream as UTF-8, decoded a piece at a time.
struct Utf16<R> {
    inner: R,
    big_endian: bool,
    /// Bytes read and not yet decoded: an odd last byte, or a high surrogate awaiting its pair.
    raw: Vec<u8>,
    /// Decoded UTF-8, given from its position.
    out: std::io::Cursor<Vec<u8>>,
    ended: bool,
}

impl<R: Read> Utf16<R> {
    /// Reads and decodes the next piece into `out`; false at the end of the stream.
    fn refill(&mut self) -> std::io::Result<bool> {
        let invalid =
            |what: &str| std::io::Error::new(std::io::ErrorKind::InvalidData, format!("UTF-16 text {what}"));
        self.out.set_position(0);
        let out = self.out.get_mut();
        out.clear();
        while out.is_empty() {
            if self.ended {
                return match self.raw.is_empty() {
                    true => Ok(false),
                    false => Err(invalid("ends inside a character")),
                };
            }
            let mut piece = [0u8; 1 << 16];
            let n = match self.inner.read(&mut piece) {
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if n == 0 {
                self.ended = true;
                continue;
            }
            self.raw.extend_from_slice(&piece[..n]);
            let unit = |p: &[u8]| match self.big_endian {
                true => u16::from_be_bytes([p[0], p[1]]),
                false => u16::from_le_bytes([p[0], p[1]]),
            };
            let mut units: Vec<u16> = self.raw.chunks_exact(2).map(unit).collect();
            // a high surrogate last waits for its pair in the next piece
            if units.last().is_some_and(|u| (0xD800..0xDC00).contains(u)) {
                units.pop();
            }
            for c in char::decode_utf16(units.iter().copied()) {
                let c = c.map_err(|e| invalid(&format!("holds an unpaired surrogate ({e})")))?;
                out.extend_from_slice(c.encode_utf8(&mut [0; 4]).as_bytes());
            }
            self.raw.drain(..2 * units.len());
        }
        Ok(true)
    }
}

impl<R: Read> Read for Utf16<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.out.position() == self.out.get_ref().len() as u64 && !self.refill()? {
            return Ok(0);
        }
        self.out.read(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A header and rows with a character beyond the basic plane (a surrogate pair), in both
    /// byte orders and read a byte at a time (pairs split across reads), come out as UTF-8;
    /// text without a mark passes unchanged; a dangling half is refused.
    #[test]
    fn utf16_with_a_mark_reads_as_utf8() {
        let text = "t\tψ [deg]\t𝑥\n0\t1,5\t2\n";
        let units: Vec<u16> = text.encode_utf16().collect();
        let little: Vec<u8> =
            [0xFF, 0xFE].into_iter().chain(units.iter().flat_map(|u| u.to_le_bytes())).collect();
        let big: Vec<u8> =
            [0xFE, 0xFF].into_iter().chain(units.iter().flat_map(|u| u.to_be_bytes())).collect();
        /// A reader that gives one byte per read.
        struct Trickle(std::vec::IntoIter<u8>);
        impl Read for Trickle {
            fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
                Ok(self.0.next().map(|b| buf[0] = b).map_or(0, |_| 1))
            }
        }
        for bytes in [little.clone(), big] {
            let mut out = String::new();
            decoded(bytes.as_slice()).unwrap().read_to_string(&mut out).unwrap();
            assert_eq!(out, text);
            let mut out = String::new();
            decoded(Trickle(bytes.into_iter())).unwrap().read_to_string(&mut out).unwrap();
            assert_eq!(out, text);
        }
        let mut out = String::new();
        decoded(text.as_bytes()).unwrap().read_to_string(&mut out).unwrap();
        assert_eq!(out, text);
        let mut out = String::new();
        decoded(&little[..little.len() - 1]).unwrap().read_to_string(&mut out).unwrap_err();
    }
}
