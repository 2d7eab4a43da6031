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

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::{DataError, Frame};

/// The dataset file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dataset {
    /// Model variable → "file column [unit]".
    pub columns: BTreeMap<String, String>,
    /// The files' column names in order, for files with no header row (every run's unless
    /// it names its own).
    #[serde(default)]
    pub header: Option<Vec<String>>,
    /// Body-frame velocities computed from the track instead of read from columns.
    #[serde(default)]
    pub track: Option<Track>,
    /// The runs.
    pub runs: Vec<RunSpec>,
}

/// `[track]`: surge and sway velocity computed from an earth-fixed track and the heading
/// (model variables, after the column map), by central differences over ± `half_window`
/// samples — for records whose logged velocities are missing or not what they say.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Track {
    /// Position along the x axis.
    pub x: String,
    /// Position along the y axis.
    pub y: String,
    /// Heading, measured from x towards y.
    pub heading: String,
    /// The surge velocity to compute.
    pub u: String,
    /// The sway velocity to compute.
    pub v: String,
    /// Samples each side of the central difference.
    #[serde(default = "two")]
    pub half_window: usize,
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
    let n = t.len().min(x.len()).min(y.len()).min(heading.len());
    let half = half.max(1);
    (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(half), (k + half).min(n - 1));
            let h = (t[b] - t[a]).max(f64::MIN_POSITIVE);
            let (xd, yd) = ((x[b] - x[a]) / h, (y[b] - y[a]) / h);
            let (s, c) = heading[k].sin_cos();
            (xd * c + yd * s, -xd * s + yd * c)
        })
        .unzip()
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
    /// Keep only samples at or after this time (file's time unit converted to s).
    #[serde(default)]
    pub from: Option<f64>,
    /// Keep only samples at or before this time.
    #[serde(default)]
    pub to: Option<f64>,
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

/// Units termid converts to SI and radians: (name, factor to SI).
const UNITS: &[(&str, f64)] = &[
    ("s", 1.0),
    ("ms", 1e-3),
    ("min", 60.0),
    ("m", 1.0),
    ("m/s", 1.0),
    ("m/s^2", 1.0),
    ("km/h", 1.0 / 3.6),
    ("kn", 1852.0 / 3600.0),
    ("rad", 1.0),
    ("rad/s", 1.0),
    ("rad/s^2", 1.0),
    ("deg", std::f64::consts::PI / 180.0),
    ("deg/s", std::f64::consts::PI / 180.0),
    ("deg/s^2", std::f64::consts::PI / 180.0),
    ("1/min", 1.0 / 60.0),
    ("1/s", 1.0),
    ("-", 1.0),
];

/// "column [unit]" → (column, unit).
fn split_spec(spec: &str) -> (String, Option<String>) {
    match spec.rsplit_once('[') {
        Some((col, unit)) if unit.trim_end().ends_with(']') => {
            (col.trim().to_string(), Some(unit.trim_end().trim_end_matches(']').trim().to_string()))
        }
        _ => (spec.trim().to_string(), None),
    }
}

impl Dataset {
    /// Reads a dataset file.
    pub fn load(path: &Path) -> Result<Dataset, DataError> {
        let file = path.display().to_string();
        let text = crate::budget::read_text(path)
            .map_err(|e| DataError::Io { file: file.clone(), message: e.to_string() })?;
        toml::from_str(&text).map_err(|e| DataError::Io { file, message: e.to_string() })
    }

    /// Reads every run into frames named by model variable, in SI units and radians; `time`
    /// is the model's time variable. Returns the frames and one line per conversion made.
    pub fn read(&self, base: &Path, time: &str) -> Result<(Vec<Frame>, Vec<String>), DataError> {
        let mut notes = Vec::new();
        let mut frames = Vec::new();
        for run in &self.runs {
            let path = base.join(&run.file);
            let origin = path.display().to_string();
            let (text, latin1) = crate::budget::read_text_or_latin1(&path)
                .map_err(|e| DataError::Io { file: origin.clone(), message: e.to_string() })?;
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
                    Delimiter::Semicolon => l.replace(';', ","),
                    Delimiter::Whitespace => l.split_whitespace().collect::<Vec<_>>().join(","),
                }))
                .collect::<Vec<_>>()
                .join("\n");
            let (time_col, time_unit) = split_spec(self.columns.get(time).map_or(time, String::as_str));
            let raw = Frame::parse_csv(&csv, &origin, &time_col)?;
            // a logging dropout would be differentiated across as if it were one step
            super::check_gaps(&raw, 3.0)?;
            let time_factor = factor(time_unit.as_deref(), &origin, time)?;
            let mut frame = Frame::new(&origin, time, raw.time().iter().map(|t| t * time_factor).collect())?;
            for (var, spec) in self.columns.iter().filter(|(v, _)| v.as_str() != time) {
                let (col, unit) = split_spec(spec);
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
                frame.push(var, values.iter().map(|v| v * f).collect())?;
            }
            if let Some(track) = &self.track {
                let col = |n: &str| frame.require(n).map(<[f64]>::to_vec);
                let (u, v) = velocities_from_track(
                    frame.time(),
                    &col(&track.x)?,
                    &col(&track.y)?,
                    &col(&track.heading)?,
                    track.half_window,
                );
                notes.push(format!(
                    "{origin}: {} and {} computed from the track ({}, {}) and {} over ±{} samples",
                    track.u, track.v, track.x, track.y, track.heading, track.half_window
                ));
                frame.set(&track.u, u)?;
                frame.set(&track.v, v)?;
            }
            if run.from.is_some() || run.to.is_some() {
                let t = frame.time();
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
            frames.push(frame);
        }
        Ok((frames, notes))
    }
}

fn factor(unit: Option<&str>, origin: &str, column: &str) -> Result<f64, DataError> {
    let Some(u) = unit else { return Ok(1.0) };
    UNITS.iter().find(|(n, _)| *n == u).map(|(_, f)| *f).ok_or_else(|| DataError::Unit {
        file: origin.into(),
        row: 0,
        column: column.into(),
        message: format!(
            "unknown unit [{u}] (known: {})",
            UNITS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) {
        std::fs::write(dir.join(name), text).unwrap();
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
