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

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use anyhow::{anyhow, Result};

use crate::{keep, Options, Tally, Target};
use client::{exchange, Outcome, Running};
use load::{load_mix, Probe};
use patterns::{pattern, run_pattern};
use requests::input;

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

mod client;
mod load;
mod patterns;
mod requests;

/// Input `i` as `--emit` writes it: the request, or the connection pattern's bytes (its
/// pattern, 0-8 in the order of [`patterns::PATTERNS`], is drawn from the same generator).
pub fn emitted(kind: Kind, seeds: &[Vec<u8>], seed: u64, i: u64) -> Vec<u8> {
    match kind {
        Kind::Requests => input(seeds, seed, i),
        Kind::Connections => pattern(seeds, seed, i).1,
    }
}

/// The `q` quantile of sorted `v`, ms.
fn quantile_ms(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v[((v.len() - 1) as f64 * q).round() as usize] * 1e3
}

/// Sends one mutated request and judges the answer: its status (0: closed without one), or
/// (what failed, why). The latency of every answer but a failure's is pushed to `latencies`.
fn request_verdict(
    addr: &str,
    data: &[u8],
    deadline: Duration,
    latencies: &Mutex<Vec<f64>>,
) -> std::result::Result<u16, (&'static str, String)> {
    let (outcome, took) = exchange(addr, data, deadline);
    match outcome {
        Outcome::Status(500) => Err(("panic", "answered 500: a computation panicked".to_string())),
        Outcome::Status(c) if c >= 500 && c != 503 => Err(("exit", format!("answered {c}"))),
        Outcome::Status(c) => {
            latencies.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(took);
            Ok(c)
        }
        Outcome::Closed => Ok(0),
        Outcome::TimedOut => Err(("hang", format!("no answer in {} s", deadline.as_secs()))),
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
                            let verdict = request_verdict(&addr, &data, o.timeout * 3, latencies);
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
