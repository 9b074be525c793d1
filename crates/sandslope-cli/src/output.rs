//! Writing results: tables for people, JSON and CSV for machines, files written atomically.
//!
//! A file is first written next to its destination under a temporary name and renamed into
//! place only when complete, so a failed run never leaves partial output.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use comfy_table::{presets::UTF8_BORDERS_ONLY, Table};

/// `--json` / `--csv` on commands that print results (a table when neither is given).
#[derive(Debug, Clone, Copy, Args)]
pub struct FormatArgs {
    /// Print JSON instead of a table.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print CSV instead of a table.
    #[arg(long)]
    pub csv: bool,
}

/// How to print results.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Human-readable table.
    Table,
    /// JSON on stdout.
    Json,
    /// CSV on stdout.
    Csv,
}

impl FormatArgs {
    /// The selected format.
    pub fn format(self) -> Format {
        if self.json {
            Format::Json
        } else if self.csv {
            Format::Csv
        } else {
            Format::Table
        }
    }
}

/// A table with the project's style and the given header.
pub fn table(header: &[&str]) -> Table {
    let mut t = Table::new();
    t.load_style(UTF8_BORDERS_ONLY).set_header(header.iter().copied());
    t
}

/// Formats an optional number with `digits` significant decimals, `-` when absent.
pub fn num(x: Option<f64>, decimals: usize) -> String {
    match x {
        Some(v) => format!("{v:.decimals$}"),
        None => "-".into(),
    }
}

/// Formats a number in scientific notation with 3 significant digits.
pub fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

/// Prints `value` as pretty JSON on stdout.
pub fn print_json<T: serde::Serialize>(value: &T) -> Result<()> {
    let mut out = std::io::stdout().lock();
    serde_json::to_writer_pretty(&mut out, value)?;
    writeln!(out)?;
    Ok(())
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
    result.with_context(|| format!("cannot write {}", path.display()))
}

/// Runs `write` on a temporary path beside `path`, then renames it into place; on failure
/// the temporary file is removed and `path` is untouched.
pub fn write_via_temp(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    check_parent_exists(path)?;
    let tmp = temp_path_for(path);
    match write(&tmp)
        .and_then(|_| std::fs::rename(&tmp, path).with_context(|| format!("cannot write {}", path.display())))
    {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}
