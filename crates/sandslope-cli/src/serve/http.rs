//! The HTTP layer: a small synchronous server (`tiny_http`) with two threads that read
//! requests and answer the embedded page, and a bounded pool of compute threads that answer
//! the API, so a slow phase map or route never holds up the page or other requests.
//!
//! Limits, each refused with a 4xx whose JSON names it: a URL of at most [`MAX_URL`] bytes
//! (414), a POST body of at most [`MAX_BODY`] bytes (413), at most [`MAX_QUEUE`] API requests
//! waiting for a compute thread (503). A panic inside a computation is caught and answered
//! with a 500 (none is known: bad input is a 400).

use std::io::Read;
use std::net::{IpAddr, SocketAddr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex};

use anyhow::{anyhow, Result};
use tiny_http::{Header, Method, Request, Response};

use super::api::{self, ApiError, Served};
use super::data::{self, Reply};
use super::page;

/// Longest request URL accepted, bytes.
pub const MAX_URL: usize = 8192;
/// Largest POST body accepted, bytes.
pub const MAX_BODY: usize = 65_536;
/// Most API requests waiting for a compute thread; more get 503.
pub const MAX_QUEUE: usize = 1024;
/// Threads that read requests and answer the page's files.
const READERS: usize = 2;

/// One API request handed to a compute thread.
struct Job {
    request: Request,
    path: String,
    params: Vec<(String, String)>,
}

/// Answers a queued request by its path: `/api/<command>`, `/data/<name>`, `/download/<file>`.
fn dispatch(path: &str, params: &[(String, String)], served: &Served) -> Result<Reply, ApiError> {
    if let Some(command) = path.strip_prefix("/api/") {
        api::answer(command, params, served).map(Reply::json)
    } else if let Some(name) = path.strip_prefix("/data/") {
        data::answer(name, params, served)
    } else if let Some(file) = path.strip_prefix("/download/") {
        data::download(file, params, served)
    } else {
        Err(ApiError { status: 404, field: None, error: format!("no page {path}") })
    }
}

/// Whether `path` is answered by the compute threads.
fn computed(path: &str) -> bool {
    ["/api/", "/data/", "/download/"].iter().any(|p| path.starts_with(p))
}

/// A bound server, ready to [`Server::serve`].
pub struct Server {
    http: Arc<tiny_http::Server>,
    served: Arc<Served>,
    threads: usize,
}

impl Server {
    /// Listens on `host:port` (port 0: any free port).
    pub fn bind(host: IpAddr, port: u16, served: Served, threads: usize) -> Result<Server> {
        let http = tiny_http::Server::http(SocketAddr::new(host, port))
            .map_err(|e| anyhow!("cannot listen on {host}:{port}: {e}"))?;
        Ok(Server { http: Arc::new(http), served: Arc::new(served), threads: threads.max(1) })
    }

    /// The address the server listens on (with the port chosen when 0 was asked).
    pub fn address(&self) -> String {
        match self.http.server_addr().to_ip() {
            Some(a) => a.to_string(),
            None => "?".into(),
        }
    }

    /// Answers requests until the process ends.
    pub fn serve(self) {
        let (tx, rx) = sync_channel::<Job>(MAX_QUEUE);
        let rx = Arc::new(Mutex::new(rx));
        let mut handles = Vec::new();
        for _ in 0..self.threads {
            let (rx, served) = (Arc::clone(&rx), Arc::clone(&self.served));
            handles.push(std::thread::spawn(move || compute_loop(&rx, &served)));
        }
        for _ in 0..READERS {
            let (http, tx, served) = (Arc::clone(&self.http), tx.clone(), Arc::clone(&self.served));
            handles.push(std::thread::spawn(move || read_loop(&http, &tx, &served)));
        }
        drop(tx);
        for h in handles {
            let _ = h.join();
        }
    }
}

fn read_loop(http: &tiny_http::Server, tx: &SyncSender<Job>, served: &Served) {
    loop {
        let Ok(request) = http.recv() else { continue };
        route(request, tx, served);
    }
}

fn compute_loop(rx: &Mutex<Receiver<Job>>, served: &Served) {
    loop {
        let job = {
            let Ok(rx) = rx.lock() else { return };
            match rx.recv() {
                Ok(job) => job,
                Err(_) => return,
            }
        };
        let result = catch_unwind(AssertUnwindSafe(|| dispatch(&job.path, &job.params, served)))
            .unwrap_or_else(|_| {
                Err(ApiError {
                    status: 500,
                    field: None,
                    error: "internal error: the computation panicked (please report it)".into(),
                })
            });
        respond_api(job.request, result);
    }
}

/// Sends a result: the body on success, `{"field": ..., "error": ...}` otherwise.
fn respond_api(request: Request, result: Result<Reply, ApiError>) {
    let (status, reply) = match result {
        Ok(reply) => (200, reply),
        Err(e) => (e.status, Reply::json(api::json(&e).unwrap_or_else(|_| b"{}\n".to_vec()))),
    };
    let mut response =
        with_type(Response::from_data(reply.body).with_status_code(status), reply.content_type);
    if let Some(name) = reply.filename {
        let value = format!("attachment; filename=\"{name}\"");
        if let Ok(h) = Header::from_bytes(&b"Content-Disposition"[..], value.as_bytes()) {
            response.add_header(h);
        }
    }
    let _ = request.respond(response);
}

fn with_type<R: Read>(r: Response<R>, content_type: &str) -> Response<R> {
    let mut r = r;
    for (k, v) in [
        ("Content-Type", content_type),
        ("Cache-Control", "no-store"),
        ("X-Content-Type-Options", "nosniff"),
        // The page loads nothing from anywhere but this server.
        (
            "Content-Security-Policy",
            "default-src 'self'; img-src 'self' data: blob:; style-src 'self'; script-src 'self'; \
             connect-src 'self'; frame-ancestors 'none'",
        ),
    ] {
        if let Ok(h) = Header::from_bytes(k.as_bytes(), v.as_bytes()) {
            r.add_header(h);
        }
    }
    r
}

fn refuse(request: Request, status: u16, field: Option<&str>, error: String) {
    respond_api(request, Err(ApiError { status, field: field.map(str::to_string), error }));
}

/// Answers the page's files on this thread and queues API requests for the compute threads.
fn route(mut request: Request, tx: &SyncSender<Job>, served: &Served) {
    let url = request.url().to_string();
    if url.len() > MAX_URL {
        return refuse(
            request,
            414,
            None,
            format!("the URL is {} bytes; at most {MAX_URL} are accepted", url.len()),
        );
    }
    let (path, query) = url.split_once('?').unwrap_or((&url, ""));
    let method = request.method().clone();
    if computed(path) {
        let mut params: Vec<(String, String)> =
            form_urlencoded::parse(query.as_bytes()).map(|(k, v)| (k.into_owned(), v.into_owned())).collect();
        match method {
            Method::Get => {}
            Method::Post => match body_params(&mut request) {
                Ok(mut more) => params.append(&mut more),
                Err(e) => return respond_api(request, Err(e)),
            },
            _ => {
                return refuse(
                    request,
                    405,
                    None,
                    format!("{method} is not accepted; use GET (or POST with JSON)"),
                )
            }
        }
        let job = Job { request, path: path.to_string(), params };
        if let Err(e) = tx.try_send(job) {
            let job = match e {
                TrySendError::Full(job) | TrySendError::Disconnected(job) => job,
            };
            refuse(
                job.request,
                503,
                None,
                format!("the server is busy: at most {MAX_QUEUE} API requests may wait; try again"),
            );
        }
        return;
    }
    if method != Method::Get && method != Method::Head {
        return refuse(request, 405, None, format!("{method} is not accepted here; use GET"));
    }
    match page::asset(path, served) {
        Some((body, content_type)) => {
            let _ = request.respond(with_type(Response::from_data(body), content_type));
        }
        None => refuse(request, 404, None, format!("no page {path}: the explorer is at /, the API at /api/")),
    }
}

/// A POST body: a JSON object of parameters (`{"slope": 20, "mass": 1.0}`), at most
/// [`MAX_BODY`] bytes. Numbers are passed on as JSON writes them, strings as they are, arrays
/// comma-joined, booleans as true/false.
fn body_params(request: &mut Request) -> Result<Vec<(String, String)>, ApiError> {
    let too_big = |n: String| ApiError {
        status: 413,
        field: None,
        error: format!("the request body is {n} bytes; at most {MAX_BODY} are accepted"),
    };
    if let Some(n) = request.body_length() {
        if n > MAX_BODY {
            return Err(too_big(n.to_string()));
        }
    }
    let mut body = Vec::new();
    request
        .as_reader()
        .take(MAX_BODY as u64 + 1)
        .read_to_end(&mut body)
        .map_err(|e| ApiError::bad(None, format!("reading the request body: {e}")))?;
    if body.len() > MAX_BODY {
        return Err(too_big(format!("more than {MAX_BODY}")));
    }
    if body.iter().all(u8::is_ascii_whitespace) {
        return Ok(Vec::new());
    }
    let value: serde_json::Value = serde_json::from_slice(&body)
        .map_err(|e| ApiError::bad(Some("body".into()), format!("the body is not valid JSON: {e}")))?;
    let serde_json::Value::Object(map) = value else {
        return Err(ApiError::bad(
            Some("body".into()),
            "the body must be a JSON object of parameters, e.g. {\"slope\": 20}",
        ));
    };
    map.into_iter()
        .map(|(k, v)| {
            let text = json_param(&k, &v)?;
            Ok((k, text))
        })
        .collect()
}

fn json_param(key: &str, v: &serde_json::Value) -> Result<String, ApiError> {
    use serde_json::Value;
    match v {
        Value::String(s) => Ok(s.clone()),
        Value::Number(n) => Ok(n.to_string()),
        Value::Bool(b) => Ok(b.to_string()),
        Value::Array(items) => {
            let parts: Result<Vec<String>, ApiError> = items
                .iter()
                .map(|item| match item {
                    Value::Array(_) | Value::Object(_) => Err(ApiError::bad(
                        Some(key.to_string()),
                        format!("{key}: a list may hold numbers and strings only"),
                    )),
                    other => json_param(key, other),
                })
                .collect();
            Ok(parts?.join(","))
        }
        Value::Null | Value::Object(_) => Err(ApiError::bad(
            Some(key.to_string()),
            format!("{key}: must be a number, a string, true/false or a list"),
        )),
    }
}
