//! Probability of each regime when the terrain is uncertain (MODEL.md section 9).
//!
//! k_n and k_s at a slope are independent log-normal variables whose medians are the table
//! values and whose coefficients of variation are `cv_n`, `cv_s`:
//! `ln k ~ Normal(ln k_median, sigma^2)`, `sigma = sqrt(ln(1 + cv^2))`.
//!
//! The probabilities are computed by deterministic quadrature, not sampling, so they are
//! exactly reproducible:
//! - sinkage happens iff `k_n <= k_n*` (the sinkage threshold), so `P(sinkage)` is one
//!   normal CDF;
//! - for a given `k_n` above it, the regime depends on k_s only through the two critical
//!   strengths of [`crate::critical`] (the step is monotone in k_s), so the conditional
//!   probabilities are normal CDFs too;
//! - what is left is one integral over `z = (ln k_n - mu_n) / sigma_n`, done by adaptive
//!   Simpson quadrature on `[z*, 8.5]` (the normal tail beyond 8.5 is below 1e-16) to an
//!   absolute tolerance of 1e-9, starting from 64 panels so that a sharp feature (small
//!   `cv_s`) cannot slip between the first samples.
//!
//! Quadrature rather than Monte Carlo because the problem is one-dimensional after the
//! closed-form k_s integral: a 1e-9 tolerance costs about a millisecond, while sampling to
//! 1e-3 absolute would need about a million model runs per probability (the tests check the
//! quadrature against a seeded Monte Carlo).
//!
//! On top of that: [`UncertainTerrain`] (the medians and coefficients of variation at any
//! slope, from a terrain table's `k_n_sd`/`k_s_sd` interpolated like the values, or given),
//! [`failure_risk`], the safe-slope limit [`safe_slope_limit`] (steepest slope below a
//! failure-risk threshold), the heaviest safe robot at a slope [`max_safe_mass`], and
//! [`failure_risk_map`] over a `(k_n, k_s)` grid.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::critical::{critical_shear_strength, StepTarget};
use crate::error::{non_negative, ParamError};
use crate::model::sinkage_threshold_k_n;
use crate::phase::Axis;
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::{Ground, Terrain};

/// Coefficients of variation of k_n and k_s (standard deviation over median value).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Uncertainty {
    cv_n: f64,
    cv_s: f64,
}

impl Uncertainty {
    /// No uncertainty: the regime is certain.
    pub const NONE: Uncertainty = Uncertainty { cv_n: 0.0, cv_s: 0.0 };

    /// Coefficients of variation, each finite and >= 0.
    pub fn new(cv_n: f64, cv_s: f64) -> Result<Uncertainty, ParamError> {
        Ok(Uncertainty { cv_n: non_negative("cv_n", cv_n)?, cv_s: non_negative("cv_s", cv_s)? })
    }

    /// From a table's standard deviations: `cv = sd / value` (0 where the value is 0).
    pub fn from_sd(ground: &Ground, k_n_sd: f64, k_s_sd: f64) -> Result<Uncertainty, ParamError> {
        let cv = |sd: f64, k: f64| if k > 0.0 { sd / k } else { 0.0 };
        Uncertainty::new(cv(k_n_sd, ground.k_n), cv(k_s_sd, ground.k_s))
    }

    /// Coefficient of variation of k_n.
    pub fn cv_n(self) -> f64 {
        self.cv_n
    }
    /// Coefficient of variation of k_s.
    pub fn cv_s(self) -> f64 {
        self.cv_s
    }
    /// Log-space standard deviation of k_n, `sqrt(ln(1 + cv_n^2))`.
    pub fn sigma_n(self) -> f64 {
        (1.0 + self.cv_n * self.cv_n).ln().sqrt()
    }
    /// Log-space standard deviation of k_s, `sqrt(ln(1 + cv_s^2))`.
    pub fn sigma_s(self) -> f64 {
        (1.0 + self.cv_s * self.cv_s).ln().sqrt()
    }
}

/// Probability of each regime; they sum to 1.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct RegimeProbabilities {
    /// P(success).
    pub success: f64,
    /// P(metastable).
    pub metastable: f64,
    /// P(slippage).
    pub slippage: f64,
    /// P(sinkage).
    pub sinkage: f64,
}

impl RegimeProbabilities {
    /// Probability of failure, `P(sinkage or slippage)`.
    pub fn p_fail(&self) -> f64 {
        self.sinkage + self.slippage
    }
    /// `P(regime != success)`.
    pub fn p_not_success(&self) -> f64 {
        1.0 - self.success
    }
}

/// Standard normal CDF.
fn phi(z: f64) -> f64 {
    0.5 * statrs::function::erf::erfc(-z / std::f64::consts::SQRT_2)
}

/// Standard normal density.
fn density(z: f64) -> f64 {
    (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

/// `P(ln k < ln threshold)` for `ln k ~ Normal(mu, sigma^2)`; a step function when sigma = 0.
fn prob_below(threshold: f64, mu: f64, sigma: f64) -> f64 {
    if threshold.is_infinite() {
        return if threshold > 0.0 { 1.0 } else { 0.0 };
    }
    if threshold <= 0.0 {
        return 0.0;
    }
    if sigma == 0.0 {
        return if threshold.ln() > mu { 1.0 } else { 0.0 };
    }
    phi((threshold.ln() - mu) / sigma)
}

const Z_MAX: f64 = 8.5;
const TOLERANCE: f64 = 1e-9;

/// The regime probabilities of `robot` at `slope` on ground whose medians are `median`.
pub fn regime_probabilities(
    robot: &Robot,
    slope: Slope,
    median: &Ground,
    uncertainty: Uncertainty,
) -> RegimeProbabilities {
    let sigma_n = uncertainty.sigma_n();
    let sigma_s = uncertainty.sigma_s();
    let mu_n = median.k_n.ln();
    let mu_s = median.k_s.ln();
    let k_n_star = sinkage_threshold_k_n(robot, slope);
    let p_sink = if median.k_n <= 0.0 {
        1.0
    } else if sigma_n == 0.0 {
        if median.k_n <= k_n_star {
            1.0
        } else {
            0.0
        }
    } else {
        // P(k_n <= k_n*), k_n* may be infinite (h = 2R: every leg sinks).
        prob_below(k_n_star, mu_n, sigma_n)
    };
    if median.beyond_repose(slope) {
        return RegimeProbabilities { sinkage: p_sink, slippage: 1.0 - p_sink, ..Default::default() };
    }
    // Conditional on k_n (not sunk): (P(slippage | k_n), P(not success | k_n)).
    let conditional = |k_n: f64| -> [f64; 2] {
        let below = |target| match critical_shear_strength(robot, slope, k_n, false, target) {
            Ok(k_crit) if median.k_s > 0.0 => prob_below(k_crit, mu_s, sigma_s),
            _ => 1.0,
        };
        [below(StepTarget::Progress), below(StepTarget::Robust)]
    };
    let [slip, not_success] = if p_sink >= 1.0 {
        [0.0, 0.0]
    } else if sigma_n == 0.0 {
        conditional(median.k_n)
    } else {
        let z_star = ((k_n_star.ln() - mu_n) / sigma_n).max(-Z_MAX);
        let f = |z: f64| {
            let [a, b] = conditional((mu_n + sigma_n * z).exp());
            let w = density(z);
            [w * a, w * b]
        };
        // Integrals of density * conditional over k_n > k_n*, which is the joint probability.
        if z_star >= Z_MAX {
            [0.0, 0.0]
        } else {
            integrate(&f, z_star, Z_MAX)
        }
    };
    let not_sunk = 1.0 - p_sink;
    let slippage = slip.clamp(0.0, not_sunk);
    let not_success = not_success.clamp(slippage, not_sunk);
    RegimeProbabilities {
        sinkage: p_sink,
        slippage,
        metastable: not_success - slippage,
        success: not_sunk - not_success,
    }
}

/// A terrain table read as uncertain: at each slope, log-normal k_n and k_s whose medians are
/// the interpolated table values (MODEL.md section 9).
///
/// Each coefficient of variation is either given (the same at every slope) or taken from the
/// table: the standard deviation interpolated like the value, divided by the value.
#[derive(Debug, Clone, PartialEq)]
pub struct UncertainTerrain {
    terrain: Terrain,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
}

impl UncertainTerrain {
    /// `terrain` with coefficients of variation `cv_n`, `cv_s` (each finite and >= 0), or,
    /// where `None`, from the table's `k_n_sd` / `k_s_sd`, which must then be given at every
    /// point.
    pub fn new(
        terrain: Terrain,
        cv_n: Option<f64>,
        cv_s: Option<f64>,
    ) -> Result<UncertainTerrain, ParamError> {
        if let Some(cv) = cv_n {
            non_negative("cv_n", cv)?;
        }
        if let Some(cv) = cv_s {
            non_negative("cv_s", cv)?;
        }
        for (i, p) in terrain.points().iter().enumerate() {
            for (given, sd, key, flag) in
                [(cv_n, p.k_n_sd, "k_n_sd", "cv_n"), (cv_s, p.k_s_sd, "k_s_sd", "cv_s")]
            {
                if given.is_none() && sd.is_none() {
                    return Err(ParamError::new(
                        format!("points[{i}].{key}"),
                        f64::NAN,
                        format!("given at every point (or give a coefficient of variation {flag})"),
                    ));
                }
            }
        }
        Ok(UncertainTerrain { terrain, cv_n, cv_s })
    }

    /// The underlying table.
    pub fn terrain(&self) -> &Terrain {
        &self.terrain
    }

    /// The median ground and its uncertainty at `slope`.
    pub fn at(&self, slope: Slope) -> (Ground, Uncertainty) {
        let sample = self.terrain.sample(slope);
        let cv = |given: Option<f64>, sd: Option<f64>, k: f64| match (given, sd) {
            (Some(cv), _) => cv,
            (None, Some(sd)) if k > 0.0 && (sd / k).is_finite() => sd / k,
            // A value extrapolated down to 0: the median is 0, the spread is irrelevant.
            _ => 0.0,
        };
        let ground = sample.ground;
        let u = Uncertainty {
            cv_n: cv(self.cv_n, sample.k_n_sd, ground.k_n),
            cv_s: cv(self.cv_s, sample.k_s_sd, ground.k_s),
        };
        (ground, u)
    }
}

/// The regime probabilities of `robot` at `slope` on an uncertain terrain.
pub fn failure_risk(robot: &Robot, slope: Slope, terrain: &UncertainTerrain) -> RegimeProbabilities {
    let (ground, u) = terrain.at(slope);
    regime_probabilities(robot, slope, &ground, u)
}

/// The result of a search for the largest value of a quantity (slope or mass) at which the
/// failure probability stays below a threshold, scanning up from the start of a range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
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
            _ => None,
        }
    }
}

fn check_risk(max_risk: f64) -> Result<f64, ParamError> {
    if max_risk.is_finite() && max_risk > 0.0 && max_risk < 1.0 {
        Ok(max_risk)
    } else {
        Err(ParamError::new("max_risk", max_risk, "a probability strictly between 0 and 1"))
    }
}

/// Scans `p_fail` at the ascending points `scan` (a few in parallel at a time) for the first
/// at or above `max_risk`, then bisects between it and the point before down to `tol`.
/// Between scan points the crossing is assumed to be single.
fn first_crossing(p_fail: &(dyn Fn(f64) -> f64 + Sync), scan: &[f64], max_risk: f64, tol: f64) -> SafeLimit {
    let p0 = p_fail(scan[0]);
    if p0 >= max_risk {
        return SafeLimit::NoneSafe { p_fail: p0 };
    }
    let (mut lo, mut p_lo) = (scan[0], p0);
    let batch = 2 * rayon::current_num_threads().max(1);
    for chunk in scan[1..].chunks(batch) {
        let ps: Vec<f64> = chunk.par_iter().map(|&x| p_fail(x)).collect();
        for (&x, &p) in chunk.iter().zip(&ps) {
            if p >= max_risk {
                let mut hi = x;
                while hi - lo > tol {
                    let mid = 0.5 * (lo + hi);
                    let p_mid = p_fail(mid);
                    if p_mid >= max_risk {
                        hi = mid;
                    } else {
                        (lo, p_lo) = (mid, p_mid);
                    }
                }
                return SafeLimit::Limit { value: lo, p_fail: p_lo };
            }
            (lo, p_lo) = (x, p);
        }
    }
    SafeLimit::BeyondRange { up_to: lo, p_fail: p_lo }
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
pub fn safe_slope_limit(
    robot: &Robot,
    terrain: &UncertainTerrain,
    max_risk: f64,
) -> Result<SafeLimit, ParamError> {
    let max_risk = check_risk(max_risk)?;
    let n = (MAX_SCAN_SLOPE_DEG / SLOPE_SCAN_STEP_DEG).round() as usize;
    let scan: Vec<f64> = (0..=n).map(|i| i as f64 * SLOPE_SCAN_STEP_DEG).collect();
    let p = |deg: f64| match Slope::from_degrees(deg) {
        Ok(s) => failure_risk(robot, s, terrain).p_fail(),
        Err(_) => 1.0,
    };
    Ok(first_crossing(&p, &scan, max_risk, SLOPE_TOLERANCE_DEG))
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
    let n = (MAX_MASS_FACTOR.ln() / MASS_SCAN_FACTOR.ln()).ceil() as i32;
    let scan: Vec<f64> = (0..=n).map(|i| m0 * MASS_SCAN_FACTOR.powi(i)).collect();
    let (ground, u) = terrain.at(slope);
    let p = |m: f64| robot.with_mass(m).map_or(1.0, |r| regime_probabilities(&r, slope, &ground, u).p_fail());
    Ok(first_crossing(&p, &scan, max_risk, 1e-5 * m0))
}

/// The regime probabilities at every cell of a `(k_n, k_s)` grid of medians, all with the
/// same uncertainty, row-major (one row per k_s value) like [`crate::phase::PhaseMap`].
///
/// `cell_done` is called once per finished cell, from any thread (for progress bars).
pub fn failure_risk_map(
    robot: &Robot,
    slope: Slope,
    repose: Option<Slope>,
    k_n_axis: &Axis,
    k_s_axis: &Axis,
    uncertainty: Uncertainty,
    cell_done: &(dyn Fn() + Sync),
) -> Vec<RegimeProbabilities> {
    let k_n = k_n_axis.values();
    let k_s = k_s_axis.values();
    (0..k_n.len() * k_s.len())
        .into_par_iter()
        .map(|c| {
            let ground = Ground { k_n: k_n[c % k_n.len()], k_s: k_s[c / k_n.len()], repose };
            let p = regime_probabilities(robot, slope, &ground, uncertainty);
            cell_done();
            p
        })
        .collect()
}

/// Adaptive Simpson quadrature of a 2-vector function on `[a, b]`, from 64 initial panels.
fn integrate(f: &dyn Fn(f64) -> [f64; 2], a: f64, b: f64) -> [f64; 2] {
    const PANELS: usize = 64;
    let h = (b - a) / PANELS as f64;
    let mut total = [0.0; 2];
    let mut fa = f(a);
    for i in 0..PANELS {
        let (x0, x1) = (a + i as f64 * h, if i + 1 == PANELS { b } else { a + (i + 1) as f64 * h });
        let xm = 0.5 * (x0 + x1);
        let (fm, fb) = (f(xm), f(x1));
        let whole = simpson(x0, x1, fa, fm, fb);
        let part = adaptive(f, x0, x1, fa, fm, fb, whole, TOLERANCE / PANELS as f64, 30);
        total[0] += part[0];
        total[1] += part[1];
        fa = fb;
    }
    total
}

fn simpson(a: f64, b: f64, fa: [f64; 2], fm: [f64; 2], fb: [f64; 2]) -> [f64; 2] {
    let w = (b - a) / 6.0;
    [w * (fa[0] + 4.0 * fm[0] + fb[0]), w * (fa[1] + 4.0 * fm[1] + fb[1])]
}

#[allow(clippy::too_many_arguments)]
fn adaptive(
    f: &dyn Fn(f64) -> [f64; 2],
    a: f64,
    b: f64,
    fa: [f64; 2],
    fm: [f64; 2],
    fb: [f64; 2],
    whole: [f64; 2],
    tol: f64,
    depth: u32,
) -> [f64; 2] {
    let m = 0.5 * (a + b);
    let (lm, rm) = (f(0.5 * (a + m)), f(0.5 * (m + b)));
    let left = simpson(a, m, fa, lm, fm);
    let right = simpson(m, b, fm, rm, fb);
    let err = (left[0] + right[0] - whole[0]).abs().max((left[1] + right[1] - whole[1]).abs());
    if depth == 0 || err <= 15.0 * tol {
        // Richardson extrapolation of the two Simpson estimates.
        return [
            left[0] + right[0] + (left[0] + right[0] - whole[0]) / 15.0,
            left[1] + right[1] + (left[1] + right[1] - whole[1]) / 15.0,
        ];
    }
    let l = adaptive(f, a, m, fa, lm, fm, left, tol / 2.0, depth - 1);
    let r = adaptive(f, m, b, fm, rm, fb, right, tol / 2.0, depth - 1);
    [l[0] + r[0], l[1] + r[1]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{predict, tests::paper_robot};
    use crate::regime::Regime;

    fn slope(d: f64) -> Slope {
        Slope::from_degrees(d).unwrap()
    }

    #[test]
    fn no_uncertainty_gives_the_certain_regime() {
        let r = paper_robot();
        for (deg, k_n, k_s) in [(0.0, 7e5, 2e6), (20.0, 7e5, 1e6), (20.0, 7e5, 2e5), (10.0, 3e4, 2e6)] {
            let g = Ground::new(k_n, k_s).unwrap();
            let p = regime_probabilities(&r, slope(deg), &g, Uncertainty::NONE);
            let regime = predict(&r, slope(deg), &g).regime;
            let got = [p.sinkage, p.slippage, p.metastable, p.success];
            for (i, reg) in Regime::ALL.iter().enumerate() {
                assert_eq!(got[i], if *reg == regime { 1.0 } else { 0.0 }, "{deg} {k_n} {k_s}: {p:?}");
            }
        }
    }

    #[test]
    fn median_on_a_boundary_gives_one_half() {
        // k_s median exactly at the progress boundary, k_n certain: P(slippage) = P(k_s < median) = 0.5.
        let r = paper_robot();
        let s = slope(20.0);
        let k_crit = critical_shear_strength(&r, s, 7e5, false, StepTarget::Progress).unwrap();
        let p = regime_probabilities(
            &r,
            s,
            &Ground::new(7e5, k_crit).unwrap(),
            Uncertainty::new(0.0, 0.3).unwrap(),
        );
        assert!((p.slippage - 0.5).abs() < 1e-9, "{p:?}");
        // And k_n median exactly at the sinkage threshold: P(sinkage) = 0.5.
        let k_star = sinkage_threshold_k_n(&r, s);
        let p = regime_probabilities(
            &r,
            s,
            &Ground::new(k_star, 1e7).unwrap(),
            Uncertainty::new(0.2, 0.0).unwrap(),
        );
        assert!((p.sinkage - 0.5).abs() < 1e-9, "{p:?}");
        assert!((p.sinkage + p.slippage + p.metastable + p.success - 1.0).abs() < 1e-9);
    }

    #[test]
    fn beyond_repose_everything_not_sunk_slips() {
        let r = paper_robot();
        let g = Ground::new(7e5, 1e8).unwrap().with_repose(Some(slope(25.0)));
        let p = regime_probabilities(&r, slope(26.0), &g, Uncertainty::new(0.1, 0.1).unwrap());
        assert!((p.slippage - 1.0).abs() < 1e-12 && p.success == 0.0);
    }

    #[test]
    fn probabilities_sum_to_one_and_p_fail_grows_with_slope() {
        let r = paper_robot();
        let g = Ground::new(7e5, 1e6).unwrap();
        let u = Uncertainty::new(0.3, 0.5).unwrap();
        let mut last = 0.0;
        for deg in [0.0, 10.0, 20.0, 30.0, 40.0] {
            let p = regime_probabilities(&r, slope(deg), &g, u);
            assert!((p.sinkage + p.slippage + p.metastable + p.success - 1.0).abs() < 1e-7, "{p:?}");
            assert!(p.p_fail() >= last - 1e-9, "{deg}: {} < {last}", p.p_fail());
            last = p.p_fail();
        }
    }

    /// (slope_deg, k_n, k_s, k_n_sd, k_s_sd).
    type Point = (f64, f64, f64, Option<f64>, Option<f64>);

    fn table(points: &[Point], repose: Option<f64>) -> Terrain {
        Terrain::new(crate::terrain::TerrainSpec {
            name: None,
            repose_deg: repose,
            points: points
                .iter()
                .map(|&(slope_deg, k_n, k_s, k_n_sd, k_s_sd)| crate::TerrainPoint {
                    slope_deg,
                    k_n,
                    k_s,
                    k_n_sd,
                    k_s_sd,
                })
                .collect(),
        })
        .unwrap()
    }

    #[test]
    fn coefficients_of_variation_come_from_interpolated_sds_or_flags() {
        // 0 deg: k_s = 2e6 +- 2e5; 20 deg: 1e6 +- 3e5. At 10 deg: 1.5e6 +- 2.5e5, cv = 1/6.
        let t = table(&[(0.0, 7e5, 2e6, Some(7e4), Some(2e5)), (20.0, 7e5, 1e6, Some(7e4), Some(3e5))], None);
        let u = UncertainTerrain::new(t.clone(), None, None).unwrap();
        let (g, cv) = u.at(slope(10.0));
        assert!((g.k_s - 1.5e6).abs() < 1e-6);
        assert!((cv.cv_s() - 1.0 / 6.0).abs() < 1e-12 && (cv.cv_n() - 0.1).abs() < 1e-12);
        // A flag replaces the table's spread for its variable only.
        let (_, cv) = UncertainTerrain::new(t, Some(0.25), None).unwrap().at(slope(10.0));
        assert!((cv.cv_n() - 0.25).abs() < 1e-15 && (cv.cv_s() - 1.0 / 6.0).abs() < 1e-12);
        // Without sds and without flags: an error naming the key.
        let bare = Terrain::constant(7e5, 2e6).unwrap();
        let e = UncertainTerrain::new(bare.clone(), Some(0.1), None).unwrap_err();
        assert_eq!(e.key, "points[0].k_s_sd");
        assert!(e.to_string().contains("cv_s"), "{e}");
        assert_eq!(UncertainTerrain::new(bare, Some(-0.1), Some(0.1)).unwrap_err().key, "cv_n");
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
            predict(&r, s, &t.terrain().sample(s).ground).regime
        };
        assert!(!regime(value - 0.01).is_failure() && regime(value + 0.01).is_failure(), "limit {value}");
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

    #[test]
    fn repose_caps_the_safe_slope_and_mass_search_reports_none_safe() {
        let r = paper_robot();
        let t =
            UncertainTerrain::new(table(&[(0.0, 7e5, 1e8, None, None)], Some(25.0)), Some(0.1), Some(0.1))
                .unwrap();
        let limit = safe_slope_limit(&r, &t, 0.05).unwrap().value().unwrap();
        assert!(limit < 25.0 && limit > 25.0 - 2.0 * SLOPE_TOLERANCE_DEG, "{limit}");
        assert!(matches!(max_safe_mass(&r, slope(26.0), &t, 0.05).unwrap(), SafeLimit::NoneSafe { .. }));
    }

    #[test]
    fn risk_map_cells_are_the_regime_probabilities() {
        let r = paper_robot();
        let kn = Axis::new("k_n", 3e4, 3e6, 4, crate::AxisScale::Log).unwrap();
        let ks = Axis::new("k_s", 1e5, 1e7, 3, crate::AxisScale::Log).unwrap();
        let u = Uncertainty::new(0.2, 0.4).unwrap();
        let map = failure_risk_map(&r, slope(20.0), None, &kn, &ks, u, &|| {});
        assert_eq!(map.len(), 12);
        let g = Ground::new(kn.value(2), ks.value(1)).unwrap();
        assert_eq!(map[4 + 2], regime_probabilities(&r, slope(20.0), &g, u));
    }

    /// Seeded Monte Carlo: sample ln k_n and ln k_s from their normals, run `predict`, count.
    /// 400 000 samples give a standard error of at most 7.9e-4 per probability; the
    /// quadrature must agree within 5 of them (4e-3).
    #[test]
    fn quadrature_agrees_with_a_large_monte_carlo() {
        use rand::{rngs::StdRng, SeedableRng};
        use rand_distr::{Distribution, Normal};
        let r = paper_robot();
        let s = slope(20.0);
        // Medians near both boundaries, wide spreads: all four regimes are likely.
        let k_n = 1.5 * sinkage_threshold_k_n(&r, s);
        let k0 = critical_shear_strength(&r, s, k_n, false, StepTarget::Progress).unwrap();
        let k1 = critical_shear_strength(&r, s, k_n, false, StepTarget::Robust).unwrap();
        let median = Ground::new(k_n, (k0 * k1).sqrt()).unwrap();
        let u = Uncertainty::new(0.6, 1.0).unwrap();
        let q = regime_probabilities(&r, s, &median, u);
        let mut rng = StdRng::seed_from_u64(20_260_306);
        let zn = Normal::new(median.k_n.ln(), u.sigma_n()).unwrap();
        let zs = Normal::new(median.k_s.ln(), u.sigma_s()).unwrap();
        let n = 400_000;
        let mut counts = [0usize; 4];
        for _ in 0..n {
            let g = Ground::new(zn.sample(&mut rng).exp(), zs.sample(&mut rng).exp()).unwrap();
            counts[predict(&r, s, &g).regime as usize] += 1;
        }
        let mc: Vec<f64> = counts.iter().map(|&c| c as f64 / n as f64).collect();
        let quad = [q.sinkage, q.slippage, q.metastable, q.success];
        for (k, reg) in Regime::ALL.iter().enumerate() {
            assert!(quad[k] > 0.05, "{reg} too rare for a useful check: {q:?}");
            assert!((mc[k] - quad[k]).abs() < 4e-3, "{reg}: Monte Carlo {} vs quadrature {}", mc[k], quad[k]);
        }
    }
}
