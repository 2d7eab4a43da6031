//! Output files written so that a failure loses nothing: every file goes to a temporary file
//! beside its target and is renamed over it only when all of a command's outputs are written
//! ([`Outputs`]); a whole folder is built beside its target and swapped in under a lock
//! ([`replace_folder`]). A full disk, a bad path or an error half-way leaves the old files as
//! they were and no new ones.

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
        // a link is followed: the file it points to is replaced, the link stays
        let path = &match std::fs::symlink_metadata(path) {
            Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(path).map_err(io_error(path))?,
            _ => path.to_path_buf(),
        };
        if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
            self.streams.push((path.clone(), bytes.to_vec()));
            return Ok(());
        }
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

/// Builds a whole output folder with `build` in a fresh folder beside `target`, then swaps it
/// in under a lock on the parent folder, so two runs at once each leave a complete folder and
/// the last one wins. A `target` that exists must be a folder `looks_ours` accepts (e.g. one
/// holding `summary.json`): a user's other folder is never replaced.
pub fn replace_folder<E: From<OutputError>>(
    target: &Path,
    looks_ours: impl Fn(&Path) -> bool,
    build: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E> {
    let unwritable = |reason: String| OutputError::Unwritable { path: target.display().to_string(), reason };
    if target.exists() {
        let empty = std::fs::read_dir(target).map(|mut d| d.next().is_none()).unwrap_or(false);
        if !target.is_dir() {
            return Err(unwritable("exists and is not a folder".into()).into());
        }
        if !empty && !looks_ours(target) {
            return Err(unwritable(
                "exists and holds other files; name a new or empty folder (termid replaces its output folder whole)".into(),
            )
            .into());
        }
    }
    check_folder(target)?;
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
    let parent = folder_of(target);
    let lock = File::open(parent).map_err(io_error(parent))?;
    lock.lock().map_err(io_error(parent))?;
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
        let ours = |p: &Path| p.join("summary.json").exists();
        let build = |text: &'static str| {
            move |dir: &Path| -> Result<(), OutputError> {
                std::fs::write(dir.join("summary.json"), text).unwrap();
                Ok(())
            }
        };
        replace_folder(&target, ours, build("1")).unwrap();
        replace_folder(&target, ours, build("2")).unwrap();
        assert_eq!(std::fs::read_to_string(target.join("summary.json")).unwrap(), "2");
        // a failing build leaves the old folder and no sibling
        let failed = replace_folder(&target, ours, |dir: &Path| {
            std::fs::write(dir.join("summary.json"), "3").unwrap();
            Err(OutputError::Unwritable { path: "x".into(), reason: "disk full".into() })
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_to_string(target.join("summary.json")).unwrap(), "2");
        assert_eq!(entries(&d), ["out"]);
        // a folder of the user's is not replaced
        std::fs::create_dir(d.join("mine")).unwrap();
        std::fs::write(d.join("mine/thesis.tex"), "").unwrap();
        assert!(replace_folder(&d.join("mine"), ours, build("4")).is_err());
        assert!(d.join("mine/thesis.tex").exists());
        let _ = std::fs::remove_dir_all(&d);
    }
}
