//! Command-line arguments shared by several commands (`--robot`, `--mass`, `--terrain`,
//! `--k-n`, `--k-s`, grid axes), the checks of flag values, and the prediction record that
//! `predict` and `sweep` print. Commands share code through this module, never through
//! each other.

use anyhow::{anyhow, bail, Result};
use clap::Args;
use serde::Serialize;

use sandslope::{
    critical_shear_strength, predict, Ground, NoShearSuffices, Prediction, Robot, Slope, StepTarget, Terrain,
};

use sandslope::{Axis, AxisScale};
use sandslope_io::presets::{DEFAULT_ROBOT, DEFAULT_TERRAIN};
use sandslope_io::{load_robot, load_terrain};

/// `--robot` and `--mass`.
#[derive(Debug, Clone, Args)]
pub struct RobotArgs {
    /// Robot: a TOML file or a built-in preset (see `sandslope presets`).
    #[arg(long, value_name = "FILE|PRESET", default_value = DEFAULT_ROBOT)]
    pub robot: String,
    /// Override the robot's total mass, kg.
    #[arg(long, value_name = "KG", allow_negative_numbers = true)]
    pub mass: Option<f64>,
}

impl RobotArgs {
    /// Loads the robot and applies `--mass`.
    pub fn load(&self) -> Result<Robot> {
        let robot = load_robot(&self.robot)?;
        match self.mass {
            Some(m) => robot.with_mass(m).map_err(|e| anyhow!("{}", e.renamed("--mass"))),
            None => Ok(robot),
        }
    }
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

/// `--k-n` and `--k-s`: fixed resistances overriding the terrain's at every slope.
#[derive(Debug, Clone, Copy, Args)]
pub struct OverrideArgs {
    /// Normal penetration resistance k_n, N/m^3, instead of the terrain's.
    #[arg(long = "k-n", value_name = "N/M^3", allow_negative_numbers = true)]
    pub k_n: Option<f64>,
    /// Shear strength k_s, N/m^3, instead of the terrain's.
    #[arg(long = "k-s", value_name = "N/M^3", allow_negative_numbers = true)]
    pub k_s: Option<f64>,
}

/// A robot on a terrain, with optional fixed resistances: what `predict` and `sweep` evaluate.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// The robot.
    pub robot: Robot,
    /// The terrain table.
    pub terrain: Terrain,
    k_n: Option<f64>,
    k_s: Option<f64>,
}

impl Scenario {
    /// Loads and validates robot, terrain and overrides.
    pub fn load(robot: &RobotArgs, terrain: &TerrainArgs, over: &OverrideArgs) -> Result<Scenario> {
        let k_n = over.k_n.map(|v| check_positive("--k-n", v)).transpose()?;
        let k_s = over.k_s.map(|v| check_positive("--k-s", v)).transpose()?;
        Ok(Scenario { robot: robot.load()?, terrain: terrain.load()?, k_n, k_s })
    }

    /// The ground at `slope` and whether its values were extrapolated beyond the table.
    pub fn ground_at(&self, slope: Slope) -> (Ground, bool) {
        let sample = self.terrain.sample(slope);
        let mut ground = sample.ground;
        ground.k_n = self.k_n.unwrap_or(ground.k_n);
        ground.k_s = self.k_s.unwrap_or(ground.k_s);
        let extrapolated = sample.extrapolated && (self.k_n.is_none() || self.k_s.is_none());
        (ground, extrapolated)
    }

    /// The model at a signed slope in degrees (descending evaluated as |theta|, MODEL.md 8).
    pub fn evaluate(&self, slope_deg: f64) -> Result<Evaluation> {
        let slope = Slope::from_signed_degrees(slope_deg).map_err(|e| anyhow!("{}", e.renamed("--slope")))?;
        let (ground, extrapolated) = self.ground_at(slope);
        let prediction = predict(&self.robot, slope, &ground);
        let critical = |target| {
            critical_shear_strength(&self.robot, slope, ground.k_n, ground.beyond_repose(slope), target)
        };
        let (progress, robust) = (critical(StepTarget::Progress), critical(StepTarget::Robust));
        Ok(Evaluation {
            slope_deg,
            prediction,
            k_s_margin: progress.as_ref().ok().map(|k| ground.k_s / k),
            critical_progress: progress,
            critical_robust: robust,
            extrapolated,
        })
    }
}

/// The model's answer at one slope, with what the CLI reports beside it.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// The slope as the user gave it (negative: descending).
    pub slope_deg: f64,
    /// Every model quantity.
    pub prediction: Prediction,
    /// `k_s / critical k_s for s > 0`; `None` when no k_s is enough.
    pub k_s_margin: Option<f64>,
    /// Smallest k_s giving progress (`s > 0`), or why none does.
    pub critical_progress: Result<f64, NoShearSuffices>,
    /// Smallest k_s giving robust progress (`s >= s_min`), or why none does.
    pub critical_robust: Result<f64, NoShearSuffices>,
    /// Whether the terrain was extrapolated beyond its last point.
    pub extrapolated: bool,
}

/// One prediction as printed by `--json` and `--csv`: exactly these keys, `null` where undefined.
#[derive(Debug, Clone, Serialize)]
pub struct PredictionRecord {
    pub slope_deg: f64,
    pub k_n: f64,
    pub k_s: f64,
    pub regime: &'static str,
    pub d_n_m: Option<f64>,
    pub level_step_m: f64,
    pub d_s_m: Option<f64>,
    pub t1_s: Option<f64>,
    pub slip_m: Option<f64>,
    pub propulsion_m: Option<f64>,
    pub step_m: Option<f64>,
    pub speed_m_s: Option<f64>,
    pub k_s_margin: Option<f64>,
}

impl From<&Evaluation> for PredictionRecord {
    fn from(e: &Evaluation) -> Self {
        let p = &e.prediction;
        PredictionRecord {
            slope_deg: e.slope_deg,
            k_n: p.k_n,
            k_s: p.k_s,
            regime: p.regime.name(),
            d_n_m: p.normal_depth,
            level_step_m: p.level_step,
            d_s_m: p.shear_depth,
            t1_s: p.anchoring_time,
            slip_m: p.slip,
            propulsion_m: p.propulsion,
            step_m: p.step,
            speed_m_s: p.speed,
            k_s_margin: e.k_s_margin,
        }
    }
}

/// Prints a warning to stderr when terrain values were extrapolated (MODEL.md section 7).
pub fn warn_extrapolated(terrain: &Terrain, slopes: &[f64]) {
    if let (Some(last), false) = (terrain.points().last(), slopes.is_empty()) {
        let list = slopes.iter().map(|s| format!("{s}")).collect::<Vec<_>>().join(", ");
        eprintln!(
            "warning: slope(s) {list} deg are above the terrain's last measured point ({} deg); k_n and k_s are \
             extrapolated linearly and floored at zero",
            last.slope_deg
        );
    }
}

/// The slopes (degrees, signed as given) strictly above the terrain's last measured point,
/// where MODEL.md section 7 extrapolates.
pub fn beyond_last_point(terrain: &Terrain, slopes_deg: &[f64]) -> Vec<f64> {
    // One rule for "extrapolated": the library's (MODEL.md section 7).
    let extrapolated =
        |d: f64| sandslope::Slope::from_signed_degrees(d).is_ok_and(|s| terrain.sample(s).extrapolated);
    slopes_deg.iter().copied().filter(|&d| extrapolated(d)).collect()
}

/// Checks a command-line number: finite and within `lo..=hi`, naming the flag (`hi` infinite:
/// no upper bound).
pub fn check_flag(flag: &str, value: f64, lo: f64, hi: f64) -> Result<f64> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(value)
    } else if hi == f64::INFINITY {
        bail!("{flag} = {value} must be a finite number of at least {lo}")
    } else {
        bail!("{flag} = {value} must be between {lo} and {hi}")
    }
}

/// Checks a command-line number is finite and strictly positive, naming the flag.
pub fn check_positive(flag: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        bail!("{flag} = {value} must be a finite number greater than 0")
    }
}

/// Parses a grid axis `MIN:MAX:N[:log|:lin]` given to `flag` (log spacing by default).
pub fn parse_axis(flag: &str, text: &str) -> Result<Axis> {
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    if !(3..=4).contains(&parts.len()) {
        bail!("{flag} = {text} must be MIN:MAX:N or MIN:MAX:N:log or MIN:MAX:N:lin (e.g. 1e4:1e7:400)");
    }
    let number = |what: &str, s: &str| -> Result<f64> {
        s.parse::<f64>().map_err(|_| anyhow!("{flag}: {what} `{s}` is not a number (in {text})"))
    };
    let (min, max) = (number("MIN", parts[0])?, number("MAX", parts[1])?);
    let n: usize = parts[2]
        .parse()
        .map_err(|_| anyhow!("{flag}: N `{}` must be a whole number of at least 2 (in {text})", parts[2]))?;
    let scale = match parts.get(3).map(|s| s.to_ascii_lowercase()).as_deref() {
        None | Some("log") => AxisScale::Log,
        Some("lin") | Some("linear") => AxisScale::Linear,
        Some(other) => bail!("{flag}: spacing `{other}` must be `log` or `lin` (in {text})"),
    };
    Axis::new(flag, min, max, n, scale).map_err(|e| anyhow!("{e}"))
}

/// A log axis from `lo / down` to `hi * up` around positive terrain values, with `n` points.
pub fn default_axis(flag: &str, values: &[f64], down: f64, up: f64, n: usize) -> Result<Axis> {
    let positive: Vec<f64> = values.iter().copied().filter(|v| *v > 0.0 && v.is_finite()).collect();
    let (lo, hi) = if positive.is_empty() {
        (1e3, 1e9)
    } else {
        (
            positive.iter().copied().fold(f64::INFINITY, f64::min) / down,
            positive.iter().copied().fold(0.0, f64::max) * up,
        )
    };
    Axis::new(flag, lo, hi, n, AxisScale::Log).map_err(|e| anyhow!("{e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_flags_parse_and_reject_bad_input() {
        let a = parse_axis("--k-n", "1e4:1e7:31").unwrap();
        assert_eq!((a.min(), a.max(), a.len(), a.scale()), (1e4, 1e7, 31, AxisScale::Log));
        assert_eq!(parse_axis("--k-n", "0:10:11:lin").unwrap().scale(), AxisScale::Linear);
        for bad in ["1e4:1e7", "a:1e7:3", "1e4:1e7:x", "1e4:1e7:3:cubic", "0:1e7:3", "1e7:1e4:3", "1e4:1e7:1"]
        {
            let msg = parse_axis("--k-n", bad).unwrap_err().to_string();
            assert!(msg.contains("--k-n"), "{bad}: {msg}");
        }
    }
}
