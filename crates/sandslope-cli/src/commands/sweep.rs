//! `sandslope sweep`: the model over a range of slopes, as a table, JSON, CSV or a figure.

use sandslope_request::format::Outcome;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use crate::args::{warn_extrapolated, FieldArgs, OverrideArgs, RobotArgs, TerrainArgs};
use crate::figures;
use crate::figures::sweep::SweepFigure;
use crate::output::{csv_string, num, print_json, ruled_out_note, speed_cell, table, Format, FormatArgs};
use sandslope_io::load_speeds;
use sandslope_request::calibrate::OBSERVED;
use sandslope_request::SweepRequest;

/// Arguments of `sandslope sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// `--slope`, `--from`, `--to` and `--step`: the request's own fields
    /// ([`sandslope_request::sweep::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<SweepRequest>,
    /// Draw speed, anchoring time and step length against slope into FILE (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Overlay measured speeds (CSV: slope_deg,speed_m_s,speed_sd_m_s) on the speed panel
    /// (the file of `calibrate`'s field [`OBSERVED`]).
    #[arg(long = OBSERVED.flag, value_name = OBSERVED.value_name, requires = "plot")]
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

impl SweepArgs {
    /// The request these flags make (the one `serve`'s `/api/sweep` builds too).
    pub fn request(&self) -> sandslope_request::Result<SweepRequest> {
        SweepRequest::with_scenario(&self.fields.pairs, self.over.request(&self.robot, &self.terrain))
    }
}

/// Runs `sandslope sweep`.
pub fn run(args: SweepArgs) -> Result<()> {
    let request = args.request()?;
    request.slopes()?;
    let scenario = request.scenario.scenario()?;
    let evals = request.answer_in(&scenario)?;
    let observed = args.observed.as_deref().map(load_speeds).transpose()?;
    let extrapolated: Vec<f64> = evals.iter().filter(|e| e.extrapolated).map(|e| e.slope_deg).collect();
    if !extrapolated.is_empty() {
        warn_extrapolated(scenario.terrain(), &extrapolated);
    }
    if let Some(path) = &args.plot {
        let observed = observed.as_deref().unwrap_or(&[]);
        let figure = SweepFigure {
            evals: &evals,
            observed,
            min_step_m: scenario.robot().min_step(),
            repose_deg: scenario.terrain().repose().map(|r| r.degrees()),
        };
        figures::save(path, &figure)?;
    }
    match args.format.format() {
        Format::Json => print_json(&evals)?,
        Format::Csv => print!("{}", csv_string(&evals)?),
        Format::Table => {
            let mut t = table(&[
                "slope deg",
                "k_s N/m^3",
                "d_s mm",
                "t1 ms",
                "slip mm",
                "step mm",
                "speed cm/s",
                "outcome (regime)",
                "cause",
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
                    speed_cell(e),
                    p.regime.in_words(),
                    p.cause.name().to_string(),
                ]);
            }
            println!("{t}");
            if evals.iter().any(|e| e.speed_ruled_out()) {
                println!("{}", ruled_out_note());
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        sweep: SweepArgs,
    }

    #[test]
    fn range_errors_name_the_flags() {
        let parse = |a: &[&str]| Cli::parse_from([&["x"], a].concat()).sweep;
        let slopes = |args: &SweepArgs| args.request().and_then(|r| r.slopes());
        let msg = slopes(&parse(&["--from", "10", "--to", "0"])).unwrap_err().to_string();
        assert!(msg.starts_with("--from = 10"), "{msg}");
        let msg = slopes(&parse(&["--step", "-1"])).unwrap_err().to_string();
        assert!(msg.starts_with("--step = -1"), "{msg}");
        let msg = slopes(&parse(&["--step", "1e-9"])).unwrap_err().to_string();
        assert!(msg.starts_with("--step = 0.000000001") && msg.contains("100000"), "{msg}");
        assert_eq!(
            slopes(&parse(&["--from", "-5", "--to", "5", "--step", "5"])).unwrap(),
            vec![-5.0, 0.0, 5.0]
        );
    }

    /// `--slope` takes the grammar of `risk` and `phase`: -5:5:3 is three slopes, -5, 0 and 5,
    /// the same as the shorthand above; a list is taken as given; with --from it is refused.
    #[test]
    fn slope_takes_the_one_grammar_of_every_command() {
        let parse = |a: &[&str]| Cli::try_parse_from([&["x"], a].concat()).map(|c| c.sweep);
        let slopes = |a: &[&str]| parse(a).unwrap().request().unwrap().slopes().unwrap();
        assert_eq!(slopes(&["--slope", "-5:5:3"]), vec![-5.0, 0.0, 5.0]);
        assert_eq!(slopes(&["--slope", "0,12.5,24"]), vec![0.0, 12.5, 24.0]);
        assert_eq!(slopes(&["--slope", "0:30:31"]).len(), 31);
        assert!(parse(&["--slope", "0:30:31", "--from", "5"]).is_err());
        let msg = parse(&["--slope", "0:30:1"]).unwrap().request().unwrap().slopes().unwrap_err().to_string();
        assert!(msg.contains("write 0:30:31"), "{msg}");
    }
}
