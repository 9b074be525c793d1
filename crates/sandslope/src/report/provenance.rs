//! Where every input of the report comes from: measured (printed in the paper, with its
//! section, or the user's own measurement), assumed (in neither; why this value), tuned (chosen
//! to match something, and what) or derived (follows from other inputs). The rows themselves,
//! in words, are the front ends' (the request layer's `report_text`, from the [`super::Evidence`]).

use serde::Serialize;

/// How an input came to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ProvenanceKind {
    /// Printed in the paper (the detail names the section), or measured by the user.
    Measured,
    /// Not in the paper nor measured: a value chosen for a stated reason.
    Assumed,
    /// Chosen to match an observation (the detail names which).
    Tuned,
    /// Follows from other inputs.
    Derived,
}

/// An input's provenance: its kind and the sentence that justifies it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Provenance {
    /// Measured, assumed, tuned or derived.
    pub kind: ProvenanceKind,
    /// Where it is printed, why this value, what it was tuned to, or what it follows from.
    pub detail: String,
}

/// One row of the inputs table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Input {
    /// What.
    pub name: String,
    /// Its value or source, as the user named it.
    pub value: String,
    /// Where it comes from.
    pub provenance: Provenance,
}
