//! The work a risk map shares between its cells (docs/phase-and-risk.md; the algorithm is
//! told in [`super::map`]): the Gauss-Legendre panels over `x = ln k_n` with the two critical
//! strengths at every node (step 1), the banded weight matrix of the columns (step 2), and the
//! conditional integrals of every cell as one banded matrix product per curve (steps 3 and 4).

use rayon::prelude::*;

use super::quadrature::{density, phi, NormalCdfTable, Z_MAX};
use crate::critical::ln_critical_closed_form;
use crate::model::{level_step_length, normal_equilibrium_depth};
use crate::robot::Robot;
use crate::slope::Slope;

/// 5-point Gauss-Legendre nodes and weights on `[-1, 1]`.
const GL_X: [f64; 5] =
    [-0.906_179_845_938_664, -0.538_469_310_105_683_1, 0.0, 0.538_469_310_105_683_1, 0.906_179_845_938_664];
const GL_W: [f64; 5] = [
    0.236_926_885_056_189_1,
    0.478_628_670_499_366_5,
    0.568_888_888_888_888_9,
    0.478_628_670_499_366_5,
    0.236_926_885_056_189_1,
];
/// Beyond this many standard deviations the map takes a normal CDF as 0 or 1: off by at most
/// `Phi(-7)` = 1.28e-12 per node, so by at most that per cell (a cell's weights sum to at most
/// 1). Measured on `risk --map` 1024 x 1024 at cv 0.1/0.2 (`perf stat`, CPU time, 15 runs):
/// 9 standard deviations, where the CDF is 0 or 1 to within 1.2e-19, took a median 29.9 ms
/// single-threaded, 7 took 27.8 ms (the mixed band of each task is 7/9 as wide).
pub(super) const Z_FLAT: f64 = 7.0;
/// Narrowest panel, in ln k_n.
const MIN_PANEL: f64 = 1e-10;

/// The two critical strengths `(ln k_s for s > 0, ln k_s for s >= s_min)` at `x = ln k_n`
/// (infinite where no strength suffices or the legs sink), and which branch each is on
/// (capped at the anchoring threshold, finite), to find kinks.
pub(super) fn curves(robot: &Robot, slope: Slope, x: f64) -> ([f64; 2], [(bool, bool); 2]) {
    let d_n = normal_equilibrium_depth(robot, slope, x.exp());
    if d_n >= robot.max_depth() {
        return ([f64::INFINITY; 2], [(false, false); 2]);
    }
    let s_star = level_step_length(robot, slope, d_n);
    let (g0, c0) = ln_critical_closed_form(robot, slope, s_star, 0.0);
    let (g1, c1) = ln_critical_closed_form(robot, slope, s_star, robot.min_step());
    ([g0, g1], [(c0, g0.is_finite()), (c1, g1.is_finite())])
}

/// The integration nodes of one map: positions, Gauss-Legendre weights and the two curves.
pub(super) struct Nodes {
    pub(super) x: Vec<f64>,
    pub(super) w: Vec<f64>,
    pub(super) g: [Vec<f64>; 2],
    /// Per segment, the panel ends with the curves there (for the crossings when
    /// `sigma_s = 0`).
    pub(super) ends: Vec<Vec<(f64, [f64; 2])>>,
}

/// Builds the nodes on `[lo, hi]` (see the module documentation). `band` is the range of g
/// within which some row's conditional probability is not flat (empty when `sigma_s = 0`).
pub(super) fn build_nodes(
    robot: &Robot,
    slope: Slope,
    segments: &[(f64, f64)],
    sigma_n: f64,
    sigma_s: f64,
    band: (f64, f64),
) -> Nodes {
    let mut nodes = Nodes { x: Vec::new(), w: Vec::new(), g: [Vec::new(), Vec::new()], ends: Vec::new() };
    let base = sigma_n;
    let resolves = |ga: [f64; 2], gb: [f64; 2]| {
        sigma_s == 0.0
            || (0..2).all(|t| {
                let (a, b) = (ga[t].min(gb[t]), ga[t].max(gb[t]));
                !a.is_finite() || !b.is_finite() || b < band.0 || a > band.1 || b - a <= sigma_s
            })
    };
    for &(lo, hi) in segments {
        let mut a = lo;
        let (mut ga, mut sa) = curves(robot, slope, a);
        let mut ends = vec![(a, ga)];
        while a < hi {
            let mut b = (a + base).min(hi);
            let (mut gb, mut sb) = curves(robot, slope, b);
            // Split at a kink or where a curve becomes infinite: bisect for the switch.
            if sb != sa {
                let (mut l, mut h) = (a, b);
                for _ in 0..200 {
                    let m = 0.5 * (l + h);
                    if m <= l || m >= h {
                        break;
                    }
                    if curves(robot, slope, m).1 == sa {
                        l = m;
                    } else {
                        h = m;
                    }
                }
                b = if l > a { l } else { h };
                (gb, sb) = curves(robot, slope, b);
            }
            // Narrower where a curve moves fast within reach of the rows' medians.
            while b - a > MIN_PANEL && !resolves(ga, gb) {
                b = a + 0.5 * (b - a);
                (gb, sb) = curves(robot, slope, b);
            }
            let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
            for (&u, &wu) in GL_X.iter().zip(&GL_W) {
                let x = mid + half * u;
                let (g, _) = curves(robot, slope, x);
                nodes.x.push(x);
                nodes.w.push(half * wu);
                nodes.g[0].push(g[0]);
                nodes.g[1].push(g[1]);
            }
            ends.push((b, gb));
            (a, ga, sa) = (b, gb, sb);
        }
        nodes.ends.push(ends);
    }
    nodes
}

/// `(p_fail, p_not_success)` of a cell: `P(sinkage)` plus the conditional integrals
/// `[P(slip, not sunk), P(not success, not sunk)]`, clamped to what is consistent.
pub(super) fn finish(sink: f64, slip: f64, not_success: f64) -> (f64, f64) {
    let not_sunk = 1.0 - sink;
    let slip = slip.clamp(0.0, not_sunk);
    let not_success = not_success.clamp(slip, not_sunk);
    (sink + slip, sink + not_success)
}

/// `Phi((g - mu) / sigma)` with the flat tails short-cut.
pub(super) fn cdf(g: f64, mu: f64, sigma: f64) -> f64 {
    let z = (g - mu) / sigma;
    if z > Z_FLAT {
        1.0
    } else if z < -Z_FLAT {
        0.0
    } else {
        phi(z)
    }
}

/// The intervals of `x` where `g_t(x) > mu`, from the curves at the panel ends of each
/// segment (crossings refined by bisection on the closed form), for `sigma_s = 0`.
pub(super) fn above(
    robot: &Robot,
    slope: Slope,
    segments: &[Vec<(f64, [f64; 2])>],
    t: usize,
    mu: f64,
) -> Vec<(f64, f64)> {
    let crossing = |l: f64, h: f64, l_above: bool| {
        let (mut l, mut h) = (l, h);
        for _ in 0..200 {
            let m = 0.5 * (l + h);
            if m <= l || m >= h {
                break;
            }
            if (curves(robot, slope, m).0[t] > mu) == l_above {
                l = m;
            } else {
                h = m;
            }
        }
        0.5 * (l + h)
    };
    let mut out = Vec::new();
    for ends in segments {
        let mut start = None;
        for (k, &(x, g)) in ends.iter().enumerate() {
            let now = g[t] > mu;
            match (start, now) {
                (None, true) => start = Some(if k == 0 { x } else { crossing(ends[k - 1].0, x, false) }),
                (Some(s), false) => {
                    out.push((s, crossing(ends[k - 1].0, x, true)));
                    start = None;
                }
                _ => {}
            }
        }
        if let (Some(s), Some(&(x, _))) = (start, ends.last()) {
            out.push((s, x));
        }
    }
    out
}

/// Columns (k_n medians) per block of the banded weight matrix. Each block is multiplied as a
/// dense matrix over the nodes any of its columns weighs, so a wider block does more work on
/// zero weights while a narrower one makes more, smaller products. Measured on `risk --map`
/// 1024 x 1024 at cv 0.1/0.2 (`perf stat`, CPU time of the whole process, 5 runs each on the
/// shared 2-core machine): 32, 64 and 128 columns all took 43-47 ms, within the noise.
pub(super) const COLUMN_BLOCK: usize = 64;
/// Rows (k_s medians) per parallel task: their conditional probabilities (2 x 32 rows x the
/// nodes) stay in cache while every column block is multiplied with them. Same measurement:
/// 32, 64 and 128 rows took 43-47 ms, 16 rows 47-64 ms (each weight block is packed once
/// per task, so smaller tasks pack more).
pub(super) const ROW_BLOCK: usize = 32;

/// Block sizes of the banded product.
#[derive(Debug, Clone, Copy)]
pub(super) struct Blocks {
    pub(super) columns: usize,
    pub(super) rows: usize,
}

/// Consecutive columns `i0..i1` of the map, the nodes `q0..q1` any of them weighs, and the
/// weights `w_q phi((x_q - mu_n)/sigma_n)/sigma_n` as a dense `(q1 - q0) x (i1 - i0)`
/// row-major matrix, zero outside each column's window `mu_n +- 8.5 sigma_n`.
pub(super) struct ColumnBlock {
    pub(super) i0: usize,
    pub(super) i1: usize,
    pub(super) q0: usize,
    pub(super) q1: usize,
    pub(super) w: Vec<f64>,
}

/// The weight matrix of every column (k_n median), in blocks of `width` columns.
pub(super) fn column_blocks(nodes: &Nodes, mu_n: &[f64], sigma_n: f64, width: usize) -> Vec<ColumnBlock> {
    let starts: Vec<usize> = (0..mu_n.len()).step_by(width.max(1)).collect();
    starts
        .par_iter()
        .map(|&i0| {
            let i1 = (i0 + width.max(1)).min(mu_n.len());
            let windows: Vec<Option<(usize, usize)>> = mu_n[i0..i1]
                .iter()
                .map(|&m| {
                    m.is_finite().then(|| {
                        (
                            nodes.x.partition_point(|&x| x < m - Z_MAX * sigma_n),
                            nodes.x.partition_point(|&x| x <= m + Z_MAX * sigma_n),
                        )
                    })
                })
                .collect();
            let q0 = windows.iter().flatten().map(|w| w.0).min().unwrap_or(0);
            let q1 = windows.iter().flatten().map(|w| w.1).max().unwrap_or(0).max(q0);
            let width = i1 - i0;
            let mut w = vec![0.0; (q1 - q0) * width];
            for (c, (window, &m)) in windows.iter().zip(&mu_n[i0..i1]).enumerate() {
                for q in window.map_or(0..0, |(a, b)| a..b) {
                    w[(q - q0) * width + c] = nodes.w[q] * density((nodes.x[q] - m) / sigma_n) / sigma_n;
                }
            }
            ColumnBlock { i0, i1, q0, q1, w }
        })
        .collect()
}

/// The conditional integrals of every cell as one matrix product per curve,
/// `out_t = C_t W^T`, where `C_t[j][q] = Phi((g_t(x_q) - mu_s_j)/sigma_s)` (rows x nodes) and
/// `W` is the banded weight matrix of the column blocks: per task of `row_block` rows, `C_t` is
/// built once and multiplied by each block with `matrixmultiply`'s packed, vectorised dgemm.
///
/// Most of `C_t` is exactly 0 or 1 (beyond 7 standard deviations `cdf` returns those without
/// an erfc): on `risk --map` 1024 x 1024 at cv 0.1/0.2, only 26% (p_fail) and 18%
/// (p_not_success) of the nodes are neither for some row of a 32-row task. So per task and
/// column block only the nodes from the first to the last such node go through the product;
/// the nodes outside that are 1 for every row of the task add the block's weights summed
/// over them (the same terms, times 1), those that are 0 add nothing. That cut the product's
/// work about four times.
///
/// Each task then adds `P(sinkage)` of each column (`p_sink`) to its rows while they are in
/// cache ([`finish`]). `out` is `[p_fail, p_not_success]`, row-major with `nx` columns;
/// `row_done` is called once per row.
#[allow(clippy::too_many_arguments)]
pub(super) fn banded_product(
    nodes: &Nodes,
    blocks: &[ColumnBlock],
    mu_s: &[f64],
    sigma_s: f64,
    p_sink: &[f64],
    row_block: usize,
    out: [&mut [f64]; 2],
    row_done: &(dyn Fn() + Sync),
) {
    let nq = nodes.x.len();
    let nx = blocks.last().map_or(0, |b| b.i1);
    let row_block = row_block.max(1);
    let [fail, not_success] = out;
    let table = NormalCdfTable::new();
    if nx == 0 {
        mu_s.iter().for_each(|_| row_done());
        return;
    }
    fail.par_chunks_mut(row_block * nx)
        .zip(not_success.par_chunks_mut(row_block * nx))
        .zip(mu_s.par_chunks(row_block))
        .for_each(|((fail, not_success), ms)| {
            let rows = ms.len();
            let mut ones = Vec::new();
            for (t, out) in [&mut *fail, &mut *not_success].into_iter().enumerate() {
                // Per node: 1 for every row of the task, 0 for every row, or neither (mixed).
                // A node whose argument is beyond +-7 for the task's extreme medians is flat
                // for all its rows (the rounded `(g - mu) / sigma` is monotone in mu), so
                // `cdf` would give exactly 1 or 0: filled without evaluating it per row.
                let (lo, hi) =
                    ms.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &m| (a.min(m), b.max(m)));
                let (mut all_one, mut all_zero) = (vec![false; nq], vec![false; nq]);
                for ((o, z), &g) in all_one.iter_mut().zip(all_zero.iter_mut()).zip(&nodes.g[t]) {
                    *o = (g - hi) / sigma_s > Z_FLAT;
                    *z = (g - lo) / sigma_s < -Z_FLAT;
                }
                let mut c = Vec::with_capacity(rows * nq);
                for &m in ms {
                    c.extend(nodes.g[t].iter().zip(all_one.iter().zip(&all_zero)).map(|(&g, (&o, &z))| {
                        if o {
                            1.0
                        } else if z {
                            0.0
                        } else {
                            table.cdf((g - m) / sigma_s)
                        }
                    }));
                }
                for b in blocks {
                    let n = b.i1 - b.i0;
                    let (q0, q1) = (b.q0, b.q1);
                    let mixed = |q: &usize| !all_one[*q] && !all_zero[*q];
                    let ma = (q0..q1).find(mixed).unwrap_or(q1);
                    let mb = (ma..q1).rev().find(mixed).map_or(ma, |q| q + 1);
                    // The flat nodes outside [ma, mb) where every row is 1: their weights, summed.
                    ones.clear();
                    ones.resize(n, 0.0);
                    for q in (q0..ma).chain(mb..q1).filter(|&q| all_one[q]) {
                        let w = &b.w[(q - q0) * n..(q - q0 + 1) * n];
                        for (s, &w) in ones.iter_mut().zip(w) {
                            *s += w;
                        }
                    }
                    for row in out.chunks_mut(nx) {
                        row[b.i0..b.i1].copy_from_slice(&ones);
                    }
                    if ma == mb {
                        continue;
                    }
                    // SAFETY: A is `rows x (mb - ma)` with row stride `nq` from node `ma`,
                    // within `c` (`rows * nq` long) since `mb <= q1 <= nq`; B is rows
                    // `ma - q0 .. mb - q0` of the block's `(q1 - q0) x n` row-major weights;
                    // C is `rows x n` with row stride `nx` from column `i0`, within `out`
                    // (`rows * nx` long) since `i0 + n = i1 <= nx`, initialised above
                    // (beta = 1 adds to it), and aliases neither A nor B.
                    unsafe {
                        matrixmultiply::dgemm(
                            rows,
                            mb - ma,
                            n,
                            1.0,
                            c.as_ptr().add(ma),
                            nq as isize,
                            1,
                            b.w.as_ptr().add((ma - q0) * n),
                            n as isize,
                            1,
                            1.0,
                            out.as_mut_ptr().add(b.i0),
                            nx as isize,
                            1,
                        );
                    }
                }
            }
            for ((f, n), &m) in fail.chunks_mut(nx).zip(not_success.chunks_mut(nx)).zip(ms) {
                for ((f, n), &sink) in f.iter_mut().zip(n.iter_mut()).zip(p_sink) {
                    // k_s = 0 (a linear axis from 0): every leg that does not sink slips.
                    let (slip, not_success) =
                        if m == f64::NEG_INFINITY { (1.0 - sink, 1.0 - sink) } else { (*f, *n) };
                    (*f, *n) = finish(sink, slip, not_success);
                }
            }
            (0..rows).for_each(|_| row_done());
        });
}
