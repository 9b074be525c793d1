//! Command-line arguments shared by several commands (`--robot`, `--mass`, `--terrain`,
//! `--k-n`, `--k-s`, grid axes) and the checks of flag values. Commands share code through
//! this module, never through each other.

use anyhow::Result;
use clap::Args;
use sandslope::{LevelStep, Robot, Terrain};
use sandslope_request::{grammar, RobotRequest, ScenarioRequest};

use sandslope::risk::UncertainTerrain;
use sandslope::robot_key::RobotKey;
use sandslope::AxisScale;
use sandslope_io::load_terrain;
use sandslope_io::presets::{DEFAULT_ROBOT, DEFAULT_TERRAIN};

/// `--robot` and `--mass`.
#[derive(Debug, Clone, Args)]
pub struct RobotArgs {
    /// Robot: a TOML file or a built-in preset (see `sandslope presets`).
    #[arg(long, value_name = "FILE|PRESET", default_value = DEFAULT_ROBOT)]
    pub robot: String,
    /// Override the robot's total mass, kg.
    #[arg(long, value_name = "KG", allow_negative_numbers = true)]
    pub mass: Option<f64>,
    #[command(flatten)]
    pub quantities: RobotQuantityArgs,
}

impl RobotArgs {
    /// The request these flags make: the robot, `--mass` and the other robot quantities given.
    pub fn request(&self) -> RobotRequest {
        RobotRequest { robot: self.robot.clone(), mass: self.mass, overrides: self.quantities.overrides() }
    }

    /// Loads the robot and applies `--mass` and the other robot quantities given (the request
    /// layer's one robot validation, errors naming the flag).
    pub fn load(&self) -> Result<Robot> {
        Ok(self.request().load()?)
    }
}

/// `--level-step`: which normal depth the derived level step s* uses (docs/model.md §3).
#[derive(Debug, Clone, Copy, Args)]
pub struct LevelStepArgs {
    /// Normal depth of the derived level step s* (docs/model.md §3, a choice the paper leaves
    /// open): `slope` takes d_n at the slope, with its cos(theta) (the default); `level` takes
    /// d_n on level sand, the paper's definition of s*. Up to 0.7% in speed on the built-in
    /// robot and terrain. No effect on a robot with `level_step_m`.
    #[arg(long, value_name = "slope|level", default_value = "slope", value_parser = sandslope_request::scenario::parse_level_step)]
    pub level_step: LevelStep,
}

/// `--terrain`.
#[derive(Debug, Clone, Args)]
pub struct TerrainArgs {
    /// Terrain: a TOML file or a built-in preset (see `sandslope presets`).
    #[arg(long, value_name = "FILE|PRESET", default_value = DEFAULT_TERRAIN)]
    pub terrain: String,
}

impl TerrainArgs {
    /// Loads the terrain.
    pub fn load(&self) -> Result<Terrain> {
        load_terrain(&self.terrain)
    }
}

/// `--cv-n` and `--cv-s`: the terrain's uncertainty by the one rule of docs/model.md §9 (a
/// given CV, else the table's SD over its value, else 0.1 / 0.2), shared by `risk`, `design`
/// and `infer` so that the flags read, check and report the same everywhere.
#[derive(Debug, Clone, Copy, Args)]
pub struct UncertaintyArgs {
    /// Coefficient of variation of k_n (sd / value) at every slope, instead of the terrain's
    /// k_n_sd; without either, 0.1 (docs/model.md §9).
    #[arg(long = "cv-n", allow_negative_numbers = true, value_name = "CV")]
    pub cv_n: Option<f64>,
    /// Coefficient of variation of k_s (sd / value) at every slope, instead of the terrain's
    /// k_s_sd; without either, 0.2 (docs/model.md §9).
    #[arg(long = "cv-s", allow_negative_numbers = true, value_name = "CV")]
    pub cv_s: Option<f64>,
}

impl UncertaintyArgs {
    /// The terrain read as uncertain (a flag's CV, else the table's SDs, else the default CV),
    /// with the note to print when a default is used anywhere on the table. Errors name the
    /// flag: `--cv-n = -1 must be a finite number of at least 0`.
    pub fn apply(&self, terrain: Terrain) -> Result<(UncertainTerrain, Option<String>)> {
        Ok(grammar::uncertain_terrain(terrain, self.cv_n, self.cv_s)?)
    }
}

/// `--leg-radius`, `--leg-width`, `--hip-height`, `--leg-speed`, `--stance-legs` and
/// `--response-time`: robot quantities overriding the robot file's (docs/model.md §2), so a
/// design question ("and with 5 cm legs?") needs no new file. Checked by the library's one
/// robot validation, errors naming the flag.
#[derive(Debug, Clone, Copy, Default, Args)]
pub struct RobotQuantityArgs {
    /// Override the C-leg radius R, m.
    #[arg(long = "leg-radius", value_name = "M", allow_negative_numbers = true)]
    pub leg_radius: Option<f64>,
    /// Override the leg width W, m.
    #[arg(long = "leg-width", value_name = "M", allow_negative_numbers = true)]
    pub leg_width: Option<f64>,
    /// Override the hip height h, m (between 0 and 2R).
    #[arg(long = "hip-height", value_name = "M", allow_negative_numbers = true)]
    pub hip_height: Option<f64>,
    /// Override the leg angular speed omega, rad/s.
    #[arg(long = "leg-speed", value_name = "RAD/S", allow_negative_numbers = true)]
    pub leg_speed: Option<f64>,
    /// Override the number of legs in stance at once.
    #[arg(long = "stance-legs", value_name = "N")]
    pub stance_legs: Option<u32>,
    /// Override the elastic response time dt, s.
    #[arg(long = "response-time", value_name = "S", allow_negative_numbers = true)]
    pub response_time: Option<f64>,
}

impl RobotQuantityArgs {
    /// The quantities given, by the library's robot key.
    pub fn overrides(&self) -> Vec<(RobotKey, f64)> {
        [
            (RobotKey::LegRadiusM, self.leg_radius),
            (RobotKey::LegWidthM, self.leg_width),
            (RobotKey::HipHeightM, self.hip_height),
            (RobotKey::LegSpeedRadS, self.leg_speed),
            (RobotKey::StanceLegs, self.stance_legs.map(f64::from)),
            (RobotKey::ResponseTimeS, self.response_time),
        ]
        .into_iter()
        .filter_map(|(key, value)| value.map(|v| (key, v)))
        .collect()
    }
}

/// `--k-n` and `--k-s`: fixed resistances overriding the terrain's at every slope; and
/// `--level-step`, the model choice of docs/model.md §3.
#[derive(Debug, Clone, Copy, Args)]
pub struct OverrideArgs {
    /// Normal penetration resistance k_n, N/m^3, instead of the terrain's.
    #[arg(long = "k-n", value_name = "N/M^3", allow_negative_numbers = true)]
    pub k_n: Option<f64>,
    /// Shear strength k_s, N/m^3, instead of the terrain's.
    #[arg(long = "k-s", value_name = "N/M^3", allow_negative_numbers = true)]
    pub k_s: Option<f64>,
    #[command(flatten)]
    pub level: LevelStepArgs,
}

impl OverrideArgs {
    /// The scenario request of `predict` and `sweep`: robot, terrain and these overrides.
    pub fn request(&self, robot: &RobotArgs, terrain: &TerrainArgs) -> ScenarioRequest {
        ScenarioRequest {
            robot: robot.request(),
            terrain: terrain.terrain.clone(),
            k_n: self.k_n,
            k_s: self.k_s,
            level_step: self.level.level_step,
        }
    }
}

/// Prints a warning to stderr when terrain values were extrapolated (docs/model.md §7).
pub fn warn_extrapolated(terrain: &Terrain, slopes: &[f64]) {
    if let (Some(last), false) = (terrain.points().last(), slopes.is_empty()) {
        let list = slope_list_text(slopes);
        eprintln!(
            "warning: slope(s) {list} deg are above the terrain's last measured point ({} deg); k_n and k_s are \
             extrapolated linearly and floored at zero",
            last.slope_deg
        );
    }
}

/// Slopes for a message: all of them up to six, else the first and last and how many (a
/// `sweep --step 0.001` warning listed 10,000 slopes on one 59 KB line).
fn slope_list_text(slopes: &[f64]) -> String {
    match slopes {
        [first, .., last] if slopes.len() > 6 => format!("{first} to {last} ({} slopes)", slopes.len()),
        _ => slopes.iter().map(|s| format!("{s}")).collect::<Vec<_>>().join(", "),
    }
}

/// The slopes (degrees, signed as given) strictly above the terrain's last measured point,
/// where docs/model.md §7 extrapolates.
pub fn beyond_last_point(terrain: &Terrain, slopes_deg: &[f64]) -> Vec<f64> {
    // One rule for "extrapolated": the library's (docs/model.md §7).
    let extrapolated =
        |d: f64| sandslope::Slope::from_signed_degrees(d).is_ok_and(|s| terrain.extrapolates(s));
    slopes_deg.iter().copied().filter(|&d| extrapolated(d)).collect()
}

/// Checks a command-line number: finite and within `lo..=hi`, naming the flag (`hi` infinite:
/// no upper bound).
pub fn check_flag(flag: &str, value: f64, lo: f64, hi: f64) -> Result<f64> {
    Ok(sandslope_request::error::check_range(flag.trim_start_matches('-'), value, lo, hi)?)
}

pub use sandslope_request::grammar::{parse_max_risk, AxisRange, SlopeSign};

/// Parses a slope list given to `flag`: the one slope-list grammar of every front end
/// ([`grammar::parse_slope_list`]: `DEG`, `DEG,DEG,...` or `MIN:MAX:N`, at most `max`).
pub fn parse_slope_list(flag: &str, text: &str, sign: SlopeSign, max: usize) -> Result<Vec<f64>> {
    Ok(grammar::parse_slope_list(flag.trim_start_matches('-'), text, sign, max)?)
}

/// Checks a command-line number is finite and strictly positive, naming the flag.
pub fn check_positive(flag: &str, value: f64) -> Result<f64> {
    Ok(sandslope_request::error::check_positive(flag.trim_start_matches('-'), value)?)
}

/// The one grammar of a grid axis, `MIN:MAX:N[:log|:lin]` ([`grammar::parse_axis_range`]);
/// errors begin with `prefix`, whose first word is the flag.
pub fn parse_axis_range(
    text: &str,
    default: AxisScale,
    prefix: &str,
    context: &str,
) -> Result<Option<AxisRange>> {
    let field = prefix.split([':', ' ']).next().unwrap_or(prefix).trim_start_matches('-');
    Ok(grammar::parse_axis_range(field, text, default, prefix, context)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One grammar for every slope list: N is refused before any expansion (an N of 1e11
    /// would have asked for 800 GB), each slope by the library's rule, named by its flag.
    #[test]
    fn slope_lists_share_one_grammar_and_cap_n_before_expanding() {
        assert_eq!(
            parse_slope_list("--slope", "0:24:4", SlopeSign::Uphill, 10).unwrap(),
            vec![0.0, 8.0, 16.0, 24.0]
        );
        assert_eq!(parse_slope_list("--slope", " 5, -10", SlopeSign::Signed, 10).unwrap(), vec![5.0, -10.0]);
        let err = |text: &str, sign| parse_slope_list("--x", text, sign, 10).unwrap_err().to_string();
        let start = std::time::Instant::now();
        assert!(err("0:24:99999999999", SlopeSign::Uphill)
            .contains("N `99999999999` must be a whole number from 2 to 10"));
        assert!(start.elapsed().as_millis() < 100);
        assert!(err("0:24:11", SlopeSign::Uphill).contains("from 2 to 10"));
        assert!(err("1,2,3,4,5,6,7,8,9,10,11", SlopeSign::Uphill).contains("lists 11 slopes; at most 10"));
        assert!(err("-5", SlopeSign::Uphill).starts_with("--x"));
        assert!(err("-95", SlopeSign::Signed).starts_with("--x"));
        assert!(err("10:5:3", SlopeSign::Uphill).contains("MAX must be greater than MIN"));
        assert!(err("0:24", SlopeSign::Uphill).contains("MIN:MAX:N"));
        assert!(err("a", SlopeSign::Uphill).contains("`a` is not a number"));
    }

    /// The robot flags are the library's table of robot keys: every key with a flag is one
    /// of `RobotArgs`' flags and sets its key (so the server's parameters, which the request
    /// layer reads by the table, and the page's list, which `/data/served` gives from it, are
    /// the command line's flags).
    #[test]
    fn robot_flags_are_the_tables() {
        use clap::{Args as _, Command};
        let cmd = RobotArgs::augment_args(Command::new("x"));
        let longs: Vec<&str> =
            cmd.get_arguments().filter_map(|a| a.get_long()).filter(|l| *l != "robot").collect();
        let table: Vec<&str> = sandslope_request::scenario::robot_fields().map(|(_, f)| f).collect();
        assert_eq!(longs, table);
        let q = RobotQuantityArgs {
            leg_radius: Some(1.0),
            leg_width: Some(2.0),
            hip_height: Some(3.0),
            leg_speed: Some(4.0),
            stance_legs: Some(5),
            response_time: Some(6.0),
        };
        let mut spec = load_robot_spec();
        for (key, v) in q.overrides() {
            key.set(&mut spec, v);
        }
        let set: Vec<f64> =
            sandslope_request::scenario::override_fields().map(|(k, _)| k.get(&spec).unwrap()).collect();
        assert_eq!(set, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    }

    fn load_robot_spec() -> sandslope::RobotSpec {
        sandslope_io::load_robot(DEFAULT_ROBOT).unwrap().spec().clone()
    }

    #[test]
    fn max_risk_is_a_probability_strictly_inside_0_1() {
        assert_eq!(parse_max_risk("0.05"), Ok(0.05));
        for bad in ["0", "1", "-0.1", "2", "nan", "inf"] {
            assert!(parse_max_risk(bad).unwrap_err().contains("strictly between 0 and 1"), "{bad}");
        }
        assert!(parse_max_risk("x").unwrap_err().contains("`x` is not a number"));
    }

    #[test]
    fn long_slope_lists_are_summarised_in_messages() {
        assert_eq!(slope_list_text(&[25.0, 26.0]), "25, 26");
        let many: Vec<f64> = (0..1000).map(|i| 25.0 + f64::from(i) * 0.001).collect();
        assert_eq!(slope_list_text(&many), format!("25 to {} (1000 slopes)", many[999]));
    }
}
