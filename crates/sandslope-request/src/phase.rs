//! [`PhaseRequest`]: phase diagrams, the regime of every terrain (k_n, k_s) on a grid, one
//! panel per (mass, slope) (the paper's Section IV figure).

use serde::{Deserialize, Serialize};

use sandslope::{Axis, PanelSummary, PhasePanel, Robot, SignedSlope, Slope, Terrain};
use sandslope_io::presets::{DEFAULT_ROBOT, DEFAULT_TERRAIN};

use crate::error::{RequestError, Result};
use crate::grammar::{self, AxisRange};
use crate::params::Params;
use crate::scenario::{load_terrain, RobotRequest};

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

/// Reads a comma list of numbers given to `key`.
fn number_list(p: &mut Params<'_>, key: &'static str) -> Result<Option<Vec<f64>>> {
    let Some(text) = p.text(key)? else { return Ok(None) };
    text.split(',')
        .map(|s| {
            s.trim().parse::<f64>().map_err(|_| {
                RequestError::invalid(key, format!("--{key}: `{}` is not a number (in {text})", s.trim()))
            })
        })
        .collect::<Result<Vec<f64>>>()
        .map(Some)
}

impl PhaseRequest {
    /// Reads the fields of a phase request; refuses any other key.
    pub fn from_params(params: &[(String, String)]) -> Result<PhaseRequest> {
        let mut p = Params::new("phase", params);
        let mut axis = |field: &'static str| -> Result<Option<AxisRange>> {
            p.text(field)?.map(|t| grammar::parse_strength_axis(field, t)).transpose()
        };
        let (k_n, k_s) = (axis("k-n")?, axis("k-s")?);
        let slopes = number_list(&mut p, "slope")?.unwrap_or_else(|| vec![0.0]);
        let masses = number_list(&mut p, "mass")?.unwrap_or_default();
        let robot = RobotRequest {
            robot: p.text_or("robot", DEFAULT_ROBOT)?,
            mass: None,
            overrides: RobotRequest::overrides_from_params(&mut p)?,
        };
        let terrain = p.text_or("terrain", DEFAULT_TERRAIN)?;
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
            .map(|&m| base.with_mass(m).map_err(|e| RequestError::invalid("mass", e.renamed("--mass"))))
            .collect::<Result<Vec<Robot>>>()?;
        if self.slopes.is_empty() {
            return Err(RequestError::invalid("slope", "--slope gives no slope: give at least one"));
        }
        let slopes = self
            .slopes
            .iter()
            .map(|&d| {
                Slope::from_signed_degrees(d)
                    .map_err(|e| RequestError::invalid("slope", e.renamed("--slope")))
            })
            .collect::<Result<Vec<Slope>>>()?;
        let grounds: Vec<_> = slopes.iter().map(|&s| terrain.at(s)).collect();
        let axis = |field: &str, given: Option<AxisRange>, values: Vec<f64>, down: f64| match given {
            Some(range) => grammar::axis(field, range),
            None => Axis::log_around(&format!("--{field}"), &values, down, 100.0, DEFAULT_POINTS)
                .map_err(|e| RequestError::invalid(field, e)),
        };
        let k_n_axis = axis("k-n", self.k_n, grounds.iter().map(|g| g.k_n).collect(), 100.0)?;
        let k_s_axis = axis("k-s", self.k_s, grounds.iter().map(|g| g.k_s).collect(), 1000.0)?;
        // Guards against a typo such as 100000 points per axis: the maps are kept in memory
        // at two bits per cell.
        let panels = robots.len() * slopes.len();
        let cells = panels as u128 * k_n_axis.len() as u128 * k_s_axis.len() as u128;
        if cells > max_cells {
            let side = if max_cells >= 4096 * 4096 { 4096 } else { 1u128 << (max_cells.max(1).ilog2() / 2) };
            return Err(RequestError::invalid(
                "k-n",
                format!(
                    "--k-n and --k-s give {cells} cells over {panels} panel(s); at most {max_cells} are allowed (e.g. {side} x {side} per panel is {})",
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
                    .map_err(|e| RequestError::invalid("slope", e.renamed("--slope")))?;
                let panel =
                    PhasePanel::compute(robot, slope, &self.terrain, &self.k_n_axis, &self.k_s_axis, on_row);
                panels.push(panel);
            }
        }
        Ok(panels)
    }
}
