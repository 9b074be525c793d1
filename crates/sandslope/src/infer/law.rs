//! Inference through a shear law: the joint posterior of the law's values at the lowest and
//! highest observed slopes, on a grid, and what the law then predicts (k_s with a credible
//! band, and the failure probability) at slopes not walked.

use serde::Serialize;

use super::{slope_posterior, tables, GaitObservation, InferError, LogUniformPrior, SpeedTable};
use crate::risk::{regime_probabilities, UncertainTerrain};
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::Ground;

/// A shear law tying k_s at different slopes together (as in docs/model.md §14).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InferLaw {
    /// `k_s(theta) = k_s0 + b theta_deg`.
    Linear,
    /// `k_s(theta) = k_s0 (cos theta - sin theta / tan phi)`, phi in (0, 90) degrees.
    Coulomb,
}

/// A law through `k_a` at `theta_a` and `k_b` at `theta_b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct LawLine {
    law: InferLaw,
    /// Linear: (k_s0, per_degree). Coulomb: (k_s0, c = 1 / tan phi).
    p: (f64, f64),
}

impl LawLine {
    fn through(law: InferLaw, (ta, ka): (Slope, f64), (tb, kb): (Slope, f64)) -> Option<LawLine> {
        match law {
            InferLaw::Linear => {
                let b = (kb - ka) / (tb.degrees() - ta.degrees());
                Some(LawLine { law, p: (ka - b * ta.degrees(), b) })
            }
            InferLaw::Coulomb => {
                let c = (kb * ta.cos() - ka * tb.cos()) / (kb * ta.sin() - ka * tb.sin());
                let base = ta.cos() - c * ta.sin();
                (c.is_finite() && c > 0.0 && base > 0.0).then(|| LawLine { law, p: (ka / base, c) })
            }
        }
    }

    pub(super) fn k_s(&self, slope: Slope) -> f64 {
        match self.law {
            InferLaw::Linear => (self.p.0 + self.p.1 * slope.degrees()).max(0.0),
            InferLaw::Coulomb => (self.p.0 * (slope.cos() - self.p.1 * slope.sin())).max(0.0),
        }
    }

    /// (k_s0, per_degree) or (k_s0, friction angle in degrees).
    fn params(&self) -> (f64, f64) {
        match self.law {
            InferLaw::Linear => self.p,
            InferLaw::Coulomb => (self.p.0, (1.0 / self.p.1).atan().to_degrees()),
        }
    }
}

/// Median and 90% credible interval of one quantity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Credible {
    /// Posterior median.
    pub median: f64,
    /// 5% quantile.
    pub q05: f64,
    /// 95% quantile.
    pub q95: f64,
}

/// The law's prediction at one slope.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RiskPrediction {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Whether this slope was observed.
    pub observed: bool,
    /// k_s under the law, N/m^3.
    pub k_s: Credible,
    /// Failure probability (docs/model.md §9) with the law's k_s as the median and the terrain's
    /// spread: median and 90% band over the law's posterior (p_fail falls as k_s grows, so its
    /// 95% quantile comes from k_s's 5% quantile).
    pub p_fail: Credible,
}

/// The joint posterior of a shear law and what it predicts.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LawPosterior {
    /// The law.
    pub law: InferLaw,
    /// Level-sand shear strength k_s0 under the law, N/m^3.
    pub k_s0: Credible,
    /// Linear: change of k_s per degree (N/m^3/deg); Coulomb: friction angle phi (degrees).
    pub second: Credible,
    /// The name of `second`: `per_degree` or `friction_angle_deg`.
    pub second_name: &'static str,
    /// Predictions at the requested slopes.
    pub prediction: Vec<RiskPrediction>,
}

/// Points per axis of the law's joint grid.
pub const LAW_GRID_POINTS: usize = 101;

/// Weighted quantiles of `values` with `weights`.
fn weighted_quantiles(values: &[f64], weights: &[f64], qs: &[f64]) -> Vec<f64> {
    let mut idx: Vec<usize> = (0..values.len()).filter(|&i| weights[i] > 0.0).collect();
    idx.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let total: f64 = idx.iter().map(|&i| weights[i]).sum();
    qs.iter()
        .map(|&q| {
            let mut acc = 0.0;
            for &i in &idx {
                // Midpoint rule: the value carries the middle of its weight.
                if acc + 0.5 * weights[i] >= q * total {
                    return values[i];
                }
                acc += weights[i];
            }
            values[*idx.last().expect("weights are not all zero")]
        })
        .collect()
}

/// The law's joint posterior on its grid: every law line with a positive prior and its
/// (unnormalised) posterior weight.
pub(super) struct LawGrid {
    lines: Vec<LawLine>,
    weights: Vec<f64>,
}

impl LawGrid {
    pub(super) fn credible(&self, value: impl Fn(&LawLine) -> f64) -> Credible {
        let values: Vec<f64> = self.lines.iter().map(value).collect();
        let q = weighted_quantiles(&values, &self.weights, &[0.05, 0.5, 0.95]);
        Credible { q05: q[0], median: q[1], q95: q[2] }
    }
}

/// The joint posterior of `law` given the observations (sorted, distinct slopes) and their tables.
pub(super) fn law_grid(
    law: InferLaw,
    obs: &[GaitObservation],
    tables: &[SpeedTable],
) -> Result<LawGrid, InferError> {
    if obs.len() < 2 {
        return Err(InferError::TooFewSlopes { given: obs.len() });
    }
    let lls = obs
        .iter()
        .zip(tables)
        .map(|(o, t)| slope_posterior(t, o).map(|_| t.log_likelihood(o)))
        .collect::<Result<Vec<_>, _>>()?;
    let last = obs.len() - 1;
    // Each end's grid: where its own likelihood is above 1e-9 of its peak.
    let span = |k: usize| -> (f64, f64) {
        let ll = &lls[k];
        let max = ll.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let x = &tables[k].ln_k;
        let first = ll.iter().position(|&l| l - max > -20.7).unwrap_or(0);
        let end = ll.iter().rposition(|&l| l - max > -20.7).unwrap_or(x.len() - 1);
        (x[first], x[end])
    };
    let ((a0, a1), (b0, b1)) = (span(0), span(last));
    let g = LAW_GRID_POINTS;
    let at = |lo: f64, hi: f64, i: usize| lo + (hi - lo) * i as f64 / (g - 1) as f64;
    let mut lines = Vec::with_capacity(g * g);
    let mut log_w = Vec::with_capacity(g * g);
    for i in 0..g {
        let ln_a = at(a0, a1, i);
        for j in 0..g {
            let ln_b = at(b0, b1, j);
            let Some(line) = LawLine::through(law, (obs[0].slope, ln_a.exp()), (obs[last].slope, ln_b.exp()))
            else {
                continue;
            };
            let mut ll = tables[0].interpolate(&lls[0], ln_a) + tables[last].interpolate(&lls[last], ln_b);
            for k in 1..last {
                // k_s = 0 is below the grid: the interpolation holds the lowest point.
                let ks = line.k_s(obs[k].slope);
                ll += tables[k].interpolate(&lls[k], if ks > 0.0 { ks.ln() } else { f64::MIN });
            }
            lines.push(line);
            log_w.push(ll);
        }
    }
    if lines.is_empty() {
        return Err(InferError::LawInconsistent);
    }
    let max = log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Ok(LawGrid { lines, weights: log_w.iter().map(|l| (l - max).exp()).collect() })
}

/// The joint posterior of `law` from the observations, and its prediction of k_s and p_fail at
/// `predict` slopes, with k_n, the angle of repose and the spread from `terrain`.
///
/// The law is parametrised by its k_s at the lowest and highest observed slopes, each
/// log-uniform on the prior (Coulomb laws must also have a friction angle in (0, 90) degrees);
/// the grid ([`LAW_GRID_POINTS`] per axis) spans where each end's own likelihood has mass.
pub fn law_posterior(
    robot: &Robot,
    terrain: &UncertainTerrain,
    observations: &[GaitObservation],
    prior: &LogUniformPrior,
    law: InferLaw,
    predict: &[Slope],
) -> Result<LawPosterior, InferError> {
    let (obs, tables) = tables(robot, terrain.terrain(), observations, prior)?;
    let grid = law_grid(law, &obs, &tables)?;
    let prediction = predict
        .iter()
        .map(|&s| {
            let ks = grid.credible(|l| l.k_s(s));
            let (ground, u) = terrain.at(s);
            let p = |k_s: f64| regime_probabilities(robot, s, &Ground { k_s, ..ground }, u).p_fail();
            RiskPrediction {
                slope_deg: s.degrees(),
                observed: obs.iter().any(|o| o.slope == s),
                k_s: ks,
                p_fail: Credible { median: p(ks.median), q05: p(ks.q95), q95: p(ks.q05) },
            }
        })
        .collect();
    Ok(LawPosterior {
        law,
        k_s0: grid.credible(|l| l.params().0),
        second: grid.credible(|l| l.params().1),
        second_name: match law {
            InferLaw::Linear => "per_degree",
            InferLaw::Coulomb => "friction_angle_deg",
        },
        prediction,
    })
}
