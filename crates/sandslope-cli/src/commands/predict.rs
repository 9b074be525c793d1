//! `sandslope predict`: every model quantity for one robot, terrain and slope.

use anyhow::Result;
use clap::Args;
use sandslope_request::format::{Explain, Outcome};
use sandslope_request::scenario::load_terrain;
use sandslope_request::PredictRequest;

use crate::args::{warn_extrapolated, FieldArgs, OverrideArgs, RobotArgs, TerrainArgs};
use crate::output::{
    csv_string, num, print_json, ruled_out_note, sci, speed_cell, table, Format, FormatArgs,
};

/// Arguments of `sandslope predict`.
#[derive(Debug, Args)]
pub struct PredictArgs {
    /// `--slope`: the request's own field ([`sandslope_request::predict::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<PredictRequest>,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    #[command(flatten)]
    pub over: OverrideArgs,
    #[command(flatten)]
    pub format: FormatArgs,
}

impl PredictArgs {
    /// The request these flags make (the one `serve`'s `/api/predict` and Python build too).
    pub fn request(&self) -> sandslope_request::Result<PredictRequest> {
        PredictRequest::with_scenario(&self.fields.pairs, self.over.request(&self.robot, &self.terrain))
    }
}

/// Runs `sandslope predict`: the request's answer (the one `/api/predict` gives), written as a
/// table, JSON or CSV.
pub fn run(args: PredictArgs) -> Result<()> {
    let request = args.request()?;
    let e = request.answer()?;
    let slope = request.slope;
    if e.extrapolated {
        warn_extrapolated(&load_terrain(&request.scenario.terrain)?, &[slope]);
    }
    if slope < 0.0 {
        eprintln!(
            "note: descending {} deg is evaluated as climbing {} deg (docs/model.md §8)",
            -slope,
            slope.abs()
        );
    }
    match args.format.format() {
        Format::Json => print_json(&e),
        Format::Csv => {
            print!("{}", csv_string(&[&e])?);
            Ok(())
        }
        Format::Table => {
            let p = &e.prediction;
            let mm = |x: Option<f64>| num(x.map(|v| v * 1e3), 2);
            let crit = |c: &Result<f64, _>| c.as_ref().map_or_else(|_| "none".to_string(), |k| sci(*k));
            let mut t = table(&["quantity", "value", "unit"]);
            let rows: Vec<[String; 3]> = vec![
                ["slope".into(), format!("{slope}"), "deg".into()],
                ["normal resistance k_n".into(), sci(p.k_n), "N/m^3".into()],
                ["shear strength k_s".into(), sci(p.k_s), "N/m^3".into()],
                ["normal equilibrium depth d_n".into(), mm(p.normal_depth), "mm".into()],
                ["level-sand step s*".into(), mm(Some(p.level_step)), "mm".into()],
                ["shear-equilibrium depth d_s".into(), mm(p.shear_depth), "mm".into()],
                ["anchoring time t1".into(), num(p.anchoring_time.map(|t| t * 1e3), 1), "ms".into()],
                ["backward slip s1".into(), mm(p.slip), "mm".into()],
                ["propulsion s2".into(), mm(p.propulsion), "mm".into()],
                ["net step s".into(), mm(p.step), "mm".into()],
                ["speed v".into(), speed_cell(&e), "cm/s".into()],
                ["critical k_s for progress (s > 0)".into(), crit(&e.critical_progress), "N/m^3".into()],
                [
                    "critical k_s for robust progress (s >= s_min)".into(),
                    crit(&e.critical_robust),
                    "N/m^3".into(),
                ],
                ["k_s margin (k_s / critical k_s for progress)".into(), num(e.k_s_margin, 2), "".into()],
                ["outcome (regime)".into(), p.regime.in_words(), "".into()],
                ["cause".into(), p.cause.name().into(), "".into()],
            ];
            for r in rows {
                t.add_row(r);
            }
            println!("{t}");
            println!("{}: {}", p.regime.in_words(), p.cause.explain());
            if e.speed_ruled_out() {
                println!("{}", ruled_out_note());
            }
            for (what, c) in [("progress", &e.critical_progress), ("robust progress", &e.critical_robust)] {
                if let Err(why) = c {
                    println!("{what}: {why}");
                }
            }
            Ok(())
        }
    }
}
