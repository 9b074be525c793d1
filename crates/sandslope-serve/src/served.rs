//! What the server was started with ([`Served`]: the robot, terrain and DEM requests fall back
//! on) and what the page is told of the DEM ([`DemInfo`]), read once at start.

use std::path::PathBuf;

use serde::Serialize;

/// Most cells sent for the DEM and its risk raster; a larger DEM is sent every `stride`-th
/// cell in each direction.
pub const MAX_DISPLAY_CELLS: usize = 1 << 20;

/// The files the server was started with; requests that name none use these.
#[derive(Debug, Clone)]
pub struct Served {
    /// `--robot` of `serve`: a file or a preset.
    pub robot: String,
    /// `--terrain` of `serve`: a file or a preset.
    pub terrain: String,
    /// `--dem` of `serve`, the only elevation model `/api/plan` uses.
    pub dem: Option<PathBuf>,
    /// The DEM's size and georeference, read at start.
    pub dem_info: Option<DemInfo>,
}

impl Served {
    /// Reads everything the server will use now, so a bad file fails at start, not per request.
    pub fn load(robot: String, terrain: String, dem: Option<PathBuf>) -> anyhow::Result<Served> {
        use anyhow::Context;
        use sandslope_request::scenario::{ROBOT, TERRAIN};
        sandslope_io::load_robot(&robot).with_context(|| ROBOT.long())?;
        sandslope_io::load_terrain(&terrain).with_context(|| TERRAIN.long())?;
        let dem_info = match &dem {
            Some(path) => Some(DemInfo::of(&sandslope_raster::read_raster(path)?)),
            None => None,
        };
        Ok(Served { robot, terrain, dem, dem_info })
    }
}

/// The served DEM's size and georeference, read once when the server starts.
#[derive(Debug, Clone, Serialize)]
pub struct DemInfo {
    cols: usize,
    rows: usize,
    /// Cell size in map units (degrees for a geographic DEM).
    cell_x: f64,
    cell_y: f64,
    /// Ground size of a cell, metres (for the hillshade).
    cell_x_m: f64,
    cell_y_m: f64,
    west: f64,
    north: f64,
    /// Every how many cells the page is sent.
    stride: usize,
}

impl DemInfo {
    /// What the page is told about this DEM.
    pub fn of(r: &sandslope_raster::Raster) -> DemInfo {
        DemInfo {
            cols: r.cols,
            rows: r.rows,
            cell_x: r.geo.cell_x,
            cell_y: r.geo.cell_y,
            cell_x_m: r.cell_m.0,
            cell_y_m: r.cell_m.1,
            west: r.geo.west,
            north: r.geo.north,
            stride: stride(r.cols, r.rows),
        }
    }
}

/// Every how many cells the page is sent for a DEM of this size.
pub fn stride(cols: usize, rows: usize) -> usize {
    let cells = cols * rows;
    let mut s = 1;
    while cells.div_ceil(s * s) > MAX_DISPLAY_CELLS {
        s += 1;
    }
    s
}
