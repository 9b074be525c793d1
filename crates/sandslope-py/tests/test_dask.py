"""The Dask risk raster equals the eager one whatever the chunking, on worker processes."""

from pathlib import Path

import numpy as np
import pytest

import sandslope

da = pytest.importorskip("dask.array")
distributed = pytest.importorskip("distributed")
import sandslope.dask as sdask  # noqa: E402


def dunes(rows, cols, seed=3):
    """A rough dune field (m) with a few nodata holes, on 0.5 m cells."""
    y, x = np.mgrid[0:rows, 0:cols] * 0.5
    rng = np.random.default_rng(seed)
    z = np.sin(x / 6.0) * np.cos(y / 9.0) + 0.2 * x + rng.normal(0, 0.02, (rows, cols))
    z[rng.integers(0, rows, 6), rng.integers(0, cols, 6)] = np.nan
    return z


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as c:
            yield c


def test_same_values_on_a_cluster_whatever_the_chunks(client, robot, terrain):
    z = dunes(61, 47)
    eager = sandslope.risk_raster(z, 0.5, robot=robot, terrain=terrain)
    assert np.isfinite(eager[0]).sum() > 1500 and np.isfinite(eager[1]).sum() > 100
    # Chunks that do not divide the map (23 x 19 leaves 15 x 9; 30 x 46 leaves 1 x 1).
    for chunks in [(23, 19), (30, 46)]:
        lazy = sdask.risk_raster(da.from_array(z, chunks=chunks), 0.5, robot=robot, terrain=terrain)
        assert lazy.shape == (2, 61, 47) and lazy.dtype == np.float32
        assert lazy.chunks[1:] == da.from_array(z, chunks=chunks).chunks
        got = client.compute(lazy).result()
        np.testing.assert_array_equal(got, eager, err_msg=f"chunks {chunks}")


def test_options_and_errors_pass_through(robot, terrain):
    z = dunes(20, 20)
    kw = dict(robot=robot, terrain=terrain, cv_n=0.3, cv_s=0.1, max_roll_deg=12, allow_metastable=True)
    eager = sandslope.risk_raster(z, (0.5, 0.4), **kw)
    lazy = sdask.risk_raster(da.from_array(z, chunks=11), (0.5, 0.4), **kw)
    np.testing.assert_array_equal(lazy.compute(scheduler="threads"), eager)
    # Bad options fail at once, not inside a worker.
    with pytest.raises(ValueError, match="max_roll_deg = 0 must be"):
        sdask.risk_raster(da.from_array(z, chunks=7), 0.5, robot=robot, terrain=terrain, max_roll_deg=0)


def test_rows_of_different_widths_give_the_eager_values_tile_by_tile(robot, terrain, tmp_path):
    """Issue 24: on a geographic DEM every row has its own east-west cell size; each tile takes
    its rows' (and its halo's), so chunks cut across rows or not, and a .npy store read
    window by window, give the eager raster exactly."""
    z = dunes(61, 47)
    widths = np.linspace(0.6, 0.4, 61)
    eager = sandslope.risk_raster(z, 0.5, robot=robot, terrain=terrain, row_widths_m=widths)
    assert not np.array_equal(eager, sandslope.risk_raster(z, 0.5, robot=robot, terrain=terrain), equal_nan=True)
    for chunks in [(23, 19), (1, 47), (61, 10)]:
        lazy = sdask.risk_raster(da.from_array(z, chunks=chunks), 0.5, robot=robot, terrain=terrain,
                                 row_widths_m=widths)
        np.testing.assert_array_equal(lazy.compute(scheduler="threads"), eager, err_msg=f"chunks {chunks}")
    np.save(tmp_path / "dem.npy", z)
    lazy = sdask.risk_raster(tmp_path / "dem.npy", 0.5, robot=robot, terrain=terrain, row_widths_m=widths,
                             chunks=(16, 20))
    np.testing.assert_array_equal(lazy.compute(scheduler="sync"), eager)
    with pytest.raises(ValueError, match="row_widths_m must hold one finite width greater than 0 .* 60 values for 61 rows"):
        sdask.risk_raster(da.from_array(z, chunks=20), 0.5, robot=robot, terrain=terrain, row_widths_m=widths[1:])


def test_stores_are_read_tile_by_tile_with_the_same_values(client, robot, terrain, tmp_path):
    """A .npy, a tiled and compressed GeoTIFF with a GDAL_NODATA tag, and a .zarr array, each
    read window by window on worker processes, give the eager raster exactly."""
    tifffile = pytest.importorskip("tifffile")
    zarr = pytest.importorskip("zarr")
    z = dunes(61, 47)
    eager = sandslope.risk_raster(z, 0.5, robot=robot, terrain=terrain)
    np.save(tmp_path / "dem.npy", z)
    # GeoTIFFs mark holes with a nodata number, not NaN; the tag says which.
    tifffile.imwrite(tmp_path / "dem.tif", np.where(np.isnan(z), -9999.0, z), tile=(16, 16),
                     compression="zlib", extratags=[(42113, "s", 0, "-9999", True)])
    stored = zarr.open_array(str(tmp_path / "dem.zarr"), mode="w", shape=z.shape, chunks=(20, 20), dtype="f8")
    stored[:] = z
    for source in [tmp_path / "dem.npy", str(tmp_path / "dem.tif"), str(tmp_path / "dem.zarr")]:
        for chunks in [(23, 19), (30, 46), None]:
            lazy = sdask.risk_raster(source, 0.5, robot=robot, terrain=terrain, chunks=chunks)
            assert lazy.shape == (2, 61, 47) and lazy.dtype == np.float32
            got = client.compute(lazy).result()
            np.testing.assert_array_equal(got, eager, err_msg=f"{source}, chunks {chunks}")
    # Without chunks a store is tiled as it is stored.
    assert sdask.risk_raster(str(tmp_path / "dem.zarr"), 0.5, robot=robot, terrain=terrain).chunks[1:] == \
        ((20, 20, 20, 1), (20, 20, 7))


class CountingStore:
    """An array-like that records the size of every read."""

    def __init__(self, z):
        self.z, self.shape, self.dtype, self.ndim, self.reads = z, z.shape, z.dtype, z.ndim, []

    def __getitem__(self, index):
        out = self.z[index]
        self.reads.append(out.shape)
        return out


def test_each_tile_reads_only_its_window(robot, terrain):
    """Tiles depend on no other task: each reads its own tile and one-cell halo, once."""
    z = dunes(50, 41)
    store = CountingStore(z)
    lazy = sdask.risk_raster(store, 0.5, robot=robot, terrain=terrain, chunks=(16, 12))
    # One task per tile, and nothing else in the graph.
    assert len(dict(lazy.__dask_graph__())) == lazy.npartitions == 4 * 4
    np.testing.assert_array_equal(lazy.compute(scheduler="sync"),
                                  sandslope.risk_raster(z, 0.5, robot=robot, terrain=terrain))
    assert len(store.reads) == 16
    assert max(r * c for r, c in store.reads) <= (16 + 2) * (12 + 2)
    # Corner tiles have no halo beyond the map: 17 x 13 cells.
    assert (17, 13) in store.reads


def test_bad_chunks_name_the_argument_and_the_valid_form(robot, terrain, tmp_path):
    np.save(tmp_path / "dem.npy", dunes(30, 20))
    for source in [tmp_path / "dem.npy", dunes(30, 20)]:
        for chunks in [0, -5, (10, 0), 2.5, (10,)]:
            with pytest.raises(ValueError, match=r"chunks = .* must be a tile size in cells of at least 1"):
                sdask.risk_raster(source, 0.5, robot=robot, terrain=terrain, chunks=chunks)


def test_store_errors_name_the_source(robot, terrain, tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.npy'?: no such file"):
        sdask.risk_raster(tmp_path / "nope.npy", 0.5, robot=robot, terrain=terrain)
    np.save(tmp_path / "cube.npy", np.zeros((2, 3, 4)))
    with pytest.raises(ValueError, match=r"2-D array .*got shape \(2, 3, 4\)"):
        sdask.risk_raster(tmp_path / "cube.npy", 0.5, robot=robot, terrain=terrain)


def test_npy_windows_in_any_layout(tmp_path):
    """The .npy reader gives exactly NumPy's slice: C and Fortran order, other dtypes, edges."""
    z = dunes(37, 29)
    for name, a in [("c", z), ("f", np.asfortranarray(z)), ("i", (np.nan_to_num(z) * 100).astype(np.int32)),
                    ("be", z.astype(">f4"))]:
        np.save(tmp_path / f"{name}.npy", a)
        for top, bottom, left, right in [(0, 37, 0, 29), (5, 6, 0, 1), (10, 30, 3, 29), (36, 37, 28, 29)]:
            got = sdask._read_window(tmp_path / f"{name}.npy", top, bottom, left, right)
            np.testing.assert_array_equal(got, a[top:bottom, left:right], err_msg=name)
    (tmp_path / "text.npy").write_text("not an array")
    with pytest.raises(ValueError, match="text.npy'?: not a .npy file"):
        sdask.risk_raster(tmp_path / "text.npy", 0.5, robot=sandslope.Robot.preset("paper-hexapod"),
                          terrain=sandslope.Terrain.preset("glass-beads-300um"))


@pytest.mark.filterwarnings("ignore::UserWarning")  # zarr and xarray on deliberately odd chunks
def test_dask_arrays_that_only_read_a_store_are_read_as_the_store(robot, terrain, tmp_path):
    """da.from_array on a lazy array-like, da.from_zarr and xarray's dask arrays read windows
    from their source in their own chunks (one task per tile); a computed array does not."""
    z = dunes(50, 41)
    eager = sandslope.risk_raster(z, 0.5, robot=robot, terrain=terrain)
    store = CountingStore(z)
    lazy = sdask.risk_raster(da.from_array(store, chunks=(16, 12)), 0.5, robot=robot, terrain=terrain)
    assert lazy.chunks[1:] == ((16, 16, 16, 2), (12, 12, 12, 5))
    assert len(dict(lazy.__dask_graph__())) == lazy.npartitions
    np.testing.assert_array_equal(lazy.compute(scheduler="sync"), eager)
    assert max(r * c for r, c in store.reads) <= (16 + 2) * (12 + 2)

    zarr = pytest.importorskip("zarr")
    stored = zarr.open_array(str(tmp_path / "dem.zarr"), mode="w", shape=z.shape, chunks=(20, 20), dtype="f8")
    stored[:] = z
    lazy = sdask.risk_raster(da.from_zarr(str(tmp_path / "dem.zarr")), 0.5, robot=robot, terrain=terrain)
    assert len(dict(lazy.__dask_graph__())) == lazy.npartitions == 9
    np.testing.assert_array_equal(lazy.compute(scheduler="sync"), eager)
    # Anything computed goes through the halo exchange: more tasks than tiles.
    computed = sdask.risk_raster(da.from_zarr(str(tmp_path / "dem.zarr")) * 1.0, 0.5, robot=robot, terrain=terrain)
    assert len(dict(computed.__dask_graph__())) > computed.npartitions
    np.testing.assert_array_equal(computed.compute(scheduler="sync"), eager)

    xr = pytest.importorskip("xarray")
    xr.Dataset({"z": (("y", "x"), z)}).to_zarr(str(tmp_path / "xr.zarr"), mode="w")
    opened = xr.open_zarr(str(tmp_path / "xr.zarr"), chunks={"y": 30, "x": 17})["z"].data
    lazy = sdask.risk_raster(opened, 0.5, robot=robot, terrain=terrain)
    assert len(dict(lazy.__dask_graph__())) == lazy.npartitions == 2 * 3
    np.testing.assert_array_equal(lazy.compute(scheduler="sync"), eager)


PDS3 = Path(__file__).resolve().parents[2] / "sandslope-io" / "tests" / "fixtures" / "pds3"


def test_pds3_dtms_are_read_window_by_window(client, robot, terrain, tmp_path):
    """Issue 24: PDS3 DTMs as HiRISE publishes them (attached label, PC_REAL, ISIS special
    pixels; a detached .lbl) through the Dask raster give exactly the eager raster of
    read_raster's heights, on worker processes, whatever the tiles, with the label's ground
    cell size when cell_size_m is None; each window holds read_raster's heights there."""
    for name in ["dtm-attached.img", "dtm-detached.lbl"]:
        path = PDS3 / name
        heights, geo = sandslope.read_raster(path)
        rows, cols = heights.shape
        assert np.isnan(heights).any() or name != "dtm-attached.img"  # its special pixels
        window = sandslope._sandslope.pds3_window(str(path), 2, rows - 1, 3, cols)
        np.testing.assert_array_equal(window, heights[2 : rows - 1, 3:cols])
        # An equirectangular DTM's rows each have their width (the polar one's are alike).
        assert (geo["row_widths_m"] is None) == (name == "dtm-detached.lbl")
        eager = sandslope.risk_raster(heights, (geo["cell_x_m"], geo["cell_y_m"]), robot=robot, terrain=terrain,
                                      row_widths_m=geo["row_widths_m"])
        assert np.isfinite(eager[0]).sum() > rows * cols // 2
        for chunks in [(7, 9), (rows, cols)]:
            lazy = sdask.risk_raster(path, None, robot=robot, terrain=terrain, chunks=chunks)
            np.testing.assert_array_equal(client.compute(lazy).result(), eager, err_msg=f"{name} {chunks}")
    # Errors name the file and what is wrong, at once on the client.
    with pytest.raises(ValueError, match="cell_size_m = None takes the cell size from a PDS3"):
        sdask.risk_raster(tmp_path / "dem.npy", None, robot=robot, terrain=terrain)
    cut = tmp_path / "cut.img"
    cut.write_bytes((PDS3 / "dtm-attached.img").read_bytes()[:-100])
    with pytest.raises(ValueError, match=r"cut.img: LINES = \d+ lines .* the label claims more than the file holds"):
        sdask.risk_raster(cut, 20.0, robot=robot, terrain=terrain)
