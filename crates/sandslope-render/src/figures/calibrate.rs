//! The calibration figure (`calibrate --plot`): observed speeds (mean ± SD, and the SD with the
//! error floor) against the fitted model curve, and each observation's pull below.

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope::calibrate::{ObservationKind, Pull};

use super::palette;
use super::{ChartSetup, Figure};
use crate::plot_err;

/// The speed observations among a joint calibration's pulls: the points this figure draws
/// (anchoring times and force tests are not drawn in it).
pub fn speed_pulls(pulls: &[Pull]) -> Vec<Pull> {
    pulls.iter().filter(|p| p.kind == ObservationKind::Speed).copied().collect()
}

/// Observed against fitted speeds (top) and pulls (bottom).
pub struct CalibrationFigure<'a> {
    /// The observations.
    pub points: &'a [Pull],
    /// The fitted model's speed over a fine slope grid (None where undefined), m/s.
    pub curve: &'a [(f64, Option<f64>)],
    /// A line under the title (fit statistics).
    pub subtitle: &'a str,
}

impl Figure for CalibrationFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (900, 900)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let (top, bottom) = root.split_vertically(560);
        let xs = self.points.iter().map(|p| p.slope_deg).chain(self.curve.iter().map(|c| c.0));
        let x_range = super::range(xs, (0.0, 25.0));
        let ys = self
            .points
            .iter()
            .flat_map(|p| {
                [100.0 * (p.observed - p.sd_total), 100.0 * (p.observed + p.sd_total), 100.0 * p.model]
            })
            .chain(self.curve.iter().filter_map(|c| c.1.map(|v| v * 100.0)))
            .chain([0.0]);
        let y_range = super::range(ys, (0.0, 16.0));
        let title = format!("Observed and fitted speeds ({})", self.subtitle);
        let setup = ChartSetup { caption: Some((&title, 20.0)), ..ChartSetup::SLOPE };
        let mut chart =
            setup.build(&top, x_range.0..x_range.1, y_range.0..y_range.1, "slope (deg)", "speed v (cm/s)")?;
        if y_range.0 < 0.0 {
            chart
                .draw_series(LineSeries::new([(x_range.0, 0.0), (x_range.1, 0.0)], BLACK.stroke_width(1)))
                .map_err(plot_err)?;
        }
        let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for &(x, y) in self.curve {
            match y {
                Some(v) => segments.last_mut().expect("non-empty").push((x, v * 100.0)),
                None if !segments.last().expect("non-empty").is_empty() => segments.push(Vec::new()),
                None => {}
            }
        }
        let mut first = true;
        for seg in segments.into_iter().filter(|s| !s.is_empty()) {
            let s = chart
                .draw_series(LineSeries::new(seg, palette::CLOSED_FORM_RED.stroke_width(2)))
                .map_err(plot_err)?;
            if first {
                s.label("fitted model").legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], palette::CLOSED_FORM_RED.stroke_width(2))
                });
                first = false;
            }
        }
        let floor = self.points.iter().any(|p| p.sd_total > p.sd * (1.0 + 1e-9));
        if floor {
            let grey = palette::MUTED_GREY;
            chart
                .draw_series(self.points.iter().map(|p| {
                    let (v, s) = (p.observed * 100.0, p.sd_total * 100.0);
                    ErrorBar::new_vertical(p.slope_deg, v - s, v, v + s, grey.stroke_width(5), 6)
                }))
                .map_err(plot_err)?
                .label("SD with the fitted error floor")
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x + 10, y - 6), (x + 10, y + 6)], grey.stroke_width(5))
                });
        }
        chart
            .draw_series(self.points.iter().map(|p| {
                let (v, s) = (p.observed * 100.0, p.sd * 100.0);
                ErrorBar::new_vertical(p.slope_deg, v - s, v, v + s, BLACK.stroke_width(2), 12)
            }))
            .map_err(plot_err)?;
        chart
            .draw_series(
                self.points.iter().map(|p| Circle::new((p.slope_deg, p.observed * 100.0), 5, BLACK.filled())),
            )
            .map_err(plot_err)?
            .label("observed (mean ± SD)")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, BLACK.filled()));
        chart
            .draw_series(self.points.iter().map(|p| {
                TriangleMarker::new((p.slope_deg, p.model * 100.0), 7, palette::CLOSED_FORM_RED.filled())
            }))
            .map_err(plot_err)?
            .label("model at the observed slope")
            .legend(|(x, y)| TriangleMarker::new((x + 10, y), 7, palette::CLOSED_FORM_RED.filled()));
        super::legend_box(&mut chart, SeriesLabelPosition::UpperRight, 15.0, super::LegendBox::LIGHT)?;

        self.draw_pulls(&bottom, x_range)
    }
}

impl CalibrationFigure<'_> {
    /// Bottom panel: each slope's pull, (observed - model) / SD, with the +-1 band.
    fn draw_pulls<DB: DrawingBackend>(
        &self,
        bottom: &DrawingArea<DB, Shift>,
        x_range: (f64, f64),
    ) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let max_pull = self.points.iter().map(|p| p.pull.abs()).fold(2.5_f64, f64::max) * 1.15;
        let setup = ChartSetup {
            caption: Some(("Pulls: (observed - model) / SD used in the fit", 18.0)),
            ..ChartSetup::SLOPE
        };
        let mut chart =
            setup.build(bottom, x_range.0..x_range.1, -max_pull..max_pull, "slope (deg)", "pull")?;
        let band = palette::PULL_BAND.mix(0.25);
        chart
            .draw_series([Rectangle::new([(x_range.0, -1.0), (x_range.1, 1.0)], band.filled())])
            .map_err(plot_err)?;
        chart
            .draw_series(LineSeries::new([(x_range.0, 0.0), (x_range.1, 0.0)], BLACK.stroke_width(1)))
            .map_err(plot_err)?;
        let w = 0.012 * (x_range.1 - x_range.0);
        chart
            .draw_series(self.points.iter().map(|p| {
                let colour = if p.pull.abs() > 2.0 { palette::SLIPPAGE } else { palette::DARK_GREY };
                Rectangle::new([(p.slope_deg - w, 0.0), (p.slope_deg + w, p.pull)], colour.filled())
            }))
            .map_err(plot_err)?;
        Ok(())
    }
}
