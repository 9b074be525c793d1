//! The HTTP layer: `hyper`'s HTTP/1.1 server on a small `tokio` runtime (2 threads, with
//! timers) that reads requests and answers the embedded page; the connections, their cap and
//! timeouts are [`super::conn`]. API requests are computed off those threads, on tokio's
//! blocking pool, each holding a permit of one of two pools:
//!
//! - **light** (`/api/predict`, `/api/sweep`, `/data/served`: milliseconds each): as many at
//!   once as the machine has cores;
//! - **heavy** (every other computation: phase maps, risk, simulations, plans, the DEM and the
//!   downloads): `--threads` at once,
//!
//! so a predict never waits behind simulations. An answer is written into the response as the
//! client reads it, in 64 KiB chunks ([`CHUNK`]); a client that does not read stops the writing
//! (and is dropped after `--send-timeout`), and at most [`IN_FLIGHT_PER_THREAD`] answers per
//! compute thread of a pool are computing or being sent at once, which bounds the memory that
//! unread answers can hold.
//!
//! Every request must name this server: its `Host` the loopback name, the address it listens
//! on, or a `--allow-host` name, and its `Origin`, when sent, this server's own (403 otherwise):
//! a web page elsewhere cannot read answers by DNS rebinding, nor make the server compute by a
//! cross-site form or `text/plain` POST.
//!
//! Limits, each refused with a 4xx whose JSON names it: a URL of at most [`MAX_URL`] bytes
//! (414), a request head of at most [`super::conn::MAX_HEAD`] bytes (431, from hyper), a POST
//! body of at most [`MAX_BODY`] bytes (413) arriving within `--header-timeout` (408), at most
//! [`MAX_QUEUE`] API requests waiting for each pool (503). A panic inside a computation is
//! caught and answered with a 500 (none is known: bad input is a 400).

use std::convert::Infallible;
use std::io::{self, Write};
use std::net::{IpAddr, SocketAddr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::pin::Pin;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;

use anyhow::{Context as _, Result};
use bytes::Bytes;
use http_body_util::{BodyExt, Limited};
use hyper::body::{Frame, Incoming, SizeHint};
use hyper::header::{self, HeaderValue};
use hyper::{Method, Request, Response, StatusCode, Version};
use tokio::sync::{mpsc, oneshot, Semaphore};

use crate::conn::{self, Busy, ConnLimits};
use crate::drive::{self, LiveDrive};
use crate::reply::{self, ApiError, Reply};
use crate::served::Served;
use crate::{api, data, page};

/// Longest request URL accepted, bytes.
pub const MAX_URL: usize = 8192;
/// Largest POST body accepted, bytes.
pub const MAX_BODY: usize = 65_536;
/// Most API requests waiting for a compute thread of one pool; more get 503.
pub const MAX_QUEUE: usize = 1024;
/// Answers of one pool computing or being sent at once, per compute thread of the pool.
pub const IN_FLIGHT_PER_THREAD: usize = 2;
/// Size of the chunks an answer is sent in, bytes; an answer that fits in one is sent whole,
/// with its Content-Length.
pub const CHUNK: usize = 65_536;
/// Threads of the runtime that read requests and answer the page's files (the computations
/// run elsewhere, so two keep every connection read).
const READERS: usize = 2;
/// Connections that may wait to be accepted: a browser opens six at once, the load test 200
/// (with the usual 128, a burst of 200 connects lost SYNs and waited the 1 s retransmission).
const BACKLOG: u32 = 1024;

/// How the server is limited (`serve`'s flags).
#[derive(Debug, Clone)]
pub struct Limits {
    /// Connections: their cap and timeouts.
    pub conn: ConnLimits,
    /// Heavy computations at once (`--threads`).
    pub threads: usize,
    /// Light computations at once (the machine's cores).
    pub light_threads: usize,
    /// Host names accepted besides the loopback name and the address listened on.
    pub allowed_hosts: Vec<String>,
}

/// Answers the page's files on the runtime and hands API requests to a compute thread.
pub struct App {
    served: Served,
    light: Pool,
    heavy: Pool,
    hosts: Hosts,
    body_timeout: Duration,
    /// The robot driven while serving (`serve --drive`).
    drive: Option<Arc<LiveDrive>>,
}

/// A bound server, ready to [`Server::serve`].
pub struct Server {
    runtime: tokio::runtime::Runtime,
    listener: tokio::net::TcpListener,
    app: Arc<App>,
    limits: ConnLimits,
}

impl Server {
    /// Listens on `host:port` (port 0: any free port).
    pub fn bind(host: IpAddr, port: u16, served: Served, limits: Limits) -> Result<Server> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(READERS)
            .enable_io()
            .enable_time()
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
        let app = Arc::new(App {
            served,
            light: Pool::new(limits.light_threads),
            heavy: Pool::new(limits.threads),
            hosts: Hosts {
                listen: host,
                names: limits.allowed_hosts.iter().map(|h| h.to_ascii_lowercase()).collect(),
            },
            body_timeout: limits.conn.header_timeout,
            drive: None,
        });
        Ok(Server { runtime, listener, app, limits: limits.conn })
    }

    /// Shows a driven run at `/api/drive/` (`serve --drive`); before [`Server::serve`].
    pub fn show_drive(&mut self, live: Arc<LiveDrive>) {
        if let Some(app) = Arc::get_mut(&mut self.app) {
            app.drive = Some(live);
        }
    }

    /// The address the server listens on (with the port chosen when 0 was asked).
    pub fn address(&self) -> String {
        self.listener.local_addr().map_or_else(|_| "?".into(), |a| a.to_string())
    }

    /// Answers requests until the process ends.
    pub fn serve(self) -> Result<()> {
        let Server { runtime, listener, app, limits } = self;
        let handler: conn::Handler<Body> =
            Arc::new(move |request, busy| Box::pin(handle(Arc::clone(&app), request, busy)));
        runtime.block_on(conn::accept_loop(listener, handler, limits));
        anyhow::bail!("the server stopped")
    }
}

/// One pool of compute permits.
struct Pool {
    /// One permit per compute thread.
    compute: Arc<Semaphore>,
    /// One permit per answer computing or being sent.
    in_flight: Arc<Semaphore>,
    /// Requests admitted and not yet computed (computing or waiting for a permit).
    admitted: AtomicUsize,
    threads: usize,
}

impl Pool {
    fn new(threads: usize) -> Pool {
        let threads = threads.max(1);
        Pool {
            compute: Arc::new(Semaphore::new(threads)),
            in_flight: Arc::new(Semaphore::new(threads * IN_FLIGHT_PER_THREAD)),
            admitted: AtomicUsize::new(0),
            threads,
        }
    }
}

/// The endpoints answered on the light pool; every other computation is heavy.
fn is_light(path: &str) -> bool {
    matches!(path, "/api/predict" | "/api/sweep" | "/data/served")
}

/// Answers a computed request by its path: `/api/<command>`, `/data/<name>`, `/download/<file>`.
fn dispatch(path: &str, params: &[(String, String)], served: &Served) -> Result<Reply, ApiError> {
    if let Some(command) = path.strip_prefix("/api/") {
        api::answer(command, params, served)
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

/// The body of an answer: whole, or its first chunk and the rest as the writer sends them.
/// It keeps its connection marked busy until hyper is done with it.
pub struct Body {
    first: Option<Bytes>,
    rest: Option<mpsc::Receiver<io::Result<Bytes>>>,
    busy: Option<Busy>,
}

impl Body {
    fn whole(bytes: impl Into<Bytes>) -> Body {
        Body { first: Some(bytes.into()), rest: None, busy: None }
    }
}

impl hyper::body::Body for Body {
    type Data = Bytes;
    type Error = io::Error;

    fn poll_frame(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Option<io::Result<Frame<Bytes>>>> {
        let this = self.get_mut();
        if let Some(first) = this.first.take().filter(|b| !b.is_empty()) {
            return Poll::Ready(Some(Ok(Frame::data(first))));
        }
        match &mut this.rest {
            None => Poll::Ready(None),
            Some(rest) => rest.poll_recv(cx).map(|chunk| chunk.map(|c| c.map(Frame::data))),
        }
    }

    fn is_end_stream(&self) -> bool {
        self.rest.is_none() && self.first.as_ref().is_none_or(Bytes::is_empty)
    }

    fn size_hint(&self) -> SizeHint {
        let first = self.first.as_ref().map_or(0, |b| b.len() as u64);
        if self.rest.is_none() {
            SizeHint::with_exact(first)
        } else {
            let mut hint = SizeHint::new();
            hint.set_lower(first);
            hint
        }
    }
}

/// The start of an answer, sent by the thread that computes it: the status and headers, and
/// the whole body or its first chunk (`more`: the rest follows).
struct Head {
    status: u16,
    content_type: &'static str,
    filename: Option<&'static str>,
    first: Bytes,
    more: bool,
}

/// Writes an answer's body into 64 KiB chunks: the first goes with the head, the rest into a
/// channel of two, so the writer waits while the client does not read.
struct ChunkWriter {
    head: Option<(oneshot::Sender<Head>, &'static str, Option<&'static str>)>,
    chunks: mpsc::Sender<io::Result<Bytes>>,
    buf: Vec<u8>,
}

fn gone() -> io::Error {
    io::Error::new(io::ErrorKind::BrokenPipe, "the client is gone")
}

impl ChunkWriter {
    fn send(&mut self, more: bool) -> io::Result<()> {
        let bytes =
            Bytes::from(std::mem::replace(&mut self.buf, Vec::with_capacity(if more { CHUNK } else { 0 })));
        match self.head.take() {
            Some((tx, content_type, filename)) => {
                tx.send(Head { status: 200, content_type, filename, first: bytes, more }).map_err(|_| gone())
            }
            None if bytes.is_empty() => Ok(()),
            None => self.chunks.blocking_send(Ok(bytes)).map_err(|_| gone()),
        }
    }

    /// After the writer failed: an error answer if nothing was sent yet, else a cut body
    /// (hyper closes the connection, so the client sees the answer incomplete).
    fn fail(mut self, e: io::Error) {
        match self.head.take() {
            Some((tx, ..)) => {
                let _ = tx.send(error_head(&ApiError {
                    status: 500,
                    field: None,
                    error: format!("internal error: writing the answer: {e}"),
                }));
            }
            None => {
                let _ = self.chunks.blocking_send(Err(e));
            }
        }
    }
}

impl Write for ChunkWriter {
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        self.buf.extend_from_slice(data);
        if self.buf.len() >= CHUNK {
            self.send(true)?;
        }
        Ok(data.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

fn error_head(e: &ApiError) -> Head {
    let body = reply::json(e).unwrap_or_else(|_| b"{}\n".to_vec());
    Head {
        status: e.status,
        content_type: "application/json",
        filename: None,
        first: body.into(),
        more: false,
    }
}

/// On a compute thread: sends `result`'s head and body, writing the body as it is read.
fn send_reply(
    result: Result<Reply, ApiError>,
    head: oneshot::Sender<Head>,
    chunks: mpsc::Sender<io::Result<Bytes>>,
) {
    let reply = match result {
        Ok(reply) => reply,
        Err(e) => {
            let _ = head.send(error_head(&e));
            return;
        }
    };
    let mut w = ChunkWriter {
        head: Some((head, reply.content_type, reply.filename)),
        chunks,
        buf: Vec::with_capacity(CHUNK),
    };
    let written = catch_unwind(AssertUnwindSafe(|| (reply.body)(&mut w)))
        .unwrap_or_else(|_| Err(io::Error::other("the writer panicked (please report it)")));
    match written.and_then(|()| w.send(false)) {
        Ok(()) => {}
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => {}
        Err(e) => w.fail(e),
    }
}

/// A response with the page's headers.
fn response(status: u16, content_type: &'static str, filename: Option<&str>, body: Body) -> Response<Body> {
    let mut response = Response::new(body);
    *response.status_mut() = StatusCode::from_u16(status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR);
    let headers = response.headers_mut();
    for (k, v) in [
        (header::CONTENT_TYPE, content_type),
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
    if let Some(name) = filename {
        if let Ok(v) = HeaderValue::from_str(&format!("attachment; filename=\"{name}\"")) {
            headers.insert(header::CONTENT_DISPOSITION, v);
        }
    }
    response
}

fn refused(e: &ApiError) -> Response<Body> {
    let head = error_head(e);
    response(head.status, head.content_type, None, Body::whole(head.first))
}

fn denied(status: u16, error: String) -> ApiError {
    ApiError { status, field: None, error }
}

fn refuse(status: u16, error: String) -> Response<Body> {
    refused(&denied(status, error))
}

fn refuse_method(method: &Method, allow: &'static str) -> Response<Body> {
    let mut r = refuse(405, format!("{method} is not accepted here; use {allow}"));
    r.headers_mut().insert(header::ALLOW, HeaderValue::from_static(allow));
    r
}

/// hyper's entry: the answer to `request`, its body keeping the connection busy.
pub async fn handle(
    app: Arc<App>,
    request: Request<Incoming>,
    busy: Busy,
) -> Result<Response<Body>, Infallible> {
    let mut response = answer(&app, request).await;
    response.body_mut().busy = Some(busy);
    Ok(response)
}

async fn answer(app: &Arc<App>, request: Request<Incoming>) -> Response<Body> {
    if let Err(e) = app.hosts.check(&request) {
        return refused(&e);
    }
    let url = request.uri().path_and_query().map_or("/", |pq| pq.as_str()).to_string();
    if url.len() > MAX_URL {
        return refuse(414, format!("the URL is {} bytes; at most {MAX_URL} are accepted", url.len()));
    }
    let (path, query) = url.split_once('?').unwrap_or((&url, ""));
    let method = request.method().clone();
    // The driven run's status and stop: a lock and a copy, answered here, off the pools.
    if let Some(name) = path.strip_prefix("/api/drive/") {
        if !matches!(method, Method::GET | Method::HEAD | Method::POST) {
            return refuse_method(&method, "GET, HEAD, POST");
        }
        return match drive::answer(name, method == Method::POST, app.drive.as_deref()) {
            Ok(body) => response(200, "application/json", None, Body::whole(body)),
            Err(e) => refused(&e),
        };
    }
    if !computed(path) {
        if method != Method::GET && method != Method::HEAD {
            return refuse_method(&method, "GET, HEAD");
        }
        return match page::asset(path, &app.served) {
            Some((body, content_type)) => response(200, content_type, None, Body::whole(body)),
            None => refuse(404, format!("no page {path}: the explorer is at /, the API at /api/")),
        };
    }
    let mut params: Vec<(String, String)> =
        form_urlencoded::parse(query.as_bytes()).map(|(k, v)| (k.into_owned(), v.into_owned())).collect();
    match method {
        // HEAD: the same status and headers as GET (hyper sends no body).
        Method::GET | Method::HEAD => {}
        Method::POST => match body_params(request, app.body_timeout).await {
            Ok(mut more) => params.append(&mut more),
            Err(e) => return refused(&e),
        },
        _ => return refuse_method(&method, "GET, HEAD, POST"),
    }
    let pool = if is_light(path) { &app.light } else { &app.heavy };
    compute(app, pool, path.to_string(), params).await
}

/// Runs a computation on `pool` and starts its answer.
async fn compute(app: &Arc<App>, pool: &Pool, path: String, params: Vec<(String, String)>) -> Response<Body> {
    let admitted = Admitted::new(&pool.admitted);
    if admitted.count > MAX_QUEUE + pool.threads {
        return refuse(
            503,
            format!("the server is busy: at most {MAX_QUEUE} API requests may wait; try again"),
        );
    }
    let (Ok(in_flight), Ok(permit)) =
        (Arc::clone(&pool.in_flight).acquire_owned().await, Arc::clone(&pool.compute).acquire_owned().await)
    else {
        return refuse(503, "the server is stopping".into());
    };
    let (head_tx, head_rx) = oneshot::channel();
    let (chunk_tx, chunk_rx) = mpsc::channel(2);
    let job = Arc::clone(app);
    tokio::task::spawn_blocking(move || {
        let result = catch_unwind(AssertUnwindSafe(|| dispatch(&path, &params, &job.served)))
            .unwrap_or_else(|_| Err(panicked()));
        drop(permit);
        send_reply(result, head_tx, chunk_tx);
        drop(in_flight);
    });
    let head = head_rx.await.unwrap_or_else(|_| error_head(&panicked()));
    drop(admitted);
    let body = Body { first: Some(head.first), rest: head.more.then_some(chunk_rx), busy: None };
    response(head.status, head.content_type, head.filename, body)
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

/// Which `Host` and `Origin` a request may name.
struct Hosts {
    /// The address listened on.
    listen: IpAddr,
    /// `--allow-host` names, lower case.
    names: Vec<String>,
}

impl Hosts {
    /// Whether `host` (a Host header's name, without port) names this server: `localhost`, the
    /// address listened on (any loopback address when that is one, any address when it is
    /// 0.0.0.0 or ::, since an address cannot be rebound by DNS), or a `--allow-host` name.
    fn allows(&self, host: &str) -> bool {
        let name = host.strip_suffix('.').unwrap_or(host).to_ascii_lowercase();
        if name == "localhost" || self.names.contains(&name) {
            return true;
        }
        let ip = name.strip_prefix('[').and_then(|n| n.strip_suffix(']')).unwrap_or(&name);
        match ip.parse::<IpAddr>() {
            Ok(ip) => {
                ip == self.listen
                    || self.listen.is_unspecified()
                    || (self.listen.is_loopback() && ip.is_loopback())
            }
            Err(_) => false,
        }
    }

    /// Refuses a request whose Host is not this server's (403; 400 when missing or repeated,
    /// HTTP/1.0 excepted) or whose Origin is another site's (403).
    fn check(&self, request: &Request<Incoming>) -> Result<(), ApiError> {
        let hosts = request.headers().get_all(header::HOST);
        let mut each = hosts.iter();
        let host = match (request.uri().authority(), each.next(), each.next()) {
            (_, Some(_), Some(_)) => {
                return Err(denied(400, "the request has more than one Host header".into()))
            }
            (Some(authority), ..) => Some(authority.as_str().to_string()),
            (None, Some(h), None) => {
                Some(h.to_str().map_err(|_| denied(400, "the Host header is not text".into()))?.to_string())
            }
            (None, None, _) if request.version() <= Version::HTTP_10 => None,
            (None, None, _) => {
                return Err(denied(400, "the request has no Host header (HTTP/1.1 requires one)".into()))
            }
        };
        if let Some(host) = &host {
            let name = host
                .parse::<hyper::http::uri::Authority>()
                .map(|a| a.host().to_string())
                .map_err(|_| denied(400, format!("the Host header `{host}` is not a host name")))?;
            if !self.allows(&name) {
                return Err(denied(
                    403,
                    format!(
                        "Host `{name}` is not this server: requests must name it as localhost or the address it \
                         listens on ({}), which keeps other web sites from reading it through DNS rebinding; \
                         start it with --allow-host {name} to accept that name",
                        self.listen
                    ),
                ));
            }
        }
        if let Some(origin) = request.headers().get(header::ORIGIN) {
            let origin = origin.to_str().unwrap_or("?");
            let same = host.as_deref().is_some_and(|host| {
                ["http://", "https://"].iter().any(|scheme| {
                    origin.strip_prefix(scheme).is_some_and(|rest| rest.eq_ignore_ascii_case(host))
                })
            });
            if !same {
                return Err(denied(
                    403,
                    format!(
                        "Origin `{origin}` is another site: the server answers its own page (http://{}) and \
                         clients that send no Origin",
                        host.as_deref().unwrap_or("?")
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A POST body: a JSON object of parameters (`{"slope": 20, "mass": 1.0}`), at most
/// [`MAX_BODY`] bytes, arriving within `timeout`. Numbers are passed on as JSON writes them,
/// strings as they are, arrays comma-joined, booleans as true/false.
async fn body_params(
    request: Request<Incoming>,
    timeout: Duration,
) -> Result<Vec<(String, String)>, ApiError> {
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
    let read = tokio::time::timeout(timeout, Limited::new(request.into_body(), MAX_BODY).collect()).await;
    let body = match read {
        Err(_elapsed) => {
            return Err(ApiError {
                status: 408,
                field: None,
                error: format!(
                    "the request body did not arrive within {} s (--header-timeout)",
                    timeout.as_secs_f64()
                ),
            })
        }
        Ok(Err(e)) if e.downcast_ref::<http_body_util::LengthLimitError>().is_some() => {
            return Err(too_big(format!("more than {MAX_BODY}")))
        }
        Ok(Err(e)) => return Err(ApiError::bad(None, format!("reading the request body: {e}"))),
        Ok(Ok(collected)) => collected.to_bytes(),
    };
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
