//! [`RiskRequest`]: the probability of failure on an uncertain terrain (docs/model.md §9): a
//! p_fail curve over slopes, the safe-slope limit, the heaviest safe mass or payload envelope,
//! or a map over median (k_n, k_s).

use serde::{Deserialize, Serialize};

use sandslope::limits::{MAX_RISK_MAP_CELLS, MAX_RISK_SLOPES};
use sandslope::risk::{
    payload_envelope, risk_curve, risk_map, safe_mass, safe_slope, RiskAnswer, UncertainTerrain,
};
use sandslope::{Axis, SignedSlope};
use sandslope_io::presets::DEFAULT_TERRAIN;

use crate::error::{RequestError, Result};
use crate::grammar::{self, parse_slope_list, AxisRange, SlopeSign};
use crate::params::Params;
use crate::scenario::{load_terrain, RobotRequest};

/// What a risk request solves for besides the curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Solve {
    /// The safe-slope limit: the steepest slope with p_fail below `max_risk`.
    Slope,
    /// The heaviest total mass with p_fail below `max_risk` at each slope (several slopes:
    /// the payload envelope).
    Mass,
}

/// The grid of a risk map over median (k_n, k_s): each axis given, or the default around the
/// terrain's medians at the map's slope.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct RiskMapGrid {
    /// Median k_n axis, N/m^3 (field `k-n`).
    pub k_n: Option<AxisRange>,
    /// Median k_s axis, N/m^3 (field `k-s`).
    pub k_s: Option<AxisRange>,
}

/// The inputs of `risk` (and `/api/risk`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RiskRequest {
    /// Slopes, degrees (field `slope`: `DEG`, `DEG,DEG,...` or `MIN:MAX:N`; default 0:24:7).
    pub slopes: Vec<f64>,
    /// The robot.
    pub robot: RobotRequest,
    /// A terrain TOML file or a built-in preset (field `terrain`).
    pub terrain: String,
    /// Coefficient of variation of k_n at every slope instead of the terrain's (field `cv-n`).
    pub cv_n: Option<f64>,
    /// Coefficient of variation of k_s at every slope instead of the terrain's (field `cv-s`).
    pub cv_s: Option<f64>,
    /// Largest acceptable failure probability (field `max-risk`, default 0.05).
    pub max_risk: f64,
    /// What to solve for (field `solve`: `slope` or `mass`).
    pub solve: Option<Solve>,
    /// A map at the first slope instead (field `map`, its axes `k-n` and `k-s`).
    pub map: Option<RiskMapGrid>,
}

/// How much work one [`RiskRequest::answer`] may do; more is an error naming the limit.
#[derive(Debug, Clone, Copy)]
pub struct AnswerLimits {
    /// Most slopes of a p_fail curve (each a quadrature).
    pub curve_slopes: usize,
    /// Most slopes of a payload envelope (each a search over masses).
    pub envelope_slopes: usize,
    /// Most map cells.
    pub map_cells: u128,
}

impl AnswerLimits {
    /// The library's own limits (the command line's and Python's).
    pub const LIBRARY: AnswerLimits = AnswerLimits {
        curve_slopes: MAX_RISK_SLOPES,
        envelope_slopes: MAX_RISK_SLOPES,
        map_cells: MAX_RISK_MAP_CELLS as u128,
    };
}

/// The default slopes, `0:24:7`.
pub const DEFAULT_SLOPES: &str = "0:24:7";

/// Parses the field `slope`: the one slope-list grammar, signed (a descent is felt as the
/// climb of its size), at most [`MAX_RISK_SLOPES`].
pub fn parse_slopes(text: &str) -> Result<Vec<f64>> {
    parse_slope_list("slope", text, SlopeSign::Signed, MAX_RISK_SLOPES)
}

/// A yes/no field: empty, `true` or `1` is yes; `false` or `0` no.
fn flag(p: &mut Params<'_>, key: &'static str) -> Result<bool> {
    match p.text(key)? {
        None => Ok(false),
        Some("" | "true" | "1") => Ok(true),
        Some("false" | "0") => Ok(false),
        Some(other) => Err(RequestError::invalid(
            key,
            format!("{key} = `{other}` must be true or false (or empty: true)"),
        )),
    }
}

impl RiskRequest {
    /// Reads the fields of a risk request; refuses any other key.
    pub fn from_params(params: &[(String, String)]) -> Result<RiskRequest> {
        let mut p = Params::new("risk", params);
        let slopes = parse_slopes(p.text("slope")?.unwrap_or(DEFAULT_SLOPES))?;
        let robot = RobotRequest::from_params(&mut p)?;
        let terrain = p.text_or("terrain", DEFAULT_TERRAIN)?;
        let cv_n = p.number("cv-n")?;
        let cv_s = p.number("cv-s")?;
        let max_risk = match p.text("max-risk")? {
            Some(text) => grammar::parse_max_risk(text)
                .map_err(|why| RequestError::invalid("max-risk", format!("--max-risk = {text}: {why}")))?,
            None => sandslope::risk::DEFAULT_MAX_RISK,
        };
        let solve = match p.text("solve")? {
            None => None,
            Some("slope") => Some(Solve::Slope),
            Some("mass") => Some(Solve::Mass),
            Some(other) => {
                return Err(RequestError::invalid(
                    "solve",
                    format!("--solve = `{other}` must be slope (the safe-slope limit) or mass (the heaviest safe mass)"),
                ))
            }
        };
        let map = flag(&mut p, "map")?;
        let mut grid = RiskMapGrid::default();
        for (field, axis) in [("k-n", &mut grid.k_n), ("k-s", &mut grid.k_s)] {
            if let Some(text) = p.text(field)? {
                if !map {
                    return Err(RequestError::invalid(
                        field,
                        format!("--{field} is the grid of --map: give map too"),
                    ));
                }
                *axis = Some(grammar::parse_strength_axis(field, text)?);
            }
        }
        if map && solve.is_some() {
            return Err(RequestError::invalid("solve", "--solve cannot be used with --map"));
        }
        p.finish()?;
        Ok(RiskRequest { slopes, robot, terrain, cv_n, cv_s, max_risk, solve, map: map.then_some(grid) })
    }

    /// The terrain read as uncertain by the one rule of docs/model.md §9, with the note to
    /// print when a default CV is used anywhere on the table.
    pub fn uncertain_terrain(&self) -> Result<(UncertainTerrain, Option<String>)> {
        grammar::uncertain_terrain(load_terrain(&self.terrain)?, self.cv_n, self.cv_s)
    }

    /// The answer (what `risk --json` prints), by the library's calls; more work than
    /// `limits` allows is an error naming the limit.
    pub fn answer(&self, limits: AnswerLimits) -> Result<RiskAnswer> {
        let robot = self.robot.load()?;
        let slopes = &self.slopes;
        if slopes.is_empty() {
            return Err(RequestError::invalid("slope", "--slope gives no slope: give at least one"));
        }
        let max_risk = self.max_risk;
        let (terrain, _) = self.uncertain_terrain()?;
        let library = |e: &dyn std::fmt::Display| RequestError::from_error(None, anyhow::anyhow!("{e}"));
        let too_many = |n: usize, most: usize, what: &str| {
            RequestError::invalid(
                "slope",
                format!("--slope gives {n} slopes; at most {most} are allowed for {what} here"),
            )
        };
        if let Some(grid) = &self.map {
            let (k_n_axis, k_s_axis) = map_axes(grid, &terrain, slopes[0], limits.map_cells)?;
            let map =
                risk_map(&robot, slope_of(slopes[0])?, &terrain, (&k_n_axis, &k_s_axis), max_risk, &|| {})
                    .map_err(|e| library(&e))?;
            return Ok(RiskAnswer::Map(Box::new(map)));
        }
        Ok(match self.solve {
            Some(Solve::Mass) if slopes.len() > 1 => {
                if slopes.len() > limits.envelope_slopes {
                    return Err(too_many(slopes.len(), limits.envelope_slopes, "--solve mass"));
                }
                let env = payload_envelope(&robot, &terrain, slopes, max_risk).map_err(|e| library(&e))?;
                RiskAnswer::Envelope(Box::new(env))
            }
            Some(Solve::Mass) => {
                let sol =
                    safe_mass(&robot, slope_of(slopes[0])?, &terrain, max_risk).map_err(|e| library(&e))?;
                RiskAnswer::Mass(Box::new(sol))
            }
            Some(Solve::Slope) => {
                RiskAnswer::Slope(Box::new(safe_slope(&robot, &terrain, max_risk).map_err(|e| library(&e))?))
            }
            None => {
                if slopes.len() > limits.curve_slopes {
                    return Err(too_many(slopes.len(), limits.curve_slopes, "a p_fail curve"));
                }
                let curve = risk_curve(&robot, &terrain, slopes)
                    .map_err(|e| RequestError::invalid("slope", e.renamed("--slope")))?;
                RiskAnswer::of_points(curve.points)
            }
        })
    }
}

/// A slope of the field `slope` as the library's type (signed: answers print it as given).
pub fn slope_of(deg: f64) -> Result<SignedSlope> {
    SignedSlope::from_degrees(deg).map_err(|e| RequestError::invalid("slope", e.renamed("--slope")))
}

/// The map's axes (the grid's, else the defaults around the terrain's medians at
/// `slope_deg`, an error naming `slope` if it is out of range), at most `max_cells` cells.
pub fn map_axes(
    grid: &RiskMapGrid,
    terrain: &UncertainTerrain,
    slope_deg: f64,
    max_cells: u128,
) -> Result<(Axis, Axis)> {
    let slope = slope_of(slope_deg)?;
    let given = |field: &str, range: Option<AxisRange>| range.map(|r| grammar::axis(field, r)).transpose();
    let (k_n_axis, k_s_axis) =
        sandslope::risk::map_axes(terrain, slope, given("k-n", grid.k_n)?, given("k-s", grid.k_s)?)
            .map_err(|e| RequestError::from_error(None, anyhow::anyhow!("{e}")))?;
    let cells = k_n_axis.len() as u128 * k_s_axis.len() as u128;
    if cells > max_cells {
        let side = (max_cells as f64).sqrt().floor();
        return Err(RequestError::invalid(
            "k-n",
            format!(
                "--k-n and --k-s give {cells} map cells; at most {max_cells} are allowed (e.g. {side} x {side}), to keep the map in memory"
            ),
        ));
    }
    Ok((k_n_axis, k_s_axis))
}
