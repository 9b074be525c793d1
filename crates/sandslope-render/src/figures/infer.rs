//! Inference figures: the posterior of k_s at each observed slope (median and 90% interval,
//! open-ended where the data give only a bound), the law's credible band over slope with the
//! terrain table for comparison, and, with a law, the predicted p_fail with its band.

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope::infer::{Bound, LawPosterior, LogUniformPrior, SlopePosterior};

use super::palette;
use super::phase::sci_label;
use super::{font, ChartSetup, Figure};

/// The posterior bands and, with a law, the predicted risk.
pub struct InferFigure {
    pub points: Vec<SlopePosterior>,
    pub law: Option<LawPosterior>,
    /// The terrain table's k_s (slope_deg, k_s), for comparison.
    pub table: Vec<(f64, f64)>,
    pub prior: LogUniformPrior,
    pub title: String,
}

impl Figure for InferFigure {
    fn size(&self) -> (u32, u32) {
        if self.law.is_some() {
            (1500, 650)
        } else {
            (950, 650)
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = crate::plot_err;
        let root = root.titled(&self.title, font(22.0)).map_err(e)?;
        let (left, right) = match self.law {
            Some(_) => {
                let (l, r) = root.split_horizontally(800);
                (l, Some(r))
            }
            None => (root, None),
        };
        // Slope range: observed and predicted.
        let mut slopes: Vec<f64> = self.points.iter().map(|p| p.slope_deg).collect();
        if let Some(l) = &self.law {
            slopes.extend(l.prediction.iter().map(|p| p.slope_deg));
        }
        let (s0, s1) =
            slopes.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &s| (a.min(s), b.max(s)));
        let pad = ((s1 - s0) * 0.05).max(1.0);
        let (x0, x1) = ((s0 - pad).max(0.0), s1 + pad);
        self.draw_k_s(&left, (x0, x1))?;
        if let (Some(l), Some(area)) = (&self.law, right) {
            draw_p_fail(l, &area, (x0, x1))?;
        }
        Ok(())
    }
}

impl InferFigure {
    /// Left panel: k_s against slope, the observed intervals, the law's band and the table.
    fn draw_k_s<DB: DrawingBackend>(&self, left: &DrawingArea<DB, Shift>, (x0, x1): (f64, f64)) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = crate::plot_err;
        // k_s range: the intervals (open ends clipped to a decade beyond the bounded values).
        // Open ends (a quantile that is the prior's) do not set the range: they get an arrow.
        let mut ks: Vec<f64> = self
            .points
            .iter()
            .flat_map(|p| {
                let lo = (!matches!(p.bound, Bound::UpperOnly | Bound::Neither)).then_some(p.k_s_q05);
                let hi = (!matches!(p.bound, Bound::LowerOnly | Bound::Neither)).then_some(p.k_s_q95);
                [Some(p.k_s_median), lo, hi]
            })
            .flatten()
            .collect();
        if let Some(l) = &self.law {
            ks.extend(l.prediction.iter().flat_map(|p| [p.k_s.q05, p.k_s.q95]).filter(|k| *k > 0.0));
        }
        ks.extend(self.table.iter().map(|t| t.1));
        let (lo, hi) =
            ks.iter().filter(|k| **k > 0.0).fold((f64::INFINITY, 0.0f64), |(a, b), &k| (a.min(k), b.max(k)));
        let (y0, y1) = ((lo / 1.5).max(self.prior.min()), (hi * 1.5).min(self.prior.max()));
        let setup = ChartSetup { y_label_area: 80, y_ticks: Some(&sci_label), ..ChartSetup::PANEL };
        let mut chart = setup.build(
            left,
            x0..x1,
            (y0..y1).log_scale(),
            "slope (deg)",
            "shear strength k_s (N/m\u{b3})",
        )?;
        let blue = palette::MODEL_BLUE;
        if let Some(l) = &self.law {
            let band: Vec<(f64, f64)> = l
                .prediction
                .iter()
                .map(|p| (p.slope_deg, p.k_s.q95.clamp(y0, y1)))
                .chain(l.prediction.iter().rev().map(|p| (p.slope_deg, p.k_s.q05.clamp(y0, y1))))
                .collect();
            chart
                .draw_series(std::iter::once(Polygon::new(band, blue.mix(0.2).filled())))
                .map_err(e)?
                .label(format!("{:?} law: 90% credible band", l.law))
                .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 24, y + 6)], blue.mix(0.2).filled()));
            chart
                .draw_series(LineSeries::new(
                    l.prediction.iter().map(|p| (p.slope_deg, p.k_s.median.clamp(y0, y1))),
                    blue.stroke_width(2),
                ))
                .map_err(e)?
                .label("law: posterior median")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], blue.stroke_width(2)));
        }
        let grey = palette::TABLE_GREY;
        if !self.table.is_empty() {
            chart
                .draw_series(DashedLineSeries::new(self.table.iter().copied(), 6, 4, grey.stroke_width(2)))
                .map_err(e)?
                .label("terrain table k_s (--terrain)")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(2)));
        }
        let black = BLACK;
        for p in &self.points {
            let top =
                if matches!(p.bound, Bound::LowerOnly | Bound::Neither) { y1 } else { p.k_s_q95.min(y1) };
            let bottom =
                if matches!(p.bound, Bound::UpperOnly | Bound::Neither) { y0 } else { p.k_s_q05.max(y0) };
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(p.slope_deg, bottom), (p.slope_deg, top)],
                    black.stroke_width(2),
                )))
                .map_err(e)?;
            if p.bound == Bound::LowerOnly {
                // An arrow head: the interval continues up to the prior's end.
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at((p.slope_deg, top))
                            + Polygon::new(vec![(-7, 10), (7, 10), (0, 0)], black.filled()),
                    ))
                    .map_err(e)?;
            }
        }
        chart
            .draw_series(
                self.points.iter().map(|p| Circle::new((p.slope_deg, p.k_s_median), 6, black.filled())),
            )
            .map_err(e)?
            .label("observed slopes: median and 90% interval (arrow: only a lower bound)")
            .legend(|(x, y)| Circle::new((x + 12, y), 6, BLACK.filled()));
        super::legend(&mut chart, SeriesLabelPosition::UpperRight, 14.0)?;
        Ok(())
    }
}

/// Right panel: the law's predicted p_fail against slope with its credible band.
fn draw_p_fail<DB: DrawingBackend>(
    l: &LawPosterior,
    area: &DrawingArea<DB, Shift>,
    (x0, x1): (f64, f64),
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = crate::plot_err;
    let setup = ChartSetup { y_label_area: 60, ..ChartSetup::PANEL };
    let mut c = setup.build(area, x0..x1, 0.0..1.02, "slope (deg)", "p_fail")?;
    let red = palette::SLIPPAGE;
    let band: Vec<(f64, f64)> = l
        .prediction
        .iter()
        .map(|p| (p.slope_deg, p.p_fail.q95))
        .chain(l.prediction.iter().rev().map(|p| (p.slope_deg, p.p_fail.q05)))
        .collect();
    c.draw_series(std::iter::once(Polygon::new(band, red.mix(0.2).filled())))
        .map_err(e)?
        .label("90% credible band")
        .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 24, y + 6)], red.mix(0.2).filled()));
    c.draw_series(LineSeries::new(
        l.prediction.iter().map(|p| (p.slope_deg, p.p_fail.median)),
        red.stroke_width(2),
    ))
    .map_err(e)?
    .label("predicted p_fail (posterior median)")
    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], red.stroke_width(2)));
    c.draw_series(
        l.prediction
            .iter()
            .filter(|p| p.observed)
            .map(|p| Circle::new((p.slope_deg, p.p_fail.median), 5, BLACK.filled())),
    )
    .map_err(e)?
    .label("observed slopes")
    .legend(|(x, y)| Circle::new((x + 12, y), 5, BLACK.filled()));
    super::legend(&mut c, SeriesLabelPosition::UpperLeft, 14.0)?;
    Ok(())
}
