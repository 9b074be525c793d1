//! Printing results: tables for people, JSON and CSV for machines. Files are written
//! atomically by `sandslope_io::files` (re-exported here for the commands).

use std::io::Write;

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

/// The speed column of `predict` and `sweep`, cm/s: the speed the robot makes; where the
/// regime rules the stance model's speed out (legs sinking, slope at or above repose) that
/// speed in parentheses, explained by [`ruled_out_note`]; `-` where the model has none.
pub fn speed_cell(e: &sandslope::SlopeEvaluation) -> String {
    match (e.speed(), e.model_speed()) {
        (Some(v), _) => format!("{:.2}", v * 100.0),
        (None, Some(v)) => format!("({:.2})", v * 100.0),
        (None, None) => "-".into(),
    }
}

/// The note printed under a table that shows a speed in parentheses.
pub fn ruled_out_note() -> &'static str {
    "speed in parentheses: the stance model's v = s/(T/2), which the regime rules out (the surface yields at \
     or above the angle of repose, or the legs sink; docs/model.md §6).\nJSON and CSV give it as \
     model_speed_m_s, with speed_m_s null."
}

/// The terminal's number format for strengths (`2.237e6`), shared by every front end.
pub use sandslope_request::format::e_notation as sci;

/// Prints `value` as pretty JSON on stdout.
pub fn print_json<T: serde::Serialize>(value: &T) -> Result<()> {
    let mut out = std::io::stdout().lock();
    serde_json::to_writer_pretty(&mut out, value)
        .map_err(std::io::Error::from)
        .and_then(|()| writeln!(out))
        .context(STDOUT)
}

/// The context of a failure to write to stdout (exit code 3, or 0 for a closed pipe).
pub const STDOUT: &str = "cannot write to standard output";

pub use sandslope_files::{check_parent_exists, csv_string, write_atomic};
