//! Limits under uncertainty (docs/model.md §9): the safe-slope limit (the steepest slope
//! below a failure-risk threshold), the heaviest safe mass at a slope, and the payload
//! envelope (the heaviest safe mass at each of several slopes).
//!
//! Every limit is one search, `first_crossing`: a scan up a range and a bisection of the
//! first point where `p_fail >= max_risk`. The safe-slope limit decides each point with the
//! fast p_fail of [`super::failure_probability`] (used by `risk --solve slope`, the report, the Python
//! `safe_slope` and every design of `design`), and so do the mass searches; each reports the
//! reference quadrature's p_fail at the limit it returns.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::failure_probability::FailureProbability;
use super::quadrature::regime_probabilities;
use super::uncertainty::{DefaultsUsed, UncertainTerrain, UsedUncertainty};
use super::RegimeProbabilities;
use crate::error::ParamError;
use crate::robot::Robot;
use crate::slope::{SignedSlope, Slope};

/// The regime probabilities of `robot` at `slope` on an uncertain terrain (one reference
/// quadrature: all four regimes; for p_fail alone [`super::p_fail()`] is about a hundred times
/// cheaper).
pub fn failure_risk(robot: &Robot, slope: Slope, terrain: &UncertainTerrain) -> RegimeProbabilities {
    let (ground, u) = terrain.at(slope);
    regime_probabilities(robot, slope, &ground, u)
}

/// The result of a search for the largest value of a quantity (slope or mass) at which the
/// failure probability stays below a threshold, scanning up from the start of a range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SafeLimit {
    /// Already at the start of the range `p_fail >= max_risk`.
    NoneSafe {
        /// p_fail at the start of the range.
        p_fail: f64,
    },
    /// `p_fail < max_risk` from the start up to `value`, and it reaches the threshold just
    /// above `value` (within the search tolerance).
    Limit {
        /// The largest safe value found (degrees or kg).
        value: f64,
        /// p_fail at `value`.
        p_fail: f64,
    },
    /// A slope search only: `p_fail < max_risk` from the start up to the terrain's angle of
    /// repose, where p_fail jumps to 1 (the surface itself flows, docs/model.md §8): the limit
    /// is the repose, not a risk threshold crossed by the terrain's uncertainty.
    Repose {
        /// The terrain's angle of repose there, degrees (the slope search's answer).
        repose_deg: f64,
        /// p_fail just below the repose (within the search tolerance), where the search
        /// stopped.
        p_fail: f64,
    },
    /// `p_fail < max_risk` over the whole range searched.
    BeyondRange {
        /// The end of the range searched (degrees or kg).
        up_to: f64,
        /// p_fail there.
        p_fail: f64,
    },
}

impl SafeLimit {
    /// The largest safe value, if the search found a threshold crossing.
    pub fn value(&self) -> Option<f64> {
        match self {
            SafeLimit::Limit { value, .. } => Some(*value),
            SafeLimit::Repose { repose_deg, .. } => Some(*repose_deg),
            _ => None,
        }
    }

    /// `kind` as serialised: `"limit"`, `"repose"`, `"none_safe"` or `"beyond_range"`.
    pub fn kind(&self) -> &'static str {
        match self {
            SafeLimit::NoneSafe { .. } => "none_safe",
            SafeLimit::Limit { .. } => "limit",
            SafeLimit::Repose { .. } => "repose",
            SafeLimit::BeyondRange { .. } => "beyond_range",
        }
    }

    /// p_fail (or, for a success limit, P(not success)) where the search stopped.
    pub fn p_at_end(&self) -> f64 {
        match *self {
            SafeLimit::NoneSafe { p_fail }
            | SafeLimit::Limit { p_fail, .. }
            | SafeLimit::Repose { p_fail, .. }
            | SafeLimit::BeyondRange { p_fail, .. } => p_fail,
        }
    }

    /// For a mass search: the payload the heaviest safe total mass leaves over the robot's own
    /// mass, kg, if the search found a threshold crossing.
    pub fn payload_over(&self, robot_mass_kg: f64) -> Option<f64> {
        self.value().map(|m| m - robot_mass_kg)
    }
}

pub(crate) fn check_risk(max_risk: f64) -> Result<f64, ParamError> {
    if max_risk.is_finite() && max_risk > 0.0 && max_risk < 1.0 {
        Ok(max_risk)
    } else {
        Err(ParamError::new("max_risk", max_risk, "a probability strictly between 0 and 1"))
    }
}

/// What a search learns at one point: whether `p_fail >= max_risk` there, and p_fail itself
/// if deciding computed it (a bound may decide without it).
type Verdict = (bool, Option<f64>);

/// Scans the ascending points `scan` (`batch` at a time, in parallel when `batch > 1`) for the
/// first where `decide` says `p_fail >= max_risk`, then bisects between it and the point before
/// down to `tol`. Between scan points the crossing is assumed to be single. The result carries
/// p_fail at the point it returns: the one `decide` computed there, else `p_fail(point)`.
fn first_crossing(
    decide: &(dyn Fn(f64) -> Verdict + Sync),
    p_fail: &dyn Fn(f64) -> f64,
    scan: &[f64],
    tol: f64,
    batch: usize,
) -> SafeLimit {
    let value = |x: f64, known: Option<f64>| known.unwrap_or_else(|| p_fail(x));
    let (fails0, p0) = decide(scan[0]);
    if fails0 {
        return SafeLimit::NoneSafe { p_fail: value(scan[0], p0) };
    }
    let (mut lo, mut p_lo) = (scan[0], p0);
    for chunk in scan[1..].chunks(batch.max(1)) {
        let verdicts: Vec<Verdict> = if chunk.len() > 1 {
            chunk.par_iter().map(|&x| decide(x)).collect()
        } else {
            chunk.iter().map(|&x| decide(x)).collect()
        };
        for (&x, &(fails, p)) in chunk.iter().zip(&verdicts) {
            if fails {
                let mut hi = x;
                while hi - lo > tol {
                    let mid = 0.5 * (lo + hi);
                    let (fails_mid, p_mid) = decide(mid);
                    if fails_mid {
                        hi = mid;
                    } else {
                        (lo, p_lo) = (mid, p_mid);
                    }
                }
                return SafeLimit::Limit { value: lo, p_fail: value(lo, p_lo) };
            }
            (lo, p_lo) = (x, p);
        }
    }
    SafeLimit::BeyondRange { up_to: lo, p_fail: value(lo, p_lo) }
}

/// A search deciding by the reference p_fail itself: each point is one quadrature, so a few are
/// evaluated in parallel at a time (the tests' reference for the fast searches).
#[cfg(test)]
fn reference_crossing(
    p_fail: &(dyn Fn(f64) -> f64 + Sync),
    scan: &[f64],
    max_risk: f64,
    tol: f64,
) -> SafeLimit {
    let decide = |x: f64| {
        let p = p_fail(x);
        (p >= max_risk, Some(p))
    };
    first_crossing(&decide, p_fail, scan, tol, 2 * rayon::current_num_threads().max(1))
}

/// Slope scan step of [`safe_slope_limit`], degrees.
pub const SLOPE_SCAN_STEP_DEG: f64 = 0.5;
/// Final resolution of [`safe_slope_limit`], degrees.
pub const SLOPE_TOLERANCE_DEG: f64 = 1e-3;
/// Steepest slope [`safe_slope_limit`] considers, degrees.
pub const MAX_SCAN_SLOPE_DEG: f64 = 89.5;

/// The safe-slope limit: the steepest slope (degrees) such that `p_fail < max_risk` at every
/// slope from level up to it, with the terrain interpolated per slope.
///
/// Scans in steps of [`SLOPE_SCAN_STEP_DEG`] from 0 to [`MAX_SCAN_SLOPE_DEG`], then bisects
/// the first crossing to [`SLOPE_TOLERANCE_DEG`]. `max_risk` must be in (0, 1).
///
/// Each decision `p_fail >= max_risk` is the fast p_fail's ([`super::failure_probability`]: a closed-form
/// bound below the limit, Gauss-Kronrod near it), about a hundred times cheaper than the
/// reference quadrature and within 2e-9 of it, so the decisions and the limit are the
/// reference's (the tests run the reference search beside it). The p_fail reported at the
/// slope returned is the reference's, [`failure_risk`]: the number [`super::risk_curve`] gives
/// at that slope, so a limit printed beside a risk curve agrees with it.
pub fn safe_slope_limit(
    robot: &Robot,
    terrain: &UncertainTerrain,
    max_risk: f64,
) -> Result<SafeLimit, ParamError> {
    let max_risk = check_risk(max_risk)?;
    Ok(safe_slope_search(robot, terrain, max_risk, ReportedPFail::Reference))
}

/// Which p_fail a safe-slope search reports at the slope it returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ReportedPFail {
    /// The reference quadrature's ([`failure_risk`]), one more quadrature per search.
    Reference,
    /// The fast p_fail the search decided with, free when the search computed it there
    /// (`design`: 10^5 searches, each reporting p_fail within 2e-9 of the reference).
    Fast,
}

/// The search of [`safe_slope_limit`], `max_risk` checked by the caller, reporting p_fail as
/// `reported` says. Sequential: the fast decisions cost microseconds, below what a parallel
/// batch costs in scheduling and in points evaluated past the crossing, and `design` runs its
/// searches in parallel already.
pub(crate) fn safe_slope_search(
    robot: &Robot,
    terrain: &UncertainTerrain,
    max_risk: f64,
    reported: ReportedPFail,
) -> SafeLimit {
    let n = (MAX_SCAN_SLOPE_DEG / SLOPE_SCAN_STEP_DEG).round() as usize;
    let scan: Vec<f64> = (0..=n).map(|i| i as f64 * SLOPE_SCAN_STEP_DEG).collect();
    let decide = |deg: f64| -> Verdict {
        let Ok(s) = Slope::from_degrees(deg) else { return (true, Some(1.0)) };
        let (ground, u) = terrain.at(s);
        let (fails, p) = FailureProbability::new(robot, s, &ground, u).fails(max_risk);
        match reported {
            ReportedPFail::Fast => (fails, p),
            ReportedPFail::Reference => (fails, None),
        }
    };
    let p_fail = |deg: f64| {
        let Ok(s) = Slope::from_degrees(deg) else { return 1.0 };
        match reported {
            ReportedPFail::Fast => {
                let (ground, u) = terrain.at(s);
                FailureProbability::new(robot, s, &ground, u).p_fail()
            }
            ReportedPFail::Reference => failure_risk(robot, s, terrain).p_fail(),
        }
    };
    at_repose(first_crossing(&decide, &p_fail, &scan, SLOPE_TOLERANCE_DEG, 1), terrain)
}

/// Names a slope search's crossing [`SafeLimit::Repose`] when it lies at the terrain's angle
/// of repose (within two search tolerances below it: p_fail jumps to 1 there, so the bisection
/// ends just below it), else returns it as found.
fn at_repose(limit: SafeLimit, terrain: &UncertainTerrain) -> SafeLimit {
    let SafeLimit::Limit { value, p_fail } = limit else { return limit };
    let above = value + 2.0 * SLOPE_TOLERANCE_DEG;
    let repose = Slope::from_degrees(above).ok().and_then(|s| terrain.at(s).0.repose).map(|r| r.degrees());
    match repose {
        Some(r) if r > value && r <= above => SafeLimit::Repose { repose_deg: r, p_fail },
        _ => limit,
    }
}

/// The success limit: the steepest slope (degrees) such that P(not success) = P(sinkage,
/// slippage or metastable) < `max_risk` at every slope from level up to it, the terrain
/// interpolated per slope (docs/model.md §9). Where the safe-slope limit ([`safe_slope_limit`])
/// says up to where the robot does not fail, this says up to where it climbs: between the two
/// the robot is metastable (it progresses by less than the minimum step, s < s_min, and gets
/// stuck in its own trench, docs/model.md §5).
///
/// The same scan and bisection as [`safe_slope_limit`] ([`SLOPE_SCAN_STEP_DEG`],
/// [`SLOPE_TOLERANCE_DEG`]), each point decided by the reference quadrature (there is no fast
/// P(not success)), a few points in parallel at a time; a crossing at the angle of repose is
/// [`SafeLimit::Repose`]. `max_risk` must be in (0, 1).
pub fn success_slope_limit(
    robot: &Robot,
    terrain: &UncertainTerrain,
    max_risk: f64,
) -> Result<SafeLimit, ParamError> {
    let max_risk = check_risk(max_risk)?;
    let n = (MAX_SCAN_SLOPE_DEG / SLOPE_SCAN_STEP_DEG).round() as usize;
    let scan: Vec<f64> = (0..=n).map(|i| i as f64 * SLOPE_SCAN_STEP_DEG).collect();
    let p_not_success = |deg: f64| match Slope::from_degrees(deg) {
        Ok(s) => failure_risk(robot, s, terrain).p_not_success(),
        Err(_) => 1.0,
    };
    let decide = |deg: f64| -> Verdict {
        let p = p_not_success(deg);
        (p >= max_risk, Some(p))
    };
    let batch = 2 * rayon::current_num_threads().max(1);
    Ok(at_repose(first_crossing(&decide, &p_not_success, &scan, SLOPE_TOLERANCE_DEG, batch), terrain))
}

/// Growth factor between scanned masses in [`max_safe_mass`].
pub const MASS_SCAN_FACTOR: f64 = 1.05;
/// Heaviest mass [`max_safe_mass`] considers, as a multiple of the robot's own.
pub const MAX_MASS_FACTOR: f64 = 1000.0;

/// The heaviest total mass (kg) of `robot` (the same robot carrying a payload) such that
/// `p_fail < max_risk` at `slope` for every mass from the robot's own up to it.
///
/// Scans masses growing by [`MASS_SCAN_FACTOR`] up to [`MAX_MASS_FACTOR`] times the robot's
/// mass, then bisects the first crossing to a relative 1e-5. `max_risk` must be in (0, 1).
pub fn max_safe_mass(
    robot: &Robot,
    slope: Slope,
    terrain: &UncertainTerrain,
    max_risk: f64,
) -> Result<SafeLimit, ParamError> {
    let max_risk = check_risk(max_risk)?;
    let m0 = robot.mass();
    let scan = mass_scan(m0);
    let (ground, u) = terrain.at(slope);
    // Each decision by the fast p_fail (a closed form over the anchoring boundary, about a
    // hundred times cheaper than the reference quadrature, issue 26), as the safe-slope search
    // decides; the p_fail reported at the mass found is the reference quadrature's.
    let decide = |m: f64| -> Verdict {
        match robot.with_mass(m) {
            Ok(r) => (FailureProbability::new(&r, slope, &ground, u).fails(max_risk).0, None),
            Err(_) => (true, Some(1.0)),
        }
    };
    let p = |m: f64| robot.with_mass(m).map_or(1.0, |r| regime_probabilities(&r, slope, &ground, u).p_fail());
    Ok(first_crossing(&decide, &p, &scan, 1e-5 * m0, 1))
}

/// The masses [`max_safe_mass`] scans from the robot's own `m0`: growing by
/// [`MASS_SCAN_FACTOR`] up to [`MAX_MASS_FACTOR`] times `m0`, and no further than the
/// plausible robot's mass (docs/model.md §2), which is the last mass scanned.
fn mass_scan(m0: f64) -> Vec<f64> {
    let heaviest = crate::robot::Plausible::of("mass_kg").map_or(f64::INFINITY, |p| p.max);
    let n = (MAX_MASS_FACTOR.ln() / MASS_SCAN_FACTOR.ln()).ceil() as i32;
    let mut masses: Vec<f64> =
        (0..=n).map(|i| m0 * MASS_SCAN_FACTOR.powi(i)).take_while(|&m| m < heaviest).collect();
    if masses.len() <= n as usize {
        masses.push(heaviest.max(m0));
    }
    masses
}

/// The heaviest safe mass at one slope of a [`PayloadEnvelope`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PayloadPoint {
    /// Slope, degrees (as requested; a negative slope is evaluated as its magnitude).
    pub slope_deg: f64,
    /// The heaviest safe total mass, kg, when the search found a threshold crossing.
    pub max_mass_kg: Option<f64>,
    /// `max_mass_kg` minus the robot's own mass, kg.
    pub max_payload_kg: Option<f64>,
    /// What the search found (none safe, a limit, or safe over the whole range searched).
    pub limit: SafeLimit,
    /// The CVs used at this slope and where they came from.
    #[serde(flatten)]
    pub uncertainty: UsedUncertainty,
}

/// The payload envelope: the heaviest total mass with `p_fail < max_risk` at each slope, the
/// curve a team puts on a wall (docs/model.md §9).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PayloadEnvelope {
    /// The failure-risk threshold.
    pub max_risk: f64,
    /// The robot's own mass, kg.
    pub robot_mass_kg: f64,
    /// One point per requested slope, in the order given.
    pub points: Vec<PayloadPoint>,
    /// Whether default CVs were used at any of the slopes.
    pub defaults_used: DefaultsUsed,
}

/// The heaviest safe mass ([`max_safe_mass`]) at each of `slopes` (negative slopes are
/// evaluated as their magnitude, docs/model.md §8; each point reports its slope as given).
pub fn payload_envelope(
    robot: &Robot,
    terrain: &UncertainTerrain,
    slopes: &[SignedSlope],
    max_risk: f64,
) -> Result<PayloadEnvelope, ParamError> {
    check_risk(max_risk)?;
    let own = robot.mass();
    let points = slopes
        .par_iter()
        .map(|&signed| {
            let s = signed.felt();
            let limit = max_safe_mass(robot, s, terrain, max_risk)?;
            Ok(PayloadPoint {
                slope_deg: signed.degrees(),
                max_mass_kg: limit.value(),
                max_payload_kg: limit.payload_over(own),
                limit,
                uncertainty: terrain.sample(s).used(),
            })
        })
        .collect::<Result<Vec<_>, ParamError>>()?;
    let defaults_used =
        slopes.iter().fold(DefaultsUsed::default(), |a, &s| a.or(terrain.defaults_used_at(s.felt())));
    Ok(PayloadEnvelope { max_risk, robot_mass_kg: own, points, defaults_used })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::critical::{critical_shear_strength, StepTarget};
    use crate::model::{predict, tests::paper_robot};
    use crate::regime::Regime;
    use crate::risk::uncertainty::tests::table;
    use crate::terrain::Terrain;

    fn slope(d: f64) -> Slope {
        Slope::from_degrees(d).unwrap()
    }
    /// With no uncertainty p_fail is 0 or 1, so the safe-slope limit is where `predict` turns
    /// to failure: just below it the robot progresses, just above it fails.
    #[test]
    fn certain_terrain_safe_slope_is_the_deterministic_failure_slope() {
        let r = paper_robot();
        let t = UncertainTerrain::new(
            table(&[(0.0, 7e5, 2e6, None, None), (20.0, 7e5, 4e5, None, None)], None),
            Some(0.0),
            Some(0.0),
        )
        .unwrap();
        let SafeLimit::Limit { value, p_fail } = safe_slope_limit(&r, &t, 0.05).unwrap() else {
            panic!("no limit")
        };
        assert_eq!(p_fail, 0.0);
        let regime = |d: f64| {
            let s = slope(d);
            predict(&r, s, &t.terrain().at(s)).regime
        };
        assert!(!regime(value - 0.01).is_failure() && regime(value + 0.01).is_failure(), "limit {value}");
    }

    /// With no uncertainty P(not success) is 0 or 1, so the success limit is where `predict`
    /// stops giving success; on this sand the robot is metastable next, and fails only higher
    /// up, so the success limit lies below the safe-slope limit by a metastable band.
    #[test]
    fn certain_terrain_success_limit_is_where_predict_stops_succeeding() {
        let r = paper_robot();
        let t = UncertainTerrain::new(
            table(&[(0.0, 7e5, 2e6, None, None), (20.0, 7e5, 4e5, None, None)], None),
            Some(0.0),
            Some(0.0),
        )
        .unwrap();
        let SafeLimit::Limit { value, p_fail } = success_slope_limit(&r, &t, 0.05).unwrap() else {
            panic!("no limit")
        };
        assert_eq!(p_fail, 0.0);
        let regime = |d: f64| {
            let s = slope(d);
            predict(&r, s, &t.terrain().at(s)).regime
        };
        assert_eq!(regime(value - 0.01), Regime::Success, "limit {value}");
        assert_eq!(regime(value + 0.01), Regime::Metastable, "limit {value}");
        let safe = safe_slope_limit(&r, &t, 0.05).unwrap().value().unwrap();
        assert!(safe > value + 0.1, "safe {safe}, success {value}");
        assert!(matches!(success_slope_limit(&r, &t, 0.0), Err(ParamError { .. })));
    }

    /// Symmetric case: at 20 deg the median k_s sits exactly on the progress boundary and k_n
    /// is certain, so p_fail(20 deg) = 1/2; since the boundary rises with slope, the slope at
    /// which p_fail reaches 0.5 is 20 deg (and the heaviest mass keeping it below 0.5 at
    /// 20 deg is the robot's own).
    #[test]
    fn symmetric_case_puts_the_half_risk_limits_on_the_boundary() {
        let r = paper_robot();
        let k_crit = critical_shear_strength(&r, slope(20.0), 7e5, false, StepTarget::Progress).unwrap();
        let t = UncertainTerrain::new(Terrain::constant(7e5, k_crit).unwrap(), Some(0.0), Some(0.3)).unwrap();
        assert!((failure_risk(&r, slope(20.0), &t).p_fail() - 0.5).abs() < 1e-9);
        let limit = safe_slope_limit(&r, &t, 0.5).unwrap().value().unwrap();
        assert!((limit - 20.0).abs() < 2e-3, "{limit}");
        // Same boundary for a 1 kg robot: the heaviest mass below 0.5 risk is 1 kg.
        let heavy = r.with_mass(1.0).unwrap();
        let k_crit = critical_shear_strength(&heavy, slope(20.0), 7e5, false, StepTarget::Progress).unwrap();
        let t = UncertainTerrain::new(Terrain::constant(7e5, k_crit).unwrap(), Some(0.0), Some(0.3)).unwrap();
        let m = max_safe_mass(&r, slope(20.0), &t, 0.5).unwrap().value().unwrap();
        assert!((m - 1.0).abs() < 1e-4, "{m}");
        // A threshold of 1 is not a probability strictly between 0 and 1.
        assert!(matches!(safe_slope_limit(&r, &t, 1.0), Err(ParamError { .. })));
    }

    /// The reference search, written out: the scan and bisection of the safe-slope limit with
    /// every decision and the reported p_fail by the reference quadrature ([`failure_risk`]).
    fn reference_safe_slope(r: &Robot, t: &UncertainTerrain, max_risk: f64) -> SafeLimit {
        let p = |deg: f64| failure_risk(r, slope(deg), t).p_fail();
        if p(0.0) >= max_risk {
            return SafeLimit::NoneSafe { p_fail: p(0.0) };
        }
        let n = (MAX_SCAN_SLOPE_DEG / SLOPE_SCAN_STEP_DEG).round() as usize;
        let mut lo = 0.0;
        for i in 1..=n {
            let mut hi = i as f64 * SLOPE_SCAN_STEP_DEG;
            if p(hi) >= max_risk {
                while hi - lo > SLOPE_TOLERANCE_DEG {
                    let mid = 0.5 * (lo + hi);
                    if p(mid) >= max_risk {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                return SafeLimit::Limit { value: lo, p_fail: p(lo) };
            }
            lo = hi;
        }
        SafeLimit::BeyondRange { up_to: lo, p_fail: p(lo) }
    }

    /// (slope_deg, k_n, k_s) points with SDs of 10% (k_n) and 25% (k_s), repose 25 deg.
    fn weakening_sand(cv: Option<(f64, f64)>) -> UncertainTerrain {
        let pts = [(0.0, 7e5, 1.7e6), (10.0, 7e5, 1.56e6), (20.0, 6.5e5, 1.1e6), (24.0, 6e5, 9e5)];
        let t = table(&pts.map(|(d, k_n, k_s)| (d, k_n, k_s, Some(0.1 * k_n), Some(0.25 * k_s))), Some(25.0));
        let (n, s) = cv.unzip();
        UncertainTerrain::new(t, n, s).unwrap()
    }

    /// The safe-slope limit, decided by the fast p_fail, is the reference search's: the same
    /// slope bit for bit and the same reported p_fail, on robots and terrains unlike the
    /// paper's, ending in each of the three ways; `design`'s variant reports the fast p_fail
    /// within 2e-9 of it. (Each reference search is ~50 quadratures: a few seconds in a debug
    /// build, so the cases run in parallel.)
    #[test]
    fn safe_slope_limit_is_the_reference_search() {
        let rs = crate::risk::failure_probability::tests::robots();
        let loose =
            || table(&[(0.0, 3e5, 9e5, Some(4e4), Some(2e5)), (25.0, 2.8e5, 3e5, None, None)], Some(32.0));
        let strong = table(&[(0.0, 7e7, 1e12, None, None)], None);
        let cases = [
            (&rs[0], weakening_sand(None), 0.05),
            (&rs[1], weakening_sand(Some((0.2, 0.4))), 0.1),
            (&rs[2], weakening_sand(Some((0.3, 0.0))), 0.05),
            (&rs[3], weakening_sand(None), 0.01),
            (&rs[4], UncertainTerrain::new(loose(), None, None).unwrap(), 0.05),
            (&rs[0], UncertainTerrain::new(loose(), Some(0.3), Some(0.5)).unwrap(), 0.2),
            (&rs[1], UncertainTerrain::new(loose(), None, None).unwrap(), 0.05),
            (&rs[0], UncertainTerrain::new(strong, Some(0.05), Some(0.1)).unwrap(), 0.05),
        ];
        let kinds: Vec<&str> = cases
            .par_iter()
            .map(|(r, t, max_risk)| {
                let want = at_repose(reference_safe_slope(r, t, *max_risk), t);
                assert_eq!(safe_slope_limit(r, t, *max_risk).unwrap(), want);
                let fast = safe_slope_search(r, t, *max_risk, ReportedPFail::Fast);
                match (want, fast) {
                    (
                        SafeLimit::Limit { value: a, p_fail: pa },
                        SafeLimit::Limit { value: b, p_fail: pb },
                    ) => {
                        assert_eq!(a, b);
                        assert!((pa - pb).abs() < 2e-9, "{pa} vs {pb}");
                        // Below the threshold at the limit, at or above it just over.
                        assert!(pa < *max_risk);
                        let over = failure_risk(r, slope(a + 2.0 * SLOPE_TOLERANCE_DEG), t).p_fail();
                        assert!(over >= *max_risk, "{a}: {over}");
                        "limit"
                    }
                    (
                        SafeLimit::Repose { repose_deg: a, p_fail: pa },
                        SafeLimit::Repose { repose_deg: b, p_fail: pb },
                    ) => {
                        assert_eq!(a, b);
                        assert!((pa - pb).abs() < 2e-9 && pa < *max_risk, "{pa} vs {pb}");
                        "repose"
                    }
                    (SafeLimit::NoneSafe { p_fail: pa }, SafeLimit::NoneSafe { p_fail: pb }) => {
                        assert!((pa - pb).abs() < 2e-9 && pa >= *max_risk, "{pa} vs {pb}");
                        "none_safe"
                    }
                    (
                        SafeLimit::BeyondRange { up_to: a, p_fail: pa },
                        SafeLimit::BeyondRange { up_to: b, p_fail: pb },
                    ) => {
                        assert_eq!(a, b);
                        assert!((pa - pb).abs() < 2e-9 && pa < *max_risk, "{pa} vs {pb}");
                        "beyond_range"
                    }
                    other => panic!("{other:?}"),
                }
            })
            .collect();
        for kind in ["limit", "none_safe", "beyond_range"] {
            assert!(kinds.contains(&kind), "no case ends in {kind}: {kinds:?}");
        }
    }

    #[test]
    fn repose_caps_the_safe_slope_and_mass_search_reports_none_safe() {
        let r = paper_robot();
        let t =
            UncertainTerrain::new(table(&[(0.0, 7e5, 1e8, None, None)], Some(25.0)), Some(0.1), Some(0.1))
                .unwrap();
        // Strong sand: p_fail stays near 0 up to the repose, where it jumps to 1; the limit is
        // named the repose (kind "repose", the repose itself), not a threshold at 24.999 deg.
        let SafeLimit::Repose { repose_deg, p_fail } = safe_slope_limit(&r, &t, 0.05).unwrap() else {
            panic!("not the repose")
        };
        assert_eq!(repose_deg, 25.0);
        assert!(p_fail < 0.05, "{p_fail}");
        let json = serde_json::to_value(SafeLimit::Repose { repose_deg, p_fail }).unwrap();
        assert_eq!(json["kind"], "repose");
        assert_eq!(safe_slope_limit(&r, &t, 0.05).unwrap().value(), Some(25.0));
        assert!(matches!(max_safe_mass(&r, slope(26.0), &t, 0.05).unwrap(), SafeLimit::NoneSafe { .. }));
    }

    /// The envelope is the heaviest safe mass at each slope, and it does not grow with slope
    /// on a terrain that weakens with slope.
    #[test]
    fn payload_envelope_is_max_safe_mass_per_slope() {
        let r = paper_robot();
        let t = UncertainTerrain::new(
            table(&[(0.0, 7e5, 2e6, None, None), (24.0, 7e5, 8e5, None, None)], Some(25.0)),
            Some(0.1),
            None,
        )
        .unwrap();
        let slopes: Vec<SignedSlope> =
            [0.0, 10.0, 20.0].iter().map(|&d| SignedSlope::from_degrees(d).unwrap()).collect();
        let env = payload_envelope(&r, &t, &slopes, 0.05).unwrap();
        assert_eq!(env.points.len(), 3);
        assert!(env.defaults_used.k_s && !env.defaults_used.k_n);
        let mut last = f64::INFINITY;
        for p in &env.points {
            let m = max_safe_mass(&r, slope(p.slope_deg), &t, 0.05).unwrap();
            assert_eq!(p.limit, m);
            let v = p.max_mass_kg.unwrap();
            assert!((p.max_payload_kg.unwrap() - (v - 0.35)).abs() < 1e-12);
            assert!(v <= last + 1e-9, "{v} > {last}");
            last = v;
        }
    }

    /// The mass search decides with the fast p_fail (issue 26); the reference search, deciding
    /// every mass by quadrature, finds the same heaviest safe mass (to the search's 1e-5
    /// relative tolerance) on a terrain whose k_s falls with slope, at slopes from success to
    /// none safe, and both report the reference p_fail there.
    #[test]
    fn fast_mass_search_finds_the_reference_search_s_mass() {
        let r = paper_robot();
        let t = UncertainTerrain::new(
            table(&[(0.0, 7e5, 2e6, None, None), (24.0, 6e5, 9e5, None, None)], None),
            Some(0.1),
            Some(0.2),
        )
        .unwrap();
        let mut kinds = std::collections::BTreeSet::new();
        for deg in [0.0, 6.0, 12.0, 18.0, 24.0] {
            let s = slope(deg);
            let fast = max_safe_mass(&r, s, &t, 0.05).unwrap();
            let (ground, u) = t.at(s);
            let m0 = r.mass();
            let scan = mass_scan(m0);
            let p = |m: f64| r.with_mass(m).map_or(1.0, |r| regime_probabilities(&r, s, &ground, u).p_fail());
            let reference = reference_crossing(&p, &scan, 0.05, 1e-5 * m0);
            match (fast, reference) {
                (SafeLimit::Limit { value: a, p_fail: pa }, SafeLimit::Limit { value: b, p_fail: pb }) => {
                    assert!((a - b).abs() <= 2e-5 * m0, "{deg} deg: {a} vs {b}");
                    assert!((pa - p(a)).abs() < 1e-15 && pb < 0.05 && pa < 0.05, "{deg} deg: {pa} {pb}");
                    kinds.insert("limit");
                }
                (f, r) => {
                    assert_eq!(std::mem::discriminant(&f), std::mem::discriminant(&r), "{deg} deg");
                    kinds.insert("other");
                }
            }
        }
        assert!(kinds.contains("limit"), "{kinds:?}");
    }
}
