"""The Dask risk raster equals the eager one whatever the chunking, on worker processes."""

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
