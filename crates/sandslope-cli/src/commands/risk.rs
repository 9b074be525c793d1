//! `sandslope risk`: the probability of failure when the terrain is uncertain (MODEL.md
//! section 9): per slope, p_fail = P(sinkage or slippage) and P(not success); the safe-slope
//! limit (steepest slope below `--max-risk`); the heaviest safe mass at a slope
//! (`--solve mass`); figures of p_fail against slope and, with `--map`, over (k_n, k_s).

use std::path::PathBuf;

use anyhow::{anyhow, bail, Result};
use clap::{Args, ValueEnum};
use rayon::prelude::*;
use serde::Serialize;

use sandslope::phase::contour_segments;
use sandslope::risk::{
    failure_risk, failure_risk_map, max_safe_mass, safe_slope_limit, SafeLimit, UncertainTerrain,
};
use sandslope::{RegimeProbabilities, Robot, Slope};

use crate::args::{
    beyond_last_point, check_flag, default_axis, parse_axis, warn_extrapolated, RobotArgs, TerrainArgs,
};
use crate::figures::risk::{CurveFigure, MapFigure};
use crate::figures::save;
use crate::output::{csv_string, print_json, table, Format, FormatArgs};
use crate::progress::progress_bar;

/// Default points per axis of the `--map` grid (each cell is a full quadrature).
pub const MAP_POINTS: usize = 48;

/// What `--solve` finds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Solve {
    /// The safe-slope limit: the steepest slope with p_fail below --max-risk.
    Slope,
    /// The heaviest total mass with p_fail below --max-risk at --slope (one slope).
    Mass,
}

/// Arguments of `sandslope risk`.
#[derive(Debug, Args)]
pub struct RiskArgs {
    /// Slope(s), degrees: one value, a comma list (0,10,20) or a range MIN:MAX:N (0:24:13).
    #[arg(long, value_name = "DEG|LIST|MIN:MAX:N", default_value = "0:24:7", allow_hyphen_values = true)]
    pub slope: String,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    /// Coefficient of variation of k_n (sd / value) at every slope, instead of the terrain's
    /// k_n_sd.
    #[arg(long = "cv-n", allow_negative_numbers = true, value_name = "CV")]
    pub cv_n: Option<f64>,
    /// Coefficient of variation of k_s (sd / value) at every slope, instead of the terrain's
    /// k_s_sd.
    #[arg(long = "cv-s", allow_negative_numbers = true, value_name = "CV")]
    pub cv_s: Option<f64>,
    /// Largest acceptable failure probability, for the safe-slope limit and --solve.
    #[arg(long = "max-risk", allow_negative_numbers = true, value_name = "P", default_value_t = 0.05)]
    pub max_risk: f64,
    /// Solve for the safe-slope limit (`slope`) or the heaviest safe mass at --slope (`mass`).
    #[arg(long, value_enum)]
    pub solve: Option<Solve>,
    /// Draw p_fail against slope (or, with --map, over (k_n, k_s)) to this .png or .svg file.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// With --plot: a p_fail heat map over (k_n, k_s) at the first --slope.
    #[arg(long, requires = "plot")]
    pub map: bool,
    /// --map grid of median k_n, N/m^3: MIN:MAX:N[:log|:lin] (default: terrain's / 100 to x 100, 48 points).
    #[arg(long = "k-n", value_name = "MIN:MAX:N[:log|:lin]", requires = "map")]
    pub k_n: Option<String>,
    /// --map grid of median k_s, N/m^3: MIN:MAX:N[:log|:lin] (default: terrain's / 1000 to x 100, 48 points).
    #[arg(long = "k-s", value_name = "MIN:MAX:N[:log|:lin]", requires = "map")]
    pub k_s: Option<String>,
    #[command(flatten)]
    pub format: FormatArgs,
}

/// Most probability evaluations one run makes (slopes, or map cells): 2^16, about a minute or
/// two on two cores at the ~3 ms a quadrature takes.
const MAX_QUADRATURES: u64 = 1 << 16;

/// Parses `--slope`: `DEG`, `DEG,DEG,...` or `MIN:MAX:N` (N evenly spaced, ends included).
pub fn parse_slopes(text: &str) -> Result<Vec<f64>> {
    let number = |s: &str| -> Result<f64> {
        let v: f64 =
            s.trim().parse().map_err(|_| anyhow!("--slope: `{}` is not a number (in {text})", s.trim()))?;
        Slope::from_signed_degrees(v).map_err(|e| anyhow!("{}", e.renamed("--slope")))?;
        Ok(v)
    };
    if text.contains(':') {
        let parts: Vec<&str> = text.split(':').collect();
        if parts.len() != 3 {
            bail!("--slope = {text} must be DEG, a comma list, or MIN:MAX:N (e.g. 0:24:13)");
        }
        let (lo, hi) = (number(parts[0])?, number(parts[1])?);
        let n: usize = parts[2].trim().parse().ok().filter(|&n| n >= 2).ok_or_else(|| {
            anyhow!("--slope: N `{}` must be a whole number of at least 2 (in {text})", parts[2])
        })?;
        if hi <= lo {
            bail!("--slope = {text}: MAX must be greater than MIN");
        }
        return Ok((0..n).map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64).collect());
    }
    text.split(',').map(number).collect()
}

/// The regime probabilities as printed by `--json`.
#[derive(Debug, Clone, Serialize)]
struct RegimeRecord {
    success: f64,
    metastable: f64,
    slippage: f64,
    sinkage: f64,
}

/// One slope as printed by `--json`: exactly these keys.
#[derive(Debug, Clone, Serialize)]
struct RiskRecord {
    slope_deg: f64,
    p_fail: f64,
    p_not_success: f64,
    p_regime: RegimeRecord,
}

/// One slope as printed by `--csv`.
#[derive(Debug, Clone, Serialize)]
struct RiskRow {
    slope_deg: f64,
    cv_n: f64,
    cv_s: f64,
    p_fail: f64,
    p_not_success: f64,
    p_success: f64,
    p_metastable: f64,
    p_slippage: f64,
    p_sinkage: f64,
}

/// `--solve slope` as printed by `--json`.
#[derive(Debug, Clone, Serialize)]
struct SlopeSolution {
    max_risk: f64,
    /// The steepest safe slope, or null when none was found (see `limit`).
    safe_slope_deg: Option<f64>,
    limit: SafeLimit,
}

/// `--solve mass` as printed by `--json`.
#[derive(Debug, Clone, Serialize)]
struct MassSolution {
    slope_deg: f64,
    max_risk: f64,
    robot_mass_kg: f64,
    /// The heaviest safe total mass, or null when none was found (see `limit`).
    max_mass_kg: Option<f64>,
    max_payload_kg: Option<f64>,
    limit: SafeLimit,
}

fn record(slope_deg: f64, p: &RegimeProbabilities) -> RiskRecord {
    RiskRecord {
        slope_deg,
        p_fail: p.p_fail(),
        p_not_success: p.p_not_success(),
        p_regime: RegimeRecord {
            success: p.success,
            metastable: p.metastable,
            slippage: p.slippage,
            sinkage: p.sinkage,
        },
    }
}

fn slope_of(deg: f64) -> Result<Slope> {
    Slope::from_signed_degrees(deg).map_err(|e| anyhow!("{}", e.renamed("--slope")))
}

fn describe_slope_limit(limit: &SafeLimit, max_risk: f64) -> String {
    match limit {
        SafeLimit::NoneSafe { p_fail } => {
            format!("no slope is safe: p_fail = {p_fail:.4} >= {max_risk} already on level ground")
        }
        SafeLimit::Limit { value, p_fail } => format!(
            "safe-slope limit: p_fail < {max_risk} from level up to {value:.3} deg (p_fail there {p_fail:.4})"
        ),
        SafeLimit::BeyondRange { up_to, p_fail } => {
            format!(
                "p_fail < {max_risk} at every slope up to {up_to} deg searched (p_fail there {p_fail:.4})"
            )
        }
    }
}

/// Runs `sandslope risk`.
pub fn run(args: RiskArgs) -> Result<()> {
    let robot = args.robot.load()?;
    let slopes = parse_slopes(&args.slope)?;
    if slopes.len() as u64 > MAX_QUADRATURES {
        bail!(
            "--slope gives {} slopes, each a quadrature of a few ms; at most {MAX_QUADRATURES} are allowed",
            slopes.len()
        );
    }
    let max_risk = check_flag("--max-risk", args.max_risk, 0.0, 1.0)?;
    if max_risk <= 0.0 || max_risk >= 1.0 {
        bail!("--max-risk = {max_risk} must be strictly between 0 and 1");
    }
    let terrain = UncertainTerrain::new(args.terrain.load()?, args.cv_n, args.cv_s).map_err(|e| {
        let hint = if e.key.starts_with("points") {
            // e.key is e.g. `points[0].k_n_sd`: name what is missing, not its NaN placeholder.
            let what = e.key.rsplit('.').next().unwrap_or("k_n_sd / k_s_sd").to_string();
            let flag = if what.starts_with("k_n") { "--cv-n" } else { "--cv-s" };
            format!(
                "terrain `{}` has no {what} (standard deviation across trials) at {}: give {flag} \
                 (a coefficient of variation, sd / value, e.g. {flag} 0.2), or add {what} to every point",
                args.terrain.terrain,
                e.key.split('.').next().unwrap_or("a point"),
            )
        } else {
            let flag = format!("--{}", e.key.replace('_', "-"));
            format!("{}", e.renamed(flag))
        };
        anyhow!(hint)
    })?;
    if let Some(p) = &args.plot {
        crate::figures::format_of(p)?;
    }
    let extrapolated = beyond_last_point(terrain.terrain(), &slopes);
    if !extrapolated.is_empty() {
        warn_extrapolated(terrain.terrain(), &extrapolated);
    }
    let json = args.format.format() == Format::Json;

    if args.map {
        if let Some(path) = &args.plot {
            draw_map(&args, &robot, &terrain, slopes[0], max_risk, path, json)?;
        }
    }

    match args.solve {
        Some(Solve::Mass) => {
            if slopes.len() != 1 {
                bail!("--solve mass needs exactly one --slope (got {})", args.slope);
            }
            let slope = slope_of(slopes[0])?;
            let limit = max_safe_mass(&robot, slope, &terrain, max_risk).map_err(|e| anyhow!("{e}"))?;
            let own = robot.mass();
            let sol = MassSolution {
                slope_deg: slopes[0],
                max_risk,
                robot_mass_kg: own,
                max_mass_kg: limit.value(),
                max_payload_kg: limit.value().map(|m| m - own),
                limit,
            };
            if args.plot.is_some() && !args.map {
                let s_limit = safe_slope_limit(&robot, &terrain, max_risk).map_err(|e| anyhow!("{e}"))?;
                draw_curve(&args, &robot, &terrain, &slopes, max_risk, &s_limit, json)?;
            }
            return match args.format.format() {
                Format::Json => print_json(&sol),
                Format::Csv => {
                    print!("{}", csv_string(&[sol_row(&sol)])?);
                    Ok(())
                }
                Format::Table => {
                    println!("{}", describe_mass_limit(&sol));
                    Ok(())
                }
            };
        }
        Some(Solve::Slope) => {
            let limit = safe_slope_limit(&robot, &terrain, max_risk).map_err(|e| anyhow!("{e}"))?;
            if args.plot.is_some() && !args.map {
                draw_curve(&args, &robot, &terrain, &slopes, max_risk, &limit, json)?;
            }
            let sol = SlopeSolution { max_risk, safe_slope_deg: limit.value(), limit };
            return match args.format.format() {
                Format::Json => print_json(&sol),
                Format::Csv => {
                    #[derive(Serialize)]
                    struct Row {
                        max_risk: f64,
                        safe_slope_deg: Option<f64>,
                    }
                    print!("{}", csv_string(&[Row { max_risk, safe_slope_deg: sol.safe_slope_deg }])?);
                    Ok(())
                }
                Format::Table => {
                    println!("{}", describe_slope_limit(&limit, max_risk));
                    Ok(())
                }
            };
        }
        None => {}
    }

    // Probabilities at each requested slope.
    let results: Vec<(f64, RegimeProbabilities, (f64, f64))> = slopes
        .par_iter()
        .map(|&d| {
            let s = slope_of(d)?;
            let (_, u) = terrain.at(s);
            Ok((d, failure_risk(&robot, s, &terrain), (u.cv_n(), u.cv_s())))
        })
        .collect::<Result<_>>()?;
    let need_limit = args.format.format() == Format::Table || (args.plot.is_some() && !args.map);
    let limit = if need_limit {
        Some(safe_slope_limit(&robot, &terrain, max_risk).map_err(|e| anyhow!("{e}"))?)
    } else {
        None
    };
    if let (Some(limit), false) = (&limit, args.map) {
        if args.plot.is_some() {
            draw_curve(&args, &robot, &terrain, &slopes, max_risk, limit, json)?;
        }
    }
    match args.format.format() {
        Format::Json => {
            let records: Vec<RiskRecord> = results.iter().map(|(d, p, _)| record(*d, p)).collect();
            if records.len() == 1 {
                print_json(&records[0])
            } else {
                print_json(&records)
            }
        }
        Format::Csv => {
            let rows: Vec<RiskRow> = results
                .iter()
                .map(|(d, p, (cv_n, cv_s))| RiskRow {
                    slope_deg: *d,
                    cv_n: *cv_n,
                    cv_s: *cv_s,
                    p_fail: p.p_fail(),
                    p_not_success: p.p_not_success(),
                    p_success: p.success,
                    p_metastable: p.metastable,
                    p_slippage: p.slippage,
                    p_sinkage: p.sinkage,
                })
                .collect();
            print!("{}", csv_string(&rows)?);
            Ok(())
        }
        Format::Table => {
            let mut t = table(&[
                "slope (deg)",
                "cv k_n",
                "cv k_s",
                "p_fail",
                "p_not_success",
                "P(sinkage)",
                "P(slippage)",
                "P(metastable)",
                "P(success)",
            ]);
            let f = |x: f64| format!("{x:.4}");
            for (d, p, (cv_n, cv_s)) in &results {
                t.add_row([
                    format!("{d}"),
                    format!("{cv_n:.3}"),
                    format!("{cv_s:.3}"),
                    f(p.p_fail()),
                    f(p.p_not_success()),
                    f(p.sinkage),
                    f(p.slippage),
                    f(p.metastable),
                    f(p.success),
                ]);
            }
            println!("{t}");
            if let Some(limit) = &limit {
                println!("{}", describe_slope_limit(limit, max_risk));
            }
            println!("p_fail = P(sinkage or slippage); log-normal k_n, k_s (MODEL.md section 9), deterministic quadrature");
            Ok(())
        }
    }
}

fn describe_mass_limit(sol: &MassSolution) -> String {
    match sol.limit {
        SafeLimit::NoneSafe { p_fail } => format!(
            "no payload is safe at {} deg: p_fail = {p_fail:.4} >= {} already at the robot's own {} kg",
            sol.slope_deg, sol.max_risk, sol.robot_mass_kg
        ),
        SafeLimit::Limit { value, p_fail } => format!(
            "heaviest safe total mass at {} deg: {value:.4} kg (payload {:.4} kg over the robot's {} kg), p_fail {p_fail:.4} < {}",
            sol.slope_deg,
            value - sol.robot_mass_kg,
            sol.robot_mass_kg,
            sol.max_risk
        ),
        SafeLimit::BeyondRange { up_to, p_fail } => format!(
            "p_fail < {} at {} deg for every total mass up to {up_to:.4} kg searched (p_fail there {p_fail:.4})",
            sol.max_risk, sol.slope_deg
        ),
    }
}

#[derive(Serialize)]
struct MassRow {
    slope_deg: f64,
    max_risk: f64,
    robot_mass_kg: f64,
    max_mass_kg: Option<f64>,
    max_payload_kg: Option<f64>,
}

fn sol_row(s: &MassSolution) -> MassRow {
    MassRow {
        slope_deg: s.slope_deg,
        max_risk: s.max_risk,
        robot_mass_kg: s.robot_mass_kg,
        max_mass_kg: s.max_mass_kg,
        max_payload_kg: s.max_payload_kg,
    }
}

/// p_fail and p_not_success against slope, sampled every 0.25 degrees.
fn draw_curve(
    args: &RiskArgs,
    robot: &Robot,
    terrain: &UncertainTerrain,
    slopes: &[f64],
    max_risk: f64,
    limit: &SafeLimit,
    quiet: bool,
) -> Result<()> {
    let Some(path) = &args.plot else { return Ok(()) };
    let requested_max = slopes.iter().fold(0.0f64, |a, &d| a.max(d.abs()));
    let mut hi = requested_max.max(30.0);
    if let Some(v) = limit.value() {
        hi = hi.max(v * 1.25);
    }
    if let Some(r) = terrain.terrain().repose() {
        hi = hi.max(r.degrees() + 3.0);
    }
    let hi = hi.min(89.5);
    let n = (hi / 0.25).round() as usize;
    let bar = progress_bar(n as u64 + 1, quiet, "p_fail curve");
    let curve: Vec<(f64, RegimeProbabilities)> = (0..=n)
        .into_par_iter()
        .filter_map(|i| {
            let d = hi * i as f64 / n as f64;
            let p = Slope::from_degrees(d).ok().map(|s| (d, failure_risk(robot, s, terrain)));
            bar.inc(1);
            p
        })
        .collect();
    bar.finish_and_clear();
    let points: Vec<(f64, f64)> = slopes
        .iter()
        .filter_map(|&d| slope_of(d).ok().map(|s| (d.abs(), failure_risk(robot, s, terrain).p_fail())))
        .collect();
    let figure = CurveFigure {
        curve,
        points,
        hi,
        max_risk,
        limit: *limit,
        title: format!(
            "Failure risk: m = {} kg on {}",
            robot.mass(),
            terrain.terrain().name().unwrap_or("terrain")
        ),
    };
    save(path, &figure)
}

/// The p_fail heat map over median (k_n, k_s) at one slope.
fn draw_map(
    args: &RiskArgs,
    robot: &Robot,
    terrain: &UncertainTerrain,
    slope_deg: f64,
    max_risk: f64,
    path: &std::path::Path,
    quiet: bool,
) -> Result<()> {
    let slope = slope_of(slope_deg)?;
    let (ground, u) = terrain.at(slope);
    let k_n_axis = match &args.k_n {
        Some(t) => parse_axis("--k-n", t)?,
        None => default_axis("--k-n", &[ground.k_n], 100.0, 100.0, MAP_POINTS)?,
    };
    let k_s_axis = match &args.k_s {
        Some(t) => parse_axis("--k-s", t)?,
        None => default_axis("--k-s", &[ground.k_s], 1000.0, 100.0, MAP_POINTS)?,
    };
    let cells = (k_n_axis.len() * k_s_axis.len()) as u64;
    if cells > MAX_QUADRATURES {
        bail!(
            "--k-n and --k-s give {cells} map cells, each a full quadrature of a few ms; at most {MAX_QUADRATURES} are allowed"
        );
    }
    let bar = progress_bar(cells, quiet, "p_fail map");
    let probs = failure_risk_map(robot, slope, ground.repose, &k_n_axis, &k_s_axis, u, &|| bar.inc(1));
    bar.finish_and_clear();
    let p_fail: Vec<f64> = probs.iter().map(|p| p.p_fail()).collect();
    let contour = contour_segments(&k_n_axis, &k_s_axis, &p_fail, max_risk);
    let figure = MapFigure {
        k_n_axis,
        k_s_axis,
        p_fail,
        contour,
        star: (ground.k_n, ground.k_s),
        max_risk,
        title: format!(
            "p_fail at {slope_deg}\u{b0}, m = {} kg, cv k_n = {:.2}, cv k_s = {:.2}",
            robot.mass(),
            u.cv_n(),
            u.cv_s()
        ),
    };
    save(path, &figure)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_lists_and_ranges() {
        assert_eq!(parse_slopes("20").unwrap(), vec![20.0]);
        assert_eq!(parse_slopes("0, 10,20").unwrap(), vec![0.0, 10.0, 20.0]);
        assert_eq!(parse_slopes("0:24:4").unwrap(), vec![0.0, 8.0, 16.0, 24.0]);
        for bad in ["x", "0:24", "0:24:1", "24:0:5", "95", "0:24:q"] {
            assert!(parse_slopes(bad).unwrap_err().to_string().contains("--slope"), "{bad}");
        }
    }
}
