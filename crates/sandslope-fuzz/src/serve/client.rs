//! The server under test (a running `sandslope serve`) and one client's view of it: a request
//! sent and its answer read, and what a connection holds.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{anyhow, Context, Result};

use super::SERVER_TIMEOUT_S;
use crate::{limit_memory, Options};

/// A running server.
pub(super) struct Running {
    child: Child,
    pub(super) addr: String,
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Running {
    pub(super) fn start(o: &Options, log: &Path) -> Result<Running> {
        let mut cmd = Command::new(&o.bin);
        cmd.args(["serve", "--port", "0", "--threads", "2"])
            .args([
                "--header-timeout",
                &SERVER_TIMEOUT_S.to_string(),
                "--send-timeout",
                &SERVER_TIMEOUT_S.to_string(),
            ])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(std::fs::File::create(log)?)
            .env("RUST_BACKTRACE", "0");
        limit_memory(&mut cmd, o.mem_limit_mib);
        let mut child = cmd.spawn().with_context(|| format!("cannot run {}", o.bin.display()))?;
        let mut line = String::new();
        BufReader::new(child.stdout.take().ok_or_else(|| anyhow!("no stdout"))?).read_line(&mut line)?;
        let addr = line
            .trim()
            .strip_prefix("sandslope serve: http://")
            .and_then(|s| s.strip_suffix('/'))
            .ok_or_else(|| anyhow!("the server said {line:?}"))?
            .to_string();
        Ok(Running { child, addr })
    }

    /// Whether the process still runs; its exit described if not.
    pub(super) fn ended(&mut self) -> Option<String> {
        match self.child.try_wait() {
            Ok(None) => None,
            Ok(Some(status)) => Some(format!("the server ended: {status}")),
            Err(e) => Some(format!("cannot wait for the server: {e}")),
        }
    }

    /// Peak resident memory so far, KiB (VmHWM).
    pub(super) fn peak_kib(&self) -> u64 {
        std::fs::read_to_string(format!("/proc/{}/status", self.child.id()))
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("VmHWM:"))
                    .and_then(|l| l.split_whitespace().nth(1).and_then(|v| v.parse().ok()))
            })
            .unwrap_or(0)
    }
}

/// How a request ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Outcome {
    /// An answer with this status, read whole.
    Status(u16),
    /// The server closed the connection without (or in the middle of) an answer.
    Closed,
    /// Neither by the deadline.
    TimedOut,
}

/// Reads one answer from `s` (no body for a HEAD request) until `deadline`.
pub(super) fn read_answer(s: &TcpStream, head_request: bool, deadline: Instant) -> Outcome {
    let mut r = BufReader::new(s);
    let timed_out = |e: &std::io::Error| {
        matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut)
    };
    let line = |r: &mut BufReader<&TcpStream>| -> Result<String, Outcome> {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(Outcome::TimedOut);
        }
        let _ = s.set_read_timeout(Some(left));
        let mut l = Vec::new();
        match r.read_until(b'\n', &mut l) {
            Ok(0) => Err(Outcome::Closed),
            Ok(_) => Ok(String::from_utf8_lossy(&l).trim_end().to_string()),
            Err(e) if timed_out(&e) => Err(Outcome::TimedOut),
            Err(_) => Err(Outcome::Closed),
        }
    };
    let result = (|| -> Result<u16, Outcome> {
        let mut status;
        let (mut length, mut chunked) = (None, false);
        loop {
            let status_line = line(&mut r)?;
            status =
                status_line.split(' ').nth(1).and_then(|v| v.parse::<u16>().ok()).ok_or(Outcome::Closed)?;
            loop {
                let h = line(&mut r)?;
                if h.is_empty() {
                    break;
                }
                let (k, v) = h.split_once(':').unwrap_or((&h, ""));
                match k.trim().to_ascii_lowercase().as_str() {
                    "content-length" => length = v.trim().parse::<u64>().ok(),
                    "transfer-encoding" => chunked = v.trim().eq_ignore_ascii_case("chunked"),
                    _ => {}
                }
            }
            if status >= 200 {
                break;
            }
        }
        if head_request || status == 204 || status == 304 {
            return Ok(status);
        }
        let read_exact = |r: &mut BufReader<&TcpStream>, n: u64| -> Result<(), Outcome> {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(Outcome::TimedOut);
            }
            let _ = s.set_read_timeout(Some(left));
            let copied = std::io::copy(&mut r.by_ref().take(n), &mut std::io::sink());
            match copied {
                Ok(m) if m == n => Ok(()),
                Ok(_) => Err(Outcome::Closed),
                Err(e) if timed_out(&e) => Err(Outcome::TimedOut),
                Err(_) => Err(Outcome::Closed),
            }
        };
        if chunked {
            loop {
                let size = line(&mut r)?;
                let n = u64::from_str_radix(size.split(';').next().unwrap_or("").trim(), 16)
                    .map_err(|_| Outcome::Closed)?;
                read_exact(&mut r, n + 2)?;
                if n == 0 {
                    return Ok(status);
                }
            }
        }
        match length {
            Some(n) => read_exact(&mut r, n).map(|()| status),
            // Neither: the body ends when the server closes.
            None => loop {
                match line(&mut r) {
                    Ok(_) => {}
                    Err(Outcome::Closed) => return Ok(status),
                    Err(e) => return Err(e),
                }
            },
        }
    })();
    match result {
        Ok(status) => Outcome::Status(status),
        Err(o) => o,
    }
}

/// Sends `request` on a fresh connection and reads the answer: (outcome, seconds).
pub(super) fn exchange(addr: &str, request: &[u8], deadline: Duration) -> (Outcome, f64) {
    let t = Instant::now();
    let Ok(mut s) = TcpStream::connect(addr) else { return (Outcome::Closed, 0.0) };
    let _ = s.set_nodelay(true);
    let _ = s.set_write_timeout(Some(deadline));
    // A write the server refused midway (it answered and closed) is not a failure.
    let _ = s.write_all(request);
    let head = request.starts_with(b"HEAD ");
    let outcome = read_answer(&s, head, t + deadline);
    (outcome, t.elapsed().as_secs_f64())
}

/// Limits the socket's receive buffer to 64 KiB (and stops its autotuning).
pub(super) fn small_receive_buffer(s: &TcpStream) {
    use std::os::fd::AsRawFd;
    let size: libc::c_int = 65_536;
    // SAFETY: setsockopt on an open socket with a pointer to a local of the declared size.
    unsafe {
        libc::setsockopt(
            s.as_raw_fd(),
            libc::SOL_SOCKET,
            libc::SO_RCVBUF,
            (&size as *const libc::c_int).cast(),
            std::mem::size_of::<libc::c_int>() as libc::socklen_t,
        );
    }
}

/// What a connection holds, looked at without reading.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Peek {
    /// Nothing yet.
    Nothing,
    /// Bytes from the server.
    Data,
    /// Closed (EOF or an error).
    Closed,
}

pub(super) fn peek(s: &TcpStream) -> Peek {
    let _ = s.set_nonblocking(true);
    let got = match s.peek(&mut [0u8; 1]) {
        Ok(0) => Peek::Closed,
        Ok(_) => Peek::Data,
        Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => Peek::Nothing,
        Err(_) => Peek::Closed,
    };
    let _ = s.set_nonblocking(false);
    got
}
