//! Work sizes termid refuses before allocating: a simulation, a resampled run or a set of
//! Monte-Carlo draws whose memory would exceed [`MEMORY_LIMIT`] is an error that says how
//! large it would be, not an abort of the process when the allocation fails.

/// The most memory one product of a command (a trajectory, a resampled run, the draws) may
/// take: 4 GiB, a sixth of this project's 24 GiB machines.
pub const MEMORY_LIMIT: f64 = 4.0 * (1u64 << 30) as f64;

/// Work that would not fit in [`MEMORY_LIMIT`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{what} would take {} of memory (the limit is {}); {advice}", size(*.bytes), size(MEMORY_LIMIT))]
pub struct TooLarge {
    /// What would be built, with its count ("a run of 975 000 000 samples × 16 columns").
    pub what: String,
    /// Its size in bytes.
    pub bytes: f64,
    /// What the user can change.
    pub advice: String,
}

/// Refuses `count` values of 8 bytes beyond the limit.
pub fn check_values(count: f64, what: impl FnOnce() -> String, advice: &str) -> Result<(), TooLarge> {
    let bytes = 8.0 * count;
    // NaN counts (from NaN settings) are refused too
    if bytes <= MEMORY_LIMIT {
        return Ok(());
    }
    Err(TooLarge { what: what(), bytes, advice: advice.into() })
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
}
