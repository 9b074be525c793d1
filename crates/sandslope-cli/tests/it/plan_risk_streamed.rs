//! `plan --risk-map` with the corridor search (issue 56): the risk raster computed band by band
//! from the heights read window by window and written as a tiled GeoTIFF holds the in-memory
//! planner's raster (`--search full`) bit for bit, on GDAL's tiled and striped GeoTIFFs, a
//! geographic DEM (rows of different widths), a PDS3 DTM and an ASCII grid; a DEM whose tiles
//! lie past the end of the file is refused naming the offset, leaving no risk map.

use std::fs::File;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use tiff::decoder::{ChunkType, Decoder, DecodingResult};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn fixture(name: &str) -> PathBuf {
    repo().join("crates/sandslope-io/tests/fixtures").join(name)
}

/// `plan` on `dem` from `start` to `goal` by `search`, writing the risk map to `out`.
fn plan(dem: &Path, start: &str, goal: &str, search: &str, out: &Path) -> std::process::Output {
    Command::cargo_bin("sandslope")
        .unwrap()
        .current_dir(repo())
        .arg("plan")
        .arg("--dem")
        .arg(dem)
        .args(["--start-px", start, "--goal-px", goal, "--search", search, "--coarse-factor", "2"])
        .arg("--risk-map")
        .arg(out)
        .output()
        .unwrap()
}

/// A written risk map's samples (band 1 and 2 interleaved) as bits, and whether it is tiled.
fn samples(path: &Path) -> (Vec<u32>, bool) {
    let mut dec = Decoder::new(File::open(path).unwrap()).unwrap();
    let tiled = dec.get_chunk_type() == ChunkType::Tile;
    let DecodingResult::F32(v) = dec.read_image().unwrap() else { panic!("{}: not float32", path.display()) };
    (v.into_iter().map(f32::to_bits).collect(), tiled)
}

#[test]
fn the_streamed_risk_map_is_the_full_planner_s_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    for (dem, start, goal) in [
        (fixture("gdal/bigtiff-deflate-tiled.tif"), "8,8", "50,40"),
        (fixture("gdal/geo-wgs84-lzw-pred3.tif"), "8,8", "50,40"),
        (fixture("gdal/i16-lzw-pred2-strips.tif"), "8,8", "30,20"),
        (fixture("pds3/dtm-detached.lbl"), "8,8", "30,20"),
        (repo().join("examples/planning/dune.asc"), "100,150", "100,50"),
    ] {
        let name = dem.file_name().unwrap().to_string_lossy().to_string();
        let (full, streamed) =
            (dir.path().join(format!("{name}.full.tif")), dir.path().join(format!("{name}.tif")));
        for (search, out) in [("full", &full), ("corridor", &streamed)] {
            let o = plan(&dem, start, goal, search, out);
            assert!(o.status.success(), "{name} {search}: {}", String::from_utf8_lossy(&o.stderr));
        }
        let ((want, _), (got, tiled)) = (samples(&full), samples(&streamed));
        assert!(tiled, "{name}: the streamed risk map is tiled");
        let finite = want.chunks(2).filter(|c| f32::from_bits(c[0]).is_finite()).count();
        assert!(finite > want.len() / 4, "{name}: {finite} cells with a risk");
        assert!(got == want, "{name}: the streamed risk map differs from the in-memory one");
    }
}

#[test]
fn a_dem_with_tiles_past_its_end_leaves_no_risk_map() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(fixture("gdal/bigtiff-deflate-tiled.tif")).unwrap();
    let dem = dir.path().join("cut.tif");
    std::fs::write(&dem, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let out = dir.path().join("risk.tif");
    let o = plan(&dem, "8,8", "50,40", "corridor", &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("cut.tif") && err.contains("past the end") && err.contains("at byte"), "{err}");
    assert!(!out.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "something was left behind");
}

#[test]
fn a_nav2_risk_map_still_needs_the_full_search() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("risk.yaml");
    let o = plan(&fixture("gdal/bigtiff-deflate-tiled.tif"), "8,8", "50,40", "corridor", &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--risk-map needs the full-resolution search"), "{err}");
}
