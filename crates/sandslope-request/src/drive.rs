//! `drive`'s run, checked once: the numbers that `sandslope drive`'s flags, `serve --drive`'s
//! and Python's `drive` keywords set (docs/drive.md), each against its range and named as each
//! front end names it. The servo crate builds the run from them (`DriveConfig`).

use serde::{Deserialize, Serialize};

use sandslope::servo::ServoModel;
use sandslope::{SignedSlope, Terrain};

use crate::error::{RequestError, Result, Words};

/// The numbers of one drive run, as a front end gives them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DriveRun {
    /// Slope of the run, degrees (negative: downhill).
    pub slope_deg: f64,
    /// How long the legs turn, s (0 to 86,400).
    pub duration_s: f64,
    /// Bus read rate, Hz (1 to 1000).
    pub rate_hz: f64,
    /// Seconds the legs hold still at the end (0 to 3600).
    pub hold_s: f64,
    /// The host's watchdog, s (0.01 to 10).
    pub watchdog_s: f64,
    /// The servos' own bus watchdog, s (0.02 to 2.54, its register's range).
    pub bus_watchdog_s: f64,
    /// The servos' current limit, mA (at most the largest a supported model accepts; the
    /// servos' own model is checked at their ping).
    pub current_limit_ma: u16,
    /// The servos' temperature limit, degC (at most the highest a supported model is rated
    /// for; the servos' own model is checked at their ping).
    pub temperature_limit_c: u8,
    /// Stop when the live risk reaches this probability (0 to 1), if given.
    pub stop_on_risk: Option<f64>,
    /// The emulator's current noise, mA (0 to 1000), when the run is emulated.
    pub emulate_noise_ma: Option<f64>,
    /// The emulated sand's k_s, N/m^3, if given.
    pub emulate_k_s: Option<f64>,
}

/// A field as each front end names it: the command line's flag, or Python's keyword (which
/// carries its unit).
fn name(words: Words, field: &str) -> String {
    let keyword = match field {
        "slope" => "slope_deg",
        "duration" => "duration_s",
        "rate" => "rate_hz",
        "hold" => "hold_s",
        "watchdog" => "watchdog_s",
        "bus-watchdog" => "bus_watchdog_s",
        "current-limit" => "current_limit_ma",
        "temperature-limit" => "temperature_limit_c",
        "emulate-noise" => "noise_ma",
        "emulate-k-s" => "k_s",
        other => return words.name(other),
    };
    match words {
        Words::Flag => format!("--{field}"),
        Words::Keyword => keyword.to_string(),
    }
}

/// `value` within `lo..=hi`, else an error naming the field and the range.
fn within(words: Words, field: &str, value: f64, lo: f64, hi: f64) -> Result<()> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(RequestError::invalid(
            field,
            format!("{} = {value} must be between {lo} and {hi}", name(words, field)),
        ))
    }
}

impl DriveRun {
    /// Checks every number against its range; errors name the field in `words`.
    pub fn check(&self, words: Words) -> Result<()> {
        SignedSlope::from_degrees(self.slope_deg)
            .map_err(|e| RequestError::invalid("slope", e.renamed(name(words, "slope"))))?;
        within(words, "duration", self.duration_s, 0.0, 86_400.0)?;
        within(words, "rate", self.rate_hz, 1.0, 1000.0)?;
        within(words, "hold", self.hold_s, 0.0, 3600.0)?;
        within(words, "watchdog", self.watchdog_s, 0.01, 10.0)?;
        within(words, "bus-watchdog", self.bus_watchdog_s, 0.02, 2.54)?;
        let max_ma =
            ServoModel::ALL.iter().filter_map(|m| m.max_current_limit_ma()).fold(0.0, f64::max).floor();
        let max_c = ServoModel::ALL.iter().map(|m| m.max_temperature_c).max().unwrap_or(0);
        if f64::from(self.current_limit_ma) > max_ma {
            return Err(RequestError::invalid(
                "current-limit",
                format!(
                    "{} = {} must be within 0 to {max_ma} mA (the largest Current Limit of a supported servo)",
                    name(words, "current-limit"),
                    self.current_limit_ma,
                ),
            ));
        }
        if self.temperature_limit_c > max_c {
            return Err(RequestError::invalid(
                "temperature-limit",
                format!(
                    "{} = {} must be within 0 to {max_c} degC (the highest rating of a supported servo)",
                    name(words, "temperature-limit"),
                    self.temperature_limit_c,
                ),
            ));
        }
        if let Some(p) = self.stop_on_risk {
            within(words, "stop-on-risk", p, 0.0, 1.0)?;
        }
        if let Some(noise) = self.emulate_noise_ma {
            within(words, "emulate-noise", noise, 0.0, 1000.0)?;
        }
        if let Some(k) = self.emulate_k_s {
            Terrain::constant(1.0, k)
                .map_err(|e| RequestError::invalid("emulate-k-s", e.renamed(name(words, "emulate-k-s"))))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run() -> DriveRun {
        DriveRun {
            slope_deg: 10.0,
            duration_s: 5.0,
            rate_hz: 100.0,
            hold_s: 1.0,
            watchdog_s: 1.0,
            bus_watchdog_s: 0.5,
            current_limit_ma: 1470,
            temperature_limit_c: 65,
            stop_on_risk: None,
            emulate_noise_ma: Some(2.0),
            emulate_k_s: None,
        }
    }

    /// One check, in each front end's words: the command line's flags, Python's keywords.
    #[test]
    fn a_drive_run_is_checked_once_in_each_front_ends_words() {
        assert!(run().check(Words::Flag).is_ok());
        let long = DriveRun { duration_s: 90_000.0, ..run() };
        assert_eq!(
            long.check(Words::Flag).unwrap_err().message(),
            "--duration = 90000 must be between 0 and 86400"
        );
        assert_eq!(
            long.check(Words::Keyword).unwrap_err().message(),
            "duration_s = 90000 must be between 0 and 86400"
        );
        let risky = DriveRun { stop_on_risk: Some(1.5), ..run() };
        assert_eq!(
            risky.check(Words::Keyword).unwrap_err().message(),
            "stop_on_risk = 1.5 must be between 0 and 1"
        );
        let steep = DriveRun { slope_deg: 95.0, ..run() };
        let e = steep.check(Words::Keyword).unwrap_err();
        assert_eq!(e.field(), Some("slope"));
        assert!(e.message().starts_with("slope_deg = 95"), "{}", e.message());
        // The XM430-W350 is rated to 80 degC, the hottest supported servo.
        let hot = DriveRun { temperature_limit_c: 81, ..run() };
        assert!(hot
            .check(Words::Flag)
            .unwrap_err()
            .message()
            .starts_with("--temperature-limit = 81 must be within 0 to 80"));
        let soft = DriveRun { emulate_k_s: Some(-1.0), ..run() };
        assert!(soft.check(Words::Keyword).unwrap_err().message().starts_with("k_s = -1"));
    }
}
