"""Risk rasters for elevation models larger than memory, tile by tile with Dask.

Needs the ``dask`` extra: ``pip install "crates/sandslope-py[dask]"``.

:func:`risk_raster` gives exactly the values of the eager :func:`sandslope.risk_raster` for
any chunking: each cell's gradient is Horn's 3 x 3 finite difference, so every tile is
computed with a halo of one cell from its neighbours (``dask.array.overlap``), and the map's
outer border is padded with NaN (nodata), which leaves border cells without a gradient
exactly as in the eager raster. Only the interior of each padded tile is kept.

Each task holds one padded tile and its two output bands (about 30 bytes per cell of the tile
at its peak), so memory per worker is bounded by a few chunks, not by the DEM. The pitch
table (the model at every pitch and its failure probability every 0.1 degree) is rebuilt per
tile; it depends only on the robot and terrain, so tiles agree with each other and with the
eager raster.
"""

from __future__ import annotations

from typing import Any, Optional

import dask.array as da
import numpy as np

from . import _cell_size, _robot, _terrain
from . import risk_raster as _eager_risk_raster

__all__ = ["risk_raster"]


def _tile(block: np.ndarray, cell_x: float, cell_y: float, options: dict) -> np.ndarray:
    """The two bands of one tile padded by one cell on every side, without the padding."""
    bands = _eager_risk_raster(block, (cell_x, cell_y), **options)
    return bands[:, 1:-1, 1:-1]


def risk_raster(
    dem: Any,
    cell_size_m: Any,
    *,
    robot: Any,
    terrain: Any,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
    max_roll_deg: float = 20.0,
    descent: str = "symmetric",
    allow_metastable: bool = False,
    nodata: Optional[float] = None,
) -> da.Array:
    """Lazy ``(2, H, W)`` float32 dask array: the two bands of :func:`sandslope.risk_raster`
    (best-heading P(failure), steepest usable climb azimuth) for a 2-D dask (or NumPy) DEM,
    chunked like the DEM in its two dimensions.

    Same arguments and the same values as the eager function, whatever the chunking,
    including at chunk seams and on the map border. Robot and terrain are checked here, at
    once; they are pickled to the workers, so this runs on a ``dask.distributed`` cluster of
    worker processes. Call ``.compute()`` (or ``da.to_zarr``, ``.store``) to evaluate.
    """
    z = da.asarray(dem)
    if z.ndim != 2:
        raise ValueError(f"dem must be a 2-D array (rows, cols), row 0 at the north (got shape {z.shape})")
    cx, cy = _cell_size(cell_size_m)
    options = dict(
        robot=_robot(robot),
        terrain=_terrain(terrain),
        cv_n=cv_n,
        cv_s=cv_s,
        max_roll_deg=max_roll_deg,
        descent=descent,
        allow_metastable=allow_metastable,
        nodata=nodata,
    )
    # Fail now, not inside a worker: the same checks on a tiny map.
    _eager_risk_raster(np.zeros((3, 3)), (cx, cy), **options)
    if not np.issubdtype(z.dtype, np.floating):
        z = z.astype(np.float64)  # room for the NaN padding
    padded = da.overlap.overlap(z, depth={0: 1, 1: 1}, boundary={0: np.nan, 1: np.nan})
    return padded.map_blocks(
        _tile,
        cx,
        cy,
        options,
        dtype=np.float32,
        chunks=((2,),) + z.chunks,
        new_axis=0,
        meta=np.empty((0, 0, 0), dtype=np.float32),
        token="sandslope-risk-raster",
    )
