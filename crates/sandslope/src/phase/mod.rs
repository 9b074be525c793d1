//! Phase diagrams: the regime of every terrain `(k_n, k_s)` on a grid, at a fixed robot and
//! slope (docs/model.md §6; the paper's Section IV and its four-panel figure).
//!
//! The model separates: the normal equilibrium depth `d_n`, the level step `s*` and sinkage
//! depend on k_n only; the shear-equilibrium depth `d_s` and anchoring time `t1` depend on k_s
//! only. So [`PhaseMap::compute`] evaluates the expensive parts (square roots, arcsines) once
//! per grid column and row, and the net step of a cell is `s = s*_i scale_j - drag_j - slip_j`,
//! in exactly the operation order of [`crate::model::net_step`], so every cell is bit-for-bit
//! what [`crate::predict`] gives. Within a row that step is monotone in `s*_i`, so the two
//! regime thresholds (s > 0, s >= s_min) are found by binary search over the columns ranked by
//! `s*`, and each cell costs two integer comparisons. Rows run in parallel (rayon). Only the
//! regimes are stored (two bits per cell); the net step of any cell is recomputed on demand
//! from the per-axis parts by [`PhaseMap::step`].
//!
//! The contour `s = s_min` (the boundary of the success region, drawn black in the paper) is
//! extracted from the step field by marching squares in axis coordinates ([`crate::contour`]).

use rayon::prelude::*;
use serde::ser::{SerializeStruct, Serializer};
use serde::Serialize;

use crate::axis::Axis;
use crate::constants::G;
use crate::contour::{contour_on_cells, contour_segments, ContourSegment};
use crate::model::{
    anchoring_time, backward_slip, level_step_length, normal_equilibrium_depth, shear_equilibrium_depth,
};
use crate::regime::Regime;
use crate::robot::Robot;
use crate::slope::Slope;
use crate::strength_grid::StrengthGrid;

mod panel;

pub use panel::{PanelGround, PanelSummary, PhasePanel, TerrainGrid};

/// The k_s-only part of the net step at one grid row: `s = s* scale - drag - slip`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct StepTerms {
    /// `((T/2 - t1)/(T/2))^2`.
    scale: f64,
    /// `g sin(theta) t1 (T/2 - t1)`, the slip inherited during propulsion.
    drag: f64,
    /// Backward slip before anchoring `s1 = 1/2 g sin(theta) t1^2`.
    slip: f64,
}

impl StepTerms {
    /// The terms for anchoring time `t1`, in the operation order of `model::propulsion` and
    /// `model::backward_slip` (checked bit-for-bit against `predict` in the tests).
    fn new(robot: &Robot, slope: Slope, t1: f64) -> StepTerms {
        let half = robot.stance_duration();
        let left = half - t1;
        StepTerms {
            scale: (left / half).powi(2),
            drag: G * slope.sin() * t1 * left,
            slip: backward_slip(slope, t1),
        }
    }

    fn step(&self, level_step: f64) -> f64 {
        level_step * self.scale - self.drag - self.slip
    }
}

/// How many cells of a map fall in each regime.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct RegimeCounts {
    /// Cells in sinkage.
    pub sinkage: usize,
    /// Cells in slippage.
    pub slippage: usize,
    /// Cells in the metastable regime.
    pub metastable: usize,
    /// Cells in success.
    pub success: usize,
}

impl RegimeCounts {
    /// The count for `regime`.
    pub fn get(&self, regime: Regime) -> usize {
        match regime {
            Regime::Sinkage => self.sinkage,
            Regime::Slippage => self.slippage,
            Regime::Metastable => self.metastable,
            Regime::Success => self.success,
        }
    }

    /// All cells.
    pub fn total(&self) -> usize {
        self.sinkage + self.slippage + self.metastable + self.success
    }
}

/// The regime of every cell of a `(k_n, k_s)` grid for one robot at one slope.
///
/// Cell `(i, j)` is `k_n = k_n axis value i`, `k_s = k_s axis value j`.
#[derive(Debug, Clone)]
pub struct PhaseMap {
    slope: Slope,
    k_n_axis: Axis,
    k_s_axis: Axis,
    k_n: Vec<f64>,
    k_s: Vec<f64>,
    min_step: f64,
    beyond_repose: bool,
    /// Per k_n column: level step `s*`.
    level_step: Vec<f64>,
    /// Per k_n column: `d_n >= d_max`.
    sunk: Vec<bool>,
    /// Per k_s row: the step terms, `None` when the leg never anchors (`d_s > d_max`).
    terms: Vec<Option<StepTerms>>,
    /// Regime codes, indices into [`Regime::ALL`] (0 sinkage, 1 slippage, 2 metastable,
    /// 3 success), two bits each, four cells per byte (cell `i` of a row in bits `2 (i % 4)`
    /// of byte `i / 4`), row-major with `row_bytes` bytes per k_s row.
    codes: Vec<u8>,
    row_bytes: usize,
    counts: RegimeCounts,
}

/// What a phase map shares across its cells: the k_n-only parts per column, the k_s-only
/// parts per row, and the columns ranked by level step (see [`PhaseMap::compute`]).
struct Parts {
    /// Per k_n column: level step `s*`.
    level_step: Vec<f64>,
    /// Per k_n column: `d_n >= d_max`.
    sunk: Vec<bool>,
    /// Per k_s row: the step terms, `None` when the leg never anchors (`d_s > d_max`).
    terms: Vec<Option<StepTerms>>,
    beyond_repose: bool,
    min_step: f64,
    /// The columns that do not sink, by ascending level step.
    order: Vec<u32>,
    /// Per column: its place in `order` (0 where it sinks).
    rank: Vec<u32>,
    /// Per column: 0 where the legs sink, 1 elsewhere (a multiplier on the regime code).
    afloat: Vec<u8>,
}

impl Parts {
    fn new(robot: &Robot, slope: Slope, repose: Option<Slope>, k_n: &[f64], k_s: &[f64]) -> Parts {
        let d_max = robot.max_depth();
        // k_n-only parts, once per column.
        let (level_step, sunk): (Vec<f64>, Vec<bool>) = k_n
            .iter()
            .map(|&k| {
                let d_n = normal_equilibrium_depth(robot, slope, k);
                (level_step_length(robot, slope, d_n), d_n >= d_max)
            })
            .unzip();
        // k_s-only parts, once per row.
        let terms: Vec<Option<StepTerms>> = k_s
            .iter()
            .map(|&k| {
                anchoring_time(robot, shear_equilibrium_depth(robot, slope, k))
                    .map(|t1| StepTerms::new(robot, slope, t1))
            })
            .collect();
        let beyond_repose = repose.is_some_and(|r| slope.radians() >= r.radians());
        let afloat: Vec<u8> = sunk.iter().map(|&s| u8::from(!s)).collect();
        // In one row the step `s*_i scale - drag - slip` is a non-decreasing function of s*_i
        // (scale >= 0; each rounded operation is monotone), so with the columns ranked by s*
        // the cells with s > 0 (and s >= s_min) are exactly those ranked at or above a
        // threshold, found by binary search with the exact expression. Ties in s* give equal
        // steps, so they never straddle a threshold.
        let mut order: Vec<u32> = (0..k_n.len() as u32).filter(|&i| !sunk[i as usize]).collect();
        order.sort_by(|&a, &b| level_step[a as usize].total_cmp(&level_step[b as usize]));
        let mut rank = vec![0u32; k_n.len()];
        for (r, &i) in order.iter().enumerate() {
            rank[i as usize] = r as u32;
        }
        Parts { level_step, sunk, terms, beyond_repose, min_step: robot.min_step(), order, rank, afloat }
    }

    /// Row `j`'s two thresholds on the rank (the first ranks with `s > 0` and with
    /// `s >= s_min`), or `None` when every afloat cell of the row slips (no anchoring, or
    /// at/above repose).
    fn thresholds(&self, j: usize) -> Option<(u32, u32)> {
        match self.terms[j] {
            Some(t) if !self.beyond_repose => {
                let first = |ok: &dyn Fn(f64) -> bool| {
                    self.order.partition_point(|&i| !ok(t.step(self.level_step[i as usize]))) as u32
                };
                Some((first(&|s| s > 0.0), first(&|s| s >= self.min_step)))
            }
            _ => None,
        }
    }

    /// Cells per regime in a row with these thresholds.
    fn counts(&self, thresholds: Option<(u32, u32)>) -> [usize; 4] {
        let (nx, n_afloat) = (self.rank.len(), self.order.len());
        match thresholds {
            Some((r0, r1)) => {
                let (r0, r1) = (r0 as usize, r1 as usize);
                [nx - n_afloat, r0, r1 - r0, n_afloat - r1]
            }
            None => [nx - n_afloat, n_afloat, 0, 0],
        }
    }
}

/// The precedence of `regime::classify` as codes of `Regime::ALL`: sinkage 0; else
/// 1 + [s > 0] + [s >= s_min], from the column's rank against the row's thresholds (checked
/// against `predict` cell by cell in `every_cell_matches_predict`).
#[inline]
fn code(afloat: u8, rank: u32, r0: u32, r1: u32) -> u8 {
    afloat * (1 + u8::from(rank >= r0) + u8::from(rank >= r1))
}

/// The phase map written straight into caller-owned buffers in one pass, without building a
/// [`PhaseMap`]: the regime code of every cell (the index into [`Regime::ALL`]: 0 sinkage,
/// 1 slippage, 2 metastable, 3 success) into `codes` and, when given, the net step (NaN where
/// the leg never anchors) into `steps`, both row-major with one row per k_s value
/// (`k_n_axis.len() * k_s_axis.len()` elements, every one written). The per-column and per-row
/// parts and each row's two thresholds are [`PhaseMap::compute`]'s, so the values are its
/// `regime` and `step` bit for bit; rows run in parallel. Returns the cells per regime.
///
/// This is what Python's `sandslope.phase` runs: building the two-bit map and then unpacking
/// it cell by cell into the NumPy arrays took about twice as long as this one pass.
///
/// # Panics
/// If `codes` (or `steps`) is shorter than the grid.
pub fn write_phase(
    grid: &StrengthGrid<'_>,
    codes: &mut [std::mem::MaybeUninit<i8>],
    steps: Option<&mut [std::mem::MaybeUninit<f64>]>,
) -> RegimeCounts {
    write_phase_rows(grid, 0..grid.k_s.len(), codes, steps)
}

/// [`write_phase`] for the k_s rows `rows` only: `codes` (and `steps`) hold those rows,
/// `rows.len() * k_n_axis.len()` elements, row-major; the values are [`write_phase`]'s rows
/// bit for bit. A caller that must stay responsive (Python's `phase`, which checks for Ctrl-C
/// between blocks of rows) writes the grid a block at a time.
///
/// # Panics
/// If `rows` is not within the k_s axis, or a buffer is shorter than the rows.
pub fn write_phase_rows(
    grid: &StrengthGrid<'_>,
    rows: std::ops::Range<usize>,
    codes: &mut [std::mem::MaybeUninit<i8>],
    steps: Option<&mut [std::mem::MaybeUninit<f64>]>,
) -> RegimeCounts {
    let StrengthGrid { robot, slope, repose, k_n: k_n_axis, k_s: k_s_axis } = *grid;
    let (k_n, k_s) = (k_n_axis.values(), k_s_axis.values());
    // The row parts depend on the row's k_s alone: those of `rows` only.
    let parts = Parts::new(robot, slope, repose, &k_n, &k_s[rows.clone()]);
    let (nx, cells) = (k_n.len(), k_n.len() * rows.len());
    let write_codes = |j: usize, row: &mut [std::mem::MaybeUninit<i8>]| {
        let thresholds = parts.thresholds(j);
        match thresholds {
            Some((r0, r1)) => {
                for ((c, &a), &r) in row.iter_mut().zip(&parts.afloat).zip(&parts.rank) {
                    c.write(code(a, r, r0, r1) as i8);
                }
            }
            None => {
                for (c, &a) in row.iter_mut().zip(&parts.afloat) {
                    c.write(a as i8);
                }
            }
        }
        parts.counts(thresholds)
    };
    let write_steps = |j: usize, row: &mut [std::mem::MaybeUninit<f64>]| match parts.terms[j] {
        Some(t) => {
            for (out, &s) in row.iter_mut().zip(&parts.level_step) {
                out.write(t.step(s));
            }
        }
        None => {
            for out in row {
                out.write(f64::NAN);
            }
        }
    };
    let add = |a: [usize; 4], b: [usize; 4]| [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]];
    let codes = codes[..cells].par_chunks_mut(nx);
    let count = match steps {
        Some(steps) => codes
            .zip(steps[..cells].par_chunks_mut(nx))
            .enumerate()
            .map(|(j, (c, s))| {
                write_steps(j, s);
                write_codes(j, c)
            })
            .reduce(|| [0; 4], add),
        None => codes.enumerate().map(|(j, c)| write_codes(j, c)).reduce(|| [0; 4], add),
    };
    RegimeCounts { sinkage: count[0], slippage: count[1], metastable: count[2], success: count[3] }
}

impl PhaseMap {
    /// Classifies every cell of the grid `k_n_axis x k_s_axis` for `robot` at `slope` on a
    /// terrain whose angle of repose is `repose` (at or beyond it every cell slips).
    ///
    /// `row_done` is called once per finished k_s row, from any thread (for progress bars).
    pub fn compute(grid: &StrengthGrid<'_>, row_done: &(dyn Fn() + Sync)) -> PhaseMap {
        let StrengthGrid { robot, slope, repose, k_n: k_n_axis, k_s: k_s_axis } = *grid;
        let k_n = k_n_axis.values();
        let k_s = k_s_axis.values();
        let parts = Parts::new(robot, slope, repose, &k_n, &k_s);
        let nx = k_n.len();
        // Four columns per byte; the per-column data padded to a multiple of four (as sunk).
        let row_bytes = nx.div_ceil(4);
        let (mut afloat_p, mut rank_p) = (parts.afloat.clone(), parts.rank.clone());
        afloat_p.resize(4 * row_bytes, 0);
        rank_p.resize(4 * row_bytes, 0);
        // A row where nothing anchors: slippage (code 1) wherever the legs do not sink.
        let mut slipping_row = vec![0u8; row_bytes];
        pack_codes(&afloat_p, &mut slipping_row);
        // Zero-initialised, so the allocator hands out fresh pages without a fill pass.
        let mut codes = vec![0u8; row_bytes * k_s.len()];
        let count = codes
            .par_chunks_mut(row_bytes)
            .enumerate()
            .map_init(
                || vec![0u8; 4 * row_bytes],
                |scratch, (j, row)| {
                    let counts = match parts.thresholds(j) {
                        Some((r0, r1)) => {
                            for ((cell, &a), &r) in scratch.iter_mut().zip(&afloat_p).zip(&rank_p) {
                                *cell = code(a, r, r0, r1);
                            }
                            pack_codes(scratch, row);
                            parts.counts(Some((r0, r1)))
                        }
                        None => {
                            row.copy_from_slice(&slipping_row);
                            parts.counts(None)
                        }
                    };
                    row_done();
                    counts
                },
            )
            .reduce(|| [0; 4], |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]);
        let Parts { level_step, sunk, terms, beyond_repose, min_step, .. } = parts;
        let counts =
            RegimeCounts { sinkage: count[0], slippage: count[1], metastable: count[2], success: count[3] };
        PhaseMap {
            slope,
            k_n_axis: *k_n_axis,
            k_s_axis: *k_s_axis,
            k_n,
            k_s,
            min_step,
            beyond_repose,
            level_step,
            sunk,
            terms,
            codes,
            row_bytes,
            counts,
        }
    }

    /// The slope of this map.
    pub fn slope(&self) -> Slope {
        self.slope
    }

    /// The k_n axis.
    pub fn k_n_axis(&self) -> &Axis {
        &self.k_n_axis
    }

    /// The k_s axis.
    pub fn k_s_axis(&self) -> &Axis {
        &self.k_s_axis
    }

    /// The k_n values (columns), N/m^3.
    pub fn k_n(&self) -> &[f64] {
        &self.k_n
    }

    /// The k_s values (rows), N/m^3.
    pub fn k_s(&self) -> &[f64] {
        &self.k_s
    }

    /// Every regime, row-major: the `(j * k_n().len() + i)`-th is cell `(i, j)`.
    pub fn regimes(&self) -> impl ExactSizeIterator<Item = Regime> + '_ {
        let nx = self.k_n.len();
        (0..nx * self.k_s.len()).map(move |c| self.regime(c % nx, c / nx))
    }

    /// Whether the slope is at or beyond the terrain's angle of repose (every cell slips).
    pub fn beyond_repose(&self) -> bool {
        self.beyond_repose
    }

    /// The regime at column `i` (k_n) and row `j` (k_s).
    pub fn regime(&self, i: usize, j: usize) -> Regime {
        let byte = self.codes[j * self.row_bytes + i / 4];
        Regime::ALL[usize::from((byte >> (2 * (i % 4))) & 3)]
    }

    /// The net step `s` at cell `(i, j)`, m; `None` when the leg never anchors. Identical to
    /// `predict(..).step` for that cell.
    pub fn step(&self, i: usize, j: usize) -> Option<f64> {
        self.terms[j].map(|t| t.step(self.level_step[i]))
    }

    /// Row `j` (the `j`-th k_s value) in one pass: the regime code of every column (the index
    /// into [`Regime::ALL`]: 0 sinkage, 1 slippage, 2 metastable, 3 success) into `codes`
    /// and, when `steps` is given, the net step (NaN where the leg never anchors) into
    /// `steps`; each must be `k_n.len()` long (extra elements are left alone). The values are
    /// those of [`PhaseMap::regime`] and [`PhaseMap::step`], but the row's step terms are
    /// looked up once and its codes unpacked four at a time, instead of per cell. Every
    /// element of `codes[..nx]` (and `steps[..nx]`) is written.
    pub fn write_row(
        &self,
        j: usize,
        codes: &mut [std::mem::MaybeUninit<i8>],
        steps: Option<&mut [std::mem::MaybeUninit<f64>]>,
    ) {
        let nx = self.k_n.len();
        let packed = &self.codes[j * self.row_bytes..(j + 1) * self.row_bytes];
        for (out, &byte) in codes[..nx].chunks_mut(4).zip(packed) {
            for (k, c) in out.iter_mut().enumerate() {
                c.write(((byte >> (2 * k)) & 3) as i8);
            }
        }
        if let Some(steps) = steps {
            let steps = &mut steps[..nx];
            match self.terms[j] {
                Some(t) => {
                    for (out, &s) in steps.iter_mut().zip(&self.level_step) {
                        out.write(t.step(s));
                    }
                }
                None => {
                    for out in steps {
                        out.write(f64::NAN);
                    }
                }
            }
        }
    }

    /// The number of cells in each regime.
    pub fn counts(&self) -> RegimeCounts {
        self.counts
    }

    /// The contour `s = s_min` (the success boundary) as line segments, by marching squares
    /// over the net step of the cells where the legs neither sink nor fail to anchor.
    /// Empty at or beyond the angle of repose, where every cell slips.
    pub fn robust_contour(&self) -> Vec<ContourSegment> {
        self.step_contour(self.min_step)
    }

    /// [`PhaseMap::robust_contour`] traced over the sub-grid of cells `xi x yj` (ascending
    /// indices along k_n and k_s), as a figure that draws those cells needs it.
    pub fn robust_contour_on(&self, xi: &[usize], yj: &[usize]) -> Vec<ContourSegment> {
        if self.beyond_repose {
            return Vec::new();
        }
        let field = |i: usize, j: usize| match self.step(i, j) {
            Some(s) if !self.sunk[i] => s,
            _ => f64::NAN,
        };
        contour_on_cells(&self.k_n_axis, &self.k_s_axis, xi, yj, field, self.min_step)
    }

    /// The contour `s = level` (m) of the net step, by marching squares (see
    /// [`PhaseMap::robust_contour`]).
    pub fn step_contour(&self, level: f64) -> Vec<ContourSegment> {
        if self.beyond_repose {
            return Vec::new();
        }
        let nx = self.k_n.len();
        let field: Vec<f64> = (0..nx * self.k_s.len())
            .into_par_iter()
            .map(|c| {
                let (i, j) = (c % nx, c / nx);
                match self.step(i, j) {
                    Some(s) if !self.sunk[i] => s,
                    _ => f64::NAN,
                }
            })
            .collect();
        contour_segments(&self.k_n_axis, &self.k_s_axis, &field, level)
    }
}

impl Serialize for PhaseMap {
    /// The slope, axes, counts and every cell's regime code (0 sinkage, 1 slippage,
    /// 2 metastable, 3 success; docs/model.md §6), row-major like [`PhaseMap::regimes`].
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let codes: Vec<u8> = self.regimes().map(|r| r as u8).collect();
        let mut st = serializer.serialize_struct("PhaseMap", 6)?;
        st.serialize_field("slope_deg", &self.slope.degrees())?;
        st.serialize_field("k_n_axis", &self.k_n_axis)?;
        st.serialize_field("k_s_axis", &self.k_s_axis)?;
        st.serialize_field("beyond_repose", &self.beyond_repose)?;
        st.serialize_field("counts", &self.counts)?;
        st.serialize_field("regime_codes", &codes)?;
        st.end()
    }
}

/// Packs 2-bit codes, one per byte in `codes` (length `4 * packed.len()`), four to a byte:
/// code `4b + k` goes to bits `2k` of byte `b`.
fn pack_codes(codes: &[u8], packed: &mut [u8]) {
    for (byte, quad) in packed.iter_mut().zip(codes.chunks_exact(4)) {
        let v = u32::from_le_bytes([quad[0], quad[1], quad[2], quad[3]]) & 0x0303_0303;
        *byte = ((v | v >> 6 | v >> 12 | v >> 18) & 0xff) as u8;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::AxisScale;
    use crate::critical::{critical_shear_strength, StepTarget};
    use crate::model::{anchoring_threshold_k_s, predict, sinkage_threshold_k_n, tests::paper_robot};
    use crate::terrain::Ground;

    fn deg(d: f64) -> Slope {
        Slope::from_degrees(d).unwrap()
    }

    fn log_axis(min: f64, max: f64, n: usize) -> Axis {
        Axis::new("k", min, max, n, AxisScale::Log).unwrap()
    }

    fn map(robot: &Robot, slope: Slope, kn: &Axis, ks: &Axis) -> PhaseMap {
        PhaseMap::compute(&StrengthGrid::new(robot, slope, None, kn, ks), &|| {})
    }

    /// Every cell agrees with `predict`, regime and step bit for bit, including on a slope,
    /// with a measured level step and beyond the angle of repose.
    #[test]
    fn every_cell_matches_predict() {
        let r = paper_robot();
        let measured = Robot::new(crate::RobotSpec { level_step_m: Some(0.07), ..r.spec().clone() }).unwrap();
        let kn = log_axis(1e4, 1e7, 37);
        let ks = log_axis(1e3, 1e8, 41);
        for (robot, d, repose) in
            [(&r, 0.0, None), (&r, 20.0, None), (&measured, 24.0, None), (&r, 26.0, Some(25.0))]
        {
            let repose = repose.map(deg);
            let grid = StrengthGrid::new(robot, deg(d), repose, &kn, &ks);
            let m = PhaseMap::compute(&grid, &|| {});
            // The one-pass writer into caller buffers, with and without the steps.
            let cells = kn.len() * ks.len();
            let mut all_codes = vec![std::mem::MaybeUninit::new(-1i8); cells];
            let mut all_steps = vec![std::mem::MaybeUninit::new(-1.0f64); cells];
            let mut only_codes = vec![std::mem::MaybeUninit::new(-1i8); cells];
            let counts = write_phase(&grid, &mut all_codes, Some(&mut all_steps));
            assert_eq!(counts, m.counts());
            assert_eq!(write_phase(&grid, &mut only_codes, None), m.counts());
            // Block by block (Python's phase, checking for Ctrl-C between blocks): the same
            // cells, bit for bit, and the blocks' counts add up.
            let mut block_codes = vec![std::mem::MaybeUninit::new(-1i8); cells];
            let mut block_steps = vec![std::mem::MaybeUninit::new(-1.0f64); cells];
            let mut total = [0usize; 4];
            for rows in [0..1, 1..8, 8..21, 21..ks.len()] {
                let span = rows.start * kn.len()..rows.end * kn.len();
                let c = write_phase_rows(
                    &grid,
                    rows,
                    &mut block_codes[span.clone()],
                    Some(&mut block_steps[span]),
                );
                for (t, g) in total.iter_mut().zip(Regime::ALL) {
                    *t += c.get(g);
                }
            }
            assert_eq!(total, Regime::ALL.map(|g| m.counts().get(g)));
            for c in 0..cells {
                // SAFETY: initialised above (and overwritten by write_phase/write_phase_rows).
                let (a, b, s, t) = unsafe {
                    (
                        all_codes[c].assume_init(),
                        block_codes[c].assume_init(),
                        all_steps[c].assume_init(),
                        block_steps[c].assume_init(),
                    )
                };
                assert_eq!((a, s.to_bits()), (b, t.to_bits()), "write_phase_rows: {d} deg, cell {c}");
            }
            for c in 0..cells {
                let (i, j) = (c % kn.len(), c / kn.len());
                // SAFETY: initialised above (and overwritten by write_phase).
                let (a, s, b) = unsafe {
                    (all_codes[c].assume_init(), all_steps[c].assume_init(), only_codes[c].assume_init())
                };
                assert_eq!(
                    (Regime::ALL[a as usize], a),
                    (m.regime(i, j), b),
                    "write_phase: {d} deg, cell {c}"
                );
                assert_eq!(s.to_bits(), m.step(i, j).unwrap_or(f64::NAN).to_bits());
            }
            for (j, &k_s) in ks.values().iter().enumerate() {
                // The one-pass row writer too (37 columns: a partial last byte of codes).
                let mut codes = vec![std::mem::MaybeUninit::new(-1i8); kn.len()];
                let mut steps = vec![std::mem::MaybeUninit::new(-1.0f64); kn.len()];
                m.write_row(j, &mut codes, Some(&mut steps));
                for (i, &k_n) in kn.values().iter().enumerate() {
                    let p = predict(robot, deg(d), &Ground::new(k_n, k_s).unwrap().with_repose(repose));
                    assert_eq!(m.regime(i, j), p.regime, "{d} deg, k_n {k_n}, k_s {k_s}");
                    assert_eq!(m.step(i, j).map(f64::to_bits), p.step.map(f64::to_bits));
                    // SAFETY: initialised above (and overwritten by write_row).
                    let (code, step) = unsafe { (codes[i].assume_init(), steps[i].assume_init()) };
                    assert_eq!(
                        Regime::ALL[code as usize],
                        p.regime,
                        "write_row: {d} deg, k_n {k_n}, k_s {k_s}"
                    );
                    assert_eq!(step.to_bits(), p.step.unwrap_or(f64::NAN).to_bits());
                }
            }
        }
    }

    /// Hand-worked cells on each side of each boundary, for the paper robot on level sand
    /// (docs/model.md §3 to §6):
    /// - sinkage: d_n = d_max = 0.05 m at k_n* = 0.35*9.81/3/(4e-4*0.05) = 57225 N/m^3;
    /// - anchoring: d_s = d_max at k_s = F_a/(W d_max^2) = 0.146608/(0.01*0.0025) = 5864.3;
    ///   on level sand there is no slip, so anchoring means s > 0 (slippage below, metastable
    ///   just above);
    /// - success needs s = s* (1 - 2 t1)^2 >= 0.04. With k_n = 286125 (d_n = 0.01, s* = 0.08)
    ///   that is (1 - 2 t1)^2 >= 0.5, t1 <= (1 - 1/sqrt 2)/2 = 0.146447 s, leg phase
    ///   2 pi t1 - 0.252680 = 0.667471 rad, d_s <= 0.04 sin(0.667471) + 0.01 = 0.034760 m,
    ///   k_s >= 0.146608/(0.01 * 0.034760^2) = 12133.8.
    #[test]
    fn hand_worked_cells_on_each_side_of_each_boundary() {
        let r = paper_robot();
        let kn = Axis::new("k_n", 57_225.0 * 0.99, 286_125.0, 3, AxisScale::Linear).unwrap();
        // Column 0 sinks; 1 and 2 do not (column 2 is k_n = 286125 exactly).
        let ks_vals = [5_864.3 * 0.99, 5_864.3 * 1.01, 12_133.8 * 0.995, 12_133.8 * 1.005];
        for (j, &k_s) in ks_vals.iter().enumerate() {
            let ks = Axis::new("k_s", k_s, k_s * 2.0, 2, AxisScale::Linear).unwrap();
            let m = map(&r, Slope::LEVEL, &kn, &ks);
            assert_eq!(m.regime(0, 0), Regime::Sinkage, "k_s {k_s}");
            let want = [Regime::Slippage, Regime::Metastable, Regime::Metastable, Regime::Success][j];
            assert_eq!(m.regime(2, 0), want, "k_s {k_s}");
        }
        // Just above the sinkage threshold the legs do not sink.
        let kn = Axis::new("k_n", 57_225.0 * 1.01, 1e6, 2, AxisScale::Linear).unwrap();
        let ks = Axis::new("k_s", 1e8, 2e8, 2, AxisScale::Linear).unwrap();
        assert_ne!(map(&r, Slope::LEVEL, &kn, &ks).regime(0, 0), Regime::Sinkage);
    }

    /// On a slope the slippage boundary is where s = 0, found independently by the root
    /// finder; cells just either side of it fall on the right side.
    #[test]
    fn slope_boundaries_against_the_root_finder() {
        let r = paper_robot();
        let s = deg(24.0);
        let k_n = 7e5;
        for (target, below, above) in [
            (StepTarget::Progress, Regime::Slippage, Regime::Metastable),
            (StepTarget::Robust, Regime::Metastable, Regime::Success),
        ] {
            let k = critical_shear_strength(&r, s, k_n, false, target).unwrap();
            let kn = Axis::new("k_n", k_n, 2.0 * k_n, 2, AxisScale::Linear).unwrap();
            let ks = Axis::new("k_s", k * 0.999, k * 1.001, 2, AxisScale::Linear).unwrap();
            let m = map(&r, s, &kn, &ks);
            assert_eq!((m.regime(0, 0), m.regime(0, 1)), (below, above), "{target:?} at k_s {k}");
        }
        assert!(
            critical_shear_strength(&r, s, k_n, false, StepTarget::Progress).unwrap()
                > anchoring_threshold_k_s(&r, s)
        );
    }

    /// The marching-squares contour crosses every k_n column at the k_s the root finder gives
    /// for s = s_min, to within the interpolation error of the grid; and it crosses no column
    /// where no k_s is enough.
    #[test]
    fn contour_matches_the_root_finder() {
        let r = paper_robot();
        for d in [0.0, 24.0] {
            let s = deg(d);
            let kn = log_axis(3e4, 3e7, 121);
            let ks = log_axis(1e3, 1e9, 161);
            let m = map(&r, s, &kn, &ks);
            let segments = m.robust_contour();
            assert!(!segments.is_empty());
            let mut checked = 0;
            for (i, &k_n) in kn.values().iter().enumerate() {
                // Contour points on this column (vertical grid line), to relative 1e-9 in k_n.
                let on_column: Vec<f64> = segments
                    .iter()
                    .flat_map(|&(a, b)| [a, b])
                    .filter(|p| (p.0 / k_n - 1.0).abs() < 1e-9)
                    .map(|p| p.1)
                    .collect();
                match critical_shear_strength(&r, s, k_n, false, StepTarget::Robust) {
                    Ok(k) if k > ks.min() && k < ks.max() && i > 0 && i + 1 < kn.len() => {
                        assert!(!on_column.is_empty(), "{d} deg: no contour at k_n {k_n}");
                        for k_c in on_column {
                            // Linear interpolation of s in ln k_s over a step of ln(1e6)/160.
                            assert!((k_c.ln() - k.ln()).abs() < 5e-3, "{d} deg, k_n {k_n}: {k_c} vs {k}");
                        }
                        checked += 1;
                    }
                    Err(_) => {
                        assert!(on_column.is_empty(), "{d} deg: contour at k_n {k_n} where none exists")
                    }
                    _ => {}
                }
            }
            assert!(checked > 50, "{d} deg: only {checked} columns checked");
        }
    }

    /// Traced over every cell, the figure's sub-grid contour is the full contour; traced over
    /// every 4th cell, each of its points still lies on the critical strength (a coarser grid
    /// only interpolates over longer steps).
    #[test]
    fn contour_on_a_subgrid_follows_the_full_contour() {
        let r = paper_robot();
        let s = deg(10.0);
        let kn = log_axis(3e4, 3e7, 121);
        let ks = log_axis(1e3, 1e9, 161);
        let m = map(&r, s, &kn, &ks);
        let all_x: Vec<usize> = (0..kn.len()).collect();
        let all_y: Vec<usize> = (0..ks.len()).collect();
        assert_eq!(m.robust_contour_on(&all_x, &all_y), m.robust_contour());
        let sub_x: Vec<usize> = (0..kn.len()).step_by(4).collect();
        let sub_y: Vec<usize> = (0..ks.len()).step_by(4).collect();
        let coarse = m.robust_contour_on(&sub_x, &sub_y);
        assert!(!coarse.is_empty());
        let columns: Vec<f64> = sub_x.iter().map(|&i| kn.value(i)).collect();
        let mut checked = 0;
        for (k_n, k_s) in coarse.iter().flat_map(|&(a, b)| [a, b]) {
            // Points on a drawn column are interpolated in k_s only.
            if !columns.iter().any(|c| (k_n / c - 1.0).abs() < 1e-9) {
                continue;
            }
            let k = critical_shear_strength(&r, s, k_n, false, StepTarget::Robust).unwrap();
            // Linear interpolation errs as the square of the step: 4x the step of
            // `contour_matches_the_root_finder` (bound 5e-3) gives 16 x 5e-3 = 0.08.
            assert!((k_s.ln() - k.ln()).abs() < 0.08, "k_n {k_n}: {k_s} vs {k}");
            checked += 1;
        }
        assert!(checked > 10, "only {checked} points checked");
    }

    #[test]
    fn sinkage_column_boundary_is_the_threshold_and_moves_with_mass() {
        // The sinkage threshold scales with m cos(theta): 1 kg sinks where 0.35 kg does not.
        let light = paper_robot();
        let heavy = light.with_mass(1.0).unwrap();
        let k_star = sinkage_threshold_k_n(&light, Slope::LEVEL);
        let kn = Axis::new("k_n", k_star * 1.5, k_star * 2.0, 2, AxisScale::Linear).unwrap();
        let ks = log_axis(1e7, 1e8, 2);
        assert_ne!(map(&light, Slope::LEVEL, &kn, &ks).regime(0, 1), Regime::Sinkage);
        assert_eq!(map(&heavy, Slope::LEVEL, &kn, &ks).regime(0, 1), Regime::Sinkage);
    }

    #[test]
    fn counts_add_up_and_progress_is_reported_per_row() {
        let r = paper_robot();
        let kn = log_axis(1e4, 1e7, 30);
        let ks = log_axis(1e3, 1e8, 20);
        let rows = std::sync::atomic::AtomicUsize::new(0);
        let m = PhaseMap::compute(&StrengthGrid::new(&r, deg(10.0), None, &kn, &ks), &|| {
            rows.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        });
        assert_eq!(rows.into_inner(), 20);
        let c = m.counts();
        assert_eq!(c.total(), 600);
        assert!(Regime::ALL.iter().all(|&g| c.get(g) > 0), "{c:?}");
        for g in Regime::ALL {
            assert_eq!(c.get(g), m.regimes().filter(|&r| r == g).count(), "{g}");
        }
    }
}
