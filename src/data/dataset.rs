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
    /// The runs.
    pub runs: Vec<RunSpec>,
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
    /// Lines before the header.
    #[serde(default)]
    pub skip: usize,
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
            let text = crate::budget::read_text(&path)
                .map_err(|e| DataError::Io { file: origin.clone(), message: e.to_string() })?;
            let body: Vec<&str> = text.lines().skip(run.skip).collect();
            let csv: String = body
                .iter()
                .map(|l| match run.delimiter {
                    Delimiter::Comma => l.to_string(),
                    Delimiter::Semicolon => l.replace(';', ","),
                    Delimiter::Whitespace => l.split_whitespace().collect::<Vec<_>>().join(","),
                })
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
