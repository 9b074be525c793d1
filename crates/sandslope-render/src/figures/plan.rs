//! The `sandslope plan --plot` figure: hillshade tinted by the regime of a head-on climb
//! (straight up the fall line) and darkened where no heading at all is safe, the routes in
//! distinct colours with a legend, start and goal, a scale bar and a colour key.

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope::plan::Objective;
use sandslope::Regime;

use sandslope::plan::PlanResult;
use sandslope_raster::GeoRef;

use super::palette;
use super::{font, ChartSetup, Figure};
use crate::plot_err;

/// Longest side of the map raster as drawn, in blocks (large DEMs are subsampled).
const MAX_BLOCKS: usize = 600;

/// Hillshade and risk, subsampled, with the routes.
pub struct PlanFigure {
    /// Blocks across and down.
    nx: usize,
    ny: usize,
    /// Block colours, row-major from the north-west.
    colours: Vec<RGBColor>,
    /// Map extent: west, east, south, north.
    extent: [f64; 4],
    /// Routes: objective and vertices in map coordinates.
    routes: Vec<(Objective, Vec<(f64, f64)>)>,
    start: (f64, f64),
    goal: (f64, f64),
}

fn route_colour(o: Objective) -> RGBColor {
    match o {
        Objective::Time => palette::ROUTE_TIME,
        Objective::Risk => palette::ROUTE_RISK,
        Objective::Distance => palette::ROUTE_DISTANCE,
    }
}

/// The colour keys of the layer: regimes of a head-on climb, then "no safe heading".
/// The regime colours are the one palette of every figure ([`super::palette`]).
const KEYS: [(&str, (f64, f64, f64)); 5] = [
    ("head-on: success", rgb(palette::SUCCESS)),
    ("head-on: metastable", rgb(palette::METASTABLE)),
    ("head-on: slippage", rgb(palette::SLIPPAGE)),
    ("head-on: sinkage", rgb(palette::SINKAGE)),
    ("no heading with P(fail) < 0.5", rgb(palette::NO_SAFE_HEADING)),
];

const fn rgb(c: RGBColor) -> (f64, f64, f64) {
    (c.0 as f64, c.1 as f64, c.2 as f64)
}

fn regime_colour(r: Regime) -> (f64, f64, f64) {
    rgb(palette::regime_colour(r))
}

impl PlanFigure {
    /// Builds the figure data from a plan result and the best-heading p_fail per cell.
    pub fn new(result: &PlanResult, geo: &GeoRef, p_fail: &[f32]) -> PlanFigure {
        let planner = &result.planner;
        let grid = planner.grid();
        let (cols, rows) = (grid.cols(), grid.rows());
        let step = cols.max(rows).div_ceil(MAX_BLOCKS).max(1);
        let (nx, ny) = (cols.div_ceil(step), rows.div_ceil(step));
        // Light from the north-west, 45 degrees up (the cartographic convention).
        let (az, alt) = (315f64.to_radians(), 45f64.to_radians());
        let light = [az.sin() * alt.cos(), az.cos() * alt.cos(), alt.sin()];
        let mut colours = Vec::with_capacity(nx * ny);
        for by in 0..ny {
            for bx in 0..nx {
                let cell = sandslope::plan::Cell {
                    col: (bx * step + step / 2).min(cols - 1),
                    row: (by * step + step / 2).min(rows - 1),
                };
                let i = cell.row * cols + cell.col;
                let colour = match (grid.height(cell), planner.gradient(cell)) {
                    (None, _) => palette::NODATA,
                    (Some(_), None) => palette::NO_SLOPE,
                    (Some(_), Some([gx, gy])) => {
                        let n = (gx * gx + gy * gy + 1.0).sqrt();
                        let shade = ((-gx * light[0] - gy * light[1] + light[2]) / n).max(0.0);
                        let k = 0.2 + 0.95 * shade;
                        let best = f64::from(p_fail[i]);
                        let (r, g, b) = match planner.fall_line(cell) {
                            _ if best >= 0.5 => KEYS[4].1,
                            Some((regime, _)) => regime_colour(regime),
                            None => rgb(palette::NO_SLOPE),
                        };
                        let c = |v: f64| (v * k).clamp(0.0, 255.0) as u8;
                        RGBColor(c(r), c(g), c(b))
                    }
                };
                colours.push(colour);
            }
        }
        let extent =
            [geo.west, geo.west + cols as f64 * geo.cell_x, geo.north - rows as f64 * geo.cell_y, geo.north];
        let routes = result
            .routes
            .iter()
            .filter_map(|(o, r)| {
                let r = r.as_ref().ok()?;
                Some((*o, r.cells.iter().map(|c| geo.centre(c.col, c.row)).collect()))
            })
            .collect();
        let _ = step;
        PlanFigure {
            nx,
            ny,
            colours,
            extent,
            routes,
            start: geo.centre(result.start.col, result.start.row),
            goal: geo.centre(result.goal.col, result.goal.row),
        }
    }
}

/// A round length near `target`: 1, 2 or 5 times a power of ten.
fn nice_length(target: f64) -> f64 {
    let p = 10f64.powf(target.log10().floor());
    [5.0, 2.0, 1.0].into_iter().map(|m| m * p).find(|&l| l <= target).unwrap_or(p)
}

impl Figure for PlanFigure {
    fn size(&self) -> (u32, u32) {
        let [w, e, s, n] = self.extent;
        let aspect = (n - s) / (e - w);
        let map_w = 820.0;
        (map_w as u32 + 200, ((map_w * aspect) as u32 + 130).clamp(400, 1400))
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let (w, _) = self.size();
        let (map_area, side) = root.split_horizontally(w - 170);
        let [west, east, south, north] = self.extent;
        let setup = ChartSetup {
            caption: Some(("Planned routes: hillshade tinted by the regime of a head-on climb", 22.0)),
            margin: 12,
            x_label_area: 45,
            label_pt: 14.0,
            desc_pt: 16.0,
            x_ticks: Some(&super::tick),
            y_ticks: Some(&super::tick),
            ..ChartSetup::MAP
        };
        let mut chart = setup.build(&map_area, west..east, south..north, "x (m)", "y (m)")?;
        let (bw, bh) = ((east - west) / self.nx as f64, (north - south) / self.ny as f64);
        chart
            .draw_series(self.colours.iter().enumerate().map(|(i, c)| {
                let (bx, by) = ((i % self.nx) as f64, (i / self.nx) as f64);
                let x0 = west + bx * bw;
                let y1 = north - by * bh;
                Rectangle::new([(x0, y1 - bh), ((x0 + bw).min(east), (y1).max(south))], c.filled())
            }))
            .map_err(plot_err)?;
        // Each route over a white halo (readable on dark and light cells) in its own colour and
        // line style, so overlapping routes stay distinguishable: time solid, risk dashed,
        // distance dotted.
        for (_, pts) in &self.routes {
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), WHITE.mix(0.75).stroke_width(6)))
                .map_err(plot_err)?;
        }
        for (o, pts) in &self.routes {
            let c = route_colour(*o);
            let style = c.stroke_width(3);
            let (dash, gap) = match o {
                Objective::Time => (0, 0),
                Objective::Risk => (14, 7),
                Objective::Distance => (4, 5),
            };
            let series = if dash == 0 {
                chart.draw_series(LineSeries::new(pts.iter().copied(), style)).map_err(plot_err)?
            } else {
                chart
                    .draw_series(DashedLineSeries::new(pts.iter().copied(), dash, gap, style))
                    .map_err(plot_err)?
            };
            // The legend's 22 px sample in the same style, as three segments.
            let segments: [(i32, i32); 3] = match o {
                Objective::Time => [(0, 22), (0, 22), (0, 22)],
                Objective::Risk => [(0, 8), (14, 22), (22, 22)],
                Objective::Distance => [(0, 3), (9, 12), (18, 21)],
            };
            series.label(format!("{} route", o.name())).legend(move |(x, y)| {
                let seg = |(a, b): (i32, i32)| PathElement::new(vec![(a, 0), (b, 0)], style);
                EmptyElement::at((x, y)) + seg(segments[0]) + seg(segments[1]) + seg(segments[2])
            });
        }
        chart
            .draw_series([
                Circle::new(self.start, 7, WHITE.filled()),
                Circle::new(self.start, 7, BLACK.stroke_width(2)),
            ])
            .map_err(plot_err)?
            .label("start")
            .legend(|(x, y)| Circle::new((x + 12, y), 6, BLACK.stroke_width(2)));
        chart
            .draw_series([
                TriangleMarker::new(self.goal, 9, WHITE.filled()),
                TriangleMarker::new(self.goal, 8, BLACK.filled()),
            ])
            .map_err(plot_err)?
            .label("goal")
            .legend(|(x, y)| TriangleMarker::new((x + 12, y), 7, BLACK.filled()));
        super::legend_box(&mut chart, SeriesLabelPosition::UpperRight, 15.0, super::LegendBox::LIGHT)?;
        // Scale bar, bottom left, about a fifth of the map width.
        let len = nice_length((east - west) / 5.0);
        let (x0, y0) = (west + 0.05 * (east - west), south + 0.05 * (north - south));
        chart
            .draw_series([Rectangle::new(
                [
                    (x0 - 0.015 * (east - west), y0 - 0.025 * (north - south)),
                    (x0 + len * 1.15, y0 + 0.06 * (north - south)),
                ],
                WHITE.mix(0.85).filled(),
            )])
            .map_err(plot_err)?;
        chart
            .draw_series([
                PathElement::new(vec![(x0, y0), (x0 + len, y0)], BLACK.stroke_width(4)),
                PathElement::new(vec![(x0, y0), (x0, y0 + 0.012 * (north - south))], BLACK.stroke_width(2)),
                PathElement::new(
                    vec![(x0 + len, y0), (x0 + len, y0 + 0.012 * (north - south))],
                    BLACK.stroke_width(2),
                ),
            ])
            .map_err(plot_err)?;
        chart
            .draw_series([Text::new(format!("{len} m"), (x0, y0 + 0.045 * (north - south)), font(15.0))])
            .map_err(plot_err)?;
        draw_colour_bar(&side)?;
        Ok(())
    }
}

fn draw_colour_bar<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let keys = KEYS
        .iter()
        .map(|(label, c)| (*label, *c))
        .chain([("no slope (border)", rgb(palette::NO_SLOPE)), ("nodata", rgb(palette::NODATA))]);
    for (i, (label, (r, g, b))) in keys.enumerate() {
        let y = 70 + 30 * i as i32;
        area.draw(&Rectangle::new([(0, y), (18, y + 18)], RGBColor(r as u8, g as u8, b as u8).filled()))
            .map_err(plot_err)?;
        area.draw(&Rectangle::new([(0, y), (18, y + 18)], BLACK.stroke_width(1))).map_err(plot_err)?;
        // Long labels on two lines.
        let (l1, l2) = match label.split_once(": ") {
            Some((a, b)) => (format!("{a}:"), b.to_string()),
            None => match label.split_once(" with ") {
                Some((a, b)) => (a.to_string(), format!("with {b}")),
                None => (label.to_string(), String::new()),
            },
        };
        area.draw(&Text::new(l1, (24, y - 2), font(13.0))).map_err(plot_err)?;
        area.draw(&Text::new(l2, (24, y + 10), font(13.0))).map_err(plot_err)?;
    }
    Ok(())
}
