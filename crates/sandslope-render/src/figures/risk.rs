//! Risk figures: p_fail and p_not_success against slope with the success and safe-slope limits; the
//! p_fail heat map over median (k_n, k_s) with the max-risk contour and the terrain's star;
//! and the payload envelope (heaviest safe mass against slope).

use anyhow::{bail, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope::risk::{PayloadEnvelope, SafeLimit};
use sandslope::{Axis, RegimeProbabilities};

use super::palette;
use super::palette::STAR_GREEN;
use super::phase::{cell_edges, reduce, sci_label, star_points, within, TerrainStar, MAX_DRAWN_CELLS};
use super::slope_curves::swatch_gap;
use super::{ChartSetup, Figure};

/// The charts against slope (p_fail curve, payload envelope): margin 20, 16-pt ticks, 18-pt
/// descriptions, no light grid.
const RISK_CURVES: ChartSetup<'static> = ChartSetup {
    margin: 20,
    x_label_area: 50,
    y_label_area: 70,
    label_pt: 16.0,
    desc_pt: 18.0,
    ..ChartSetup::PANEL
};

/// p_fail and p_not_success against slope, with the success limit (P(not success) below
/// `max_risk`: the robot climbs) and the safe-slope limit (p_fail below it: the robot does not
/// fail) marked and named apart.
pub struct CurveFigure {
    pub curve: Vec<(f64, RegimeProbabilities)>,
    pub points: Vec<(f64, f64)>,
    pub hi: f64,
    pub max_risk: f64,
    /// The safe-slope (p_fail) limit.
    pub limit: SafeLimit,
    /// The success (P(not success)) limit.
    pub success_limit: SafeLimit,
    pub title: String,
}

/// A slope limit's label in a legend: `what` and its slope, one decimal (the search's
/// tolerance would show as 24.999 below a 25 deg repose), "= repose" at the angle of repose.
fn limit_label(what: &str, limit: &SafeLimit) -> Option<(f64, String)> {
    match *limit {
        SafeLimit::Limit { value, .. } => Some((value, format!("{what} {value:.1}°"))),
        SafeLimit::Repose { repose_deg, .. } => {
            Some((repose_deg, format!("{what} {repose_deg}° (the angle of repose)")))
        }
        _ => None,
    }
}

impl Figure for CurveFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = crate::plot_err;
        let setup = ChartSetup { caption: Some((&self.title, 24.0)), ..RISK_CURVES };
        let mut chart = setup.build(
            root,
            0.0..self.hi,
            -0.015..1.02,
            "slope along the direction of travel (deg)",
            "probability",
        )?;
        let red = palette::SLIPPAGE;
        let orange = palette::NOT_SUCCESS_ORANGE;
        chart
            .draw_series(LineSeries::new(
                self.curve.iter().map(|(d, p)| (*d, p.p_fail().clamp(0.0, 1.0))),
                red.stroke_width(3),
            ))
            .map_err(e)?
            .label("p_fail = P(sinkage or slippage)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], red.stroke_width(3)));
        chart
            .draw_series(LineSeries::new(
                self.curve.iter().map(|(d, p)| (*d, p.p_not_success().clamp(0.0, 1.0))),
                orange.stroke_width(2),
            ))
            .map_err(e)?
            .label("p_not_success = P(regime != success)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], orange.stroke_width(2)));
        let grey = palette::DATA_GREY;
        chart
            .draw_series(DashedLineSeries::new(
                vec![(0.0, self.max_risk), (self.hi, self.max_risk)],
                8,
                6,
                grey.stroke_width(2),
            ))
            .map_err(e)?
            .label(format!("risk threshold {}", self.max_risk))
            .legend(move |(x, y)| {
                let (a, b) = swatch_gap(true);
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (a, 0)], grey.stroke_width(2))
                    + PathElement::new(vec![(b, 0), (20, 0)], grey.stroke_width(2))
            });
        if !self.points.is_empty() {
            chart
                .draw_series(self.points.iter().map(|&(d, p)| Circle::new((d, p), 5, BLACK.filled())))
                .map_err(e)?
                .label("requested slopes")
                .legend(|(x, y)| Circle::new((x + 12, y), 5, BLACK.filled()));
        }
        let limits = [
            (limit_label("climbs steadily up to (P(not success) < risk)", &self.success_limit), orange, true),
            (
                limit_label("safe up to (p_fail = P(sinks or slides back) < risk)", &self.limit),
                palette::MODEL_BLUE,
                false,
            ),
        ];
        for (label, colour, dashed) in limits {
            let Some((value, label)) = label else { continue };
            let line = vec![(value, -0.015), (value, 1.02)];
            let series = if dashed {
                chart.draw_series(DashedLineSeries::new(line, 10, 5, colour.stroke_width(3))).map_err(e)?
            } else {
                chart.draw_series(LineSeries::new(line, colour.stroke_width(2))).map_err(e)?
            };
            series
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3)));
            chart
                .draw_series(std::iter::once(Circle::new((value, self.max_risk), 7, colour.stroke_width(3))))
                .map_err(e)?;
        }
        super::legend(&mut chart, SeriesLabelPosition::UpperLeft, 16.0)?;
        Ok(())
    }
}

/// The p_fail heat map over median (k_n, k_s) at one slope.
pub struct MapFigure {
    pub k_n_axis: Axis,
    pub k_s_axis: Axis,
    pub p_fail: Vec<f64>,
    pub contour: Vec<sandslope::ContourSegment>,
    pub star: (f64, f64),
    pub max_risk: f64,
    pub title: String,
}

impl Figure for MapFigure {
    fn size(&self) -> (u32, u32) {
        (900, 720)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = crate::plot_err;
        let (main, bar_area) = root.split_horizontally(780);
        let (xe, ye) = (cell_edges(&self.k_n_axis), cell_edges(&self.k_s_axis));
        if self.k_n_axis.scale() != sandslope::AxisScale::Log
            || self.k_s_axis.scale() != sandslope::AxisScale::Log
        {
            bail!("--map plots need log axes (:log)");
        }
        let setup = ChartSetup {
            caption: Some((&self.title, 20.0)),
            x_ticks: Some(&sci_label),
            y_ticks: Some(&sci_label),
            ..ChartSetup::MAP
        };
        let mut chart = setup.build(
            &main,
            (xe[0]..xe[xe.len() - 1]).log_scale(),
            (ye[0]..ye[ye.len() - 1]).log_scale(),
            "median normal resistance k_n (N/m\u{b3})",
            "median shear strength k_s (N/m\u{b3})",
        )?;
        let nx = self.k_n_axis.len();
        // At most one block per pixel, whatever the grid.
        let (xs, xc) = reduce(nx, MAX_DRAWN_CELLS);
        let (ys, yc) = reduce(self.k_s_axis.len(), MAX_DRAWN_CELLS);
        chart
            .draw_series(yc.iter().enumerate().flat_map(|(jj, &j)| {
                let (xs, ys, xe, ye) = (&xs, &ys, &xe, &ye);
                xc.iter().enumerate().map(move |(ii, &i)| {
                    Rectangle::new(
                        [(xe[xs[ii]], ye[ys[jj]]), (xe[xs[ii + 1]], ye[ys[jj + 1]])],
                        palette::p_fail_colour(self.p_fail[j * nx + i]).filled(),
                    )
                })
            }))
            .map_err(e)?;
        let contour = super::polylines(&self.contour);
        chart
            .draw_series(contour.iter().map(|line| PathElement::new(line.clone(), BLACK.stroke_width(5))))
            .map_err(e)?;
        chart
            .draw_series(contour.iter().map(|line| PathElement::new(line.clone(), WHITE.stroke_width(3))))
            .map_err(e)?
            .label(format!("p_fail = {} (--max-risk)", self.max_risk))
            .legend(|(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (24, 0)], BLACK.stroke_width(6))
                    + PathElement::new(vec![(1, 0), (23, 0)], WHITE.stroke_width(3))
            });
        let (k_n, k_s) = self.star;
        if within(&xe, &ye, (k_n, k_s)) {
            chart
                .draw_series(std::iter::once(TerrainStar { at: (k_n, k_s), outline: BLACK }))
                .map_err(e)?
                .label("terrain medians")
                .legend(|(x, y)| {
                    EmptyElement::at((x + 12, y)) + Polygon::new(star_points(9.0), STAR_GREEN.filled())
                });
        }
        super::legend(&mut chart, SeriesLabelPosition::LowerRight, 15.0)?;
        super::colour_bar(&bar_area, (0.0, 1.0), 44, "p_fail", None, (14.0, 16.0), &|k| {
            palette::p_fail_colour(k as f64 / 100.0 + 0.005)
        })?;
        Ok(())
    }
}

/// The payload envelope: the heaviest safe total mass against slope.
pub struct EnvelopeFigure<'a> {
    env: &'a PayloadEnvelope,
    title: String,
}

impl<'a> EnvelopeFigure<'a> {
    /// The figure of `env`, titled after the robot and terrain.
    pub fn new(env: &'a PayloadEnvelope, what: &str) -> Self {
        EnvelopeFigure { env, title: format!("Payload envelope (p_fail < {}): {what}", env.max_risk) }
    }
}

impl Figure for EnvelopeFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = crate::plot_err;
        let own = self.env.robot_mass_kg;
        // Each point: (slope, mass drawn, kind) with kind 0 limit, 1 none safe, 2 beyond range.
        let pts: Vec<(f64, f64, u8)> = self
            .env
            .points
            .iter()
            .map(|p| match p.limit {
                SafeLimit::Limit { value, .. } | SafeLimit::Repose { repose_deg: value, .. } => {
                    (p.slope_deg.abs(), value, 0)
                }
                SafeLimit::NoneSafe { .. } => (p.slope_deg.abs(), own, 1),
                SafeLimit::BeyondRange { up_to, .. } => (p.slope_deg.abs(), up_to, 2),
            })
            .collect();
        let x_hi = pts.iter().fold(1.0f64, |a, p| a.max(p.0));
        let x_lo = pts.iter().fold(x_hi, |a, p| a.min(p.0));
        let y_hi = pts.iter().fold(own, |a, p| a.max(p.1)) * 1.1;
        let setup = ChartSetup { caption: Some((&self.title, 22.0)), ..RISK_CURVES };
        let mut chart = setup.build(
            root,
            x_lo..x_hi + 0.02 * (x_hi - x_lo).max(1.0),
            0.0..y_hi,
            "slope along the direction of travel (deg)",
            "heaviest safe total mass (kg)",
        )?;
        let blue = palette::MODEL_BLUE;
        let grey = palette::DATA_GREY;
        let red = palette::SLIPPAGE;
        let safe: Vec<(f64, f64)> = pts.iter().filter(|p| p.2 != 1).map(|p| (p.0, p.1)).collect();
        chart.draw_series(AreaSeries::new(safe.iter().copied(), 0.0, blue.mix(0.15))).map_err(e)?;
        chart
            .draw_series(LineSeries::new(safe.iter().copied(), blue.stroke_width(3)))
            .map_err(e)?
            .label("heaviest safe total mass")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], blue.stroke_width(3)));
        chart.draw_series(safe.iter().map(|&(x, y)| Circle::new((x, y), 4, blue.filled()))).map_err(e)?;
        chart
            .draw_series(DashedLineSeries::new(vec![(x_lo, own), (x_hi, own)], 8, 6, grey.stroke_width(2)))
            .map_err(e)?
            .label(format!("robot's own mass {own} kg"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(2)));
        if pts.iter().any(|p| p.2 == 1) {
            chart
                .draw_series(
                    pts.iter().filter(|p| p.2 == 1).map(|p| Cross::new((p.0, p.1), 7, red.stroke_width(3))),
                )
                .map_err(e)?
                .label("no mass safe")
                .legend(move |(x, y)| Cross::new((x + 12, y), 7, red.stroke_width(3)));
        }
        if pts.iter().any(|p| p.2 == 2) {
            chart
                .draw_series(
                    pts.iter()
                        .filter(|p| p.2 == 2)
                        .map(|p| TriangleMarker::new((p.0, p.1), 7, blue.stroke_width(2))),
                )
                .map_err(e)?
                .label("safe up to the end of the search");
        }
        super::legend(&mut chart, SeriesLabelPosition::UpperRight, 16.0)?;
        Ok(())
    }
}
