//! `sandslope phase`: phase diagrams (the paper's Section IV figure): the regime of every
//! terrain `(k_n, k_s)` on a grid, for each requested slope and mass, as a CSV of cells, a
//! summary table or JSON, and a figure with one panel per (mass, slope).
//!
//! Also the grid-axis parsing (`MIN:MAX:N[:log|:lin]`) and the progress bar shared with
//! `sandslope risk --map`.

use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters_backend::{BackendCoord, DrawingErrorKind};
use serde::Serialize;

use sandslope::model::{anchoring_threshold_k_s, sinkage_threshold_k_n};
use sandslope::{predict, Axis, AxisScale, PhaseMap, Regime, RegimeCounts, Robot, Slope, Terrain};

use super::common::{warn_extrapolated, TerrainArgs};
use crate::inputs::load_robot;
use crate::output::{print_json, sci, table, write_via_temp};
use crate::plot::{font, save, Figure};
use crate::presets::DEFAULT_ROBOT;

/// Default number of grid points per axis of `sandslope phase`.
pub const DEFAULT_POINTS: usize = 400;

/// Arguments of `sandslope phase`.
#[derive(Debug, Args)]
pub struct PhaseArgs {
    /// Normal-resistance axis, N/m^3: MIN:MAX:N with optional :log (default) or :lin.
    /// Default: the terrain's k_n / 100 to x 100, 400 points, log.
    #[arg(long = "k-n", value_name = "MIN:MAX:N[:log|:lin]")]
    pub k_n: Option<String>,
    /// Shear-strength axis, N/m^3: MIN:MAX:N with optional :log (default) or :lin.
    /// Default: the terrain's k_s / 1000 to x 100, 400 points, log.
    #[arg(long = "k-s", value_name = "MIN:MAX:N[:log|:lin]")]
    pub k_s: Option<String>,
    /// Slope(s) along the direction of travel, degrees, comma-separated (one panel each).
    #[arg(
        long,
        value_name = "DEG[,DEG...]",
        value_delimiter = ',',
        default_value = "0",
        allow_negative_numbers = true
    )]
    pub slope: Vec<f64>,
    /// Total robot mass(es), kg, comma-separated (one panel row each). Default: the robot's.
    #[arg(long, value_name = "KG[,KG...]", value_delimiter = ',')]
    pub mass: Vec<f64>,
    /// Robot: a TOML file or a built-in preset (see `sandslope presets`).
    #[arg(long, value_name = "FILE|PRESET", default_value = DEFAULT_ROBOT)]
    pub robot: String,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    /// Write every cell to this CSV file: k_n,k_s,slope_deg,mass_kg,regime,step_m.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Draw the phase diagram(s) to this file (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Print a JSON summary per panel instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Most grid cells a `phase` run computes, over all panels (2^28: 64 MiB of regimes).
const MAX_CELLS: u128 = 1 << 28;
/// Most rows `--csv` writes (2^25: about 2 GB of text).
const MAX_CSV_CELLS: u128 = 1 << 25;

/// Parses a grid axis `MIN:MAX:N[:log|:lin]` given to `flag` (log spacing by default).
pub fn parse_axis(flag: &str, text: &str) -> Result<Axis> {
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    if !(3..=4).contains(&parts.len()) {
        bail!("{flag} = {text} must be MIN:MAX:N or MIN:MAX:N:log or MIN:MAX:N:lin (e.g. 1e4:1e7:400)");
    }
    let number = |what: &str, s: &str| -> Result<f64> {
        s.parse::<f64>().map_err(|_| anyhow!("{flag}: {what} `{s}` is not a number (in {text})"))
    };
    let (min, max) = (number("MIN", parts[0])?, number("MAX", parts[1])?);
    let n: usize = parts[2]
        .parse()
        .map_err(|_| anyhow!("{flag}: N `{}` must be a whole number of at least 2 (in {text})", parts[2]))?;
    let scale = match parts.get(3).map(|s| s.to_ascii_lowercase()).as_deref() {
        None | Some("log") => AxisScale::Log,
        Some("lin") | Some("linear") => AxisScale::Linear,
        Some(other) => bail!("{flag}: spacing `{other}` must be `log` or `lin` (in {text})"),
    };
    Axis::new(flag, min, max, n, scale).map_err(|e| anyhow!("{e}"))
}

/// A log axis from `lo / down` to `hi * up` around positive terrain values, with `n` points.
pub fn default_axis(flag: &str, values: &[f64], down: f64, up: f64, n: usize) -> Result<Axis> {
    let positive: Vec<f64> = values.iter().copied().filter(|v| *v > 0.0 && v.is_finite()).collect();
    let (lo, hi) = if positive.is_empty() {
        (1e3, 1e9)
    } else {
        (
            positive.iter().copied().fold(f64::INFINITY, f64::min) / down,
            positive.iter().copied().fold(0.0, f64::max) * up,
        )
    };
    Axis::new(flag, lo, hi, n, AxisScale::Log).map_err(|e| anyhow!("{e}"))
}

/// The slopes (degrees, signed as given) strictly above the terrain's last measured point,
/// where MODEL.md section 7 extrapolates.
pub fn beyond_last_point(terrain: &Terrain, slopes_deg: &[f64]) -> Vec<f64> {
    // One rule for "extrapolated": the library's (MODEL.md section 7).
    let extrapolated =
        |d: f64| sandslope::Slope::from_signed_degrees(d).is_ok_and(|s| terrain.sample(s).extrapolated);
    slopes_deg.iter().copied().filter(|&d| extrapolated(d)).collect()
}

/// A progress bar of `len` steps on stderr, shown only when stdout and stderr are terminals
/// and `quiet` is false (hidden in `--json` mode and when piped).
pub fn progress_bar(len: u64, quiet: bool, what: &str) -> ProgressBar {
    if quiet || !std::io::stdout().is_terminal() || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(what.to_string());
    bar
}

/// One (mass, slope) panel: the map and what is drawn and reported with it.
struct Panel {
    slope_deg: f64,
    mass_kg: f64,
    map: PhaseMap,
    /// The terrain's (k_n, k_s) at this slope and its regime for this robot.
    terrain: (f64, f64, Regime),
    sinkage_k_n: f64,
    anchoring_k_s: f64,
}

/// One cell as written by `--csv`.
#[derive(Serialize)]
struct CellRow {
    k_n: f64,
    k_s: f64,
    slope_deg: f64,
    mass_kg: f64,
    regime: &'static str,
    step_m: Option<f64>,
}

#[derive(Serialize)]
struct AxisRecord {
    min: f64,
    max: f64,
    points: usize,
    scale: &'static str,
}

impl From<&Axis> for AxisRecord {
    fn from(a: &Axis) -> Self {
        AxisRecord {
            min: a.min(),
            max: a.max(),
            points: a.len(),
            scale: if a.scale() == AxisScale::Log { "log" } else { "lin" },
        }
    }
}

#[derive(Serialize)]
struct TerrainRecord {
    k_n: f64,
    k_s: f64,
    regime: &'static str,
}

/// One panel as printed by `--json`.
#[derive(Serialize)]
struct PanelRecord {
    slope_deg: f64,
    mass_kg: f64,
    k_n_axis: AxisRecord,
    k_s_axis: AxisRecord,
    counts: RegimeCounts,
    terrain: TerrainRecord,
    sinkage_threshold_k_n: f64,
    anchoring_threshold_k_s: f64,
    beyond_repose: bool,
}

/// Runs `sandslope phase`.
pub fn run(args: PhaseArgs) -> Result<()> {
    for p in [&args.csv, &args.plot].into_iter().flatten() {
        crate::output::check_parent_exists(p)?;
    }
    let base = load_robot(&args.robot)?;
    let terrain = args.terrain.load()?;
    let masses = if args.mass.is_empty() { vec![base.mass()] } else { args.mass.clone() };
    let robots = masses
        .iter()
        .map(|&m| base.with_mass(m).map_err(|e| anyhow!("{}", e.renamed("--mass"))))
        .collect::<Result<Vec<Robot>>>()?;
    let slopes = args
        .slope
        .iter()
        .map(|&d| Slope::from_signed_degrees(d).map_err(|e| anyhow!("{}", e.renamed("--slope"))))
        .collect::<Result<Vec<Slope>>>()?;
    let samples: Vec<_> = slopes.iter().map(|&s| terrain.sample(s)).collect();
    let extrapolated = beyond_last_point(&terrain, &args.slope);
    if !extrapolated.is_empty() {
        warn_extrapolated(&terrain, &extrapolated);
    }
    let k_n_axis = match &args.k_n {
        Some(t) => parse_axis("--k-n", t)?,
        None => default_axis(
            "--k-n",
            &samples.iter().map(|s| s.ground.k_n).collect::<Vec<_>>(),
            100.0,
            100.0,
            DEFAULT_POINTS,
        )?,
    };
    let k_s_axis = match &args.k_s {
        Some(t) => parse_axis("--k-s", t)?,
        None => default_axis(
            "--k-s",
            &samples.iter().map(|s| s.ground.k_s).collect::<Vec<_>>(),
            1000.0,
            100.0,
            DEFAULT_POINTS,
        )?,
    };
    if let Some(p) = &args.plot {
        crate::plot::format_of(p)?;
    }
    // Guards against a typo such as 100000 points per axis: the maps are kept in memory at two
    // bits per cell, and every cell is a CSV row of about 60 bytes.
    let cells = (robots.len() * slopes.len()) as u128 * k_n_axis.len() as u128 * k_s_axis.len() as u128;
    if cells > MAX_CELLS {
        bail!(
            "--k-n and --k-s give {cells} cells over {} panel(s); at most {MAX_CELLS} are allowed (e.g. 4096 x 4096 per panel is {})",
            robots.len() * slopes.len(),
            4096u128 * 4096
        );
    }
    if args.csv.is_some() && cells > MAX_CSV_CELLS {
        bail!("--csv would write {cells} rows; at most {MAX_CSV_CELLS} are allowed: use fewer --k-n/--k-s points");
    }

    let rows = (robots.len() * slopes.len() * k_s_axis.len()) as u64;
    let bar = progress_bar(rows, args.json, "phase map");
    let mut panels = Vec::new();
    for (robot, &mass_kg) in robots.iter().zip(&masses) {
        for ((&slope, &slope_deg), sample) in slopes.iter().zip(&args.slope).zip(&samples) {
            let map = PhaseMap::compute(robot, slope, terrain.repose(), &k_n_axis, &k_s_axis, &|| bar.inc(1));
            let g = sample.ground;
            panels.push(Panel {
                slope_deg,
                mass_kg,
                map,
                terrain: (g.k_n, g.k_s, predict(robot, slope, &g).regime),
                sinkage_k_n: sinkage_threshold_k_n(robot, slope),
                anchoring_k_s: anchoring_threshold_k_s(robot, slope),
            });
        }
    }
    bar.finish_and_clear();

    if let Some(path) = &args.csv {
        write_cells(path, &panels)?;
    }
    if let Some(path) = &args.plot {
        let figure = PhaseFigure::new(&panels, slopes.len(), terrain_label(&terrain));
        save(path, &figure)?;
    }
    if args.json {
        let records: Vec<PanelRecord> = panels.iter().map(record).collect();
        return print_json(&records);
    }
    let mut t = table(&[
        "slope (deg)",
        "mass (kg)",
        "terrain k_n",
        "terrain k_s",
        "terrain regime",
        "sinkage below k_n",
        "sinkage %",
        "slippage %",
        "metastable %",
        "success %",
    ]);
    for p in &panels {
        let c = p.map.counts();
        let pct = |r: Regime| format!("{:.1}", 100.0 * c.get(r) as f64 / c.total() as f64);
        t.add_row([
            format!("{}", p.slope_deg),
            format!("{}", p.mass_kg),
            sci(p.terrain.0),
            sci(p.terrain.1),
            p.terrain.2.name().to_string(),
            sci(p.sinkage_k_n),
            pct(Regime::Sinkage),
            pct(Regime::Slippage),
            pct(Regime::Metastable),
            pct(Regime::Success),
        ]);
    }
    println!("{t}");
    println!(
        "grid: k_n {} to {} N/m^3 ({} points), k_s {} to {} N/m^3 ({} points); percentages are of grid cells",
        sci(k_n_axis.min()),
        sci(k_n_axis.max()),
        k_n_axis.len(),
        sci(k_s_axis.min()),
        sci(k_s_axis.max()),
        k_s_axis.len()
    );
    Ok(())
}

fn terrain_label(terrain: &Terrain) -> String {
    terrain.name().map(str::to_string).unwrap_or_else(|| "terrain".into())
}

fn record(p: &Panel) -> PanelRecord {
    PanelRecord {
        slope_deg: p.slope_deg,
        mass_kg: p.mass_kg,
        k_n_axis: p.map.k_n_axis().into(),
        k_s_axis: p.map.k_s_axis().into(),
        counts: p.map.counts(),
        terrain: TerrainRecord { k_n: p.terrain.0, k_s: p.terrain.1, regime: p.terrain.2.name() },
        sinkage_threshold_k_n: p.sinkage_k_n,
        anchoring_threshold_k_s: p.anchoring_k_s,
        beyond_repose: p.map.beyond_repose(),
    }
}

/// Writes every cell of every panel, atomically.
fn write_cells(path: &std::path::Path, panels: &[Panel]) -> Result<()> {
    write_via_temp(path, |tmp| {
        let file = std::fs::File::create(tmp).with_context(|| format!("cannot write {}", path.display()))?;
        let mut w = csv::Writer::from_writer(std::io::BufWriter::with_capacity(1 << 20, file));
        for p in panels {
            let (k_n, k_s) = (p.map.k_n(), p.map.k_s());
            for (j, &ks) in k_s.iter().enumerate() {
                for (i, &kn) in k_n.iter().enumerate() {
                    w.serialize(CellRow {
                        k_n: kn,
                        k_s: ks,
                        slope_deg: p.slope_deg,
                        mass_kg: p.mass_kg,
                        regime: p.map.regime(i, j).name(),
                        step_m: p.map.step(i, j),
                    })
                    .with_context(|| format!("cannot write {}", path.display()))?;
                }
            }
        }
        w.flush().with_context(|| format!("cannot write {}", path.display()))?;
        Ok(())
    })
}

/// The paper's colours: blue sinkage, red slippage, yellow metastable, light green success.
pub fn regime_colour(r: Regime) -> RGBColor {
    match r {
        Regime::Sinkage => RGBColor(66, 110, 201),
        Regime::Slippage => RGBColor(214, 56, 48),
        Regime::Metastable => RGBColor(247, 214, 67),
        Regime::Success => RGBColor(168, 226, 150),
    }
}

/// Dark green of the terrain star.
pub const STAR_GREEN: RGBColor = RGBColor(0, 100, 0);

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
        backend.fill_polygon(star.iter().copied(), &STAR_GREEN)?;
        backend.draw_path(star.iter().copied().chain(std::iter::once(star[0])), &self.outline)
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
struct PhaseFigure<'a> {
    panels: &'a [Panel],
    columns: usize,
    terrain: String,
}

const PANEL_W: u32 = 600;
const PANEL_H: u32 = 500;
const LEGEND_H: u32 = 70;

impl<'a> PhaseFigure<'a> {
    fn new(panels: &'a [Panel], columns: usize, terrain: String) -> Self {
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
    panel: &Panel,
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
    let e = crate::error::plot_err;
    let mut chart = ChartBuilder::on(area)
        .caption(title, font(20.0))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(xr, yr)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("normal resistance k_n (N/m\u{b3})")
        .y_desc("shear strength k_s (N/m\u{b3})")
        .x_label_formatter(&sci_label)
        .y_label_formatter(&sci_label)
        .label_style(font(14.0))
        .axis_desc_style(font(16.0))
        .draw()
        .map_err(e)?;
    let map = &panel.map;
    let nx = map.k_n().len();
    let mut rects = Vec::new();
    for j in 0..map.k_s().len() {
        let mut start = 0;
        for i in 1..=nx {
            if i == nx || map.regime(i, j) != map.regime(start, j) {
                let colour = regime_colour(map.regime(start, j));
                rects.push(Rectangle::new([(xe[start], ye[j]), (xe[i], ye[j + 1])], colour.filled()));
                start = i;
            }
        }
    }
    chart.draw_series(rects).map_err(e)?;
    let contour = map.robust_contour();
    chart
        .draw_series(contour.iter().map(|&(a, b)| PathElement::new(vec![a, b], BLACK.stroke_width(2))))
        .map_err(e)?;
    let (k_n, k_s, _) = panel.terrain;
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
    let e = crate::error::plot_err;
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
    fn axis_flags_parse_and_reject_bad_input() {
        let a = parse_axis("--k-n", "1e4:1e7:31").unwrap();
        assert_eq!((a.min(), a.max(), a.len(), a.scale()), (1e4, 1e7, 31, AxisScale::Log));
        assert_eq!(parse_axis("--k-n", "0:10:11:lin").unwrap().scale(), AxisScale::Linear);
        for bad in ["1e4:1e7", "a:1e7:3", "1e4:1e7:x", "1e4:1e7:3:cubic", "0:1e7:3", "1e7:1e4:3", "1e4:1e7:1"]
        {
            let msg = parse_axis("--k-n", bad).unwrap_err().to_string();
            assert!(msg.contains("--k-n"), "{bad}: {msg}");
        }
    }

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
}
