//! Elevation models (docs/model.md §8): the two-band risk raster of `sandslope plan
//! --risk-map`, routes of `sandslope plan --json` with their cells, and the raster reader.

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::sync::LazyLock;

use numpy::{PyArrayMethods, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use sandslope::plan::{
    Cell, Descent, ElevationGrid, Objective, PitchTableCache, PlanRequest, PlanSettings, Planner, Route,
};
use sandslope::risk::UncertainTerrain;
use sandslope_io::pds3::Pds3Dtm;
use sandslope_io::raster::read_raster as read;
use sandslope_request::plan::RouteRecord;

use crate::arrays::put;
use crate::interrupt::interruptibly;
use crate::types::{PyRobot, PyTerrain};
use crate::{anyhow_error, value_error};

/// The grid, terrain and settings of a NumPy DEM (row 0 = north; NaN or `nodata` = missing
/// heights, used as float32 like the CLI), as `sandslope plan` builds them; `row_widths`, the
/// east-west ground size of each row's cells where they differ (a geographic DEM's).
#[allow(clippy::too_many_arguments)]
fn inputs(
    dem: &PyReadonlyArray2<'_, f64>,
    cell_x: f64,
    cell_y: f64,
    row_widths: Option<Vec<f64>>,
    nodata: Option<f64>,
    terrain: &PyTerrain,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
    max_roll_deg: f64,
    descent: &str,
    allow_metastable: bool,
    time_weight: f64,
) -> PyResult<(ElevationGrid, UncertainTerrain, PlanSettings)> {
    let descent = Descent::parse(descent)
        .ok_or_else(|| value_error(format!("descent = {descent:?} must be \"symmetric\" or \"level\"")))?;
    let settings =
        PlanSettings::new(max_roll_deg, descent, allow_metastable, time_weight).map_err(value_error)?;
    let terrain = crate::risk::uncertain(terrain, cv_n, cv_s)?;
    let a = dem.as_array();
    let (rows, cols) = (a.shape()[0], a.shape()[1]);
    let grid = match a.as_slice() {
        Some(z) => ElevationGrid::from_heights(cols, rows, cell_x, cell_y, z, nodata),
        None => ElevationGrid::from_heights(
            cols,
            rows,
            cell_x,
            cell_y,
            &a.iter().copied().collect::<Vec<_>>(),
            nodata,
        ),
    }
    .and_then(|g| match row_widths {
        Some(w) => g.with_row_widths(w),
        None => Ok(g),
    })
    .map_err(|e| value_error(format!("{e} (row_widths_m: one width per row of the dem, in metres)")))?;
    Ok((grid, terrain, settings))
}

/// The pitch tables of this process, shared by every `risk_raster` call: the tiles of a Dask
/// raster on one worker tabulate the model once, not once per tile (the table was 60% of a
/// 1024 x 1024 tile's time); results are bit for bit those of a fresh table.
static PITCH_TABLES: LazyLock<PitchTableCache> = LazyLock::new(PitchTableCache::new);

/// Per cell, the lowest p_fail over the 16 headings and the azimuth of the steepest usable
/// climb (degrees from north), as `sandslope plan --risk-map` writes them: `2 * rows * cols`
/// float32 values, band after band.
#[pyfunction]
#[pyo3(signature = (dem, cell_x, cell_y, robot, terrain, nodata=None, cv_n=None, cv_s=None, max_roll_deg=sandslope::plan::DEFAULT_MAX_ROLL_DEG, descent="symmetric", allow_metastable=false, row_widths_m=None))]
#[allow(clippy::too_many_arguments)]
pub fn risk_raster<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    cell_x: f64,
    cell_y: f64,
    robot: &PyRobot,
    terrain: &PyTerrain,
    nodata: Option<f64>,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
    max_roll_deg: f64,
    descent: &str,
    allow_metastable: bool,
    row_widths_m: Option<Vec<f64>>,
) -> PyResult<Bound<'py, numpy::PyArray1<f32>>> {
    let (grid, terrain, settings) = inputs(
        &dem,
        cell_x,
        cell_y,
        row_widths_m,
        nodata,
        terrain,
        cv_n,
        cv_s,
        max_roll_deg,
        descent,
        allow_metastable,
        sandslope::plan::DEFAULT_TIME_WEIGHT,
    )?;
    let robot = &robot.inner;
    let bands = py
        .detach(move || {
            let planner = Planner::with_cache(grid, None, &[terrain], robot, settings, &PITCH_TABLES)?;
            let (mut p_fail, climb) = planner.risk_map();
            drop(planner);
            p_fail.extend_from_slice(&climb);
            Ok::<_, sandslope::plan::PlanError>(p_fail)
        })
        .map_err(value_error)?;
    Ok(crate::arrays::array(py, bands))
}

fn objective(name: &str) -> PyResult<Objective> {
    Objective::ALL.into_iter().find(|o| o.name() == name).ok_or_else(|| {
        value_error(format!("objective = {name:?} must be \"time\", \"risk\" or \"distance\""))
    })
}

fn cell(which: &str, rc: (i64, i64), rows: usize, cols: usize) -> PyResult<Cell> {
    let (r, c) = rc;
    if r < 0 || c < 0 || r as usize >= rows || c as usize >= cols {
        return Err(value_error(format!(
            "{which} = ({r}, {c}) is outside the map: rows 0 to {}, columns 0 to {}",
            rows - 1,
            cols - 1
        )));
    }
    Ok(Cell { col: c as usize, row: r as usize })
}

/// A route as `plan --json` prints it (the request layer's `RouteRecord`: every figure, null
/// where no route exists), with the found route's cells, coordinates, heights and steps as arrays.
fn route_dict<'py>(
    py: Python<'py>,
    r: &Result<Route, sandslope::plan::NoRoute>,
    planner: &Planner,
    origin: (f64, f64),
) -> PyResult<Bound<'py, PyDict>> {
    let d = pythonize::pythonize(py, &RouteRecord::from(r)).map_err(value_error)?.cast_into::<PyDict>()?;
    if let Ok(r) = r {
        let g = planner.grid();
        put(&d, "rows", r.cells.iter().map(|c| c.row as i64).collect())?;
        put(&d, "cols", r.cells.iter().map(|c| c.col as i64).collect())?;
        // East of the west edge along the cell's own row: on a geographic DEM each row's
        // cells have their own width (`row_widths_m`), on a uniform grid this is cell_x.
        put(
            &d,
            "x_m",
            r.cells.iter().map(|c| origin.0 + (c.col as f64 + 0.5) * g.cell_x_at(c.row)).collect(),
        )?;
        put(&d, "y_m", r.cells.iter().map(|c| origin.1 - (c.row as f64 + 0.5) * g.cell_y()).collect())?;
        put(&d, "z_m", r.cells.iter().map(|&c| g.height(c).unwrap_or(f64::NAN)).collect())?;
        let steps = PyDict::new(py);
        put(&steps, "heading_deg", r.steps.iter().map(|s| s.heading_deg).collect())?;
        put(&steps, "pitch_deg", r.steps.iter().map(|s| s.pitch_deg).collect())?;
        put(&steps, "roll_deg", r.steps.iter().map(|s| s.roll_deg).collect())?;
        put(&steps, "length_m", r.steps.iter().map(|s| s.length_m).collect())?;
        put(&steps, "regime", r.steps.iter().map(|s| s.regime as i8).collect())?;
        put(&steps, "speed_m_s", r.steps.iter().map(|s| s.speed.unwrap_or(f64::NAN)).collect())?;
        put(&steps, "p_fail", r.steps.iter().map(|s| s.p_fail).collect())?;
        put(&steps, "over_roll_limit", r.steps.iter().map(|s| s.over_roll_limit).collect())?;
        d.set_item("steps", steps)?;
    }
    Ok(d)
}

/// Routes from `start` to `goal` (each `(row, col)`) for each objective, by the library's
/// `plan::plan` (what `sandslope plan` computes): `{"routes": {name: route}, "extrapolation":
/// None or {max_pitch_deg, last_point_deg}}`.
#[pyfunction]
#[pyo3(signature = (dem, cell_x, cell_y, robot, terrain, start, goal, objectives, origin, nodata=None, cv_n=None, cv_s=None, max_roll_deg=sandslope::plan::DEFAULT_MAX_ROLL_DEG, descent="symmetric", allow_metastable=false, time_weight=sandslope::plan::DEFAULT_TIME_WEIGHT, classes=None, class_terrains=None, row_widths_m=None))]
#[allow(clippy::too_many_arguments)]
pub fn plan<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    cell_x: f64,
    cell_y: f64,
    robot: &PyRobot,
    terrain: &PyTerrain,
    start: (i64, i64),
    goal: (i64, i64),
    objectives: Vec<String>,
    origin: (f64, f64),
    nodata: Option<f64>,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
    max_roll_deg: f64,
    descent: &str,
    allow_metastable: bool,
    time_weight: f64,
    classes: Option<PyReadonlyArray2<'py, f64>>,
    class_terrains: Option<Vec<(i64, PyRef<'py, PyTerrain>)>>,
    row_widths_m: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let objectives: Vec<Objective> = objectives.iter().map(|o| objective(o)).collect::<PyResult<_>>()?;
    let (grid, terrain, settings) = inputs(
        &dem,
        cell_x,
        cell_y,
        row_widths_m,
        nodata,
        terrain,
        cv_n,
        cv_s,
        max_roll_deg,
        descent,
        allow_metastable,
        time_weight,
    )?;
    let (rows, cols) = (grid.rows(), grid.cols());
    let request = PlanRequest {
        start: cell("start", start, rows, cols)?,
        goal: cell("goal", goal, rows, cols)?,
        objectives,
        risk_map: false,
    };
    let (classes, terrains) = match (classes, class_terrains) {
        (None, None) => (None, vec![terrain]),
        (Some(c), Some(t)) => {
            let (indices, terrains) = class_inputs(&c, &t, rows, cols, cv_n, cv_s)?;
            (Some(indices), terrains)
        }
        _ => return Err(value_error("classes and class_terrains go together: give both or neither")),
    };
    let robot = &robot.inner;
    // The search runs on a thread of its own so that Ctrl-C, checked here, can stop it
    // (issue 21: a 4096^2 plan ran to its end, seconds to minutes, before Python saw the signal).
    let result = interruptibly(py, |stop| {
        sandslope::plan::plan(grid, classes, &terrains, robot, settings, &request, &|_, _, _| {
            if stop.load(Ordering::Relaxed) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
    })?
    .map_err(value_error)?;
    let routes = PyDict::new(py);
    for (o, r) in &result.routes {
        routes.set_item(o.name(), route_dict(py, r, &result.planner, origin)?)?;
    }
    let d = PyDict::new(py);
    d.set_item("routes", routes)?;
    d.set_item("extrapolation", pythonize::pythonize(py, &result.extrapolation).map_err(value_error)?)?;
    Ok(d)
}

/// A class array (aligned with the DEM; NaN: no class) and `(class, terrain)` pairs as the
/// planner takes them: each cell's index into the terrains, and the terrains with their
/// uncertainty, by the rule of `sandslope plan --classes --class-terrain`.
fn class_inputs(
    classes: &PyReadonlyArray2<'_, f64>,
    class_terrains: &[(i64, PyRef<'_, PyTerrain>)],
    rows: usize,
    cols: usize,
    cv_n: Option<f64>,
    cv_s: Option<f64>,
) -> PyResult<(Vec<u8>, Vec<UncertainTerrain>)> {
    let a = classes.as_array();
    if a.shape() != [rows, cols] {
        let shape = a.shape();
        return Err(value_error(format!(
            "classes has shape ({}, {}); it must be the DEM's ({rows}, {cols})",
            shape[0], shape[1]
        )));
    }
    if class_terrains.is_empty() || class_terrains.len() >= usize::from(sandslope::plan::NO_CLASS) {
        return Err(value_error("class_terrains: give between 1 and 254 {class: terrain} pairs"));
    }
    let keys: Vec<i64> = class_terrains.iter().map(|(k, _)| *k).collect();
    let terrains = class_terrains
        .iter()
        .map(|(_, t)| crate::risk::uncertain(t, cv_n, cv_s))
        .collect::<PyResult<Vec<_>>>()?;
    let values: Vec<f64> = a.iter().copied().collect();
    let indices = sandslope::plan::class_indices(&values, |i| !values[i].is_finite(), &keys)
        .map_err(|e| value_error(format!("classes: {e}; add it to class_terrains")))?;
    Ok((indices, terrains))
}

/// The GDAL_NODATA value of a GeoTIFF (None when it has none), read from its tags only, as
/// `read_raster` honours it (the Dask raster reads windows itself and marks the same cells).
#[pyfunction]
pub fn geotiff_nodata(path: PathBuf) -> PyResult<Option<f64>> {
    sandslope_io::raster::geotiff_nodata(&path).map_err(crate::anyhow_error)
}

/// The size, ground cell size and notes of a PDS3 DTM from its label alone, checked against
/// its data file: `{rows, cols, cell_x_m, cell_y_m, row_widths_m, notes}` (`row_widths_m`: an
/// equirectangular DTM's east-west size of each row's cells, else None). The Dask raster then reads it
/// window by window with [`pds3_window`] (a HiRISE DTM can be larger than memory).
#[pyfunction]
pub fn pds3_info<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let dtm = py.detach(|| Pds3Dtm::open(&path)).map_err(anyhow_error)?;
    let d = PyDict::new(py);
    d.set_item("rows", dtm.rows)?;
    d.set_item("cols", dtm.cols)?;
    d.set_item("cell_x_m", dtm.cell_m.0)?;
    d.set_item("cell_y_m", dtm.cell_m.1)?;
    d.set_item("row_widths_m", dtm.row_widths_m.map(|w| crate::arrays::array(py, w)))?;
    d.set_item("notes", dtm.notes)?;
    Ok(d)
}

/// Rows `top:bottom` and columns `left:right` of a PDS3 DTM as a 2-D float64 array of heights
/// in metres (NaN where missing or special), the same values `read_raster` gives there; only
/// those samples are read from the file.
#[pyfunction]
pub fn pds3_window<'py>(
    py: Python<'py>,
    path: PathBuf,
    top: usize,
    bottom: usize,
    left: usize,
    right: usize,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let values =
        py.detach(|| Pds3Dtm::open(&path)?.read_window(top..bottom, left..right)).map_err(anyhow_error)?;
    crate::arrays::array(py, values).reshape([bottom - top, right - left])
}

/// `(values, rows, cols, geo)` as returned by [`read_raster`].
type RasterTuple<'py> = (Bound<'py, numpy::PyArray1<f64>>, usize, usize, Bound<'py, PyDict>);

/// A GeoTIFF, ESRI ASCII or PDS3 raster: `(values, rows, cols, geo)` with the values row-major
/// (nodata as NaN) and `geo = {west, north, cell_x, cell_y}`.
#[pyfunction]
pub fn read_raster<'py>(py: Python<'py>, path: PathBuf) -> PyResult<RasterTuple<'py>> {
    let raster = py.detach(|| read(&path)).map_err(anyhow_error)?;
    let values: Vec<f64> = (0..raster.values.len())
        .map(|i| if raster.is_nodata(i) { f64::NAN } else { raster.values[i] })
        .collect();
    let geo = PyDict::new(py);
    geo.set_item("west", raster.geo.west)?;
    geo.set_item("north", raster.geo.north)?;
    geo.set_item("cell_x", raster.geo.cell_x)?;
    geo.set_item("cell_y", raster.geo.cell_y)?;
    // The ground size of a cell in metres (what plan and risk_raster take as cell_size_m), and
    // what the coordinates are: cell_x/cell_y are in map units (degrees when geographic).
    geo.set_item("cell_x_m", raster.cell_m.0)?;
    geo.set_item("cell_y_m", raster.cell_m.1)?;
    // Where the rows' east-west sizes differ (geographic, equirectangular), each row's, m: what
    // plan and risk_raster take as row_widths_m.
    geo.set_item("row_widths_m", raster.row_widths_m.clone().map(|w| crate::arrays::array(py, w)))?;
    geo.set_item("crs", pythonize::pythonize(py, &raster.crs).map_err(crate::value_error)?)?;
    geo.set_item("notes", raster.notes.clone())?;
    Ok((crate::arrays::array(py, values), raster.rows, raster.cols, geo))
}
