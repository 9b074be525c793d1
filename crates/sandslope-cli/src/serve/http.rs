//! The HTTP layer: `axum` on a small `tokio` runtime (2 threads) that reads requests and
//! answers the embedded page, and at most `--threads` computations at once on tokio's blocking
//! pool, so a slow phase map or route never holds up the page, other connections or other
//! requests. Every connection is read as soon as it has bytes, whatever other clients keep open
//! (the server before this one, `tiny_http` 0.12, could leave a new connection unread behind
//! idle kept-alive ones; `idle_kept_alive_connections_do_not_stall_new_requests` in
//! tests/serve.rs reproduced it in 2 of 3 runs).
//!
//! Limits, each refused with a 4xx whose JSON names it: a URL of at most [`MAX_URL`] bytes
//! (414), a POST body of at most [`MAX_BODY`] bytes (413), at most [`MAX_QUEUE`] API requests
//! waiting for a compute thread (503). A panic inside a computation is caught and answered
//! with a 500 (none is known: bad input is a 400).

use std::net::{IpAddr, SocketAddr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use anyhow::{Context, Result};
use axum::body::{to_bytes, Body};
use axum::extract::{Request, State};
use axum::http::{header, HeaderValue, Method, StatusCode};
use axum::response::Response;
use axum::Router;
use tokio::sync::Semaphore;

use super::api::{self, ApiError, Served};
use super::data::{self, Reply};
use super::page;

/// Longest request URL accepted, bytes.
pub const MAX_URL: usize = 8192;
/// Largest POST body accepted, bytes.
pub const MAX_BODY: usize = 65_536;
/// Most API requests waiting for a compute thread; more get 503.
pub const MAX_QUEUE: usize = 1024;
/// Threads of the runtime that read requests and answer the page's files (the computations
/// run elsewhere, so two keep every connection read).
const READERS: usize = 2;

/// Answers a computed request by its path: `/api/<command>`, `/data/<name>`, `/download/<file>`.
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

/// Whether `path` is answered by a computation.
fn computed(path: &str) -> bool {
    ["/api/", "/data/", "/download/"].iter().any(|p| path.starts_with(p))
}

/// What every request handler shares.
struct App {
    served: Served,
    /// One permit per compute thread.
    compute: Semaphore,
    /// API requests admitted and not yet answered (computing or waiting for a permit).
    admitted: AtomicUsize,
    threads: usize,
}

/// Connections that may wait to be accepted: a browser opens six at once, the load test 200
/// (with the usual 128, a burst of 200 connects lost SYNs and waited the 1 s retransmission).
const BACKLOG: u32 = 1024;

/// A bound server, ready to [`Server::serve`].
pub struct Server {
    runtime: tokio::runtime::Runtime,
    listener: tokio::net::TcpListener,
    served: Served,
    threads: usize,
}

impl Server {
    /// Listens on `host:port` (port 0: any free port).
    pub fn bind(host: IpAddr, port: u16, served: Served, threads: usize) -> Result<Server> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(READERS)
            .enable_io()
            .build()
            .context("cannot start the server's threads")?;
        let address = SocketAddr::new(host, port);
        let listener = {
            let _in_runtime = runtime.enter();
            let socket = match host {
                IpAddr::V4(_) => tokio::net::TcpSocket::new_v4(),
                IpAddr::V6(_) => tokio::net::TcpSocket::new_v6(),
            }
            .and_then(|s| {
                // As std's TcpListener::bind does: a restarted server can take its port back.
                #[cfg(unix)]
                s.set_reuseaddr(true)?;
                s.bind(address)?;
                s.listen(BACKLOG)
            })
            .with_context(|| format!("cannot listen on {address}"))?;
            socket
        };
        Ok(Server { runtime, listener, served, threads: threads.max(1) })
    }

    /// The address the server listens on (with the port chosen when 0 was asked).
    pub fn address(&self) -> String {
        self.listener.local_addr().map_or_else(|_| "?".into(), |a| a.to_string())
    }

    /// Answers requests until the process ends.
    pub fn serve(self) -> Result<()> {
        let app = Arc::new(App {
            served: self.served,
            compute: Semaphore::new(self.threads),
            admitted: AtomicUsize::new(0),
            threads: self.threads,
        });
        let (runtime, listener) = (self.runtime, self.listener);
        runtime.block_on(async move {
            let router = Router::new().fallback(route).with_state(app);
            axum::serve(listener, router).await.context("the server stopped")
        })
    }
}

/// The answer to a request: the reply's body on success, `{"field": ..., "error": ...}`
/// otherwise, with the page's headers.
fn respond(result: Result<Reply, ApiError>) -> Response {
    let (status, reply) = match result {
        Ok(reply) => (200, reply),
        Err(e) => (e.status, Reply::json(api::json(&e).unwrap_or_else(|_| b"{}\n".to_vec()))),
    };
    let mut response = Response::new(Body::from(reply.body));
    *response.status_mut() = StatusCode::from_u16(status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR);
    let headers = response.headers_mut();
    for (k, v) in [
        (header::CONTENT_TYPE, reply.content_type),
        (header::CACHE_CONTROL, "no-store"),
        (header::X_CONTENT_TYPE_OPTIONS, "nosniff"),
        // The page loads nothing from anywhere but this server.
        (
            header::CONTENT_SECURITY_POLICY,
            "default-src 'self'; img-src 'self' data: blob:; style-src 'self'; script-src 'self'; \
             connect-src 'self'; frame-ancestors 'none'",
        ),
    ] {
        headers.insert(k, HeaderValue::from_static(v));
    }
    if let Some(name) = reply.filename {
        if let Ok(v) = HeaderValue::from_str(&format!("attachment; filename=\"{name}\"")) {
            headers.insert(header::CONTENT_DISPOSITION, v);
        }
    }
    response
}

fn refuse(status: u16, error: String) -> Response {
    respond(Err(ApiError { status, field: None, error }))
}

/// Answers the page's files on the runtime and hands API requests to a compute thread.
async fn route(State(app): State<Arc<App>>, request: Request) -> Response {
    let url = request.uri().path_and_query().map_or("/", |pq| pq.as_str()).to_string();
    if url.len() > MAX_URL {
        return refuse(414, format!("the URL is {} bytes; at most {MAX_URL} are accepted", url.len()));
    }
    let (path, query) = url.split_once('?').unwrap_or((&url, ""));
    let method = request.method().clone();
    if !computed(path) {
        if method != Method::GET && method != Method::HEAD {
            return refuse(405, format!("{method} is not accepted here; use GET"));
        }
        return match page::asset(path, &app.served) {
            Some((body, content_type)) => respond(Ok(Reply { body, content_type, filename: None })),
            None => refuse(404, format!("no page {path}: the explorer is at /, the API at /api/")),
        };
    }
    let mut params: Vec<(String, String)> =
        form_urlencoded::parse(query.as_bytes()).map(|(k, v)| (k.into_owned(), v.into_owned())).collect();
    match method {
        Method::GET => {}
        Method::POST => match body_params(request).await {
            Ok(mut more) => params.append(&mut more),
            Err(e) => return respond(Err(e)),
        },
        _ => return refuse(405, format!("{method} is not accepted; use GET (or POST with JSON)")),
    }
    // Admitted: computing or waiting for one of the compute threads.
    let admitted = Admitted::new(&app.admitted);
    if admitted.count > MAX_QUEUE + app.threads {
        return refuse(
            503,
            format!("the server is busy: at most {MAX_QUEUE} API requests may wait; try again"),
        );
    }
    let Ok(_permit) = app.compute.acquire().await else {
        return refuse(503, "the server is stopping".into());
    };
    let path = path.to_string();
    let job = Arc::clone(&app);
    let result = tokio::task::spawn_blocking(move || {
        catch_unwind(AssertUnwindSafe(|| dispatch(&path, &params, &job.served)))
            .unwrap_or_else(|_| Err(panicked()))
    })
    .await
    .unwrap_or_else(|_| Err(panicked()));
    respond(result)
}

fn panicked() -> ApiError {
    ApiError {
        status: 500,
        field: None,
        error: "internal error: the computation panicked (please report it)".into(),
    }
}

/// Counts an admitted API request for as long as it lives.
struct Admitted<'a> {
    counter: &'a AtomicUsize,
    /// Requests admitted, this one included, when it came.
    count: usize,
}

impl<'a> Admitted<'a> {
    fn new(counter: &'a AtomicUsize) -> Admitted<'a> {
        Admitted { counter, count: counter.fetch_add(1, Ordering::AcqRel) + 1 }
    }
}

impl Drop for Admitted<'_> {
    fn drop(&mut self) {
        self.counter.fetch_sub(1, Ordering::AcqRel);
    }
}

/// A POST body: a JSON object of parameters (`{"slope": 20, "mass": 1.0}`), at most
/// [`MAX_BODY`] bytes. Numbers are passed on as JSON writes them, strings as they are, arrays
/// comma-joined, booleans as true/false.
async fn body_params(request: Request) -> Result<Vec<(String, String)>, ApiError> {
    let too_big = |n: String| ApiError {
        status: 413,
        field: None,
        error: format!("the request body is {n} bytes; at most {MAX_BODY} are accepted"),
    };
    let declared = request
        .headers()
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.trim().parse::<u64>().ok());
    if let Some(n) = declared {
        if n > MAX_BODY as u64 {
            return Err(too_big(n.to_string()));
        }
    }
    // A body without Content-Length (chunked) is read up to the limit and refused past it.
    let body = to_bytes(request.into_body(), MAX_BODY).await.map_err(|e| {
        let e = e.into_inner();
        if e.downcast_ref::<http_body_util::LengthLimitError>().is_some() {
            too_big(format!("more than {MAX_BODY}"))
        } else {
            ApiError::bad(None, format!("reading the request body: {e}"))
        }
    })?;
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
