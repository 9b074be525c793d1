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

/// Writes `bytes` to `path` atomically (temporary file, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    check_parent_exists(path)?;
    let tmp = temp_path_for(path);
    let result = std::fs::write(&tmp, bytes).and_then(|_| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(|source| WriteError { path: path.to_path_buf(), source }.into())
}

/// Runs `write` on a temporary path beside `path`, then renames it into place; on failure
/// the temporary file is removed and `path` is untouched.
pub fn write_via_temp(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    check_parent_exists(path)?;
    let tmp = temp_path_for(path);
    match write(&tmp).and_then(|_| {
        std::fs::rename(&tmp, path).map_err(|source| WriteError { path: path.to_path_buf(), source }.into())
    }) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
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
