//! The failure probability `p_fail` fast enough for a safe-slope search per robot, 10^5 robots
//! at a time (docs/model.md §9): what [`super::safe_slope_limit`] and `design` decide with.
//!
//! The quantity is the reference's, [`super::regime_probabilities`]`(..).p_fail()`: with
//! log-normal k_n and k_s, `p_fail = P(sinkage) + P(slippage)`, where
//! `P(slippage) = ∫_{z*} φ(z) P(k_s < k_crit(k_n(z))) dz` and `k_crit` is the progress boundary
//! of docs/model.md §13. The reference integrates `P(slippage)` and `P(not success)` together
//! and finds each `k_crit` with Brent's method; three things make this about a hundred times
//! cheaper:
//!
//! - `k_crit` in closed form (the critical module's, which the risk map also uses): the net
//!   step is a quadratic in the anchoring time `t1` (docs/model.md §5), so the `t1` at which
//!   `s = 0` is its smaller root, and `k_crit = F_a / (W d(t1)^2)` with the leg depth `d(t)`
//!   of §4 (floored at the anchoring threshold). The tests check it against
//!   [`crate::critical_shear_strength`] (Brent's method) to 1e-9.
//! - adaptive Gauss-Kronrod (7-15 points) quadrature of only `P(slippage)` to 1e-11: p_fail
//!   needs no metastable/success boundary.
//! - a closed-form upper bound (`FailureProbability::fails`) that settles `p_fail < max_risk`
//!   without any quadrature on slopes well below the limit.
//!
//! It covers every input the reference does (any robot, repose, `k_s = 0`, a median k_n at or
//! below the sinkage threshold, zero CVs); the tests check it against the reference to 2e-9 on
//! robots, slopes, grounds and CVs unlike the paper's. What it does not give is the other
//! regime probabilities: [`super::failure_risk`] and [`super::risk_curve`] keep the reference.

use super::quadrature::{density, phi, prob_below, sinkage_probability, Z_MAX};
use super::uncertainty::Uncertainty;
use crate::critical::critical_closed_form;
use crate::model::{
    anchoring_threshold_k_s, level_step_length, normal_equilibrium_depth, sinkage_threshold_k_n,
};
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::Ground;

/// The progress boundary `k_crit(k_n)` of one robot at one slope, in closed form
/// ([`crate::critical`]'s, with the target step 0), floored at the anchoring threshold.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ProgressBoundary<'a> {
    robot: &'a Robot,
    slope: Slope,
    /// Anchoring threshold `F_a / (W d_max^2)`.
    k_anchor: f64,
}

impl<'a> ProgressBoundary<'a> {
    pub(crate) fn new(robot: &'a Robot, slope: Slope) -> ProgressBoundary<'a> {
        ProgressBoundary { robot, slope, k_anchor: anchoring_threshold_k_s(robot, slope) }
    }

    /// The smallest k_s giving a positive net step at level step `s_star`, or `None` when
    /// no k_s does (`s_star <= 0`).
    fn at_level_step(&self, s_star: f64) -> Option<f64> {
        if s_star <= 0.0 || s_star.is_nan() {
            return None;
        }
        let (k, _capped) = critical_closed_form(self.robot, self.slope, s_star, 0.0);
        Some(k.max(self.k_anchor))
    }

    /// The smallest k_s giving progress (`s > 0`) at normal resistance `k_n`; `None` when
    /// no k_s does (the legs sink or the level step is zero).
    pub(crate) fn k_crit(&self, k_n: f64) -> Option<f64> {
        let d_n = normal_equilibrium_depth(self.robot, self.slope, k_n);
        if d_n >= self.robot.max_depth() {
            return None;
        }
        self.at_level_step(level_step_length(self.robot, self.slope, d_n))
    }

    /// The largest `k_crit` over every `k_n >= k_lo` (above the sinkage threshold): the
    /// level step is concave in `d_n`, so its least value on `d_n in (0, d_n(k_lo)]` is at an
    /// end, and `k_crit` falls as the level step grows.
    fn k_crit_max_above(&self, k_lo: f64) -> Option<f64> {
        let d_lo = normal_equilibrium_depth(self.robot, self.slope, k_lo);
        if d_lo >= self.robot.max_depth() {
            return None;
        }
        let s_min = level_step_length(self.robot, self.slope, d_lo)
            .min(level_step_length(self.robot, self.slope, 0.0));
        self.at_level_step(s_min)
    }
}

/// Absolute tolerance of the slippage integral.
const TOLERANCE: f64 = 1e-11;

/// `p_fail = P(sinkage or slippage)` of `robot` at `slope` on ground whose medians are `median`
/// (the same value as [`super::regime_probabilities`]`(..).p_fail()`, to 2e-9).
pub fn p_fail(robot: &Robot, slope: Slope, median: &Ground, uncertainty: Uncertainty) -> f64 {
    FailureProbability::new(robot, slope, median, uncertainty).p_fail()
}

/// Everything about one (robot, slope, ground) needed for p_fail and its cheap upper bound.
pub(crate) struct FailureProbability<'a> {
    boundary: ProgressBoundary<'a>,
    beyond_repose: bool,
    k_s_positive: bool,
    mu_n: f64,
    mu_s: f64,
    sigma_n: f64,
    sigma_s: f64,
    k_n_star: f64,
    p_sink: f64,
}

impl<'a> FailureProbability<'a> {
    pub(crate) fn new(
        robot: &'a Robot,
        slope: Slope,
        median: &Ground,
        u: Uncertainty,
    ) -> FailureProbability<'a> {
        let (sigma_n, sigma_s) = (u.sigma_n(), u.sigma_s());
        let mu_n = median.k_n.ln();
        let k_n_star = sinkage_threshold_k_n(robot, slope);
        let p_sink = sinkage_probability(median.k_n, k_n_star, sigma_n);
        FailureProbability {
            boundary: ProgressBoundary::new(robot, slope),
            beyond_repose: median.beyond_repose(slope),
            k_s_positive: median.k_s > 0.0,
            mu_n,
            mu_s: median.k_s.ln(),
            sigma_n,
            sigma_s,
            k_n_star,
            p_sink,
        }
    }

    /// `P(slippage | k_n)`.
    fn slip_given(&self, k_n: f64) -> f64 {
        match self.boundary.k_crit(k_n) {
            Some(k) if self.k_s_positive => prob_below(k, self.mu_s, self.sigma_s),
            _ => 1.0,
        }
    }

    fn trivially_failed(&self) -> bool {
        self.beyond_repose || self.p_sink >= 1.0
    }

    pub(crate) fn p_fail(&self) -> f64 {
        if self.trivially_failed() {
            return 1.0;
        }
        let slip = if self.sigma_n == 0.0 {
            self.slip_given(self.mu_n.exp())
        } else {
            let z_star = ((self.k_n_star.ln() - self.mu_n) / self.sigma_n).max(-Z_MAX);
            if z_star >= Z_MAX {
                0.0
            } else {
                let f = |z: f64| density(z) * self.slip_given((self.mu_n + self.sigma_n * z).exp());
                integrate(&f, z_star, Z_MAX)
            }
        };
        let not_sunk = 1.0 - self.p_sink;
        self.p_sink + slip.clamp(0.0, not_sunk)
    }

    /// An upper bound of p_fail in closed form: `P(k_n < k_lo) + P(k_s < max k_crit above k_lo)`
    /// with `k_lo` six standard deviations below the median (or just above the sinkage
    /// threshold). Infinite when no useful bound exists.
    fn upper_bound(&self) -> f64 {
        if self.trivially_failed() || !self.k_s_positive {
            return 1.0;
        }
        if self.sigma_n == 0.0 {
            return f64::INFINITY; // exact value is cheap anyway
        }
        let z_star = (self.k_n_star.ln() - self.mu_n) / self.sigma_n;
        let z_lo = (-6.0f64).max(z_star + 0.25);
        match self.boundary.k_crit_max_above((self.mu_n + self.sigma_n * z_lo).exp()) {
            Some(k) => phi(z_lo) + prob_below(k, self.mu_s, self.sigma_s),
            None => f64::INFINITY,
        }
    }

    /// Whether `p_fail >= max_risk`, settled by the upper bound when it can be; p_fail itself
    /// when it had to be computed.
    pub(crate) fn fails(&self, max_risk: f64) -> (bool, Option<f64>) {
        if self.upper_bound() < max_risk {
            return (false, None);
        }
        let p = self.p_fail();
        (p >= max_risk, Some(p))
    }
}

/// Gauss-Kronrod 7-15 nodes (non-negative half) and weights.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
/// Gauss 7-point weights at the Kronrod nodes 1, 3, 5, 7.
const WG: [f64; 4] =
    [0.129_484_966_168_869_7, 0.279_705_391_489_276_7, 0.381_830_050_505_118_9, 0.417_959_183_673_469_4];

/// One Gauss-Kronrod 7-15 panel: (Kronrod estimate, |Kronrod - Gauss|).
fn gk15(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut kronrod = WGK[7] * fc;
    let mut gauss = WG[3] * fc;
    for j in 0..7 {
        let dx = h * XGK[j];
        let pair = f(c - dx) + f(c + dx);
        kronrod += WGK[j] * pair;
        if j % 2 == 1 {
            gauss += WG[j / 2] * pair;
        }
    }
    (kronrod * h, ((kronrod - gauss) * h).abs())
}

/// Most Gauss-Kronrod panels one [`integrate`] call evaluates. An integrand that is rough at
/// every scale defeats the error test at every depth, and bisecting both halves of every panel
/// to depth 40 never ends: the 100,000-input fuzz of `risk` found terrains whose k_s SD is
/// 2e-6 of its median, where P(slippage | k_n) is a step narrower than the closed form's
/// rounding (docs/robustness.md). Past the budget the remaining panels are taken as they are.
const MAX_PANELS: u32 = 1000;

/// Adaptive Gauss-Kronrod on `[a, b]` from 4 panels, bisecting any panel whose error estimate
/// exceeds its share of [`TOLERANCE`], within [`MAX_PANELS`] panels.
fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    fn panel(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64, depth: u32, left: &mut u32) -> f64 {
        let (value, err) = gk15(f, a, b);
        if err <= tol || depth == 0 || *left < 2 {
            return value;
        }
        *left -= 2;
        let m = 0.5 * (a + b);
        panel(f, a, m, 0.5 * tol, depth - 1, left) + panel(f, m, b, 0.5 * tol, depth - 1, left)
    }
    const PANELS: usize = 4;
    let h = (b - a) / PANELS as f64;
    let mut left = MAX_PANELS - PANELS as u32;
    (0..PANELS)
        .map(|i| {
            let x1 = if i + 1 == PANELS { b } else { a + (i + 1) as f64 * h };
            panel(f, a + i as f64 * h, x1, TOLERANCE / PANELS as f64, 40, &mut left)
        })
        .sum()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::critical::{critical_shear_strength, StepTarget};
    use crate::risk::regime_probabilities;
    use crate::robot::RobotSpec;

    fn slope(d: f64) -> Slope {
        Slope::from_degrees(d).unwrap()
    }

    /// Robots unlike the paper's: heavy, hip above and below R, a measured level step, few legs.
    pub(crate) fn robots() -> Vec<Robot> {
        let p = RobotSpec::paper_hexapod();
        [
            p.clone(),
            RobotSpec { mass_kg: 1.2, hip_height_m: 0.05, ..p.clone() },
            RobotSpec { leg_radius_m: 0.06, hip_height_m: 0.015, leg_width_m: 0.02, ..p.clone() },
            RobotSpec { stance_legs: 2, leg_speed_rad_s: 12.0, response_time_s: 0.1, ..p.clone() },
            RobotSpec { level_step_m: Some(0.05), ..p },
        ]
        .into_iter()
        .map(|s| Robot::new(s).unwrap())
        .collect()
    }

    #[test]
    fn closed_form_boundary_matches_brent() {
        for r in robots() {
            for deg in [0.0, 5.0, 12.0, 20.0, 30.0, 45.0] {
                let b = ProgressBoundary::new(&r, slope(deg));
                for k_n in [3e4, 1e5, 3e5, 7e5, 3e6, 1e8] {
                    let brent =
                        critical_shear_strength(&r, slope(deg), k_n, false, StepTarget::Progress).ok();
                    let closed = b.k_crit(k_n);
                    match (brent, closed) {
                        (Some(x), Some(y)) => assert!((x - y).abs() <= 1e-9 * x, "{deg} {k_n}: {x} vs {y}"),
                        (None, None) => {}
                        other => panic!("{deg} {k_n}: {other:?}"),
                    }
                }
            }
        }
    }

    /// The reference is the general quadrature (Simpson to 1e-9 over both boundaries found by
    /// Brent's method), computed independently of everything in this module.
    #[test]
    fn p_fail_matches_the_risk_quadrature() {
        let cases = [(0.1, 0.2), (0.3, 0.5), (0.0, 0.3), (0.2, 0.0), (0.6, 1.0)];
        for r in robots() {
            for deg in [0.0, 10.0, 20.0, 26.0] {
                for (k_n, k_s) in [(7e5, 1.5e6), (1.2e5, 4e5), (5e4, 3e6), (7e5, 0.0)] {
                    for (cv_n, cv_s) in cases {
                        let u = Uncertainty::new(cv_n, cv_s).unwrap();
                        let g = Ground { k_n, k_s, repose: Some(slope(25.0)) };
                        let want = regime_probabilities(&r, slope(deg), &g, u).p_fail();
                        let got = p_fail(&r, slope(deg), &g, u);
                        assert!(
                            (got - want).abs() < 2e-9,
                            "{deg} {k_n} {k_s} {cv_n} {cv_s}: {got} vs {want}"
                        );
                    }
                }
            }
        }
    }

    /// The terrain the 100,000-input fuzz of `risk` hung on (docs/robustness.md): k_s with an SD
    /// of 2 N/m^3 on 9e5 (cv 2.2e-6), so P(slippage | k_n) is a step narrower than the closed
    /// form's rounding and the adaptive quadrature bisected both halves of every panel to depth
    /// 40. Within its panel budget p_fail now ends, and agrees with the reference quadrature
    /// (which finds the step's place by Brent's method).
    #[test]
    fn a_k_s_spread_narrower_than_rounding_ends_and_agrees_with_the_reference() {
        let u = Uncertainty::new(0.1, 2.0 / 9e5).unwrap();
        let g = Ground { k_n: 3e5, k_s: 9e5, repose: Some(slope(32.0)) };
        for r in robots() {
            for deg in [0.0, 5.0, 10.0, 20.0, 25.0, 30.0] {
                let want = regime_probabilities(&r, slope(deg), &g, u).p_fail();
                let got = p_fail(&r, slope(deg), &g, u);
                assert!((got - want).abs() < 1e-6, "{deg}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn upper_bound_bounds() {
        for r in robots() {
            for deg in [0.0, 10.0, 20.0] {
                for (k_n, k_s) in [(7e5, 1.5e6), (2e5, 5e5), (7e5, 3e7)] {
                    let u = Uncertainty::new(0.1, 0.2).unwrap();
                    let g = Ground::new(k_n, k_s).unwrap();
                    let e = FailureProbability::new(&r, slope(deg), &g, u);
                    assert!(e.upper_bound() >= e.p_fail() - 1e-12, "{deg} {k_n} {k_s}");
                }
            }
        }
    }
}
