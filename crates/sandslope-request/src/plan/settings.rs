//! The search's settings, descent rule and objectives read from their fields, checked once
//! for the file-based [`PlanRequest`](super::PlanRequest) and the grid requests of `grid.rs`,
//! messages in the front end's words.

use anyhow::anyhow;

use sandslope::plan::{Descent, Objective, PlanSettings};

use crate::error::{check_range, RequestError, Result, Words};
use crate::grammar;

/// The planner's settings from their fields, checked, messages in `words`: the command line's
/// checks its flags first (`--max-roll`, `--time-weight`, `--cv-n`, `--cv-s`); the library
/// names its keys as Python's keywords (`max_roll_deg`, `time_weight`).
#[allow(clippy::too_many_arguments)]
pub fn settings_in(
    words: Words,
    max_roll: f64,
    descent: Descent,
    allow_metastable: bool,
    time_weight: f64,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> Result<PlanSettings> {
    let field_of_key = |key: &str| if key == "time_weight" { "time-weight" } else { "max-roll" };
    if words == Words::Flag {
        let max_roll = check_range("max-roll", max_roll, 0.0, 90.0)?;
        if max_roll <= 0.0 || max_roll >= 90.0 {
            return Err(RequestError::invalid(
                "max-roll",
                format!("--max-roll = {max_roll} must be strictly between 0 and 90 degrees"),
            ));
        }
        check_range("time-weight", time_weight, 0.0, f64::INFINITY)?;
    }
    grammar::check_cvs_in(words, cv_n, cv_s)?;
    PlanSettings::new(max_roll, descent, allow_metastable, time_weight).map_err(|e| match words {
        Words::Flag => RequestError::from_error(None, anyhow!("{e}")),
        Words::Keyword => RequestError::invalid(field_of_key(&e.key), e),
    })
}

/// The descent rule named `text` (`symmetric` or `level`), or an error in `words`.
pub fn parse_descent(words: Words, text: &str) -> Result<Descent> {
    Descent::parse(text).ok_or_else(|| {
        let message = match words {
            Words::Flag => format!("--descent = `{text}` must be symmetric (as climbing |pitch|) or level"),
            Words::Keyword => format!("descent = {text:?} must be \"symmetric\" or \"level\""),
        };
        RequestError::invalid("descent", message)
    })
}

/// The objective named `name` (`time`, `risk` or `distance`), or an error in `words`.
pub fn parse_objective(words: Words, name: &str) -> Result<Objective> {
    let name = name.trim();
    Objective::ALL.into_iter().find(|o| o.name() == name).ok_or_else(|| {
        let message = match words {
            Words::Flag => format!("--objective: `{name}` is not an objective: time, risk or distance"),
            Words::Keyword => format!("objective = {name:?} must be \"time\", \"risk\" or \"distance\""),
        };
        RequestError::invalid("objective", message)
    })
}
