//! Printing results: tables for people, JSON and CSV for machines. Files are written
//! atomically by `sandslope_io::files` (re-exported here for the commands).

use std::io::Write;

use anyhow::Result;
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

pub use sandslope_io::files::{check_parent_exists, csv_string, write_atomic, write_via_temp};
