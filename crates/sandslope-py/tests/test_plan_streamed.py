"""Issue 56: `plan --risk-map` with the corridor search writes the risk raster band by band as a
tiled GeoTIFF; GDAL (through rasterio) reads it as the in-memory raster, bit for bit: the one
`--search full` writes and the one `risk_raster` computes. Skipped where rasterio is not
installed (scripts/test.sh installs it)."""

import numpy as np
import pytest

import sandslope

rasterio = pytest.importorskip("rasterio")

DUNE = "examples/planning/dune.asc"


def test_the_streamed_risk_map_reads_in_gdal_as_the_in_memory_one(cli, robot, terrain, root, tmp_path):
    streamed, full = tmp_path / "streamed.tif", tmp_path / "full.tif"
    common = ["plan", "--dem", DUNE, "--start-px", "100,150", "--goal-px", "100,50", "--coarse-factor", "2"]
    cli.run(*common, "--search", "corridor", "--risk-map", streamed)
    cli.run(*common, "--search", "full", "--risk-map", full)
    with rasterio.open(streamed) as s, rasterio.open(full) as f:
        assert s.count == 2 and s.dtypes == ("float32", "float32")
        assert s.block_shapes == [(256, 256), (256, 256)]
        assert s.profile["compress"] == "deflate"
        assert s.transform == f.transform and s.width == f.width == 200 and s.height == f.height == 200
        assert np.isnan(s.nodata)
        got, want = s.read(), f.read()
        # A window read by GDAL through the tiles is the same window of the whole.
        window = s.read(window=rasterio.windows.Window(37, 91, 120, 64))
    np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32))
    np.testing.assert_array_equal(window.view(np.uint32), got[:, 91:155, 37:157].view(np.uint32))
    z, _ = sandslope.read_raster(root / DUNE)
    mem = sandslope.risk_raster(z, 0.3, robot=robot, terrain=terrain)
    np.testing.assert_array_equal(got.view(np.uint32), mem.view(np.uint32))
    assert np.isfinite(got[0, 1:-1, 1:-1]).mean() > 0.9
