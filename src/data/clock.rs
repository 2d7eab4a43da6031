//! Time stamps as a ship's logger or a data acquisition system prints them — a clock time
//! (`12:00:01.25`) or a date and time (`2026-11-27T12:00:01.25Z`, ISO 8601 / RFC 3339) — read as
//! seconds: a clock's since midnight, a date's since 1970-01-01 UTC (without a zone it is taken
//! as UTC). A run's time is only ever used relative to its own first stamp.

use chrono::{DateTime, NaiveDateTime, NaiveTime, Timelike};

/// Seconds in a year of 365.25 days.
const YEAR: f64 = 365.25 * 86_400.0;

/// What to say of a run whose time column (`name`, no unit in its header) starts at
/// `first`, a number no clock of seconds reaches: 10¹¹ s after 1970 is the year 5139, where a
/// logger's milliseconds (or micro-, nanoseconds) since 1970 read as seconds make every rate a
/// thousand (a million, a billion) times too slow. `None` below 10¹¹ or where the header
/// names its unit ([`super::seconds_per`]).
pub fn epoch_note(origin: &str, name: &str, first: f64) -> Option<String> {
    if super::seconds_per(name).is_some() || !(1e11..1e21).contains(&first.abs()) {
        return None;
    }
    let (unit, short, factor) = match first.abs() {
        v if v < 1e14 => ("milliseconds", "ms", 1e-3),
        v if v < 1e17 => ("microseconds", "us", 1e-6),
        _ => ("nanoseconds", "ns", 1e-9),
    };
    Some(format!(
        "{origin}: the time `{name}` starts at {first:.4e}, which as seconds since 1970 is the year {:.0}; as \
         {unit} since 1970 it is {:.0}: read as seconds, every rate is {} times too slow. Name the unit with the \
         time column (a header `{name} [{short}]` or `{name}_{short}`; a dataset file's `{name} = \"… [{short}]\"`) \
         and it is read in seconds",
        1970.0 + first / YEAR,
        1970.0 + first * factor / YEAR,
        crate::output::sig(1.0 / factor, 1)
    ))
}

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
    time_of_day(text)
}

/// The seconds since midnight of a stamp that is a time of day alone (`23:59:59.980`, no
/// date): such a clock starts again at midnight, which its reader counts on.
pub(super) fn time_of_day(text: &str) -> Option<f64> {
    let at = NaiveTime::parse_from_str(text.trim(), "%H:%M:%S%.f").ok()?;
    Some(f64::from(at.num_seconds_from_midnight()) + f64::from(at.nanosecond()) * 1e-9)
}

/// A day in seconds.
const DAY: f64 = 86_400.0;

/// A column of times of day read on past midnight: each reading's seconds since the first
/// reading's midnight, a day added wherever the clock falls back by over half a day (a log
/// over midnight read `23:59:59.99` then `00:00:00.00`, which refused it as a run starting
/// again).
#[derive(Clone, Debug, Default)]
pub(super) struct Midnights {
    last: Option<f64>,
    days: f64,
}

impl Midnights {
    /// `seconds` since midnight as seconds since the first reading's midnight.
    pub(super) fn read_on(&mut self, seconds: f64) -> f64 {
        if self.last.is_some_and(|last| seconds + self.days < last - DAY / 2.0) {
            self.days += DAY;
        }
        let on = seconds + self.days;
        self.last = Some(on);
        on
    }
}

fn epoch_seconds(whole: i64, nanos: u32) -> f64 {
    whole as f64 + f64::from(nanos) * 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Milliseconds, microseconds and nanoseconds since 1970 read as seconds are said, with
    /// the year each makes; seconds since 1970 (1.7e9), a header with its unit and a run of
    /// hours are not.
    #[test]
    fn a_logger_s_epoch_read_as_seconds_is_said() {
        let said = |first: f64| epoch_note("log.csv", "timestamp", first);
        assert!(said(1.7e12).unwrap().contains("is the year 55840; as milliseconds since 1970 it is 2024"));
        assert!(said(1.7e15).unwrap().contains("as microseconds since 1970 it is 2024"));
        assert!(said(1.7e18).unwrap().contains("as nanoseconds since 1970 it is 2024"));
        assert!(said(1.7e12).unwrap().contains("every rate is 1000 times too slow"));
        assert_eq!(said(1.7e9), None);
        assert_eq!(said(3600.0), None);
        assert_eq!(epoch_note("log.csv", "timestamp [ms]", 1.7e12), None);
        assert_eq!(epoch_note("log.csv", "timestamp_ms", 1.7e12), None);
    }

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
