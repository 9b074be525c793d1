//! Byte mutations of a seed file, in the spirit of AFL's havoc stage, with the values that have
//! broken readers before: numbers no sensor gives (-1e308, 1e-320, NaN, 1e400, 2^64 + 1), sizes
//! a binary header may claim (0xFFFFFFFF in a TIFF tag count), truncation and repetition.

use rand::rngs::StdRng;
use rand::RngExt;

/// Largest mutated input, bytes (repetition stops here).
pub const MAX_INPUT: usize = 4 << 20;

/// Text tokens that replace a number, a field or a line.
const TOKENS: &[&str] = &[
    "-1e308",
    "1e308",
    "1e-320",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "1e400",
    "0",
    "-0",
    "-1",
    "99999999999",
    "18446744073709551617",
    "4294967296",
    "",
    " ",
    "\"",
    ",,,,",
    "\t",
    "#",
    "=",
    "[",
    "]",
    "{}",
    "0x10",
    "1.",
    ".5e",
    "\u{feff}",
    "é",
    "\0",
    "-",
    "1e-7",
    "65536",
    "1000000000",
    "true",
];

/// 32-bit values a binary header may claim.
const WORDS: &[u32] =
    &[0, 1, 2, 0xFF, 0xFFFF, 0x7FFF_FFFF, 0x8000_0000, 0xFFFF_FFFF, 0x1000_0000, 65_536, 2_000_000];

/// `seed` mutated by 1 to 8 stacked operations chosen by `rng`.
pub fn mutate(seed: &[u8], rng: &mut StdRng) -> Vec<u8> {
    let mut data = seed.to_vec();
    let ops = 1 + rng.random_range(0..8usize).min(rng.random_range(0..8usize));
    for _ in 0..ops {
        apply(&mut data, rng);
        data.truncate(MAX_INPUT);
    }
    data
}

fn apply(data: &mut Vec<u8>, rng: &mut StdRng) {
    let len = data.len();
    let at = |rng: &mut StdRng| if len == 0 { 0 } else { rng.random_range(0..len) };
    match rng.random_range(0..11u8) {
        0 if len > 0 => {
            let i = at(rng);
            data[i] ^= 1 << rng.random_range(0..8u8);
        }
        1 if len > 0 => {
            let i = at(rng);
            data[i] = *[b'\n', b',', b'"', b'-', b'9', b'=', b'.', b'e', 0, 0xFF, b' ', b'#', b'\r']
                .get(rng.random_range(0..13usize))
                .unwrap_or(&0);
        }
        2 if len > 0 => {
            // Delete a range.
            let i = at(rng);
            let n = rng.random_range(1..=64usize.min(len - i));
            data.drain(i..i + n);
        }
        3 if len > 0 => {
            // Duplicate a range in place.
            let i = at(rng);
            let n = rng.random_range(1..=256usize.min(len - i));
            let copy: Vec<u8> = data[i..i + n].to_vec();
            let j = at(rng);
            data.splice(j..j, copy);
        }
        4 => {
            let i = at(rng);
            let n = rng.random_range(1..=16usize);
            let bytes: Vec<u8> = (0..n).map(|_| rng.random::<u8>()).collect();
            data.splice(i..i, bytes);
        }
        5 if len > 0 => {
            // Replace a number (a run of digits, signs, dots and exponents) with a token.
            let i = at(rng);
            let numeric = |b: u8| b.is_ascii_digit() || b"+-.eE".contains(&b);
            if let Some(start) = (i..len).find(|&k| data[k].is_ascii_digit()) {
                let mut s = start;
                while s > 0 && numeric(data[s - 1]) {
                    s -= 1;
                }
                let e = (start..len).find(|&k| !numeric(data[k])).unwrap_or(len);
                let token = TOKENS[rng.random_range(0..TOKENS.len())].as_bytes().to_vec();
                data.splice(s..e, token);
            }
        }
        6 => {
            let i = at(rng);
            let token = TOKENS[rng.random_range(0..TOKENS.len())].as_bytes().to_vec();
            data.splice(i..i, token);
        }
        7 if len >= 4 => {
            // A binary word (little or big endian) a header may claim.
            let i = rng.random_range(0..=len - 4);
            let w = WORDS[rng.random_range(0..WORDS.len())];
            let bytes = if rng.random_bool(0.5) { w.to_le_bytes() } else { w.to_be_bytes() };
            data[i..i + 4].copy_from_slice(&bytes);
        }
        8 if len > 0 => {
            data.truncate(at(rng));
        }
        9 if len > 0 => {
            // Repeat one line many times (a long file, a header repeated).
            let i = at(rng);
            let start = data[..i].iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
            let end = data[i..].iter().position(|&b| b == b'\n').map_or(len, |p| i + p + 1);
            let line = data[start..end].to_vec();
            let times = rng.random_range(2..=2000usize).min(MAX_INPUT / line.len().max(1));
            let mut block = Vec::with_capacity(line.len() * times);
            for _ in 0..times {
                block.extend_from_slice(&line);
            }
            data.splice(end..end, block);
        }
        10 if len > 0 => {
            // Swap two lines' worth of bytes: columns or rows out of order.
            let (i, j) = (at(rng), at(rng));
            let (a, b) = (i.min(j), i.max(j));
            data[a..=b.min(len - 1)].reverse();
        }
        _ => {
            let i = at(rng);
            data.insert(i.min(data.len()), rng.random::<u8>());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// Mutation is deterministic in the seed (so a failure is reproducible from its index),
    /// changes the input, and never exceeds the size cap.
    #[test]
    fn mutations_are_reproducible_bounded_and_change_the_input() {
        let seed = b"slope_deg,speed_m_s,speed_sd_m_s\n0,0.157,0.0097\n10,0.113,0.011\n".to_vec();
        let a: Vec<Vec<u8>> = (0..200).map(|i| mutate(&seed, &mut StdRng::seed_from_u64(i))).collect();
        let b: Vec<Vec<u8>> = (0..200).map(|i| mutate(&seed, &mut StdRng::seed_from_u64(i))).collect();
        assert_eq!(a, b);
        assert!(a.iter().filter(|m| **m != seed).count() > 180);
        assert!(a.iter().all(|m| m.len() <= MAX_INPUT));
        assert!(a.iter().any(|m| m.windows(6).any(|w| w == b"-1e308" || w == b"1e-320")));
    }
}
