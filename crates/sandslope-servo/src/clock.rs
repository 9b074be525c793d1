//! The run's clock (docs/drive.md, "The emulator's clock"): the wall's, or, for an emulated
//! bus, a virtual one that the driver's loop and the emulated servos advance themselves.
//!
//! On the real clock a cycle's wait is a `sleep` and the emulated servos move with the wall's
//! time, so an emulated run takes as long as a robot's and shows the real loop's timing (its
//! rate and jitter on this machine). On the virtual clock the driver's wait between cycles
//! moves the clock on instead of sleeping, and the emulator moves it over what a real bus would
//! have waited through: a reply that does not come (a silent servo: dynamixel2's reply timeout)
//! and a frozen bus (to the freeze's end). The run then costs its computing time, not its
//! duration, and a loaded machine cannot stretch a cycle past the watchdogs: the clock stands
//! still while the process is descheduled.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use serde::Serialize;

use crate::packet::{inst, Instruction, BROADCAST};

/// Which clock an emulated run keeps (`--emulate-clock`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ClockKind {
    /// The wall's: a run of S seconds takes S seconds.
    #[default]
    Real,
    /// Simulated time: a run takes its computing time.
    Virtual,
}

impl ClockKind {
    /// The kind named `real` or `virtual`.
    pub fn parse(text: &str) -> Option<ClockKind> {
        match text {
            "real" => Some(ClockKind::Real),
            "virtual" => Some(ClockKind::Virtual),
            _ => None,
        }
    }

    /// A new clock of this kind, at time 0; `seed` seeds the virtual clock's oversleeps
    /// ([`Clock::wait_cycle`]).
    pub fn start(self, seed: u64) -> Clock {
        match self {
            ClockKind::Real => Clock::Real(Instant::now()),
            ClockKind::Virtual => {
                Clock::Virtual(Arc::new(VirtualTime { ns: AtomicU64::new(0), rng: AtomicU64::new(seed) }))
            }
        }
    }
}

/// Seconds since the clock's start, shared by the driver's loop and the emulator's thread
/// (clones read and move the same clock).
#[derive(Debug, Clone)]
pub enum Clock {
    /// The wall's, from this instant.
    Real(Instant),
    /// Virtual time.
    Virtual(Arc<VirtualTime>),
}

/// The virtual clock's state.
#[derive(Debug)]
pub struct VirtualTime {
    /// Nanoseconds since the start.
    ns: AtomicU64,
    /// The oversleeps' random state (SplitMix64).
    rng: AtomicU64,
}

impl VirtualTime {
    /// A uniform number in [0, 1) (SplitMix64, Steele, Lea and Flood 2014).
    fn uniform(&self) -> f64 {
        let mut z =
            self.rng.fetch_add(0x9E37_79B9_7F4A_7C15, Ordering::SeqCst).wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) as f64 / 2f64.powi(64)
    }
}

impl Clock {
    /// The wall's clock from now.
    pub fn real() -> Clock {
        ClockKind::Real.start(0)
    }

    /// Whether the clock is virtual.
    pub fn is_virtual(&self) -> bool {
        matches!(self, Clock::Virtual(_))
    }

    /// Seconds since the start.
    pub fn now(&self) -> f64 {
        match self {
            Clock::Real(start) => start.elapsed().as_secs_f64(),
            Clock::Virtual(v) => v.ns.load(Ordering::SeqCst) as f64 * 1e-9,
        }
    }

    /// Waits `s` seconds: sleeps on the real clock, moves the virtual one on.
    pub fn sleep(&self, s: f64) {
        if s.is_nan() || s <= 0.0 {
            return;
        }
        match self {
            Clock::Real(_) => std::thread::sleep(Duration::from_secs_f64(s)),
            Clock::Virtual(v) => {
                v.ns.fetch_add(nanos(s), Ordering::SeqCst);
            }
        }
    }

    /// The driver's wait for the rest of cycle number `cycle` (`period` s long, `spent` s of
    /// it gone): a sleep on the real clock. On the virtual one the rest plus what a real
    /// sleep oversleeps, uniform up to [`OVERSLEEP_S`] (seeded), and before the second cycle
    /// a uniform part of a period, so that the bus's samples fall at a phase of the gait of
    /// the seed's choosing, as a real loop's do at whatever phase its start and its sleeps
    /// set. Nothing when the cycle overran.
    pub fn wait_cycle(&self, period: f64, spent: f64, cycle: usize) {
        let rest = period - spent;
        match self {
            Clock::Virtual(v) if rest > 0.0 => {
                let extra = if cycle == 0 { period } else { OVERSLEEP_S };
                self.sleep(rest + extra * v.uniform());
            }
            _ => self.sleep(rest),
        }
    }

    /// Moves a virtual clock on by `s` seconds that a real bus spends waiting (the real clock
    /// has spent them already).
    pub fn advance_by(&self, s: f64) {
        if let Clock::Virtual(v) = self {
            v.ns.fetch_add(nanos(s), Ordering::SeqCst);
        }
    }

    /// Moves a virtual clock on to at least `t` s (the real clock moves by itself).
    pub fn advance_to(&self, t: f64) {
        if let Clock::Virtual(v) = self {
            v.ns.fetch_max(nanos(t), Ordering::SeqCst);
        }
    }
}

fn nanos(s: f64) -> u64 {
    (s.max(0.0) * 1e9).round().min(u64::MAX as f64) as u64
}

/// The most a virtual cycle's wait oversleeps, s, as a real loop's sleep does (its cycles at
/// the emulator's 50 Hz averaged 20.3 ms, 49.2 Hz). Not for realism alone: cycles of exactly
/// 20 ms sample every 1 s stride at the same 50 instants, and the stance bins' means then
/// alias (a touchdown's spike caught or missed in every stride alike): 20 runs on sand of
/// k_s 1.95e6 N/m^3 at 20 deg read it as 4e6 to 3e7, the pooled interval covering the truth
/// in 0 of 20 (crates/sandslope-cli/tests/drive/bench.rs); up to 1 ms, 0.5 ms on average, the
/// sampling drifts 25 ms a stride, more than the 20 ms between samples. The seeds' phases
/// (the first wait's) keep runs of different seeds from sampling alike: with the oversleeps
/// alone, four seeds' runs read nearly the same k_s stance by stance (the first stance 8.9e6
/// to 1.0e7 N/m^3 in all four, the second 6.0e5 to 6.7e5).
pub const OVERSLEEP_S: f64 = 0.001;

/// What dynamixel2 waits for a status packet that does not come, s: its reply timeout, the
/// transfer time of the message at the bus's baud rate plus 34 ms, for the driver's state
/// block (11 bytes of packet around 21 of data) at the pty's nominal 9600 baud
/// ([`EMULATED_BAUD`]): 32 x 10 / 9600 s + 34 ms = 67 ms.
pub const REPLY_TIMEOUT_S: f64 = 32.0 * 10.0 / EMULATED_BAUD as f64 + 0.034;

/// The emulator's pty's nominal baud rate: a pty moves bytes at once whatever its rate, but
/// dynamixel2 sets its reply timeouts from it ([`REPLY_TIMEOUT_S`]).
pub const EMULATED_BAUD: u32 = 9600;

/// Whether servo `id` answers `ins` with a status packet (Status Return Level 2, as the
/// driver's setup writes it): what the driver waits for when the servo is silent.
pub fn expects_reply(ins: &Instruction, id: u8) -> bool {
    let p = &ins.params;
    match ins.instruction {
        inst::PING => ins.id == id || ins.id == BROADCAST,
        inst::SYNC_READ => ins.id == BROADCAST && p.len() >= 4 && p[4..].contains(&id),
        inst::BULK_READ => ins.id == BROADCAST && p.chunks(5).any(|c| c.len() == 5 && c[0] == id),
        _ => ins.id == id,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_virtual_clock_moves_only_when_told() {
        let c = ClockKind::Virtual.start(1);
        assert_eq!(c.now(), 0.0);
        c.sleep(0.02);
        let shared = c.clone();
        shared.sleep(0.03);
        assert!((c.now() - 0.05).abs() < 1e-12);
        c.advance_to(0.04);
        assert!((c.now() - 0.05).abs() < 1e-12, "advance_to never goes back");
        c.advance_to(0.6);
        assert!((c.now() - 0.6).abs() < 1e-12);
    }

    #[test]
    fn the_reply_timeout_is_dynamixel2s_for_the_state_block() {
        // 32 bytes of 10 bits at 9600 baud: 33.3 ms, plus dynamixel2's 34 ms.
        assert!((REPLY_TIMEOUT_S - 0.0673).abs() < 1e-4, "{REPLY_TIMEOUT_S}");
    }
}
