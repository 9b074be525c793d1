//! Connections: the accept loop, the cap on open connections, and the timeouts of each.
//!
//! Each connection is served by `hyper`'s HTTP/1.1 server ([`hyper::server::conn::http1`])
//! with a timer, so its own header-read timeout applies: a request's head must be complete
//! within `--header-timeout` of the connection opening or of the previous answer's end (so it
//! is also the idle keep-alive limit; a trickled head, slowloris, is cut at the same deadline).
//! What hyper does not have is added here, each after a server that has it:
//!
//! - **A send timeout** ([`SendTimeout`]): a write that makes no progress for `--send-timeout`
//!   ends the connection, as nginx's `send_timeout` does (between two successive writes, not
//!   for the whole answer), so a client that asks and does not read cannot hold an answer.
//! - **A cap on open connections** (`--max-connections`, at most the open-file limit less
//!   [`RESERVED_FDS`]): when it is reached, the connection that has been idle longest (no
//!   request in progress) is closed to make room, as nginx does when `worker_connections` run
//!   out ("reusing connections"); when none is idle, new connections wait in the listen
//!   backlog.
//! - **Accept errors back off** ([`accept_failed`]): out of file descriptors (EMFILE, ENFILE)
//!   or memory, the loop closes an idle connection and waits 5 ms, doubling up to 1 s, as Go's
//!   `net/http` does, and goes on; a client that gave up before being accepted is skipped.

use std::collections::HashMap;
use std::future::Future;
use std::io;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll};
use std::time::{Duration, Instant};

use hyper::server::conn::http1;
use hyper_util::rt::{TokioIo, TokioTimer};
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{Notify, Semaphore};
use tokio::time::Sleep;

/// What answers a connection's requests: called with each request and the mark that keeps
/// its connection busy for as long as the answer lives (the HTTP layer, `http::handle`, given
/// here so that this file needs nothing of it).
pub type Handler<B> = Arc<
    dyn Fn(hyper::Request<hyper::body::Incoming>, Busy) -> Pin<Box<dyn Future<Output = Answer<B>> + Send>>
        + Send
        + Sync,
>;

/// A handler's answer (never an error: failures are answered as error responses).
pub type Answer<B> = Result<hyper::Response<B>, std::convert::Infallible>;

/// File descriptors kept free of connections: standard streams, the runtime's, the listener,
/// and the files computations open (the DEM, a download's temporary file).
pub const RESERVED_FDS: usize = 64;
/// Largest request head (request line and headers) read, bytes; hyper answers a larger one
/// with 431. hyper's default is about 400 KiB, which 500 slow clients could turn into 200 MB.
pub const MAX_HEAD: usize = 65_536;
/// First and longest waits after a failed accept (Go's `net/http` `Server.Serve`).
const ACCEPT_BACKOFF: (Duration, Duration) = (Duration::from_millis(5), Duration::from_secs(1));

/// The connection limits of a server.
#[derive(Debug, Clone)]
pub struct ConnLimits {
    /// A request's head must be read within this of the connection opening or of the
    /// previous answer's end.
    pub header_timeout: Duration,
    /// A write that makes no progress for this long ends the connection.
    pub send_timeout: Duration,
    /// Most connections open at once.
    pub max_connections: usize,
}

/// The soft limit on open files of this process, if it has one.
pub fn open_file_limit() -> Option<usize> {
    #[cfg(unix)]
    {
        let mut lim = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
        // SAFETY: getrlimit writes into the struct it is given.
        if unsafe { libc::getrlimit(libc::RLIMIT_NOFILE, &mut lim) } == 0
            && lim.rlim_cur != libc::RLIM_INFINITY
        {
            return Some(usize::try_from(lim.rlim_cur).unwrap_or(usize::MAX));
        }
    }
    None
}

/// One open connection, as the accept loop sees it.
struct Conn {
    /// Requests in progress (from the head read to the answer's last byte handed to hyper).
    busy: AtomicUsize,
    /// When it last became idle, ms since the registry's epoch.
    idle_since_ms: AtomicU64,
    /// Told to close (once idle) to make room.
    evicted: AtomicBool,
    wake: Notify,
}

/// The open connections.
struct Registry {
    epoch: Instant,
    next: AtomicU64,
    open: Mutex<HashMap<u64, Arc<Conn>>>,
}

impl Registry {
    fn now_ms(&self) -> u64 {
        u64::try_from(self.epoch.elapsed().as_millis()).unwrap_or(u64::MAX)
    }

    fn add(&self) -> (u64, Arc<Conn>) {
        let id = self.next.fetch_add(1, Ordering::Relaxed);
        let conn = Arc::new(Conn {
            busy: AtomicUsize::new(0),
            idle_since_ms: AtomicU64::new(self.now_ms()),
            evicted: AtomicBool::new(false),
            wake: Notify::new(),
        });
        self.lock().insert(id, Arc::clone(&conn));
        (id, conn)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<u64, Arc<Conn>>> {
        // A panic while holding this lock cannot leave the map inconsistent (insert/remove).
        self.open.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Tells the connection idle longest to close; false when none is idle.
    fn evict_oldest_idle(&self) -> bool {
        let open = self.lock();
        let oldest = open
            .values()
            .filter(|c| c.busy.load(Ordering::Acquire) == 0 && !c.evicted.load(Ordering::Acquire))
            .min_by_key(|c| c.idle_since_ms.load(Ordering::Acquire));
        match oldest {
            Some(c) => {
                c.evicted.store(true, Ordering::Release);
                c.wake.notify_one();
                true
            }
            None => false,
        }
    }
}

/// Marks a connection busy for as long as a request and its answer live.
pub struct Busy {
    conn: Arc<Conn>,
    registry: Arc<Registry>,
}

impl Busy {
    fn new(conn: &Arc<Conn>, registry: &Arc<Registry>) -> Busy {
        conn.busy.fetch_add(1, Ordering::AcqRel);
        Busy { conn: Arc::clone(conn), registry: Arc::clone(registry) }
    }
}

impl Drop for Busy {
    fn drop(&mut self) {
        self.conn.idle_since_ms.store(self.registry.now_ms(), Ordering::Release);
        self.conn.busy.fetch_sub(1, Ordering::AcqRel);
    }
}

/// Accepts connections until the process ends, serving each on its own task.
pub async fn accept_loop<B>(listener: TcpListener, handler: Handler<B>, limits: ConnLimits)
where
    B: hyper::body::Body + Send + 'static,
    B::Data: Send,
    B::Error: Into<Box<dyn std::error::Error + Send + Sync>>,
{
    let slots = Arc::new(Semaphore::new(limits.max_connections));
    let registry =
        Arc::new(Registry { epoch: Instant::now(), next: AtomicU64::new(0), open: Mutex::default() });
    let mut builder = http1::Builder::new();
    builder
        .timer(TokioTimer::new())
        .header_read_timeout(limits.header_timeout)
        .max_buf_size(MAX_HEAD)
        // The exact limit: a head that arrives in one read can overshoot max_buf_size.
        .max_header_size(MAX_HEAD)
        .keep_alive(true);
    let builder = Arc::new(builder);
    let mut backoff: Option<Duration> = None;
    let mut warned: Option<Instant> = None;
    loop {
        let stream = match listener.accept().await {
            Ok((stream, _peer)) => {
                backoff = None;
                stream
            }
            Err(e) => {
                accept_failed(e, &registry, &mut backoff, &mut warned).await;
                continue;
            }
        };
        // A slot, making one by closing the connection idle longest when all are taken.
        let slot = loop {
            if let Ok(slot) = Arc::clone(&slots).try_acquire_owned() {
                break Some(slot);
            }
            registry.evict_oldest_idle();
            match tokio::time::timeout(Duration::from_millis(100), Arc::clone(&slots).acquire_owned()).await {
                Ok(Ok(slot)) => break Some(slot),
                Ok(Err(_closed)) => break None,
                Err(_elapsed) => {}
            }
        };
        let Some(slot) = slot else { return };
        let _ = stream.set_nodelay(true);
        let (id, conn) = registry.add();
        let (handler, registry, builder, send_timeout) =
            (Arc::clone(&handler), Arc::clone(&registry), Arc::clone(&builder), limits.send_timeout);
        tokio::spawn(async move {
            serve_connection(stream, &conn, &registry, handler, &builder, send_timeout).await;
            registry.lock().remove(&id);
            drop(slot);
        });
    }
}

/// After a failed accept: a client that gave up is skipped; running out of file descriptors
/// or memory closes an idle connection and waits (5 ms doubling up to 1 s), saying so on
/// stderr at most every 10 s. Never ends the server.
async fn accept_failed(
    e: io::Error,
    registry: &Registry,
    backoff: &mut Option<Duration>,
    warned: &mut Option<Instant>,
) {
    use io::ErrorKind::*;
    if matches!(e.kind(), ConnectionAborted | ConnectionReset | ConnectionRefused | Interrupted | WouldBlock)
    {
        return;
    }
    registry.evict_oldest_idle();
    let wait = backoff.map_or(ACCEPT_BACKOFF.0, |b| (b * 2).min(ACCEPT_BACKOFF.1));
    *backoff = Some(wait);
    if warned.is_none_or(|t| t.elapsed() > Duration::from_secs(10)) {
        *warned = Some(Instant::now());
        eprintln!(
            "warning: cannot accept a connection ({e}); closing idle connections and retrying \
             (see --max-connections and `ulimit -n`)"
        );
    }
    tokio::time::sleep(wait).await;
}

/// Serves one connection until it closes, it times out, or it is told to make room while idle.
async fn serve_connection<B>(
    stream: TcpStream,
    conn: &Arc<Conn>,
    registry: &Arc<Registry>,
    handler: Handler<B>,
    builder: &http1::Builder,
    send_timeout: Duration,
) where
    B: hyper::body::Body + Send + 'static,
    B::Data: Send,
    B::Error: Into<Box<dyn std::error::Error + Send + Sync>>,
{
    let io = TokioIo::new(SendTimeout::new(stream, send_timeout));
    let (busy_conn, busy_registry) = (Arc::clone(conn), Arc::clone(registry));
    let service = hyper::service::service_fn(move |request| {
        let busy = Busy::new(&busy_conn, &busy_registry);
        handler(request, busy)
    });
    let served = builder.serve_connection(io, service);
    tokio::pin!(served);
    loop {
        tokio::select! {
            // Closed, timed out or failed: hyper has answered what it could (a 408 or 431).
            _ = served.as_mut() => return,
            () = conn.wake.notified() => {
                // Requests start only while `served` is polled, on this task: no race.
                if conn.busy.load(Ordering::Acquire) == 0 {
                    return;
                }
                conn.evicted.store(false, Ordering::Release);
            }
        }
    }
}

/// A TCP stream whose writes fail with `TimedOut` once one has made no progress for the
/// timeout (the timer starts at a write that cannot proceed and stops at one that does).
pub struct SendTimeout {
    inner: TcpStream,
    timeout: Duration,
    stalled: Option<Pin<Box<Sleep>>>,
}

impl SendTimeout {
    /// Wraps `inner`.
    pub fn new(inner: TcpStream, timeout: Duration) -> SendTimeout {
        SendTimeout { inner, timeout, stalled: None }
    }

    /// After a write: clears the timer if it progressed, or fails once stalled too long.
    fn watch<T>(&mut self, cx: &mut Context<'_>, polled: Poll<io::Result<T>>) -> Poll<io::Result<T>> {
        match polled {
            Poll::Pending => {
                let timeout = self.timeout;
                let stalled = self.stalled.get_or_insert_with(|| Box::pin(tokio::time::sleep(timeout)));
                match stalled.as_mut().poll(cx) {
                    Poll::Ready(()) => Poll::Ready(Err(io::Error::new(
                        io::ErrorKind::TimedOut,
                        format!("the client read nothing for {} s (--send-timeout)", timeout.as_secs_f64()),
                    ))),
                    Poll::Pending => Poll::Pending,
                }
            }
            ready => {
                self.stalled = None;
                ready
            }
        }
    }
}

impl AsyncRead for SendTimeout {
    fn poll_read(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_read(cx, buf)
    }
}

impl AsyncWrite for SendTimeout {
    fn poll_write(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<io::Result<usize>> {
        let polled = Pin::new(&mut self.inner).poll_write(cx, buf);
        self.watch(cx, polled)
    }

    fn poll_write_vectored(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        let polled = Pin::new(&mut self.inner).poll_write_vectored(cx, bufs);
        self.watch(cx, polled)
    }

    fn is_write_vectored(&self) -> bool {
        self.inner.is_write_vectored()
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        let polled = Pin::new(&mut self.inner).poll_flush(cx);
        self.watch(cx, polled)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        let polled = Pin::new(&mut self.inner).poll_shutdown(cx);
        self.watch(cx, polled)
    }
}
