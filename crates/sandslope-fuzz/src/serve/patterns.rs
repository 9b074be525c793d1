//! The connection patterns of `serve-connections`: pipelined, oversized and too many headers,
//! garbage, abandoned, half-open, slowloris, silent, and answers nobody reads.

use std::io::{Read, Write};
use std::net::{Shutdown, TcpStream};
use std::time::{Duration, Instant};

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use super::client::{peek, read_answer, small_receive_buffer, Outcome, Peek};
use super::requests::{input, join, split};
use super::SERVER_TIMEOUT_S;

/// A connection pattern's input: which pattern, and its numbers.
pub(super) fn pattern(seeds: &[Vec<u8>], seed: u64, i: u64) -> (u8, Vec<u8>) {
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
pub(super) const PATTERNS: [&str; 9] = [
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
pub(super) fn run_pattern(addr: &str, kind: u8, data: &[u8], timeout: Duration) -> Result<u16, String> {
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
