//! The failure risk against slope: the regime probabilities at each requested slope, with
//! the uncertainty used there and where it came from (docs/model.md §9).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::quadrature::regime_probabilities;
use super::uncertainty::{DefaultsUsed, UncertainTerrain, UsedUncertainty};
use super::RegimeProbabilities;
use crate::robot::Robot;
use crate::slope::SignedSlope;

/// The risk at one slope of a [`RiskCurve`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RiskPoint {
    /// Slope, degrees, as requested (a negative slope is evaluated as its magnitude).
    pub slope_deg: f64,
    /// The CVs used and where they came from.
    #[serde(flatten)]
    pub uncertainty: UsedUncertainty,
    /// `P(sinkage or slippage)`.
    pub p_fail: f64,
    /// `P(regime != success)`.
    pub p_not_success: f64,
    /// The probability of each regime (`p_regime` in JSON).
    #[serde(rename = "p_regime")]
    pub probabilities: RegimeProbabilities,
}

/// p_fail and p_not_success at each requested slope.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RiskCurve {
    /// One point per requested slope, in the order given.
    pub points: Vec<RiskPoint>,
    /// Whether default CVs were used at any of the slopes.
    pub defaults_used: DefaultsUsed,
}

/// The risk of `robot` on `terrain` at each of `slopes` (negative slopes are evaluated as their
/// magnitude, docs/model.md §8; each point reports its slope as given), one quadrature per
/// slope, in parallel.
pub fn risk_curve(robot: &Robot, terrain: &UncertainTerrain, slopes: &[SignedSlope]) -> RiskCurve {
    let points: Vec<RiskPoint> = slopes
        .par_iter()
        .map(|&signed| {
            let s = signed.felt();
            let g = terrain.sample(s);
            let p = regime_probabilities(robot, s, &g.ground, g.uncertainty);
            RiskPoint {
                slope_deg: signed.degrees(),
                uncertainty: g.used(),
                p_fail: p.p_fail(),
                p_not_success: p.p_not_success(),
                probabilities: p,
            }
        })
        .collect();
    let defaults_used =
        points.iter().fold(DefaultsUsed::default(), |a, p| a.or(p.uncertainty.defaults_used()));
    RiskCurve { points, defaults_used }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::risk::failure_risk;
    use crate::terrain::Terrain;

    /// The built-in-like terrain without SDs works with the defaults and says so; each point
    /// is the one-slope quadrature.
    #[test]
    fn curve_without_sds_uses_the_defaults() {
        let r = paper_robot();
        let t = UncertainTerrain::new(Terrain::constant(7e5, 1.5e6).unwrap(), None, None).unwrap();
        let slopes: Vec<SignedSlope> =
            [0.0, -10.0, 20.0].iter().map(|&d| SignedSlope::from_degrees(d).unwrap()).collect();
        let c = risk_curve(&r, &t, &slopes);
        assert_eq!(c.defaults_used, DefaultsUsed { k_n: true, k_s: true });
        for p in &c.points {
            assert_eq!((p.uncertainty.cv_n, p.uncertainty.cv_s), (0.1, 0.2));
            let s = crate::Slope::from_signed_degrees(p.slope_deg).unwrap();
            assert_eq!(p.probabilities, failure_risk(&r, s, &t));
            assert_eq!(p.p_fail, p.probabilities.p_fail());
        }
        assert_eq!(c.points[1].slope_deg, -10.0);
        assert!(c.points[2].p_fail > c.points[0].p_fail);
    }
}
