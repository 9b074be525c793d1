//! What the page needs beyond the commands' JSON: the served robot and DEM, the cells of a phase
//! map, a risk raster without routes (`/data/...`), and the files `plan` writes
//! (`/download/...`), each computed by the same command code (docs/serve.md).

use sandslope_request::format::{Explain, Outcome};
use std::io::Write;

use serde::Serialize;

use crate::api;
use crate::reply::{ApiError, Reply};
use crate::served::{stride, DemInfo, Served};
use sandslope::Cause;
use sandslope_io::presets::{PresetKind, PRESETS};
use sandslope_raster::{read_raster, write_two_band_geotiff};
use sandslope_request::plan::{DEM, GOAL, GOAL_PX, OBJECTIVE, START, START_PX};
use sandslope_request::scenario::robot_fields;
use sandslope_request::{phase, simulate, PhaseRequest, PlanRequest};

/// Most cells of a `/data/phase-map` (the page asks for about 160 x 160).
pub const MAX_MAP_CELLS: u128 = 1 << 18;
/// Most trajectory samples of a `/data/simulation` (duration x rate: 60 s at 120 Hz; the page
/// asks for 30 Hz).
pub const MAX_SIM_SAMPLES: f64 = 7200.0;
fn not_found(what: &str, names: &str) -> ApiError {
    ApiError { status: 404, field: None, error: format!("no {what}; there are {names}") }
}

fn failed(e: &anyhow::Error) -> ApiError {
    ApiError::bad(None, format!("{e:#}"))
}

/// Answers `/data/<name>`.
pub fn answer(name: &str, params: &[(String, String)], served: &Served) -> Result<Reply, ApiError> {
    match name {
        "served" => served_info(served),
        "dem" => dem(served),
        "phase-map" => phase_map(params, served),
        "risk-map" => risk_map(params, served),
        "simulation" => simulation(params, served),
        _ => Err(not_found(
            &format!("/data/{name}"),
            "/data/served, /data/dem, /data/phase-map, /data/risk-map, /data/simulation",
        )),
    }
}

/// Answers `/download/<name>`: the bytes `plan` writes to `--geojson` or `--risk-map` for the
/// same flags.
pub fn download(name: &str, params: &[(String, String)], served: &Served) -> Result<Reply, ApiError> {
    let (file, content_type): (&'static str, &'static str) = match name {
        "plan.geojson" => ("plan.geojson", "application/geo+json"),
        "risk-map.tif" => ("risk-map.tif", "image/tiff"),
        _ => {
            return Err(not_found(
                &format!("/download/{name}"),
                "/download/plan.geojson, /download/risk-map.tif",
            ))
        }
    };
    let request = PlanRequest::from_params(&api::plan_params(params, served)?)?;
    let planned = request.plan(file == "risk-map.tif", &|_| {}, &|_, _, _| {})?;
    let dir = tempfile::tempdir().map_err(|e| ApiError { status: 500, field: None, error: e.to_string() })?;
    let path = dir.path().join(file);
    let geo = &planned.dem.geo;
    let written = match (file, &planned.result.risk) {
        ("plan.geojson", _) => sandslope_io::routes::write_geojson(&path, geo, &planned.result.routes),
        (_, Some(risk)) => write_two_band_geotiff(
            &path,
            planned.dem.cols,
            planned.dem.rows,
            geo,
            &risk.p_fail,
            &risk.climb_azimuth_deg,
        ),
        (_, None) => Err(anyhow::anyhow!("no risk raster was computed")),
    };
    written.map_err(|e| ApiError { status: 500, field: None, error: format!("{e:#}") })?;
    let mut opened = std::fs::File::open(&path).map_err(|e| ApiError {
        status: 500,
        field: None,
        error: e.to_string(),
    })?;
    // The folder (and the file in it) lives until the file is sent.
    let write = move |w: &mut dyn Write| {
        std::io::copy(&mut opened, w)?;
        drop(dir);
        Ok(())
    };
    Ok(Reply { body: Box::new(write), content_type, filename: Some(file) })
}

/// The served robot (its file keys), terrain name, the presets and the DEM's size.
fn served_info(served: &Served) -> Result<Reply, ApiError> {
    #[derive(Serialize)]
    struct Info {
        robot: sandslope::RobotSpec,
        robot_name: String,
        terrain_name: String,
        robots: Vec<&'static str>,
        terrains: Vec<&'static str>,
        /// Each regime cause's name and its one-line explanation.
        causes: Vec<(&'static str, &'static str)>,
        /// Each regime's name and what the robot does in it (docs/model.md §6, "Outcomes").
        outcomes: Vec<(&'static str, &'static str)>,
        /// The robot quantities a request may set, from the library's table of robot keys.
        robot_keys: Vec<RobotField>,
        dem: Option<DemInfo>,
    }
    /// One robot quantity a request may set: its parameter, its key in robot files (and in
    /// `robot`), its unit and what it is.
    #[derive(Serialize)]
    struct RobotField {
        field: &'static str,
        key: &'static str,
        unit: &'static str,
        description: &'static str,
    }
    let robot = sandslope_io::load_robot(&served.robot).map_err(|e| failed(&e))?;
    let terrain = sandslope_io::load_terrain(&served.terrain).map_err(|e| failed(&e))?;
    let names = |kind| PRESETS.iter().filter(|p| p.kind == kind).map(|p| p.name).collect();
    Ok(Reply::compact(Info {
        robot: robot.spec().clone(),
        robot_name: served.robot.clone(),
        terrain_name: terrain.name().unwrap_or(&served.terrain).to_string(),
        robots: names(PresetKind::Robot),
        terrains: names(PresetKind::Terrain),
        causes: Cause::ALL.iter().map(|c| (c.name(), c.explain())).collect(),
        outcomes: sandslope::Regime::ALL.iter().map(|r| (r.name(), r.outcome())).collect(),
        robot_keys: robot_fields()
            .map(|(key, field)| {
                let row = key.row();
                RobotField { field, key: row.name, unit: row.unit, description: row.description }
            })
            .collect(),
        dem: served.dem_info.clone(),
    }))
}

/// Values at every `stride`-th cell, NaN as null.
fn sampled(values: &[f32], cols: usize, rows: usize, stride: usize) -> Vec<Option<f32>> {
    (0..rows)
        .step_by(stride)
        .flat_map(|r| (0..cols).step_by(stride).map(move |c| r * cols + c))
        .map(|i| Some(values[i]).filter(|v| v.is_finite()))
        .collect()
}

#[derive(Serialize)]
struct Grid {
    cols: usize,
    rows: usize,
    stride: usize,
    values: Vec<Option<f32>>,
}

/// The served DEM's heights (nodata as null), every `stride`-th cell.
fn dem(served: &Served) -> Result<Reply, ApiError> {
    let Some(path) = &served.dem else {
        return Err(not_found(&format!("DEM: the server was started without {}", DEM.long()), "none"));
    };
    let r = read_raster(path).map_err(|e| failed(&e))?;
    let heights: Vec<f32> =
        (0..r.values.len()).map(|i| if r.is_nodata(i) { f32::NAN } else { r.values[i] as f32 }).collect();
    let stride = stride(r.cols, r.rows);
    Ok(Reply::compact(Grid {
        cols: r.cols,
        rows: r.rows,
        stride,
        values: sampled(&heights, r.cols, r.rows, stride),
    }))
}

/// The regime of every cell of the first panel of `phase` with these flags: `regimes` holds
/// one digit per cell (0 sinkage, 1 slippage, 2 metastable, 3 success), k_s rows from the
/// lowest, k_n columns from the lowest.
fn phase_map(params: &[(String, String)], served: &Served) -> Result<Reply, ApiError> {
    #[derive(Serialize)]
    struct Map {
        k_n: Vec<f64>,
        k_s: Vec<f64>,
        regimes: String,
        summary: sandslope::PanelSummary,
    }
    let request = PhaseRequest::from_params(&api::request_params(params, served)?)?;
    let panels = request.grid(MAX_MAP_CELLS)?.compute(&|| {})?;
    let Some(p) = panels.first() else {
        return Err(ApiError::bad(Some(phase::SLOPE.flag.to_string()), "no panel: give a slope"));
    };
    let (nx, ny) = (p.map.k_n().len(), p.map.k_s().len());
    let regimes = (0..ny)
        .flat_map(|j| (0..nx).map(move |i| (i, j)))
        .map(|(i, j)| char::from(b'0' + p.map.regime(i, j) as u8))
        .collect();
    Ok(Reply::compact(Map {
        k_n: p.map.k_n().to_vec(),
        k_s: p.map.k_s().to_vec(),
        regimes,
        summary: p.summary(),
    }))
}

/// P(failure) of every cell of the served DEM under `plan`'s flags, by a heading rule:
/// `rule=best` (the lowest over the 16 headings, band 1 of `plan --risk-map`) or
/// `rule=fall-line` (climbing straight up the cell's fall line). Start and goal are not
/// needed (any given are ignored).
fn risk_map(params: &[(String, String)], served: &Served) -> Result<Reply, ApiError> {
    let mut fall_line = false;
    let mut rest: Vec<(String, String)> = Vec::new();
    for (k, v) in params {
        match k.as_str() {
            "rule" => {
                fall_line = match v.as_str() {
                    "best" => false,
                    "fall-line" => true,
                    _ => {
                        return Err(ApiError::bad(
                            Some("rule".to_string()),
                            format!(
                            "rule = `{v}` must be best (lowest over 16 headings) or fall-line (straight up)"
                        ),
                        ))
                    }
                }
            }
            k if [&START, &GOAL, &START_PX, &GOAL_PX, &OBJECTIVE].iter().any(|f| f.flag == k) => {}
            _ => rest.push((k.clone(), v.clone())),
        }
    }
    // The planner's inputs need no endpoints; plan's flags require some, so any cell will do.
    rest.push((START_PX.flag.into(), "0,0".into()));
    rest.push((GOAL_PX.flag.into(), "0,0".into()));
    let request = PlanRequest::from_params(&api::plan_params(&rest, served)?)?;
    let inputs = request.inputs(&|_| {})?;
    let planner = inputs.planner()?;
    let (cols, rows) = (inputs.dem.cols, inputs.dem.rows);
    let p_fail = if fall_line { planner.fall_line_map() } else { planner.risk_map().0 };
    let stride = stride(cols, rows);
    Ok(Reply::compact(Grid { cols, rows, stride, values: sampled(&p_fail, cols, rows, stride) }))
}

/// One walk of `simulate` with these flags (one `slope`, not `slopes`), whole: the summary
/// `simulate --json` prints, the trajectory sampled at `rate` and the legs' geometry, for the
/// page's animation (the library's [`sandslope::simulate::Simulation`], as compact JSON), and
/// `scaling_spread`, the slope under all three contact scalings (`simulate --json`'s key; on
/// unless `scaling-spread=off`).
fn simulation(params: &[(String, String)], served: &Served) -> Result<Reply, ApiError> {
    if params.iter().any(|(k, _)| k == simulate::SLOPES.flag) {
        return Err(ApiError::bad(
            Some(simulate::SLOPES.flag.to_string()),
            format!(
                "/data/simulation animates one walk: give {}, not {} (/api/simulate takes {})",
                simulate::SLOPE.flag,
                simulate::SLOPES.flag,
                simulate::SLOPES.flag
            ),
        ));
    }
    let walks = api::simulate_walks(params, served)?;
    if walks.check_convergence || walks.ensemble.is_some() {
        let field = if walks.check_convergence { simulate::CHECK_CONVERGENCE } else { simulate::ENSEMBLE };
        return Err(ApiError::bad(
            Some(field.flag.to_string()),
            format!(
                "/data/simulation animates one walk: /api/simulate takes {} and {}",
                simulate::ENSEMBLE.flag,
                simulate::CHECK_CONVERGENCE.flag
            ),
        ));
    }
    let samples = walks.settings.duration_s * walks.settings.sample_rate_hz;
    if samples > MAX_SIM_SAMPLES {
        return Err(ApiError::bad(
            Some(simulate::RATE.flag.to_string()),
            format!(
                "{} x {} = {samples} trajectory samples: the page's animation takes at most {MAX_SIM_SAMPLES}",
                simulate::DURATION.long(),
                simulate::RATE.long()
            ),
        ));
    }
    let (sims, mut spreads) = walks.simulate_with_spreads()?;
    let scaling_spread = spreads.pop().flatten();
    let Some(sim) = sims.into_iter().next() else {
        return Err(ApiError::bad(Some(simulate::SLOPE.flag.to_string()), "no walk: give a slope"));
    };
    /// The walk beside its scaling spread.
    #[derive(serde::Serialize)]
    struct Walk {
        #[serde(flatten)]
        sim: sandslope::simulate::Simulation,
        scaling_spread: Option<sandslope_request::simulate::SpreadAnswer>,
    }
    Ok(Reply::compact(Walk { sim, scaling_spread }))
}
