//! The robot and terrain a request names, and the scenario `predict` and `sweep` evaluate.

use serde::{Deserialize, Serialize};

use sandslope::robot_key::RobotKey;
use sandslope::{LevelStep, Robot, Scenario, Terrain};
use sandslope_io::presets::{DEFAULT_ROBOT, DEFAULT_TERRAIN};

use crate::error::{check_positive, RequestError, Result};
use crate::field::{Field, Kind, Table};
use crate::params::Params;

/// `--robot`: a robot file or preset.
pub const ROBOT: Field = Field::text("robot", "FILE|PRESET")
    .keyword("robot")
    .default(DEFAULT_ROBOT)
    .help("Robot: a TOML file or a built-in preset (see `sandslope presets`)");
/// `--terrain`: a terrain file or preset.
pub const TERRAIN: Field = Field::text("terrain", "FILE|PRESET")
    .keyword("terrain")
    .default(DEFAULT_TERRAIN)
    .help("Terrain: a TOML file or a built-in preset (see `sandslope presets`)");
/// `--k-n`: a fixed normal resistance.
pub const K_N: Field = Field::number("k-n", "N/M^3")
    .keyword("k_n")
    .key("k_n")
    .unit("N/m^3")
    .range("greater than 0, plausible (docs/model.md §7)")
    .help("Normal penetration resistance k_n, N/m^3, instead of the terrain's");
/// `--k-s`: a fixed shear strength.
pub const K_S: Field = Field::number("k-s", "N/M^3")
    .keyword("k_s")
    .key("k_s")
    .unit("N/m^3")
    .range("greater than 0, plausible (docs/model.md §7)")
    .help("Shear strength k_s, N/m^3, instead of the terrain's");
/// `--level-step`: which normal depth the derived level step uses.
pub const LEVEL_STEP: Field =
    Field::new("level-step", Kind::Choice(&["slope", "level"]), "slope|level").default("slope").help(
        "Normal depth of the derived level step s* (docs/model.md §3, a choice the paper leaves \
         open): `slope` takes d_n at the slope, with its cos(theta) (the default); `level` takes \
         d_n on level sand, the paper's definition of s*. Up to 0.7% in speed on the built-in \
         robot and terrain. No effect on a robot with `level_step_m`.",
    );

/// A robot quantity's field: its flag overrides the robot file's key of the same name.
const fn quantity(
    flag: &'static str,
    key: &'static str,
    unit: &'static str,
    value_name: &'static str,
) -> Field {
    Field::number(flag, value_name).keyword(key).key(key).unit(unit)
}

/// `--mass`: the robot's total mass instead of the file's.
pub const MASS: Field = quantity("mass", "mass_kg", "kg", "KG").help("Override the robot's total mass, kg");

/// `--leg-speed`: the leg's angular speed instead of the file's (what sets the stride period).
pub const LEG_SPEED: Field = quantity("leg-speed", "leg_speed_rad_s", "rad/s", "RAD/S")
    .help("Override the leg angular speed omega, rad/s");

/// The robot quantities a request may override (docs/model.md §2), the mass first: the
/// command line's flags, the server's fields and the explorer page's robot panel (which reads
/// this list from `/data/served`). Each field's key is the library's robot key
/// ([`RobotKey::name`]) and its keyword Python's.
pub const ROBOT_QUANTITIES: Table = Table {
    command: "robot",
    fields: &[
        MASS,
        quantity("leg-radius", "leg_radius_m", "m", "M").help("Override the C-leg radius R, m"),
        quantity("leg-width", "leg_width_m", "m", "M").help("Override the leg width W, m"),
        quantity("hip-height", "hip_height_m", "m", "M")
            .range("between 0 and 2R")
            .help("Override the hip height h, m (between 0 and 2R)"),
        LEG_SPEED,
        Field::new("stance-legs", Kind::Whole, "N")
            .keyword("stance_legs")
            .key("stance_legs")
            .unit("legs")
            .help("Override the number of legs in stance at once"),
        quantity("response-time", "response_time_s", "s", "S")
            .help("Override the elastic response time dt, s"),
    ],
};

/// The field overriding the robot key `key`, where a request may.
pub fn robot_field(key: RobotKey) -> Option<&'static Field> {
    ROBOT_QUANTITIES.by_key(key.name())
}

/// The fields of a scenario besides the robot's quantities (those are the library's table of
/// robot keys, [`robot_fields`]): what `predict`, `sweep` and `simulate` share.
pub const FIELDS: Table = Table { command: "scenario", fields: &[ROBOT, TERRAIN, K_N, K_S, LEVEL_STEP] };

/// The robot of a request: a file or built-in preset, with the robot quantities it overrides.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotRequest {
    /// A robot TOML file or a built-in preset (field `robot`).
    pub robot: String,
    /// Total mass, kg, instead of the file's (field `mass`).
    pub mass: Option<f64>,
    /// Robot quantities instead of the file's, by key: those of [`RobotKey::TABLE`] with a
    /// flag, other than the mass (fields `leg-radius`, `leg-width`, `hip-height`, `leg-speed`,
    /// `stance-legs`, `response-time`).
    pub overrides: Vec<(RobotKey, f64)>,
}

impl Default for RobotRequest {
    fn default() -> RobotRequest {
        RobotRequest { robot: DEFAULT_ROBOT.to_string(), mass: None, overrides: Vec::new() }
    }
}

/// Every key a request may set, with its field: the rows of [`RobotKey::TABLE`] that have a
/// flag, the mass first (what the command line's flags, the server's parameters and the
/// explorer page's robot panel are; the page reads this list from `/data/served`).
pub fn robot_fields() -> impl Iterator<Item = (RobotKey, &'static str)> {
    RobotKey::ALL.into_iter().filter_map(|k| robot_field(k).map(|f| (k, f.flag)))
}

/// The keys a request may override besides the mass, with their fields: the table's rows
/// that have a flag.
pub fn override_fields() -> impl Iterator<Item = (RobotKey, &'static str)> {
    robot_fields().filter(|(k, _)| *k != RobotKey::MassKg)
}

impl RobotRequest {
    /// Reads `robot`, `mass` and the override fields.
    pub fn from_params(p: &mut Params<'_>) -> Result<RobotRequest> {
        let robot = ROBOT.text_in(p)?.unwrap_or(DEFAULT_ROBOT).to_string();
        let mass = MASS.number_in(p)?;
        let overrides = Self::overrides_from_params(p)?;
        Ok(RobotRequest { robot, mass, overrides })
    }

    /// Reads the override fields alone (`leg-radius`, ..., from [`RobotKey::TABLE`]).
    pub fn overrides_from_params(p: &mut Params<'_>) -> Result<Vec<(RobotKey, f64)>> {
        let mut overrides = Vec::new();
        for (key, field) in override_fields() {
            let value =
                if key == RobotKey::StanceLegs { p.whole(field)?.map(f64::from) } else { p.number(field)? };
            if let Some(v) = value {
                overrides.push((key, v));
            }
        }
        Ok(overrides)
    }

    /// `robot` with this request's quantities replaced (not the mass), validated again as a
    /// whole. An error on a key a request can override names its field (from
    /// [`robot_field`]), even when another override broke it (`leg-radius` made too small
    /// for the file's hip height names `hip-height`).
    pub fn apply(&self, robot: Robot) -> Result<Robot> {
        if self.overrides.is_empty() {
            return Ok(robot);
        }
        let mut spec = robot.spec().clone();
        for &(key, value) in &self.overrides {
            key.set(&mut spec, value);
        }
        Robot::new(spec).map_err(|e| {
            let key = RobotKey::of_error(&e).filter(|k| *k != RobotKey::MassKg);
            match key.and_then(robot_field) {
                Some(f) => RequestError::invalid(f.flag, e.renamed(f.long())),
                None => RequestError::from_error(None, anyhow::anyhow!("{e}")),
            }
        })
    }

    /// The robot for the closed form: [`RobotRequest::load_any_leg`], refused (naming the
    /// robot and its `leg_shape`) unless its legs are C-legs, the one shape the closed form is
    /// derived for ([`sandslope::LegShape::closed_form`]).
    pub fn load(&self) -> Result<Robot> {
        let robot = self.load_any_leg()?;
        self.closed_form(&robot)?;
        Ok(robot)
    }

    /// Refuses `robot` (this request's) for the closed form unless its legs are C-legs.
    fn closed_form(&self, robot: &Robot) -> Result<()> {
        robot
            .leg_shape()
            .closed_form()
            .map_err(|e| RequestError::invalid(ROBOT.flag, format!("{}: {e}", self.robot)))
    }

    /// The robot of any leg shape, for the simulator: read, its quantities replaced and
    /// validated again as a whole ([`apply`]), then the mass.
    ///
    /// [`apply`]: RobotRequest::apply
    pub fn load_any_leg(&self) -> Result<Robot> {
        let robot = sandslope_io::load_robot(&self.robot)
            .map_err(|e| RequestError::from_error(Some(ROBOT.flag), e))?;
        let robot = self.apply(robot)?;
        match self.mass {
            Some(m) => {
                robot.with_mass(m).map_err(|e| RequestError::invalid(MASS.flag, e.renamed(MASS.long())))
            }
            None => Ok(robot),
        }
    }
}

/// Reads a terrain file or preset, an error naming the field `terrain`.
pub fn load_terrain(terrain: &str) -> Result<Terrain> {
    sandslope_io::load_terrain(terrain).map_err(|e| RequestError::from_error(Some(TERRAIN.flag), e))
}

/// The slopes (degrees, signed as given) strictly above the terrain's last measured point,
/// where docs/model.md §7 extrapolates: the library's rule ([`Terrain::extrapolates`]).
pub fn beyond_last_point(terrain: &Terrain, slopes_deg: &[f64]) -> Vec<f64> {
    let extrapolated =
        |d: f64| sandslope::Slope::from_signed_degrees(d).is_ok_and(|s| terrain.extrapolates(s));
    slopes_deg.iter().copied().filter(|&d| extrapolated(d)).collect()
}

/// The warning every front end gives when it answers at `slopes_deg` (already found beyond
/// the last point by [`beyond_last_point`]): none when there are none or the terrain has no
/// points. The slopes are listed up to six, else as the first and last and how many (a
/// `sweep --step 0.001` warning once listed 10,000 slopes on one 59 KB line).
pub fn extrapolation_warning(terrain: &Terrain, slopes_deg: &[f64]) -> Option<String> {
    let last = terrain.points().last()?;
    let list = match slopes_deg {
        [] => return None,
        [first, .., last] if slopes_deg.len() > 6 => {
            format!("{first} to {last} ({} slopes)", slopes_deg.len())
        }
        _ => slopes_deg.iter().map(|s| format!("{s}")).collect::<Vec<_>>().join(", "),
    };
    Some(format!(
        "slope(s) {list} deg are above the terrain's last measured point ({} deg); k_n and k_s are \
         extrapolated linearly and floored at zero (docs/model.md §7)",
        last.slope_deg
    ))
}

/// Parses a level-step rule (`slope` or `level`, docs/model.md §3).
pub fn parse_level_step(s: &str) -> std::result::Result<LevelStep, String> {
    match s {
        "slope" => Ok(LevelStep::Slope),
        "level" => Ok(LevelStep::Level),
        other => Err(format!(
            "`{other}` is not a level-step rule: expected `slope` (d_n at the slope) or `level` (d_n on level sand)"
        )),
    }
}

/// A robot on a terrain with fixed resistances overriding the terrain's: what `predict` and
/// `sweep` evaluate (the library's [`Scenario`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScenarioRequest {
    /// The robot.
    pub robot: RobotRequest,
    /// A terrain TOML file or a built-in preset (field `terrain`).
    pub terrain: String,
    /// Normal penetration resistance k_n, N/m^3, at every slope instead of the terrain's
    /// (field `k-n`).
    pub k_n: Option<f64>,
    /// Shear strength k_s, N/m^3, at every slope instead of the terrain's (field `k-s`).
    pub k_s: Option<f64>,
    /// Which normal depth the derived level step s* uses (field `level-step`, docs/model.md §3).
    pub level_step: LevelStep,
}

impl Default for ScenarioRequest {
    fn default() -> ScenarioRequest {
        ScenarioRequest {
            robot: RobotRequest::default(),
            terrain: DEFAULT_TERRAIN.to_string(),
            k_n: None,
            k_s: None,
            level_step: LevelStep::Slope,
        }
    }
}

impl ScenarioRequest {
    /// Reads the robot's fields, `terrain`, `k-n`, `k-s` and `level-step`.
    pub fn from_params(p: &mut Params<'_>) -> Result<ScenarioRequest> {
        let robot = RobotRequest::from_params(p)?;
        let terrain = TERRAIN.text_in(p)?.unwrap_or(DEFAULT_TERRAIN).to_string();
        let k_n = K_N.number_in(p)?;
        let k_s = K_S.number_in(p)?;
        let level_step = match LEVEL_STEP.text_in(p)? {
            Some(text) => parse_level_step(text).map_err(|why| {
                RequestError::invalid(LEVEL_STEP.flag, format!("{}: {why}", LEVEL_STEP.long()))
            })?,
            None => LevelStep::Slope,
        };
        Ok(ScenarioRequest { robot, terrain, k_n, k_s, level_step })
    }

    /// The library's scenario for the closed form: the resistances checked, the robot (of
    /// C-legs, [`RobotRequest::load`]) and terrain read.
    pub fn scenario(&self) -> Result<Scenario> {
        let scenario = self.walk_scenario()?;
        self.robot.closed_form(scenario.robot())?;
        Ok(scenario)
    }

    /// The scenario for the simulator, whose robot may have legs of any shape.
    pub fn walk_scenario(&self) -> Result<Scenario> {
        let k_n = self.k_n.map(|v| check_resistance(K_N.flag, v)).transpose()?;
        let k_s = self.k_s.map(|v| check_resistance(K_S.flag, v)).transpose()?;
        let robot = self.robot.load_any_leg()?.with_level_step(self.level_step);
        Scenario::new(robot, load_terrain(&self.terrain)?, k_n, k_s)
            .map_err(|e| RequestError::from_error(None, anyhow::anyhow!("{e}")))
    }
}

/// A `--k-n`/`--k-s` override: finite and positive, then plausible (docs/model.md §7).
fn check_resistance(field: &str, value: f64) -> Result<f64> {
    let v = check_positive(field, value)?;
    sandslope::terrain::check_plausible_resistance(&format!("--{field}"), v)
        .map_err(|e| RequestError::invalid(field, e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rule is the library's (strictly above the last point, 24 degrees on the built-in
    /// sand, either sign) and long lists are summarised in the message.
    #[test]
    fn extrapolated_slopes_are_found_once_and_summarised() {
        let terrain = load_terrain(DEFAULT_TERRAIN).unwrap();
        assert_eq!(beyond_last_point(&terrain, &[10.0, 24.0, 25.0, -26.0]), vec![25.0, -26.0]);
        assert_eq!(extrapolation_warning(&terrain, &[]), None);
        let two = extrapolation_warning(&terrain, &[25.0, 26.0]).unwrap();
        assert!(
            two.starts_with("slope(s) 25, 26 deg are above the terrain's last measured point (24 deg)"),
            "{two}"
        );
        let many: Vec<f64> = (0..1000).map(|i| 25.0 + f64::from(i) * 0.001).collect();
        let text = extrapolation_warning(&terrain, &many).unwrap();
        assert!(text.starts_with(&format!("slope(s) 25 to {} (1000 slopes) deg", many[999])), "{text}");
    }
}
