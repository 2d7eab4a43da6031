//! Measured runs as a model basin records them: a small TOML dataset file lists the runs and
//! maps the files' own column names and units onto the model's variables, e.g.
//!
//! ```toml
//! [columns]
//! t = "time [s]"
//! "δ" = "delta [deg]"
//! r = "yawrate [deg/s]"
//! u = "u [m/s]"
//!
//! [[runs]]
//! file = "zz20_1.dat"
//! delimiter = "whitespace"   # or "comma" (default), "semicolon"
//! skip = 3                   # lines before the header
//! ```
//!
//! termid works in SI and radians inside; every conversion is stated, and a column declared in
//! radians whose values can only be degrees (beyond 2π) is refused with its file and row.
//! A leading `-` negates a column (`"δ" = "-delta [deg]"`, for a basin whose sign convention is
//! not the model's); `froude = λ` reads records of a geosim λ times larger (full scale) at the
//! model's scale; `regular_time = true` rebuilds time stamps printed with too few digits.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::stream::Table;
use super::{DataError, Frame};

/// The dataset file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dataset {
    /// Model variable → "file column [unit]".
    pub columns: BTreeMap<String, String>,
    /// Further records, read as `columns` are, for the models that name them (a propeller's
    /// thrust, which a grey-box model compares with its derived `T_P` and a polynomial one
    /// does not have): a command's model is not asked to know these names.
    #[serde(default)]
    pub extra: BTreeMap<String, String>,
    /// The files' column names in order, for files with no header row (every run's unless
    /// it names its own).
    #[serde(default)]
    pub header: Option<Vec<String>>,
    /// Where the run files are: relative to the dataset file, or absolute (default: the
    /// dataset file's own folder), `$NAME` / `${NAME}` read from the environment — records
    /// that stay where the basin put them (`folder = "${SIMMAN}/kvlcc2"`).
    #[serde(default)]
    pub folder: Option<PathBuf>,
    /// Body-frame velocities computed from the track instead of read from columns.
    #[serde(default)]
    pub track: Option<Track>,
    /// The records are of a geosim this many times larger than the model (a full-scale
    /// ship, a larger model): every column is brought to the model's scale by Froude's law,
    /// from the dimension of its unit (lengths ÷ λ, times and speeds ÷ √λ, rates × √λ).
    #[serde(default)]
    pub froude: Option<f64>,
    /// Time stamps printed with too few digits (repeated stamps, steps of uneven size) are
    /// replaced by their least-squares line over the row number: for records sampled at a
    /// fixed rate. Every run's unless it says otherwise.
    #[serde(default)]
    pub regular_time: bool,
    /// The runs.
    pub runs: Vec<RunSpec>,
}

/// `[track]`: surge and sway velocity computed from an earth-fixed track and the heading
/// (model variables, after the column map), by central differences over ± `half_window`
/// samples — for records whose logged velocities are missing or not what they say; or, with
/// `x_dot` and `y_dot`, turned into the body frame from logged earth-fixed velocities (for
/// records whose positions are printed too coarsely to differentiate).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Track {
    /// Position along the x axis.
    #[serde(default)]
    pub x: Option<String>,
    /// Position along the y axis.
    #[serde(default)]
    pub y: Option<String>,
    /// Earth-fixed velocity along the x axis (instead of the positions): a column of the
    /// file with its unit, as in `[columns]` (`"dx0 [m/s]"`).
    #[serde(default)]
    pub x_dot: Option<String>,
    /// Earth-fixed velocity along the y axis, a column of the file.
    #[serde(default)]
    pub y_dot: Option<String>,
    /// A satellite fix's latitude, a column of the file with its unit (`"lat [deg]"`): with
    /// `longitude`, the positions `x` (north) and `y` (east) are computed from it, in metres
    /// from the run's first fix ([`super::north_east`]).
    #[serde(default)]
    pub latitude: Option<String>,
    /// The fix's longitude, a column of the file with its unit.
    #[serde(default)]
    pub longitude: Option<String>,
    /// A satellite receiver's speed over ground, a column of the file with its unit
    /// (`"sog [kn]"`): with `course_over_ground`, the earth-fixed velocity (x north, y east)
    /// the surge and sway velocities are turned from, instead of `x_dot`, `y_dot` or the
    /// differenced fixes (a receiver measures it from the carrier's Doppler shift, finer
    /// than its fixes).
    #[serde(default)]
    pub speed_over_ground: Option<String>,
    /// The receiver's course over ground, a column of the file with its unit (`"cog [deg]"`),
    /// from north towards east.
    #[serde(default)]
    pub course_over_ground: Option<String>,
    /// Heading, measured from x towards y.
    pub heading: String,
    /// The surge velocity to compute.
    pub u: String,
    /// The sway velocity to compute.
    pub v: String,
    /// Samples each side of the central difference.
    #[serde(default = "two")]
    pub half_window: usize,
    /// Where the track is measured, in m forward of and to starboard of the point the model's
    /// motion is of (midship), at the records' scale: a satellite receiver's antenna, often
    /// on the bridge far aft. The positions are moved to that point by the heading, the
    /// velocities by the yaw rate (from the heading's differences): u − r·y, v + r·x at the
    /// antenna.
    #[serde(default)]
    pub antenna: Option<[f64; 2]>,
}

fn two() -> usize {
    2
}

/// Surge and sway velocity from a track and heading: the earth-fixed velocity by central
/// differences over ± `half` samples (one-sided at the ends), turned into the body frame by
/// the heading.
pub fn velocities_from_track(
    t: &[f64],
    x: &[f64],
    y: &[f64],
    heading: &[f64],
    half: usize,
) -> (Vec<f64>, Vec<f64>) {
    velocities_from_earth_fixed(&differenced(t, x, half), &differenced(t, y, half), heading)
}

/// The rate of `x` by central differences over ± `half` samples (one-sided at the ends).
fn differenced(t: &[f64], x: &[f64], half: usize) -> Vec<f64> {
    let n = t.len().min(x.len());
    let half = half.max(1);
    (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(half), (k + half).min(n - 1));
            (x[b] - x[a]) / (t[b] - t[a]).max(f64::MIN_POSITIVE)
        })
        .collect()
}

/// The rate of an angle as [`differenced`], taken the short way round (a compass's 359° → 1°
/// is 2°, not −358°).
fn rate_of(t: &[f64], angle: &[f64], half: usize) -> Vec<f64> {
    let mut turning = angle.to_vec();
    super::angle::unwrap_turns(&mut turning);
    differenced(t, &turning, half)
}

/// `$NAME` and `${NAME}` replaced by `lookup(NAME)`; the first name it does not know is the error.
/// Why a folder's `$NAME` could not be expanded.
#[derive(Debug, PartialEq)]
enum Unexpanded {
    /// The variable is not set.
    Unset(String),
    /// The text is not `$NAME` or `${NAME}`.
    Syntax(String),
}

fn expand_environment(text: &str, lookup: impl Fn(&str) -> Option<String>) -> Result<String, Unexpanded> {
    let mut out = String::new();
    let mut rest = text;
    while let Some(at) = rest.find('$') {
        out.push_str(&rest[..at]);
        let after = &rest[at + 1..];
        let (name, tail) = match after.strip_prefix('{') {
            Some(inner) => match inner.find('}') {
                Some(end) => (&inner[..end], &inner[end + 1..]),
                None => {
                    return Err(Unexpanded::Syntax(format!(
                        "`${{{inner}` has no closing brace: write ${{NAME}}"
                    )))
                }
            },
            None => {
                let end = after.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(after.len());
                (&after[..end], &after[end..])
            }
        };
        if name.is_empty() {
            out.push('$');
        } else if !name.chars().all(|c| c.is_alphanumeric() || c == '_') {
            return Err(Unexpanded::Syntax(format!(
                "`${{{name}}}`: termid reads $NAME and ${{NAME}} only, no shell forms such as ${{NAME:-default}}"
            )));
        } else {
            out.push_str(&lookup(name).ok_or_else(|| Unexpanded::Unset(name.to_string()))?);
        }
        rest = tail;
    }
    out.push_str(rest);
    Ok(out)
}

/// Earth-fixed velocities turned into the body frame by the heading.
pub fn velocities_from_earth_fixed(x_dot: &[f64], y_dot: &[f64], heading: &[f64]) -> (Vec<f64>, Vec<f64>) {
    x_dot
        .iter()
        .zip(y_dot)
        .zip(heading)
        .map(|((xd, yd), h)| {
            let (s, c) = h.sin_cos();
            (xd * c + yd * s, -xd * s + yd * c)
        })
        .unzip()
}

/// Time stamps replaced by their least-squares line over the row number. Refused (with the
/// row) where a stamp lies further from the line than rounding (to three significant digits,
/// or to the stamps' own last digit: a 100 Hz logger's time to 0.1 s) and two sample
/// intervals explain: a dropout or a change of rate, not rounding.
pub fn regular_time(t: &[f64], origin: &str, column: &str) -> Result<(Vec<f64>, f64), DataError> {
    let n = t.len();
    if n < 3 {
        return Err(DataError::TooShort {
            file: origin.into(),
            rows: n,
            needed: 3,
            what: "a regular time".into(),
        });
    }
    let nf = n as f64;
    let km = (nf - 1.0) / 2.0;
    let tm = t.iter().sum::<f64>() / nf;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (k, v) in t.iter().enumerate() {
        let dk = k as f64 - km;
        sxy += dk * (v - tm);
        sxx += dk * dk;
    }
    let step = sxy / sxx;
    let line: Vec<f64> = (0..n).map(|k| tm + step * (k as f64 - km)).collect();
    if !(step > 0.0 && step.is_finite()) {
        return Err(DataError::Unit {
            file: origin.into(),
            row: 1,
            column: column.into(),
            message: "regular_time: the time stamps do not increase along the rows".into(),
        });
    }
    let digit = super::stamps_digit(t);
    let rounding = if digit.is_finite() { 0.5 * digit } else { 0.0 };
    for (k, (v, l)) in t.iter().zip(&line).enumerate() {
        if (v - l).abs() > 0.005 * v.abs() + rounding + 2.0 * step {
            return Err(DataError::Unit {
                file: origin.into(),
                row: k + 1,
                column: column.into(),
                message: format!(
                    "regular_time: the stamp {v} is {:.3} from a regular rate of {step:.6} per row \
                     (more than rounding explains: a dropout or a change of rate)",
                    v - l
                ),
            });
        }
    }
    Ok((line, step))
}

/// One run of a dataset.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    /// The file, relative to the dataset file.
    pub file: PathBuf,
    /// Column separator.
    #[serde(default)]
    pub delimiter: Delimiter,
    /// Lines before the header (before the data where there is no header row).
    #[serde(default)]
    pub skip: usize,
    /// The column names in order, for a file with no header row.
    #[serde(default)]
    pub header: Option<Vec<String>>,
    /// Keep only samples at or after this time (the file's time in s, before any Froude scaling).
    #[serde(default)]
    pub from: Option<f64>,
    /// Keep only samples at or before this time.
    #[serde(default)]
    pub to: Option<f64>,
    /// This run's own `regular_time`.
    #[serde(default)]
    pub regular_time: Option<bool>,
    /// A column that names each row's run, where the file holds several (a long table): each
    /// of its values read as a run of its own (`FILE [by=value]`), `from`, `to` and the rest
    /// applied to each.
    #[serde(default)]
    pub by: Option<String>,
}

/// Column separators.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Delimiter {
    /// `,`
    #[default]
    Comma,
    /// `;`
    Semicolon,
    /// Runs of spaces or tabs.
    Whitespace,
}

/// Units termid converts to SI and radians: (name, factor to SI, exponents of length, time
/// and mass of the SI unit — for Froude scaling).
const UNITS: &[(&str, f64, [i32; 3])] = &[
    ("s", 1.0, [0, 1, 0]),
    ("ms", 1e-3, [0, 1, 0]),
    ("min", 60.0, [0, 1, 0]),
    // a pharmacokinetic study's hours, an epidemic's days
    ("h", 3600.0, [0, 1, 0]),
    ("d", 86400.0, [0, 1, 0]),
    ("m", 1.0, [1, 0, 0]),
    ("m/s", 1.0, [1, -1, 0]),
    ("m/s^2", 1.0, [1, -2, 0]),
    ("km/h", 1.0 / 3.6, [1, -1, 0]),
    ("kn", 1852.0 / 3600.0, [1, -1, 0]),
    ("rad", 1.0, [0, 0, 0]),
    ("rad/s", 1.0, [0, -1, 0]),
    ("rad/s^2", 1.0, [0, -2, 0]),
    ("deg", std::f64::consts::PI / 180.0, [0, 0, 0]),
    ("deg/s", std::f64::consts::PI / 180.0, [0, -1, 0]),
    ("deg/s^2", std::f64::consts::PI / 180.0, [0, -2, 0]),
    ("1/min", 1.0 / 60.0, [0, -1, 0]),
    ("1/s", 1.0, [0, -1, 0]),
    ("N", 1.0, [1, -2, 1]),
    ("N m", 1.0, [2, -2, 1]),
    ("-", 1.0, [0, 0, 0]),
    // a temperature in degrees Celsius is one in SI (a coherent derived unit): its differences
    // and rates are kelvin's, and its zero is kept, as every constant of a law in it is
    // written in it (Newton's cooling towards 20 °C, not 293.15 K)
    ("°C", 1.0, [0, 0, 0]),
    ("degC", 1.0, [0, 0, 0]),
    ("K", 1.0, [0, 0, 0]),
];

/// The factor to seconds of a time column whose header says its unit of time (`Time [ms]`,
/// `t (min)`, as loggers and spreadsheets write them): a plain file's time read in
/// milliseconds as seconds makes every rate a thousand times too slow. `None` where the header
/// names no unit, or one that is not of time.
pub fn seconds_per(header: &str) -> Option<f64> {
    match split_spec(header).1 {
        Some(unit) => unit_seconds(&unit),
        None => suffixed_seconds(header),
    }
}

/// The factor to seconds of a unit of time (`ms`, `h`, `days`, `weeks`, `yr`), of the table or
/// written as a word; `None` for a unit of anything else.
fn unit_seconds(unit: &str) -> Option<f64> {
    match UNITS.iter().find(|(n, _, _)| *n == unit) {
        Some((_, f, dims)) => (*dims == [0, 1, 0]).then_some(*f),
        None => seconds_of_unit(&unit.to_lowercase()),
    }
}

/// SI's base units and its derived units with names of their own: a header in a product or
/// quotient of them (`i [A]`, `P [W/m^2]`) holds SI values already.
const SI_SYMBOLS: &[&str] = &[
    "m", "kg", "s", "A", "K", "mol", "cd", "N", "Pa", "J", "W", "C", "V", "F", "Ω", "ohm", "Ohm", "S", "Wb",
    "T", "H", "Hz", "rad", "sr", "lm", "lx", "Bq", "Gy", "Sv", "kat", "1",
];

/// Whether `unit` is a product or quotient of SI's own symbols with powers (`A`, `V`, `W/m^2`,
/// `kg m^-3`, `N·m`, `m/s²`): a coherent SI unit, its values read as they are.
fn is_coherent_si(unit: &str) -> bool {
    let mut factors = unit.split(['/', '*', '·', ' ', '.']).filter(|f| !f.is_empty()).peekable();
    factors.peek().is_some()
        && factors.all(|f| {
            let symbol = f.split('^').next().unwrap_or(f);
            let symbol =
                symbol.trim_end_matches(|c: char| c.is_ascii_digit() || c == '-' || "²³⁻¹".contains(c));
            SI_SYMBOLS.contains(&symbol)
        })
}

/// Whether termid reads a header's unit (`x [m]`, `i [A]`): one of its table, converted, or a
/// coherent SI one, as it is. Any other (`rpm`, `mg/L`, `%`) is read as written and said so.
fn unit_is_read(unit: &str) -> bool {
    UNITS.iter().any(|(n, _, _)| *n == unit) || is_coherent_si(unit)
}

/// How a header that carries its unit is read, as it is said: the header, its bare name, and
/// its factor to SI where that is not 1, or that its unit is one termid does not convert.
pub fn read_as(header: &str, bare: &str, unit: &str, factor: f64) -> String {
    match (factor == 1.0, unit.is_empty() || unit_is_read(unit) || unit_seconds(unit).is_some()) {
        (false, _) => format!("`{header}` as {bare} in SI (× {factor:.6e})"),
        (true, true) => format!("`{header}` as {bare}"),
        // the model then holds in that unit: a rate of `w [rpm]` is per second of rpm
        (true, false) => {
            format!("`{header}` as {bare} in {unit} as written (a unit termid does not convert)")
        }
    }
}

/// Where the time column `time` is among `names`: the column of that name, else the one
/// whose header is that name with a unit of time (`t [s]`, `Time (ms)`, as loggers and
/// spreadsheets export them), whose values [`in_seconds`] reads in seconds under its header.
/// The model's time keeps its name: `--time t` reads `t [ms]` as `t` in seconds.
pub fn time_position(names: &[String], time: &str) -> Option<usize> {
    names.iter().position(|n| n == time).or_else(|| {
        let mut headed = names.iter().enumerate().filter(|(_, n)| {
            let (bare, unit, sign) = split_spec(n);
            bare == time && sign > 0.0 && unit.is_some() && seconds_per(n).is_some()
        });
        match (headed.next(), headed.next()) {
            (Some((i, _)), None) => Some(i),
            _ => None,
        }
    })
}

/// Units of time as loggers write them after a name (`timestamp_ms`, `time_us`, `t.sec`),
/// with their factor to seconds.
const TIME_SUFFIXES: [(&[&str], f64); 9] = [
    (&["s", "sec", "secs", "seconds"], 1.0),
    (&["ms", "msec", "millis"], 1e-3),
    (&["us", "µs", "μs", "usec", "micros"], 1e-6),
    (&["ns", "nsec", "nanos"], 1e-9),
    (&["min", "mins", "minutes"], 60.0),
    (&["h", "hr", "hrs", "hour", "hours"], 3600.0),
    (&["d", "day", "days"], 86400.0),
    // an ecologist's weekly counts, a census's years (the Julian year, 365.25 days)
    (&["wk", "week", "weeks"], 604800.0),
    (&["yr", "year", "years"], 31_557_600.0),
];

/// The factor to seconds of a unit of time written as a word (`h`, `min`, `days`, `ms`);
/// `None` for any other word.
pub fn seconds_of_unit(word: &str) -> Option<f64> {
    TIME_SUFFIXES.iter().find(|(names, _)| names.contains(&word)).map(|(_, f)| *f)
}

/// The factor to seconds of a time header whose last word, after `_`, `.`, `-` or a space,
/// is a unit of time (`timestamp_ms`: a logger's milliseconds, read as seconds a thousand
/// times too slow), or that is such a word of three letters or more alone (`day`, `hours`: an
/// epidemic's day count read as seconds); `None` otherwise (`t`, `time`, `elapsed`,
/// `time_of_day`).
fn suffixed_seconds(header: &str) -> Option<f64> {
    let unit = match header.trim().rsplit_once(['_', '.', '-', ' ']) {
        // `time_of_day`, `hour_of_day`: a time of day, not a count of days
        Some((name, _))
            if name.rsplit(['_', '.', '-', ' ']).next().is_some_and(|w| w.eq_ignore_ascii_case("of")) =>
        {
            return None
        }
        Some((name, unit)) if !name.trim().is_empty() => unit,
        // a header that is a unit's word alone (`days`, `hours`: a day count), not an
        // abbreviation (`ms`, `h`, `d` may name anything)
        _ if header.trim().chars().count() > 2 => header.trim(),
        _ => return None,
    };
    seconds_of_unit(&unit.to_lowercase())
}

/// A time column's values in seconds, where its header `name` says another unit of time
/// (`Time [ms]`, `t (min)`): what a plain file or a Python run is read with.
pub fn in_seconds(name: &str, mut values: Vec<f64>) -> Vec<f64> {
    if let Some(factor) = seconds_per(name).filter(|f| *f != 1.0) {
        values.iter_mut().for_each(|v| *v *= factor);
    }
    values
}

/// Times in seconds as a column headed `name` holds them (ms under `Time [ms]`): what a frame
/// writes and a Python run gives, so that reading them back ([`in_seconds`]) gives the same
/// seconds.
pub fn from_seconds(name: &str, mut seconds: Vec<f64>) -> Vec<f64> {
    if let Some(factor) = seconds_per(name).filter(|f| *f != 1.0) {
        seconds.iter_mut().for_each(|v| *v /= factor);
    }
    seconds
}

/// "column [unit]" or "column (unit)" with a unit termid knows → (column, unit, sign): a
/// leading `-` negates the column.
fn split_spec(spec: &str) -> (String, Option<String>, f64) {
    let spec = spec.trim();
    let (spec, sign) = match spec.strip_prefix('-') {
        Some(rest) => (rest.trim_start(), -1.0),
        None => (spec, 1.0),
    };
    match spec.rsplit_once('[') {
        Some((col, unit)) if unit.trim_end().ends_with(']') => {
            (col.trim().to_string(), Some(unit.trim_end().trim_end_matches(']').trim().to_string()), sign)
        }
        // in parentheses only a unit termid knows, or SI's or a unit of time's after a space
        // (`Current (A)`, `t (days)`): `f(x)`, `g(T)` stay names
        _ => match spec.strip_suffix(')').and_then(|s| s.rsplit_once('(')) {
            Some((col, unit))
                if !col.trim().is_empty()
                    && (UNITS.iter().any(|(n, _, _)| *n == unit.trim())
                        || (col.ends_with(char::is_whitespace)
                            && (is_coherent_si(unit.trim()) || unit_seconds(unit.trim()).is_some()))) =>
            {
                (col.trim().to_string(), Some(unit.trim().to_string()), sign)
            }
            _ => (spec.trim().to_string(), None, sign),
        },
    }
}

/// Renames the headers that carry their unit (`Time [s]`, `x [m]`, as spreadsheets and
/// loggers export them) to their bare names, so the mapping names them as any column, and
/// returns each such column's unit; a header whose bare name another header has keeps its
/// whole text.
fn bare_headers(names: &mut [String]) -> BTreeMap<String, String> {
    let mut units = BTreeMap::new();
    for (i, bare, unit) in unit_headers(names) {
        names[i] = bare.clone();
        units.insert(bare, unit);
    }
    units
}

/// The headers that carry their unit (`x [m]`, `ψ (deg)`): each one's place, bare name and
/// unit, where no other header has its bare name (`x [m]` beside an `x` is a name of its own).
fn unit_headers(names: &[String]) -> Vec<(usize, String, String)> {
    let split: Vec<Option<(String, String)>> = names
        .iter()
        .map(|n| match split_spec(n) {
            (bare, Some(unit), sign) if sign > 0.0 && !bare.is_empty() => Some((bare, unit)),
            _ => None,
        })
        .collect();
    let taken = |bare: &str, own: usize| {
        names
            .iter()
            .enumerate()
            .any(|(i, n)| i != own && (n == bare || split[i].as_ref().is_some_and(|(b, _)| b == bare)))
    };
    split
        .iter()
        .enumerate()
        .filter_map(|(i, s)| s.clone().filter(|(bare, _)| !taken(bare, i)).map(|(b, u)| (i, b, u)))
        .collect()
}

/// A plain file's headers read by their bare names in SI, as a dataset file maps them: each
/// one's place, bare name, unit and factor to SI. A unit of termid's table is converted, a
/// coherent SI one (`i [A]`) read as it is, any other in brackets (`w [rpm]`, `C [mg/L]`) read
/// as written, factor 1 ([`read_as`] says so): a model of them holds in those units, where
/// refusing them refused every field's logger. None of time: a time column keeps its header,
/// whose unit the time is read in ([`in_seconds`]).
pub fn headers_in_si(names: &[String]) -> Vec<(usize, String, String, f64)> {
    unit_headers(names)
        .into_iter()
        .filter(|(_, _, unit)| unit_seconds(unit).is_none())
        .map(|(i, bare, unit)| {
            let f = UNITS.iter().find(|(n, _, _)| *n == unit).map_or(1.0, |(_, f, _)| *f);
            (i, bare, unit, f)
        })
        .collect()
}

/// A mapping's column, unit and sign, the unit from the file's header where the mapping
/// gives none; a mapping whose unit is not the header's is refused. A header kept whole
/// (`x [m]` beside an `x`) is named by its whole text, the unit its own.
fn spec_with_header_unit(
    spec: &str,
    names: &[String],
    header_units: &BTreeMap<String, String>,
    origin: &str,
) -> Result<(String, Option<String>, f64), DataError> {
    let (col, unit, sign) = split_spec(spec);
    // a header kept whole (its bare name shared) is named by its whole text
    let whole = spec.trim().trim_start_matches('-').trim_start();
    if names.iter().any(|n| n == whole) && col != whole {
        return Ok((whole.to_string(), unit, sign));
    }
    match (unit, header_units.get(&col)) {
        (Some(unit), Some(header)) if unit != *header => Err(DataError::Unit {
            file: origin.into(),
            row: 0,
            column: col,
            message: format!("the dataset file reads it in [{unit}], the file's header says [{header}]"),
        }),
        (None, Some(header)) => Ok((col, Some(header.clone()), sign)),
        (unit, _) => Ok((col, unit, sign)),
    }
}

impl Dataset {
    /// Whether its runs are tracked over ground (a satellite receiver: `[track] latitude` or
    /// `speed_over_ground`): their velocities are the body's over the earth, with any current
    /// it moves in.
    pub fn over_ground(&self) -> bool {
        self.track.as_ref().is_some_and(|t| t.latitude.is_some() || t.speed_over_ground.is_some())
    }

    /// Reads a dataset file.
    pub fn load(path: &Path) -> Result<Dataset, DataError> {
        let file = path.display().to_string();
        let text = crate::budget::read_text(path)
            .map_err(|e| DataError::Io { file: file.clone(), message: e.to_string() })?;
        let ds: Dataset = toml::from_str(&text).map_err(|e| DataError::Io {
            file: file.clone(),
            message: crate::contain::toml_message(&e, &text),
        })?;
        ds.check().map_err(|message| DataError::Io { file, message })?;
        Ok(ds)
    }

    /// What the schema cannot say: one file column per model variable, a sensible window.
    fn check<'a>(&'a self) -> Result<(), String> {
        let mut seen: BTreeMap<String, String> = BTreeMap::new();
        if self.extra.keys().any(|v| v.trim().is_empty()) {
            return Err("`extra` maps a column onto an empty name: give the variable's name".into());
        }
        if let Some(var) = self.extra.keys().find(|v| self.columns.contains_key(*v)) {
            return Err(format!("`{var}` is in both `columns` and `extra`: one variable, one column"));
        }
        let keyed = |table: &'static str, map: &'a BTreeMap<String, String>| {
            map.iter().map(move |(v, s)| (format!("{table}.{v}"), s))
        };
        for (key, spec) in keyed("columns", &self.columns).chain(keyed("extra", &self.extra)) {
            let (column, _, _) = split_spec(spec);
            if let Some(first) = seen.insert(column.clone(), key.clone()) {
                return Err(format!(
                    "`{first}` and `{key}` both read the file column `{column}`: one column is one variable"
                ));
            }
        }
        if let Some(t) = &self.track {
            if !(1..=1000).contains(&t.half_window) {
                return Err(format!(
                    "`track.half_window = {}`: the central difference takes 1 to 1000 samples each side (default 2)",
                    t.half_window
                ));
            }
        }
        Ok(())
    }

    /// The folder the run files are read from, for a dataset file at `path`.
    pub fn folder(&self, path: &Path) -> Result<PathBuf, DataError> {
        let own = path.parent().unwrap_or(Path::new("."));
        let Some(folder) = &self.folder else { return Ok(own.to_path_buf()) };
        let text = folder.to_string_lossy();
        let expanded =
            expand_environment(&text, |name| std::env::var(name).ok()).map_err(|why| DataError::Io {
                file: path.display().to_string(),
                message: match why {
                    Unexpanded::Unset(name) => format!(
                        "`folder = \"{text}\"` names the environment variable {name}, which is not set: \
                         set it to the folder of the records ({name}=/path/to/records termid …)"
                    ),
                    Unexpanded::Syntax(m) => format!("`folder = \"{text}\"`: {m}"),
                },
            })?;
        Ok(own.join(expanded))
    }

    /// Reads every run into frames named by model variable, in SI units and radians; `time`
    /// is the model's time variable. Returns the frames and one line per conversion made.
    pub fn read(&self, base: &Path, time: &str) -> Result<(Vec<Frame>, Vec<String>), DataError> {
        let mut notes = Vec::new();
        let mut frames = Vec::new();
        for run in &self.runs {
            let path = base.join(&run.file);
            let origin = path.display().to_string();
            let table = self.table_of(run, &path, &origin, &mut notes)?;
            let parts = match &run.by {
                Some(by) => {
                    let (parts, note) = super::long::split(table, by, &origin)?;
                    notes.push(note);
                    parts.into_iter().map(|(origin, table, rows)| (origin, table, Some(rows))).collect()
                }
                None => {
                    super::long::refuse_interleaved(&table, &origin)?;
                    vec![(origin.clone(), table, None)]
                }
            };
            for (origin, table, rows) in parts {
                let at_file = |e: DataError| match &rows {
                    Some(rows) => e.at_file_rows(rows),
                    None => e,
                };
                let (mut frame, file_time) =
                    self.frame_of(run, table, &origin, time, &mut notes).map_err(at_file)?;
                if let Some(rows) = rows {
                    frame = frame.at_file_rows(rows);
                }
                if run.from.is_some() || run.to.is_some() {
                    let t = &file_time;
                    let lo = run.from.map_or(0, |a| t.iter().position(|v| *v >= a).unwrap_or(t.len()));
                    let hi = run.to.map_or(t.len(), |b| t.iter().rposition(|v| *v <= b).map_or(0, |i| i + 1));
                    if hi <= lo + 2 {
                        return Err(DataError::TooShort {
                            file: origin.clone(),
                            rows: hi.saturating_sub(lo),
                            needed: 3,
                            what: "the trimmed window".into(),
                        });
                    }
                    notes.push(format!(
                        "{origin}: trimmed to {} ≤ t ≤ {} ({} of {} samples)",
                        t[lo],
                        t[hi - 1],
                        hi - lo,
                        t.len()
                    ));
                    frame = frame.slice(lo..hi);
                }
                // a logging dropout would be integrated or differentiated across as if the
                // motion in it were a line: each piece a run, less the rows a track's
                // differences across the gap spoiled
                let margin = self.track.as_ref().map_or(0, |t| t.half_window);
                let (pieces, said) = super::cut_at_gaps(frame, margin)?;
                notes.extend(said);
                frames.extend(pieces);
            }
        }
        Ok((frames, notes))
    }

    /// A run's file as a table: its numeric columns, its columns of text and, where the run
    /// names a column `by`, each row's label.
    fn table_of(
        &self,
        run: &RunSpec,
        path: &Path,
        origin: &str,
        notes: &mut Vec<String>,
    ) -> Result<Table, DataError> {
        Ok(if super::stream::is_columnar(path) {
            // columnar files name their own columns
            super::csv_io::read_table(path, run.by.as_deref())?
        } else {
            let (text, latin1) = crate::budget::read_text_or_latin1(path)
                .map_err(|e| DataError::Io { file: origin.into(), message: e.to_string() })?;
            if latin1 {
                notes.push(format!("{origin}: not UTF-8, read as Latin-1 (Windows-1252)"));
            }
            let header = run.header.as_ref().or(self.header.as_ref()).map(|h| h.join(","));
            let body: Vec<&str> = text.lines().skip(run.skip).collect();
            let csv: String = header
                .iter()
                .cloned()
                .chain(body.iter().map(|l| match run.delimiter {
                    Delimiter::Comma => l.to_string(),
                    // a semicolon-separated file is a European spreadsheet's: its commas
                    // are decimal commas
                    Delimiter::Semicolon => l.replace(',', ".").replace(';', ","),
                    Delimiter::Whitespace => l.split_whitespace().collect::<Vec<_>>().join(","),
                }))
                .collect::<Vec<_>>()
                .join("\n");
            super::csv_io::parse_table(&csv, origin, run.by.as_deref())?
        })
    }

    /// A run's frame from its file's table (the file's rows, or one label's): its columns
    /// mapped onto the model's variables in SI at the model's scale, with the file's time in
    /// s (before any Froude scaling) for the run's window.
    fn frame_of(
        &self,
        run: &RunSpec,
        table: Table,
        origin: &str,
        time: &str,
        notes: &mut Vec<String>,
    ) -> Result<(Frame, Vec<f64>), DataError> {
        let origin = origin.to_string();
        let Table { mut names, mut columns, mut text, .. } = table;
        let header_units = bare_headers(&mut names);
        let mut text_names: Vec<String> = text.iter().map(|t| t.0.clone()).collect();
        bare_headers(&mut text_names);
        text.iter_mut().zip(text_names).for_each(|(t, bare)| t.0 = bare);
        let (time_col, time_unit, _) = spec_with_header_unit(
            self.columns.get(time).map_or(time, String::as_str),
            &names,
            &header_units,
            &origin,
        )?;
        if let Some((_, cell)) = text.iter().find(|(n, _)| *n == time_col) {
            return Err(DataError::text_column(&origin, &time_col, cell));
        }
        let Some(time_index) = names.iter().position(|h| *h == time_col) else {
            return Err(DataError::MissingColumn {
                file: origin.clone(),
                column: time_col.clone(),
                available: names.join(", "),
            });
        };
        let stamps = std::mem::take(&mut columns[time_index]);
        let stamps = if run.regular_time.unwrap_or(self.regular_time) {
            let (line, step) = regular_time(&stamps, &origin, &time_col)?;
            notes.push(format!(
                "{origin}: time stamps replaced by a regular rate of {step:.6} per row (largest change {:.3})",
                stamps.iter().zip(&line).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
            ));
            line
        } else {
            stamps
        };
        let mut raw = Frame::new(&origin, &time_col, stamps)
            .map_err(|e| super::csv_io::repeated_row(e, &columns, time_index))?;
        for (name, values) in names.iter().zip(columns).filter(|(n, _)| **n != time_col) {
            raw.push(name, values)?;
        }
        // a column the dataset maps that holds text is refused with its first cell
        raw.text = text;
        let scale = |unit: Option<&str>, column: &str| -> Result<f64, DataError> {
            let Some(lambda) = self.froude else { return Ok(1.0) };
            froude_factor(lambda, unit, &origin, column)
        };
        // a logger's unit after the name (`timestamp_ms`) where none is given in brackets
        let time_factor = match time_unit.as_deref() {
            None => suffixed_seconds(&time_col).unwrap_or(1.0),
            unit => factor(unit, &origin, time)?,
        };
        let time_scale = scale(time_unit.as_deref(), &time_col)?;
        // the file's time in s, for `from` and `to`
        let file_time: Vec<f64> = raw.time().iter().map(|t| t * time_factor).collect();
        let mut frame = Frame::new(&origin, time, file_time.iter().map(|t| t * time_scale).collect())?;
        if let Some(lambda) = self.froude {
            notes.push(format!(
                "{origin}: Froude-scaled from a geosim {lambda} times larger (lengths ÷ {lambda}, times ÷ {:.4}, rates × {:.4})",
                lambda.sqrt(),
                lambda.sqrt()
            ));
        }
        // one column of the file in SI at the model's scale, with the conversions said
        let mut convert = |spec: &str, var: &str| -> Result<Vec<f64>, DataError> {
            let (col, unit, sign) = spec_with_header_unit(spec, &names, &header_units, &origin)?;
            let values = raw.require(&col)?;
            if unit.as_deref() == Some("rad") {
                if let Some((i, v)) =
                    values.iter().enumerate().find(|(_, v)| v.abs() > 2.0 * std::f64::consts::PI)
                {
                    return Err(DataError::Unit {
                        file: origin.clone(),
                        row: i + 1,
                        column: col.clone(),
                        message: format!(
                            "declared [rad] but reaches {v}: that can only be degrees; declare [deg]"
                        ),
                    });
                }
            }
            let f = factor(unit.as_deref(), &origin, &col)?;
            if f != 1.0 {
                notes.push(format!(
                    "{origin}: `{col}` [{}] → {var} in SI (× {f:.6e})",
                    unit.as_deref().unwrap_or("")
                ));
            }
            if sign < 0.0 {
                notes.push(format!("{origin}: `{col}` negated → {var}"));
            }
            let f = sign * f * scale(unit.as_deref(), &col)?;
            Ok(values.iter().map(|v| v * f).collect())
        };
        for (var, spec) in self.columns.iter().chain(&self.extra).filter(|(v, _)| v.as_str() != time) {
            let values = convert(spec, var)?;
            frame.push(var, values)?;
        }
        if let Some(track) = &self.track {
            // a satellite fix: the positions in m north and east of the run's first
            let mut said = None;
            match (&track.latitude, &track.longitude, &track.x, &track.y) {
                (None, None, _, _) => {}
                (Some(lat), Some(lon), Some(x), Some(y)) => {
                    let (north, east) = super::north_east(&convert(lat, "latitude")?, &convert(lon, "longitude")?);
                    let f = scale(Some("m"), x)?;
                    frame.push(x, north.iter().map(|v| v * f).collect())?;
                    frame.push(y, east.iter().map(|v| v * f).collect())?;
                    said = Some(format!(
                        "{origin}: {x} and {y} in m north and east of the first fix ({lat}, {lon}), on the plane touching the WGS-84 ellipsoid there"
                    ));
                }
                _ => {
                    return Err(DataError::Unit {
                        file: origin.clone(),
                        row: 0,
                        column: track.heading.clone(),
                        message: "[track] takes latitude and longitude together, with x and y to name the positions they give (x north, y east)".into(),
                    })
                }
            }
            let heading = frame.require(&track.heading)?.to_vec();
            // the antenna's offset at the model's scale, and the point's track from its
            let antenna = match track.antenna {
                Some([ax, ay]) if ax.is_finite() && ay.is_finite() => {
                    let f = scale(Some("m"), &track.heading)?;
                    Some((ax * f, ay * f))
                }
                Some(a) => {
                    return Err(DataError::Unit {
                        file: origin.clone(),
                        row: 0,
                        column: track.heading.clone(),
                        message: format!(
                            "[track] antenna = {a:?}: two finite numbers, m forward and to starboard"
                        ),
                    })
                }
                None => None,
            };
            let mut moved_note = None;
            if let (Some((ax, ay)), Some(x), Some(y)) = (antenna, &track.x, &track.y) {
                if let (Some(xs), Some(ys)) = (frame.column(x), frame.column(y)) {
                    let (sn_cs, n) = (heading.iter().map(|h| h.sin_cos()), xs.len().min(ys.len()));
                    let (mx, my): (Vec<f64>, Vec<f64>) = xs[..n]
                        .iter()
                        .zip(&ys[..n])
                        .zip(sn_cs)
                        .map(|((px, py), (sn, cs))| (px - (ax * cs - ay * sn), py - (ax * sn + ay * cs)))
                        .unzip();
                    frame.set(x, mx)?;
                    frame.set(y, my)?;
                    moved_note = Some(format!(
                        "{origin}: the track ({x}, {y}) moved from the antenna, {ax} m forward and {ay} m to starboard, to the model's point by {}",
                        track.heading
                    ));
                }
            }
            let col = |n: &str| frame.require(n).map(<[f64]>::to_vec);
            // a receiver's Doppler velocity over ground, where given
            let doppler = match (&track.speed_over_ground, &track.course_over_ground) {
                (None, None) => None,
                (Some(sog), Some(cog)) if track.x_dot.is_none() && track.y_dot.is_none() => {
                    Some((sog, cog, convert(sog, "speed over ground")?, convert(cog, "course over ground")?))
                }
                _ => {
                    return Err(DataError::Unit {
                        file: origin.clone(),
                        row: 0,
                        column: track.heading.clone(),
                        message: "[track] takes speed_over_ground and course_over_ground together, and not with x_dot and y_dot".into(),
                    })
                }
            };
            // velocities measured (at the antenna), not differenced from the moved track
            let measured = doppler.is_some() || track.x_dot.is_some();
            let (u, v) = match (doppler, &track.x, &track.y, &track.x_dot, &track.y_dot) {
                (Some((sog, cog, speed, course)), ..) => {
                    notes.push(format!(
                        "{origin}: {} and {} turned into the body frame from the velocity over ground ({sog}, {cog}) by {}",
                        track.u, track.v, track.heading
                    ));
                    let north: Vec<f64> = speed.iter().zip(&course).map(|(s, c)| s * c.cos()).collect();
                    let east: Vec<f64> = speed.iter().zip(&course).map(|(s, c)| s * c.sin()).collect();
                    velocities_from_earth_fixed(&north, &east, &heading)
                }
                (None, Some(x), Some(y), None, None) => {
                    notes.push(format!(
                        "{origin}: {} and {} computed from the track ({x}, {y}) and {} over ±{} samples",
                        track.u, track.v, track.heading, track.half_window
                    ));
                    velocities_from_track(frame.time(), &col(x)?, &col(y)?, &heading, track.half_window)
                }
                (None, None, None, Some(xd), Some(yd)) => {
                    let (xd_values, yd_values) = (convert(xd, "ẋ")?, convert(yd, "ẏ")?);
                    notes.push(format!(
                        "{origin}: {} and {} turned into the body frame from ({xd}, {yd}) by {}",
                        track.u, track.v, track.heading
                    ));
                    velocities_from_earth_fixed(&xd_values, &yd_values, &heading)
                }
                _ => {
                    return Err(DataError::Unit {
                        file: origin.clone(),
                        row: 0,
                        column: track.heading.clone(),
                        message: "[track] takes either the positions x and y or the earth-fixed velocities x_dot and y_dot".into(),
                    })
                }
            };
            // velocities measured at the antenna (not differenced from the moved track):
            // the ship's turning moves it, u_a = u − r·y_a, v_a = v + r·x_a
            let (u, v) = match antenna {
                Some((ax, ay)) if measured => {
                    let r = rate_of(frame.time(), &heading, track.half_window);
                    notes.push(format!(
                        "{origin}: {} and {} moved from the antenna ({ax} m forward, {ay} m to starboard) to the model's point by the heading's rate",
                        track.u, track.v
                    ));
                    (
                        u.iter().zip(&r).map(|(u, r)| u + r * ay).collect(),
                        v.iter().zip(&r).map(|(v, r)| v - r * ax).collect(),
                    )
                }
                _ => (u, v),
            };
            frame.set(&track.u, u)?;
            frame.set(&track.v, v)?;
            notes.extend(said);
            notes.extend(moved_note);
            if antenna.is_none() && (track.latitude.is_some() || track.speed_over_ground.is_some()) {
                notes.push(format!(
                    "{origin}: the receiver's fixes taken as of the model's point (midship): an antenna elsewhere (on the bridge, far aft) moves the sway velocity by the yaw rate times its distance, which the hull's derivatives then absorb; `[track] antenna = [forward, starboard]` in m moves them"
                ));
            }
        }
        Ok((frame, file_time))
    }
}

/// Whether a cell names a unit termid knows (`m/s`, `[deg]`, `(s)`): a row of them is a
/// second header row, not data.
pub(super) fn is_unit(cell: &str) -> bool {
    let cell = cell.trim();
    let bare = cell.trim_start_matches(['[', '(']).trim_end_matches([']', ')']);
    // a bare cell only of termid's table: a label column's `A`, `B` (treatment groups) is
    // no row of amperes; in brackets any unit, in parentheses SI's own or time's
    UNITS.iter().any(|(n, _, _)| *n == bare)
        || (cell.starts_with('[') && cell.ends_with(']'))
        || (cell.starts_with('(')
            && cell.ends_with(')')
            && (is_coherent_si(bare) || unit_seconds(bare).is_some()))
}

fn unit_row(
    unit: &str,
    origin: &str,
    column: &str,
) -> Result<&'static (&'static str, f64, [i32; 3]), DataError> {
    UNITS.iter().find(|(n, _, _)| *n == unit).ok_or_else(|| DataError::Unit {
        file: origin.into(),
        row: 0,
        column: column.into(),
        message: format!(
            "unknown unit [{unit}] (known: {})",
            UNITS.iter().map(|(n, _, _)| *n).collect::<Vec<_>>().join(", ")
        ),
    })
}

fn factor(unit: Option<&str>, origin: &str, column: &str) -> Result<f64, DataError> {
    let Some(u) = unit else { return Ok(1.0) };
    Ok(unit_row(u, origin, column)?.1)
}

/// The factor from a geosim λ times larger to the model, for a column of this unit: Froude's
/// law keeps u²/(gL) and the density, so lengths go as λ, times as √λ, masses as λ³.
fn froude_factor(lambda: f64, unit: Option<&str>, origin: &str, column: &str) -> Result<f64, DataError> {
    if !(lambda > 0.0 && lambda.is_finite()) {
        return Err(DataError::Unit {
            file: origin.into(),
            row: 0,
            column: column.into(),
            message: format!("froude = {lambda}: the scale must be a positive number"),
        });
    }
    let Some(u) = unit else {
        return Err(DataError::Unit {
            file: origin.into(),
            row: 0,
            column: column.into(),
            message: "Froude scaling needs every column's unit ([-] for a number without one)".into(),
        });
    };
    let [l, t, m] = unit_row(u, origin, column)?.2;
    Ok(lambda.powi(-l) * lambda.sqrt().powi(-t) * lambda.powi(-3 * m))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) {
        std::fs::write(dir.join(name), text).unwrap();
    }

    /// A semicolon-separated file with decimal commas, as a European spreadsheet writes it.
    #[test]
    fn semicolons_with_decimal_commas() {
        let dir = std::env::temp_dir().join(format!("termid-semicolon-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write(&dir, "e.csv", "Zeit;Ruder\n0;1,5\n0,5;-2,25\n");
        let text = "[columns]\nt = \"Zeit [s]\"\n\"δ\" = \"Ruder [rad]\"\n[[runs]]\nfile = \"e.csv\"\ndelimiter = \"semicolon\"\n";
        let set: Dataset = toml::from_str(text).unwrap();
        let (frames, _) = set.read(&dir, "t").unwrap();
        assert_eq!(frames[0].time(), [0.0, 0.5]);
        assert_eq!(frames[0].column("δ").unwrap(), [1.5, -2.25]);
    }

    /// Headers that carry their unit, as spreadsheets export them: named by their bare name,
    /// the unit read from the header where the mapping gives none, a mapping that says
    /// another unit refused; a bare name two headers share keeps each header's whole text.
    /// A time column's header that says its unit of time: read in seconds, and written back in
    /// its unit (what is read back is the same seconds); a header of another unit, or none, or
    /// a name with parentheses that hold no unit, is read as it is.
    /// A header's unit beyond termid's table: SI's own (`i [A]`, `P [W/m^2]`, `Current (A)`)
    /// read as it is, any other in brackets (`w [rpm]`, `C [mg/L]`, `SOC [%]`) read as written
    /// and said so, where both were refused; units of time beyond hours (weeks, years) read
    /// in seconds and never renamed; a name's own parentheses (`f(x)`, `g(T)`) stay a name.
    #[test]
    fn a_unit_beyond_the_table_is_read_as_written_and_said() {
        let names: Vec<String> =
            ["t [weeks]", "i [A]", "P [W/m^2]", "Current (A)", "w [rpm]", "C [mg/L]", "SOC [%]", "g(T)"]
                .map(String::from)
                .to_vec();
        let read = headers_in_si(&names);
        let bare: Vec<(&str, f64)> = read.iter().map(|(_, b, _, f)| (b.as_str(), *f)).collect();
        assert_eq!(bare, [("i", 1.0), ("P", 1.0), ("Current", 1.0), ("w", 1.0), ("C", 1.0), ("SOC", 1.0)]);
        let said: Vec<String> = read.iter().map(|(i, b, u, f)| read_as(&names[*i], b, u, *f)).collect();
        assert_eq!(said[0], "`i [A]` as i");
        assert_eq!(said[3], "`w [rpm]` as w in rpm as written (a unit termid does not convert)");
        assert_eq!(read_as("v [kn]", "v", "kn", 1852.0 / 3600.0), "`v [kn]` as v in SI (× 5.144444e-1)");
        assert_eq!(seconds_per("t [weeks]"), Some(604800.0));
        assert_eq!(seconds_per("t (yr)"), Some(31_557_600.0));
        assert_eq!(seconds_per("year"), Some(31_557_600.0));
        assert_eq!(split_spec("g(T)"), ("g(T)".to_string(), None, 1.0));
        // a second header row of units termid does not convert is still a row of units
        assert!(is_unit("[rpm]") && is_unit("[A]") && is_unit("(V)") && is_unit("(days)") && is_unit("m"));
        assert!(!is_unit("rpm") && !is_unit("run1") && !is_unit("A") && !is_unit("(run1)"));
    }

    #[test]
    fn a_time_header_says_its_unit() {
        assert_eq!(seconds_per("Time [ms]"), Some(1e-3));
        assert_eq!(seconds_per("t (min)"), Some(60.0));
        assert_eq!(seconds_per("t [s]"), Some(1.0));
        for plain in
            ["t", "x [m]", "f(x)", "time (rad)", "ms", "_ms", "x_dot", "time_of_day", "hour_of_day", "d", "h"]
        {
            assert_eq!(seconds_per(plain), None, "{plain}");
        }
        // a pharmacokinetic study's hours, an epidemic's days, by unit or by name (a day count
        // was read as seconds, every rate 86 400 times too fast)
        for (header, factor) in [
            ("proof_days", 86400.0),
            ("t [h]", 3600.0),
            ("time (d)", 86400.0),
            ("day", 86400.0),
            ("Days", 86400.0),
            ("hours", 3600.0),
            ("t_days", 86400.0),
        ] {
            assert_eq!(seconds_per(header), Some(factor), "{header}");
        }
        // a logger's unit after the name: `timestamp_ms` was read as seconds, every rate a
        // thousand times too slow
        for (header, factor) in [
            ("timestamp_ms", 1e-3),
            ("time_us", 1e-6),
            ("t.sec", 1.0),
            ("elapsed min", 60.0),
            ("t_ns", 1e-9),
            ("Time_MS", 1e-3),
        ] {
            assert_eq!(seconds_per(header), Some(factor), "{header}");
        }
        // a dataset file's mapping reads a unit in parentheses as in brackets (it read
        // `t = "Time (ms)"` as a column of seconds), a name's own parentheses stay
        assert_eq!(split_spec("Time (ms)"), ("Time".to_string(), Some("ms".to_string()), 1.0));
        assert_eq!(split_spec("-rudder (deg)"), ("rudder".to_string(), Some("deg".to_string()), -1.0));
        assert_eq!(split_spec("f(x)"), ("f(x)".to_string(), None, 1.0));
        assert_eq!(in_seconds("Time (ms)", vec![0.0, 50.0, 100.0]), [0.0, 0.05, 0.1]);
        assert_eq!(in_seconds("t", vec![0.0, 50.0]), [0.0, 50.0]);
        let mut f = crate::data::Frame::new("log.csv", "Time (ms)", vec![0.0, 0.05, 0.1]).unwrap();
        f.push("x", vec![1.0, 2.0, 3.0]).unwrap();
        let text = f.to_csv();
        assert!(text.starts_with("Time (ms),x\n0.0,1.0\n50.0,2.0\n100.0,3.0"), "{text}");
        let back = crate::data::Frame::parse_csv(&text, "log.csv", "Time (ms)").unwrap();
        assert_eq!(back.time(), f.time());
        // a dataset file's time mapped onto a logger's `timestamp_ms` (read as seconds before)
        let dir = std::env::temp_dir().join(format!("termid-suffixed-time-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write(&dir, "log.csv", "timestamp_ms,x\n1000,1\n1050,2\n1100,3\n");
        let set: Dataset =
            toml::from_str("[columns]\nt = \"timestamp_ms\"\nx = \"x\"\n[[runs]]\nfile = \"log.csv\"\n")
                .unwrap();
        let (frames, _) = set.read(&dir, "t").unwrap();
        assert_eq!(frames[0].time(), [1.0, 1.05, 1.1]);
        // a row the logger wrote twice is named so through a dataset file as in a plain file
        write(&dir, "log.csv", "timestamp_ms,x\n1000,1\n1050,2\n1050,2\n1100,3\n");
        let e = set.read(&dir, "t").unwrap_err().to_string();
        assert!(e.contains("row 3 repeats row 2 in every column"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn headers_with_their_units() {
        let dir = std::env::temp_dir().join(format!("termid-header-units-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write(&dir, "h.csv", "Time [s],psi [deg],u [m/s],x [m],x\n0,90,1.5,1,2\n0.5,180,1.25,3,4\n");
        let read = |columns: &str| {
            let text = format!("[columns]\n{columns}\n[[runs]]\nfile = \"h.csv\"\n");
            let set: Dataset = toml::from_str(&text).unwrap();
            set.read(&dir, "t")
        };
        let (frames, notes) = read("t = \"Time\"\n\"ψ\" = \"psi\"\nu = \"u [m/s]\"\ny = \"x [m]\"").unwrap();
        assert_eq!(frames[0].time(), [0.0, 0.5]);
        let psi = frames[0].column("ψ").unwrap();
        assert!((psi[0] - std::f64::consts::FRAC_PI_2).abs() < 1e-12, "{psi:?} {notes:?}");
        assert_eq!(frames[0].column("u").unwrap(), [1.5, 1.25]);
        assert_eq!(frames[0].column("y").unwrap(), [1.0, 3.0]);
        let refused = read("t = \"Time\"\n\"ψ\" = \"psi [rad]\"").unwrap_err().to_string();
        assert!(refused.contains("reads it in [rad], the file's header says [deg]"), "{refused}");
        let shared = read("t = \"Time\"\ny = \"x\"").unwrap();
        assert_eq!(shared.0[0].column("y").unwrap(), [2.0, 4.0]);
        let shared = read("t = \"Time\"\ny = \"x [m]\"\nu = \"x\"").unwrap();
        assert_eq!(shared.0[0].column("y").unwrap(), [1.0, 3.0]);
    }

    /// A basin file as HSVA writes them: Latin-1 header lines (a degree sign), no row of
    /// column names, whitespace columns, angles in radians; u and v computed from the track.
    #[test]
    fn headerless_latin1_files_with_velocities_from_the_track() {
        let dir = std::env::temp_dir().join(format!("termid-hsva-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut bytes =
            b" HSVA, experimental data\n KVLCC2\n Z20\xb0/10\xb0 starting to starboard\n Time series\n"
                .to_vec();
        // u = 1.2, v = -0.1 in the body frame, heading 0.2 rad: the track moves accordingly
        let (c, s) = (0.2f64.cos(), 0.2f64.sin());
        for k in 0..40 {
            let t = 0.05 * k as f64;
            let (x, y) = ((1.2 * c + 0.1 * s) * t, (1.2 * s - 0.1 * c) * t);
            bytes.extend(format!("  {t:.3}  {x:.9}  {y:.9}  0.2  9.99  9.99  0.001\n").as_bytes());
        }
        std::fs::write(dir.join("z.dat"), bytes).unwrap();
        let text = r#"
header = ["time", "x0", "y0", "psi", "u", "v", "p"]
[columns]
t = "time [s]"
x0 = "x0 [m]"
y0 = "y0 [m]"
"ψ" = "psi [rad]"
r = "p [rad/s]"
[track]
x = "x0"
y = "y0"
heading = "ψ"
u = "u"
v = "v"
[[runs]]
file = "z.dat"
delimiter = "whitespace"
skip = 4
"#;
        let set: Dataset = toml::from_str(text).unwrap();
        let (frames, notes) = set.read(&dir, "t").unwrap();
        assert!(
            notes.iter().any(|n| n.contains("Latin-1")) && notes.iter().any(|n| n.contains("from the track"))
        );
        let f = &frames[0];
        assert_eq!(f.len(), 40);
        for k in 0..40 {
            assert!(
                (f.column("u").unwrap()[k] - 1.2).abs() < 1e-6
                    && (f.column("v").unwrap()[k] + 0.1).abs() < 1e-6
            );
        }
        assert_eq!(f.column("r").unwrap()[0], 0.001);
    }

    /// A ship at sea logged by a satellite receiver: latitude and longitude in degrees (60° N,
    /// 8 m/s on a heading of 30° with 5° of drift), read as metres north and east of the first
    /// fix, and from them u and v. The fixes are written from the track by the ellipsoid's
    /// radii of curvature at the first fix (M, N), which over 800 m bend the course by 1e-4 rad.
    #[test]
    fn a_satellite_fix_gives_the_track_in_metres() {
        let dir = std::env::temp_dir().join(format!("termid-gnss-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (lat0, lon0) = (60f64.to_radians(), 5.3f64.to_radians());
        let (m, n) = crate::data::radii_of_curvature(lat0);
        let (speed, heading, drift) = (8.0, 30f64.to_radians(), 5f64.to_radians());
        let mut text = String::from("t,lat,lon,hdg,sog,cog\n");
        for k in 0..=100 {
            let t = f64::from(k);
            let (north, east) = (speed * (heading + drift).cos() * t, speed * (heading + drift).sin() * t);
            let (lat, lon) = (lat0 + north / m, lon0 + east / (n * lat0.cos()));
            // the receiver's speed (knots) and course over ground beside its fixes
            let (sog, cog) = (speed * 3600.0 / 1852.0, (heading + drift).to_degrees());
            text.push_str(&format!(
                "{t},{:.10},{:.10},30,{sog:.6},{cog}\n",
                lat.to_degrees(),
                lon.to_degrees()
            ));
        }
        std::fs::write(dir.join("trial.csv"), text).unwrap();
        let set: Dataset = toml::from_str(
            r#"
[columns]
t = "t [s]"
"ψ" = "hdg [deg]"
[track]
latitude = "lat [deg]"
longitude = "lon [deg]"
x = "x0"
y = "y0"
heading = "ψ"
u = "u"
v = "v"
[[runs]]
file = "trial.csv"
"#,
        )
        .unwrap();
        // over ground: the velocities carry any current
        assert!(set.over_ground());
        let (frames, notes) = set.read(&dir, "t").unwrap();
        assert!(
            notes.iter().any(|n| n.contains("x0 and y0 in m north and east of the first fix")),
            "{notes:?}"
        );
        // no antenna given: the fixes are said to be taken as the ship's point
        assert!(notes.iter().any(|n| n.contains("fixes taken as of the model's point")), "{notes:?}");
        let f = &frames[0];
        let (x0, y0) = (f.column("x0").unwrap(), f.column("y0").unwrap());
        assert!(x0[0] == 0.0 && y0[0] == 0.0);
        assert!((x0[100].hypot(y0[100]) - 800.0).abs() < 0.1, "{} {}", x0[100], y0[100]);
        for k in [0, 50, 100] {
            let (u, v) = (f.column("u").unwrap()[k], f.column("v").unwrap()[k]);
            assert!(
                (u - speed * drift.cos()).abs() < 5e-3 && (v - speed * drift.sin()).abs() < 5e-3,
                "{k}: {u} {v}"
            );
        }
        // the receiver's velocity over ground instead of the differenced fixes: exact
        let doppler = r#"
[columns]
t = "t [s]"
"ψ" = "hdg [deg]"
[track]
speed_over_ground = "sog [kn]"
course_over_ground = "cog [deg]"
heading = "ψ"
u = "u"
v = "v"
[[runs]]
file = "trial.csv"
"#;
        let set: Dataset = toml::from_str(doppler).unwrap();
        assert!(set.over_ground());
        let (frames, notes) = set.read(&dir, "t").unwrap();
        assert!(
            notes.iter().any(|n| n.contains("from the velocity over ground (sog [kn], cog [deg])")),
            "{notes:?}"
        );
        for k in [0, 50, 100] {
            let (u, v) = (frames[0].column("u").unwrap()[k], frames[0].column("v").unwrap()[k]);
            assert!(
                (u - speed * drift.cos()).abs() < 1e-5 && (v - speed * drift.sin()).abs() < 1e-5,
                "{k}: {u} {v}"
            );
        }
        let half: Dataset =
            toml::from_str(&doppler.replace("course_over_ground = \"cog [deg]\"\n", "")).unwrap();
        let e = half.read(&dir, "t").unwrap_err().to_string();
        assert!(e.contains("speed_over_ground and course_over_ground together"), "{e}");
        // the fixes of an antenna on the bridge, 100 m aft and 5 m to starboard, moved to
        // the ship's point: it turns at 0.5°/s, the antenna sweeping 0.87 m/s more sideways
        // on a heading from 330°, which a compass reads through north (360° → 0°) at t = 60 s
        let (rate, (ax, ay), heading) = (0.5f64.to_radians(), (-100.0, 5.0), 330f64.to_radians());
        let mut text = String::from("t,x,y,hdg,sog,cog\n");
        for k in 0..=100 {
            let t = f64::from(k);
            // the ship's point on a circle at 8 m/s with 5° of drift, its heading turning
            let psi = heading + rate * t;
            let radius = speed / rate;
            let (north, east) = (
                radius * ((psi + drift).sin() - (heading + drift).sin()),
                radius * ((heading + drift).cos() - (psi + drift).cos()),
            );
            let (an, ae) = (north + ax * psi.cos() - ay * psi.sin(), east + ax * psi.sin() + ay * psi.cos());
            // the antenna's velocity over ground: the ship's, and the turning about the point
            let (vn, ve) = (
                speed * (psi + drift).cos() + rate * (-ax * psi.sin() - ay * psi.cos()),
                speed * (psi + drift).sin() + rate * (ax * psi.cos() - ay * psi.sin()),
            );
            let compass = psi.rem_euclid(std::f64::consts::TAU);
            text.push_str(&format!("{t},{an},{ae},{compass},{},{}\n", vn.hypot(ve), ve.atan2(vn)));
        }
        std::fs::write(dir.join("turn.csv"), text).unwrap();
        let read = |track: &str| {
            let set: Dataset = toml::from_str(&format!(
                "[columns]\nt = \"t [s]\"\n\"ψ\" = \"hdg [rad]\"\nx0 = \"x [m]\"\ny0 = \"y [m]\"\n[track]\n{track}heading = \"ψ\"\nu = \"u\"\nv = \"v\"\nantenna = [-100.0, 5.0]\n[[runs]]\nfile = \"turn.csv\"\n"
            ))
            .unwrap();
            set.read(&dir, "t").unwrap()
        };
        let (positions, notes) = read("x = \"x0\"\ny = \"y0\"\n");
        assert!(
            notes.iter().any(|n| n.contains("moved from the antenna, -100 m forward and 5 m to starboard")),
            "{notes:?}"
        );
        let (doppler, notes) =
            read("speed_over_ground = \"sog [m/s]\"\ncourse_over_ground = \"cog [rad]\"\n");
        assert!(
            notes.iter().any(|n| n.contains("moved from the antenna (-100 m forward, 5 m to starboard)")),
            "{notes:?}"
        );
        let f = &positions[0];
        // (at the ends the difference is one-sided, a chord's direction a second ahead)
        for k in [2, 50, 59, 60, 61, 98] {
            let psi = heading + rate * k as f64;
            let radius = speed / rate;
            let north = radius * ((psi + drift).sin() - (heading + drift).sin());
            assert!((f.column("x0").unwrap()[k] - north).abs() < 1e-6, "{k}");
            // differenced over ±2 s of a turn (a chord): within 2 mm/s; the Doppler velocity at
            // the antenna moved by the heading's differenced rate (exact on a steady turn)
            let (u, v) = (f.column("u").unwrap()[k], f.column("v").unwrap()[k]);
            assert!(
                (u - speed * drift.cos()).abs() < 2e-3 && (v - speed * drift.sin()).abs() < 2e-3,
                "{k}: {u} {v}"
            );
            let (u, v) = (doppler[0].column("u").unwrap()[k], doppler[0].column("v").unwrap()[k]);
            assert!(
                (u - speed * drift.cos()).abs() < 1e-6 && (v - speed * drift.sin()).abs() < 1e-6,
                "{k}: {u} {v}"
            );
        }
        // a latitude without its longitude, or without the positions' names, is refused
        let half = toml::from_str::<Dataset>(
            "[columns]\nt = \"t [s]\"\n\"ψ\" = \"hdg [deg]\"\n[track]\nlatitude = \"lat [deg]\"\nx = \"x0\"\ny = \"y0\"\nheading = \"ψ\"\nu = \"u\"\nv = \"v\"\n[[runs]]\nfile = \"trial.csv\"\n",
        )
        .unwrap();
        let e = half.read(&dir, "t").unwrap_err().to_string();
        assert!(e.contains("latitude and longitude together"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A full-scale record as MARIN prints them (three significant digits: repeated time
    /// stamps, coarse positions; earth-fixed velocities; rpm; rudder of the other sign) read
    /// at the model's scale: time rebuilt, Froude's law per unit, u and v in the body frame.
    #[test]
    fn full_scale_records_at_model_scale() {
        let dir = std::env::temp_dir().join(format!("termid-marin-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let lambda: f64 = 49.0; // √λ = 7
        let heading = (-17.2f64).to_radians(); // printable in three digits
        let (u, v) = (7.0, 0.7); // full scale, body frame
        let (xd, yd) = (u * heading.cos() - v * heading.sin(), u * heading.sin() + v * heading.cos());
        let mut text = String::from("MARIN\nZig-zag\n\n");
        for k in 0..900 {
            let t = 0.14 * k as f64;
            text.push_str(&format!(
                "{t:.2E}\t{:.2E}\t{:.2E}\t{:.2E}\t{xd:.6E}\t{yd:.6E}\t{:.2E}\t{:.2E}\n",
                xd * t,
                yd * t,
                heading.to_degrees(),
                0.5,  // yaw rate, deg/s
                -5.0, // rudder, the basin's sign
            ));
        }
        write(&dir, "zz.dat", &text);
        let set: Dataset = toml::from_str(
            r#"
header = ["time", "x0", "y0", "psi", "dx0", "dy0", "r", "delta"]
froude = 49.0
regular_time = true
folder = "${TERMID_TEST_RECORDS}"
[columns]
t = "time [s]"
x0 = "x0 [m]"
"ψ" = "psi [deg]"
r = "r [deg/s]"
"δ" = "-delta [deg]"
[track]
x_dot = "dx0 [m/s]"
y_dot = "dy0 [m/s]"
heading = "ψ"
u = "u"
v = "v"
[[runs]]
file = "zz.dat"
delimiter = "whitespace"
skip = 3
"#,
        )
        .unwrap();
        let set_path = Path::new("/nowhere/set.toml");
        let e = set.folder(set_path).unwrap_err().to_string();
        assert!(e.contains("TERMID_TEST_RECORDS") && e.contains("not set"), "{e}");
        let folder =
            expand_environment("${TERMID_TEST_RECORDS}", |_| Some(dir.display().to_string())).unwrap();
        assert_eq!(Path::new(&folder), dir);
        let (frames, notes) = set.read(&dir, "t").unwrap();
        let f = &frames[0];
        // 0.14 s per row at full scale is 0.02 s at the model's; the stamps above 100 s
        // repeat (1.00E+02 … 1.26E+02) but the rate is rebuilt
        assert!(notes.iter().any(|n| n.contains("regular rate")), "{notes:?}");
        for (k, t) in f.time().iter().enumerate() {
            assert!((t - 0.02 * k as f64).abs() < 1e-3, "row {k}: {t}");
        }
        let sq = lambda.sqrt();
        for k in [0, 450, 899] {
            assert!((f.column("u").unwrap()[k] - u / sq).abs() < 1e-5);
            assert!((f.column("v").unwrap()[k] - v / sq).abs() < 1e-5);
            assert!((f.column("r").unwrap()[k] - 0.5f64.to_radians() * sq).abs() < 1e-9);
            assert!((f.column("δ").unwrap()[k] - 5f64.to_radians()).abs() < 1e-12);
            assert!((f.column("ψ").unwrap()[k] - heading).abs() < 1e-12);
        }
        // lengths ÷ λ (the positions printed to three digits)
        let x_full = xd * 0.14 * 899.0;
        assert!((f.column("x0").unwrap()[899] - x_full / lambda).abs() < 0.01 * x_full / lambda);
        // a dropout is not rounding: refused with its row
        let mut t: Vec<f64> = (0..100).map(|k| 0.1 * k as f64).collect();
        for v in &mut t[60..] {
            *v += 3.0;
        }
        let e = regular_time(&t, "f.dat", "time").unwrap_err().to_string();
        assert!(e.contains("f.dat") && e.contains("dropout"), "{e}");
        // a 100 Hz logger's time written to 0.1 s (off by up to 0.05 s: five samples) is rounding
        let t: Vec<f64> = (0..2000).map(|k| (0.1 * k as f64).round() / 10.0).collect();
        let (line, step) = regular_time(&t, "f.dat", "time").unwrap();
        assert!((step - 0.01).abs() < 1e-5 && (line[1999] - 19.99).abs() < 0.01, "{step} {}", line[1999]);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn environment_in_folders() {
        let env = |n: &str| (n == "A").then(|| "/data".to_string());
        assert_eq!(expand_environment("$A/x", env).unwrap(), "/data/x");
        assert_eq!(expand_environment("${A}x/y", env).unwrap(), "/datax/y");
        assert_eq!(expand_environment("a$/b", env).unwrap(), "a$/b");
        assert_eq!(expand_environment("$B/x", env).unwrap_err(), Unexpanded::Unset("B".into()));
        assert!(
            matches!(expand_environment("${X", env), Err(Unexpanded::Syntax(m)) if m.contains("closing brace"))
        );
        assert!(
            matches!(expand_environment("${X:-/tmp}", env), Err(Unexpanded::Syntax(m)) if m.contains(":-"))
        );
    }

    /// `[extra]` records are read and converted as `[columns]` are; a file column read twice,
    /// or a name in both tables, is refused naming both keys, an empty name as such.
    #[test]
    fn extra_records_are_read_as_columns_are() {
        let dir = std::env::temp_dir().join(format!("termid-extra-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write(&dir, "run.csv", "time,delta,thrust\n0,1,40.5\n0.1,2,41.0\n");
        let set = |extra: &str| {
            let text = format!(
                "[columns]\nt = \"time [s]\"\n\"δ\" = \"delta [deg]\"\n\n[extra]\n{extra}\n\n[[runs]]\nfile = \"run.csv\"\n"
            );
            write(&dir, "set.toml", &text);
            Dataset::load(&dir.join("set.toml"))
        };
        let (frames, _) = set("T_P = \"thrust [N]\"").unwrap().read(&dir, "t").unwrap();
        assert_eq!(frames[0].require("T_P").unwrap(), &[40.5, 41.0]);
        assert!((frames[0].require("δ").unwrap()[1] - 2f64.to_radians()).abs() < 1e-15);
        let twice = set("T_P = \"delta [deg]\"").unwrap_err().to_string();
        assert!(twice.contains("`columns.δ` and `extra.T_P` both read the file column `delta`"), "{twice}");
        let both = set("\"δ\" = \"thrust [N]\"").unwrap_err().to_string();
        assert!(both.contains("`δ` is in both `columns` and `extra`"), "{both}");
        let empty = set("\"\" = \"thrust [N]\"").unwrap_err().to_string();
        assert!(empty.contains("`extra` maps a column onto an empty name"), "{empty}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn maps_names_and_converts_units() {
        let dir = std::env::temp_dir().join(format!("termid-dataset-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write(
            &dir,
            "run1.dat",
            "basin log\nmodel 1512\n time  delta  yawrate  speed\n0.0 1.0 0.5 4.0\n0.1 2.0 1.0 3.6\n",
        );
        write(
            &dir,
            "set.toml",
            "[columns]\nt = \"time [s]\"\n\"δ\" = \"delta [deg]\"\nr = \"yawrate [deg/s]\"\nu = \"speed [km/h]\"\n\n[[runs]]\nfile = \"run1.dat\"\ndelimiter = \"whitespace\"\nskip = 2\n",
        );
        let ds = Dataset::load(&dir.join("set.toml")).unwrap();
        let (frames, notes) = ds.read(&dir, "t").unwrap();
        let f = &frames[0];
        assert!((f.require("δ").unwrap()[1] - 2f64.to_radians()).abs() < 1e-15);
        assert!((f.require("r").unwrap()[0] - 0.5f64.to_radians()).abs() < 1e-15);
        assert!((f.require("u").unwrap()[1] - 1.0).abs() < 1e-15);
        assert_eq!(notes.len(), 3, "{notes:?}");
        // a time window
        write(&dir, "set4.toml", "[columns]\nt = \"time [s]\"\n\"δ\" = \"delta [deg]\"\n\n[[runs]]\nfile = \"run4.csv\"\nfrom = 0.15\nto = 0.45\n");
        write(&dir, "run4.csv", "time,delta\n0,1\n0.1,2\n0.2,3\n0.3,4\n0.4,5\n0.5,6\n");
        let (fr, _) = Dataset::load(&dir.join("set4.toml")).unwrap().read(&dir, "t").unwrap();
        assert_eq!(fr[0].time(), &[0.2, 0.3, 0.4]);
        // degrees declared as radians: refused with file, row and column
        write(
            &dir,
            "set2.toml",
            "[columns]\nt = \"time [s]\"\n\"δ\" = \"delta [rad]\"\n\n[[runs]]\nfile = \"run2.csv\"\n",
        );
        write(&dir, "run2.csv", "time,delta\n0,0.1\n0.1,12.5\n");
        let e = Dataset::load(&dir.join("set2.toml")).unwrap().read(&dir, "t").unwrap_err().to_string();
        assert!(
            e.contains("run2.csv") && e.contains("row 2") && e.contains("`delta`") && e.contains("degrees"),
            "{e}"
        );
        // a missing column names file and column
        write(
            &dir,
            "set3.toml",
            "[columns]\nt = \"time [s]\"\nv = \"sway [m/s]\"\n\n[[runs]]\nfile = \"run2.csv\"\n",
        );
        let e = Dataset::load(&dir.join("set3.toml")).unwrap().read(&dir, "t").unwrap_err().to_string();
        assert!(e.contains("run2.csv") && e.contains("`sway`"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
