//! What a run will ask of the servos and the bus, worked out before anything moves
//! (docs/drive.md, "Before it moves"): the range of every goal over the requested duration
//! against the control table's ranges, and the cycle rate the bus can carry.

use sandslope::servo::model::{EXTENDED_GOAL_LIMIT_PULSES, RAD_PER_PULSE};
use sandslope::servo::GaitSchedule;

use crate::config::{Profile, ServoConfig};

/// The widest a leg's start goal can lie from zero once its revolution counter is cleared: the
/// CLEAR instruction puts Present Position within one turn (0 to 4095), and the stand-up goes
/// to the nearest turn of the start angle, at most half a turn (2048) away: -2048 to 6143.
pub const CLEARED_START_RANGE_PULSES: (i32, i32) = (-2048, 6143);

/// The longest gait, s, that keeps every goal of the extended position mode within its range
/// (`sandslope::servo::model::EXTENDED_GOAL_LIMIT_PULSES`, every supported model's), with each leg starting at `start_goal[j]` pulses;
/// and the leg that limits it. The gait turns every leg forward (`omega > 0`), so a servo of
/// direction +1 counts up and one of direction -1 down: the room is the limit minus the start
/// goal in the direction of travel, less one pulse for rounding.
pub fn longest_position_run_s(
    schedule: &GaitSchedule,
    servos: &[ServoConfig],
    start_goal: &[i32],
) -> (f64, usize) {
    let limit = f64::from(EXTENDED_GOAL_LIMIT_PULSES);
    servos
        .iter()
        .zip(start_goal)
        .enumerate()
        .map(|(j, (s, &g))| {
            let ahead = if s.direction >= 0 { f64::from(g) } else { -f64::from(g) };
            let room = (limit - ahead - 1.0).max(0.0);
            (schedule.time_to_travel(room * RAD_PER_PULSE), j)
        })
        .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
}

/// The start goal that leaves a servo the least room after its counter is cleared
/// ([`CLEARED_START_RANGE_PULSES`]): the top for one counting up, the bottom for one counting
/// down.
pub fn worst_cleared_start(servos: &[ServoConfig]) -> Vec<i32> {
    servos
        .iter()
        .map(|s| if s.direction >= 0 { CLEARED_START_RANGE_PULSES.1 } else { CLEARED_START_RANGE_PULSES.0 })
        .collect()
}

/// Why a run's goals do not fit the servos' ranges.
#[derive(Debug, Clone, PartialEq)]
pub struct RangeShortfall {
    /// The longest duration that fits, s.
    pub longest_s: f64,
    /// The leg that limits it.
    pub leg: usize,
}

/// Checks that a run of `duration_s` in `profile` sends no Goal Position outside the extended
/// mode's range, from the worst start a cleared counter allows; velocity mode has no position
/// goal and its Goal Velocity is capped at the Velocity Limit written, so it always fits.
pub fn check_goal_range(
    schedule: &GaitSchedule,
    servos: &[ServoConfig],
    profile: Profile,
    duration_s: f64,
    start_goal: Option<&[i32]>,
) -> Result<(), RangeShortfall> {
    if profile == Profile::Velocity {
        return Ok(());
    }
    let worst = worst_cleared_start(servos);
    let (longest_s, leg) = longest_position_run_s(schedule, servos, start_goal.unwrap_or(&worst));
    if duration_s > longest_s {
        return Err(RangeShortfall { longest_s, leg });
    }
    Ok(())
}

/// The bus's share of one cycle: a Sync Write of every goal and a Sync Read of the state
/// block, with each servo's Return Delay Time and the adapter's latency.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BusBudget {
    /// Baud rate.
    pub baud: u32,
    /// Servos on the bus.
    pub servos: usize,
    /// Bytes on the wire per cycle.
    pub bytes: usize,
    /// Return Delay Time of each servo, s (the driver writes 0).
    pub return_delay_s: f64,
    /// The USB adapter's latency timer, s (read from the system when it says; else assumed).
    pub latency_s: f64,
    /// The shortest cycle, s.
    pub cycle_s: f64,
    /// The fastest rate, Hz.
    pub max_rate_hz: f64,
}

/// The bytes of one cycle for `n` servos (Protocol 2.0, no byte stuffing): the Sync Write
/// `14 + 5 n` (header 4, ID 1, length 2, instruction 1, address 2, data length 2, per servo its
/// ID and 4 bytes, CRC 2), the Sync Read `14 + n`, and `n` status packets of `11 + 21` (the
/// state block, [`crate::table::STATE_BLOCK`]).
pub fn cycle_bytes(n: usize) -> usize {
    let status = 11 + usize::from(crate::table::STATE_BLOCK.1);
    (14 + 5 * n) + (14 + n) + n * status
}

/// The shortest cycle at `baud` (10 bits a byte: start, 8 data, stop) for `n` servos that each
/// wait `return_delay_s` before answering, with one adapter latency per cycle (the last status
/// packets wait in a USB-serial chip until its latency timer expires).
pub fn bus_budget(baud: u32, n: usize, return_delay_s: f64, latency_s: f64) -> BusBudget {
    let bytes = cycle_bytes(n);
    let cycle_s = 10.0 * bytes as f64 / f64::from(baud.max(1)) + n as f64 * return_delay_s + latency_s;
    BusBudget { baud, servos: n, bytes, return_delay_s, latency_s, cycle_s, max_rate_hz: 1.0 / cycle_s }
}

/// The latency timer of a USB-serial adapter at `port` (`/dev/ttyUSB0`), s, as Linux shows it
/// (`/sys/bus/usb-serial/devices/ttyUSB0/latency_timer`, ms); `None` where the system does not
/// say (an ACM device, another OS).
pub fn usb_latency_s(port: &std::path::Path) -> Option<f64> {
    let name = port.file_name()?.to_str()?;
    let text = std::fs::read_to_string(format!("/sys/bus/usb-serial/devices/{name}/latency_timer")).ok()?;
    text.trim().parse::<f64>().ok().map(|ms| ms / 1000.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sandslope::robot::RobotSpec;
    use sandslope::Robot;

    fn paper() -> GaitSchedule {
        GaitSchedule::new(&Robot::new(RobotSpec::paper_hexapod()).unwrap(), 6).unwrap()
    }

    fn servos() -> Vec<ServoConfig> {
        crate::session::default_servos(6)
    }

    /// By hand: 1 turn/s, run-up 0.2 s. A servo counting up from 6143 has 1,048,575 - 6143 - 1
    /// = 1,042,431 pulses = 254.500 turns of room, reached at 0.1 + 254.500 = 254.600 s.
    #[test]
    fn the_longest_position_run_by_hand() {
        let s = paper();
        let (t, leg) = longest_position_run_s(&s, &servos(), &worst_cleared_start(&servos()));
        assert!((t - (0.1 + 1_042_431.0 / 4096.0)).abs() < 1e-9, "{t}");
        assert_eq!(leg, 0);
        // A 600 s run at 1 turn/s does not fit; 250 s does; velocity mode always does.
        let e = check_goal_range(&s, &servos(), Profile::Position, 600.0, None).unwrap_err();
        assert!((e.longest_s - 254.6).abs() < 1e-3);
        assert!(check_goal_range(&s, &servos(), Profile::Position, 250.0, None).is_ok());
        assert!(check_goal_range(&s, &servos(), Profile::Velocity, 600.0, None).is_ok());
        // From a count near the top (1,040,000, counting up): 8574 pulses = 2.093 turns.
        let near = vec![1_040_000, 0, 0, 0, 0, 0];
        let (t, leg) = longest_position_run_s(&s, &servos(), &near);
        assert_eq!(leg, 0);
        assert!((t - (0.1 + 8574.0 / 4096.0)).abs() < 1e-9, "{t}");
    }

    /// By hand: 6 servos, 14 + 30 + 14 + 6 + 6 x 32 = 256 bytes, 2560 bits: 44.4 ms at 57,600
    /// baud (22.5 Hz at most, below the default 50 Hz); 2.56 ms at 1 Mbaud.
    #[test]
    fn the_bus_budget_by_hand() {
        assert_eq!(cycle_bytes(6), 256);
        let slow = bus_budget(57_600, 6, 0.0, 0.0);
        assert!((slow.cycle_s - 2560.0 / 57_600.0).abs() < 1e-12);
        assert!((slow.max_rate_hz - 22.5).abs() < 1e-9);
        // The factory Return Delay Time (250 x 2 us = 0.5 ms each) and a 16 ms latency timer.
        let factory = bus_budget(57_600, 6, 500e-6, 0.016);
        assert!((factory.cycle_s - (2560.0 / 57_600.0 + 0.003 + 0.016)).abs() < 1e-12);
        let fast = bus_budget(1_000_000, 6, 0.0, 0.001);
        assert!((fast.cycle_s - 0.003_56).abs() < 1e-12);
    }
}
