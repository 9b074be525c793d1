//! Where the model's step goes, against slope (docs/model.md §5): the level step s*, the three
//! losses (shorter propulsion time, inherited speed, backward slip) and the net step. The
//! report's step-budget figure.

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope::report::StepBudget;

use super::palette;
use super::slope_curves::swatch_gap;
use super::{ChartSetup, Figure};
use crate::plot_err;

/// The step budget over a slope grid (entries without anchoring are gaps).
pub struct StepBudgetFigure<'a> {
    /// One entry per slope, ascending.
    pub budget: &'a [StepBudget],
    /// Angle of repose, degrees: shaded from there on.
    pub repose: Option<f64>,
}

impl Figure for StepBudgetFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (760, 480)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        type Pick = fn(&StepBudget) -> Option<f64>;
        let series: [(&str, RGBColor, bool, Pick); 5] = [
            ("level step s*", palette::DATA_GREY, true, |b| Some(b.level_step_m)),
            ("net step s", palette::NET_STEP, false, |b| b.step_m),
            ("inherited speed g sin θ t1 (T/2 - t1)", palette::LOSS_RED, false, |b| b.inherited_speed_m),
            ("shorter propulsion time", palette::MODEL_BLUE, false, |b| b.shorter_propulsion_m),
            ("backward slip ½ g sin θ t1²", palette::SLIP_ORANGE, false, |b| b.slip_m),
        ];
        let x_hi = self.budget.last().map_or(30.0, |b| b.slope_deg);
        let ys =
            self.budget.iter().flat_map(|b| series.iter().filter_map(move |s| (s.3)(b).map(|v| v * 1e3)));
        let y_range = super::range(ys.chain([0.0]), (0.0, 1.0));
        let setup = ChartSetup { caption: Some(("Where the step goes", 20.0)), ..ChartSetup::CURVES };
        let mut chart =
            setup.build(root, 0.0..x_hi, y_range.0..y_range.1, "slope (deg)", "length per step (mm)")?;
        super::shade_repose(
            &mut chart,
            self.repose,
            (0.0, x_hi),
            y_range,
            "at or above the angle of repose",
        )?;
        for (label, colour, dashed, pick) in series {
            let points: Vec<(f64, f64)> =
                self.budget.iter().filter_map(|b| pick(b).map(|v| (b.slope_deg, v * 1e3))).collect();
            let style = colour.stroke_width(3);
            let drawn = if dashed {
                chart.draw_series(DashedLineSeries::new(points, 10, 4, style)).map_err(plot_err)?
            } else {
                chart.draw_series(LineSeries::new(points, style)).map_err(plot_err)?
            };
            let (a, b) = swatch_gap(dashed);
            drawn.label(label).legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (a, 0)], style)
                    + PathElement::new(vec![(b, 0), (20, 0)], style)
            });
        }
        super::legend_box(&mut chart, SeriesLabelPosition::MiddleLeft, 14.0, super::LegendBox::LIGHT)?;
        Ok(())
    }
}
