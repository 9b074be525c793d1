//! The raster value every reader returns ([`Raster`], georeferenced by [`GeoRef`]) and the
//! size limits every reader checks before allocating, apart from the format dispatcher
//! ([`super`]) so that readers of each format (GeoTIFF, ASCII grid, PDS3) depend on it alone.

use anyhow::{bail, Result};

use crate::crs::Crs;

/// The memory a raster read may take, bytes: set by the front end ([`set_memory_limit`], from
/// `--max-memory`), else three quarters of what the machine has available when asked
/// (`MemAvailable` in /proc/meminfo), else 4 GiB (the old 2^29 cells of 8 bytes) where that
/// cannot be read. The size a file claims is checked against it before anything of that size
/// is allocated, so a small file that claims a huge image is refused at once instead of
/// exhausting memory, and a large DEM is refused naming what it would need.
pub fn memory_limit() -> (u64, &'static str) {
    let set = MEMORY_LIMIT.with(std::cell::Cell::get);
    if set != 0 {
        return (set, "the --max-memory limit");
    }
    match available_memory() {
        Some(bytes) => (
            bytes / 4 * 3,
            "three quarters of the memory available (MemAvailable in /proc/meminfo; --max-memory sets another limit)",
        ),
        None => (DEFAULT_MEMORY_LIMIT, "the default limit (the machine's memory cannot be read)"),
    }
}

/// The memory limit where the machine's cannot be read: 4 GiB.
pub const DEFAULT_MEMORY_LIMIT: u64 = 4 << 30;

thread_local! {
    /// The limit set on this thread, bytes (0: none set).
    static MEMORY_LIMIT: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Sets the memory limit of the raster reads made on the calling thread ([`memory_limit`]),
/// in bytes (`None`: back to the machine's available memory). Per thread, so that a server or
/// a test suite reading on several threads keeps each request's own limit.
pub fn set_memory_limit(bytes: Option<u64>) {
    MEMORY_LIMIT.with(|m| m.set(bytes.map_or(0, |b| b.max(1))));
}

/// The memory the kernel says is available for new allocations (MemAvailable), in bytes;
/// `None` where /proc/meminfo cannot be read (not Linux).
pub fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb.saturating_mul(1024))
}

/// Refuses a `cols` x `rows` raster whose read would hold more than [`memory_limit`] bytes at
/// `bytes_per_cell` bytes a cell, naming the file, what it needs and the limit.
pub(crate) fn check_raster_size(
    name: &dyn std::fmt::Display,
    cols: u64,
    rows: u64,
    bytes_per_cell: u64,
) -> Result<()> {
    let cells = cols.saturating_mul(rows);
    let need = cells.saturating_mul(bytes_per_cell);
    let (limit, what) = memory_limit();
    if need > limit {
        let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
        bail!(
            "{name}: {cols} x {rows} = {cells} cells need {:.3} GiB to read ({bytes_per_cell} bytes a cell), more \
             than {what} of {:.3} GiB; crop or resample the raster (for example with gdal_translate -srcwin or -tr), \
             or give a larger --max-memory",
            gib(need),
            gib(limit)
        );
    }
    Ok(())
}

/// Where a raster sits on the map: the north-west corner of its north-west cell and the cell
/// size (x east, y north). Plus the raw GeoTIFF georeferencing tags, copied to outputs.
#[derive(Debug, Clone, PartialEq)]
pub struct GeoRef {
    /// Map x of the western edge of column 0.
    pub west: f64,
    /// Map y of the northern edge of row 0.
    pub north: f64,
    /// Cell width, map units.
    pub cell_x: f64,
    /// Cell height, map units.
    pub cell_y: f64,
    /// GeoKeyDirectory, GeoDoubleParams, GeoAsciiParams of the source, if any.
    pub geokeys: Option<Vec<u16>>,
    pub(crate) geodoubles: Option<Vec<f64>>,
    pub(crate) geoascii: Option<String>,
}

impl GeoRef {
    /// A north-up raster's georeferencing with the GeoTIFF keys that describe its CRS (a PDS3
    /// map's, for instance), copied to the GeoTIFFs written over it.
    pub(crate) fn north_up(
        (west, north, cell_x, cell_y): (f64, f64, f64, f64),
        geokeys: Vec<u16>,
        geodoubles: Vec<f64>,
        geoascii: String,
    ) -> GeoRef {
        GeoRef {
            west,
            north,
            cell_x,
            cell_y,
            geokeys: Some(geokeys),
            geodoubles: Some(geodoubles),
            geoascii: Some(geoascii),
        }
    }
    /// Map coordinates of the centre of (col, row).
    pub fn centre(&self, col: usize, row: usize) -> (f64, f64) {
        (self.west + (col as f64 + 0.5) * self.cell_x, self.north - (row as f64 + 0.5) * self.cell_y)
    }
    /// The (col, row) containing map point (x, y), as signed numbers (may be outside).
    pub fn cell_of(&self, x: f64, y: f64) -> (f64, f64) {
        (((x - self.west) / self.cell_x).floor(), ((self.north - y) / self.cell_y).floor())
    }
    /// Whether two rasters share cell size and origin (within a thousandth of a cell).
    pub fn aligned(&self, other: &GeoRef) -> bool {
        let tol = 1e-3 * self.cell_x.min(self.cell_y);
        (self.west - other.west).abs() < tol
            && (self.north - other.north).abs() < tol
            && (self.cell_x - other.cell_x).abs() < tol
            && (self.cell_y - other.cell_y).abs() < tol
    }
}

/// A single-band raster: values row-major from the north-west corner.
#[derive(Debug, Clone)]
pub struct Raster {
    /// Columns.
    pub cols: usize,
    /// Rows.
    pub rows: usize,
    /// Values (nodata cells hold the nodata value or NaN).
    pub values: Vec<f64>,
    /// The nodata value, if declared.
    pub nodata: Option<f64>,
    /// Georeferencing, in the file's own map units (degrees for a geographic CRS).
    pub geo: GeoRef,
    /// What the map coordinates are (crs.rs).
    pub crs: Crs,
    /// Ground size of a cell, metres (east, north): the cell size the planner uses (on a
    /// geographic raster the east-west size at the mid-latitude, the reference cell).
    pub cell_m: (f64, f64),
    /// East-west ground size of each row's cells, metres (row 0 at the north), where the rows
    /// differ (a geographic CRS): what the planner uses east-west instead of `cell_m.0`.
    pub row_widths_m: Option<Vec<f64>>,
    /// What was assumed or converted in reading (units, ellipsoid, the mid-latitude), for the
    /// front end to print as notes.
    pub notes: Vec<String>,
}

impl Raster {
    /// Whether cell `i` is nodata (the declared value, or not finite).
    pub fn is_nodata(&self, i: usize) -> bool {
        self.is_nodata_value(self.values[i])
    }

    /// Whether `v` is a nodata value here (the declared value, or not finite).
    pub fn is_nodata_value(&self, v: f64) -> bool {
        !v.is_finite() || self.nodata.is_some_and(|nd| v == nd || (nd.is_nan() && v.is_nan()))
    }
}

/// What a caller checks a raster's size against before its samples are read: `fits(cols,
/// rows)` fails to refuse the raster (for instance because what the caller would build on it
/// cannot fit in memory).
pub type SizeCheck<'a> = &'a dyn Fn(usize, usize) -> Result<()>;
