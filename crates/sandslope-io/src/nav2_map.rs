//! The planner's per-cell risk raster (docs/planning.md, `plan --risk-map`) for navigation
//! stacks (docs/bags.md): a Nav2 `map_server` pair (`.yaml` + `.pgm`) and, in an MCAP file,
//! a `nav_msgs/OccupancyGrid` with the routes as `nav_msgs/Path`, in the DEM's frame.
//!
//! The occupancy of a cell is its best-heading failure probability in percent,
//! `round(100 p_fail)` (0 to 100; -1 where the DEM has no value), so a costmap reads the risk
//! itself. The `.pgm` holds these numbers as its grey levels (Nav2's `mode: raw`, where a
//! pixel's value is the occupancy and 255 is unknown); row 0 of the image is the map's north
//! edge, as `map_server` expects, and the grid's row 0 its south edge, as `OccupancyGrid`
//! expects.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

use sandslope_bag::messages::{Header, MapMetaData, NavPath, OccupancyGrid, Point, Pose, PoseStamped, Time};
use sandslope_files::{write_output, WriteError};
use sandslope_raster::Raster;

/// The frame the maps are in (the DEM's projected coordinates, metres).
pub const MAP_FRAME: &str = "map";

/// A cell's occupancy: `round(100 p_fail)`, -1 for no value.
pub fn occupancy(p_fail: f64) -> i8 {
    if p_fail.is_finite() {
        (100.0 * p_fail.clamp(0.0, 1.0)).round() as i8
    } else {
        -1
    }
}

/// The map's geometry in metres: (resolution, west, south, metres per map unit). Nav2 and
/// `OccupancyGrid` need square cells of one size on a projected map.
fn geometry(dem: &Raster) -> Result<(f64, f64, f64, f64)> {
    if dem.crs.is_geographic() || dem.row_widths_m.is_some() {
        bail!(
            "a Nav2 map or OccupancyGrid needs a projected DEM (cells of one size in metres); this one is in \
             degrees: reproject it first (gdalwarp -t_srs EPSG:326xx for UTM)"
        );
    }
    let (cx, cy) = dem.cell_m;
    if (cx - cy).abs() > 1e-6 * cx.max(cy) {
        bail!(
            "a Nav2 map or OccupancyGrid needs square cells; this DEM's are {cx} m by {cy} m (resample it: \
             gdalwarp -tr)"
        );
    }
    let per_unit = cx / dem.geo.cell_x;
    let south = dem.geo.north - dem.rows as f64 * dem.geo.cell_y;
    Ok((cx, dem.geo.west * per_unit, south * per_unit, per_unit))
}

/// The `.pgm` beside a `.yaml`.
pub fn pgm_path(yaml: &Path) -> PathBuf {
    yaml.with_extension("pgm")
}

/// Writes `yaml` and the `.pgm` beside it (same stem) from the planner's p_fail raster
/// (`dem.cols` x `dem.rows`, row 0 north).
pub fn write_nav2_map(yaml: &Path, dem: &Raster, p_fail: &[f32]) -> Result<()> {
    let (resolution, west, south, _) = geometry(dem)?;
    let pgm = pgm_path(yaml);
    let image = pgm.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut bytes = format!(
        "P5\n# sandslope plan --risk-map: 100 p_fail per cell, 255 no value\n{} {}\n255\n",
        dem.cols, dem.rows
    )
    .into_bytes();
    bytes.extend(p_fail.iter().map(|&p| match occupancy(f64::from(p)) {
        -1 => 255u8,
        v => v as u8,
    }));
    let text = format!(
        "# Nav2 map_server map from `sandslope plan --risk-map` (docs/bags.md): each pixel is the cell's\n\
         # best-heading failure probability in percent (mode raw; 255: no value). occupied_thresh is\n\
         # docs/model.md \u{a7}9's acceptable failure probability ({max_risk}); raw mode does not use the thresholds.\n\
         image: {image}\nmode: raw\nresolution: {resolution}\norigin: [{west}, {south}, 0.0]\nnegate: 0\n\
         occupied_thresh: {max_risk}\nfree_thresh: 0.0\n",
        max_risk = sandslope::risk::DEFAULT_MAX_RISK
    );
    write_output(&pgm, |out| {
        out.write_all(&bytes).map_err(|source| WriteError { path: pgm.clone(), source }.into())
    })?;
    write_output(yaml, |out| {
        out.write_all(text.as_bytes())
            .map_err(|source| WriteError { path: yaml.to_path_buf(), source }.into())
    })
}

/// The risk raster as a `nav_msgs/OccupancyGrid` on `/sandslope/risk_map` in [`MAP_FRAME`]
/// (row 0 south) and each route found as a `nav_msgs/Path` of its cell centres on
/// `/sandslope/route/<objective>`, written to an MCAP file at time 0.
pub fn write_map_mcap(
    path: &Path,
    dem: &Raster,
    p_fail: &[f32],
    routes: &crate::routes::Routes,
) -> Result<()> {
    let (resolution, west, south, per_unit) = geometry(dem)?;
    let mut data = Vec::with_capacity(p_fail.len());
    for row in (0..dem.rows).rev() {
        data.extend(p_fail[row * dem.cols..(row + 1) * dem.cols].iter().map(|&p| occupancy(f64::from(p))));
    }
    let header = Header { stamp: Time::default(), frame_id: MAP_FRAME.into() };
    let grid = OccupancyGrid {
        header: header.clone(),
        info: MapMetaData {
            map_load_time: Time::default(),
            resolution: resolution as f32,
            width: dem.cols as u32,
            height: dem.rows as u32,
            origin: Pose { position: Point { x: west, y: south, z: 0.0 }, ..Pose::default() },
        },
        data,
    };
    let mut out = crate::mcap_out::McapOut::new()?;
    out.write("/sandslope/risk_map", 0, &grid)?;
    for (objective, route) in routes {
        let Ok(route) = route else { continue };
        let poses = route
            .cells
            .iter()
            .map(|c| {
                let (x, y) = dem.geo.centre(c.col, c.row);
                PoseStamped {
                    header: header.clone(),
                    pose: Pose {
                        position: Point { x: x * per_unit, y: y * per_unit, z: 0.0 },
                        ..Pose::default()
                    },
                }
            })
            .collect();
        let topic = format!(
            "/sandslope/route/{}",
            objective.name().replace(|c: char| !c.is_ascii_alphanumeric(), "_")
        );
        out.write(&topic, 0, &NavPath { header: header.clone(), poses })?;
    }
    let bytes = out.finish()?;
    sandslope_files::write_atomic(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn occupancy_is_the_risk_in_percent() {
        assert_eq!(occupancy(0.0), 0);
        assert_eq!(occupancy(0.054), 5);
        assert_eq!(occupancy(1.0), 100);
        assert_eq!(occupancy(f64::NAN), -1);
    }
}
