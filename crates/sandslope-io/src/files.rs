//! Reading text files and writing output files atomically.
//!
//! A file is first written next to its destination under a temporary name and renamed into
//! place only when complete, so a failed run never leaves partial output. A failure to write
//! is a [`WriteError`], so a program can tell a broken environment (disk full, no permission)
//! from bad input.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context, Result};
use serde::de::DeserializeOwned;

/// Where an input came from, for messages.
#[derive(Debug, Clone)]
pub enum Source {
    /// A built-in preset.
    Preset(&'static str),
    /// A file.
    File(PathBuf),
}

impl std::fmt::Display for Source {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Source::Preset(n) => write!(f, "preset `{n}`"),
            Source::File(p) => write!(f, "{}", p.display()),
        }
    }
}

/// Reads a whole file, naming it in the error.
pub fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

/// Parses TOML into `T`, naming the source; unknown keys are rejected by `T`'s definition.
pub fn parse_toml<T: DeserializeOwned>(text: &str, source: &Source) -> Result<T> {
    toml::from_str(text).map_err(|e| anyhow!("{source}: {}", e.to_string().trim_end()))
}

/// An output file that could not be written: the environment's fault, not the input's.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}", path.display())]
pub struct WriteError {
    /// The destination.
    pub path: PathBuf,
    /// What the operating system said.
    #[source]
    pub source: std::io::Error,
}

/// CSV text of `rows` (with a header from the field names).
pub fn csv_string<T: serde::Serialize>(rows: &[T]) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r)?;
    }
    Ok(String::from_utf8(w.into_inner().context("CSV output")?)?)
}

/// A temporary path beside `path` that keeps its extension (backends choose formats by it).
pub fn temp_path_for(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "out".into());
    path.with_file_name(format!(".{name}.partial-{}", std::process::id()))
        .with_extension(path.extension().map(|e| e.to_string_lossy().into_owned()).unwrap_or_default())
}

/// Fails with a clear message when the folder `path` should be written into does not exist.
pub fn check_parent_exists(path: &Path) -> Result<()> {
    match path.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(dir) if !dir.is_dir() => {
            anyhow::bail!("cannot write {}: the folder {} does not exist", path.display(), dir.display())
        }
        _ => Ok(()),
    }
}

/// Writes `bytes` to `path` as [`write_via_temp`] does.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_via_temp(path, |tmp| {
        std::fs::write(tmp, bytes).map_err(|source| WriteError { path: path.to_path_buf(), source }.into())
    })
}

/// Runs `write` on a temporary file, then puts it in place of `path`; on failure the temporary
/// file is removed and `path` is untouched.
///
/// What "in place" means follows the most careful Unix tools:
/// - a symbolic link is followed: its target is replaced, the link stays a link;
/// - a regular file (or a new one) is replaced atomically by a rename in its own folder, and
///   keeps the permissions of the file it replaces;
/// - anything else that exists (`/dev/null`, a FIFO, a terminal) is written into, never
///   replaced, so `--out /dev/null` discards the output instead of replacing the device.
///
/// When [`stage_outputs`] was called (the `sandslope` binary does at start-up), the result is
/// only staged: nothing is put in place until [`commit_outputs`], so a run that fails after
/// writing some of its outputs leaves none of them.
pub fn write_via_temp(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let target = OutputTarget::resolve(path)?;
    let tmp = target.temp_path();
    register_temp(&tmp);
    if let Err(e) = write(&tmp) {
        remove_temp(&tmp);
        return Err(e);
    }
    let staged = Staged { temp: tmp, target, requested: path.to_path_buf() };
    let mut guard = lock_outputs();
    match guard.staged.as_mut() {
        Some(list) => {
            // The same output written twice in one run: the later content wins.
            if let Some(i) = list.iter().position(|s| s.target == staged.target) {
                let old = list.remove(i);
                if old.temp != staged.temp {
                    let _ = std::fs::remove_file(&old.temp);
                    guard.temps.retain(|t| t != &old.temp);
                }
            }
            guard.staged.as_mut().expect("checked above").push(staged);
            Ok(())
        }
        None => {
            drop(guard);
            let result = staged.put_in_place();
            remove_temp(&staged.temp);
            result
        }
    }
}

/// Where an output goes once its content is complete.
#[derive(Debug, Clone, PartialEq, Eq)]
enum OutputTarget {
    /// A regular file, existing or new (symbolic links resolved): replaced by a rename.
    Replace(PathBuf),
    /// An existing file that is not a regular file (a device, a FIFO): written into.
    Stream(PathBuf),
}

impl OutputTarget {
    /// Follows symbolic links from `path` (at most 40, as the kernel does) and decides how the
    /// output is put in place.
    fn resolve(path: &Path) -> Result<OutputTarget> {
        let mut at = path.to_path_buf();
        for _ in 0..40 {
            match std::fs::symlink_metadata(&at) {
                Ok(m) if m.file_type().is_symlink() => {
                    let link =
                        std::fs::read_link(&at).map_err(|source| WriteError { path: at.clone(), source })?;
                    at = match at.parent() {
                        Some(dir) if link.is_relative() => dir.join(link),
                        _ => link,
                    };
                }
                Ok(m) if m.is_dir() => {
                    anyhow::bail!("cannot write {}: it is a folder; give a file name", path.display())
                }
                Ok(m) if !m.is_file() => return Ok(OutputTarget::Stream(at)),
                _ => {
                    check_parent_exists(&at)?;
                    return Ok(OutputTarget::Replace(at));
                }
            }
        }
        Err(WriteError {
            path: path.to_path_buf(),
            source: std::io::Error::other("too many levels of symbolic links"),
        }
        .into())
    }

    /// The temporary file the output is written to first: beside a regular target (so the
    /// rename is atomic), in the system's temporary folder for a device or FIFO.
    fn temp_path(&self) -> PathBuf {
        match self {
            OutputTarget::Replace(p) => temp_path_for(p),
            OutputTarget::Stream(p) => {
                let name = p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
                temp_path_for(&std::env::temp_dir().join(format!("sandslope-{name}")))
            }
        }
    }
}

/// One output written to its temporary file, waiting to be put in place.
#[derive(Debug)]
struct Staged {
    temp: PathBuf,
    target: OutputTarget,
    requested: PathBuf,
}

impl Staged {
    fn put_in_place(&self) -> Result<()> {
        let fail = |source| WriteError { path: self.requested.clone(), source };
        match &self.target {
            OutputTarget::Replace(p) => {
                if let Ok(m) = std::fs::metadata(p) {
                    let _ = std::fs::set_permissions(&self.temp, m.permissions());
                }
                std::fs::rename(&self.temp, p).map_err(fail)?;
            }
            OutputTarget::Stream(p) => {
                let mut from = std::fs::File::open(&self.temp).map_err(fail)?;
                let mut to = std::fs::OpenOptions::new().write(true).open(p).map_err(fail)?;
                std::io::copy(&mut from, &mut to).map_err(fail)?;
            }
        }
        Ok(())
    }
}

/// The process's outputs: temporary files that exist now, and (when staging) the outputs
/// waiting for [`commit_outputs`].
#[derive(Debug, Default)]
struct Outputs {
    temps: Vec<PathBuf>,
    staged: Option<Vec<Staged>>,
    /// Folders this run created for its outputs, parents first.
    dirs: Vec<PathBuf>,
}

static OUTPUTS: std::sync::Mutex<Outputs> =
    std::sync::Mutex::new(Outputs { temps: Vec::new(), staged: None, dirs: Vec::new() });

fn lock_outputs() -> std::sync::MutexGuard<'static, Outputs> {
    OUTPUTS.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn register_temp(tmp: &Path) {
    lock_outputs().temps.push(tmp.to_path_buf());
}

fn remove_temp(tmp: &Path) {
    let _ = std::fs::remove_file(tmp);
    lock_outputs().temps.retain(|t| t != tmp);
}

/// From now on, outputs are staged and put in place together by [`commit_outputs`] (the
/// `sandslope` binary calls this at start-up; a library user who never calls it gets each
/// output in place as soon as it is written).
pub fn stage_outputs() {
    lock_outputs().staged.get_or_insert_with(Vec::new);
}

/// Puts every staged output in place, in the order written, and returns the paths as they
/// were asked for. A failure (which a rename within one folder makes rare) is reported and
/// the outputs not yet in place are removed.
pub fn commit_outputs() -> Result<Vec<PathBuf>> {
    let staged = {
        let mut guard = lock_outputs();
        guard.dirs.clear();
        guard.staged.as_mut().map(std::mem::take).unwrap_or_default()
    };
    let mut written = Vec::with_capacity(staged.len());
    let mut result = Ok(());
    for s in &staged {
        if result.is_ok() {
            result = s.put_in_place();
            if result.is_ok() {
                written.push(s.requested.clone());
            }
        }
        remove_temp(&s.temp);
    }
    result.map(|()| written)
}

/// Removes every temporary file of this process and forgets the staged outputs: what a failed
/// or interrupted run calls so that it leaves nothing behind. Safe to call from a signal
/// handler's thread.
pub fn discard_outputs() {
    let mut guard = lock_outputs();
    for t in guard.temps.drain(..) {
        let _ = std::fs::remove_file(t);
    }
    if let Some(list) = guard.staged.as_mut() {
        list.clear();
    }
    // Deepest first; a folder that is not empty (something else put a file there) stays.
    for d in guard.dirs.drain(..).rev() {
        let _ = std::fs::remove_dir(d);
    }
}

/// Creates the output folder `dir` and its missing parents, as `mkdir -p` does. A run that
/// then fails removes the folders it created ([`discard_outputs`]); [`commit_outputs`] keeps them.
pub fn create_output_dir(dir: &Path) -> Result<()> {
    if dir.is_file() {
        anyhow::bail!("cannot write into {}: it is a file, not a folder", dir.display());
    }
    let mut missing = Vec::new();
    let mut at = Some(dir);
    while let Some(d) = at.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
        missing.push(d.to_path_buf());
        at = d.parent();
    }
    std::fs::create_dir_all(dir).map_err(|source| WriteError { path: dir.to_path_buf(), source })?;
    lock_outputs().dirs.extend(missing.into_iter().rev());
    Ok(())
}

/// The line a record is on: the csv reader's position is where it began reading, before the
/// blank lines and `#` comments it skipped, so those are stepped over here.
pub(crate) fn record_line(text: &str, at: &csv::Position) -> u64 {
    let mut line = at.line();
    let mut rest = text.get(at.byte() as usize..).unwrap_or("");
    while let Some((first, after)) = rest.split_once('\n') {
        if !(first.starts_with('#') || first.is_empty() || first == "\r") {
            break;
        }
        line += 1;
        rest = after;
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_leaves_nothing_when_the_folder_is_missing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing").join("out.csv");
        let err = write_atomic(&path, b"x").unwrap_err().to_string();
        assert!(err.contains("does not exist"), "{err}");
        assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
    }

    #[test]
    fn atomic_write_replaces_the_file_whole() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "second");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
