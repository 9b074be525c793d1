//! Options shared by the model commands (`--robot`, `--mass`, `--terrain`, `--k-n`, `--k-s`)
//! and the prediction record they print.

use anyhow::{anyhow, Result};
use clap::Args;
use serde::Serialize;

use sandslope::{
    critical_shear_strength, predict, Ground, NoShearSuffices, Prediction, Robot, Slope, StepTarget, Terrain,
};

use crate::inputs::{check_positive, load_robot, load_terrain};
use crate::presets::{DEFAULT_ROBOT, DEFAULT_TERRAIN};

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
