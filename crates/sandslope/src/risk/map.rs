//! The risk map: p_fail and p_not_success at every cell of a grid of median (k_n, k_s), at
//! one robot, slope and uncertainty (docs/model.md §9; algorithm in docs/phase-and-risk.md).

use rayon::prelude::*;
use serde::Serialize;

use super::quadrature::regime_probabilities;
use super::uncertainty::Uncertainty;
use crate::phase::{contour_segments, Axis, ContourSegment};
use crate::robot::Robot;
use crate::slope::Slope;
use crate::terrain::Ground;

/// p_fail and p_not_success over a `(k_n, k_s)` grid of medians, all cells with the same
/// uncertainty. Cell `(i, j)` (k_n value `i`, k_s value `j`) is at index `j * nx + i`
/// (row-major, one row per k_s value, like [`crate::phase::PhaseMap`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RiskMap {
    /// Slope, degrees.
    pub slope_deg: f64,
    /// Whether the slope is at or beyond the terrain's angle of repose.
    pub beyond_repose: bool,
    /// The median-k_n axis (columns).
    pub k_n_axis: Axis,
    /// The median-k_s axis (rows).
    pub k_s_axis: Axis,
    /// The uncertainty of every cell.
    pub uncertainty: Uncertainty,
    /// `P(sinkage or slippage)` per cell, row-major.
    pub p_fail: Vec<f64>,
    /// `P(regime != success)` per cell, row-major.
    pub p_not_success: Vec<f64>,
}

impl RiskMap {
    /// The map for `robot` at `slope` on terrain with angle of repose `repose`, over
    /// `k_n_axis x k_s_axis` with `uncertainty` in every cell. `row_done` is called once per
    /// finished k_s row, from any thread (for progress bars).
    pub fn compute(
        robot: &Robot,
        slope: Slope,
        repose: Option<Slope>,
        k_n_axis: &Axis,
        k_s_axis: &Axis,
        uncertainty: Uncertainty,
        row_done: &(dyn Fn() + Sync),
    ) -> RiskMap {
        let k_n = k_n_axis.values();
        let k_s = k_s_axis.values();
        let nx = k_n.len();
        let rows: Vec<(Vec<f64>, Vec<f64>)> = k_s
            .par_iter()
            .map(|&ks| {
                let (a, b) = k_n
                    .iter()
                    .map(|&kn| {
                        let ground = Ground { k_n: kn, k_s: ks, repose };
                        let p = regime_probabilities(robot, slope, &ground, uncertainty);
                        (p.p_fail(), p.p_not_success())
                    })
                    .unzip();
                row_done();
                (a, b)
            })
            .collect();
        let mut p_fail = Vec::with_capacity(nx * k_s.len());
        let mut p_not_success = Vec::with_capacity(nx * k_s.len());
        for (a, b) in rows {
            p_fail.extend(a);
            p_not_success.extend(b);
        }
        RiskMap {
            slope_deg: slope.degrees(),
            beyond_repose: repose.is_some_and(|r| slope.radians() >= r.radians()),
            k_n_axis: *k_n_axis,
            k_s_axis: *k_s_axis,
            uncertainty,
            p_fail,
            p_not_success,
        }
    }

    /// p_fail at column `i` (k_n) and row `j` (k_s).
    pub fn p_fail_at(&self, i: usize, j: usize) -> f64 {
        self.p_fail[j * self.k_n_axis.len() + i]
    }

    /// p_not_success at column `i` (k_n) and row `j` (k_s).
    pub fn p_not_success_at(&self, i: usize, j: usize) -> f64 {
        self.p_not_success[j * self.k_n_axis.len() + i]
    }

    /// The contour `p_fail = level` (e.g. the `--max-risk` threshold), by marching squares.
    pub fn p_fail_contour(&self, level: f64) -> Vec<ContourSegment> {
        contour_segments(&self.k_n_axis, &self.k_s_axis, &self.p_fail, level)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::paper_robot;
    use crate::AxisScale;

    #[test]
    fn risk_map_cells_are_the_regime_probabilities() {
        let r = paper_robot();
        let s = Slope::from_degrees(20.0).unwrap();
        let kn = Axis::new("k_n", 3e4, 3e6, 4, AxisScale::Log).unwrap();
        let ks = Axis::new("k_s", 1e5, 1e7, 3, AxisScale::Log).unwrap();
        let u = Uncertainty::new(0.2, 0.4).unwrap();
        let map = RiskMap::compute(&r, s, None, &kn, &ks, u, &|| {});
        assert_eq!(map.p_fail.len(), 12);
        let g = Ground::new(kn.value(2), ks.value(1)).unwrap();
        let p = regime_probabilities(&r, s, &g, u);
        assert!((map.p_fail_at(2, 1) - p.p_fail()).abs() < 1e-6);
        assert!((map.p_not_success_at(2, 1) - p.p_not_success()).abs() < 1e-6);
    }
}
