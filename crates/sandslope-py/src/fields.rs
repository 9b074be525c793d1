//! The request layer's field tables as Python sees them: each keyword with its default and its
//! parser, so that a test holds the Python functions' signatures and their stubs to the tables
//! the command line's flags are built from (`tests/test_request_keywords.py`).

use pyo3::prelude::*;

use sandslope_request::field::{Kind, Table};
use sandslope_request::{calibrate, drive, fit, phase, plan, report, risk};

use crate::value_error;

/// The tables of `command`'s own fields.
fn tables(command: &str) -> PyResult<Vec<Table>> {
    Ok(match command {
        "fit" => vec![fit::FIELDS],
        "calibrate" => vec![calibrate::FIELDS],
        "report" => vec![report::FIELDS, Table { command: "report", fields: &[report::TRACKS] }],
        "risk" => vec![risk::FIELDS],
        "phase" => vec![phase::FIELDS],
        "drive" => vec![drive::FIELDS],
        "plan" => vec![plan::FIELDS],
        other => {
            return Err(value_error(format!(
                "command = {other:?} must be \"fit\", \"calibrate\", \"report\", \"risk\", \"phase\", \"drive\" or \"plan\""
            )))
        }
    })
}

/// The name of a field's parser: `"number"`, `"whole"`, `"text"`, `"switch"`, `"choice"` or `"list"`.
fn kind_name(kind: Kind) -> &'static str {
    match kind {
        Kind::Number => "number",
        Kind::Whole => "whole",
        Kind::Text => "text",
        Kind::Switch => "switch",
        Kind::Choice(_) => "choice",
        Kind::List => "list",
    }
}

/// `command`'s fields that Python takes, as `(keyword, default as text or None, parser)`, in
/// the table's order.
#[pyfunction]
pub fn request_keywords(command: &str) -> PyResult<Vec<(&'static str, Option<&'static str>, &'static str)>> {
    Ok(tables(command)?
        .iter()
        .flat_map(|t| t.fields.iter())
        .filter(|f| !f.keyword.is_empty())
        .map(|f| (f.keyword, f.default, kind_name(f.kind)))
        .collect())
}
