//! `design`'s request: robot keys varied over ranges around a template robot, evaluated on the
//! uncertain terrain (docs/model.md §9, docs/design.md), and the `--json` value of the study.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use sandslope::design::{design_key, explore, Design, DesignGoal, DesignRange, DesignSpace, DesignStudy};
use sandslope::risk::UncertainTerrain;
use sandslope::robot_key::RobotKey;
use sandslope::{AxisScale, Slope};
use sandslope_io::presets::DEFAULT_TERRAIN;

use crate::error::{RequestError, Result};
use crate::field::{Field, Fields, Kind, Table};
use crate::grammar::{self, AxisQuantity};
use crate::params::Params;
pub use crate::risk::{CV_N, CV_S};
use crate::scenario::{load_terrain, RobotRequest};

/// `--vary`: the robot keys to vary, each over a range or at one value.
pub const VARY: Field = Field::new("vary", Kind::List, "KEY=MIN:MAX:N[:log],...").required().help(
    "Robot keys to vary: KEY=MIN:MAX:N[:log|:lin] or KEY=VALUE, comma-separated or repeated \
     (e.g. leg_radius_m=0.03:0.06:7,mass_kg=0.3:1.5:9), spaced linearly unless :log (robot \
     quantities; the strength axes of phase and risk are log unless :lin). Keys: the robot \
     file's (docs/model.md §2)",
);
/// `--slope-target`: the mission's target slope.
pub const SLOPE_TARGET: Field = Field::number("slope-target", "DEG")
    .unit("deg")
    .required()
    .range("-90 to 90")
    .help("The mission's target slope, degrees: speed, regime, p_fail and k_s margin are reported there");
/// `--max-risk`: `risk`'s row (its default the library's), said of the safe-slope limit.
pub const MAX_RISK: Field =
    crate::risk::MAX_RISK.help("Largest acceptable failure probability, for the safe-slope limit");

/// `design`'s own fields (the robot's and the terrain's are [`crate::scenario`]'s).
pub const FIELDS: Table = Table { command: "design", fields: &[VARY, SLOPE_TARGET, CV_N, CV_S, MAX_RISK] };

impl Fields for DesignRequest {
    const TABLE: Table = FIELDS;
}

/// The inputs of `sandslope design`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignRequest {
    /// The robot keys to vary (field `vary`): each item `KEY=MIN:MAX:N[:log|:lin]` or
    /// `KEY=VALUE` as written (a comma list is split into its items), `KEY` a key of the robot
    /// file (docs/model.md §2), linear spacing unless `:log` ([`AxisQuantity::Robot`]).
    pub vary: Vec<String>,
    /// The mission's target slope, degrees (field `slope-target`).
    pub slope_target: f64,
    /// The template robot.
    pub robot: RobotRequest,
    /// A terrain TOML file or a built-in preset (field `terrain`).
    pub terrain: String,
    /// Coefficient of variation of k_n (field `cv-n`, docs/model.md §9).
    pub cv_n: Option<f64>,
    /// Coefficient of variation of k_s (field `cv-s`).
    pub cv_s: Option<f64>,
    /// Largest acceptable failure probability for the safe-slope limit (field `max-risk`).
    pub max_risk: f64,
}

impl Default for DesignRequest {
    fn default() -> DesignRequest {
        DesignRequest {
            vary: Vec::new(),
            slope_target: 0.0,
            robot: RobotRequest::default(),
            terrain: DEFAULT_TERRAIN.to_string(),
            cv_n: None,
            cv_s: None,
            max_risk: sandslope::risk::DEFAULT_MAX_RISK,
        }
    }
}

/// A design request checked into the library's types: what [`DesignInputs::explore`] runs.
#[derive(Debug, Clone)]
pub struct DesignInputs {
    /// The template robot and the ranges varied.
    pub space: DesignSpace,
    /// The target slope and the largest acceptable risk.
    pub goal: DesignGoal,
    /// The terrain read as uncertain.
    pub terrain: UncertainTerrain,
    /// The note to print when a default CV is used (docs/model.md §9).
    pub notes: Vec<String>,
}

/// Parses one `KEY=MIN:MAX:N[:log|:lin]` or `KEY=VALUE` item of `vary` into the library's
/// range (the one axis grammar, [`grammar::parse_axis_range`], with the robot quantities' rule:
/// linear unless `:log`).
pub fn parse_vary_item(item: &str) -> Result<DesignRange> {
    let bad = |message: String| RequestError::invalid(VARY.flag, message);
    let shape = || bad(format!("--vary: `{item}` must be KEY=MIN:MAX:N[:log|:lin] or KEY=VALUE"));
    let (key, range) = item.split_once('=').ok_or_else(shape)?;
    let key = design_key(key.trim()).map_err(|e| bad(format!("--vary: {e}")))?;
    let (min, max, n, scale) = if range.contains(':') {
        let prefix = format!("--vary: {key}");
        let r = grammar::parse_axis_range(VARY.flag, range, AxisQuantity::Robot, &prefix, item)?
            .ok_or_else(shape)?;
        if r.n < 2 {
            return Err(bad(format!(
                "--vary: {key} N `{}` must be a whole number of at least 2 (in {item})",
                r.n
            )));
        }
        (r.min, r.max, r.n, r.scale)
    } else {
        let v = range.trim();
        let v = v
            .parse::<f64>()
            .map_err(|_| bad(format!("--vary: {key} value `{v}` is not a number (in {item})")))?;
        (v, v, 1, AxisScale::Linear)
    };
    DesignRange::new(key, min, max, n, scale).map_err(|e| bad(format!("--vary: {e}")))
}

impl DesignRequest {
    /// The command line's request: its own fields from `params` (the flags given, by
    /// [`FIELDS`]: the one raw-to-typed step), the robot and the terrain already read from the
    /// flags it shares with other commands; refuses any other key.
    pub fn with_sources(
        params: &[(String, String)],
        robot: RobotRequest,
        terrain: String,
    ) -> Result<DesignRequest> {
        let mut p = Params::new(FIELDS.command, params);
        let vary = VARY.text_in(&mut p)?.map(|v| vec![v.to_string()]).unwrap_or_default();
        if vary.is_empty() {
            return Err(RequestError::invalid(
                VARY.flag,
                format!("{} is required: {}", VARY.long(), VARY.help),
            ));
        }
        let slope_target = SLOPE_TARGET.required_number_in(&mut p)?;
        let (cv_n, cv_s) = (CV_N.number_in(&mut p)?, CV_S.number_in(&mut p)?);
        let text = MAX_RISK.text_in(&mut p)?.unwrap_or_default();
        let max_risk = grammar::parse_max_risk(text).map_err(|why| {
            RequestError::invalid(MAX_RISK.flag, format!("{} = {text}: {why}", MAX_RISK.long()))
        })?;
        p.finish()?;
        Ok(DesignRequest { vary, slope_target, robot, terrain, cv_n, cv_s, max_risk })
    }

    /// The request checked into the library's types: the robot read, every `vary` item
    /// parsed, the space, the goal and the uncertain terrain, in that order, errors naming
    /// their field.
    pub fn inputs(&self) -> Result<DesignInputs> {
        let robot = self.robot.load()?;
        let mut ranges = Vec::new();
        for text in &self.vary {
            for item in text.split(',').filter(|s| !s.trim().is_empty()) {
                ranges.push(parse_vary_item(item.trim())?);
            }
        }
        let space = DesignSpace::new(robot.spec().clone(), ranges)
            .map_err(|e| RequestError::invalid(VARY.flag, format!("{}: {e}", VARY.long())))?;
        let target = Slope::from_signed_degrees(self.slope_target)
            .map_err(|e| RequestError::invalid(SLOPE_TARGET.flag, e.renamed(SLOPE_TARGET.long())))?;
        let goal = DesignGoal::new(self.max_risk, target)
            .map_err(|e| RequestError::invalid(MAX_RISK.flag, format!("{}: {e}", MAX_RISK.long())))?;
        let (terrain, note) = grammar::uncertain_terrain(load_terrain(&self.terrain)?, self.cv_n, self.cv_s)?;
        Ok(DesignInputs { space, goal, terrain, notes: note.into_iter().collect() })
    }
}

impl DesignInputs {
    /// Evaluates every design (`progress` is called once per design) and adds a note for each
    /// bound of `vary` the Pareto front reaches.
    pub fn explore(&mut self, progress: &(dyn Fn() + Sync)) -> DesignStudy {
        let study = explore(&self.space, &self.terrain, &self.goal, progress);
        self.notes.extend(front_at_bounds(&study, &self.space));
        study
    }
}

/// A note for each varied key whose smallest or largest value holds designs of the Pareto
/// front: the front is then cut by the range searched, and a better design may lie beyond it.
pub fn front_at_bounds(study: &DesignStudy, space: &DesignSpace) -> Vec<String> {
    let front = study.front();
    let mut notes = Vec::new();
    for (i, range) in space.ranges().iter().enumerate() {
        let values = range.values();
        let (Some(&lo), Some(&hi)) = (values.first(), values.last()) else { continue };
        if values.len() < 2 {
            continue;
        }
        for (value, end) in [(lo, "smallest"), (hi, "largest")] {
            let at = front.iter().filter(|d| d.params[i] == value).count();
            if at > 0 {
                notes.push(format!(
                    "the Pareto front is at the bound of --vary: {at} of its {} designs have {} = {value}, the {end} value \
                     searched; a better design may lie beyond it (widen the range to see)",
                    front.len(),
                    range.key().name()
                ));
            }
        }
    }
    notes
}

/// One design as `design --json` prints it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignRecord {
    /// The varied keys' values, by key name.
    pub params: BTreeMap<&'static str, f64>,
    /// Whether the design is a valid robot (docs/model.md §2).
    pub valid: bool,
    /// Why the robot is not valid, null when it is.
    pub invalid_reason: Option<String>,
    /// The safe-slope limit, degrees.
    pub safe_slope_deg: Option<f64>,
    /// `limit`, `repose` (up to the angle of repose), `none_safe` (not even level ground) or
    /// `beyond_range` (every slope searched).
    pub safe_limit: Option<&'static str>,
    /// Speed at the target slope on the median terrain, m/s.
    pub speed_m_s: Option<f64>,
    /// Failure probability at the target slope.
    pub p_fail: Option<f64>,
    /// Regime at the target slope on the median terrain.
    pub regime: Option<&'static str>,
    /// Median k_s over the critical k_s for progress at the target slope.
    pub k_s_margin: Option<f64>,
    /// Whether the design is on the Pareto front.
    pub pareto: bool,
}

impl DesignRecord {
    /// The record of design `d`, whose `params` are the values of `keys`.
    pub fn new(keys: &[RobotKey], d: &Design) -> DesignRecord {
        let params = keys.iter().zip(&d.params).map(|(k, v)| (k.name(), *v)).collect();
        let mut r = DesignRecord {
            params,
            valid: d.outcome.is_ok(),
            invalid_reason: d.outcome.as_ref().err().cloned(),
            safe_slope_deg: None,
            safe_limit: None,
            speed_m_s: None,
            p_fail: None,
            regime: None,
            k_s_margin: None,
            pareto: false,
        };
        if let Ok(p) = &d.outcome {
            r.safe_slope_deg = p.safe_slope_deg;
            r.safe_limit = Some(p.safe_limit.kind());
            r.speed_m_s = p.speed_m_s;
            r.p_fail = Some(p.p_fail);
            r.regime = Some(p.regime.name());
            r.k_s_margin = p.k_s_margin;
            r.pareto = d.pareto;
        }
        r
    }
}

/// The study as `design --json` prints it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignAnswer {
    /// The target slope, degrees.
    pub slope_target_deg: f64,
    /// Largest acceptable failure probability.
    pub max_risk: f64,
    /// Designs evaluated.
    pub designs_evaluated: usize,
    /// Designs that are not valid robots.
    pub invalid: usize,
    /// Notes: a default CV used, the front at a bound of `vary`.
    pub notes: Vec<String>,
    /// The template robot's own record.
    pub template: DesignRecord,
    /// Every design, in the space's order.
    pub designs: Vec<DesignRecord>,
}

impl DesignAnswer {
    /// The answer of `study` with its `notes`.
    pub fn new(study: &DesignStudy, notes: Vec<String>) -> DesignAnswer {
        let keys = &study.keys;
        DesignAnswer {
            slope_target_deg: study.slope_target_deg,
            max_risk: study.max_risk,
            designs_evaluated: study.designs.len(),
            invalid: study.invalid_count(),
            notes,
            template: DesignRecord::new(keys, &study.template),
            designs: study.designs.iter().map(|d| DesignRecord::new(keys, d)).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    fn read(list: &[(&str, &str)]) -> Result<DesignRequest> {
        DesignRequest::with_sources(&pairs(list), RobotRequest::default(), DEFAULT_TERRAIN.to_string())
    }

    /// `--vary` and `--slope-target` are required; `--max-risk` is 0.05 (the library's) and the
    /// CVs the terrain's unless given; a bad value is named by its flag.
    #[test]
    fn fields_read_by_the_table() {
        let r = read(&[("vary", "mass_kg=1:3:3,leg_width_m=0.02"), ("slope-target", "-5")]).unwrap();
        assert_eq!(r.vary, vec!["mass_kg=1:3:3,leg_width_m=0.02".to_string()]);
        assert_eq!((r.slope_target, r.max_risk, r.cv_n, r.cv_s), (-5.0, 0.05, None, None));
        assert_eq!(r.max_risk, sandslope::risk::DEFAULT_MAX_RISK);
        let e = read(&[("slope-target", "10")]).unwrap_err();
        assert_eq!(e.field(), Some("vary"));
        let e = read(&[("vary", "mass_kg=1")]).unwrap_err();
        assert_eq!(e.field(), Some("slope-target"));
        let e = read(&[("vary", "mass_kg=1"), ("slope-target", "10"), ("max-risk", "1.5")]).unwrap_err();
        assert!(
            e.message().starts_with("--max-risk = 1.5: 1.5 is not a failure probability"),
            "{}",
            e.message()
        );
        let e = read(&[("vary", "mass_kg=1"), ("slope-target", "10"), ("show", "3")]).unwrap_err();
        assert_eq!(e.field(), Some("show"));
    }

    /// Robot quantities are spaced linearly unless `:log` is written (the one axis rule), and
    /// each error names the field `vary`.
    #[test]
    fn vary_items_follow_the_one_axis_rule_and_name_their_field() {
        let lin = parse_vary_item("mass_kg=1:3:3").unwrap();
        assert_eq!((lin.key(), lin.values()), (RobotKey::MassKg, &[1.0, 2.0, 3.0][..]));
        let log = parse_vary_item("mass_kg=1:100:3:log").unwrap();
        assert_eq!(log.values(), &[1.0, 10.0, 100.0]);
        assert_eq!(parse_vary_item("leg_width_m=0.02").unwrap().values(), &[0.02]);
        for bad in ["mass_kg", "legs=1", "mass_kg=1:3", "mass_kg=1:3:1", "mass_kg=x", "mass_kg=1:3:3:cube"] {
            let e = parse_vary_item(bad).unwrap_err();
            assert_eq!(e.field(), Some("vary"), "{bad}");
            assert!(e.message().starts_with("--vary"), "{bad}: {}", e.message());
        }
    }
}
