//! [`RequestError`]: a refused request, carrying the field at fault.

use std::fmt;

/// Why a request was refused: the field at fault, when one is, and the error itself.
///
/// The field is the request's own name for it (`slope`, `k-n`, `leg-radius`): the command
/// line's flag without its dashes, the HTTP parameter, and (with `_` for `-`) the Python
/// keyword, so a front end names the field from this value and never by scanning the text.
/// The message says what is wrong and the valid range in the command line's words
/// (`--mass = -1 must be a finite number greater than 0`), which the CLI prints and the server
/// returns as they are. A file or preset that cannot be read keeps the reader's whole error
/// (its causes say whether the input is wrong or the system failed, which sets the CLI's exit
/// code): [`RequestError::into_anyhow`] gives it back unchanged.
///
/// Not a `std::error::Error` itself, so that `?` into `anyhow` hands the inner error on whole
/// (cause chain and all) rather than wrapping it.
#[derive(Debug)]
pub struct RequestError {
    field: Option<String>,
    error: anyhow::Error,
}

impl RequestError {
    /// A value of `field` the request cannot accept; `message` names it and its valid range.
    pub fn invalid(field: impl Into<String>, message: impl fmt::Display) -> RequestError {
        RequestError { field: Some(field.into()), error: anyhow::anyhow!("{message}") }
    }

    /// An error about `field` from below (a reader, the library), kept whole.
    pub fn from_error(field: Option<&str>, error: anyhow::Error) -> RequestError {
        RequestError { field: field.map(str::to_string), error }
    }

    /// A computation stopped on its stop flag (a front end's Ctrl-C) before its end: no field
    /// is at fault, and the front end reports the signal instead.
    pub fn interrupted() -> RequestError {
        RequestError { field: None, error: anyhow::anyhow!("interrupted") }
    }

    /// The request field at fault (`slope`, `k-n`), when there is one.
    pub fn field(&self) -> Option<&str> {
        self.field.as_deref()
    }

    /// The error's message, its causes joined by `: ` (anyhow's `{:#}`).
    pub fn message(&self) -> String {
        format!("{:#}", self.error)
    }

    /// The error as the command line reports it, cause chain unchanged.
    pub fn into_anyhow(self) -> anyhow::Error {
        self.error
    }
}

impl fmt::Display for RequestError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:#}", self.error)
    }
}

impl From<RequestError> for anyhow::Error {
    fn from(e: RequestError) -> anyhow::Error {
        e.error
    }
}

/// The result of reading or answering a request.
pub type Result<T> = std::result::Result<T, RequestError>;

/// Checks a number is finite and within `lo..=hi`, naming the field as its flag (`hi`
/// infinite: no upper bound).
pub fn check_range(field: &str, value: f64, lo: f64, hi: f64) -> Result<f64> {
    check_range_in(Words::Flag, field, value, lo, hi)
}

/// [`check_range`], naming the field in the front end's `words`.
pub fn check_range_in(words: Words, field: &str, value: f64, lo: f64, hi: f64) -> Result<f64> {
    let name = words.name(field);
    if value.is_finite() && value >= lo && value <= hi {
        Ok(value)
    } else if hi == f64::INFINITY {
        Err(RequestError::invalid(
            field,
            format!("{name} = {value} must be a finite number of at least {lo}"),
        ))
    } else {
        Err(RequestError::invalid(field, format!("{name} = {value} must be between {lo} and {hi}")))
    }
}

/// Checks a number is finite and strictly positive, naming the field as its flag.
pub fn check_positive(field: &str, value: f64) -> Result<f64> {
    check_positive_in(Words::Flag, field, value)
}

/// [`check_positive`], naming the field in the front end's `words`.
pub fn check_positive_in(words: Words, field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(RequestError::invalid(
            field,
            format!("{} = {value} must be a finite number greater than 0", words.name(field)),
        ))
    }
}

/// How a front end names a field in its messages: the command line's flag (`--plateau-from`)
/// or Python's keyword (`plateau_from`). The field itself is the same (`plateau-from`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Words {
    /// The command line's flag.
    Flag,
    /// Python's keyword.
    Keyword,
}

impl Words {
    /// `field` as this front end names it.
    pub fn name(self, field: &str) -> String {
        match self {
            Words::Flag => format!("--{field}"),
            Words::Keyword => field.replace('-', "_"),
        }
    }

    /// A field set to a word as this front end writes it: `--law per-slope` or
    /// `law="per-slope"`.
    pub fn setting(self, field: &str, value: &str) -> String {
        match self {
            Words::Flag => format!("--{field} {value}"),
            Words::Keyword => format!("{}={value:?}", self.name(field)),
        }
    }
}
