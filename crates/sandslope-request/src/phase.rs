//! [`PhaseRequest`]: phase diagrams, the regime of every terrain (k_n, k_s) on a grid, one
//! panel per (mass, slope) (the paper's Section IV figure); [`PhaseMapRequest`]: one map over
//! axes given as values (Python's `phase`).

use std::sync::atomic::{AtomicBool, Ordering};

use serde::{Deserialize, Serialize};

use sandslope::limits::MAX_PHASE_CELLS;
use sandslope::memory::uninit;
use sandslope::{
    write_phase_rows, Axis, PanelSummary, PhasePanel, RegimeCounts, Robot, SignedSlope, Slope, StrengthGrid,
    Terrain, TerrainGrid,
};

use crate::error::{RequestError, Result};
use crate::field::{Field, Fields, Table};
use crate::grammar::{self, AxisRange};
use crate::params::Params;
use crate::scenario::{load_terrain, RobotRequest, ROBOT, TERRAIN};

/// Default number of grid points per axis.
pub const DEFAULT_POINTS: usize = 400;

/// The inputs of `phase` (and `/api/phase`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseRequest {
    /// Normal-resistance axis, N/m^3 (field `k-n`; default the terrain's k_n / 100 to x 100,
    /// 400 points, log).
    pub k_n: Option<AxisRange>,
    /// Shear-strength axis, N/m^3 (field `k-s`; default the terrain's k_s / 1000 to x 100, 400
    /// points, log).
    pub k_s: Option<AxisRange>,
    /// Slopes along the direction of travel, degrees, one panel each (field `slope`, a comma
    /// list; default 0).
    pub slopes: Vec<f64>,
    /// Total masses, kg, one panel row each (field `mass`, a comma list; default the robot's).
    pub masses: Vec<f64>,
    /// The robot (its `mass` unused: the masses are the panels').
    pub robot: RobotRequest,
    /// A terrain TOML file or a built-in preset (field `terrain`).
    pub terrain: String,
}

/// A phase request checked and its grid decided, before any cell is computed.
pub struct PhaseGrid {
    /// One robot per mass.
    pub robots: Vec<Robot>,
    /// The masses, kg.
    pub masses: Vec<f64>,
    /// The slopes as given, degrees (signed).
    pub slopes_deg: Vec<f64>,
    /// The terrain.
    pub terrain: Terrain,
    /// The grid's k_n axis.
    pub k_n_axis: Axis,
    /// The grid's k_s axis.
    pub k_s_axis: Axis,
}

/// `--k-n`: the grid's normal-resistance axis.
pub const K_N_AXIS: Field = Field::text("k-n", "MIN:MAX:N[:log|:lin]")
    .keyword("k_n_axis")
    .unit("N/m^3")
    .range("0 < MIN < MAX, N at least 2")
    .help(
        "Normal-resistance axis, N/m^3: MIN:MAX:N with optional :log (default) or :lin. Default: \
     the terrain's k_n / 100 to x 100, 400 points, log.",
    );
/// `--k-s`: the grid's shear-strength axis.
pub const K_S_AXIS: Field = Field::text("k-s", "MIN:MAX:N[:log|:lin]")
    .keyword("k_s_axis")
    .unit("N/m^3")
    .range("0 < MIN < MAX, N at least 2")
    .help(
        "Shear-strength axis, N/m^3: MIN:MAX:N with optional :log (default) or :lin. Default: the \
     terrain's k_s / 1000 to x 100, 400 points, log.",
    );
/// `--slope`: the panels' slopes.
pub const SLOPE: Field = Field::text("slope", "DEG[,DEG...]")
    .keyword("slope_deg")
    .unit("deg")
    .default("0")
    .range("-90 to 90 each")
    .help("Slope(s) along the direction of travel, degrees, comma-separated (one panel each)");
/// `--mass`: the panel rows' total masses.
pub const MASS: Field = Field::text("mass", "KG[,KG...]")
    .keyword("mass_kg")
    .unit("kg")
    .range("greater than 0 each")
    .help("Total robot mass(es), kg, comma-separated (one panel row each). Default: the robot's.");

/// `phase`'s own fields (the robot's, without its mass, and the terrain's are
/// [`crate::scenario`]'s).
pub const FIELDS: Table = Table { command: "phase", fields: &[K_N_AXIS, K_S_AXIS, SLOPE, MASS] };

impl Fields for PhaseRequest {
    const TABLE: Table = FIELDS;
}

/// Reads a comma list of numbers given to `field` (else its default).
fn number_list(p: &mut Params<'_>, field: &Field) -> Result<Option<Vec<f64>>> {
    let Some(text) = field.text_in(p)? else { return Ok(None) };
    text.split(',')
        .map(|s| {
            s.trim().parse::<f64>().map_err(|_| {
                RequestError::invalid(
                    field.flag,
                    format!("{}: `{}` is not a number (in {text})", field.long(), s.trim()),
                )
            })
        })
        .collect::<Result<Vec<f64>>>()
        .map(Some)
}

impl PhaseRequest {
    /// Reads the fields of a phase request ([`FIELDS`], the robot's and the terrain's); refuses
    /// any other key.
    pub fn from_params(params: &[(String, String)]) -> Result<PhaseRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let robot = RobotRequest {
            robot: ROBOT.text_in(&mut p)?.unwrap_or_default().to_string(),
            mass: None,
            overrides: RobotRequest::overrides_from_params(&mut p)?,
        };
        let terrain = TERRAIN.text_in(&mut p)?.unwrap_or_default().to_string();
        Self::read(p, robot, terrain)
    }

    /// The command line's request: its own fields from `params` (the flags given, by
    /// [`FIELDS`]), the robot and the terrain already read from the flags it shares with other
    /// commands.
    pub fn with_robot(
        params: &[(String, String)],
        robot: RobotRequest,
        terrain: String,
    ) -> Result<PhaseRequest> {
        Self::read(Params::new(FIELDS.command, params), robot, terrain)
    }

    /// Reads the request's own fields from `p`, each by its row of [`FIELDS`], and refuses any
    /// key left.
    fn read(mut p: Params<'_>, robot: RobotRequest, terrain: String) -> Result<PhaseRequest> {
        let mut axis = |field: &'static Field| -> Result<Option<AxisRange>> {
            field.text_in(&mut p)?.map(|t| grammar::parse_strength_axis(field.flag, t)).transpose()
        };
        let (k_n, k_s) = (axis(&K_N_AXIS)?, axis(&K_S_AXIS)?);
        let slopes = number_list(&mut p, &SLOPE)?.unwrap_or_default();
        let masses = number_list(&mut p, &MASS)?.unwrap_or_default();
        p.finish()?;
        Ok(PhaseRequest { k_n, k_s, slopes, masses, robot, terrain })
    }

    /// Reads the robot and terrain, checks every field and decides the grid (at most
    /// `max_cells` cells over all panels), computing nothing yet.
    pub fn grid(&self, max_cells: u128) -> Result<PhaseGrid> {
        let base = self.robot.load()?;
        let terrain = load_terrain(&self.terrain)?;
        let masses = if self.masses.is_empty() { vec![base.mass()] } else { self.masses.clone() };
        let robots = masses
            .iter()
            .map(|&m| base.with_mass(m).map_err(|e| RequestError::invalid(MASS.flag, e.renamed(MASS.long()))))
            .collect::<Result<Vec<Robot>>>()?;
        if self.slopes.is_empty() {
            return Err(RequestError::invalid(
                SLOPE.flag,
                format!("{} gives no slope: give at least one", SLOPE.long()),
            ));
        }
        let slopes = self
            .slopes
            .iter()
            .map(|&d| {
                Slope::from_signed_degrees(d)
                    .map_err(|e| RequestError::invalid(SLOPE.flag, e.renamed(SLOPE.long())))
            })
            .collect::<Result<Vec<Slope>>>()?;
        let grounds: Vec<_> = slopes.iter().map(|&s| terrain.at(s)).collect();
        let axis = |field: &Field, given: Option<AxisRange>, values: Vec<f64>, down: f64| match given {
            Some(range) => grammar::axis(field.flag, range),
            None => Axis::log_around(&field.long(), &values, down, 100.0, DEFAULT_POINTS)
                .map_err(|e| RequestError::invalid(field.flag, e)),
        };
        let k_n_axis = axis(&K_N_AXIS, self.k_n, grounds.iter().map(|g| g.k_n).collect(), 100.0)?;
        let k_s_axis = axis(&K_S_AXIS, self.k_s, grounds.iter().map(|g| g.k_s).collect(), 1000.0)?;
        // Guards against a typo such as 100000 points per axis: the maps are kept in memory
        // at two bits per cell.
        let panels = robots.len() * slopes.len();
        let cells = panels as u128 * k_n_axis.len() as u128 * k_s_axis.len() as u128;
        if cells > max_cells {
            let side = if max_cells >= 4096 * 4096 { 4096 } else { 1u128 << (max_cells.max(1).ilog2() / 2) };
            return Err(RequestError::invalid(
                K_N_AXIS.flag,
                format!(
                    "{} and {} give {cells} cells over {panels} panel(s); at most {max_cells} are allowed (e.g. {side} x {side} per panel is {})",
                    K_N_AXIS.long(),
                    K_S_AXIS.long(),
                    side * side
                ),
            ));
        }
        Ok(PhaseGrid { robots, masses, slopes_deg: self.slopes.clone(), terrain, k_n_axis, k_s_axis })
    }

    /// The answer (what `phase --json` prints): each panel's summary, at most `max_cells` grid
    /// cells computed.
    pub fn answer(&self, max_cells: u128) -> Result<Vec<PanelSummary>> {
        Ok(self.grid(max_cells)?.compute(&|| {})?.iter().map(PhasePanel::summary).collect())
    }
}

impl PhaseGrid {
    /// Grid cells over all panels.
    pub fn cells(&self) -> u128 {
        (self.robots.len() * self.slopes_deg.len()) as u128
            * self.k_n_axis.len() as u128
            * self.k_s_axis.len() as u128
    }

    /// Rows of k_s over all panels (what `on_row` is called for).
    pub fn rows(&self) -> u64 {
        (self.robots.len() * self.slopes_deg.len() * self.k_s_axis.len()) as u64
    }

    /// Every panel, masses outermost; `on_row` is called after each row of k_s.
    pub fn compute(&self, on_row: &(dyn Fn() + Sync)) -> Result<Vec<PhasePanel>> {
        let mut panels = Vec::with_capacity(self.robots.len() * self.slopes_deg.len());
        for robot in &self.robots {
            for &slope_deg in &self.slopes_deg {
                let slope = SignedSlope::from_degrees(slope_deg)
                    .map_err(|e| RequestError::invalid(SLOPE.flag, e.renamed(SLOPE.long())))?;
                let on = TerrainGrid { terrain: &self.terrain, k_n: &self.k_n_axis, k_s: &self.k_s_axis };
                let panel = PhasePanel::compute(robot, slope, on, on_row);
                panels.push(panel);
            }
        }
        Ok(panels)
    }
}

/// Cells a [`PhaseMapRequest`] computes between two looks at its stop flag (about 10 ms of one
/// core).
const PHASE_MAP_CELLS_PER_BLOCK: usize = 1 << 20;

/// One phase map at one slope over axes given as values, no terrain table: Python's
/// `sandslope.phase` (its NumPy axes and the cells' arrays have no command-line counterpart;
/// `phase` draws panels from a terrain). The fields are the keywords, and messages name them so.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseMapRequest {
    /// Slope along the direction of travel, degrees (negative: descending; `slope_deg`).
    pub slope_deg: f64,
    /// The k_n values, N/m^3, evenly spaced or evenly spaced in logarithm (`k_n_axis`).
    pub k_n_axis: Vec<f64>,
    /// The k_s values, N/m^3, likewise (`k_s_axis`).
    pub k_s_axis: Vec<f64>,
    /// Angle of repose, degrees, strictly between 0 and 90, at or beyond which every cell slips
    /// (`repose_deg`; default the terrain's, when one is given, as `phase --terrain` has it).
    pub repose_deg: Option<f64>,
    /// The regime codes alone, without the net step (`regime_only`).
    pub regime_only: bool,
}

/// The answer to a [`PhaseMapRequest`]: every cell row-major, one row per k_s value.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseMapAnswer {
    /// Each cell's regime, its index in [`sandslope::Regime::ALL`].
    pub regime: Vec<i8>,
    /// Each cell's net step, m (NaN where the leg never anchors); none with `regime_only`.
    pub step_m: Option<Vec<f64>>,
    /// The k_n axis the values matched.
    pub k_n_axis: Axis,
    /// The k_s axis the values matched.
    pub k_s_axis: Axis,
    /// Cells per regime.
    pub counts: RegimeCounts,
}

impl PhaseMapRequest {
    /// Checks every field and the map's size (at most [`MAX_PHASE_CELLS`]) before anything is
    /// allocated: the slope, the angle of repose (`terrain`'s when none is given) and the axes
    /// as the library takes them.
    pub fn check(&self, terrain: Option<&Terrain>) -> Result<(Slope, Option<Slope>, Axis, Axis)> {
        let slope =
            Slope::from_signed_degrees(self.slope_deg).map_err(|e| RequestError::invalid("slope-deg", e))?;
        let repose = self
            .repose_deg
            .map(|r| {
                Slope::from_degrees(r).ok().filter(|_| r > 0.0).ok_or_else(|| {
                    RequestError::invalid(
                        "repose-deg",
                        format!("repose_deg = {r} must be strictly between 0 and 90 degrees"),
                    )
                })
            })
            .transpose()?
            .or_else(|| terrain.and_then(Terrain::repose));
        let k_n = grammar::axis_of_values("k_n_axis", &self.k_n_axis)?;
        let k_s = grammar::axis_of_values("k_s_axis", &self.k_s_axis)?;
        sandslope::limits::grid_cells(
            "len(k_n_axis) * len(k_s_axis)",
            k_n.len(),
            k_s.len(),
            1,
            MAX_PHASE_CELLS,
        )
        .map_err(|e| RequestError::invalid("k-n-axis", e))?;
        Ok((slope, repose, k_n, k_s))
    }

    /// The map for `robot` (on `terrain`, which lends its angle of repose alone), written row by row in parallel straight into the answer's buffers
    /// (no zeroing first, no packed map to unpack: `sandslope::write_phase_rows`), in blocks of
    /// about 2^20 cells with `stop` looked at between them: once it is raised the answer is
    /// [`RequestError::interrupted`] (the cap, 2^28 cells, takes minutes).
    pub fn answer(
        &self,
        robot: &Robot,
        terrain: Option<&Terrain>,
        stop: Option<&AtomicBool>,
    ) -> Result<PhaseMapAnswer> {
        let (slope, repose, k_n_axis, k_s_axis) = self.check(terrain)?;
        let (nx, ny) = (k_n_axis.len(), k_s_axis.len());
        let cells = nx * ny;
        let mut regime = uninit::<i8>(cells);
        let mut step = (!self.regime_only).then(|| uninit::<f64>(cells));
        let grid = StrengthGrid::new(robot, slope, repose, &k_n_axis, &k_s_axis);
        let block = (PHASE_MAP_CELLS_PER_BLOCK / nx).max(1);
        let mut counts = RegimeCounts::default();
        let mut j0 = 0;
        while j0 < ny {
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return Err(RequestError::interrupted());
            }
            let rows = j0..(j0 + block).min(ny);
            let span = rows.start * nx..rows.end * nx;
            let codes = &mut regime.spare_capacity_mut()[span.clone()];
            let steps = step.as_mut().map(|s| &mut s.spare_capacity_mut()[span]);
            let c = write_phase_rows(&grid, rows.clone(), codes, steps);
            counts.sinkage += c.sinkage;
            counts.slippage += c.slippage;
            counts.metastable += c.metastable;
            counts.success += c.success;
            j0 = rows.end;
        }
        // SAFETY: the blocks cover rows 0..ny, and `write_phase_rows` writes every one of its
        // rows' elements of each buffer it is given; `cells` is within their capacities.
        unsafe {
            regime.set_len(cells);
            if let Some(s) = step.as_mut() {
                s.set_len(cells);
            }
        }
        Ok(PhaseMapAnswer { regime, step_m: step, k_n_axis, k_s_axis, counts })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    /// Without a field given: one panel on level ground at the robot's mass, the axes around
    /// the terrain's; each list is read by its field's row, a bad entry named by its flag.
    #[test]
    fn fields_read_by_their_rows() {
        let r = PhaseRequest::from_params(&[]).unwrap();
        assert_eq!((r.slopes, r.masses, r.k_n, r.k_s), (vec![0.0], vec![], None, None));
        let r = PhaseRequest::from_params(&pairs(&[("slope", "-5, 10"), ("mass", "0.5,1")])).unwrap();
        assert_eq!((r.slopes, r.masses), (vec![-5.0, 10.0], vec![0.5, 1.0]));
        let e = PhaseRequest::from_params(&pairs(&[("mass", "1,kg")])).unwrap_err();
        assert_eq!(
            (e.field(), e.message().as_str()),
            (Some("mass"), "--mass: `kg` is not a number (in 1,kg)")
        );
        let e = PhaseRequest::from_params(&pairs(&[("solve", "mass")])).unwrap_err();
        assert_eq!(e.field(), Some("solve"));
    }
}
