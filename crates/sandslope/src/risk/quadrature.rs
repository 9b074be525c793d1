//! The regime probabilities at one slope by deterministic quadrature (docs/model.md §9): the
//! reference every faster method is checked against.
//!
//! k_n and k_s at a slope are independent log-normal variables whose medians are the table
//! values and whose coefficients of variation are `cv_n`, `cv_s`:
//! `ln k ~ Normal(ln k_median, sigma^2)`, `sigma = sqrt(ln(1 + cv^2))`.
//!
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

use serde::{Deserialize, Serialize};

use super::uncertainty::Uncertainty;
use crate::critical::{critical_shear_strength, StepTarget};
use crate::model::sinkage_threshold_k_n;
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::Ground;

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
pub(crate) fn phi(z: f64) -> f64 {
    0.5 * statrs::function::erf::erfc(-z / std::f64::consts::SQRT_2)
}

/// Standard normal density.
pub(crate) fn density(z: f64) -> f64 {
    (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

/// Half-width of [`NormalCdfTable`], in standard deviations; beyond it the CDF is 0 or 1 to
/// within 1.2e-19.
pub(crate) const CDF_TABLE_SPAN: f64 = 9.0;
/// Nodes of [`NormalCdfTable`] per standard deviation.
const CDF_TABLE_PER_SD: f64 = 64.0;

/// The standard normal CDF on `[-9, 9]` by cubic Hermite interpolation between values of
/// [`phi`] and of its derivative, the [`density`], tabulated every 1/64 standard deviation
/// (1,153 nodes, 18 KiB: it stays in the L1 cache).
///
/// Why not [`phi`]: the risk map evaluates a few hundred thousand CDFs per 1024 x 1024 map, and
/// statrs' erfc took 15% of `risk --map`'s CPU time there (`perf record`, 8 single-threaded
/// runs; 17-23 ns per call in a loop against 2-3 ns for this table). Accuracy: cubic Hermite
/// interpolation with exact derivatives errs by at most `h^4/384 max|Phi''''|`, and
/// `Phi'''' = -(z^3 - 3z) phi(z)` peaks at 0.5506, so with `h = 1/64` by at most 8.6e-11,
/// far below the map's 1e-6 (a test checks the bound against [`phi`]).
pub(crate) struct NormalCdfTable {
    /// `[Phi(z_k), h phi(z_k)]` at `z_k = -9 + k h`.
    nodes: Vec<[f64; 2]>,
}

impl NormalCdfTable {
    /// Tabulates the CDF (about 1,153 erfc and exp calls).
    pub(crate) fn new() -> Self {
        let h = 1.0 / CDF_TABLE_PER_SD;
        let n = (2.0 * CDF_TABLE_SPAN * CDF_TABLE_PER_SD).round() as usize;
        let nodes = (0..=n)
            .map(|k| {
                let z = -CDF_TABLE_SPAN + k as f64 * h;
                [phi(z), h * density(z)]
            })
            .collect();
        NormalCdfTable { nodes }
    }

    /// `Phi(z)`: interpolated inside `[-9, 9]`, 0 below and 1 above.
    #[inline]
    pub(crate) fn cdf(&self, z: f64) -> f64 {
        let t = (z + CDF_TABLE_SPAN) * CDF_TABLE_PER_SD;
        let last = self.nodes.len() - 1;
        if t.is_nan() {
            return f64::NAN;
        }
        if t < 0.0 {
            return 0.0;
        }
        if t >= last as f64 {
            return 1.0;
        }
        let k = t as usize;
        let u = t - k as f64;
        let ([p0, m0], [p1, m1]) = (self.nodes[k], self.nodes[k + 1]);
        // Hermite basis on [0, 1].
        let (u2, u3) = (u * u, u * u * u);
        let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
        let h10 = u3 - 2.0 * u2 + u;
        let h01 = 3.0 * u2 - 2.0 * u3;
        let h11 = u3 - u2;
        h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1
    }
}

/// `P(ln k < ln threshold)` for `ln k ~ Normal(mu, sigma^2)`; a step function when sigma = 0.
pub(crate) fn prob_below(threshold: f64, mu: f64, sigma: f64) -> f64 {
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

pub(crate) const Z_MAX: f64 = 8.5;
const TOLERANCE: f64 = 1e-9;

/// P(sinkage) = P(k_n <= k_n*) for a log-normal k_n of median `median_k_n` and log-SD
/// `sigma_n` (docs/model.md §9); `k_n_star` may be infinite (h = 2R: every leg sinks). A
/// median of zero or less always sinks; with `sigma_n = 0` the median decides.
pub(crate) fn sinkage_probability(median_k_n: f64, k_n_star: f64, sigma_n: f64) -> f64 {
    if median_k_n <= 0.0 {
        1.0
    } else if sigma_n == 0.0 {
        if median_k_n <= k_n_star {
            1.0
        } else {
            0.0
        }
    } else {
        prob_below(k_n_star, median_k_n.ln(), sigma_n)
    }
}

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
    let p_sink = sinkage_probability(median.k_n, k_n_star, sigma_n);
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

    /// The tabulated CDF is within the cubic Hermite bound h^4/384 max|(z^3 - 3z) phi(z)| =
    /// 8.6e-11 (h = 1/64, the maximum 0.5506 found by hand at z = 0.742) of statrs' erfc
    /// everywhere, at the nodes and between them; exactly 0 and 1 beyond +-9 sd, where the
    /// true CDF is within 1.2e-19 of them; NaN stays NaN.
    #[test]
    fn the_tabulated_cdf_is_within_its_interpolation_bound() {
        let table = NormalCdfTable::new();
        let mut worst: f64 = 0.0;
        // 1/997 sd apart: prime against the 1/64 spacing, so every phase within an interval.
        for k in -9_500..=9_500 {
            let z = k as f64 / 997.0;
            worst = worst.max((table.cdf(z) - phi(z)).abs());
        }
        assert!(worst < 8.6e-11, "worst error {worst:e}");
        assert!(worst > 0.0, "an exact match everywhere would mean the table is not interpolating");
        assert_eq!(table.cdf(-9.5), 0.0);
        assert_eq!(table.cdf(9.0), 1.0);
        assert_eq!(table.cdf(f64::INFINITY), 1.0);
        assert_eq!(table.cdf(f64::NEG_INFINITY), 0.0);
        assert!(table.cdf(f64::NAN).is_nan());
        assert!((table.cdf(0.0) - 0.5).abs() < 1e-15);
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
