//! Elevation models (docs/model.md §8): the two-band risk raster of `sandslope plan
//! --risk-map`, routes of `sandslope plan --json` with their cells (both the request layer's
//! grid requests: NumPy heights in, columns out), and the raster readers.

use std::borrow::Cow;
use std::path::PathBuf;

use numpy::{PyArrayMethods, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use sandslope_raster::pds3::Pds3Dtm;
use sandslope_raster::read_raster as read;
use sandslope_request::plan::{ClassRaster, GridPlanRequest, GridRequest, GridSource, RouteRecord};

use crate::arrays::put;
use crate::interrupt::interruptibly;
use crate::types::{PyRobot, PyTerrain};
use crate::{anyhow_error, value_error};

/// `descent`'s default, the field table's ([`sandslope_request::plan::DESCENT`]; its other
/// keywords, `max_roll_deg`, `time_weight`, `allow_metastable`, `cv_n`, `cv_s` and
/// `objectives`, are the table's too: `crates/sandslope-request/tests/fields.rs` checks the
/// signatures and the stub against it).
const DESCENT_DEFAULT: &str = match sandslope_request::plan::DESCENT.default {
    Some(d) => d,
    None => panic!("--descent has a default"),
};

/// The values of a 2-D array row-major, borrowed when it is contiguous, and its shape.
fn row_major<'a>(a: &'a PyReadonlyArray2<'_, f64>) -> (Cow<'a, [f64]>, (usize, usize)) {
    let a = a.as_array();
    let shape = (a.shape()[0], a.shape()[1]);
    match a.to_slice() {
        Some(v) => (Cow::Borrowed(v), shape),
        None => (Cow::Owned(a.iter().copied().collect()), shape),
    }
}

/// Per cell, the lowest p_fail over the 16 headings and the azimuth of the steepest usable
/// climb (degrees from north), as `sandslope plan --risk-map` writes them: `2 * rows * cols`
/// float32 values, band after band (the request layer's [`GridRequest::risk_raster`], the DEM
/// row 0 = north, NaN or `nodata` = missing heights, used as float32 like the CLI).
#[pyfunction]
#[pyo3(signature = (dem, cell_x, cell_y, robot, terrain, nodata=None, cv_n=None, cv_s=None, max_roll_deg=sandslope::plan::DEFAULT_MAX_ROLL_DEG, descent=DESCENT_DEFAULT, allow_metastable=false, row_widths_m=None))]
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
    let time_weight = sandslope::plan::DEFAULT_TIME_WEIGHT;
    let request = GridRequest {
        cell_x,
        cell_y,
        row_widths_m,
        nodata,
        cv_n,
        cv_s,
        max_roll_deg,
        descent: descent.to_string(),
        allow_metastable,
        time_weight,
    };
    let (heights, (rows, cols)) = row_major(&dem);
    let (robot, terrain) = (robot.closed_form()?, &terrain.inner);
    let source =
        GridSource { heights: &heights, rows, cols, robot, terrain, classes: None, class_terrains: None };
    let bands = py.detach(|| request.risk_raster(&source)).map_err(|e| value_error(e.message()))?;
    Ok(crate::arrays::array(py, bands))
}

/// Routes from `start` to `goal` (each `(row, col)`) for each objective, by the request
/// layer's [`GridPlanRequest`] (the library's `plan::plan`, what `sandslope plan` computes):
/// `{"routes": {name: route}, "extrapolation": None or {max_pitch_deg, last_point_deg}}`, each
/// route as `plan --json` prints it (`RouteRecord`: every figure, null where no route exists)
/// with a found route's cells, coordinates, heights and steps as arrays.
#[pyfunction]
#[pyo3(signature = (dem, cell_x, cell_y, robot, terrain, start, goal, objectives, origin, nodata=None, cv_n=None, cv_s=None, max_roll_deg=sandslope::plan::DEFAULT_MAX_ROLL_DEG, descent=DESCENT_DEFAULT, allow_metastable=false, time_weight=sandslope::plan::DEFAULT_TIME_WEIGHT, classes=None, class_terrains=None, row_widths_m=None))]
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
    origin: Option<(f64, f64)>,
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
    let grid = GridRequest {
        cell_x,
        cell_y,
        row_widths_m,
        nodata,
        cv_n,
        cv_s,
        max_roll_deg,
        descent: descent.to_string(),
        allow_metastable,
        time_weight,
    };
    let request = GridPlanRequest { grid, start, goal, objectives, origin };
    let (heights, (rows, cols)) = row_major(&dem);
    let class_values = classes.as_ref().map(row_major);
    let classes = class_values.as_ref().map(|(values, shape)| ClassRaster { values, shape: *shape });
    let class_terrains = class_terrains.as_ref().map(|p| p.iter().map(|(k, t)| (*k, &t.inner)).collect());
    let (robot, terrain) = (robot.closed_form()?, &terrain.inner);
    let source = GridSource { heights: &heights, rows, cols, robot, terrain, classes, class_terrains };
    // The search runs on a thread of its own so that Ctrl-C, checked here, can stop it
    // (issue 21: a 4096^2 plan ran to its end, seconds to minutes, before Python saw the signal).
    let result = interruptibly(py, |stop| request.answer(&source, Some(stop)))?
        .map_err(|e| value_error(e.message()))?;
    let routes = PyDict::new(py);
    for (o, r) in &result.routes {
        let d =
            pythonize::pythonize(py, &RouteRecord::from(r)).map_err(value_error)?.cast_into::<PyDict>()?;
        if let Ok(route) = r {
            route_arrays(&d, request.route_cells(route, &result.planner))?;
        }
        routes.set_item(o.name(), d)?;
    }
    let d = PyDict::new(py);
    d.set_item("routes", routes)?;
    d.set_item("extrapolation", pythonize::pythonize(py, &result.extrapolation).map_err(value_error)?)?;
    Ok(d)
}

/// A found route's cells and steps put into its dict as arrays.
fn route_arrays(d: &Bound<'_, PyDict>, c: sandslope_request::plan::RouteCells) -> PyResult<()> {
    put(d, "rows", c.rows)?;
    put(d, "cols", c.cols)?;
    put(d, "x_m", c.x_m)?;
    put(d, "y_m", c.y_m)?;
    put(d, "z_m", c.z_m)?;
    let steps = PyDict::new(d.py());
    put(&steps, "heading_deg", c.heading_deg)?;
    put(&steps, "pitch_deg", c.pitch_deg)?;
    put(&steps, "roll_deg", c.roll_deg)?;
    put(&steps, "length_m", c.length_m)?;
    put(&steps, "regime", c.regime)?;
    put(&steps, "speed_m_s", c.speed_m_s)?;
    put(&steps, "p_fail", c.p_fail)?;
    put(&steps, "over_roll_limit", c.over_roll_limit)?;
    d.set_item("steps", steps)
}

/// The GDAL_NODATA value of a GeoTIFF (None when it has none), read from its tags only, as
/// `read_raster` honours it (the Dask raster reads windows itself and marks the same cells).
#[pyfunction]
pub fn geotiff_nodata(path: PathBuf) -> PyResult<Option<f64>> {
    sandslope_raster::geotiff_nodata(&path).map_err(crate::anyhow_error)
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
