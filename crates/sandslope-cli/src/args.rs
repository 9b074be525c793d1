//! Command-line arguments shared by several commands (`--robot`, `--mass`, `--terrain`,
//! `--k-n`, `--k-s`, grid axes) and the checks of flag values. Commands share code through
//! this module, never through each other.

use anyhow::Result;
use clap::Args;
use sandslope::{LevelStep, Robot, Terrain};
use sandslope_request::field::{Field, Fields, Kind};
use sandslope_request::scenario::{K_N, K_S, LEVEL_STEP, ROBOT, TERRAIN};
use sandslope_request::{RobotRequest, ScenarioRequest};

use sandslope::robot_key::RobotKey;
use sandslope_io::load_terrain;

/// `--robot` and the robot quantities that override its file's (`--mass`, `--leg-radius`, ...).
#[derive(Debug, Clone, Args)]
pub struct RobotArgs {
    /// `--robot` ([`ROBOT`]).
    #[arg(long = ROBOT.flag, value_name = ROBOT.value_name, default_value = ROBOT.default, help = ROBOT.help)]
    pub robot: String,
    #[command(flatten)]
    pub quantities: RobotKeyArgs<true>,
}

impl RobotArgs {
    /// The request these flags make: the robot, `--mass` and the other robot quantities given.
    pub fn request(&self) -> RobotRequest {
        RobotRequest {
            robot: self.robot.clone(),
            mass: self.quantities.get(RobotKey::MassKg),
            overrides: self.quantities.overrides(),
        }
    }

    /// Loads the robot and applies `--mass` and the other robot quantities given (the request
    /// layer's one robot validation, errors naming the flag).
    /// Prints a note on stderr when the robot's `stance_legs` may count every leg rather than
    /// those in stance at once ([`sandslope::robot::stance_legs_note`]).
    pub fn load(&self) -> Result<Robot> {
        let robot = self.request().load()?;
        if let Some(note) = sandslope::robot::stance_legs_note(robot.stance_legs()) {
            eprintln!("note: {note}");
        }
        Ok(robot)
    }
}

/// `--level-step`: which normal depth the derived level step s* uses (docs/model.md §3).
#[derive(Debug, Clone, Copy, Args)]
pub struct LevelStepArgs {
    /// `--level-step` ([`LEVEL_STEP`]).
    #[arg(long = LEVEL_STEP.flag, value_name = LEVEL_STEP.value_name, default_value = LEVEL_STEP.default, help = LEVEL_STEP.help, value_parser = sandslope_request::scenario::parse_level_step)]
    pub level_step: LevelStep,
}

/// `--terrain`.
#[derive(Debug, Clone, Args)]
pub struct TerrainArgs {
    /// `--terrain` ([`TERRAIN`]).
    #[arg(long = TERRAIN.flag, value_name = TERRAIN.value_name, default_value = TERRAIN.default, help = TERRAIN.help)]
    pub terrain: String,
}

impl TerrainArgs {
    /// Loads the terrain.
    pub fn load(&self) -> Result<Terrain> {
        load_terrain(&self.terrain)
    }
}

/// The robot quantities overriding the robot file's (docs/model.md §2), so a design question
/// ("and with 5 cm legs?") needs no new file: one flag per row of the library's table of robot
/// quantities ([`sandslope_request::scenario::ROBOT_QUANTITIES`], its flag, placeholder and help line), `--mass`
/// among them when `MASS`. Checked by the request layer's one robot validation, errors naming
/// the flag.
#[derive(Debug, Clone, Default)]
pub struct RobotKeyArgs<const MASS: bool> {
    given: Vec<(RobotKey, f64)>,
}

/// `--leg-radius`, `--leg-width`, `--hip-height`, `--leg-speed`, `--stance-legs` and
/// `--response-time` without `--mass` (for `phase`, whose `--mass` is a list of panels).
pub type RobotQuantityArgs = RobotKeyArgs<false>;

impl<const MASS: bool> RobotKeyArgs<MASS> {
    /// The keys these flags set, with their fields, in the table's order.
    fn flags() -> impl Iterator<Item = (RobotKey, &'static Field)> {
        RobotKey::ALL
            .into_iter()
            .filter(|k| MASS || *k != RobotKey::MassKg)
            .filter_map(|k| sandslope_request::scenario::robot_field(k).map(|f| (k, f)))
    }

    /// The value given for `key`, if its flag was.
    pub fn get(&self, key: RobotKey) -> Option<f64> {
        self.given.iter().find(|(k, _)| *k == key).map(|&(_, v)| v)
    }

    /// The quantities given other than the mass, by the library's robot key.
    pub fn overrides(&self) -> Vec<(RobotKey, f64)> {
        self.given.iter().copied().filter(|(k, _)| *k != RobotKey::MassKg).collect()
    }
}

impl<const MASS: bool> clap::Args for RobotKeyArgs<MASS> {
    fn augment_args(mut cmd: clap::Command) -> clap::Command {
        for (key, field) in Self::flags() {
            let arg = clap::Arg::new(key.name())
                .long(field.flag)
                .value_name(field.value_name)
                .help(field.help_line())
                .action(clap::ArgAction::Set);
            // A whole number: clap's parser, which refuses `2.5` and `-1` itself.
            cmd = cmd.arg(if key == RobotKey::StanceLegs {
                arg.value_parser(clap::value_parser!(u32))
            } else {
                arg.value_parser(clap::value_parser!(f64)).allow_negative_numbers(true)
            });
        }
        cmd
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

impl<const MASS: bool> clap::FromArgMatches for RobotKeyArgs<MASS> {
    fn from_arg_matches(matches: &clap::ArgMatches) -> std::result::Result<Self, clap::Error> {
        let mut args = RobotKeyArgs { given: Vec::new() };
        args.update_from_arg_matches(matches)?;
        Ok(args)
    }

    fn update_from_arg_matches(
        &mut self,
        matches: &clap::ArgMatches,
    ) -> std::result::Result<(), clap::Error> {
        let internal =
            |e: clap::parser::MatchesError| clap::Error::raw(clap::error::ErrorKind::ArgumentConflict, e);
        for (key, _) in Self::flags() {
            let value = if key == RobotKey::StanceLegs {
                matches.try_get_one::<u32>(key.name()).map_err(internal)?.map(|&v| f64::from(v))
            } else {
                matches.try_get_one::<f64>(key.name()).map_err(internal)?.copied()
            };
            if let Some(v) = value {
                self.given.retain(|(k, _)| *k != key);
                self.given.push((key, v));
            }
        }
        Ok(())
    }
}

/// `--k-n` and `--k-s`: fixed resistances overriding the terrain's at every slope; and
/// `--level-step`, the model choice of docs/model.md §3.
#[derive(Debug, Clone, Copy, Args)]
pub struct OverrideArgs {
    /// `--k-n` ([`K_N`]).
    #[arg(long = K_N.flag, value_name = K_N.value_name, help = K_N.help, allow_negative_numbers = true)]
    pub k_n: Option<f64>,
    /// `--k-s` ([`K_S`]).
    #[arg(long = K_S.flag, value_name = K_S.value_name, help = K_S.help, allow_negative_numbers = true)]
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

/// A request's own fields as flags, built from its field table ([`Fields::TABLE`]): the flags
/// given, as the text pairs the request's `from_params` reads (the one step from raw text to
/// the typed request that the server's fields take too). Defaults, ranges and checks are the
/// table's and the request's; clap only splits the command line.
#[derive(Debug, Clone)]
pub struct FieldArgs<T> {
    /// The flags given on the command line, without dashes, with their text.
    pub pairs: Vec<(String, String)>,
    request: std::marker::PhantomData<T>,
}

/// The clap argument of one field: its flag, placeholder, help, default (shown in `--help`),
/// choices and conflicts from its row.
pub fn field_arg(f: &'static Field) -> clap::Arg {
    let arg = clap::Arg::new(f.flag)
        .long(f.flag)
        .help(f.help_line())
        .conflicts_with_all(f.conflicts)
        .required(f.required);
    match f.kind {
        Kind::Switch => arg.action(clap::ArgAction::SetTrue),
        Kind::List => arg.action(clap::ArgAction::Append).value_name(f.value_name),
        kind => {
            let arg = arg.action(clap::ArgAction::Set).value_name(f.value_name).default_value(f.default);
            match kind {
                Kind::Choice(words) => arg.value_parser(clap::builder::PossibleValuesParser::new(words)),
                // A number, or a list or axis of numbers in a unit, may start with a minus (the
                // request then names what is wrong with it).
                Kind::Number | Kind::Whole => arg.allow_negative_numbers(true),
                Kind::Text if !f.unit.is_empty() => arg.allow_hyphen_values(true),
                _ => arg,
            }
        }
    }
}

impl<T: Fields> clap::Args for FieldArgs<T> {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        T::TABLE.fields.iter().fold(cmd, |cmd, f| cmd.arg(field_arg(f)))
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

impl<T: Fields> clap::FromArgMatches for FieldArgs<T> {
    fn from_arg_matches(matches: &clap::ArgMatches) -> std::result::Result<Self, clap::Error> {
        let mut args = FieldArgs { pairs: Vec::new(), request: std::marker::PhantomData };
        args.update_from_arg_matches(matches)?;
        Ok(args)
    }

    fn update_from_arg_matches(
        &mut self,
        matches: &clap::ArgMatches,
    ) -> std::result::Result<(), clap::Error> {
        for f in T::TABLE.fields {
            if matches.value_source(f.flag) != Some(clap::parser::ValueSource::CommandLine) {
                continue;
            }
            let text = match f.kind {
                Kind::Switch => "true".to_string(),
                // Given more than once: one comma list, as HTTP and Python write it.
                Kind::List => matches
                    .get_many::<String>(f.flag)
                    .map(|v| v.map(String::as_str).collect::<Vec<_>>().join(","))
                    .unwrap_or_default(),
                _ => matches.get_one::<String>(f.flag).cloned().unwrap_or_default(),
            };
            self.pairs.retain(|(k, _)| k != f.flag);
            self.pairs.push((f.flag.to_string(), text));
        }
        Ok(())
    }
}

/// Prints a warning to stderr when terrain values were extrapolated (docs/model.md §7).
pub fn warn_extrapolated(terrain: &Terrain, slopes: &[f64]) {
    if let Some(warning) = sandslope_request::scenario::extrapolation_warning(terrain, slopes) {
        eprintln!("warning: {warning}");
    }
}

pub use sandslope_request::scenario::beyond_last_point;

#[cfg(test)]
mod tests {
    use super::*;
    use sandslope_request::grammar::{self, parse_max_risk, SlopeSign};

    /// A slope list given to `flag`: the one slope-list grammar of every front end
    /// ([`grammar::parse_slope_list`]: `DEG`, `DEG,DEG,...` or `MIN:MAX:N`, at most `max`).
    fn parse_slope_list(flag: &str, text: &str, sign: SlopeSign, max: usize) -> Result<Vec<f64>> {
        Ok(grammar::parse_slope_list(flag.trim_start_matches('-'), text, sign, max)?)
    }

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
    /// of `RobotArgs`' flags, in the table's order (so the server's parameters, which the
    /// request layer reads by the table, and the page's list, which `/data/served` gives from
    /// it, are the command line's flags), and each flag sets the key it names.
    #[test]
    fn robot_flags_are_the_tables() {
        use clap::{Args as _, Command, FromArgMatches as _};
        let cmd = RobotArgs::augment_args(Command::new("x"));
        let longs: Vec<&str> =
            cmd.get_arguments().filter_map(|a| a.get_long()).filter(|l| *l != "robot").collect();
        let table: Vec<&str> = sandslope_request::scenario::robot_fields().map(|(_, f)| f).collect();
        assert_eq!(longs, table);
        let argv = "x --mass 7 --leg-radius 1 --leg-width 2 --hip-height 3 --leg-speed 4 --stance-legs 5 --response-time -6";
        let args = RobotArgs::from_arg_matches(&cmd.get_matches_from(argv.split(' '))).unwrap();
        let request = args.request();
        assert_eq!(request.mass, Some(7.0));
        let expected = [
            (RobotKey::LegRadiusM, 1.0),
            (RobotKey::LegWidthM, 2.0),
            (RobotKey::HipHeightM, 3.0),
            (RobotKey::LegSpeedRadS, 4.0),
            (RobotKey::StanceLegs, 5.0),
            (RobotKey::ResponseTimeS, -6.0),
        ];
        assert_eq!(request.overrides, expected);
        // `phase`'s set has no `--mass` (its own is a list of panels).
        let phase = RobotQuantityArgs::augment_args(Command::new("x"));
        assert!(phase.get_arguments().all(|a| a.get_long() != Some("mass")));
        assert_eq!(phase.get_arguments().count(), 6);
    }

    #[test]
    fn max_risk_is_a_probability_strictly_inside_0_1() {
        assert_eq!(parse_max_risk("0.05"), Ok(0.05));
        for bad in ["0", "1", "-0.1", "2", "nan", "inf"] {
            assert!(parse_max_risk(bad).unwrap_err().contains("strictly between 0 and 1"), "{bad}");
        }
        assert!(parse_max_risk("x").unwrap_err().contains("`x` is not a number"));
    }
}
