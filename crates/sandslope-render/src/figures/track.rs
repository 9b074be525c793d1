//! The figures of `sandslope track`: speed within a stride (the paper's Fig. 3b) and, for a
//! campaign over slopes, speed against slope with the model's curve (Fig. 3a).

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope::gait::TrackResult;
use sandslope::SlopeEvaluation;

use super::palette;
use super::{range, ChartSetup, Figure};
use crate::plot_err;
use sandslope_io::SpeedRow;

/// What the stride panel draws, in plotting units (s, cm/s).
pub struct TrackFigure {
    time: Vec<f64>,
    mean: Vec<f64>,
    sd: Vec<f64>,
    strides: usize,
    period: f64,
    t1: Option<f64>,
    slope: Option<f64>,
    measured: Vec<SpeedRow>,
    /// The model's speed against slope, in pieces where the robot makes a speed, cm/s.
    model: Vec<Vec<(f64, f64)>>,
    /// The stance model's speed where the regime rules it out (at or above repose), cm/s.
    ruled_out: Vec<Vec<(f64, f64)>>,
    /// Slope axis: from, to, degrees.
    x_range: (f64, f64),
}

/// The stretches of `(slope, speed)` where `speed` is defined, in cm/s.
fn pieces(
    model: &[SlopeEvaluation],
    speed: impl Fn(&SlopeEvaluation) -> Option<f64>,
) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![Vec::new()];
    for e in model {
        match speed(e) {
            Some(v) => out.last_mut().expect("non-empty").push((e.slope_deg, v * 100.0)),
            None if !out.last().expect("non-empty").is_empty() => out.push(Vec::new()),
            None => {}
        }
    }
    out.retain(|p| !p.is_empty());
    out
}

impl TrackFigure {
    /// Prepares the figure from `track`'s result; `campaign` (rows of the speeds file) adds
    /// the slope panel, with the model's speeds `model` (a sweep over slope) beside it.
    pub fn new(r: &TrackResult, campaign: Option<Vec<SpeedRow>>, model: &[SlopeEvaluation]) -> TrackFigure {
        let (time, mean, sd, strides) = match &r.analysis.curve {
            Some(c) => (
                c.time_s.clone(),
                c.mean.iter().map(|v| v * 100.0).collect(),
                c.sd.iter().map(|v| v * 100.0).collect(),
                c.strides,
            ),
            None => (Vec::new(), Vec::new(), Vec::new(), 0),
        };
        let measured = campaign.unwrap_or_default();
        let model_pieces = pieces(model, SlopeEvaluation::speed);
        let ruled_out = pieces(model, |e| e.model_speed().filter(|_| e.speed_ruled_out()));
        // The slope axis holds the whole model curve and the data, with room on both sides,
        // so that neither ends at the frame.
        let hi =
            model.iter().map(|e| e.slope_deg).chain(measured.iter().map(|r| r.slope_deg)).fold(0.0, f64::max);
        let x_range = (-1.0, hi + 0.04 * hi.max(10.0));
        TrackFigure {
            time,
            mean,
            sd,
            strides,
            period: r.period_s,
            t1: r.summary.t1_s,
            slope: r.slope_deg,
            measured,
            model: model_pieces,
            ruled_out,
            x_range,
        }
    }

    fn draw_stride<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let lo_hi = self.mean.iter().zip(&self.sd).flat_map(|(m, s)| [m - s, m + s]).chain([0.0]);
        let (y0, y1) = range(lo_hi, (-5.0, 20.0));
        let title = match self.slope {
            Some(s) => format!("Speed within a stride, {s} deg ({} strides)", self.strides),
            None => format!("Speed within a stride ({} strides)", self.strides),
        };
        let setup = ChartSetup {
            caption: Some((&title, 22.0)),
            x_ticks: Some(&super::tick),
            y_ticks: Some(&super::tick),
            ..ChartSetup::DATA
        };
        let mut chart = setup.build(
            area,
            0.0..self.period,
            y0..y1,
            "time since touchdown t0 (s)",
            "upslope speed v (cm/s)",
        )?;
        let band: Vec<(f64, f64)> = self
            .time
            .iter()
            .zip(self.mean.iter().zip(&self.sd))
            .map(|(t, (m, s))| (*t, m + s))
            .chain(self.time.iter().zip(self.mean.iter().zip(&self.sd)).rev().map(|(t, (m, s))| (*t, m - s)))
            .collect();
        chart
            .draw_series(std::iter::once(Polygon::new(band, palette::TRACKED_BLUE.mix(0.2).filled())))
            .map_err(plot_err)?
            .label("± 1 SD across strides")
            .legend(|(x, y)| {
                Rectangle::new([(x, y - 6), (x + 20, y + 6)], palette::TRACKED_BLUE.mix(0.2).filled())
            });
        chart
            .draw_series(LineSeries::new(
                self.time.iter().copied().zip(self.mean.iter().copied()),
                palette::TRACKED_BLUE.stroke_width(3),
            ))
            .map_err(plot_err)?
            .label("mean speed")
            .legend(|(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], palette::TRACKED_BLUE.stroke_width(3))
            });
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(0.0, 0.0), (self.period, 0.0)],
                BLACK.mix(0.5),
            )))
            .map_err(plot_err)?;
        let half = 0.5 * self.period;
        for (i, t0) in [0.0, half].into_iter().enumerate() {
            let s = chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(t0, y0), (t0, y1)],
                    BLACK.stroke_width(1),
                )))
                .map_err(plot_err)?;
            if i == 0 {
                s.label("touchdown t0 (every T/2)")
                    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
            }
            if let Some(t1) = self.t1 {
                let x = t0 + t1;
                let dashes = (0..40).filter(|k| k % 2 == 0).map(move |k| {
                    let a = y0 + (y1 - y0) * k as f64 / 40.0;
                    let b = y0 + (y1 - y0) * (k + 1) as f64 / 40.0;
                    PathElement::new(vec![(x, a), (x, b)], palette::CLOSED_FORM_RED.stroke_width(2))
                });
                let s = chart.draw_series(dashes).map_err(plot_err)?;
                if i == 0 {
                    s.label(format!("mean anchoring time t1 = {:.0} ms", t1 * 1e3)).legend(|(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], palette::CLOSED_FORM_RED.stroke_width(2))
                    });
                }
            }
        }
        super::legend_box(&mut chart, SeriesLabelPosition::UpperLeft, 14.0, super::LegendBox::LIGHT)?;
        Ok(())
    }

    fn draw_slopes<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let ys = self
            .measured
            .iter()
            .flat_map(|r| [100.0 * (r.speed_m_s - r.speed_sd_m_s), 100.0 * (r.speed_m_s + r.speed_sd_m_s)])
            .chain(self.model.iter().chain(&self.ruled_out).flatten().map(|p| p.1))
            .chain([0.0]);
        let (y0, y1) = range(ys, (0.0, 20.0));
        let setup = ChartSetup {
            caption: Some(("Speed against slope", 22.0)),
            x_ticks: Some(&super::tick),
            y_ticks: Some(&super::tick),
            ..ChartSetup::DATA
        };
        let mut chart = setup.build(
            area,
            self.x_range.0..self.x_range.1,
            y0..y1,
            "slope θ (deg)",
            "step-averaged speed (cm/s)",
        )?;
        for (i, piece) in self.model.iter().enumerate() {
            let s = chart
                .draw_series(LineSeries::new(piece.iter().copied(), palette::CLOSED_FORM_RED.stroke_width(2)))
                .map_err(plot_err)?;
            if i == 0 {
                s.label("model, for the robot and terrain given").legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], palette::CLOSED_FORM_RED.stroke_width(2))
                });
            }
        }
        let faded = palette::CLOSED_FORM_RED.mix(0.6).stroke_width(2);
        for (i, piece) in self.ruled_out.iter().enumerate() {
            let s = chart
                .draw_series(DashedLineSeries::new(piece.iter().copied(), 6, 5, faded))
                .map_err(plot_err)?;
            if i == 0 {
                s.label("model at or above repose: ruled out, the surface yields").legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (6, 0)], faded)
                        + PathElement::new(vec![(11, 0), (17, 0)], faded)
                });
            }
        }
        // Markers first and small, SD bars over them with wide caps: an SD smaller than a
        // marker still shows as its caps.
        chart
            .draw_series(
                self.measured
                    .iter()
                    .map(|r| Circle::new((r.slope_deg, 100.0 * r.speed_m_s), 3, BLACK.filled())),
            )
            .map_err(plot_err)?
            .label("tracked mean ± SD across steps (speeds file)")
            .legend(|(x, y)| Circle::new((x + 10, y), 3, BLACK.filled()));
        chart
            .draw_series(self.measured.iter().map(|r| {
                ErrorBar::new_vertical(
                    r.slope_deg,
                    100.0 * (r.speed_m_s - r.speed_sd_m_s),
                    100.0 * r.speed_m_s,
                    100.0 * (r.speed_m_s + r.speed_sd_m_s),
                    BLACK.stroke_width(2),
                    12,
                )
            }))
            .map_err(plot_err)?;
        super::legend_box(&mut chart, SeriesLabelPosition::UpperRight, 14.0, super::LegendBox::LIGHT)?;
        Ok(())
    }
}

impl Figure for TrackFigure {
    fn size(&self) -> (u32, u32) {
        if self.measured.is_empty() {
            (1000, 650)
        } else {
            (1800, 650)
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        if self.measured.is_empty() {
            return self.draw_stride(root);
        }
        let (left, right) = root.split_horizontally(1000);
        self.draw_stride(&left)?;
        self.draw_slopes(&right)
    }
}

/// Several stride panels (Fig. 3b at several slopes) stacked in one figure, first on top;
/// each panel is a [`TrackFigure`] without a campaign, drawn at its own size.
pub struct StridePanels(pub Vec<TrackFigure>);

impl Figure for StridePanels {
    fn size(&self) -> (u32, u32) {
        (1000, 650 * self.0.len().max(1) as u32)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        for (panel, area) in self.0.iter().zip(root.split_evenly((self.0.len().max(1), 1))) {
            panel.draw(&area)?;
        }
        Ok(())
    }
}
