//! A plain file's columns whose headers carry a unit termid knows (`x [m]`, `ψ [deg]`, `u
//! (kn)`, as loggers and spreadsheets export them), read by their bare names in SI units and
//! radians, as a dataset file maps them. A time column keeps its header: its unit of time is
//! read where the time is ([`super::in_seconds`]), so `--time "Time [ms]"` names it, as does
//! `--time Time` ([`super::time_position`]).

use std::path::Path;

use super::stream::{rows_of, Labels, RowSource};
use super::DataError;

/// A source whose unit-carrying columns are renamed to their bare names and scaled to SI.
pub(super) struct InSi {
    inner: Box<dyn RowSource>,
    names: Vec<String>,
    /// Each column's factor to SI (1 where its header carries no unit).
    factors: Vec<f64>,
}

impl InSi {
    /// `inner` with its unit-carrying columns in SI; `inner` itself where it has none.
    pub(super) fn wrap(inner: Box<dyn RowSource>) -> Box<dyn RowSource> {
        let renamed = super::dataset::headers_in_si(inner.names());
        if renamed.is_empty() {
            return inner;
        }
        let mut names = inner.names().to_vec();
        let mut factors = vec![1.0; names.len()];
        for (i, bare, _, f) in renamed {
            names[i] = bare;
            factors[i] = f;
        }
        Box::new(InSi { inner, names, factors })
    }

    /// The header a name of this source has in the file.
    fn header<'a>(&'a self, name: &'a str) -> &'a str {
        self.names.iter().position(|n| n == name).map_or(name, |i| &self.inner.names()[i])
    }
}

impl RowSource for InSi {
    fn names(&self) -> &[String] {
        &self.names
    }

    fn read(&mut self, max: usize, columns: &mut [Vec<f64>]) -> Result<usize, DataError> {
        let n = self.inner.read(max, columns)?;
        for (column, &f) in columns.iter_mut().zip(&self.factors).filter(|(_, f)| **f != 1.0) {
            let from = column.len() - n;
            column[from..].iter_mut().for_each(|v| *v *= f);
        }
        Ok(n)
    }

    fn text(&self) -> &[(String, String)] {
        self.inner.text()
    }

    fn label_by(&mut self, name: &str) -> bool {
        let header = self.header(name).to_string();
        self.inner.label_by(&header)
    }

    fn take_labels(&mut self) -> Vec<(String, Labels)> {
        let labels = self.inner.take_labels();
        let bare = |header: String| match self.inner.names().iter().position(|n| *n == header) {
            Some(i) => self.names[i].clone(),
            None => header,
        };
        labels.into_iter().map(|(header, l)| (bare(header), l)).collect()
    }
}

/// What to say of a time whose own name is a unit of time's (`day`, `time_ms`): it keeps its
/// name and is read in seconds all the same, so every rate is per second. `None` for one in
/// seconds or of no unit.
pub fn time_in_seconds(time: &str) -> Option<String> {
    super::seconds_per(time)
        .filter(|f| *f != 1.0)
        .map(|s| format!("the time `{time}` read in seconds (× {s:.6e}): every rate is per second"))
}

/// What reading the plain file `path` in SI does to its columns' headers, to be said: `None`
/// where no header carries a unit termid reads (or the file cannot be read: reading it says why).
/// The time column `time` is said where its header carries its unit (`t [ms]`).
pub fn units_note(path: &Path, time: &str) -> Option<String> {
    let names = rows_of(path).ok()?.names().to_vec();
    let mut renamed = super::dataset::headers_in_si(&names);
    // a time named by its unit keeps its name and is read in seconds all the same (`day`, an
    // epidemic's day count; `time_ms`): said, as every rate is then per second
    let mut own = None;
    if let Some(i) = super::time_position(&names, time) {
        if names[i] != time {
            let seconds = super::seconds_per(&names[i]).unwrap_or(1.0);
            renamed.insert(0, (i, time.to_string(), String::new(), seconds));
        } else {
            own = time_in_seconds(time);
        }
    }
    let read: Vec<String> =
        renamed.iter().map(|(i, bare, unit, f)| super::read_as(&names[*i], bare, unit, *f)).collect();
    let read = (!read.is_empty()).then(|| format!("read by their bare names: {}", read.join(", ")));
    let said: Vec<String> = own.into_iter().chain(read).collect();
    (!said.is_empty()).then(|| format!("{}: {}", path.display(), said.join("; ")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_with_units_are_read_by_their_bare_names_in_si() {
        let dir = std::env::temp_dir().join(format!("termid-in-si-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("run.csv");
        // a time in ms keeps its header; `v` beside `v [kn]` keeps both whole
        std::fs::write(
            &path,
            "Time [ms],x [m],psi (deg),u [kn],v,v [kn],run\n0,1,90,1,0,2,a\n500,2,180,2,0,4,a\n",
        )
        .unwrap();
        let mut rows = InSi::wrap(rows_of(&path).unwrap());
        assert_eq!(rows.names(), ["Time [ms]", "x", "psi", "u", "v", "v [kn]"]);
        assert!(rows.label_by("run"));
        let mut columns = vec![Vec::new(); 6];
        while rows.read(1, &mut columns).unwrap() > 0 {}
        assert_eq!(columns[0], [0.0, 500.0]);
        assert_eq!(columns[1], [1.0, 2.0]);
        assert_eq!(columns[2], [std::f64::consts::FRAC_PI_2, std::f64::consts::PI]);
        assert_eq!(columns[3], [1852.0 / 3600.0, 2.0 * 1852.0 / 3600.0]);
        assert_eq!(columns[5], [2.0, 4.0]);
        assert_eq!(rows.take_labels()[0].1.values, ["a"]);
        let note = units_note(&path, "Time [ms]").unwrap();
        assert!(note.contains("`x [m]` as x, `psi (deg)` as psi in SI (× 1.745329e-2)"), "{note}");
        // the time under its header with its unit: read in seconds, said as such
        assert!(note.contains(": the time `Time [ms]` read in seconds (× 1.000000e-3): every rate is per second; read by their bare names: `x [m]`"), "{note}");
        assert!(!note.contains("`v [kn]`"), "{note}");
        // the time by its bare name: read in seconds, said
        let note = units_note(&path, "Time").unwrap();
        assert!(
            note.contains("read by their bare names: `Time [ms]` as Time in SI (× 1.000000e-3), `x [m]`"),
            "{note}"
        );
        let frame = crate::data::Frame::read(&path, "Time").unwrap();
        assert_eq!((frame.time_name(), frame.time()), ("Time", &[0.0, 0.5][..]));
        std::fs::write(&path, "t,x\n0,1\n").unwrap();
        assert!(units_note(&path, "t").is_none());
        std::fs::remove_dir_all(&dir).ok();
    }
}
