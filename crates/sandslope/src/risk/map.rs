//! The risk map: p_fail and p_not_success at every cell of a grid of median (k_n, k_s), at
//! one robot, slope and uncertainty (docs/model.md §9; algorithm and error bound in
//! docs/phase-and-risk.md).
//!
//! Per cell, with `x = ln k_n ~ Normal(mu_n, sigma_n^2)` and `ln k_s ~ Normal(mu_s, sigma_s^2)`,
//!
//! `p_fail = Phi((x* - mu_n)/sigma_n) + integral over x > x* of
//!           phi_n(x - mu_n) Phi((g(x) - mu_s)/sigma_s) dx`
//!
//! where `x* = ln k_n*` (sinkage) and `g(x) = ln k_s_crit(e^x)` is the critical shear strength
//! for progress (docs/model.md §13); `p_not_success` is the same with the critical strength
//! for robust progress. `g` does not depend on the medians, so the map shares all the work
//! that does not depend on the cell:
//!
//! 1. **Nodes, once per map.** The integration range (the union over columns of
//!    `[mu_n - 8.5 sigma_n, mu_n + 8.5 sigma_n]`, cut at `x*`) is split into panels of width
//!    at most `sigma_n`, narrower wherever `g` moves by more than `sigma_s` inside a panel
//!    while within reach of some row's `mu_s`, and split exactly where `g` has a kink
//!    (where the anchoring threshold starts to bind) or becomes infinite (no strength
//!    suffices). Each panel carries 5 Gauss-Legendre nodes; `g` is evaluated at each node in
//!    closed form ([`crate::critical::critical_shear_strength_closed_form`]).
//! 2. **Weights, once per column:** `w_q phi((x_q - mu_n)/sigma_n)/sigma_n` over the nodes
//!    within 8.5 sigma_n of the column's median, zero elsewhere: a banded matrix `W`
//!    (columns x nodes), stored as dense blocks of 64 consecutive columns over the nodes any
//!    of them weighs.
//! 3. **Conditional probabilities, once per row:** `C_t[j][q] = Phi((g_t(x_q) - mu_s_j)/sigma_s)`
//!    at every node (0 or 1 where the argument is beyond +-7, off by at most 1.3e-12; otherwise from a tabulated CDF
//!    within 8.6e-11 of statrs' erfc: `quadrature::NormalCdfTable`).
//! 4. **All cells at once** are the matrix products `C_t W^T` (rows x columns), one dense
//!    product per column block and task of 32 rows, by `matrixmultiply`'s packed, vectorised
//!    dgemm; then `P(sinkage)` is added per column. The sums are the same terms as a dot
//!    product per cell, added in another order (results differ in the last bits).
//!
//! Both factors of the integrand change by a bounded amount within a panel, so the 10th-order
//! Gauss-Legendre rule converges far below the 1e-6 target; the tests check every cell of
//! random maps (random robots, slopes, spreads down to `cv_s = 0.01`, `cv_n = 0`, medians on
//! the sinkage boundary) against the per-cell adaptive quadrature of
//! [`super::regime_probabilities`] ([`RiskMap::compute_by_quadrature`]) to 1e-6 absolute.
//! Without spread in k_n (`cv_n = 0`) each cell is a normal CDF at the column's critical
//! strength; without spread in k_s (`cv_s = 0`) the conditional probability is a step, so
//! each row's crossings `g(x) = mu_s` are found by bisection and each cell is a sum of normal
//! CDF differences.

use rayon::prelude::*;
use serde::Serialize;

use super::panels::{
    above, banded_product, build_nodes, cdf, column_blocks, curves, finish, Blocks, ColumnBlock, Nodes,
    COLUMN_BLOCK, ROW_BLOCK, Z_FLAT,
};
use super::quadrature::{phi, regime_probabilities, Z_MAX};
use super::uncertainty::Uncertainty;
use crate::axis::Axis;
use crate::contour::{contour_segments, ContourSegment};
use crate::model::sinkage_threshold_k_n;
use crate::robot::Robot;
use crate::slope::Slope;
use crate::strength_grid::StrengthGrid;
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

/// `P(sinkage)` of each column (k_n median `e^mu_n`): `Phi((x* - mu_n)/sigma_n)`, a step when
/// `sigma_n = 0`, 1 where the median is 0 or no depth supports the robot.
fn sinkage_probabilities(mu_n: &[f64], x_star: f64, sigma_n: f64) -> Vec<f64> {
    mu_n.iter()
        .map(|&m| {
            if m == f64::NEG_INFINITY || x_star == f64::INFINITY {
                1.0
            } else if sigma_n == 0.0 {
                f64::from(u8::from(m <= x_star))
            } else {
                phi((x_star - m) / sigma_n)
            }
        })
        .collect()
}

/// Per column: the integration window as a node range and its weights, or (`sigma_n = 0`) the
/// two curves at the column's median.
enum Columns {
    Certain(Vec<[f64; 2]>),
    /// The nodes, and (`sigma_s > 0`) the column blocks of the weight matrix.
    Spread {
        nodes: Nodes,
        blocks: Vec<ColumnBlock>,
    },
}

impl Columns {
    /// The columns of a map below the angle of repose (module documentation, steps 1 and 2).
    fn new(
        robot: &Robot,
        slope: Slope,
        mu_n: &[f64],
        mu_s: &[f64],
        x_star: f64,
        uncertainty: Uncertainty,
        block_columns: usize,
    ) -> Columns {
        let (sigma_n, sigma_s) = (uncertainty.sigma_n(), uncertainty.sigma_s());
        if sigma_n == 0.0 {
            return Columns::Certain(
                mu_n.iter()
                    .map(|&m| if m > x_star { curves(robot, slope, m).0 } else { [f64::INFINITY; 2] })
                    .collect(),
            );
        }
        // The union of the columns' windows, cut at x*.
        let mut windows: Vec<(f64, f64)> = mu_n
            .iter()
            .filter(|m| m.is_finite())
            .map(|&m| ((m - Z_MAX * sigma_n).max(x_star), m + Z_MAX * sigma_n))
            .filter(|(a, b)| a < b)
            .collect();
        windows.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut segments: Vec<(f64, f64)> = Vec::new();
        for (a, b) in windows {
            match segments.last_mut() {
                Some(last) if a <= last.1 => last.1 = last.1.max(b),
                _ => segments.push((a, b)),
            }
        }
        let finite_s: Vec<f64> = mu_s.iter().copied().filter(|m| m.is_finite()).collect();
        let band = if sigma_s > 0.0 && !finite_s.is_empty() {
            let lo = finite_s.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = finite_s.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (lo - Z_FLAT * sigma_s, hi + Z_FLAT * sigma_s)
        } else {
            (f64::INFINITY, f64::NEG_INFINITY)
        };
        let nodes = build_nodes(robot, slope, &segments, sigma_n, sigma_s, band);
        let column_blocks =
            if sigma_s > 0.0 { column_blocks(&nodes, mu_n, sigma_n, block_columns) } else { Vec::new() };
        Columns::Spread { nodes, blocks: column_blocks }
    }
}

/// What every cell of a map shares: the medians' logarithms per column and row, `P(sinkage)`
/// per column, the spreads, and whether the slope is at or beyond repose.
struct Cells<'a> {
    mu_n: &'a [f64],
    mu_s: &'a [f64],
    p_sink: &'a [f64],
    sigma_n: f64,
    sigma_s: f64,
    beyond_repose: bool,
}

/// The cells of a map that needs no matrix product (at or beyond repose, `k_s = 0`, `cv_n =
/// 0` or `cv_s = 0`; module documentation), row by row in parallel: `out` is `[p_fail,
/// p_not_success]`, row-major.
fn cells_without_product(
    robot: &Robot,
    slope: Slope,
    columns: &Columns,
    cells: &Cells<'_>,
    out: [&mut [f64]; 2],
    row_done: &(dyn Fn() + Sync),
) {
    let Cells { mu_n, mu_s, p_sink, sigma_n, sigma_s, beyond_repose } = *cells;
    let nx = mu_n.len().max(1);
    let [p_fail, p_not_success] = out;
    p_fail.par_chunks_mut(nx).zip(p_not_success.par_chunks_mut(nx)).zip(mu_s.par_iter()).for_each(
        |((fail_row, ns_row), &ms)| {
            // Conditional integrals [P(slip, not sunk), P(not success, not sunk)] per column.
            let integrals: Vec<[f64; 2]> = if beyond_repose || ms == f64::NEG_INFINITY {
                // Every leg that does not sink slips (at/above repose, or k_s = 0).
                p_sink.iter().map(|&p| [1.0 - p; 2]).collect()
            } else {
                match columns {
                    Columns::Certain(g) => g
                        .iter()
                        .zip(p_sink)
                        .map(|(g, &p)| {
                            if p >= 1.0 {
                                return [0.0; 2];
                            }
                            let f = |g: f64| {
                                if sigma_s == 0.0 {
                                    f64::from(u8::from(g > ms))
                                } else {
                                    cdf(g, ms, sigma_s)
                                }
                            };
                            [f(g[0]), f(g[1])]
                        })
                        .collect(),
                    Columns::Spread { nodes, .. } => {
                        let intervals = [0, 1].map(|t| above(robot, slope, &nodes.ends, t, ms));
                        mu_n.iter()
                            .map(|&m| {
                                if !m.is_finite() {
                                    return [0.0; 2];
                                }
                                intervals.clone().map(|iv| {
                                    iv.iter()
                                        .map(|&(a, b)| phi((b - m) / sigma_n) - phi((a - m) / sigma_n))
                                        .sum::<f64>()
                                })
                            })
                            .collect()
                    }
                }
            };
            for (i, [slip, not_success]) in integrals.into_iter().enumerate() {
                (fail_row[i], ns_row[i]) = finish(p_sink[i], slip, not_success);
            }
            row_done();
        },
    );
}

impl RiskMap {
    /// The map for `robot` at `slope` on terrain with angle of repose `repose`, over
    /// `k_n_axis x k_s_axis` with `uncertainty` in every cell, by the shared-work algorithm
    /// of the module documentation (within 1e-6 of [`RiskMap::compute_by_quadrature`]).
    /// `row_done` is called once per finished k_s row, from any thread (for progress bars).
    pub fn compute(
        grid: &StrengthGrid<'_>,
        uncertainty: Uncertainty,
        row_done: &(dyn Fn() + Sync),
    ) -> RiskMap {
        Self::compute_blocked(grid, uncertainty, row_done, Blocks { columns: COLUMN_BLOCK, rows: ROW_BLOCK })
    }

    /// [`RiskMap::compute`] with the block sizes of the banded product given (the tests use
    /// small ones so that small grids cross block boundaries).
    fn compute_blocked(
        grid: &StrengthGrid<'_>,
        uncertainty: Uncertainty,
        row_done: &(dyn Fn() + Sync),
        blocks: Blocks,
    ) -> RiskMap {
        let StrengthGrid { robot, slope, k_n: k_n_axis, k_s: k_s_axis, .. } = *grid;
        let (nx, ny) = (k_n_axis.len(), k_s_axis.len());
        let beyond_repose = grid.beyond_repose();
        let ln = |v: f64| if v > 0.0 { v.ln() } else { f64::NEG_INFINITY };
        let mu_n: Vec<f64> = k_n_axis.values().into_iter().map(ln).collect();
        let mu_s: Vec<f64> = k_s_axis.values().into_iter().map(ln).collect();
        let (sigma_n, sigma_s) = (uncertainty.sigma_n(), uncertainty.sigma_s());
        let x_star = sinkage_threshold_k_n(robot, slope).ln();
        let p_sink = sinkage_probabilities(&mu_n, x_star, sigma_n);

        let columns = if beyond_repose {
            Columns::Certain(Vec::new())
        } else {
            Columns::new(robot, slope, &mu_n, &mu_s, x_star, uncertainty, blocks.columns)
        };

        let mut p_fail = crate::memory::zeroed(nx * ny);
        let mut p_not_success = crate::memory::zeroed(nx * ny);
        if let (false, Columns::Spread { nodes, blocks: column_blocks }) = (beyond_repose, &columns) {
            if sigma_s > 0.0 {
                banded_product(
                    nodes,
                    column_blocks,
                    &mu_s,
                    sigma_s,
                    &p_sink,
                    blocks.rows,
                    [&mut p_fail, &mut p_not_success],
                    row_done,
                );
                return RiskMap {
                    slope_deg: slope.degrees(),
                    beyond_repose,
                    k_n_axis: *k_n_axis,
                    k_s_axis: *k_s_axis,
                    uncertainty,
                    p_fail,
                    p_not_success,
                };
            }
        }
        let cells = Cells { mu_n: &mu_n, mu_s: &mu_s, p_sink: &p_sink, sigma_n, sigma_s, beyond_repose };
        cells_without_product(robot, slope, &columns, &cells, [&mut p_fail, &mut p_not_success], row_done);
        RiskMap {
            slope_deg: slope.degrees(),
            beyond_repose,
            k_n_axis: *k_n_axis,
            k_s_axis: *k_s_axis,
            uncertainty,
            p_fail,
            p_not_success,
        }
    }

    /// The same map by one adaptive quadrature per cell ([`super::regime_probabilities`]):
    /// the reference [`RiskMap::compute`] is tested against, a few milliseconds per cell.
    pub fn compute_by_quadrature(
        grid: &StrengthGrid<'_>,
        uncertainty: Uncertainty,
        row_done: &(dyn Fn() + Sync),
    ) -> RiskMap {
        let StrengthGrid { robot, slope, repose, k_n: k_n_axis, k_s: k_s_axis } = *grid;
        let k_n = k_n_axis.values();
        let k_s = k_s_axis.values();
        let rows: Vec<(Vec<f64>, Vec<f64>)> = k_s
            .par_iter()
            .map(|&ks| {
                let row = k_n
                    .iter()
                    .map(|&kn| {
                        let p = regime_probabilities(
                            robot,
                            slope,
                            &Ground { k_n: kn, k_s: ks, repose },
                            uncertainty,
                        );
                        (p.p_fail(), p.p_not_success())
                    })
                    .unzip();
                row_done();
                row
            })
            .collect();
        let (p_fail, p_not_success) =
            rows.into_iter().fold((Vec::new(), Vec::new()), |(mut a, mut b), (x, y)| {
                a.extend(x);
                b.extend(y);
                (a, b)
            });
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

    /// The largest difference between two maps over every cell of p_fail and p_not_success.
    fn largest_difference(a: &RiskMap, b: &RiskMap) -> f64 {
        a.p_fail
            .iter()
            .zip(&b.p_fail)
            .chain(a.p_not_success.iter().zip(&b.p_not_success))
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }
    use crate::model::tests::paper_robot;
    use crate::{AxisScale, RobotSpec};

    fn log_axis(min: f64, max: f64, n: usize) -> Axis {
        Axis::new("k", min, max, n, AxisScale::Log).unwrap()
    }

    /// Largest absolute difference between the fast map and the per-cell quadrature.
    fn worst(robot: &Robot, deg: f64, repose: Option<f64>, kn: &Axis, ks: &Axis, cv: (f64, f64)) -> f64 {
        let s = Slope::from_degrees(deg).unwrap();
        let repose = repose.map(|r| Slope::from_degrees(r).unwrap());
        let u = Uncertainty::new(cv.0, cv.1).unwrap();
        let grid = StrengthGrid::new(robot, s, repose, kn, ks);
        let fast = RiskMap::compute(&grid, u, &|| {});
        let slow = RiskMap::compute_by_quadrature(&grid, u, &|| {});
        largest_difference(&fast, &slow)
    }

    /// Random robots, slopes, spreads and grids (a small deterministic generator), every
    /// cell within 1e-6 of the quadrature; grids straddle the sinkage threshold and both
    /// critical strengths so every regime boundary is crossed.
    #[test]
    fn fast_map_agrees_with_the_quadrature_on_random_cases() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut rand = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let base = RobotSpec::paper_hexapod();
        let mut overall: f64 = 0.0;
        for case in 0..10 {
            let spec = RobotSpec {
                mass_kg: 0.2 + 1.2 * rand(),
                hip_height_m: 0.005 + 0.05 * rand(),
                level_step_m: (case % 5 == 4).then_some(0.05 + 0.04 * rand()),
                ..base.clone()
            };
            let robot = Robot::new(spec).unwrap();
            let deg = 30.0 * rand();
            let s = Slope::from_degrees(deg).unwrap();
            let k_star = sinkage_threshold_k_n(&robot, s);
            let cv = [(0.1, 0.2), (0.3, 0.5), (0.2, 0.01), (0.05, 0.05), (0.6, 1.0)][case % 5];
            // Columns from below the sinkage threshold to far above; rows across both curves.
            let kn = log_axis(k_star * (0.3 + 0.6 * rand()), k_star * (30.0 + 300.0 * rand()), 9);
            let ks = log_axis(2e3 * (1.0 + rand()), 1e7 * (1.0 + rand()), 7);
            let e = worst(&robot, deg, None, &kn, &ks, cv);
            eprintln!("case {case}: {deg:.1} deg, cv {cv:?}: worst error {e:.2e}");
            assert!(e < 1e-6, "case {case}: {deg} deg, cv {cv:?}, mass {}: error {e}", robot.mass());
            overall = overall.max(e);
        }
        assert!(overall > 0.0);
    }

    /// Sharp and degenerate cases: cv_s = 0.01 (a near-step in k_s), cv_n = 0 (no
    /// integral), cv_s = 0 (crossings), medians exactly on the sinkage boundary, beyond the
    /// angle of repose, and a linear k_s axis starting at 0.
    #[test]
    fn fast_map_agrees_in_sharp_and_degenerate_cases() {
        let r = paper_robot();
        let s = Slope::from_degrees(20.0).unwrap();
        let k_star = sinkage_threshold_k_n(&r, s);
        let kn = log_axis(k_star, k_star * 100.0, 7);
        let ks = log_axis(1e4, 1e7, 7);
        for cv in [(0.1, 0.01), (0.0, 0.2), (0.0, 0.0), (0.3, 0.0), (0.01, 0.3)] {
            let e = worst(&r, 20.0, None, &kn, &ks, cv);
            eprintln!("cv {cv:?}: worst error {e:.2e}");
            assert!(e < 1e-6, "cv {cv:?}: error {e}");
        }
        assert!(worst(&r, 26.0, Some(25.0), &kn, &ks, (0.1, 0.2)) < 1e-12);
        let lin = Axis::new("k_s", 0.0, 4e6, 5, AxisScale::Linear).unwrap();
        assert!(worst(&r, 10.0, None, &kn, &lin, (0.2, 0.3)) < 1e-6);
        // The first column sits exactly on the sinkage threshold: P(sinkage) = 1/2 there, and
        // just above it the level step is short, so slipping is likely too.
        let m = RiskMap::compute(
            &StrengthGrid::new(&r, s, None, &kn, &ks),
            Uncertainty::new(0.2, 0.2).unwrap(),
            &|| {},
        );
        assert!(m.p_fail_at(0, 6) > 0.5 && m.p_fail_at(0, 6) <= 1.0);
    }

    /// Largest absolute difference between the map with the given block sizes of the banded
    /// product and the per-cell adaptive quadrature (the reference, computed independently).
    fn worst_blocked(kn: &Axis, ks: &Axis, deg: f64, cv: (f64, f64), blocks: Blocks) -> f64 {
        let r = paper_robot();
        let s = Slope::from_degrees(deg).unwrap();
        let u = Uncertainty::new(cv.0, cv.1).unwrap();
        let grid = StrengthGrid::new(&r, s, None, kn, ks);
        let fast = RiskMap::compute_blocked(&grid, u, &|| {}, blocks);
        let slow = RiskMap::compute_by_quadrature(&grid, u, &|| {});
        largest_difference(&fast, &slow)
    }

    /// The banded matrix product across block edges (blocks of 1, 3 and 4 columns and rows,
    /// partial last blocks, and the default 64-column blocks on a 70-column grid), on columns
    /// packed around the sinkage threshold k_n* (where P(sinkage) goes from 1 to 0 and the
    /// short level step makes slipping likely): every cell within 1e-6 of the per-cell
    /// quadrature.
    #[test]
    fn banded_product_agrees_with_the_quadrature_near_the_sinkage_threshold() {
        let r = paper_robot();
        for deg in [5.0, 20.0] {
            let k_star = sinkage_threshold_k_n(&r, Slope::from_degrees(deg).unwrap());
            let kn = Axis::new("k_n", 0.9 * k_star, 1.3 * k_star, 9, AxisScale::Linear).unwrap();
            let ks = log_axis(3e4, 3e7, 7);
            for cv in [(0.1, 0.2), (0.02, 0.3), (0.3, 0.05)] {
                for blocks in [
                    Blocks { columns: 4, rows: 3 },
                    Blocks { columns: 1, rows: 1 },
                    Blocks { columns: 3, rows: 4 },
                ] {
                    let e = worst_blocked(&kn, &ks, deg, cv, blocks);
                    eprintln!("{deg} deg, cv {cv:?}, {blocks:?}: worst error {e:.2e}");
                    assert!(e < 1e-6, "{deg} deg, cv {cv:?}, {blocks:?}: error {e}");
                }
            }
            let kn = Axis::new("k_n", 0.95 * k_star, 3.0 * k_star, 70, AxisScale::Log).unwrap();
            let ks = log_axis(1e5, 1e7, 2);
            let e =
                worst_blocked(&kn, &ks, deg, (0.1, 0.2), Blocks { columns: COLUMN_BLOCK, rows: ROW_BLOCK });
            eprintln!("{deg} deg, 70 x 2 default blocks: worst error {e:.2e}");
            assert!(e < 1e-6, "{deg} deg, default blocks: error {e}");
        }
    }

    #[test]
    fn rows_are_reported_and_cells_are_the_regime_probabilities() {
        let r = paper_robot();
        let s = Slope::from_degrees(20.0).unwrap();
        let kn = log_axis(3e4, 3e6, 4);
        let ks = log_axis(1e5, 1e7, 3);
        let u = Uncertainty::new(0.2, 0.4).unwrap();
        let rows = std::sync::atomic::AtomicUsize::new(0);
        let map = RiskMap::compute(&StrengthGrid::new(&r, s, None, &kn, &ks), u, &|| {
            rows.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        });
        assert_eq!(rows.into_inner(), 3);
        assert_eq!(map.p_fail.len(), 12);
        let g = Ground::new(kn.value(2), ks.value(1)).unwrap();
        let p = regime_probabilities(&r, s, &g, u);
        assert!((map.p_fail_at(2, 1) - p.p_fail()).abs() < 1e-6);
        assert!((map.p_not_success_at(2, 1) - p.p_not_success()).abs() < 1e-6);
    }
}
