//! The live decision of `drive --stop-on-risk` (docs/model.md §19, "Live, during `drive`"): the
//! stances' estimates pooled, and the risk that the walk fails read two ways, by the stride
//! simulator's grid (the regimes of the grid walks under the posterior) and by the calibrated
//! closed form (§9's p_fail at the estimate, its interval as the uncertainty of k_s), the
//! decision taking the more pessimistic. Before any stance is estimated, the closed form at the
//! terrain's own uncertain k_s (the prior) decides.

use serde::Serialize;

use crate::infer::servo::{quantile, ModelGrid};
use crate::regime::Regime;
use crate::risk::uncertainty::{Uncertainty, MAX_GIVEN_CV};
use crate::risk::{failure_risk, p_fail, UncertainTerrain};
use crate::robot::Robot;
use crate::slope::Slope;

/// The standard normal's 95% quantile: a 90% interval spans 2 x 1.6449 standard deviations.
const Z95: f64 = 1.644_853_626_951_472_2;

/// The stances' estimates pooled: the product of their likelihoods over the grid (the prior is
/// uniform over the log-spaced grid, so each stance's posterior is its likelihood normalised)
/// for the median and the simulator's verdict; the 90% interval the wider of the product's and
/// the one the stances' own scatter gives the median (`median x exp(+/- t SD / sqrt(n))`, SD
/// of the n stances' log medians, t Student's 95% quantile with n - 1 degrees of freedom)
/// **(choice: the stances' likelihoods are narrower than their scatter, so the product's
/// interval alone is overconfident: on constant sand of 1.95e6 N/m^3 at 20 degrees it covered
/// the truth in 5 of 8 emulated runs of 14 stances; docs/drive.md)**.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PooledEstimate {
    /// Stances pooled (the last `window` of them, or all).
    pub stances: usize,
    /// Posterior median of k_s, N/m^3.
    pub k_s: f64,
    /// 5% quantile, N/m^3.
    pub k_s_lo: f64,
    /// 95% quantile, N/m^3.
    pub k_s_hi: f64,
    /// P(slippage) by the grid walks' regimes.
    pub p_slippage: f64,
    /// P(sinkage) by the grid walks' regimes.
    pub p_sinkage: f64,
    /// The simulator's verdict: P(slippage) + P(sinkage).
    pub p_fail_simulator: f64,
    /// The closed form's verdict at the pooled estimate ([`closed_form_p_fail`]).
    pub p_fail_closed_form: f64,
    /// The decision: the larger of the two.
    pub p_fail: f64,
}

/// Pools stance posteriors `stances` (each the grid's probabilities, in grid order) and reads
/// both verdicts. `None` when there is none or a posterior does not match the grid.
pub fn pool(
    robot: &Robot,
    terrain: &UncertainTerrain,
    slope: Slope,
    grid: &ModelGrid,
    stances: &[&[f64]],
    medians: &[f64],
) -> Option<PooledEstimate> {
    let n = grid.k_s.len();
    if stances.is_empty() || stances.iter().any(|p| p.len() != n) || n < 2 {
        return None;
    }
    // Sum of log-probabilities, floored so that one stance's zero does not veto a point for
    // good (1e-300: below any weight the likelihood's exponent gives a sensible fit).
    let log: Vec<f64> = (0..n).map(|i| stances.iter().map(|p| p[i].max(1e-300).ln()).sum::<f64>()).collect();
    let top = log.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = log.iter().map(|l| (l - top).exp()).collect();
    let total: f64 = w.iter().sum();
    let p: Vec<f64> = w.iter().map(|x| x / total).collect();
    let ln: Vec<f64> = grid.k_s.iter().map(|k| k.ln()).collect();
    let q = |level: f64| quantile(&ln, &p, level).exp();
    let weight =
        |r: Regime| 0.0 + p.iter().zip(&grid.regime).filter(|(_, g)| **g == r).map(|(x, _)| x).sum::<f64>();
    let (k_s, mut k_s_lo, mut k_s_hi) = (q(0.5), q(0.05), q(0.95));
    let logs: Vec<f64> = medians.iter().filter(|m| **m > 0.0).map(|m| m.ln()).collect();
    if logs.len() >= 2 {
        let mean = logs.iter().sum::<f64>() / logs.len() as f64;
        let sd = (logs.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / (logs.len() - 1) as f64).sqrt();
        let half = student_t95(logs.len() - 1) * sd / (logs.len() as f64).sqrt();
        k_s_lo = k_s_lo.min(k_s * (-half).exp());
        k_s_hi = k_s_hi.max(k_s * half.exp());
    }
    let (p_slippage, p_sinkage) = (weight(Regime::Slippage), weight(Regime::Sinkage));
    let simulator = p_slippage + p_sinkage;
    let closed = closed_form_p_fail(robot, terrain, slope, k_s, k_s_lo, k_s_hi);
    Some(PooledEstimate {
        stances: stances.len(),
        k_s,
        k_s_lo,
        k_s_hi,
        p_slippage,
        p_sinkage,
        p_fail_simulator: simulator,
        p_fail_closed_form: closed,
        p_fail: simulator.max(closed),
    })
}

/// Student's t distribution's 95% quantile with `dof` degrees of freedom (tables to 30, the
/// normal's beyond).
pub fn student_t95(dof: usize) -> f64 {
    const T: [f64; 30] = [
        6.314, 2.920, 2.353, 2.132, 2.015, 1.943, 1.895, 1.860, 1.833, 1.812, 1.796, 1.782, 1.771, 1.761,
        1.753, 1.746, 1.740, 1.734, 1.729, 1.725, 1.721, 1.717, 1.714, 1.711, 1.708, 1.706, 1.703, 1.701,
        1.699, 1.697,
    ];
    match dof {
        0 => f64::INFINITY,
        d if d <= 30 => T[d - 1],
        _ => Z95,
    }
}

/// The coefficient of variation of a log-normal k_s whose 90% interval is `lo` to `hi`:
/// `sigma = ln(hi / lo) / (2 x 1.6449)`, `CV = sqrt(exp(sigma^2) - 1)`, at most
/// [`MAX_GIVEN_CV`] **(choice: the closed form's uncertainty is a CV, §9; the posterior's
/// interval is in log k_s)**.
pub fn cv_of_interval(lo: f64, hi: f64) -> f64 {
    let sigma = (hi / lo).ln().abs() / (2.0 * Z95);
    if !sigma.is_finite() {
        return MAX_GIVEN_CV;
    }
    (sigma * sigma).exp_m1().sqrt().min(MAX_GIVEN_CV)
}

/// §9's p_fail of the closed form at `slope`, the terrain's k_n and its CV there, k_s at the
/// estimate `k_s` with the CV of its 90% interval ([`cv_of_interval`]).
pub fn closed_form_p_fail(
    robot: &Robot,
    terrain: &UncertainTerrain,
    slope: Slope,
    k_s: f64,
    k_s_lo: f64,
    k_s_hi: f64,
) -> f64 {
    let (mut ground, u) = terrain.at(slope);
    ground.k_s = k_s;
    let cv_s = cv_of_interval(k_s_lo, k_s_hi);
    match Uncertainty::new(u.cv_n(), cv_s) {
        Ok(u) => p_fail(robot, slope, &ground, u),
        Err(_) => 1.0,
    }
}

/// The closed form's p_fail at `slope` on the terrain's own uncertain ground: the decision
/// before the first stance is estimated (`risk`'s p_fail there).
pub fn prior_p_fail(robot: &Robot, terrain: &UncertainTerrain, slope: Slope) -> f64 {
    failure_risk(robot, slope, terrain).p_fail()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// By hand: a 90% interval of a factor 3 either side (9 in all) is sigma = ln 9 / 3.2897
    /// = 0.6679, CV = sqrt(exp(0.4461) - 1) = 0.7498; a point interval has CV 0.
    #[test]
    fn the_cv_of_an_interval_by_hand() {
        assert!((cv_of_interval(1e5, 9e5) - 0.749_8).abs() < 1e-3, "{}", cv_of_interval(1e5, 9e5));
        assert_eq!(cv_of_interval(2e5, 2e5), 0.0);
        assert_eq!(cv_of_interval(0.0, 1e5), MAX_GIVEN_CV);
    }
}
