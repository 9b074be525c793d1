//! [`Params`]: a request written as `key=value` text pairs (a URL query, or a JSON body whose
//! values the server has turned into text), read field by field into a typed request.
//!
//! Each read names its field; a value that is not of the field's kind, a field given twice
//! and a key no field reads are refused naming that key, and the list of accepted keys is the
//! list of fields the request read, so it cannot go stale.

use crate::error::{RequestError, Result};

/// `key=value` pairs being read into one request.
#[derive(Debug)]
pub struct Params<'a> {
    command: &'a str,
    pairs: &'a [(String, String)],
    used: Vec<bool>,
    asked: Vec<&'static str>,
}

impl<'a> Params<'a> {
    /// The pairs of a request to `command` (named in messages), in the order given.
    pub fn new(command: &'a str, pairs: &'a [(String, String)]) -> Params<'a> {
        Params { command, pairs, used: vec![false; pairs.len()], asked: Vec::new() }
    }

    /// The text given for `key`, if any; a key given twice is refused.
    pub fn text(&mut self, key: &'static str) -> Result<Option<&'a str>> {
        self.asked.push(key);
        let mut found = None;
        for (i, (k, v)) in self.pairs.iter().enumerate() {
            if k == key {
                if found.is_some() {
                    return Err(RequestError::invalid(key, format!("--{key} is given more than once")));
                }
                self.used[i] = true;
                found = Some(v.as_str());
            }
        }
        Ok(found)
    }

    /// `key` as a number, if given (the command line's number grammar, `f64::from_str`).
    pub fn number(&mut self, key: &'static str) -> Result<Option<f64>> {
        let Some(text) = self.text(key)? else { return Ok(None) };
        text.trim()
            .parse::<f64>()
            .map(Some)
            .map_err(|_| RequestError::invalid(key, format!("--{key} = `{text}` is not a number")))
    }

    /// `key` as a switch: absent is false; given, its value must be `true`, `false`, `1`, `0` or
    /// empty (a bare `key` in a query string), empty meaning true.
    pub fn flag(&mut self, key: &'static str) -> Result<bool> {
        match self.text(key)?.map(str::trim) {
            None => Ok(false),
            Some("" | "true" | "1") => Ok(true),
            Some("false" | "0") => Ok(false),
            Some(other) => {
                Err(RequestError::invalid(key, format!("--{key} = `{other}` must be true or false")))
            }
        }
    }

    /// `key` as a number, `default` when not given.
    pub fn number_or(&mut self, key: &'static str, default: f64) -> Result<f64> {
        Ok(self.number(key)?.unwrap_or(default))
    }

    /// `key` as a number that must be given; `what` says what it is.
    pub fn required_number(&mut self, key: &'static str, what: &str) -> Result<f64> {
        self.number(key)?.ok_or_else(|| RequestError::invalid(key, format!("--{key} is required: {what}")))
    }

    /// `key` as a whole number from 0 to 2^32 - 1, if given.
    pub fn whole(&mut self, key: &'static str) -> Result<Option<u32>> {
        let Some(text) = self.text(key)? else { return Ok(None) };
        text.trim().parse::<u32>().map(Some).map_err(|_| {
            RequestError::invalid(key, format!("--{key} = `{text}` is not a whole number of at least 0"))
        })
    }

    /// `key` as text, `default` when not given.
    pub fn text_or(&mut self, key: &'static str, default: &str) -> Result<String> {
        Ok(self.text(key)?.unwrap_or(default).to_string())
    }

    /// Refuses any key no read asked for, listing the accepted ones.
    pub fn finish(self) -> Result<()> {
        match self.pairs.iter().zip(&self.used).find(|(_, used)| !**used) {
            Some(((key, _), _)) => Err(RequestError::invalid(
                key.clone(),
                format!("unknown parameter `{key}`: {} takes {}", self.command, self.asked.join(", ")),
            )),
            None => Ok(()),
        }
    }
}
