//! The force-measurement figure of the paper (its panels c, d, g, h): force against depth and
//! against displacement coloured by slope, with the fitted lines and plateaus, and k_n and k_s
//! against slope with error bars (SD across trials).

use std::path::{Path, PathBuf};

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope::measure::{Origin, SlopeEstimate, SlopeStat};

use super::{font, range, save, Figure};
use crate::commands::fit::{FittedTrial, TrialFit};
use crate::error::plot_err;

/// Which panel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Panel {
    /// (c) penetration force against depth.
    PenetrationForce,
    /// (d) k_n against slope.
    NormalResistance,
    /// (g) shear force against displacement.
    ShearForce,
    /// (h) k_s against slope.
    ShearStrength,
}

impl Panel {
    fn title(self) -> &'static str {
        match self {
            Panel::PenetrationForce => "(c) Penetration force",
            Panel::NormalResistance => "(d) Normal penetration resistance k_n",
            Panel::ShearForce => "(g) Shear force",
            Panel::ShearStrength => "(h) Shear strength k_s",
        }
    }

    fn file(self) -> &'static str {
        match self {
            Panel::PenetrationForce => "penetration-force.png",
            Panel::NormalResistance => "k_n-vs-slope.png",
            Panel::ShearForce => "shear-force.png",
            Panel::ShearStrength => "k_s-vs-slope.png",
        }
    }
}

/// Red (lowest slope) to blue (highest), as in the paper.
fn slope_colour(deg: f64, lo: f64, hi: f64) -> RGBColor {
    let t = if hi > lo { ((deg - lo) / (hi - lo)).clamp(0.0, 1.0) } else { 0.0 };
    let (a, b) = ((215.0, 48.0, 39.0), (44.0, 90.0, 200.0));
    let mix = |p: f64, q: f64| (p + t * (q - p)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

struct Data<'a> {
    trials: &'a [FittedTrial],
    points: &'a [SlopeEstimate],
    slope_lo: f64,
    slope_hi: f64,
}

impl Data<'_> {
    fn colour(&self, deg: f64) -> RGBColor {
        slope_colour(deg, self.slope_lo, self.slope_hi)
    }

    fn draw_panel<DB: DrawingBackend>(&self, panel: Panel, area: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        match panel {
            Panel::PenetrationForce | Panel::ShearForce => self.draw_forces(panel, area),
            Panel::NormalResistance | Panel::ShearStrength => self.draw_resistance(panel, area),
        }
    }

    fn draw_forces<DB: DrawingBackend>(&self, panel: Panel, area: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let shear = panel == Panel::ShearForce;
        let trials: Vec<&FittedTrial> = self
            .trials
            .iter()
            .filter(|t| !matches!(t.fit, TrialFit::Air) && matches!(t.fit, TrialFit::Shear(_)) == shear)
            .collect();
        let xs = trials.iter().flat_map(|t| t.corrected.position().iter().map(|x| x * 1e3));
        let ys = trials.iter().flat_map(|t| t.corrected.force().iter().copied());
        let (x0, x1) = range(xs, (0.0, 1.0));
        let (y0, y1) = range(ys.chain([0.0]), (0.0, 1.0));
        let mut chart = ChartBuilder::on(area)
            .caption(panel.title(), font(22.0))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc(if shear { "shear displacement (mm)" } else { "penetration depth (mm)" })
            .y_desc(if shear {
                "shear force, in-air offset removed (N)"
            } else {
                "normal force, in-air offset removed (N)"
            })
            .label_style(font(15.0))
            .axis_desc_style(font(17.0))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(plot_err)?;
        let mut labelled = Vec::new();
        for t in &trials {
            let deg = t.clean.trial.slope_deg;
            let colour = self.colour(deg);
            let pts: Vec<(f64, f64)> =
                t.corrected.position().iter().zip(t.corrected.force()).map(|(x, f)| (x * 1e3, *f)).collect();
            let series = chart
                .draw_series(LineSeries::new(pts, colour.mix(0.55).stroke_width(1)))
                .map_err(plot_err)?;
            if !labelled.contains(&deg.to_bits()) {
                labelled.push(deg.to_bits());
                series.label(format!("{deg} deg")).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
                });
            }
            // The fitted line over its window, or the plateau mean over the plateau.
            let fitted: Vec<(f64, f64)> = match t.fit {
                TrialFit::Penetration(f) => [f.window.0, f.window.1]
                    .iter()
                    .map(|&d| (d * 1e3, f.line.intercept + f.line.slope * d))
                    .collect(),
                TrialFit::Shear(f) => {
                    vec![(f.plateau.0 * 1e3, f.plateau_force), (f.plateau.1 * 1e3, f.plateau_force)]
                }
                TrialFit::Air => continue,
            };
            chart.draw_series(LineSeries::new(fitted.clone(), BLACK.stroke_width(1))).map_err(plot_err)?;
            chart
                .draw_series(fitted.iter().map(|&(x, y)| Circle::new((x, y), 2, BLACK.filled())))
                .map_err(plot_err)?;
        }
        let fit_label =
            if shear { "plateau mean (ends marked)" } else { "fitted line over window (ends marked)" };
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(plot_err)?
            .label(fit_label)
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK.stroke_width(3)));
        chart
            .configure_series_labels()
            .position(if shear { SeriesLabelPosition::LowerRight } else { SeriesLabelPosition::UpperLeft })
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .label_font(font(14.0))
            .draw()
            .map_err(plot_err)?;
        Ok(())
    }

    fn draw_resistance<DB: DrawingBackend>(&self, panel: Panel, area: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let normal = panel == Panel::NormalResistance;
        let stat = |p: &SlopeEstimate| if normal { p.k_n } else { p.k_s };
        let scale = 1e5;
        let per_trial: Vec<(f64, f64)> = self
            .trials
            .iter()
            .filter_map(|t| match (normal, t.fit) {
                (true, TrialFit::Penetration(f)) => Some((t.clean.trial.slope_deg, f.k_n / scale)),
                (false, TrialFit::Shear(f)) => Some((t.clean.trial.slope_deg, f.k_s / scale)),
                _ => None,
            })
            .collect();
        let bars = |s: &SlopeStat| {
            let sd = s.sd.unwrap_or(0.0);
            ((s.mean - sd) / scale, (s.mean + sd) / scale)
        };
        let ys = self
            .points
            .iter()
            .flat_map(|p| {
                let b = bars(&stat(p));
                [b.0, b.1]
            })
            .chain(per_trial.iter().map(|p| p.1))
            .chain([0.0]);
        let (y0, y1) = range(ys, (0.0, 1.0));
        let (x0, x1) = range(self.points.iter().map(|p| p.slope_deg).chain([0.0]), (0.0, 25.0));
        let x1 = x1 + 1.0;
        let mut chart = ChartBuilder::on(area)
            .caption(panel.title(), font(22.0))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d((x0 - 1.0)..x1, y0..(y1 * 1.08))
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("slope (deg)")
            .y_desc(if normal { "k_n (10^5 N/m^3)" } else { "k_s (10^5 N/m^3)" })
            .label_style(font(15.0))
            .axis_desc_style(font(17.0))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(plot_err)?;
        chart
            .draw_series(
                per_trial.iter().map(|&(d, k)| Circle::new((d, k), 3, RGBColor(120, 120, 120).filled())),
            )
            .map_err(plot_err)?
            .label("single trials (drawn left of their slope)")
            .legend(|(x, y)| Circle::new((x + 9, y), 3, RGBColor(120, 120, 120).filled()));
        let measured: Vec<&SlopeEstimate> =
            self.points.iter().filter(|p| stat(p).origin == Origin::Measured).collect();
        chart
            .draw_series(measured.iter().map(|p| {
                let s = stat(p);
                let (lo, hi) = bars(&s);
                ErrorBar::new_vertical(
                    p.slope_deg,
                    lo,
                    s.mean / scale,
                    hi,
                    self.colour(p.slope_deg).stroke_width(2),
                    10,
                )
            }))
            .map_err(plot_err)?;
        chart
            .draw_series(measured.iter().map(|p| {
                Circle::new((p.slope_deg, stat(p).mean / scale), 6, self.colour(p.slope_deg).filled())
            }))
            .map_err(plot_err)?
            .label("mean +- SD across trials")
            .legend(|(x, y)| Circle::new((x + 9, y), 6, RGBColor(120, 60, 120).filled()));
        let filled: Vec<&SlopeEstimate> =
            self.points.iter().filter(|p| stat(p).origin != Origin::Measured).collect();
        if !filled.is_empty() {
            chart
                .draw_series(filled.iter().map(|p| {
                    Circle::new(
                        (p.slope_deg, stat(p).mean / scale),
                        6,
                        self.colour(p.slope_deg).stroke_width(2),
                    )
                }))
                .map_err(plot_err)?
                .label("not measured: interpolated")
                .legend(|(x, y)| Circle::new((x + 9, y), 6, BLACK.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .label_font(font(14.0))
            .draw()
            .map_err(plot_err)?;
        Ok(())
    }
}

/// One panel on its own.
struct Single<'a> {
    data: &'a Data<'a>,
    panel: Panel,
}

impl Figure for Single<'_> {
    fn size(&self) -> (u32, u32) {
        (800, 600)
    }
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        self.data.draw_panel(self.panel, root)
    }
}

/// The four panels, laid out as in the paper (c, d over g, h).
struct Combined<'a> {
    data: &'a Data<'a>,
}

impl Figure for Combined<'_> {
    fn size(&self) -> (u32, u32) {
        (1600, 1200)
    }
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let areas = root.split_evenly((2, 2));
        let panels =
            [Panel::PenetrationForce, Panel::NormalResistance, Panel::ShearForce, Panel::ShearStrength];
        for (area, panel) in areas.iter().zip(panels) {
            self.data.draw_panel(panel, area)?;
        }
        Ok(())
    }
}

/// Writes `force-measurements.png` (all four panels) and one PNG per panel into `dir`;
/// returns the paths written.
pub fn write_all(dir: &Path, trials: &[FittedTrial], points: &[SlopeEstimate]) -> Result<Vec<PathBuf>> {
    let slopes = points.iter().map(|p| p.slope_deg);
    let slope_lo = slopes.clone().fold(f64::INFINITY, f64::min);
    let slope_hi = slopes.fold(f64::NEG_INFINITY, f64::max);
    let data = Data { trials, points, slope_lo, slope_hi };
    let mut written = Vec::new();
    let path = dir.join("force-measurements.png");
    save(&path, &Combined { data: &data })?;
    written.push(path);
    for panel in [Panel::PenetrationForce, Panel::NormalResistance, Panel::ShearForce, Panel::ShearStrength] {
        let path = dir.join(panel.file());
        save(&path, &Single { data: &data, panel })?;
        written.push(path);
    }
    Ok(written)
}
