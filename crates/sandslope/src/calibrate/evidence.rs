//! The evidence a calibration fits: observed speeds and anchoring times (force tests are a
//! terrain table, [`super::ShearShape::ForceTests`]), and the checks they must pass.

use super::CalibrationError;
use crate::slope::Slope;

/// One observed step-averaged speed with its standard deviation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedObservation {
    /// Slope of the trials.
    pub slope: Slope,
    /// Mean step-averaged upslope speed, m/s.
    pub speed: f64,
    /// Standard deviation of the speed across steps or trials, m/s (> 0).
    pub speed_sd: f64,
}

/// One observed anchoring time with its standard deviation (as `sandslope track` measures it)
/// at a slope, for the calibration. `infer`'s per-walk mean with its standard error is
/// [`crate::infer::MeanAnchoringTime`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnchoringObservation {
    /// Slope of the trials.
    pub slope: Slope,
    /// Mean anchoring time t1 after touchdown, s.
    pub t1: f64,
    /// Its standard deviation across steps or trials, s (> 0).
    pub t1_sd: f64,
}

/// Every speed finite with an SD above 0, at most one per slope.
pub(crate) fn check_speeds(speeds: &[SpeedObservation]) -> Result<(), CalibrationError> {
    let rule = Rule { what: "speed", value_key: "speed_m_s", sd_key: "speed_sd_m_s", non_negative: false };
    rule.check(speeds.iter().map(|o| (o.slope, o.speed, o.speed_sd)))
}

/// Every t1 finite and >= 0 with an SD above 0, at most one per slope.
pub(crate) fn check_anchoring(anchoring: &[AnchoringObservation]) -> Result<(), CalibrationError> {
    let rule = Rule { what: "anchoring time", value_key: "t1_s", sd_key: "t1_sd_s", non_negative: true };
    rule.check(anchoring.iter().map(|o| (o.slope, o.t1, o.t1_sd)))
}

/// What one kind of observation must satisfy, with the file keys its messages name.
struct Rule {
    what: &'static str,
    value_key: &'static str,
    sd_key: &'static str,
    non_negative: bool,
}

impl Rule {
    fn check(&self, observations: impl Iterator<Item = (Slope, f64, f64)>) -> Result<(), CalibrationError> {
        let mut seen: Vec<f64> = Vec::new();
        for (slope, value, sd) in observations {
            let slope_deg = slope.degrees();
            let bad =
                |reason: String| CalibrationError::BadObservation { what: self.what, slope_deg, reason };
            if !(value.is_finite() && (value >= 0.0 || !self.non_negative)) {
                let rule = if self.non_negative { "a finite number >= 0" } else { "a finite number" };
                return Err(bad(format!("{} = {value} must be {rule}", self.value_key)));
            }
            if !(sd.is_finite() && sd > 0.0) {
                return Err(bad(format!("{} = {sd} must be greater than 0", self.sd_key)));
            }
            if seen.contains(&slope_deg) {
                return Err(CalibrationError::DuplicateSlope { what: self.what, slope_deg });
            }
            seen.push(slope_deg);
        }
        Ok(())
    }
}
