//! The load mix that runs beside the fuzzed inputs, with its `predict` probe.

use std::io::Write;
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use super::client::{exchange, peek, Outcome, Peek};

/// What the load mix measured: the probe's predict latencies, seconds.
#[derive(Default)]
pub(super) struct Probe {
    pub(super) latencies: Vec<f64>,
    pub(super) failures: u64,
}

/// Runs the load mix against `addr` until `stop`: heavy requests back to back, 50 idle
/// connections, 5 slowloris heads, 2 unread large answers, and a predict every 50 ms.
pub(super) fn load_mix(
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
