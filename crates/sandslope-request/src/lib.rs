//! # sandslope-request
//!
//! The typed requests under every front end of sandslope. Each command's inputs are one serde
//! type ([`PredictRequest`], [`SweepRequest`], ...) that names files and presets as a user
//! does, validated once into the library's types (reading the robot and terrain through
//! `sandslope-io`) and answered by one function returning the library's value, the one the
//! command prints with `--json`. The command line (clap), the server (a URL query or a JSON
//! body, read by [`Params`]) and Python translate into these types and nothing else, so a
//! check, a default or an answer is written once.
//!
//! Errors are [`RequestError`]s: the field at fault (the flag's name without dashes, which is
//! also the HTTP parameter) and a message naming it and its valid range.
//!
//! This crate sits between `sandslope-io` and the front ends (docs/architecture.md): requests
//! name files, which the physics library does not read.

#![warn(missing_docs)]

pub mod calibrate;
pub mod design;
pub mod drive;
pub mod error;
pub mod field;
pub mod fit;
pub use sandslope_format as format;
pub mod grammar;
pub mod infer;
pub mod params;
pub mod phase;
pub mod plan;
pub mod predict;
pub mod report;
pub mod report_text;
pub mod risk;
pub mod scenario;
pub mod simulate;
mod simulate_spread;
pub mod sweep;
pub mod track;

pub use calibrate::CalibrateRequest;
pub use design::DesignRequest;
pub use error::{RequestError, Result};
pub use fit::FitRequest;
pub use infer::InferRequest;
pub use params::Params;
pub use phase::PhaseRequest;
pub use plan::PlanRequest;
pub use predict::PredictRequest;
pub use report::ReportRequest;
pub use risk::RiskRequest;
pub use scenario::{RobotRequest, ScenarioRequest};
pub use simulate::SimulateRequest;
pub use sweep::SweepRequest;
pub use track::TrackRequest;
