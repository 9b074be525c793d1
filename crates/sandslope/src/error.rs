//! Errors raised when a parameter is outside the range the model accepts.
//!
//! Every constructor of a validated type ([`crate::Robot`], [`crate::Terrain`],
//! [`crate::Slope`], ...) reports the offending key, its value and the valid range, so that
//! a user reading the message knows what to change without opening the docs.

use std::fmt;

/// A parameter that is outside its valid range.
///
/// Displays as `hip_height_m = 0.09 must be between 0 and 2 * leg_radius_m = 0.08`.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamError {
    /// The key as it appears in a file or on the command line (e.g. `hip_height_m`).
    pub key: String,
    /// The rejected value (may be NaN or infinite).
    pub value: f64,
    /// The valid range, phrased to follow "must be" (e.g. `greater than 0`).
    pub expected: String,
}

impl ParamError {
    /// A new error for `key = value`, which must be `expected`.
    pub fn new(key: impl Into<String>, value: f64, expected: impl Into<String>) -> Self {
        Self { key: key.into(), value, expected: expected.into() }
    }

    /// The same error reported under another key name (e.g. a CLI flag instead of a file key).
    pub fn renamed(mut self, key: impl Into<String>) -> Self {
        self.key = key.into();
        self
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.value;
        // Extreme values in scientific notation: `{}` writes 1e-320 as a zero and 324 more
        // digits. Values from 1e-15 to 1e21 keep the plain form the messages have always had.
        if v != 0.0 && v.is_finite() && !(1e-15..1e21).contains(&v.abs()) {
            write!(f, "{} = {v:e} must be {}", self.key, self.expected)
        } else {
            write!(f, "{} = {v} must be {}", self.key, self.expected)
        }
    }
}

impl std::error::Error for ParamError {}

/// Checks that `value` is finite and strictly positive.
pub(crate) fn positive(key: &str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ParamError::new(key, value, "a finite number greater than 0"))
    }
}

/// Checks that `value` is finite and not negative.
pub(crate) fn non_negative(key: &str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(ParamError::new(key, value, "a finite number of at least 0"))
    }
}
