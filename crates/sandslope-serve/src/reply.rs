//! What every route answers with: a [`Reply`] written as it is sent, or an [`ApiError`]
//! naming the parameter at fault. Below the routes ([`crate::api`], [`crate::data`],
//! [`crate::http`]), so none of them imports another for these.

use std::io::Write;

use serde::Serialize;

use sandslope_request::RequestError;

/// How a reply's body is made: written into the response as the client reads it (http.rs
/// sends it in 64 KiB chunks), so a large answer (the 44 MB of a 2^20-cell `risk --map`) is
/// never whole in memory: a client that does not read holds the computed value and a few
/// chunks.
pub type Writer = Box<dyn FnOnce(&mut dyn Write) -> std::io::Result<()> + Send>;

/// An answer: its body, type, and the file name a download is saved under.
pub struct Reply {
    /// The body.
    pub body: Writer,
    /// Its content type.
    pub content_type: &'static str,
    /// For downloads: the suggested file name.
    pub filename: Option<&'static str>,
}

impl Reply {
    /// `value` as `print_json` prints it (pretty JSON and a newline), written as it is sent.
    pub fn pretty<T: Serialize + Send + 'static>(value: T) -> Reply {
        let write = move |w: &mut dyn Write| {
            serde_json::to_writer_pretty(&mut *w, &value)?;
            w.write_all(b"\n")
        };
        Reply { body: Box::new(write), content_type: "application/json", filename: None }
    }

    /// `value` as compact JSON (the page's data need not read like `--json`, only be small),
    /// written as it is sent.
    pub fn compact<T: Serialize + Send + 'static>(value: T) -> Reply {
        let write = move |w: &mut dyn Write| Ok(serde_json::to_writer(&mut *w, &value)?);
        Reply { body: Box::new(write), content_type: "application/json", filename: None }
    }

    /// The whole body in memory.
    #[cfg(test)]
    pub fn into_bytes(self) -> std::io::Result<Vec<u8>> {
        let mut out = Vec::new();
        (self.body)(&mut out)?;
        Ok(out)
    }
}

/// A refused request: the HTTP status, the parameter at fault (when one is) and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ApiError {
    /// HTTP status code (400 bad input, 404 no such endpoint, 413/414 too big, ...).
    #[serde(skip)]
    pub status: u16,
    /// The request parameter the error is about, without `--` (`slope`), when there is one.
    pub field: Option<String>,
    /// What is wrong and what is accepted, as the command line says it.
    pub error: String,
}

impl ApiError {
    /// A 400 about `field`.
    pub fn bad(field: impl Into<Option<String>>, error: impl Into<String>) -> ApiError {
        ApiError { status: 400, field: field.into(), error: error.into() }
    }
}

impl From<RequestError> for ApiError {
    /// A refused request: 400, the field the request layer names.
    fn from(e: RequestError) -> ApiError {
        ApiError::bad(e.field().map(str::to_string), e.message())
    }
}

/// `value` as `print_json` prints it: pretty JSON and a newline.
pub fn json<T: Serialize>(value: &T) -> Result<Vec<u8>, ApiError> {
    let mut body = serde_json::to_vec_pretty(value).map_err(|e| ApiError {
        status: 500,
        field: None,
        error: format!("serialising the answer: {e}"),
    })?;
    body.push(b'\n');
    Ok(body)
}
