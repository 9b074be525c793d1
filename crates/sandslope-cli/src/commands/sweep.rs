//! `sandslope sweep`: the model over a range of slopes, as a table, JSON, CSV or a figure.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use crate::args::check_positive;
use crate::args::{warn_extrapolated, OverrideArgs, PredictionRecord, RobotArgs, Scenario, TerrainArgs};
use crate::figures;
use crate::figures::sweep::SweepFigure;
use crate::output::{csv_string, num, print_json, table, Format, FormatArgs};
use sandslope_io::load_speeds;

/// Most slopes a sweep evaluates (a guard against `--step 1e-9`).
const MAX_SLOPES: usize = 100_000;

/// Arguments of `sandslope sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// First slope, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 0.0, allow_negative_numbers = true)]
    pub from: f64,
    /// Last slope, degrees (included when the steps land on it).
    #[arg(long, value_name = "DEG", default_value_t = 30.0, allow_negative_numbers = true)]
    pub to: f64,
    /// Slope increment, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 1.0, allow_negative_numbers = true)]
    pub step: f64,
    /// Draw speed, anchoring time and step length against slope into FILE (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Overlay measured speeds (CSV: slope_deg,speed_m_s,speed_sd_m_s) on the speed panel.
    #[arg(long, value_name = "CSV", requires = "plot")]
    pub observed: Option<PathBuf>,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    #[command(flatten)]
    pub over: OverrideArgs,
    #[command(flatten)]
    pub format: FormatArgs,
}

/// The slopes `from, from + step, ..., <= to` (with a tolerance so `to` is not lost to rounding).
pub fn slope_range(from: f64, to: f64, step: f64) -> Result<Vec<f64>> {
    check_positive("--step", step)?;
    if !(from.is_finite() && to.is_finite()) || from > to {
        bail!("--from = {from} must not exceed --to = {to}");
    }
    let n = ((to - from) / step + 1e-9).floor();
    if n >= MAX_SLOPES as f64 {
        bail!("--from {from} --to {to} --step {step} gives {n} slopes; at most {MAX_SLOPES} are allowed");
    }
    Ok((0..=n as usize).map(|i| from + i as f64 * step).collect())
}

/// Runs `sandslope sweep`.
pub fn run(args: SweepArgs) -> Result<()> {
    let slopes = slope_range(args.from, args.to, args.step)?;
    let scenario = Scenario::load(&args.robot, &args.terrain, &args.over)?;
    let evals = slopes.iter().map(|&s| scenario.evaluate(s)).collect::<Result<Vec<_>>>()?;
    let observed = args.observed.as_deref().map(load_speeds).transpose()?;
    let extrapolated: Vec<f64> = evals.iter().filter(|e| e.extrapolated).map(|e| e.slope_deg).collect();
    if !extrapolated.is_empty() {
        warn_extrapolated(&scenario.terrain, &extrapolated);
    }
    if let Some(path) = &args.plot {
        let observed = observed.as_deref().unwrap_or(&[]);
        let figure = SweepFigure {
            evals: &evals,
            observed,
            min_step_m: scenario.robot.min_step(),
            repose_deg: scenario.terrain.repose().map(|r| r.degrees()),
        };
        figures::save(path, &figure)?;
    }
    let records: Vec<PredictionRecord> = evals.iter().map(PredictionRecord::from).collect();
    match args.format.format() {
        Format::Json => print_json(&records)?,
        Format::Csv => print!("{}", csv_string(&records)?),
        Format::Table => {
            let mut t = table(&[
                "slope deg",
                "k_s N/m^3",
                "d_s mm",
                "t1 ms",
                "slip mm",
                "step mm",
                "speed cm/s",
                "regime",
            ]);
            for e in &evals {
                let p = &e.prediction;
                t.add_row([
                    format!("{}", e.slope_deg),
                    format!("{:.3e}", p.k_s),
                    num(p.shear_depth.map(|d| d * 1e3), 2),
                    num(p.anchoring_time.map(|t| t * 1e3), 1),
                    num(p.slip.map(|s| s * 1e3), 2),
                    num(p.step.map(|s| s * 1e3), 2),
                    num(p.speed.map(|v| v * 100.0), 2),
                    p.regime.name().to_string(),
                ]);
            }
            println!("{t}");
        }
    }
    if let Some(path) = &args.plot {
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::slope_range;

    #[test]
    fn range_includes_end_despite_rounding() {
        assert_eq!(slope_range(0.0, 1.0, 0.1).unwrap().len(), 11);
        assert_eq!(slope_range(0.0, 30.0, 5.0).unwrap(), vec![0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0]);
        assert!(slope_range(10.0, 0.0, 1.0).is_err());
        assert!(slope_range(0.0, 10.0, 0.0).is_err());
        assert!(slope_range(0.0, 10.0, 1e-9).is_err());
    }
}
