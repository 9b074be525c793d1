//! The sweep figure: speed, anchoring time and step length against slope, stacked in three
//! panels, with observed speeds and their SDs overlaid.

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope::SpeedObservation;

use super::palette;
use super::{ChartSetup, Figure};
use crate::plot_err;
use sandslope::SlopeEvaluation;

/// Speed, anchoring time and step length against slope, stacked in three panels.
pub struct SweepFigure<'a> {
    pub evals: &'a [SlopeEvaluation],
    pub observed: &'a [SpeedObservation],
    pub min_step_m: f64,
    pub repose_deg: Option<f64>,
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
        let x_range = super::range(
            x.iter().copied().chain(self.observed.iter().map(|o| o.slope.degrees())),
            (0.0, 30.0),
        );
        let speed: Vec<Option<f64>> = self.evals.iter().map(|e| e.speed().map(|v| v * 100.0)).collect();
        // Where the regime rules the stance model's speed out (at or above repose), that speed
        // is drawn dashed and labelled, not as a speed the robot makes.
        let ruled_out: Vec<Option<f64>> = self
            .evals
            .iter()
            .map(|e| e.model_speed().filter(|_| e.speed_ruled_out()).map(|v| v * 100.0))
            .collect();
        let obs: Vec<(f64, f64, f64)> =
            self.observed.iter().map(|o| (o.slope.degrees(), o.speed * 100.0, o.speed_sd * 100.0)).collect();
        let speed_range = super::range(
            speed
                .iter()
                .chain(&ruled_out)
                .flatten()
                .copied()
                .chain(obs.iter().flat_map(|&(_, v, sd)| [v - sd, v + sd]))
                .chain([0.0]),
            (0.0, 16.0),
        );
        let upper = SeriesLabelPosition::UpperRight;
        let panel = Panel {
            x_range,
            x: &x,
            observed: &[],
            reference: None,
            legend: upper,
            repose: self.repose_deg,
            ruled_out: &[],
        };
        let speed_panel = Panel { observed: &obs, ruled_out: &ruled_out, ..panel.clone() };
        draw_panel(&panels[0], "Step-averaged speed", "speed v (cm/s)", speed_range, &speed, &speed_panel)?;
        let t1: Vec<Option<f64>> =
            self.evals.iter().map(|e| e.prediction.anchoring_time.map(|t| t * 1e3)).collect();
        let t1_range = super::range(t1.iter().flatten().copied().chain([0.0]), (0.0, 500.0));
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
        let step_range = super::range(step.iter().flatten().copied().chain([0.0, s_min]), (0.0, 80.0));
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
    /// Model values the regime rules out, drawn dashed (empty: none).
    ruled_out: &'a [Option<f64>],
}

/// Splits a curve into its defined stretches (gaps where the value is `None`).
fn pieces(x: &[f64], y: &[Option<f64>]) -> Vec<Vec<(f64, f64)>> {
    let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for (&xi, yi) in x.iter().zip(y) {
        match yi {
            Some(v) => segments.last_mut().expect("non-empty").push((xi, *v)),
            None if !segments.last().expect("non-empty").is_empty() => segments.push(Vec::new()),
            None => {}
        }
    }
    segments.retain(|s| !s.is_empty());
    segments
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
    let setup = ChartSetup {
        caption: Some((title, 22.0)),
        x_ticks: Some(&super::tick),
        y_ticks: Some(&super::tick),
        ..ChartSetup::SLOPE
    };
    let mut chart = setup.build(area, x_range.0..x_range.1, y_range.0..y_range.1, "slope (deg)", y_label)?;
    super::shade_repose(
        &mut chart,
        panel.repose,
        x_range,
        y_range,
        "at or above the angle of repose: slippage",
    )?;
    if let Some((level, label)) = panel.reference {
        super::reference_line(&mut chart, level, label, x_range)?;
    }
    // Zero, where the curve goes below it (the robot loses ground).
    if y_range.0 < 0.0 && y_range.1 > 0.0 {
        chart
            .draw_series([PathElement::new(vec![(x_range.0, 0.0), (x_range.1, 0.0)], BLACK.stroke_width(1))])
            .map_err(plot_err)?;
    }
    for (i, seg) in pieces(x, y).into_iter().enumerate() {
        let series = chart
            .draw_series(LineSeries::new(seg, ShapeStyle::from(&palette::CLOSED_FORM_RED).stroke_width(2)))
            .map_err(plot_err)?;
        if i == 0 {
            series.label("model").legend(|(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], palette::CLOSED_FORM_RED.stroke_width(2))
            });
        }
    }
    let faded = palette::CLOSED_FORM_RED.mix(0.6).stroke_width(2);
    for (i, seg) in pieces(x, panel.ruled_out).into_iter().enumerate() {
        let series = chart.draw_series(DashedLineSeries::new(seg, 6, 5, faded)).map_err(plot_err)?;
        if i == 0 {
            series.label("stance model, ruled out: the surface yields").legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (6, 0)], faded)
                    + PathElement::new(vec![(11, 0), (17, 0)], faded)
            });
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
    super::legend_box(&mut chart, panel.legend.clone(), 15.0, super::LegendBox::LIGHT)?;
    Ok(())
}
