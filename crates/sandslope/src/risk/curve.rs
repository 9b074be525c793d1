//! The failure risk against slope: the regime probabilities at each requested slope, with
//! the uncertainty used there and where it came from (docs/model.md §9).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::quadrature::regime_probabilities;
use super::uncertainty::{DefaultsUsed, UncertainTerrain, UsedUncertainty};
use super::RegimeProbabilities;
use crate::error::ParamError;
use crate::robot::Robot;
use crate::slope::Slope;

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

/// The risk of `robot` on `terrain` at each of `slopes_deg` (degrees, in (-90, 90);
/// negative slopes are evaluated as their magnitude, docs/model.md §8), one quadrature per
/// slope, in parallel. Errors name the key `slope_deg`.
pub fn risk_curve(
    robot: &Robot,
    terrain: &UncertainTerrain,
    slopes_deg: &[f64],
) -> Result<RiskCurve, ParamError> {
    let slopes = slopes_deg
        .iter()
        .map(|&d| Slope::from_signed_degrees(d).map_err(|e| e.renamed("slope_deg")))
        .collect::<Result<Vec<Slope>, ParamError>>()?;
    let points: Vec<RiskPoint> = slopes
        .par_iter()
        .zip(slopes_deg.par_iter())
        .map(|(&s, &slope_deg)| {
            let g = terrain.sample(s);
            let p = regime_probabilities(robot, s, &g.ground, g.uncertainty);
            RiskPoint {
                slope_deg,
                uncertainty: g.used(),
                p_fail: p.p_fail(),
                p_not_success: p.p_not_success(),
                probabilities: p,
            }
        })
        .collect();
    let defaults_used =
        points.iter().fold(DefaultsUsed::default(), |a, p| a.or(p.uncertainty.defaults_used()));
    Ok(RiskCurve { points, defaults_used })
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
        let c = risk_curve(&r, &t, &[0.0, -10.0, 20.0]).unwrap();
        assert_eq!(c.defaults_used, DefaultsUsed { k_n: true, k_s: true });
        for p in &c.points {
            assert_eq!((p.uncertainty.cv_n, p.uncertainty.cv_s), (0.1, 0.2));
            let s = Slope::from_signed_degrees(p.slope_deg).unwrap();
            assert_eq!(p.probabilities, failure_risk(&r, s, &t));
            assert_eq!(p.p_fail, p.probabilities.p_fail());
        }
        assert_eq!(c.points[1].slope_deg, -10.0);
        assert!(c.points[2].p_fail > c.points[0].p_fail);
        assert_eq!(risk_curve(&r, &t, &[91.0]).unwrap_err().key, "slope_deg");
    }
}
