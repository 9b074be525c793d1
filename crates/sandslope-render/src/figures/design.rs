//! Design figures: every design in the (safe-slope limit, speed at the target slope) plane with
//! the Pareto front and the template robot, and, when two keys vary, a map of the safe-slope
//! limit over them.

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::{ColorMap, ViridisRGB};

use super::palette;
use super::palette::STAR_GREEN;
use super::phase::star_points;
use super::{font, range, tick, ChartSetup, Figure};

/// The safe-slope limit over two varied keys (row-major: one row per `x` value).
pub struct SafeSlopeMap {
    pub x_key: String,
    pub y_key: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    /// Per design (`x` index slowest): the safe-slope rank, -1 when no slope is safe, `None`
    /// when invalid.
    pub safe: Vec<Option<f64>>,
}

/// The front figure, with the map beside it when there is one.
pub struct DesignFigure {
    pub others: Vec<(f64, f64)>,
    pub front: Vec<(f64, f64)>,
    pub template: Option<(f64, f64)>,
    pub map: Option<SafeSlopeMap>,
    pub title: String,
}

impl Figure for DesignFigure {
    fn size(&self) -> (u32, u32) {
        if self.map.is_some() {
            (1700, 720)
        } else {
            (1000, 720)
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = crate::plot_err;
        let root = root.titled(&self.title, font(22.0)).map_err(e)?;
        let (left, right) = match &self.map {
            Some(_) => {
                let (l, r) = root.split_horizontally(950);
                (l, Some(r))
            }
            None => (root, None),
        };
        // Speeds in cm/s, as every table prints them.
        let cm = |p: &(f64, f64)| (p.0, 100.0 * p.1);
        let others: Vec<(f64, f64)> = self.others.iter().map(cm).collect();
        let front: Vec<(f64, f64)> = self.front.iter().map(cm).collect();
        let template = self.template.as_ref().map(cm);
        let all = || others.iter().chain(&front).chain(template.iter());
        let (x0, x1) = range(all().map(|p| p.0), (0.0, 30.0));
        let (y0, y1) = range(all().map(|p| p.1), (0.0, 20.0));
        let setup = ChartSetup { x_ticks: Some(&tick), y_ticks: Some(&tick), ..ChartSetup::PANEL };
        let mut chart = setup.build(
            &left,
            x0..x1,
            y0..y1,
            "safe-slope limit (deg; -1: no slope is safe)",
            "speed at the target slope (cm/s)",
        )?;
        let grey = palette::MUTED_GREY;
        chart
            .draw_series(others.iter().map(|&p| Circle::new(p, 2, grey.mix(0.5).filled())))
            .map_err(e)?
            .label(format!("designs ({})", others.len() + front.len()))
            .legend(move |(x, y)| Circle::new((x + 12, y), 4, grey.filled()));
        let red = palette::SLIPPAGE;
        chart.draw_series(LineSeries::new(front.iter().copied(), red.stroke_width(2))).map_err(e)?;
        chart
            .draw_series(front.iter().map(|&p| Circle::new(p, 5, red.filled())))
            .map_err(e)?
            .label(format!("Pareto front ({})", front.len()))
            .legend(move |(x, y)| Circle::new((x + 12, y), 5, red.filled()));
        if let Some(t) = template {
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at(t)
                        + Polygon::new(star_points(12.0), STAR_GREEN.filled())
                        + PathElement::new(close(star_points(12.0)), BLACK.stroke_width(1)),
                ))
                .map_err(e)?
                .label("template robot (--robot)")
                .legend(|(x, y)| {
                    EmptyElement::at((x + 12, y)) + Polygon::new(star_points(9.0), STAR_GREEN.filled())
                });
        }
        super::legend(&mut chart, SeriesLabelPosition::LowerLeft, 15.0)?;
        if let (Some(map), Some(area)) = (&self.map, right) {
            draw_map(map, &area)?;
        }
        Ok(())
    }
}

fn close(mut pts: Vec<(i32, i32)>) -> Vec<(i32, i32)> {
    if let Some(&first) = pts.first() {
        pts.push(first);
    }
    pts
}

/// Edges of cells centred on sorted values (half-way between neighbours).
fn edges(v: &[f64]) -> Vec<f64> {
    let n = v.len();
    let mut e = Vec::with_capacity(n + 1);
    e.push(v[0] - 0.5 * (v[1] - v[0]));
    for w in v.windows(2) {
        e.push(0.5 * (w[0] + w[1]));
    }
    e.push(v[n - 1] + 0.5 * (v[n - 1] - v[n - 2]));
    e
}

fn draw_map<DB: DrawingBackend>(map: &SafeSlopeMap, area: &DrawingArea<DB, Shift>) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = crate::plot_err;
    let (main, bar) = area.split_horizontally(600);
    let (xe, ye) = (edges(&map.x), edges(&map.y));
    let setup = ChartSetup {
        caption: Some(("safe-slope limit (deg)", 18.0)),
        x_ticks: Some(&tick),
        y_ticks: Some(&tick),
        ..ChartSetup::MAP
    };
    let mut chart = setup.build(
        &main,
        xe[0]..xe[xe.len() - 1],
        ye[0]..ye[ye.len() - 1],
        map.x_key.as_str(),
        map.y_key.as_str(),
    )?;
    let finite = map.safe.iter().flatten().copied().filter(|v| *v >= 0.0);
    let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    let (lo, hi) = if lo.is_finite() { (lo, hi.max(lo + 1e-9)) } else { (0.0, 1.0) };
    let ny = map.y.len();
    let none_safe = palette::DARK_GREY;
    chart
        .draw_series(map.safe.iter().enumerate().map(|(c, v)| {
            let (i, j) = (c / ny, c % ny);
            let colour = match v {
                None => WHITE.filled(),
                Some(s) if *s < 0.0 => none_safe.filled(),
                Some(s) => ViridisRGB.get_color(((s - lo) / (hi - lo)) as f32).filled(),
            };
            Rectangle::new([(xe[i], ye[j]), (xe[i + 1], ye[j + 1])], colour)
        }))
        .map_err(e)?;
    // Invalid designs: a cross on white.
    chart
        .draw_series(map.safe.iter().enumerate().filter(|(_, v)| v.is_none()).map(|(c, _)| {
            let (i, j) = (c / ny, c % ny);
            PathElement::new(
                vec![(xe[i], ye[j]), (xe[i + 1], ye[j + 1])],
                palette::SHADE_GREY.stroke_width(1),
            )
        }))
        .map_err(e)?;
    super::colour_bar(
        &bar,
        (lo, hi),
        55,
        "deg (dark grey: none safe; white: invalid)",
        Some(&tick),
        (13.0, 14.0),
        &|k| ViridisRGB.get_color((k as f32 + 0.5) / 100.0),
    )?;
    Ok(())
}
