//! `sandslope sweep`: the model over a range of slopes, as a table, JSON, CSV or a figure.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::common::{
    warn_extrapolated, Evaluation, OverrideArgs, PredictionRecord, RobotArgs, Scenario, TerrainArgs,
};
use crate::error::plot_err;
use crate::inputs::{check_positive, load_speeds};
use crate::output::{csv_string, num, print_json, table, Format, FormatArgs};
use crate::plot::{self, font, Figure};
use sandslope::SpeedObservation;

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
        plot::save(path, &figure)?;
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

/// Speed, anchoring time and step length against slope, stacked in three panels.
struct SweepFigure<'a> {
    evals: &'a [Evaluation],
    observed: &'a [SpeedObservation],
    min_step_m: f64,
    repose_deg: Option<f64>,
}

impl Figure for SweepFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (900, 1100)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let panels = root.split_evenly((3, 1));
        let x: Vec<f64> = self.evals.iter().map(|e| e.slope_deg).collect();
        let x_range = plot::range(
            x.iter().copied().chain(self.observed.iter().map(|o| o.slope.degrees())),
            (0.0, 30.0),
        );
        let speed: Vec<Option<f64>> =
            self.evals.iter().map(|e| e.prediction.speed.map(|v| v * 100.0)).collect();
        let obs: Vec<(f64, f64, f64)> =
            self.observed.iter().map(|o| (o.slope.degrees(), o.speed * 100.0, o.speed_sd * 100.0)).collect();
        let speed_range = plot::range(
            speed
                .iter()
                .flatten()
                .copied()
                .chain(obs.iter().flat_map(|&(_, v, sd)| [v - sd, v + sd]))
                .chain([0.0]),
            (0.0, 16.0),
        );
        let upper = SeriesLabelPosition::UpperRight;
        let panel =
            Panel { x_range, x: &x, observed: &[], reference: None, legend: upper, repose: self.repose_deg };
        let speed_panel = Panel { observed: &obs, ..panel.clone() };
        draw_panel(&panels[0], "Step-averaged speed", "speed v (cm/s)", speed_range, &speed, &speed_panel)?;
        let t1: Vec<Option<f64>> =
            self.evals.iter().map(|e| e.prediction.anchoring_time.map(|t| t * 1e3)).collect();
        let t1_range = plot::range(t1.iter().flatten().copied().chain([0.0]), (0.0, 500.0));
        let lower = SeriesLabelPosition::LowerRight;
        draw_panel(
            &panels[1],
            "Anchoring time",
            "anchoring time t1 (ms)",
            t1_range,
            &t1,
            &Panel { legend: lower, ..panel.clone() },
        )?;
        let step: Vec<Option<f64>> = self.evals.iter().map(|e| e.prediction.step.map(|s| s * 1e3)).collect();
        let s_min = self.min_step_m * 1e3;
        let step_range = plot::range(step.iter().flatten().copied().chain([0.0, s_min]), (0.0, 80.0));
        let reference = Some((s_min, "s_min: success above, metastable below"));
        draw_panel(
            &panels[2],
            "Net step length",
            "net step s (mm)",
            step_range,
            &step,
            &Panel { reference, ..panel },
        )?;
        Ok(())
    }
}

/// What the three panels share, and what each may add.
#[derive(Clone)]
struct Panel<'a> {
    x_range: (f64, f64),
    x: &'a [f64],
    /// Observations `(slope, value, sd)` drawn with error bars.
    observed: &'a [(f64, f64, f64)],
    /// A dashed horizontal reference line and its label.
    reference: Option<(f64, &'a str)>,
    legend: SeriesLabelPosition,
    /// The terrain's angle of repose: slopes at or above it are shaded (regime slippage).
    repose: Option<f64>,
}

/// One panel: the model curve (gaps where undefined), an optional reference line and optional
/// observations with error bars.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    y_label: &str,
    y_range: (f64, f64),
    y: &[Option<f64>],
    panel: &Panel<'_>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let (x_range, x, observed) = (panel.x_range, panel.x, panel.observed);
    let mut chart = ChartBuilder::on(area)
        .caption(title, font(22.0))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("slope (deg)")
        .y_desc(y_label)
        .label_style(font(15.0))
        .axis_desc_style(font(17.0))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(plot_err)?;
    // Split the curve where the model is undefined (no anchoring).
    let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for (&xi, yi) in x.iter().zip(y) {
        match yi {
            Some(v) => segments.last_mut().expect("non-empty").push((xi, *v)),
            None if !segments.last().expect("non-empty").is_empty() => segments.push(Vec::new()),
            None => {}
        }
    }
    if let Some(repose) = panel.repose.filter(|r| *r < x_range.1) {
        let shade = RGBColor(200, 200, 200).mix(0.45);
        chart
            .draw_series([Rectangle::new(
                [(repose.max(x_range.0), y_range.0), (x_range.1, y_range.1)],
                shade.filled(),
            )])
            .map_err(plot_err)?
            .label("at or above the angle of repose: slippage")
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], shade.filled()));
    }
    if let Some((level, label)) = panel.reference {
        let grey = RGBColor(90, 90, 90);
        chart
            .draw_series(DashedLineSeries::new(
                [(x_range.0, level), (x_range.1, level)],
                8,
                5,
                grey.stroke_width(2),
            ))
            .map_err(plot_err)?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey.stroke_width(2)));
    }
    let mut first = true;
    for seg in segments.into_iter().filter(|s| !s.is_empty()) {
        let series = chart
            .draw_series(LineSeries::new(seg, ShapeStyle::from(&RED).stroke_width(2)))
            .map_err(plot_err)?;
        if first {
            series
                .label("model")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
            first = false;
        }
    }
    if !observed.is_empty() {
        chart
            .draw_series(
                observed.iter().map(|&(x, v, sd)| {
                    ErrorBar::new_vertical(x, v - sd, v, v + sd, BLACK.stroke_width(2), 10)
                }),
            )
            .map_err(plot_err)?;
        chart
            .draw_series(observed.iter().map(|&(x, v, _)| Circle::new((x, v), 5, BLACK.filled())))
            .map_err(plot_err)?
            .label("observed (mean ± SD)")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, BLACK.filled()));
    }
    chart
        .configure_series_labels()
        .label_font(font(15.0))
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .position(panel.legend.clone())
        .draw()
        .map_err(plot_err)?;
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
