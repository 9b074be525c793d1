//! The user's observations the calibrated model misses, in words: the first items of the
//! report's "where the model and the evidence disagree" (the library's
//! [`ObservationMiss`] values).

use crate::format::Explain;
use sandslope::calibrate::ObservationKind;
use sandslope::report::{ObservationMiss, OBSERVATION_MISS_SD};

/// One item per miss, in the library's order (speeds, then anchoring times).
pub(super) fn observation_items(misses: &[ObservationMiss]) -> Vec<String> {
    misses.iter().map(item).collect()
}

/// A speed (cm/s) or an anchoring time (ms) observed against the calibrated model's.
fn item(m: &ObservationMiss) -> String {
    let rule = format!("rule: within {OBSERVATION_MISS_SD} SD");
    match m.kind {
        ObservationKind::AnchoringTime => format!(
            "Your anchoring time at {}°: observed t1 = {:.0} ± {:.0} ms, the calibrated model gives {} ({rule}).",
            m.slope_deg,
            m.observed * 1e3,
            m.sd * 1e3,
            match (m.model, m.pull()) {
                (Some(t), Some(z)) => format!(
                    "{:.0} ms (the observed is {:.1} times the model's, {:.1} SD away)",
                    t * 1e3,
                    m.observed / t,
                    z.abs()
                ),
                _ => "no anchoring".to_string(),
            }
        ),
        _ => format!(
            "Your speed at {}°: observed {:.2} ± {:.2} cm/s (SD as measured), the calibrated model gives {} ({rule}).",
            m.slope_deg,
            m.observed * 100.0,
            m.sd * 100.0,
            match (m.model, m.pull()) {
                (Some(v), Some(z)) => format!("{:.2} cm/s, {:.1} SD away", v * 100.0, z.abs()),
                _ => format!("no speed ({})", m.cause.explain()),
            }
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sandslope::Cause;

    /// A speed of 5.0 ± 0.5 cm/s against the model's 7.0: (5 - 7) / 0.5 = 4 SD; a t1 of
    /// 114 ± 10 ms against the model's 38 ms: 3.0 times it, 7.6 SD; a speed the model rules out
    /// names the cause.
    #[test]
    fn misses_are_worded_with_their_distance_in_sds() {
        let miss = |kind, observed, sd, model| ObservationMiss {
            kind,
            slope_deg: 20.0,
            observed,
            sd,
            model,
            cause: Cause::NormalSinkage,
        };
        let items = observation_items(&[
            miss(ObservationKind::Speed, 0.05, 0.005, Some(0.07)),
            miss(ObservationKind::AnchoringTime, 0.114, 0.01, Some(0.038)),
            miss(ObservationKind::Speed, 0.05, 0.005, None),
        ]);
        assert_eq!(
            items[0],
            "Your speed at 20°: observed 5.00 ± 0.50 cm/s (SD as measured), the calibrated model gives 7.00 cm/s, \
             4.0 SD away (rule: within 2 SD)."
        );
        assert_eq!(
            items[1],
            "Your anchoring time at 20°: observed t1 = 114 ± 10 ms, the calibrated model gives 38 ms (the observed \
             is 3.0 times the model's, 7.6 SD away) (rule: within 2 SD)."
        );
        assert!(items[2].contains("gives no speed (legs sink: normal equilibrium depth"), "{}", items[2]);
    }
}
