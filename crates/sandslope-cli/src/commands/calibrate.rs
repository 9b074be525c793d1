//! `sandslope calibrate`: fit k_s(theta) so that the model's speeds match observed speeds, and
//! write the result as a terrain file every other command accepts.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{anyhow, Result};
use clap::{Args, ValueEnum};
use serde::Serialize;

use sandslope::{calibrate, Calibration, LawParams, ShearLaw, Slope, Terrain, TerrainPoint, TerrainSpec};

use crate::args::{check_flag, check_positive, RobotArgs, TerrainArgs};
use crate::output::{print_json, table, write_atomic};
use sandslope_io::load_speeds;

/// The law to fit, as named on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LawArg {
    /// k_s(theta) = k_s0 + b * theta_deg.
    Linear,
    /// k_s(theta) = k_s0 * (cos theta - sin theta / tan phi), Mohr-Coulomb on an infinite slope.
    Coulomb,
    /// One k_s per observed slope, by root finding.
    PerSlope,
}

impl LawArg {
    fn law(self) -> ShearLaw {
        match self {
            LawArg::Linear => ShearLaw::Linear,
            LawArg::Coulomb => ShearLaw::Coulomb,
            LawArg::PerSlope => ShearLaw::PerSlope,
        }
    }
    fn name(self) -> &'static str {
        match self {
            LawArg::Linear => "linear",
            LawArg::Coulomb => "coulomb",
            LawArg::PerSlope => "per-slope",
        }
    }
}

/// Arguments of `sandslope calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Observed speeds: CSV with columns slope_deg,speed_m_s,speed_sd_m_s.
    #[arg(long, value_name = "CSV")]
    pub observed: PathBuf,
    /// Form of k_s(theta) to fit.
    #[arg(long, value_enum, default_value_t = LawArg::Linear)]
    pub law: LawArg,
    /// Write the calibrated terrain (MODEL.md section 7 format) to this TOML file.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Normal resistance k_n, N/m^3, at every slope (default: the --terrain's k_n).
    #[arg(long = "k-n", value_name = "N/M^3", allow_negative_numbers = true)]
    pub k_n: Option<f64>,
    /// Name written into the terrain file (default: calibrated-<law>).
    #[arg(long)]
    pub name: Option<String>,
    /// Angle of repose written into the terrain file, degrees.
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub repose: Option<f64>,
    /// Print the fit as JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Source of k_n when --k-n is not given.
    #[command(flatten)]
    pub terrain: TerrainArgs,
}

#[derive(Serialize)]
struct ResidualRecord {
    slope_deg: f64,
    k_n: f64,
    k_s: f64,
    observed_m_s: f64,
    observed_sd_m_s: f64,
    model_m_s: f64,
    residual_m_s: f64,
}

#[derive(Serialize)]
struct CalibrationRecord<'a> {
    law: &'static str,
    params: serde_json::Value,
    param_se: Option<serde_json::Value>,
    residuals: Vec<ResidualRecord>,
    rmse_m_s: f64,
    chi_squared: f64,
    terrain: &'a TerrainSpec,
}

/// Parameters as named JSON values (and their standard errors).
fn params_json(params: &LawParams, se: Option<[f64; 2]>) -> (serde_json::Value, Option<serde_json::Value>) {
    match *params {
        LawParams::Linear { k_s0, per_degree } => (
            serde_json::json!({"k_s0": k_s0, "k_s_per_deg": per_degree}),
            se.map(|s| serde_json::json!({"k_s0": s[0], "k_s_per_deg": s[1]})),
        ),
        LawParams::Coulomb { k_s0, friction_angle_deg } => (
            serde_json::json!({"k_s0": k_s0, "friction_angle_deg": friction_angle_deg}),
            se.map(|s| serde_json::json!({"k_s0": s[0], "friction_angle_deg": s[1]})),
        ),
        LawParams::PerSlope => (serde_json::json!({}), None),
    }
}

/// The terrain table for a calibration: the law at each observed slope (the linear law is then
/// reproduced exactly by the table's linear interpolation); the Coulomb law is also sampled every
/// degree between the observed slopes, since it is curved.
fn terrain_spec(
    cal: &Calibration,
    name: String,
    repose_deg: Option<f64>,
    k_n_at: &dyn Fn(Slope) -> f64,
) -> Result<TerrainSpec> {
    let mut slopes: Vec<f64> = cal.residuals.iter().map(|r| r.slope_deg).collect();
    if let (LawParams::Coulomb { .. }, Some(&first), Some(&last)) =
        (&cal.params, slopes.first(), slopes.last())
    {
        let whole = (first.ceil() as i64..=last.floor() as i64).map(|d| d as f64);
        slopes.extend(whole.filter(|d| !slopes.contains(d)).collect::<Vec<_>>());
        slopes.sort_by(f64::total_cmp);
    }
    let mut points = Vec::with_capacity(slopes.len());
    for d in slopes {
        let slope = Slope::from_degrees(d).map_err(|e| anyhow!("{e}"))?;
        let k_s = match cal.params.k_s(slope) {
            Some(k) => k,
            None => cal.residuals.iter().find(|r| r.slope_deg == d).map(|r| r.k_s).unwrap_or(0.0),
        };
        points.push(TerrainPoint { slope_deg: d, k_n: k_n_at(slope), k_s, k_n_sd: None, k_s_sd: None });
    }
    Ok(TerrainSpec { name: Some(name), repose_deg, points })
}

/// Runs `sandslope calibrate`.
pub fn run(args: CalibrateArgs) -> Result<()> {
    let robot = args.robot.load()?;
    let observations = load_speeds(&args.observed)?;
    let fixed_k_n = args.k_n.map(|v| check_positive("--k-n", v)).transpose()?;
    if let Some(r) = args.repose {
        check_flag("--repose", r, 0.0, 90.0)?;
    }
    let terrain = if fixed_k_n.is_none() { Some(args.terrain.load()?) } else { None };
    let k_n_at = |s: Slope| fixed_k_n.unwrap_or_else(|| terrain.as_ref().map_or(0.0, |t| t.at(s).k_n));
    let cal = calibrate(&robot, &k_n_at, &observations, args.law.law())
        .map_err(|e| anyhow!("{}: {e}", args.observed.display()))?;
    let name = args.name.clone().unwrap_or_else(|| format!("calibrated-{}", args.law.name()));
    let spec = terrain_spec(&cal, name, args.repose, &k_n_at)?;
    // Validate through the same constructor every reader uses, so the file we write loads.
    Terrain::new(spec.clone()).map_err(|e| {
        anyhow!("the calibrated terrain is not valid ({e}); a fitted k_s reached zero within the observed slopes: try --law per-slope or coulomb")
    })?;
    let mut text = String::new();
    let command: Vec<String> = std::env::args().skip(1).collect();
    writeln!(text, "# Written by: sandslope {}", command.join(" "))?;
    match cal.params {
        LawParams::Linear { k_s0, per_degree } => {
            writeln!(text, "# k_s(theta) = {k_s0:.6e} + ({per_degree:.6e}) * theta_deg N/m^3")?
        }
        LawParams::Coulomb { k_s0, friction_angle_deg } => writeln!(
            text,
            "# k_s(theta) = {k_s0:.6e} * (cos theta - sin theta / tan({friction_angle_deg:.4} deg)) N/m^3"
        )?,
        LawParams::PerSlope => writeln!(text, "# k_s per observed slope, inverted from each speed")?,
    }
    writeln!(text, "# RMSE of speed {:.3e} m/s over {} slopes.", cal.rmse(), cal.residuals.len())?;
    text.push_str(&toml::to_string(&spec)?);
    write_atomic(&args.out, text.as_bytes())?;

    if args.json {
        let (params, param_se) = params_json(&cal.params, cal.param_se);
        let residuals = cal
            .residuals
            .iter()
            .map(|r| ResidualRecord {
                slope_deg: r.slope_deg,
                k_n: r.k_n,
                k_s: r.k_s,
                observed_m_s: r.observed,
                observed_sd_m_s: r.observed_sd,
                model_m_s: r.model,
                residual_m_s: r.residual(),
            })
            .collect();
        let record = CalibrationRecord {
            law: args.law.name(),
            params,
            param_se,
            residuals,
            rmse_m_s: cal.rmse(),
            chi_squared: cal.chi_squared(),
            terrain: &spec,
        };
        return print_json(&record);
    }
    let se = |i: usize| cal.param_se.map(|s| format!(" ± {:.3e}", s[i])).unwrap_or_default();
    match cal.params {
        LawParams::Linear { k_s0, per_degree } => {
            println!("law: linear, k_s(theta) = k_s0 + b theta_deg");
            println!("  k_s0 = {k_s0:.4e}{} N/m^3", se(0));
            println!("  b    = {per_degree:.4e}{} N/m^3 per deg", se(1));
        }
        LawParams::Coulomb { k_s0, friction_angle_deg } => {
            println!("law: coulomb, k_s(theta) = k_s0 (cos theta - sin theta / tan phi)");
            println!("  k_s0 = {k_s0:.4e}{} N/m^3", se(0));
            println!(
                "  phi  = {friction_angle_deg:.3}{} deg",
                cal.param_se.map(|s| format!(" ± {:.3}", s[1])).unwrap_or_default()
            );
        }
        LawParams::PerSlope => println!("law: per-slope (each speed inverted by root finding)"),
    }
    let level = cal.residuals.first().map(|r| r.k_s).filter(|k| *k > 0.0);
    let mut t =
        table(&["slope deg", "k_s N/m^3", "k_s / first", "observed cm/s", "model cm/s", "residual cm/s"]);
    for r in &cal.residuals {
        t.add_row([
            format!("{}", r.slope_deg),
            format!("{:.4e}", r.k_s),
            level.map_or("-".into(), |l| format!("{:.3}", r.k_s / l)),
            format!("{:.2} ± {:.2}", r.observed * 100.0, r.observed_sd * 100.0),
            format!("{:.2}", r.model * 100.0),
            format!("{:+.2}", r.residual() * 100.0),
        ]);
    }
    println!("{t}");
    println!(
        "RMSE {:.3} cm/s, chi^2 {:.2} over {} slopes",
        cal.rmse() * 100.0,
        cal.chi_squared(),
        cal.residuals.len()
    );
    eprintln!("wrote {}", args.out.display());
    Ok(())
}
