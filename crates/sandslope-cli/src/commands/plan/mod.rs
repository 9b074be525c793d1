//! `sandslope plan`: heading-aware routes and risk maps over an elevation model.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use sandslope::plan::Objective;

use crate::args::{FieldArgs, RobotArgs, TerrainArgs};
use crate::figures::plan::PlanFigure;
use crate::output::print_json;
use sandslope_io::routes as writers;
use sandslope_raster::write_two_band_geotiff;
use sandslope_request::plan::{
    answer, corridor_answer, Computed, CorridorPlanned, PlanSearch, Planned, CLASSES, SEARCH,
};
use sandslope_request::PlanRequest;

mod table;

use table::print_routes;

/// Maps at least this large get a progress bar (on a terminal).
const PROGRESS_MIN_CELLS: usize = 1 << 20;

/// Arguments of `sandslope plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// `--dem`, `--start`, `--goal`, `--start-px`, `--goal-px`, `--objective`, `--classes`,
    /// `--class-terrain`, `--allow-metastable`, `--time-weight`, `--max-roll`, `--descent`,
    /// `--cv-n`, `--cv-s`, `--max-memory`, `--search`, `--coarse-factor` and
    /// `--corridor-width`: the request's own fields ([`sandslope_request::plan::FIELDS`]).
    #[command(flatten)]
    pub fields: FieldArgs<PlanRequest>,
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub terrain: TerrainArgs,
    #[command(flatten)]
    pub out: Box<OutputArgs>,
}

/// Output files of `sandslope plan`.
#[derive(Debug, Args)]
pub struct OutputArgs {
    /// Write the routes as GeoJSON LineStrings in map coordinates.
    #[arg(long, value_name = "FILE")]
    pub geojson: Option<PathBuf>,
    /// Write one row per route vertex (x, y, z, heading, pitch, roll, regime, speed, p_fail).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Draw hillshade, risk layer and routes (PNG or SVG).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Write a 2-band GeoTIFF: best-heading p_fail, steepest safe climb azimuth (deg from north);
    /// a name ending .yaml writes a Nav2 map_server pair (.yaml + .pgm), .mcap an
    /// OccupancyGrid with the routes as Paths (docs/bags.md).
    #[arg(long, value_name = "FILE")]
    pub risk_map: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

impl PlanArgs {
    /// The request these flags make, read by the request layer's one raw-to-typed step (the
    /// one `serve`'s `/api/plan` takes): the plan's own flags, the robot and the terrain read
    /// from the flags it shares with other commands.
    pub fn request(&self) -> Result<PlanRequest> {
        let sources = (self.robot.request(), self.terrain.terrain.clone());
        Ok(PlanRequest::with_sources(&self.fields.pairs, sources)?)
    }
}

/// The request's routes by the search it chooses (`full_only`: always the full one), with
/// progress bars for large maps and notes on stderr unless `quiet`.
fn compute_any(request: &PlanRequest, risk_map: bool, full_only: bool, quiet: bool) -> Result<Computed> {
    let bars = Bars::new(!quiet);
    let note = |n: &str| {
        if !quiet {
            eprintln!("note: {n}");
        }
    };
    let computed = request.compute(risk_map, full_only, &note, &|obj, n, total| bars.set(obj, n, total))?;
    bars.finish();
    Ok(computed)
}

/// A progress bar per objective on a terminal (hidden ones otherwise).
struct Bars {
    show: bool,
    multi: MultiProgress,
    style: ProgressStyle,
    bars: std::sync::Mutex<Vec<(Objective, ProgressBar)>>,
}

impl Bars {
    /// Bars drawn on stderr when `show` and stderr is a terminal.
    fn new(show: bool) -> Bars {
        let show = show && std::io::IsTerminal::is_terminal(&std::io::stderr());
        let multi = MultiProgress::with_draw_target(if show {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        });
        let style =
            ProgressStyle::with_template("{prefix:>9} {bar:40} {pos}/{len} cells settled ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_bar());
        let bars = Objective::ALL.iter().map(|&o| (o, ProgressBar::hidden())).collect();
        Bars { show, multi, style, bars: std::sync::Mutex::new(bars) }
    }

    /// `n` of `total` cells settled by the search of `obj`.
    fn set(&self, obj: Objective, n: u64, total: u64) {
        let mut bars = self.bars.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, bar)) = bars.iter_mut().find(|(o, _)| *o == obj) {
            if bar.is_hidden() && self.show && total >= PROGRESS_MIN_CELLS as u64 {
                *bar = self
                    .multi
                    .add(ProgressBar::new(total).with_style(self.style.clone()).with_prefix(obj.name()));
            }
            bar.set_length(total);
            bar.set_position(n);
        }
    }

    fn finish(self) {
        for (_, bar) in self.bars.into_inner().unwrap_or_else(|e| e.into_inner()) {
            bar.finish();
        }
    }
}

/// Runs `sandslope plan`.
pub fn run(args: PlanArgs) -> Result<()> {
    // The flags are checked, in this order, before the output folders and any other file.
    let request = args.request()?;
    request.robot.load()?;
    request.settings()?;
    for p in [&args.out.plot].into_iter().flatten() {
        crate::figures::format_of(p)?;
    }
    // Every output folder is checked before any work, so a bad path cannot leave some of
    // the outputs written and others not.
    for p in [&args.out.geojson, &args.out.csv, &args.out.plot, &args.out.risk_map].into_iter().flatten() {
        crate::output::check_parent_exists(p)?;
    }
    // A GeoTIFF risk map is computed band by band from the heights read window by window
    // when the routes are searched in corridors (a DEM larger than memory); a Nav2 or MCAP map
    // and terrain classes need the full-resolution planner.
    let streamed_risk = args.out.risk_map.as_deref().is_some_and(is_geotiff) && request.classes.is_none();
    if request.search == PlanSearch::Corridor {
        for (flag, given) in [
            ("--plot", args.out.plot.is_some()),
            ("--risk-map", args.out.risk_map.is_some() && !streamed_risk),
            (CLASSES.long().as_str(), request.classes.is_some()),
        ] {
            if given {
                bail!(
                    "{flag} needs the full-resolution search: drop {} corridor (or crop the DEM)",
                    SEARCH.long()
                );
            }
        }
    }
    request.check_corridor()?;
    let full_only = args.out.plot.is_some();
    let risk_in_planner = (args.out.risk_map.is_some() && !streamed_risk) || args.out.plot.is_some();
    match compute_any(&request, risk_in_planner, full_only, false)? {
        Computed::Full(planned) => run_full(&args, &request, &planned),
        Computed::Corridor(planned) => {
            if let Some(p) = &args.out.risk_map {
                write_streamed_risk_map(&request, &planned, p, args.out.json)?;
            }
            run_corridor(&args, &request, &planned)
        }
    }
}

/// Whether `path` names a GeoTIFF risk map (not a Nav2 `.yaml` pair or an `.mcap`).
fn is_geotiff(path: &std::path::Path) -> bool {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    !matches!(ext.as_deref(), Some("yaml" | "yml" | "mcap"))
}

/// The risk map of a DEM searched in corridors, computed and written band by band with a
/// progress bar of rows on a terminal (none when `quiet`).
fn write_streamed_risk_map(
    request: &PlanRequest,
    planned: &CorridorPlanned,
    path: &std::path::Path,
    quiet: bool,
) -> Result<()> {
    let rows = planned.dem.rows as u64;
    let bar = crate::progress::progress_bar(rows, quiet, "risk map rows");
    request
        .write_streamed_risk_map(&planned.dem, &planned.heights, path, &|done, _| bar.set_position(done))?;
    bar.finish_and_clear();
    Ok(())
}

/// Writes and prints what the full-resolution search found.
fn run_full(args: &PlanArgs, request: &PlanRequest, planned: &Planned) -> Result<()> {
    let Planned { dem, result } = planned;
    if let Some(p) = &args.out.geojson {
        writers::write_geojson(p, &dem.geo, &result.routes)?;
    }
    if let Some(p) = &args.out.csv {
        writers::write_csv(p, &dem.geo, result.planner.grid(), &result.routes)?;
    }
    // A GeoTIFF risk map the planner was not asked for (it would have been streamed had the
    // routes been searched in corridors): the planner holds the map, so it is computed here.
    let computed;
    let risk = match &result.risk {
        Some(r) => Some(r),
        None if args.out.risk_map.is_some() => {
            let (p_fail, climb_azimuth_deg) = result.planner.risk_map();
            computed = sandslope::plan::RiskRaster { p_fail, climb_azimuth_deg };
            Some(&computed)
        }
        None => None,
    };
    if let (Some(p), Some(risk)) = (&args.out.risk_map, risk) {
        // `.yaml`: a Nav2 map_server pair; `.mcap`: OccupancyGrid and the routes (docs/bags.md).
        match p.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("yaml" | "yml") => sandslope_io::nav2_map::write_nav2_map(p, dem, &risk.p_fail)?,
            Some("mcap") => sandslope_io::nav2_map::write_map_mcap(p, dem, &risk.p_fail, &result.routes)?,
            _ => write_two_band_geotiff(
                p,
                dem.cols,
                dem.rows,
                &dem.geo,
                &risk.p_fail,
                &risk.climb_azimuth_deg,
            )?,
        }
    }
    if let (Some(p), Some(risk)) = (&args.out.plot, risk) {
        crate::figures::save(p, &PlanFigure::new(result, &dem.geo, &risk.p_fail))?;
    }
    warn_extrapolation(result.extrapolation);
    if args.out.json {
        return print_json(&answer(planned));
    }
    print_routes(&result.routes, request.allow_metastable);
    Ok(())
}

/// Writes and prints what the corridor search found, saying how it was found.
fn run_corridor(args: &PlanArgs, request: &PlanRequest, planned: &CorridorPlanned) -> Result<()> {
    let CorridorPlanned { dem, heights, plan, settings } = planned;
    if let Some(p) = &args.out.geojson {
        writers::write_geojson(p, &dem.geo, &plan.routes)?;
    }
    if let Some(p) = &args.out.csv {
        writers::write_csv(p, &dem.geo, heights, &plan.routes)?;
    }
    warn_extrapolation(plan.extrapolation);
    if args.out.json {
        return print_json(&corridor_answer(planned));
    }
    print_routes(&plan.routes, request.allow_metastable);
    let cells: Vec<String> = plan
        .corridors
        .iter()
        .map(|c| {
            let extent =
                if c.whole { "the whole map".to_string() } else { format!("{} coarse cells", c.half_width) };
            format!("{} within {extent}, {} cells", c.objective.name(), c.corridor_cells)
        })
        .collect();
    println!(
        "note: planned coarse-to-fine (--search corridor): routes on the map averaged over {f} x {f} cells \
         ({} x {}), then the exact optimum at full resolution in a corridor around each ({}); the \
         full-resolution optimum may be cheaper (docs/planning.md measures by how much; --search full finds it)",
        plan.coarse_size.0,
        plan.coarse_size.1,
        cells.join("; "),
        f = settings.factor()
    );
    let unreached = |r: &Result<_, _>| matches!(r, Err(sandslope::plan::NoRoute::GoalUnreachable));
    if plan.routes.iter().zip(&plan.corridors).any(|((_, r), c)| unreached(r) && !c.whole) {
        println!(
            "note: a route not found in its corridor may still exist on the whole map (the corridor could not be \
             widened to it within the memory limit): --search full decides"
        );
    }
    Ok(())
}

/// The warning for routes above a terrain's last measured point.
fn warn_extrapolation(extrapolation: Option<sandslope::plan::Extrapolation>) {
    if let Some(x) = extrapolation {
        eprintln!(
            "warning: routes reach {:.1} deg, above the terrain's last measured point ({} deg); k_n and k_s are \
             extrapolated linearly and floored at zero (docs/model.md §7)",
            x.max_pitch_deg, x.last_point_deg
        );
    }
}
