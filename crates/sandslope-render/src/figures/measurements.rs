//! The force-measurement figure of the paper (its panels c, d, g, h): force against depth and
//! against displacement coloured by slope, each trial's fitted line over its window (or plateau
//! mean over its plateau) with the window's ends marked, and k_n and k_s against slope with
//! error bars (the combined SD) and every single trial.

use std::path::{Path, PathBuf};

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope::measure::{Campaign, Origin, SlopeEstimate, SlopeStat, TrialFit, TrialResult};

use super::palette;
use super::{range, save, ChartSetup, Figure};
use crate::plot_err;

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
            Panel::NormalResistance => "(d) Normal penetration resistance kₙ",
            Panel::ShearForce => "(g) Shear force",
            Panel::ShearStrength => "(h) Shear strength kₛ",
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

/// Viridis (a perceptually uniform sequential map, readable in grey and by colour-blind
/// readers) at `t` in [0, 1], from its published stops at every eighth.
fn viridis(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 9] = [
        (68.0, 1.0, 84.0),
        (71.0, 44.0, 122.0),
        (59.0, 81.0, 139.0),
        (44.0, 113.0, 142.0),
        (33.0, 144.0, 141.0),
        (39.0, 173.0, 129.0),
        (92.0, 200.0, 99.0),
        (170.0, 220.0, 50.0),
        (253.0, 231.0, 37.0),
    ];
    let x = t.clamp(0.0, 1.0) * 8.0;
    let i = (x.floor() as usize).min(7);
    let w = x - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |p: f64, q: f64| (p + w * (q - p)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

struct Data<'a> {
    campaign: &'a Campaign,
    slope_lo: f64,
    slope_hi: f64,
}

impl Data<'_> {
    /// Slope colour: viridis from the lowest slope (dark purple) to just short of the highest
    /// (yellow-green; pure yellow is too pale on white).
    fn colour(&self, deg: f64) -> RGBColor {
        let t = if self.slope_hi > self.slope_lo {
            (deg - self.slope_lo) / (self.slope_hi - self.slope_lo)
        } else {
            0.0
        };
        viridis(0.88 * t)
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
        let trials: Vec<&TrialResult> = self
            .campaign
            .trials
            .iter()
            .filter(|t| !t.air && if shear { t.shear.is_some() } else { t.penetration.is_some() })
            .collect();
        let xs = trials.iter().flat_map(|t| t.curve.position().iter().map(|x| x * 1e3));
        let ys = trials.iter().flat_map(|t| t.curve.force().iter().copied());
        let (x0, x1) = range(xs, (0.0, 1.0));
        let (y0, y1) = range(ys.chain([0.0]), (0.0, 1.0));
        // Shear curves fill the panel's width at their plateau: room above them for the legend.
        let y1 = if shear { y1 + 0.4 * (y1 - y0) } else { y1 };
        let setup = ChartSetup { caption: Some((panel.title(), 22.0)), ..ChartSetup::DATA };
        let mut chart = setup.build(
            area,
            x0..x1,
            y0..y1,
            if shear { "shear displacement (mm)" } else { "penetration depth (mm)" },
            if shear {
                "shear force, in-air offset removed (N)"
            } else {
                "normal force, in-air offset removed (N)"
            },
        )?;
        let mut labelled = Vec::new();
        // Data first, as small dots joined by a faint line, so every sample stays visible.
        for t in &trials {
            let deg = t.slope_deg;
            let colour = self.colour(deg);
            let pts: Vec<(f64, f64)> =
                t.curve.position().iter().zip(t.curve.force()).map(|(x, f)| (x * 1e3, *f)).collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), colour.mix(0.35).stroke_width(1)))
                .map_err(plot_err)?;
            let series = chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 2, colour.mix(0.8).filled())))
                .map_err(plot_err)?;
            if !labelled.contains(&deg.to_bits()) {
                labelled.push(deg.to_bits());
                series
                    .label(format!("{deg}°"))
                    .legend(move |(x, y)| Circle::new((x + 9, y), 4, colour.filled()));
            }
        }
        // Then each trial's fit: a thin black dashed line over the window (or the plateau mean
        // over the plateau), with short vertical bars at the window's ends.
        let tick = 0.025 * (y1 - y0);
        // Trials with a warning last, on top.
        let mut in_order = trials.clone();
        in_order.sort_by_key(|t| !t.warnings.is_empty());
        for t in &in_order {
            let (a, b, fa, fb) = match t.fit() {
                TrialFit::Penetration(f) => {
                    let (a, b) = f.depth_window_m;
                    (a, b, f.force_at(a), f.force_at(b))
                }
                TrialFit::Shear(f) => (f.plateau_m.0, f.plateau_m.1, f.plateau_force_n, f.plateau_force_n),
                TrialFit::Air => continue,
            };
            // A trial with a warning is drawn in red, so that a bad window stands out.
            let ink = if t.warnings.is_empty() { BLACK } else { palette::WARNING_RED };
            let line = vec![(a * 1e3, fa), (b * 1e3, fb)];
            let width = if t.warnings.is_empty() { 1 } else { 2 };
            chart
                .draw_series(DashedLineSeries::new(line, 6, 4, ink.stroke_width(width)))
                .map_err(plot_err)?;
            for (x, y) in [(a * 1e3, fa), (b * 1e3, fb)] {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(x, y - tick), (x, y + tick)],
                        ink.stroke_width(2),
                    )))
                    .map_err(plot_err)?;
            }
        }
        let fit_label = if shear {
            "plateau mean over the plateau (| ends)"
        } else {
            "fitted line over the window (| ends)"
        };
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(plot_err)?
            .label(fit_label)
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK.stroke_width(2)));
        if trials.iter().any(|t| !t.warnings.is_empty()) {
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(plot_err)?
                .label("trial with a warning")
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], palette::WARNING_RED.stroke_width(2))
                });
        }
        super::legend_box(
            &mut chart,
            if shear { SeriesLabelPosition::UpperRight } else { SeriesLabelPosition::UpperLeft },
            14.0,
            super::LegendBox::FAINT,
        )?;
        Ok(())
    }

    fn draw_resistance<DB: DrawingBackend>(&self, panel: Panel, area: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let normal = panel == Panel::NormalResistance;
        let stat = |p: &SlopeEstimate| if normal { p.k_n } else { p.k_s };
        let scale = 1e5;
        // Single trials are drawn just left of their slope so that the mean's marker does not
        // cover them.
        let offset = 0.6;
        let per_trial = self.trial_points(normal, offset, scale);
        let bars = |s: &SlopeStat| ((s.mean - s.sd) / scale, (s.mean + s.sd) / scale);
        let points = &self.campaign.points;
        let ys = points
            .iter()
            .flat_map(|p| {
                let b = bars(&stat(p));
                [b.0, b.1]
            })
            .chain(per_trial.iter().map(|p| p.1))
            .chain([0.0]);
        let (y0, y1) = range(ys, (0.0, 1.0));
        let (x0, x1) = range(points.iter().map(|p| p.slope_deg).chain([0.0]), (0.0, 25.0));
        let setup = ChartSetup { caption: Some((panel.title(), 22.0)), ..ChartSetup::DATA };
        let mut chart = setup.build(
            area,
            (x0 - 1.5)..(x1 + 1.0),
            y0..(y1 * 1.12),
            "slope (°)",
            if normal { "kₙ (10⁵ N/m³)" } else { "kₛ (10⁵ N/m³)" },
        )?;
        draw_trials(&mut chart, &per_trial)?;
        let measured: Vec<&SlopeEstimate> =
            points.iter().filter(|p| stat(p).origin == Origin::Measured).collect();
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
        let legend_colour = self.colour(0.5 * (self.slope_lo + self.slope_hi));
        chart
            .draw_series(measured.iter().map(|p| {
                Circle::new((p.slope_deg, stat(p).mean / scale), 6, self.colour(p.slope_deg).filled())
            }))
            .map_err(plot_err)?
            .label("mean ± SD (trial spread and fit SE combined)")
            .legend(move |(x, y)| Circle::new((x + 9, y), 6, legend_colour.filled()));
        let filled: Vec<&SlopeEstimate> =
            points.iter().filter(|p| stat(p).origin != Origin::Measured).collect();
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
        super::legend_box(&mut chart, SeriesLabelPosition::LowerLeft, 14.0, super::LegendBox::FAINT)?;
        Ok(())
    }
}

impl Data<'_> {
    /// Each trial's k (in units of `scale`) at its slope less `offset`, and whether it has a
    /// warning.
    fn trial_points(&self, normal: bool, offset: f64, scale: f64) -> Vec<(f64, f64, bool)> {
        self.campaign
            .trials
            .iter()
            .filter_map(|t| match (normal, t.fit()) {
                (true, TrialFit::Penetration(f)) => {
                    Some((t.slope_deg - offset, f.k_n / scale, !t.warnings.is_empty()))
                }
                (false, TrialFit::Shear(f)) => {
                    Some((t.slope_deg - offset, f.k_s / scale, !t.warnings.is_empty()))
                }
                _ => None,
            })
            .collect()
    }
}

/// The single trials: circles, and crosses for those with a warning.
fn draw_trials<DB: DrawingBackend>(
    chart: &mut ChartContext<
        '_,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    per_trial: &[(f64, f64, bool)],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let grey = palette::DATA_GREY;
    chart
        .draw_series(
            per_trial.iter().filter(|p| !p.2).map(|&(d, k, _)| Circle::new((d, k), 4, grey.stroke_width(2))),
        )
        .map_err(plot_err)?
        .label("single trials (drawn left of their slope)")
        .legend(move |(x, y)| Circle::new((x + 9, y), 4, grey.stroke_width(2)));
    if per_trial.iter().any(|p| p.2) {
        let red = palette::WARNING_RED;
        chart
            .draw_series(
                per_trial.iter().filter(|p| p.2).map(|&(d, k, _)| Cross::new((d, k), 5, red.stroke_width(2))),
            )
            .map_err(plot_err)?
            .label("single trial with a warning")
            .legend(move |(x, y)| Cross::new((x + 9, y), 5, red.stroke_width(2)));
    }
    Ok(())
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
pub fn write_all(dir: &Path, campaign: &Campaign) -> Result<Vec<PathBuf>> {
    let slopes = campaign.points.iter().map(|p| p.slope_deg);
    let slope_lo = slopes.clone().fold(f64::INFINITY, f64::min);
    let slope_hi = slopes.fold(f64::NEG_INFINITY, f64::max);
    let data = Data { campaign, slope_lo, slope_hi };
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends_and_middle() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(0.5), RGBColor(33, 144, 141));
    }
}
