//! The run's report as JSON (`drive --json`, Python's `drive`, the explorer): how the run ended
//! flat beside its numbers, not a Rust `Result`'s `{"Ok": ...}`.

use serde::Serialize;

use crate::driver::{DriveOutcome, DriveReport, LiveEstimate, TorqueOff};
use crate::setup::SetupDone;

#[derive(Serialize)]
struct Flat<'a> {
    outcome: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    time_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    p_fail: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<&'a str>,
    cycles: usize,
    rate_hz: f64,
    cycle_jitter_ms: f64,
    max_cycle_ms: f64,
    setup: &'a SetupDone,
    live: &'a [LiveEstimate],
    prior_p_fail: Option<f64>,
    leg_speed_rad_s: Option<f64>,
    torque_off: &'a TorqueOff,
}

impl Serialize for DriveReport {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let (outcome, time_s, p_fail, error) = match &self.outcome {
            Ok(DriveOutcome::Completed { time_s }) => ("completed", Some(*time_s), None, None),
            Ok(DriveOutcome::Interrupted { time_s }) => ("interrupted", Some(*time_s), None, None),
            Ok(DriveOutcome::Halted { time_s, p_fail }) => ("halted", Some(*time_s), Some(*p_fail), None),
            Err(e) => ("failed", None, None, Some(e.as_str())),
        };
        Flat {
            outcome,
            time_s,
            p_fail,
            error,
            cycles: self.cycles,
            rate_hz: self.rate_hz,
            cycle_jitter_ms: self.cycle_jitter_ms,
            max_cycle_ms: self.max_cycle_ms,
            setup: &self.setup,
            live: &self.live,
            prior_p_fail: self.prior_p_fail,
            leg_speed_rad_s: self.leg_speed_rad_s,
            torque_off: &self.torque_off,
        }
        .serialize(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_outcome_is_flat_not_a_rust_result() {
        let mut r = DriveReport::not_started("no bus".into());
        let v = serde_json::to_value(&r).unwrap();
        assert_eq!(v["outcome"], "failed");
        assert_eq!(v["error"], "no bus");
        r.outcome = Ok(DriveOutcome::Halted { time_s: 1.5, p_fail: 0.7 });
        let v = serde_json::to_value(&r).unwrap();
        assert_eq!(
            (v["outcome"].as_str(), v["time_s"].as_f64(), v["p_fail"].as_f64()),
            (Some("halted"), Some(1.5), Some(0.7))
        );
        assert!(v.get("Ok").is_none() && v.get("error").is_none());
    }
}
