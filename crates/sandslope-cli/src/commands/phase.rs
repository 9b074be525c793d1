//! `sandslope phase`: phase diagrams (the paper's Section IV figure): the regime of every
//! terrain `(k_n, k_s)` on a grid, for each requested slope and mass, as a CSV of cells, a
//! summary table or JSON, and a figure with one panel per (mass, slope).
//!
//! Also the grid-axis parsing (`MIN:MAX:N[:log|:lin]`) and the progress bar shared with
//! `sandslope risk --map`.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use sandslope::{Axis, PanelSummary, PhasePanel, Regime, Terrain};

use crate::args::{beyond_last_point, warn_extrapolated, FieldArgs, RobotQuantityArgs, TerrainArgs};
use crate::figures::phase::PhaseFigure;
use crate::figures::save;
use crate::output::{print_json, sci, table};
use crate::progress::progress_bar;
use sandslope_request::scenario::ROBOT;
use sandslope_request::{PhaseRequest, RobotRequest};

/// Arguments of `sandslope phase`.
#[derive(Debug, Args)]
pub struct PhaseArgs {
    /// `--k-n`, `--k-s`, `--slope` and `--mass`: the request's own fields
    /// ([`sandslope_request::phase::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<PhaseRequest>,
    /// `--robot` ([`ROBOT`]; its mass is the panels').
    #[arg(long = ROBOT.flag, value_name = ROBOT.value_name, default_value = ROBOT.default, help = ROBOT.help)]
    pub robot: String,
    #[command(flatten)]
    pub quantities: RobotQuantityArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    /// Write every cell to this CSV file: k_n,k_s,slope_deg,mass_kg,regime,step_m.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Write NumPy arrays into this existing folder: regime.npy (int8 codes 0 sinkage,
    /// 1 slippage, 2 metastable, 3 success; shape mass x slope x k_s x k_n), step_m.npy
    /// (float64, NaN where the leg never anchors), k_n.npy, k_s.npy, slope_deg.npy, mass_kg.npy.
    #[arg(long, value_name = "DIR")]
    pub npy: Option<PathBuf>,
    /// Draw the phase diagram(s) to this file (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Print a JSON summary per panel instead of a table.
    #[arg(long)]
    pub json: bool,
    /// With --csv or --npy: the regime only, without the net step (no step_m column or
    /// step_m.npy), which writes less.
    #[arg(long)]
    pub regime_only: bool,
}

/// Most grid cells a `phase` run computes, over all panels (the library's cap, as Python's).
const MAX_CELLS: u128 = sandslope::limits::MAX_PHASE_CELLS as u128;
/// Most rows `--csv` writes (2^25: about 2 GB of text).
const MAX_CSV_CELLS: u128 = 1 << 25;

/// The panels of a `phase` run and what its figure needs.
pub struct Panels {
    /// One panel per (mass, slope), masses outermost.
    pub panels: Vec<PhasePanel>,
    /// The masses, kg.
    pub masses: Vec<f64>,
    /// The slopes each mass has, degrees as given.
    pub slopes_deg: Vec<f64>,
    /// The terrain read from `--terrain`.
    pub terrain: Terrain,
    /// The grid's k_n axis.
    pub k_n_axis: Axis,
    /// The grid's k_s axis.
    pub k_s_axis: Axis,
}

impl PhaseArgs {
    /// The request these flags make (the one `serve`'s `/api/phase` builds too): the
    /// request's own fields read by its one raw-to-typed step.
    pub fn request(&self) -> Result<PhaseRequest> {
        let robot =
            RobotRequest { robot: self.robot.clone(), mass: None, overrides: self.quantities.overrides() };
        Ok(PhaseRequest::with_robot(&self.fields.pairs, robot, self.terrain.terrain.clone())?)
    }
}

/// Checks the flags and computes every panel by the request layer (at most `max_cells` cells;
/// a progress bar on a terminal unless `quiet`; the extrapolation warning on stderr when
/// `warn`).
fn compute(args: &PhaseArgs, max_cells: u128, quiet: bool, warn: bool) -> Result<Panels> {
    let grid = args.request()?.grid(max_cells)?;
    let extrapolated = beyond_last_point(&grid.terrain, &grid.slopes_deg);
    if !extrapolated.is_empty() && warn {
        warn_extrapolated(&grid.terrain, &extrapolated);
    }
    if let Some(p) = &args.plot {
        crate::figures::format_of(p)?;
    }
    // Every cell is a CSV row of about 60 bytes.
    let cells = grid.cells();
    if args.csv.is_some() && cells > MAX_CSV_CELLS {
        bail!("--csv would write {cells} rows; at most {MAX_CSV_CELLS} are allowed: use fewer --k-n/--k-s points");
    }
    let bar = progress_bar(grid.rows(), quiet, "phase map");
    let panels = grid.compute(&|| bar.inc(1))?;
    bar.finish_and_clear();
    Ok(Panels {
        panels,
        masses: grid.masses,
        slopes_deg: grid.slopes_deg,
        terrain: grid.terrain,
        k_n_axis: grid.k_n_axis,
        k_s_axis: grid.k_s_axis,
    })
}

/// Runs `sandslope phase`.
pub fn run(args: PhaseArgs) -> Result<()> {
    for p in [&args.csv, &args.plot].into_iter().flatten() {
        crate::output::check_parent_exists(p)?;
    }
    if let Some(dir) = &args.npy {
        sandslope_io::npy::prepare_npy_dir(dir)?;
    }
    let Panels { panels, masses, slopes_deg, terrain, k_n_axis, k_s_axis } =
        compute(&args, MAX_CELLS, args.json, true)?;

    if let Some(path) = &args.csv {
        sandslope_render::tables::write_phase_csv(path, &panels, args.regime_only)?;
    }
    if let Some(dir) = &args.npy {
        sandslope_render::tables::write_phase_npy(dir, &panels, &masses, &slopes_deg, args.regime_only)?;
    }
    if let Some(path) = &args.plot {
        let figure = PhaseFigure::new(&panels, slopes_deg.len(), terrain_label(&terrain));
        save(path, &figure)?;
    }
    if args.json {
        let summaries: Vec<PanelSummary> = panels.iter().map(PhasePanel::summary).collect();
        return print_json(&summaries);
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
            sci(p.terrain_k_n),
            sci(p.terrain_k_s),
            p.terrain_regime.name().to_string(),
            sci(p.sinkage_threshold_k_n),
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
