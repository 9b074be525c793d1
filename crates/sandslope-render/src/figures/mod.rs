//! Every figure of the tool, in one place: PNG or SVG by file extension, with an embedded font
//! so plots render on machines without system fonts, and one regime palette ([`palette`]).
//!
//! A figure implements [`Figure`] once, generically over the plotters backend, and draws from
//! result values only (it computes nothing); [`save`] picks the backend from the file name,
//! draws into a temporary file and renames it into place; [`to_svg`] renders it to a string
//! (for pages that embed figures).

pub mod calibrate;
pub mod design;
pub mod infer;
pub mod measurements;
pub mod palette;
pub mod phase;
pub mod plan;
pub mod risk;
pub mod simulate;
pub mod slope_curves;
pub mod step_budget;
pub mod sweep;
pub mod track;

use std::path::Path;
use std::sync::Once;

use anyhow::{bail, Result};
use plotters::coord::cartesian::Cartesian2d;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope_files::write_atomic;

/// Font family name under which the embedded DejaVu Sans is registered.
pub const FONT: &str = "sans-serif";

static REGISTER: Once = Once::new();

/// Registers DejaVu Sans (regular and bold) with plotters, once per process.
pub fn register_fonts() {
    REGISTER.call_once(|| {
        // The bytes are a valid TrueType font shipped by the `dejavu` crate.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

/// Something that can draw itself on any plotters backend.
pub trait Figure {
    /// Pixel size (width, height).
    fn size(&self) -> (u32, u32) {
        (1000, 700)
    }
    /// Draws the whole figure on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static;
}

/// Output image format, from the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// Portable Network Graphics.
    Png,
    /// Scalable Vector Graphics.
    Svg,
}

/// The image format for `path`, or an error naming the accepted extensions.
pub fn format_of(path: &Path) -> Result<ImageFormat> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("png") => Ok(ImageFormat::Png),
        Some("svg") => Ok(ImageFormat::Svg),
        _ => bail!("plot file {} must end in .png or .svg", path.display()),
    }
}

/// Draws `figure` into `path` (PNG or SVG by extension) through the one output writer.
///
/// The image is drawn and encoded in memory first, so that writing it is writing bytes: a
/// full disk is a write error naming the file (exit code 3), and a FIFO or `/dev/stdout`
/// receives the image directly.
pub fn save(path: &Path, figure: &impl Figure) -> Result<()> {
    let bytes = match format_of(path)? {
        ImageFormat::Png => to_png(figure)?,
        ImageFormat::Svg => to_svg(figure)?.into_bytes(),
    };
    write_atomic(path, &bytes)
}

/// Renders `figure` as a PNG file's bytes (RGB, the encoder plotters itself uses).
pub fn to_png(figure: &impl Figure) -> Result<Vec<u8>> {
    register_fonts();
    let (w, h) = figure.size();
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(crate::plot_err)?;
        figure.draw(&root)?;
        root.present().map_err(crate::plot_err)?;
    }
    png_bytes(&rgb, w, h)
}

/// Encodes an RGB buffer of `w` x `h` pixels as PNG.
pub fn png_bytes(rgb: &[u8], w: u32, h: u32) -> Result<Vec<u8>> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgb, w, h, image::ColorType::Rgb8)
        .map_err(|e| anyhow::anyhow!("encoding a PNG image: {e}"))?;
    Ok(out)
}

/// Renders `figure` as an SVG document in memory (for pages that embed figures inline).
pub fn to_svg(figure: &impl Figure) -> Result<String> {
    register_fonts();
    let size = figure.size();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(crate::plot_err)?;
        figure.draw(&root)?;
        root.present().map_err(crate::plot_err)?;
    }
    Ok(svg)
}

/// A text style in the embedded font.
pub fn font(size: f64) -> TextStyle<'static> {
    (FONT, size).into_font().into()
}

/// An axis tick label: whole numbers without a trailing `.0` (`16`, not `16.0`), others with
/// up to three decimals and no trailing zeros (`0.25`, `2.5`).
pub fn tick(v: &f64) -> String {
    let r = (v * 1000.0).round() / 1000.0;
    if r == r.trunc() {
        // `-0` prints as `0`.
        format!("{}", r.trunc() as i64)
    } else {
        let s = format!("{r:.3}");
        s.trim_end_matches('0').to_string()
    }
}

/// Padded `(min, max)` of finite values, or `fallback` if there are none.
pub fn range(values: impl IntoIterator<Item = f64>, fallback: (f64, f64)) -> (f64, f64) {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() {
        return fallback;
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.05 * lo.abs().max(1e-9) };
    (lo - pad, hi + pad)
}

/// A chart over two axes (plain or log coordinates `X`, `Y`), as [`ChartSetup::build`] makes.
pub type XyChart<'a, DB, X, Y> = ChartContext<'a, DB, Cartesian2d<X, Y>>;

/// How an x-y chart is set up: caption, margin, label areas, type sizes, grid lines and tick
/// labels, the one place these are chosen ([`ChartSetup::PANEL`] for design and inference
/// panels, [`ChartSetup::SLOPE`] for charts against slope, [`ChartSetup::MAP`] for heat maps).
#[derive(Clone, Copy)]
pub struct ChartSetup<'s> {
    /// Caption and its size, pt.
    pub caption: Option<(&'s str, f64)>,
    /// Margin around the chart, px.
    pub margin: u32,
    /// Height of the x axis' label area, px.
    pub x_label_area: u32,
    /// Width of the y axis' label area, px.
    pub y_label_area: u32,
    /// Tick labels, pt.
    pub label_pt: f64,
    /// Axis descriptions, pt.
    pub desc_pt: f64,
    /// Whether grid lines are drawn at all (heat maps have none).
    pub grid: bool,
    /// Light grid lines (white or [`palette::NO_GRID`]: none to see).
    pub light_lines: RGBAColor,
    /// Bold grid lines, if not plotters' default.
    pub bold_lines: Option<RGBColor>,
    /// Tick labels of the x axis, if not plotters' default.
    pub x_ticks: Option<&'s dyn Fn(&f64) -> String>,
    /// Tick labels of the y axis, if not plotters' default.
    pub y_ticks: Option<&'s dyn Fn(&f64) -> String>,
}

impl<'s> ChartSetup<'s> {
    /// Design and inference panels: margin 15, 15-pt ticks, 17-pt descriptions, no light grid.
    pub const PANEL: ChartSetup<'static> = ChartSetup {
        caption: None,
        margin: 15,
        x_label_area: 50,
        y_label_area: 75,
        label_pt: 15.0,
        desc_pt: 17.0,
        grid: true,
        light_lines: palette::opaque(WHITE),
        bold_lines: None,
        x_ticks: None,
        y_ticks: None,
    };
    /// Charts against slope (sweep, slope curves): margin 12, 15-pt ticks, 17-pt descriptions.
    pub const SLOPE: ChartSetup<'static> = ChartSetup {
        caption: None,
        margin: 12,
        x_label_area: 45,
        y_label_area: 70,
        label_pt: 15.0,
        desc_pt: 17.0,
        grid: true,
        light_lines: palette::opaque(palette::GRID),
        bold_lines: None,
        x_ticks: None,
        y_ticks: None,
    };
    /// The model's curves against slope (slope curves, the step budget): margin 12, 14-pt
    /// ticks, 16-pt descriptions, bold grid lines only.
    pub const CURVES: ChartSetup<'static> = ChartSetup {
        y_label_area: 80,
        label_pt: 14.0,
        desc_pt: 16.0,
        light_lines: palette::opaque(WHITE),
        bold_lines: Some(palette::GRID_BOLD),
        ..ChartSetup::SLOPE
    };
    /// Measurements and gait (load-cell curves, per-slope tables, tracked speeds): margin 12,
    /// 15-pt ticks, 17-pt descriptions, light grid lines transparent.
    pub const DATA: ChartSetup<'static> =
        ChartSetup { y_label_area: 60, light_lines: palette::NO_GRID, ..ChartSetup::SLOPE };
    /// Heat maps (risk and design maps; phase diagrams and the planned routes' map with
    /// smaller type): margin 15, 15-pt ticks, 17-pt descriptions, no grid lines.
    pub const MAP: ChartSetup<'static> = ChartSetup { grid: false, ..ChartSetup::PANEL };

    /// The chart over `x` and `y` (plain or log ranges) on `area`, its mesh drawn with the
    /// axis descriptions `x_desc` and `y_desc`.
    pub fn build<'a, DB, X, Y>(
        &self,
        area: &'a DrawingArea<DB, Shift>,
        x: X,
        y: Y,
        x_desc: &str,
        y_desc: &str,
    ) -> Result<XyChart<'a, DB, X::CoordDescType, Y::CoordDescType>>
    where
        DB: DrawingBackend + 'a,
        DB::ErrorType: 'static,
        X: AsRangedCoord,
        Y: AsRangedCoord,
        X::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let e = crate::plot_err;
        let mut builder = ChartBuilder::on(area);
        if let Some((text, pt)) = self.caption {
            builder.caption(text, font(pt));
        }
        let mut chart = builder
            .margin(self.margin)
            .x_label_area_size(self.x_label_area)
            .y_label_area_size(self.y_label_area)
            .build_cartesian_2d(x, y)
            .map_err(e)?;
        let mut mesh = chart.configure_mesh();
        if !self.grid {
            mesh.disable_mesh();
        }
        mesh.x_desc(x_desc)
            .y_desc(y_desc)
            .label_style(font(self.label_pt))
            .axis_desc_style(font(self.desc_pt))
            .light_line_style(self.light_lines);
        if let Some(c) = self.bold_lines {
            mesh.bold_line_style(c);
        }
        if let Some(f) = self.x_ticks {
            mesh.x_label_formatter(f);
        }
        if let Some(f) = self.y_ticks {
            mesh.y_label_formatter(f);
        }
        mesh.draw().map_err(e)?;
        Ok(chart)
    }
}

/// The colour bar beside a heat map: 100 bands from `lo` to `hi` on `area`, band `k` in
/// `colour(k)`, its axis described by `desc` with `ticks` (plotters' default if `None`) in
/// `label_pt`-point type, its description in `desc_pt`.
#[allow(clippy::too_many_arguments)]
pub fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (lo, hi): (f64, f64),
    y_label_area: u32,
    desc: &str,
    ticks: Option<&dyn Fn(&f64) -> String>,
    (label_pt, desc_pt): (f64, f64),
    colour: &dyn Fn(usize) -> RGBColor,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = crate::plot_err;
    let mut cb = ChartBuilder::on(area)
        .margin_top(45)
        .margin_bottom(65)
        .margin_right(10)
        .y_label_area_size(y_label_area)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(e)?;
    let mut mesh = cb.configure_mesh();
    mesh.disable_mesh()
        .disable_x_axis()
        .y_desc(desc)
        .label_style(font(label_pt))
        .axis_desc_style(font(desc_pt));
    if let Some(f) = ticks {
        mesh.y_label_formatter(f);
    }
    mesh.draw().map_err(e)?;
    cb.draw_series((0..100).map(|k| {
        let (a, b) = (lo + (hi - lo) * k as f64 / 100.0, lo + (hi - lo) * (k + 1) as f64 / 100.0);
        Rectangle::new([(0.0, a), (1.0, b)], colour(k).filled())
    }))
    .map_err(e)?;
    Ok(())
}

/// How opaque a legend box is: its white background and its black border.
#[derive(Debug, Clone, Copy)]
pub struct LegendBox {
    /// Opacity of the white background.
    pub white: f64,
    /// Opacity of the black border.
    pub border: f64,
}

impl LegendBox {
    /// Design, inference and risk figures: 90%-opaque white, black border.
    pub const PANEL: LegendBox = LegendBox { white: 0.9, border: 1.0 };
    /// Charts against slope, gait, simulation and routes: 85%-opaque white, black border.
    pub const LIGHT: LegendBox = LegendBox { white: 0.85, border: 1.0 };
    /// Load-cell measurements: 85%-opaque white, a 40% black border.
    pub const FAINT: LegendBox = LegendBox { white: 0.85, border: 0.4 };
}

/// The legend box of the design, inference and risk figures: at `position`, on 90%-opaque
/// white with a black border, in `pt`-point type.
pub fn legend<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    pt: f64,
) -> Result<()>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    CT: plotters::coord::CoordTranslate,
{
    legend_box(chart, position, pt, LegendBox::PANEL)
}

/// The legend box of every figure: at `position`, `style`'s white and border, in `pt`-point
/// type.
pub fn legend_box<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    pt: f64,
    style: LegendBox,
) -> Result<()>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    CT: plotters::coord::CoordTranslate,
{
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(style.white))
        .border_style(BLACK.mix(style.border))
        .label_font(font(pt))
        .draw()
        .map_err(crate::plot_err)?;
    Ok(())
}

/// A chart over slope (degrees, x) and some quantity (y), as the slope-curve figures draw.
pub type SlopeChart<'a, DB> = ChartContext<
    'a,
    DB,
    plotters::coord::cartesian::Cartesian2d<
        plotters::coord::types::RangedCoordf64,
        plotters::coord::types::RangedCoordf64,
    >,
>;

/// Shades the slopes at or above the angle of repose `repose` (when inside `x`) over the
/// whole height `y`, with a legend entry `label`: the one look of "the surface yields here".
pub fn shade_repose<DB: DrawingBackend>(
    chart: &mut SlopeChart<'_, DB>,
    repose: Option<f64>,
    x: (f64, f64),
    y: (f64, f64),
    label: &str,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    if let Some(repose) = repose.filter(|r| *r < x.1) {
        let shade = palette::SHADE_GREY.mix(0.45);
        chart
            .draw_series([Rectangle::new([(repose.max(x.0), y.0), (x.1, y.1)], shade.filled())])
            .map_err(crate::plot_err)?
            .label(label)
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], shade.filled()));
    }
    Ok(())
}

/// A dashed grey horizontal line at `level` across `x`, with a legend entry `label` (a
/// threshold such as s_min = R).
pub fn reference_line<'a, DB: DrawingBackend + 'a>(
    chart: &mut SlopeChart<'a, DB>,
    level: f64,
    label: &str,
    x: (f64, f64),
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let grey = palette::DATA_GREY;
    chart
        .draw_series(DashedLineSeries::new([(x.0, level), (x.1, level)], 8, 5, grey.stroke_width(2)))
        .map_err(crate::plot_err)?
        .label(label)
        .legend(move |(x, y)| {
            // Dashed like the line it names.
            let (a, b) = slope_curves::swatch_gap(true);
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (a, 0)], grey.stroke_width(2))
                + PathElement::new(vec![(b, 0), (20, 0)], grey.stroke_width(2))
        });
    Ok(())
}

/// Joins marching-squares segments that share an end into polylines, so a contour is stroked
/// as continuous paths: stroked one by one, segments shorter than a pixel leave gaps in a wide
/// line. Ends are matched at 8 significant digits (two squares compute their shared edge's
/// crossing in opposite directions, so the floats can differ in the last bits).
pub fn polylines(segments: &[sandslope::ContourSegment]) -> Vec<Vec<(f64, f64)>> {
    use std::collections::HashMap;
    type Key = (String, String);
    let key = |p: (f64, f64)| -> Key { (format!("{:.7e}", p.0), format!("{:.7e}", p.1)) };
    // Every segment end, by key: (segment, which end).
    let mut ends: HashMap<Key, Vec<(usize, bool)>> = HashMap::new();
    for (k, &(a, b)) in segments.iter().enumerate() {
        ends.entry(key(a)).or_default().push((k, false));
        ends.entry(key(b)).or_default().push((k, true));
    }
    let mut used = vec![false; segments.len()];
    // The unused segment touching `p` and its other end, marking it used.
    let mut next = |p: (f64, f64), used: &mut Vec<bool>| -> Option<(f64, f64)> {
        let list = ends.get_mut(&key(p))?;
        let pos = list.iter().position(|&(k, _)| !used[k])?;
        let (k, at_b) = list.swap_remove(pos);
        used[k] = true;
        let (a, b) = segments[k];
        Some(if at_b { a } else { b })
    };
    let mut lines = Vec::new();
    for k in 0..segments.len() {
        if used[k] {
            continue;
        }
        used[k] = true;
        let (a, b) = segments[k];
        let mut forward = vec![a, b];
        while let Some(p) = next(*forward.last().expect("non-empty"), &mut used) {
            forward.push(p);
        }
        let mut backward = Vec::new();
        let mut at = a;
        while let Some(p) = next(at, &mut used) {
            backward.push(p);
            at = p;
        }
        backward.reverse();
        backward.extend(forward);
        lines.push(backward);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::{polylines, tick};

    #[test]
    fn segments_sharing_ends_become_one_polyline() {
        // A square's four sides, out of order and in mixed directions, with the last bits of
        // one shared corner perturbed: one closed polyline of 5 points.
        let eps = 1e-15;
        let segs = vec![
            ((1.0, 1.0), (0.0, 1.0)),
            ((0.0, 0.0), (1.0, 0.0)),
            ((0.0, 1.0 + eps), (0.0, 0.0)),
            ((1.0, 1.0), (1.0, 0.0)),
        ];
        let lines = polylines(&segs);
        assert_eq!(lines.len(), 1, "{lines:?}");
        assert_eq!(lines[0].len(), 5);
        assert_eq!(lines[0].first(), lines[0].last());
        // Two separate segments stay two lines; no segment is lost or repeated.
        let apart = polylines(&[((0.0, 0.0), (1.0, 0.0)), ((5.0, 5.0), (6.0, 5.0))]);
        assert_eq!(apart.len(), 2);
        assert!(apart.iter().all(|l| l.len() == 2));
        assert!(polylines(&[]).is_empty());
    }

    #[test]
    fn ticks_drop_a_trailing_point_zero() {
        assert_eq!(tick(&16.0), "16");
        assert_eq!(tick(&-0.0), "0");
        assert_eq!(tick(&-2.0), "-2");
        assert_eq!(tick(&2.5), "2.5");
        assert_eq!(tick(&0.25), "0.25");
        assert_eq!(tick(&(0.1 + 0.2)), "0.3");
        assert_eq!(tick(&1e-4), "0");
    }
}
