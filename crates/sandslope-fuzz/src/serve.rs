//! The server's targets (issue 39): one `sandslope serve` is started and fed, from several
//! client threads at once, either mutated HTTP requests (`serve-requests`: the seeds in
//! `seeds/serve/` mutated as bytes, in their query or body, or with a value replaced by a
//! hostile one) or connection patterns (`serve-connections`: pipelined requests, oversized and
//! too many headers, half-open and abandoned connections, slowloris heads, silent connections,
//! trickled bodies, answers nobody reads, garbage), while a load mix runs beside them: heavy
//! requests back to back, 50 idle connections, 5 slowloris heads, 2 large answers nobody reads,
//! and a `predict` probe every 50 ms whose latency is reported.
//!
//! The server runs with `--header-timeout 2 --send-timeout 2` so that patterns that wait for a
//! timeout take seconds, not minutes. Per input, a failure is: a 500 (a computation panicked,
//! counted as a panic), any other 5xx but 503, no answer and no close within the deadline (a
//! hang: 3 x `--timeout`, or the header timeout plus 3 s for patterns the server must cut),
//! the server process ending (an abort; it is restarted), or its peak memory over
//! `--max-peak-mib`. The "exit codes" column counts HTTP statuses (0: closed without an answer).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{Shutdown, TcpStream};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::{anyhow, Context, Result};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use crate::{keep, limit_memory, mutate, Options, Tally, Target};

/// What a server target feeds the server.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// Mutated requests, one per connection.
    Requests,
    /// Connection patterns.
    Connections,
}

/// The seed requests (raw HTTP), relative to the repository root.
pub const SEEDS: &[&str] = &[
    "crates/sandslope-fuzz/seeds/serve/get-predict.http",
    "crates/sandslope-fuzz/seeds/serve/post-predict.http",
    "crates/sandslope-fuzz/seeds/serve/get-sweep.http",
    "crates/sandslope-fuzz/seeds/serve/get-phase.http",
    "crates/sandslope-fuzz/seeds/serve/get-risk.http",
    "crates/sandslope-fuzz/seeds/serve/get-risk-solve.http",
    "crates/sandslope-fuzz/seeds/serve/get-risk-map.http",
    "crates/sandslope-fuzz/seeds/serve/get-simulate.http",
    "crates/sandslope-fuzz/seeds/serve/post-simulate.http",
    "crates/sandslope-fuzz/seeds/serve/get-data.http",
    "crates/sandslope-fuzz/seeds/serve/head-page.http",
    "crates/sandslope-fuzz/seeds/serve/chunked-post.http",
    "crates/sandslope-fuzz/seeds/serve/cross-origin.http",
    "crates/sandslope-fuzz/seeds/serve/get-served.http",
];

/// The server's header-read and send timeouts under the fuzzer, seconds.
const SERVER_TIMEOUT_S: u64 = 2;
/// Client threads sending inputs.
const CLIENTS: usize = 4;
/// Client threads running connection patterns (most of them wait for a timeout).
const PATTERN_CLIENTS: usize = 32;

/// Values that replace a parameter's: what has broken number parsers and limits before.
const VALUES: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e400",
    "1e-320",
    "-0",
    "0",
    "-1",
    "",
    "%FF%FE",
    "%00",
    "99999999999999999999",
    "18446744073709551617",
    "0x10",
    "1_000",
    "1.",
    ".5e",
    "abc",
    "0:90:100000",
    "1e4:1e9:100000",
    "1e4:1e9:3:lin",
    "0,0,0,0,0,0,0,0,0,0,0,0,0",
    "-90",
    "90",
    "89.999",
    "true",
    "false",
    "paper-hexapod",
    "glass-beads-300um",
    "..%2F..%2Fetc%2Fpasswd",
    "%2Ftmp%2Fx",
    "time,risk,distance",
    "1e-9",
    "60",
    "61",
    "1000",
    "1001",
    "0:24:25",
    "10:0:5",
    "5,5",
];

/// Parameters added to a request: every flag the endpoints take, and some they do not.
const KEYS: &[&str] = &[
    "slope",
    "slopes",
    "mass",
    "k-n",
    "k-s",
    "leg-radius",
    "leg-width",
    "hip-height",
    "leg-speed",
    "from",
    "to",
    "step",
    "duration",
    "dt",
    "rate",
    "map",
    "solve",
    "max-risk",
    "cv-n",
    "cv-s",
    "robot",
    "terrain",
    "objective",
    "start-px",
    "goal-px",
    "json",
    "plot",
    "dem",
    "csv",
    "out",
    "allow-metastable",
    "rule",
    "threads",
    "%00",
    "a%20b",
];

/// Input `i` of a server target: a seed mutated one of four ways.
pub fn input(seeds: &[Vec<u8>], seed: u64, i: u64) -> Vec<u8> {
    let mut rng = StdRng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ i ^ 0x5E55_0000);
    let base = &seeds[rng.random_range(0..seeds.len())];
    match rng.random_range(0..4u8) {
        0 => mutate::mutate(base, &mut rng),
        1 => mutate_target(base, &mut rng),
        2 => substitute(base, &mut rng),
        _ => mutate_body(base, &mut rng),
    }
}

/// Input `i` as `--emit` writes it: the request, or the connection pattern's bytes (its
/// pattern, 0-8 in the order of [`PATTERNS`], is drawn from the same generator).
pub fn emitted(kind: Kind, seeds: &[Vec<u8>], seed: u64, i: u64) -> Vec<u8> {
    match kind {
        Kind::Requests => input(seeds, seed, i),
        Kind::Connections => pattern(seeds, seed, i).1,
    }
}

/// (request line, header lines, body) of a raw request.
fn split(request: &[u8]) -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    let end = request.windows(4).position(|w| w == b"\r\n\r\n").unwrap_or(request.len());
    let head = &request[..end];
    let body = request.get(end + 4..).unwrap_or_default().to_vec();
    let line_end = head.windows(2).position(|w| w == b"\r\n").unwrap_or(head.len());
    (head[..line_end].to_vec(), head.get(line_end..).unwrap_or_default().to_vec(), body)
}

/// A request from its parts, with a Content-Length that matches the body when it had one.
fn join(line: &[u8], headers: &[u8], body: &[u8]) -> Vec<u8> {
    let text = String::from_utf8_lossy(headers);
    let headers: String = text
        .split("\r\n")
        .map(|h| {
            if h.to_ascii_lowercase().starts_with("content-length:") {
                format!("Content-Length: {}", body.len())
            } else {
                h.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\r\n");
    [line, headers.as_bytes(), b"\r\n\r\n", body].concat()
}

/// The request target's bytes mutated (the method, version and headers kept).
fn mutate_target(request: &[u8], rng: &mut StdRng) -> Vec<u8> {
    let (line, headers, body) = split(request);
    let text = String::from_utf8_lossy(&line).to_string();
    let mut parts = text.splitn(3, ' ');
    let (method, target, version) =
        (parts.next().unwrap_or(""), parts.next().unwrap_or(""), parts.next().unwrap_or(""));
    let mutated = mutate::mutate(target.as_bytes(), rng);
    let line = [method.as_bytes(), b" ", &mutated, b" ", version.as_bytes()].concat();
    join(&line, &headers, &body)
}

/// One parameter's value replaced by a hostile one, or a parameter added (in the query or, for
/// a JSON body, in the body).
fn substitute(request: &[u8], rng: &mut StdRng) -> Vec<u8> {
    let (line, headers, body) = split(request);
    let value = VALUES[rng.random_range(0..VALUES.len())];
    let key = KEYS[rng.random_range(0..KEYS.len())];
    let text = String::from_utf8_lossy(&line).to_string();
    let json_body = body.first() == Some(&b'{');
    if json_body && rng.random_bool(0.7) {
        let mut body = String::from_utf8_lossy(&body).to_string();
        let raw = if value.parse::<f64>().is_ok() && rng.random_bool(0.5) {
            value.to_string()
        } else {
            format!("{value:?}")
        };
        match body.find(": ") {
            Some(at) if rng.random_bool(0.5) => {
                let end = body[at..].find([',', '}']).map_or(body.len(), |e| at + e);
                body.replace_range(at + 2..end, &raw);
            }
            _ => body = body.replacen('{', &format!("{{{key:?}: {raw}, "), 1),
        }
        return join(&line, &headers, body.as_bytes());
    }
    let Some((before, rest)) = text.split_once('?') else {
        let line = text.replacen(" HTTP", &format!("?{key}={value} HTTP"), 1);
        return join(line.as_bytes(), &headers, &body);
    };
    let (query, version) = rest.split_once(' ').unwrap_or((rest, "HTTP/1.1"));
    let mut pairs: Vec<String> = query.split('&').map(str::to_string).collect();
    let at = rng.random_range(0..pairs.len());
    if rng.random_bool(0.6) {
        let k = pairs[at].split('=').next().unwrap_or("").to_string();
        pairs[at] = format!("{k}={value}");
    } else {
        pairs.insert(at, format!("{key}={value}"));
    }
    let line = format!("{before}?{} {version}", pairs.join("&"));
    join(line.as_bytes(), &headers, &body)
}

/// The body's bytes mutated, its Content-Length kept true (or the whole request, without one).
fn mutate_body(request: &[u8], rng: &mut StdRng) -> Vec<u8> {
    let (line, headers, body) = split(request);
    if body.is_empty() {
        return mutate::mutate(request, rng);
    }
    join(&line, &headers, &mutate::mutate(&body, rng))
}

/// A running server.
struct Running {
    child: Child,
    addr: String,
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Running {
    fn start(o: &Options, log: &Path) -> Result<Running> {
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
    fn ended(&mut self) -> Option<String> {
        match self.child.try_wait() {
            Ok(None) => None,
            Ok(Some(status)) => Some(format!("the server ended: {status}")),
            Err(e) => Some(format!("cannot wait for the server: {e}")),
        }
    }

    /// Peak resident memory so far, KiB (VmHWM).
    fn peak_kib(&self) -> u64 {
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
enum Outcome {
    /// An answer with this status, read whole.
    Status(u16),
    /// The server closed the connection without (or in the middle of) an answer.
    Closed,
    /// Neither by the deadline.
    TimedOut,
}

/// Reads one answer from `s` (no body for a HEAD request) until `deadline`.
fn read_answer(s: &TcpStream, head_request: bool, deadline: Instant) -> Outcome {
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
fn exchange(addr: &str, request: &[u8], deadline: Duration) -> (Outcome, f64) {
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
fn small_receive_buffer(s: &TcpStream) {
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
enum Peek {
    /// Nothing yet.
    Nothing,
    /// Bytes from the server.
    Data,
    /// Closed (EOF or an error).
    Closed,
}

fn peek(s: &TcpStream) -> Peek {
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

/// What the load mix measured: the probe's predict latencies, seconds.
#[derive(Default)]
struct Probe {
    latencies: Vec<f64>,
    failures: u64,
}

/// Runs the load mix against `addr` until `stop`: heavy requests back to back, 50 idle
/// connections, 5 slowloris heads, 2 unread large answers, and a predict every 50 ms.
fn load_mix(
    addr: String,
    stop: Arc<AtomicBool>,
    probe: Arc<Mutex<Probe>>,
) -> Vec<std::thread::JoinHandle<()>> {
    let mut threads = Vec::new();
    let heavy = [
        "/api/simulate?slopes=0:20:5&duration=3",
        "/api/risk?slope=0:24:25",
        "/api/phase?slope=10&k-n=1e4:1e7:300&k-s=1e3:1e8:300",
        "/api/risk?solve=mass&slope=0:20:3",
    ];
    {
        let (addr, stop) = (addr.clone(), Arc::clone(&stop));
        threads.push(std::thread::spawn(move || {
            let mut i = 0;
            while !stop.load(Ordering::Relaxed) {
                let req = format!(
                    "GET {} HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n",
                    heavy[i % heavy.len()]
                );
                exchange(&addr, req.as_bytes(), Duration::from_secs(120));
                i += 1;
            }
        }));
    }
    {
        // Idle, trickling and unread connections, reopened as the server closes them.
        let (addr, stop) = (addr.clone(), Arc::clone(&stop));
        threads.push(std::thread::spawn(move || {
            let big = "GET /api/risk?map&slope=10&k-n=1e4:1e7:512&k-s=1e3:1e8:512 HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
            let slow = b"GET /api/predict?slope=10 HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\r\n\r\n";
            let open = |first: &[u8]| {
                TcpStream::connect(&addr).ok().inspect(|s| {
                    let _ = (&*s).write_all(first);
                })
            };
            let closed = |s: &Option<TcpStream>| s.as_ref().is_none_or(|s| peek(s) != Peek::Nothing);
            let mut idle: Vec<Option<TcpStream>> = (0..50).map(|_| open(b"")).collect();
            let mut trickle: Vec<(Option<TcpStream>, usize)> = (0..5).map(|_| (open(b""), 0)).collect();
            let mut unread: Vec<Option<TcpStream>> = (0..2).map(|_| open(big.as_bytes())).collect();
            let mut round = 0u64;
            while !stop.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(200));
                round += 1;
                for s in idle.iter_mut() {
                    if closed(s) {
                        *s = open(b"");
                    }
                }
                for (s, sent) in trickle.iter_mut() {
                    let wrote = s.as_ref().is_some_and(|c| (&*c).write(&slow[*sent % slow.len()..][..1]).is_ok());
                    *sent += 1;
                    if !wrote || closed(s) {
                        *s = open(b"");
                        *sent = 0;
                    }
                }
                // Unread answers are asked for again every 10 s (the server drops each after
                // its 2 s send timeout; what it sent stays unread in the socket).
                if round % 50 == 0 {
                    drop(std::mem::replace(&mut unread, (0..2).map(|_| open(big.as_bytes())).collect()));
                }
            }
        }));
    }
    {
        let (addr, stop) = (addr, Arc::clone(&stop));
        threads.push(std::thread::spawn(move || {
            let req = b"GET /api/predict?slope=17&mass=0.6 HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
            while !stop.load(Ordering::Relaxed) {
                let (outcome, took) = exchange(&addr, req, Duration::from_secs(60));
                let mut p = probe.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                if outcome == Outcome::Status(200) {
                    p.latencies.push(took);
                } else {
                    p.failures += 1;
                }
                drop(p);
                std::thread::sleep(Duration::from_millis(50));
            }
        }));
    }
    threads
}

/// The `q` quantile of sorted `v`, ms.
fn quantile_ms(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v[((v.len() - 1) as f64 * q).round() as usize] * 1e3
}

/// A connection pattern's input: which pattern, and its numbers.
fn pattern(seeds: &[Vec<u8>], seed: u64, i: u64) -> (u8, Vec<u8>) {
    let mut rng = StdRng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ i ^ 0xC0_0000);
    let base = seeds[rng.random_range(0..seeds.len())].clone();
    // Slow patterns (5-8: they wait for a timeout) one time in five.
    let kind = if rng.random_bool(0.2) { rng.random_range(5..9u8) } else { rng.random_range(0..5u8) };
    let data = match kind {
        // Pipelined: 2-8 requests in one write.
        0 => {
            let n = rng.random_range(2..9);
            (0..n).flat_map(|_| input(seeds, seed, rng.random::<u64>())).collect()
        }
        // A head over 64 KiB.
        1 => {
            let (line, headers, body) = split(&base);
            let pad = format!("\r\nX-Pad: {}", "a".repeat(rng.random_range(66_000..300_000)));
            join(&line, &[headers, pad.into_bytes()].concat(), &body)
        }
        // Too many headers.
        2 => {
            let (line, headers, body) = split(&base);
            let many: String = (0..rng.random_range(101..2000)).map(|k| format!("\r\nX-{k}: {k}")).collect();
            join(&line, &[headers, many.into_bytes()].concat(), &body)
        }
        // Garbage.
        3 => (0..rng.random_range(1..4096)).map(|_| rng.random::<u8>()).collect(),
        // Abandoned: a request cut anywhere, then the connection closed.
        4 => {
            let cut = rng.random_range(0..=base.len());
            base[..cut].to_vec()
        }
        // Half-open: part of a request, then the write side shut.
        5 => {
            let cut = rng.random_range(0..base.len().max(1));
            base[..cut].to_vec()
        }
        // Slowloris: a request's head a byte at a time.
        6 => base,
        // Silent.
        7 => Vec::new(),
        // An answer nobody reads (a 2^20-cell risk map, 44 MB).
        _ => b"GET /api/risk?map&slope=12&k-n=1e4:1e7:1024&k-s=1e3:1e8:1024 HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"
            .to_vec(),
    };
    (kind, data)
}

/// Names of the patterns, for the report.
const PATTERNS: [&str; 9] = [
    "pipelined",
    "head over 64 KiB",
    "too many headers",
    "garbage",
    "abandoned",
    "half-open",
    "slowloris",
    "silent",
    "unread answer",
];

/// Runs one pattern: its outcome (a status, or 0 closed), or a failure's description.
fn run_pattern(addr: &str, kind: u8, data: &[u8], timeout: Duration) -> Result<u16, String> {
    let cut = Duration::from_secs(SERVER_TIMEOUT_S + 3);
    let mut s = TcpStream::connect(addr).map_err(|e| format!("connect: {e}"))?;
    let _ = s.set_nodelay(true);
    let _ = s.set_write_timeout(Some(timeout));
    let t = Instant::now();
    let status = |o: Outcome| match o {
        Outcome::Status(c) => Ok(c),
        Outcome::Closed => Ok(0),
        Outcome::TimedOut => Err(format!("{}: neither answered nor closed", PATTERNS[kind as usize])),
    };
    match kind {
        0 => {
            let _ = s.write_all(data);
            // Every answer in turn until the connection closes or a request was malformed.
            let mut last = 0;
            loop {
                match read_answer(&s, false, Instant::now() + timeout * 3) {
                    Outcome::Status(c) => last = c,
                    Outcome::Closed => return Ok(last),
                    // A pipelined request cut short by the mutation: the server waits for the
                    // rest of it, then closes at the header timeout.
                    Outcome::TimedOut => return Err("pipelined: neither answered nor closed".into()),
                }
                if last >= 400 && last != 404 && last != 403 {
                    return Ok(last);
                }
            }
        }
        1..=3 => {
            let _ = s.write_all(data);
            status(read_answer(&s, false, Instant::now() + cut))
        }
        4 => {
            let _ = s.write_all(data);
            drop(s);
            Ok(0)
        }
        5 => {
            let _ = s.write_all(data);
            let _ = s.shutdown(Shutdown::Write);
            status(read_answer(&s, false, Instant::now() + cut))
        }
        6 => {
            for b in data {
                if s.write_all(&[*b]).is_err() {
                    break;
                }
                std::thread::sleep(Duration::from_millis(400));
                if t.elapsed() > cut {
                    return Err(format!("slowloris: still open after {:.1} s", t.elapsed().as_secs_f64()));
                }
                if peek(&s) != Peek::Nothing {
                    break;
                }
            }
            // A whole head trickled within the timeout is answered; a longer one cut.
            status(read_answer(&s, data.starts_with(b"HEAD "), t + cut + timeout * 3))
        }
        7 => status(read_answer(&s, false, t + cut)),
        _ => {
            // A small receive buffer, as a slow client's: the machine's own may hold 32 MB.
            small_receive_buffer(&s);
            let _ = s.write_all(data);
            // Read nothing until the answer has begun and the server must have given up (its
            // send timeout), then everything: the answer must end short.
            let _ = s.set_read_timeout(Some(timeout * 3));
            let _ = s.peek(&mut [0u8; 1]);
            std::thread::sleep(cut);
            let mut got = Vec::new();
            let _ = s.read_to_end(&mut got);
            if got.len() > 40_000_000 {
                return Err(format!("unread answer: {} bytes sent to a client that read nothing", got.len()));
            }
            Ok(0)
        }
    }
}

/// Fuzzes the server with `kind`'s inputs: the target's tally, with the latency lines.
pub fn fuzz(o: &Options, target: &Target, kind: Kind) -> Result<(Tally, Vec<String>)> {
    let seeds = crate::read_seeds(&o.repo, target)?;
    let scratch = crate::tempdir()?;
    let log = scratch.join("serve.log");
    let server = Arc::new(Mutex::new(Running::start(o, &log)?));
    let addr = server.lock().map_err(|_| anyhow!("poisoned"))?.addr.clone();
    let stop = Arc::new(AtomicBool::new(false));
    let probe = Arc::new(Mutex::new(Probe::default()));
    let load = load_mix(addr.clone(), Arc::clone(&stop), Arc::clone(&probe));
    let tally = Arc::new(Mutex::new(Tally::default()));
    let latencies = Arc::new(Mutex::new(Vec::new()));
    let next = Arc::new(AtomicU64::new(0));
    let workers = match kind {
        Kind::Requests => CLIENTS,
        Kind::Connections => PATTERN_CLIENTS,
    };
    std::thread::scope(|scope| {
        for _ in 0..workers {
            let (seeds, next, tally, latencies, server, addr, log) =
                (&seeds, &next, &tally, &latencies, &server, addr.clone(), &log);
            scope.spawn(move || {
                let mut addr = addr;
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= o.runs {
                        break;
                    }
                    let (data, verdict) = match kind {
                        Kind::Requests => {
                            let data = input(seeds, o.seed, i);
                            let (outcome, took) = exchange(&addr, &data, o.timeout * 3);
                            let verdict = match outcome {
                                Outcome::Status(500) => {
                                    Err(("panic", "answered 500: a computation panicked".to_string()))
                                }
                                Outcome::Status(c) if c >= 500 && c != 503 => {
                                    Err(("exit", format!("answered {c}")))
                                }
                                Outcome::Status(c) => {
                                    latencies
                                        .lock()
                                        .unwrap_or_else(std::sync::PoisonError::into_inner)
                                        .push(took);
                                    Ok(c)
                                }
                                Outcome::Closed => Ok(0),
                                Outcome::TimedOut => {
                                    Err(("hang", format!("no answer in {} s", (o.timeout * 3).as_secs())))
                                }
                            };
                            (data, verdict)
                        }
                        Kind::Connections => {
                            let (k, data) = pattern(seeds, o.seed, i);
                            let verdict = run_pattern(&addr, k, &data, o.timeout).map_err(|e| ("hang", e));
                            (data, verdict)
                        }
                    };
                    // The server must still run; if not, say so and start another.
                    let ended = {
                        let mut s = server.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                        let ended = s.ended();
                        if ended.is_some() {
                            if let Ok(fresh) = Running::start(o, log) {
                                *s = fresh;
                            }
                        }
                        addr = s.addr.clone();
                        ended
                    };
                    let mut t = tally.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                    t.runs += 1;
                    match (ended, verdict) {
                        (Some(why), _) => t.aborts.push(keep(o, target, i, &data, "abort", &why)),
                        (None, Ok(code)) => *t.exits.entry(i32::from(code)).or_default() += 1,
                        (None, Err(("panic", why))) => {
                            t.panics.push(keep(o, target, i, &data, "panic", &why))
                        }
                        (None, Err(("hang", why))) => t.hangs.push(keep(o, target, i, &data, "hang", &why)),
                        (None, Err((what, why))) => t.aborts.push(keep(o, target, i, &data, what, &why)),
                    }
                }
            });
        }
    });
    stop.store(true, Ordering::Relaxed);
    for h in load {
        let _ = h.join();
    }
    let mut tally = std::mem::take(&mut *tally.lock().unwrap_or_else(std::sync::PoisonError::into_inner));
    {
        let s = server.lock().map_err(|_| anyhow!("poisoned"))?;
        tally.peak_kib = s.peak_kib();
        if tally.peak_kib > o.max_peak_mib * 1024 {
            tally.memory.push(format!("the server's peak was {} MiB", tally.peak_kib / 1024));
        }
    }
    let mut lat = std::mem::take(&mut *latencies.lock().unwrap_or_else(std::sync::PoisonError::into_inner));
    lat.sort_by(f64::total_cmp);
    let mut p = std::mem::take(&mut *probe.lock().unwrap_or_else(std::sync::PoisonError::into_inner));
    p.latencies.sort_by(f64::total_cmp);
    let mut lines = Vec::new();
    if matches!(kind, Kind::Requests) {
        lines.push(format!(
            "answered: p50 {:.1} ms, p99 {:.1} ms, max {:.1} ms over {} answers",
            quantile_ms(&lat, 0.5),
            quantile_ms(&lat, 0.99),
            quantile_ms(&lat, 1.0),
            lat.len()
        ));
    }
    lines.push(format!(
        "load mix's predict probe: p50 {:.1} ms, p99 {:.1} ms, max {:.1} ms over {} ({} failed)",
        quantile_ms(&p.latencies, 0.5),
        quantile_ms(&p.latencies, 0.99),
        quantile_ms(&p.latencies, 1.0),
        p.latencies.len(),
        p.failures
    ));
    if p.failures > 0 {
        tally
            .hangs
            .push(format!("{} of the load mix's predicts were not answered 200 within 60 s", p.failures));
    }
    drop(server);
    let _ = std::fs::remove_dir_all(&scratch);
    Ok((tally, lines))
}
