//! The phase diagram figure (the paper's Fig. 6): one panel per (mass, slope), the regime of
//! every (k_n, k_s) cell in the regime palette, the success boundary s = s_min and the
//! terrain's star; and the drawing elements the risk map shares (star, cell edges, labels).

use anyhow::Result;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters_backend::{BackendCoord, DrawingErrorKind};

use sandslope::{Axis, AxisScale, PhasePanel, Regime};

use super::palette::{regime_colour, STAR_GREEN};
use super::{font, ChartSetup, Figure};

/// A five-pointed star of outer radius `r` pixels, centred on (0, 0).
pub fn star_points(r: f64) -> Vec<(i32, i32)> {
    (0..10)
        .map(|k| {
            let rad = if k % 2 == 0 { r } else { 0.42 * r };
            let a = std::f64::consts::FRAC_PI_2 + k as f64 * std::f64::consts::PI / 5.0;
            ((rad * a.cos()).round() as i32, (-rad * a.sin()).round() as i32)
        })
        .collect()
}

/// The terrain's measured (k_n, k_s) drawn as the paper's dark green star, outlined in
/// `outline` (black on the regime map, white on the dark risk map).
pub struct TerrainStar {
    /// Data coordinates (k_n, k_s).
    pub at: (f64, f64),
    /// Outline colour.
    pub outline: RGBColor,
}

impl<'a> PointCollection<'a, (f64, f64)> for &'a TerrainStar {
    type Point = &'a (f64, f64);
    type IntoIter = std::iter::Once<&'a (f64, f64)>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

impl<DB: DrawingBackend> Drawable<DB> for TerrainStar {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut points: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = points.next() else { return Ok(()) };
        let star: Vec<BackendCoord> = star_points(13.0).iter().map(|&(dx, dy)| (x + dx, y + dy)).collect();
        let closed = || star.iter().copied().chain(std::iter::once(star[0]));
        // A white halo first, so the star stands out on the light green of success cells.
        backend.draw_path(closed(), &WHITE.stroke_width(5))?;
        backend.fill_polygon(star.iter().copied(), &STAR_GREEN)?;
        backend.draw_path(closed(), &self.outline.stroke_width(2))
    }
}

/// Whether `(k_n, k_s)` lies within the cell edges `xe`, `ye` of a map (else no star is drawn).
pub fn within(xe: &[f64], ye: &[f64], (k_n, k_s): (f64, f64)) -> bool {
    let inside =
        |v: f64, e: &[f64]| e.first().is_some_and(|&lo| v >= lo) && e.last().is_some_and(|&hi| v <= hi);
    inside(k_n, xe) && inside(k_s, ye)
}

/// Cell edges along an axis: midpoints between values in axis coordinates, the ends
/// extended by half a step.
pub fn cell_edges(axis: &Axis) -> Vec<f64> {
    let c: Vec<f64> = axis.values().iter().map(|&v| axis.coordinate(v)).collect();
    let n = c.len();
    let mut edges = Vec::with_capacity(n + 1);
    edges.push(c[0] - 0.5 * (c[1] - c[0]));
    for k in 0..n - 1 {
        edges.push(0.5 * (c[k] + c[k + 1]));
    }
    edges.push(c[n - 1] + 0.5 * (c[n - 1] - c[n - 2]));
    edges.into_iter().map(|e| axis.from_coordinate(e)).collect()
}

/// Most cells drawn along one axis of a panel (about its width in pixels).
pub const MAX_DRAWN_CELLS: usize = 512;

/// Reduces an axis of `n` cells to at most `max` drawn blocks: the cell-edge index where each
/// block starts (and the final edge `n`), and the cell whose value each block shows (its
/// middle cell). With `n <= max`, every cell is its own block.
pub fn reduce(n: usize, max: usize) -> (Vec<usize>, Vec<usize>) {
    let m = n.min(max).max(1);
    let edges: Vec<usize> = (0..=m).map(|k| k * n / m).collect();
    let centres = edges.windows(2).map(|w| (w[0] + w[1]) / 2).collect();
    (edges, centres)
}

/// Tick labels for N/m^3 values: 1e5, 3e5, ...
pub fn sci_label(v: &f64) -> String {
    if *v == 0.0 {
        return "0".into();
    }
    let e = v.abs().log10().floor();
    let m = v / 10f64.powf(e);
    if (m - m.round()).abs() < 1e-6 {
        format!("{}e{}", m.round(), e)
    } else {
        format!("{m:.1}e{e}")
    }
}

/// The phase diagram figure: one panel per (mass, slope), masses down, slopes across.
pub struct PhaseFigure<'a> {
    panels: &'a [PhasePanel],
    columns: usize,
    terrain: String,
}

const PANEL_W: u32 = 600;
const PANEL_H: u32 = 500;
const LEGEND_H: u32 = 70;

impl<'a> PhaseFigure<'a> {
    pub fn new(panels: &'a [PhasePanel], columns: usize, terrain: String) -> Self {
        PhaseFigure { panels, columns: columns.max(1), terrain }
    }
    fn rows(&self) -> usize {
        self.panels.len().div_ceil(self.columns)
    }
    /// A single column is too narrow for the one-line legend (about 1100 px): wrap it.
    fn legend_wraps(&self) -> bool {
        self.columns == 1
    }
    fn legend_height(&self) -> u32 {
        if self.legend_wraps() {
            LEGEND_H + 60
        } else {
            LEGEND_H
        }
    }
}

impl Figure for PhaseFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (PANEL_W * self.columns as u32, PANEL_H * self.rows() as u32 + self.legend_height())
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let (_, h) = self.size();
        let (grid, legend) = root.split_vertically(h - self.legend_height());
        let areas = grid.split_evenly((self.rows(), self.columns));
        for (k, (panel, area)) in self.panels.iter().zip(areas.iter()).enumerate() {
            let letter = (b'a' + (k % 26) as u8) as char;
            let title = format!(
                "({letter}) m = {} kg, slope {}\u{b0}{}",
                panel.mass_kg,
                panel.slope_deg,
                if panel.map.beyond_repose() { " (at/above repose)" } else { "" }
            );
            let (x, y) = (panel.map.k_n_axis(), panel.map.k_s_axis());
            let (xe, ye) = (cell_edges(x), cell_edges(y));
            let xr = xe[0]..xe[xe.len() - 1];
            let yr = ye[0]..ye[ye.len() - 1];
            match (x.scale(), y.scale()) {
                (AxisScale::Log, AxisScale::Log) => {
                    draw_panel(area, xr.log_scale(), yr.log_scale(), panel, &title, &xe, &ye)?
                }
                (AxisScale::Log, AxisScale::Linear) => {
                    draw_panel(area, xr.log_scale(), yr, panel, &title, &xe, &ye)?
                }
                (AxisScale::Linear, AxisScale::Log) => {
                    draw_panel(area, xr, yr.log_scale(), panel, &title, &xe, &ye)?
                }
                (AxisScale::Linear, AxisScale::Linear) => draw_panel(area, xr, yr, panel, &title, &xe, &ye)?,
            }
        }
        draw_legend(&legend, &self.terrain, self.legend_wraps())?;
        Ok(())
    }
}

/// One panel: regime cells (runs of equal regime merged per row), the s = s_min contour and
/// the terrain star.
fn draw_panel<DB, X, Y>(
    area: &DrawingArea<DB, Shift>,
    xr: X,
    yr: Y,
    panel: &PhasePanel,
    title: &str,
    xe: &[f64],
    ye: &[f64],
) -> Result<()>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let e = crate::plot_err;
    let setup = ChartSetup {
        caption: Some((title, 20.0)),
        margin: 12,
        x_label_area: 48,
        y_label_area: 72,
        label_pt: 14.0,
        desc_pt: 16.0,
        x_ticks: Some(&sci_label),
        y_ticks: Some(&sci_label),
        ..ChartSetup::MAP
    };
    let mut chart =
        setup.build(area, xr, yr, "normal resistance k_n (N/m\u{b3})", "shear strength k_s (N/m\u{b3})")?;
    let map = &panel.map;
    // At most one drawn block per pixel: the grid is reduced to the panel's pixels first, so
    // drawing costs the same for 400 x 400 and 4096 x 4096 cells.
    let (xs, xc) = reduce(map.k_n().len(), MAX_DRAWN_CELLS);
    let (ys, yc) = reduce(map.k_s().len(), MAX_DRAWN_CELLS);
    let mut rects = Vec::new();
    for (jj, &j) in yc.iter().enumerate() {
        let mut start = 0;
        for ii in 1..=xc.len() {
            if ii == xc.len() || map.regime(xc[ii], j) != map.regime(xc[start], j) {
                let colour = regime_colour(map.regime(xc[start], j));
                // Each block reaches one cell into the next row and run, which are drawn
                // after it and cover the overlap: no hairline seams of background where
                // rounded pixel edges of neighbours do not meet.
                let right = xe[xs[(ii + 1).min(xc.len())]];
                let top = ye[ys[(jj + 2).min(yc.len())]];
                rects.push(Rectangle::new([(xe[xs[start]], ye[ys[jj]]), (right, top)], colour.filled()));
                start = ii;
            }
        }
    }
    chart.draw_series(rects).map_err(e)?;
    let contour = map.robust_contour_on(&xc, &yc);
    chart
        .draw_series(
            super::polylines(&contour).into_iter().map(|line| PathElement::new(line, BLACK.stroke_width(2))),
        )
        .map_err(e)?;
    let (k_n, k_s) = (panel.terrain_k_n, panel.terrain_k_s);
    if within(xe, ye, (k_n, k_s)) {
        chart.draw_series(std::iter::once(TerrainStar { at: (k_n, k_s), outline: BLACK })).map_err(e)?;
    }
    // Frame on top of the cells.
    let (xs, ys) = (chart.x_range(), chart.y_range());
    chart
        .draw_series(std::iter::once(Rectangle::new(
            [(xs.start, ys.start), (xs.end, ys.end)],
            BLACK.stroke_width(1),
        )))
        .map_err(e)?;
    Ok(())
}

/// The legend strip shared by all panels; `wrap` puts the contour and the star on lines of
/// their own.
fn draw_legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, terrain: &str, wrap: bool) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = crate::plot_err;
    let style = font(16.0);
    let mut x = 20;
    let mut y = 25;
    for r in Regime::ALL {
        area.draw(&Rectangle::new([(x, y - 10), (x + 24, y + 10)], regime_colour(r).filled())).map_err(e)?;
        area.draw(&Rectangle::new([(x, y - 10), (x + 24, y + 10)], BLACK.stroke_width(1))).map_err(e)?;
        area.draw(&Text::new(r.name(), (x + 32, y - 9), style.clone())).map_err(e)?;
        x += 40 + 9 * r.name().len() as i32 + 20;
    }
    if wrap {
        (x, y) = (20, y + 35);
    }
    area.draw(&PathElement::new(vec![(x, y), (x + 30, y)], BLACK.stroke_width(3))).map_err(e)?;
    area.draw(&Text::new("s = s_min (success boundary)", (x + 38, y - 9), style.clone())).map_err(e)?;
    x += 38 + 235;
    if wrap {
        (x, y) = (20, y + 35);
    }
    area.draw(&(EmptyElement::at((x + 12, y)) + Polygon::new(star_points(12.0), STAR_GREEN.filled())))
        .map_err(e)?;
    area.draw(&Text::new(format!("{terrain} (k_n, k_s) at that slope"), (x + 30, y - 9), style))
        .map_err(e)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_edges_bracket_the_values() {
        let a = Axis::new("k", 1e3, 1e5, 3, AxisScale::Log).unwrap();
        let e = cell_edges(&a);
        // Geometric midpoints: sqrt(1e3 * 1e4), sqrt(1e4 * 1e5); ends half a decade out.
        for (x, want) in
            e.iter().zip([1e3 / 10f64.sqrt(), 1e3 * 10f64.sqrt(), 1e4 * 10f64.sqrt(), 1e5 * 10f64.sqrt()])
        {
            assert!((x / want - 1.0).abs() < 1e-12, "{x} vs {want}");
        }
        assert_eq!(sci_label(&3e5), "3e5");
    }

    #[test]
    fn reduction_keeps_small_axes_and_covers_large_ones() {
        assert_eq!(reduce(3, 512), (vec![0, 1, 2, 3], vec![0, 1, 2]));
        let (e, c) = reduce(4096, 512);
        assert_eq!((e.len(), c.len(), e[0], e[512]), (513, 512, 0, 4096));
        assert!(e.windows(2).all(|w| w[1] - w[0] == 8) && c[0] == 4);
    }
}
