//! One quantity against slope, in the paper's style: the model as a line (gaps where it is
//! undefined), measurements as points with SD bars, an optional reference line and the slopes
//! at or above the angle of repose shaded. The report's fig3a, fig4d, fig4h, fig5b and fig5c.

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::palette;
use super::{ChartSetup, Figure};
use crate::plot_err;

/// A legend swatch is two segments 20 px long in all: `(0, a)` and `(b, 20)`. Touching for a
/// solid line; with a gap for a dashed one, so the legend looks like the line it names:
/// `EmptyElement::at(p) + PathElement::new(vec![(0, 0), (a, 0)], s) + PathElement::new(vec![(b, 0), (20, 0)], s)`.
pub fn swatch_gap(dashed: bool) -> (i32, i32) {
    if dashed {
        (8, 12)
    } else {
        (10, 10)
    }
}

/// The ruled-out values within `range` widened by half its span on each side: a value beyond
/// is cut to that edge where the line leaves (so the line runs off the chart) and dropped
/// after that, until the line comes back.
fn ruled_out_within(values: &[(f64, Option<f64>)], range: (f64, f64)) -> Vec<(f64, Option<f64>)> {
    let half = (range.1 - range.0) / 2.0;
    let (lo, hi) = (range.0 - half, range.1 + half);
    let mut inside_before = false;
    values
        .iter()
        .map(|&(x, v)| {
            let Some(v) = v else {
                inside_before = false;
                return (x, None);
            };
            let inside = (lo..=hi).contains(&v);
            let kept = (inside || inside_before).then(|| v.clamp(lo, hi));
            inside_before = inside;
            (x, kept)
        })
        .collect()
}

/// A quantity against slope.
pub struct SlopeCurveFigure {
    /// Caption.
    pub title: String,
    /// Y-axis label (with unit).
    pub y_label: String,
    /// The model curve `(slope_deg, value)`, `None` where undefined or ruled out; solid.
    pub model: Vec<(f64, Option<f64>)>,
    /// The model's values where its regime rules them out (slippage or sinkage), `None`
    /// elsewhere; dashed and faded, as `sweep --plot` draws them.
    pub ruled_out: Vec<(f64, Option<f64>)>,
    /// Legend of the dashed curve (by default what the regime rules out; fig4d/h: the
    /// terrain extrapolated beyond its last point).
    pub ruled_out_label: String,
    /// Legend of the model curve.
    pub model_label: String,
    /// Measurements `(slope_deg, mean, sd)`.
    pub observed: Vec<(f64, f64, f64)>,
    /// Legend of the measurements.
    pub observed_label: String,
    /// A dashed horizontal line and its legend.
    pub reference: Option<(f64, String)>,
    /// Angle of repose, degrees: shaded from there on.
    pub repose: Option<f64>,
    /// Start the y axis at zero.
    pub from_zero: bool,
    /// Where the legend goes (where the curves are not).
    pub legend: SeriesLabelPosition,
}

impl Figure for SlopeCurveFigure {
    fn size(&self) -> (u32, u32) {
        (760, 480)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let xs = self.model.iter().map(|m| m.0).chain(self.observed.iter().map(|o| o.0));
        let x_range = super::range(xs, (0.0, 30.0));
        let ys = self
            .model
            .iter()
            .filter_map(|m| m.1)
            .chain(self.observed.iter().flat_map(|o| [o.1 - o.2, o.1 + o.2]))
            .chain(self.reference.as_ref().map(|r| r.0))
            .chain(self.from_zero.then_some(0.0));
        let y_range = super::range(ys, (0.0, 1.0));
        // The ruled-out part widens the axis by at most half the span of the rest: a badly
        // calibrated model's -70 cm/s "speed" near repose would otherwise squash the data into
        // a strip. Beyond that the dashed line runs off the edge.
        let ruled_out = ruled_out_within(&self.ruled_out, y_range);
        let y_range =
            ruled_out.iter().filter_map(|m| m.1).fold(y_range, |(lo, hi), v| (lo.min(v), hi.max(v)));
        let setup = ChartSetup { caption: Some((&self.title, 20.0)), ..ChartSetup::CURVES };
        let mut chart =
            setup.build(root, x_range.0..x_range.1, y_range.0..y_range.1, "slope (deg)", &self.y_label)?;
        if y_range.0 < 0.0 && y_range.1 > 0.0 {
            chart
                .draw_series(LineSeries::new([(x_range.0, 0.0), (x_range.1, 0.0)], BLACK.stroke_width(1)))
                .map_err(plot_err)?;
        }
        super::shade_repose(&mut chart, self.repose, x_range, y_range, "at or above the angle of repose")?;
        if let Some((level, label)) = &self.reference {
            super::reference_line(&mut chart, *level, label, x_range)?;
        }
        let red = palette::LOSS_RED;
        let label = (!self.model_label.is_empty()).then_some(self.model_label.as_str());
        draw_pieces(&mut chart, &self.model, red.stroke_width(3), false, label)?;
        draw_pieces(
            &mut chart,
            &ruled_out,
            red.mix(0.6).stroke_width(2),
            true,
            Some(self.ruled_out_label.as_str()),
        )?;
        if !self.observed.is_empty() {
            chart
                .draw_series(self.observed.iter().map(|&(x, v, sd)| {
                    ErrorBar::new_vertical(x, v - sd, v, v + sd, BLACK.stroke_width(2), 10)
                }))
                .map_err(plot_err)?;
            chart
                .draw_series(self.observed.iter().map(|&(x, v, _)| Circle::new((x, v), 5, BLACK.filled())))
                .map_err(plot_err)?
                .label(self.observed_label.as_str())
                .legend(|(x, y)| Circle::new((x + 10, y), 5, BLACK.filled()));
        }
        super::legend_box(&mut chart, self.legend.clone(), 14.0, super::LegendBox::LIGHT)?;
        Ok(())
    }
}

/// The continuous pieces of `curve` (split at `None`).
fn pieces(curve: &[(f64, Option<f64>)]) -> Vec<Vec<(f64, f64)>> {
    let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for &(x, y) in curve {
        match y {
            Some(v) => segments.last_mut().expect("non-empty").push((x, v)),
            None if !segments.last().expect("non-empty").is_empty() => segments.push(Vec::new()),
            None => {}
        }
    }
    segments.retain(|s| !s.is_empty());
    segments
}

/// Draws `curve` solid or dashed, with one legend entry (a swatch like the line) if labelled.
fn draw_pieces<'a, DB: DrawingBackend + 'a>(
    chart: &mut super::SlopeChart<'a, DB>,
    curve: &[(f64, Option<f64>)],
    style: ShapeStyle,
    dashed: bool,
    label: Option<&str>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    for (i, seg) in pieces(curve).into_iter().enumerate() {
        let s = if dashed {
            chart.draw_series(DashedLineSeries::new(seg, 8, 5, style)).map_err(plot_err)?
        } else {
            chart.draw_series(LineSeries::new(seg, style)).map_err(plot_err)?
        };
        if let (0, Some(label)) = (i, label) {
            let (a, b) = swatch_gap(dashed);
            s.label(label).legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (a, 0)], style)
                    + PathElement::new(vec![(b, 0), (20, 0)], style)
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::ruled_out_within;

    #[test]
    fn ruled_out_line_is_cut_at_half_a_span_beyond_the_data() {
        // Data span 0..10: the dashed line may reach -5..15; -70 is cut to -5 where the line
        // leaves, the next point beyond is dropped, and the line resumes when it is back.
        let values =
            [(20.0, Some(2.0)), (21.0, Some(-70.0)), (22.0, Some(-90.0)), (23.0, None), (24.0, Some(-4.0))];
        let cut = ruled_out_within(&values, (0.0, 10.0));
        assert_eq!(
            cut,
            vec![(20.0, Some(2.0)), (21.0, Some(-5.0)), (22.0, None), (23.0, None), (24.0, Some(-4.0))]
        );
    }
}
