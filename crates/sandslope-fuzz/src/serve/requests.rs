//! The mutated requests of `serve-requests`: a seed mutated as bytes, in its target or body, or
//! with a parameter's value replaced by a hostile one.

use std::sync::LazyLock;

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use sandslope_request::{phase, risk};
use sandslope_request::{plan, predict, scenario, simulate, sweep};

use crate::mutate;

/// Values that replace a parameter's: what has broken number parsers and limits before.
pub(super) const VALUES: &[&str] = &[
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

/// Parameters that are no field of an endpoint: output flags the API refuses, the risk map's
/// heading `rule` (a `/data/risk-map` word), a word no request takes, and broken names.
const OTHER_KEYS: &[&str] = &["json", "plot", "csv", "out", "rule", "threads", "%00", "a%20b"];

/// Parameters added to a request: every field the endpoints read, from their field tables
/// (the scenario's and the robot's, predict, sweep, phase, risk, simulate and plan), so a new
/// field is fuzzed without a line here, then [`OTHER_KEYS`].
pub(super) static KEYS: LazyLock<Vec<&'static str>> = LazyLock::new(|| {
    let tables = [
        scenario::FIELDS,
        scenario::ROBOT_QUANTITIES,
        predict::FIELDS,
        sweep::FIELDS,
        phase::FIELDS,
        risk::FIELDS,
        simulate::FIELDS,
        plan::FIELDS,
    ];
    let mut keys: Vec<&'static str> = tables.iter().flat_map(|t| t.fields.iter().map(|f| f.flag)).collect();
    keys.sort_unstable();
    keys.dedup();
    keys.extend(OTHER_KEYS);
    keys
});

/// Input `i` of a server target: a seed mutated one of four ways.
pub(super) fn input(seeds: &[Vec<u8>], seed: u64, i: u64) -> Vec<u8> {
    let mut rng = StdRng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ i ^ 0x5E55_0000);
    let base = &seeds[rng.random_range(0..seeds.len())];
    match rng.random_range(0..4u8) {
        0 => mutate::mutate(base, &mut rng),
        1 => mutate_target(base, &mut rng),
        2 => substitute(base, &mut rng),
        _ => mutate_body(base, &mut rng),
    }
}

/// (request line, header lines, body) of a raw request.
pub(super) fn split(request: &[u8]) -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    let end = request.windows(4).position(|w| w == b"\r\n\r\n").unwrap_or(request.len());
    let head = &request[..end];
    let body = request.get(end + 4..).unwrap_or_default().to_vec();
    let line_end = head.windows(2).position(|w| w == b"\r\n").unwrap_or(head.len());
    (head[..line_end].to_vec(), head.get(line_end..).unwrap_or_default().to_vec(), body)
}

/// A request from its parts, with a Content-Length that matches the body when it had one.
pub(super) fn join(line: &[u8], headers: &[u8], body: &[u8]) -> Vec<u8> {
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
pub(super) fn mutate_target(request: &[u8], rng: &mut StdRng) -> Vec<u8> {
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
pub(super) fn substitute(request: &[u8], rng: &mut StdRng) -> Vec<u8> {
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
pub(super) fn mutate_body(request: &[u8], rng: &mut StdRng) -> Vec<u8> {
    let (line, headers, body) = split(request);
    if body.is_empty() {
        return mutate::mutate(request, rng);
    }
    join(&line, &headers, &mutate::mutate(&body, rng))
}
