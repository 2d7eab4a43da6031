//! Time stamps as a ship's logger or a data acquisition system prints them — a clock time
//! (`12:00:01.25`) or a date and time (`2026-11-27T12:00:01.25Z`, ISO 8601 / RFC 3339) — read as
//! seconds: a clock's since midnight, a date's since 1970-01-01 UTC (without a zone it is taken
//! as UTC). A run's time is only ever used relative to its own first stamp.

use chrono::{DateTime, NaiveDateTime, NaiveTime, Timelike};

/// The seconds a time stamp stands for; `None` for text that is no time stamp.
pub fn clock_seconds(text: &str) -> Option<f64> {
    let text = text.trim();
    // a stamp has a colon between hours and minutes; anything else is left to the caller's error
    if !text.contains(':') {
        return None;
    }
    if let Ok(at) = DateTime::parse_from_rfc3339(text) {
        return Some(epoch_seconds(at.timestamp(), at.timestamp_subsec_nanos()));
    }
    for format in ["%Y-%m-%dT%H:%M:%S%.f", "%Y-%m-%d %H:%M:%S%.f"] {
        if let Ok(at) = NaiveDateTime::parse_from_str(text, format) {
            let utc = at.and_utc();
            return Some(epoch_seconds(utc.timestamp(), utc.timestamp_subsec_nanos()));
        }
    }
    let at = NaiveTime::parse_from_str(text, "%H:%M:%S%.f").ok()?;
    Some(f64::from(at.num_seconds_from_midnight()) + f64::from(at.nanosecond()) * 1e-9)
}

fn epoch_seconds(whole: i64, nanos: u32) -> f64 {
    whole as f64 + f64::from(nanos) * 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clock_and_date_stamps_are_seconds() {
        assert_eq!(clock_seconds("12:00:01.25"), Some(43_201.25));
        assert_eq!(clock_seconds(" 00:00:00 "), Some(0.0));
        // 2026-11-27 is day 20 784 since 1970-01-01
        let day = 20_784.0 * 86_400.0;
        assert_eq!(clock_seconds("2026-11-27T12:00:01.5Z"), Some(day + 43_201.5));
        assert_eq!(clock_seconds("2026-11-27T13:00:01.5+01:00"), Some(day + 43_201.5));
        assert_eq!(clock_seconds("2026-11-27 12:00:01.5"), Some(day + 43_201.5));
        // a tenth of a second apart at 20 Hz, resolved at the epoch's magnitude
        let (a, b) = (
            clock_seconds("2026-11-27T12:00:01.05Z").unwrap(),
            clock_seconds("2026-11-27T12:00:01.10Z").unwrap(),
        );
        assert!((b - a - 0.05).abs() < 1e-6);
        for text in ["1.5", "abc", "12:61:00", "2026-13-01T00:00:00Z", ""] {
            assert_eq!(clock_seconds(text), None, "{text}");
        }
    }
}
