//! Work sizes termid refuses before allocating: a simulation, a resampled run or a set of
//! Monte-Carlo draws whose memory would exceed [`MEMORY_LIMIT`] is an error that says how
//! large it would be, not an abort of the process when the allocation fails; text inputs are
//! read within bounds, UTF-16 ones as UTF-8.

pub(crate) mod utf16;

/// The most memory one product of a command (a trajectory, a resampled run, the draws) may
/// take: 4 GiB, a sixth of this project's 24 GiB machines.
pub const MEMORY_LIMIT: f64 = 4.0 * (1u64 << 30) as f64;

/// Work that would not fit in [`memory_limit`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{what} would take {} of memory (the limit is {}{}); {advice}", size(*.bytes), size(.limit.0), .limit.1)]
pub struct TooLarge {
    /// What would be built, with its count ("a run of 975 000 000 samples × 16 columns").
    pub what: String,
    /// Its size in bytes.
    pub bytes: f64,
    /// The limit in bytes, and why it is that (empty, or ", half of the address space left
    /// under this process's limit").
    pub limit: (f64, &'static str),
    /// What the user can change.
    pub advice: String,
}

/// The memory one product may take: [`MEMORY_LIMIT`], or less where the process runs under
/// an address-space limit (`ulimit -v`, a container's): half of what that limit leaves, so a
/// refused size is an error here and not an abort in the allocator. With the reason shown.
pub fn memory_limit() -> (f64, &'static str) {
    static LIMIT: std::sync::OnceLock<(f64, &'static str)> = std::sync::OnceLock::new();
    *LIMIT.get_or_init(|| match address_space_left() {
        Some(left) if left / 2.0 < MEMORY_LIMIT => {
            (left / 2.0, ", half of the address space this process's limit (ulimit -v) leaves")
        }
        _ => (MEMORY_LIMIT, ""),
    })
}

/// The soft address-space limit less what the process already maps (Linux's /proc), if set.
fn address_space_left() -> Option<f64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits.lines().find(|l| l.starts_with("Max address space"))?;
    let soft: f64 = line["Max address space".len()..].split_whitespace().next()?.parse().ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let used_kb: f64 =
        status.lines().find(|l| l.starts_with("VmSize:"))?.split_whitespace().nth(1)?.parse().ok()?;
    Some((soft - 1024.0 * used_kb).max(0.0))
}

/// Refuses `count` values of 8 bytes beyond the limit.
pub fn check_values(count: f64, what: impl FnOnce() -> String, advice: &str) -> Result<(), TooLarge> {
    check_bytes(8.0 * count, what, advice)
}

/// Refuses `bytes` beyond the limit.
pub fn check_bytes(bytes: f64, what: impl FnOnce() -> String, advice: &str) -> Result<(), TooLarge> {
    let limit = memory_limit();
    // NaN counts (from NaN settings) are refused too
    if bytes <= limit.0 {
        return Ok(());
    }
    Err(TooLarge { what: what(), bytes, limit, advice: advice.into() })
}

/// The longest line a text input may have (a CSV row, a model file line): 1 MiB.
pub const MAX_LINE: usize = 1 << 20;

/// A text input that could not be read within bounds.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReadError {
    /// The system refused.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A NUL byte: a binary file or a device, not text.
    #[error("byte {offset} is NUL: this is not a text file")]
    Binary {
        /// Its offset.
        offset: usize,
    },
    /// A line beyond [`MAX_LINE`].
    #[error("line {line} is longer than {} (is this a text file?)", size(MAX_LINE as f64))]
    LongLine {
        /// 1-based line.
        line: usize,
    },
    /// More than the memory limit.
    #[error("the file is larger than {}: too large to read whole", size(MEMORY_LIMIT))]
    TooLarge,
    /// Not UTF-8.
    #[error("line {line} is not UTF-8 text")]
    NotUtf8 {
        /// 1-based line.
        line: usize,
    },
}

/// Reads a text file with bounds: at most [`MEMORY_LIMIT`] bytes, lines of at most
/// [`MAX_LINE`], no NUL byte; so `/dev/zero`, a binary file or an endless pipe is an error
/// after a few reads instead of memory that grows without bound.
pub fn read_text(path: &std::path::Path) -> Result<String, ReadError> {
    utf8(read_bytes(path, MAX_LINE)?)
}

/// [`read_text`] without the line limit, for text termid writes on one line whatever its
/// size (statistics files as JSON): still bounded by [`MEMORY_LIMIT`] and refused at a NUL.
pub fn read_json(path: &std::path::Path) -> Result<String, ReadError> {
    utf8(read_bytes(path, usize::MAX)?)
}

fn utf8(bytes: Vec<u8>) -> Result<String, ReadError> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let line = e.as_bytes()[..at].iter().filter(|b| **b == b'\n').count() + 1;
        ReadError::NotUtf8 { line }
    })
}

/// [`read_text`], with a file that is not UTF-8 read as Latin-1 (Windows-1252's letters and
/// signs, e.g. a degree sign in a basin's header lines); `true` when it was.
pub fn read_text_or_latin1(path: &std::path::Path) -> Result<(String, bool), ReadError> {
    let bytes = read_bytes(path, MAX_LINE)?;
    match String::from_utf8(bytes) {
        Ok(text) => Ok((text, false)),
        Err(e) => Ok((e.into_bytes().iter().map(|&b| char::from(b)).collect(), true)),
    }
}

/// The size of the file at `path` (0 for a device or a pipe, whose size is not known ahead),
/// refused beyond [`MEMORY_LIMIT`]: a file to be read whole.
pub fn file_size(path: &std::path::Path) -> Result<u64, ReadError> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() && m.len() as f64 > MEMORY_LIMIT => Err(ReadError::TooLarge),
        Ok(m) if m.is_file() => Ok(m.len()),
        _ => Ok(0),
    }
}

/// The bytes of a file, with the bounds of [`read_text`].
fn read_bytes(path: &std::path::Path, max_line: usize) -> Result<Vec<u8>, ReadError> {
    use std::io::Read;
    // UTF-16 with a byte-order mark read as UTF-8 (its NUL high bytes refused it as binary)
    let mut file = utf16::decoded(std::fs::File::open(path)?)?;
    // the file's own size up front: no copies as the buffer grows
    let size = file_size(path)?;
    let mut bytes = Vec::with_capacity(size as usize + 1);
    let mut chunk = vec![0u8; 1 << 16];
    let (mut line, mut line_start) = (1usize, 0usize);
    loop {
        let n = match file.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e.into()),
        };
        let base = bytes.len();
        let part = &chunk[..n];
        if let Some(i) = memchr::memchr(0, part) {
            return Err(ReadError::Binary { offset: base + i });
        }
        // every line break of the piece; a line too long is one whose break is too far
        // from the one before (or from the start of the line the piece goes on)
        for i in memchr::memchr_iter(b'\n', part) {
            if base + i - line_start > max_line {
                return Err(ReadError::LongLine { line });
            }
            line += 1;
            line_start = base + i + 1;
        }
        if base + n - line_start > max_line {
            return Err(ReadError::LongLine { line });
        }
        if (base + n) as f64 > MEMORY_LIMIT {
            return Err(ReadError::TooLarge);
        }
        bytes.extend_from_slice(part);
    }
    Ok(bytes)
}

/// A byte count as a person reads it: 7.8 GB, 512 MB.
pub fn size(bytes: f64) -> String {
    match bytes {
        b if b.is_nan() || b.is_infinite() => "without bound".into(),
        b if b >= 1e12 => format!("{:.1} TB", b / 1e12),
        b if b >= 1e9 => format!("{:.1} GB", b / 1e9),
        b if b >= 1e6 => format!("{:.0} MB", b / 1e6),
        b => format!("{:.0} kB", b / 1e3),
    }
}

/// A count with thin groups of three digits, as the messages print them: 975 000 000.
pub fn count(n: f64) -> String {
    if !n.is_finite() || n >= 1e15 {
        return format!("{n:.2e}");
    }
    let digits = format!("{:.0}", n.round());
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_refusals() {
        assert!(check_values(1e6, String::new, "").is_ok());
        let e =
            check_values(9.75e8 * 16.0, || "a run of 975 000 000 samples × 16 columns".into(), "shorten it")
                .unwrap_err()
                .to_string();
        assert_eq!(e, "a run of 975 000 000 samples × 16 columns would take 124.8 GB of memory (the limit is 4.3 GB); shorten it");
        assert!(check_values(f64::NAN, String::new, "").is_err());
        assert_eq!(count(975e6), "975 000 000");
        assert_eq!(count(12.0), "12");
    }

    #[test]
    fn endless_and_binary_inputs_are_refused() {
        let e = read_text(std::path::Path::new("/dev/zero")).unwrap_err();
        assert!(matches!(e, ReadError::Binary { offset: 0 }), "{e}");
        let dir = std::env::temp_dir().join(format!("termid-budget-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let long = dir.join("long.csv");
        std::fs::write(&long, format!("t,u\n0,{}\n", "1".repeat(MAX_LINE + 10))).unwrap();
        assert!(matches!(read_text(&long), Err(ReadError::LongLine { line: 2 })));
        std::fs::write(&long, b"t,u\n0,\xff\n").unwrap();
        assert!(matches!(read_text(&long), Err(ReadError::NotUtf8 { line: 2 })));
        std::fs::write(&long, "t,u\n0,1\n").unwrap();
        assert_eq!(read_text(&long).unwrap(), "t,u\n0,1\n");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
