//! Output files written so that a failure loses nothing: every file goes to a temporary file
//! beside its target and is renamed over it only when all of a command's outputs are written
//! ([`Outputs`]); a whole folder is built beside its target and swapped in under a lock
//! ([`replace_folder`]). A full disk, a bad path or an error half-way leaves the old files as
//! they were and no new ones. Numbers in what is written: [`sig`].

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// An output that could not be written; nothing was replaced.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// The path cannot take a file (its folder is missing, or it is a folder).
    #[error("{path}: {reason}")]
    Unwritable {
        /// The output path.
        path: String,
        /// Why.
        reason: String,
    },
    /// The system refused a write, a rename or a lock.
    #[error("{path}: {error}")]
    Io {
        /// The path written.
        path: String,
        /// What the system said (in the message, so not also a source that would print twice).
        error: std::io::Error,
    },
}

impl OutputError {
    /// What went wrong, without the path (for errors that name the path themselves).
    pub fn reason(&self) -> String {
        match self {
            OutputError::Unwritable { reason, .. } => reason.clone(),
            OutputError::Io { error, .. } => error.to_string(),
        }
    }
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |error| OutputError::Io { path: path.display().to_string(), error }
}

/// A name beside `target` that no other process or call uses: `.NAME.termid-PID-N.tmp`.
fn sibling(target: &Path, what: &str) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = target.file_name().map_or("output".into(), |s| s.to_string_lossy().into_owned());
    target.with_file_name(format!(".{name}.termid-{}-{n}.{what}", std::process::id()))
}

/// The folder a relative or absolute path's file lives in (`.` for a bare file name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Checks, before any work, that a file can be written at `path`: it names a file (not a
/// folder) in a folder that exists.
pub fn check_file(path: &Path) -> Result<(), OutputError> {
    let unwritable =
        |reason: &str| OutputError::Unwritable { path: path.display().to_string(), reason: reason.into() };
    if path.as_os_str().is_empty() || path.file_name().is_none() {
        return Err(unwritable("not a file name"));
    }
    if path.is_dir() {
        return Err(unwritable("is a folder; name a file"));
    }
    let folder = folder_of(path);
    if !folder.is_dir() {
        return Err(unwritable(&format!("folder {} does not exist", folder.display())));
    }
    Ok(())
}

/// Checks, before any work, that files can be written into folder `dir`: it is a folder or
/// can be made one (its parent exists).
pub fn check_folder(dir: &Path) -> Result<(), OutputError> {
    if dir.is_dir() {
        return Ok(());
    }
    let unwritable = |reason: String| OutputError::Unwritable { path: dir.display().to_string(), reason };
    if dir.exists() {
        return Err(unwritable("exists and is not a folder".into()));
    }
    let parent = folder_of(dir);
    if !parent.is_dir() {
        return Err(unwritable(format!("folder {} does not exist", parent.display())));
    }
    Ok(())
}

/// The identity of an existing file (device and inode), so that two names of one file (a
/// link, `./d.csv` and `d.csv`) are seen as one.
fn identity(path: &Path) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        std::fs::canonicalize(path).ok().map(|p| (0, p.to_string_lossy().len() as u64))
    }
}

/// Whether two paths name one existing file (by identity).
pub fn same_file(a: &Path, b: &Path) -> bool {
    identity(a).is_some_and(|x| identity(b) == Some(x))
}

/// A path as it will be once written: its folder made absolute and resolved, its name kept
/// (for outputs that do not exist yet).
fn resolved(path: &Path) -> Option<PathBuf> {
    Some(std::fs::canonicalize(folder_of(path)).ok()?.join(path.file_name()?))
}

/// Refuses, before any work, outputs that are one of the command's inputs (by identity, not
/// by name: a link or another spelling of the same file counts) or that are one another: a
/// command would read its input and then replace it, or write two outputs over each other.
/// `outputs` and `inputs` are (what, path), e.g. ("--out", …), ("--data", …).
pub fn check_distinct(outputs: &[(&str, &Path)], inputs: &[(&str, &Path)]) -> Result<(), OutputError> {
    let same = |a: &Path, b: &Path| match (identity(a), identity(b)) {
        (Some(x), Some(y)) => x == y,
        _ => resolved(a).is_some_and(|a| resolved(b).is_some_and(|b| a == b)),
    };
    for (k, (what, out)) in outputs.iter().enumerate() {
        // a device or pipe (/dev/stdout) is no file to lose
        if std::fs::metadata(out).is_ok_and(|m| !m.is_file()) {
            continue;
        }
        let clash = |reason: String| Err(OutputError::Unwritable { path: out.display().to_string(), reason });
        if let Some((input, _)) = inputs.iter().find(|(_, i)| identity(i).is_some() && same(out, i)) {
            return clash(format!(
                "{what} names the same file as {input}: termid never overwrites its own input; write elsewhere"
            ));
        }
        if let Some((other, _)) = outputs[..k].iter().find(|(_, o)| same(out, o)) {
            return clash(format!(
                "{what} and {other} name the same file: one output would replace the other"
            ));
        }
    }
    Ok(())
}

/// Writes one file atomically: to a temporary file beside it, flushed to disk, then renamed
/// over `path`. On any failure `path` is as it was and the temporary file is gone.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let mut outputs = Outputs::new();
    outputs.file(path, bytes)?;
    outputs.commit()
}

/// A command's output files as one transaction: each is written to a temporary file beside
/// its target as it comes; [`Outputs::commit`] renames them all into place. Dropped without a
/// commit (an error on the way), it removes what it wrote, including folders it made.
#[derive(Debug, Default)]
pub struct Outputs {
    /// (temporary file, target), in the order staged.
    staged: Vec<(PathBuf, PathBuf)>,
    /// Targets that are not regular files (`/dev/stdout`, a pipe): written in place on commit,
    /// since renaming over them would replace the device rather than write to it.
    streams: Vec<(PathBuf, Vec<u8>)>,
    /// Folders this transaction created (removed again if it does not commit).
    made: Vec<PathBuf>,
}

impl Outputs {
    /// An empty transaction.
    pub fn new() -> Outputs {
        Outputs::default()
    }

    /// Makes folder `dir` (and the folders above it) if missing; removed again without a commit.
    pub fn folder(&mut self, dir: &Path) -> Result<(), OutputError> {
        let mut missing = Vec::new();
        let mut d = dir;
        while !d.as_os_str().is_empty() && !d.exists() {
            missing.push(d.to_path_buf());
            d = match d.parent() {
                Some(p) => p,
                None => break,
            };
        }
        for m in missing.into_iter().rev() {
            std::fs::create_dir(&m).map_err(io_error(&m))?;
            self.made.push(m);
        }
        if !dir.is_dir() {
            return Err(OutputError::Unwritable {
                path: dir.display().to_string(),
                reason: "exists and is not a folder".into(),
            });
        }
        Ok(())
    }

    /// Stages `bytes` for `path` (written and flushed now, beside the target; renamed into
    /// place on commit).
    pub fn file(&mut self, path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
        check_file(path)?;
        // a device or pipe, also behind a link (/dev/stdout → /proc/self/fd/1 → pipe:[…],
        // which has no path to resolve; /dev/fd/63 of a process substitution): written in
        // place through the name given
        if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
            self.streams.push((path.to_path_buf(), bytes.to_vec()));
            return Ok(());
        }
        // a link to a file is followed: the file it points to is replaced, the link stays
        let path = &match std::fs::symlink_metadata(path) {
            Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(path).map_err(io_error(path))?,
            _ => path.to_path_buf(),
        };
        let temp = sibling(path, "tmp");
        // recorded first, so that a failed write is removed by Drop
        self.staged.push((temp.clone(), path.to_path_buf()));
        let mut f = File::create(&temp).map_err(io_error(path))?;
        f.write_all(bytes).map_err(io_error(path))?;
        f.sync_all().map_err(io_error(path))?;
        Ok(())
    }

    /// Renames every staged file into place. Renames within a folder do not fail for lack of
    /// space, so once the files are written they all arrive.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let staged = std::mem::take(&mut self.staged);
        for (k, (temp, target)) in staged.iter().enumerate() {
            if let Err(e) = std::fs::rename(temp, target) {
                // those not yet renamed are removed by Drop
                self.staged = staged[k..].to_vec();
                return Err(io_error(target)(e));
            }
        }
        self.made.clear();
        for (target, bytes) in std::mem::take(&mut self.streams) {
            std::fs::write(&target, bytes).map_err(io_error(&target))?;
        }
        Ok(())
    }
}

impl Drop for Outputs {
    fn drop(&mut self) {
        for (temp, _) in &self.staged {
            let _ = std::fs::remove_file(temp);
        }
        for dir in self.made.iter().rev() {
            // only if empty: a folder that holds anything else is not ours to remove
            let _ = std::fs::remove_dir(dir);
        }
    }
}

/// The file in a folder termid built that lists what it wrote there: a line per file
/// (`<size> <FNV-1a 64 of its bytes> <path>`) and per folder (`- - <path>/`), paths relative
/// to the folder. Only a folder whose every entry is listed, unchanged, is termid's to replace.
pub const MANIFEST: &str = ".termid-files";

/// FNV-1a (64 bit) of a file's bytes: enough to tell an edited file from the one written.
fn fingerprint(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3))
}

/// Every entry under `dir` (not following links), relative, sorted; folders end in `/`.
fn entries_under(dir: &Path) -> std::io::Result<Vec<String>> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::new()];
    while let Some(rel) = stack.pop() {
        for e in std::fs::read_dir(dir.join(&rel))? {
            let e = e?;
            let path = rel.join(e.file_name());
            let text = path.to_string_lossy().into_owned();
            if e.file_type()?.is_dir() {
                out.push(format!("{text}/"));
                stack.push(path);
            } else {
                out.push(text);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// The manifest of folder `dir` as it is now (without the manifest itself).
fn manifest_of(dir: &Path) -> std::io::Result<String> {
    let mut text = String::new();
    for e in entries_under(dir)? {
        if e == MANIFEST {
            continue;
        }
        if e.ends_with('/') {
            text.push_str(&format!("- - {e}\n"));
        } else {
            let bytes = std::fs::read(dir.join(&e))?;
            text.push_str(&format!("{} {:016x} {e}\n", bytes.len(), fingerprint(&bytes)));
        }
    }
    Ok(text)
}

/// Checks, before any work, that [`replace_folder`] may replace `target`: it does not exist,
/// is an empty folder, or holds exactly what termid wrote there last time (its
/// [`MANIFEST`]), unchanged. A file or folder of anyone else's, or one edited since, is named
/// in the error and nothing is touched.
pub fn check_replaceable(target: &Path) -> Result<(), OutputError> {
    let unwritable = |reason: String| OutputError::Unwritable { path: target.display().to_string(), reason };
    if !target.exists() {
        return check_folder(target);
    }
    if !target.is_dir() {
        return Err(unwritable("exists and is not a folder".into()));
    }
    let entries = entries_under(target).map_err(io_error(target))?;
    if entries.is_empty() {
        return Ok(());
    }
    let advice = "termid replaces only a folder it wrote itself, unchanged; move your files elsewhere or name a new or empty folder";
    let Ok(recorded) = std::fs::read_to_string(target.join(MANIFEST)) else {
        return Err(unwritable(format!(
            "holds files termid did not write (no {MANIFEST} of termid's, e.g. `{}`); {advice}",
            entries[0]
        )));
    };
    let now = manifest_of(target).map_err(io_error(target))?;
    if now == recorded {
        return Ok(());
    }
    let listed: Vec<&str> = recorded.lines().collect();
    // the first difference, named: a foreign entry, or one of termid's changed or gone
    let first = now
        .lines()
        .find(|l| !listed.contains(l))
        .map(|l| {
            let name = l.splitn(3, ' ').nth(2).unwrap_or(l);
            let ours = listed.iter().any(|r| r.splitn(3, ' ').nth(2) == Some(name));
            if ours {
                format!("`{name}` was changed since termid wrote it")
            } else {
                format!("`{name}` is not termid's")
            }
        })
        .or_else(|| {
            let present: Vec<&str> = now.lines().filter_map(|l| l.splitn(3, ' ').nth(2)).collect();
            listed
                .iter()
                .filter_map(|l| l.splitn(3, ' ').nth(2))
                .find(|name| !present.contains(name))
                .map(|name| format!("`{name}`, which termid wrote, was removed or moved"))
        })
        .unwrap_or_else(|| "its files differ from those termid wrote".into());
    Err(unwritable(format!("{first}; {advice}")))
}

/// Builds a whole output folder with `build` in a fresh folder beside `target`, then swaps it
/// in under a lock on the parent folder, so two runs at once each leave a complete folder and
/// the last one wins. A `target` that exists must pass [`check_replaceable`] (checked first —
/// under the lock when that first look fails, since another run may be swapping its folder in —
/// and again under the lock, just before the swap): termid never deletes a file it did not
/// write.
pub fn replace_folder<E: From<OutputError>>(
    target: &Path,
    build: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E> {
    let parent = folder_of(target);
    if check_replaceable(target).is_err() {
        // another run may be swapping its folder in right now (its old one half deleted):
        // judged again under the lock, where no swap is under way
        let lock = File::open(parent).map_err(io_error(parent))?;
        lock.lock().map_err(io_error(parent))?;
        check_replaceable(target)?;
    }
    let fresh = sibling(target, "new");
    std::fs::create_dir(&fresh).map_err(io_error(&fresh))?;
    // removes the fresh folder on any failure below
    struct Remove(PathBuf);
    impl Drop for Remove {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
    let fresh_guard = Remove(fresh.clone());
    build(&fresh)?;
    let manifest = manifest_of(&fresh).map_err(io_error(&fresh))?;
    std::fs::write(fresh.join(MANIFEST), manifest).map_err(io_error(&fresh))?;
    let lock = File::open(parent).map_err(io_error(parent))?;
    lock.lock().map_err(io_error(parent))?;
    // what the user may have put there while the folder was built
    check_replaceable(target)?;
    let old = sibling(target, "old");
    if target.exists() {
        std::fs::rename(target, &old).map_err(io_error(target))?;
    }
    if let Err(e) = std::fs::rename(&fresh, target) {
        // put the old folder back
        let _ = std::fs::rename(&old, target);
        return Err(io_error(target)(e).into());
    }
    drop(lock);
    std::mem::forget(fresh_guard);
    let _ = std::fs::remove_dir_all(&old);
    Ok(())
}

/// A measured quantity at `n` significant figures (an error, a spread: what its data
/// support), fixed-point between 0.001 and 100 000 (`0.0206`, `1.55`, `2990`), else in
/// scientific notation (`9.52e-5`).
pub fn sig(x: f64, n: usize) -> String {
    let n = n.max(1);
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() || !(1e-3..1e5).contains(&x.abs()) {
        return format!("{x:.prec$e}", prec = n - 1);
    }
    let magnitude = x.abs().log10().floor() as i32;
    let digits = (n as i32 - 1 - magnitude).max(0) as usize;
    let text = format!("{x:.digits$}");
    // rounded up into the next decade (99.99 to three figures: "100.0"), one digit fewer
    match text.trim_start_matches('-').parse::<f64>() {
        Ok(v) if digits > 0 && v >= 10f64.powi(magnitude + 1) => format!("{x:.prec$}", prec = digits - 1),
        _ => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("termid-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_failed_transaction_leaves_old_files_and_nothing_new() {
        let d = scratch("rollback");
        std::fs::write(d.join("a.csv"), "old").unwrap();
        {
            let mut out = Outputs::new();
            out.file(&d.join("a.csv"), b"new").unwrap();
            out.folder(&d.join("figs/sub")).unwrap();
            out.file(&d.join("figs/sub/x.svg"), b"<svg/>").unwrap();
            // the third output's folder is missing: the command fails here
            assert!(out.file(&d.join("nope/b.csv"), b"x").is_err());
        }
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "old");
        assert_eq!(entries(&d), ["a.csv"]);
        let mut out = Outputs::new();
        out.file(&d.join("a.csv"), b"new").unwrap();
        out.commit().unwrap();
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "new");
        assert_eq!(entries(&d), ["a.csv"]);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn links_are_followed_and_devices_written_in_place() {
        let d = scratch("links");
        std::fs::write(d.join("real.csv"), "old").unwrap();
        std::os::unix::fs::symlink(d.join("real.csv"), d.join("link.csv")).unwrap();
        write_file(&d.join("link.csv"), b"new").unwrap();
        assert!(std::fs::symlink_metadata(d.join("link.csv")).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(d.join("real.csv")).unwrap(), "new");
        // a device is written to, not replaced
        write_file(Path::new("/dev/null"), b"x").unwrap();
        assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
        assert_eq!(entries(&d), ["link.csv", "real.csv"]);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn paths_are_checked_before_writing() {
        let d = scratch("check");
        assert!(check_file(&d.join("missing/x.csv")).is_err());
        assert!(check_file(&d).is_err());
        assert!(check_file(&d.join("x.csv")).is_ok());
        std::fs::write(d.join("file"), "").unwrap();
        assert!(check_folder(&d.join("file")).is_err());
        assert!(check_folder(&d.join("new")).is_ok());
        assert!(check_folder(&d.join("a/b")).is_err());
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn folders_are_swapped_whole_and_foreign_ones_refused() {
        let d = scratch("swap");
        let target = d.join("out");
        let build = |text: &'static str| {
            move |dir: &Path| -> Result<(), OutputError> {
                std::fs::write(dir.join("summary.json"), text).unwrap();
                std::fs::create_dir(dir.join("data")).unwrap();
                std::fs::write(dir.join("data/a.csv"), text).unwrap();
                Ok(())
            }
        };
        replace_folder(&target, build("1")).unwrap();
        replace_folder(&target, build("2")).unwrap();
        assert_eq!(std::fs::read_to_string(target.join("summary.json")).unwrap(), "2");
        // a failing build leaves the old folder and no sibling
        let failed = replace_folder(&target, |dir: &Path| {
            std::fs::write(dir.join("summary.json"), "3").unwrap();
            Err(OutputError::Unwritable { path: "x".into(), reason: "disk full".into() })
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_to_string(target.join("summary.json")).unwrap(), "2");
        assert_eq!(entries(&d), ["out"]);
        // a folder of the user's is not replaced
        std::fs::create_dir(d.join("mine")).unwrap();
        std::fs::write(d.join("mine/thesis.tex"), "").unwrap();
        assert!(replace_folder(&d.join("mine"), build("4")).is_err());
        assert!(d.join("mine/thesis.tex").exists());
        // nor termid's own folder once anything was added, edited or put in a subfolder
        for (what, add) in [
            (
                "precious.txt",
                Box::new(|t: &Path| std::fs::write(t.join("precious.txt"), "x").unwrap())
                    as Box<dyn Fn(&Path)>,
            ),
            ("data/mine.csv", Box::new(|t: &Path| std::fs::write(t.join("data/mine.csv"), "x").unwrap())),
            ("sub/", Box::new(|t: &Path| std::fs::create_dir(t.join("sub")).unwrap())),
            ("summary.json", Box::new(|t: &Path| std::fs::write(t.join("summary.json"), "edited").unwrap())),
        ] {
            add(&target);
            let e = replace_folder(&target, build("5")).unwrap_err().to_string();
            assert!(e.contains(&format!("`{what}`")), "{e}");
            assert_ne!(std::fs::read_to_string(target.join("summary.json")).unwrap(), "5");
            let path = target.join(what.trim_end_matches('/'));
            if path.is_dir() {
                std::fs::remove_dir(&path).unwrap();
            } else if what == "summary.json" {
                std::fs::write(&path, "2").unwrap();
            } else {
                std::fs::remove_file(&path).unwrap();
            }
            replace_folder(&target, build("2")).unwrap();
        }
        let _ = std::fs::remove_dir_all(&d);
    }

    /// Significant figures as read: a number that rounds up into the next decade keeps as
    /// many figures (99.99 to three is "100", it read "100.0"; 0.09999 is "0.100").
    #[test]
    fn significant_figures_across_a_decade() {
        assert_eq!(sig(99.99999999, 3), "100");
        assert_eq!(sig(-99.99999999, 3), "-100");
        assert_eq!(sig(0.099999, 3), "0.100");
        assert_eq!(sig(42.87, 3), "42.9");
        assert_eq!(sig(9.996, 3), "10.0");
        assert_eq!(sig(0.5, 3), "0.500");
        assert_eq!(sig(999.7, 2), "1000");
    }
}
