"""Risk rasters for elevation models larger than memory, tile by tile with Dask.

Needs the ``dask`` extra: ``pip install "crates/sandslope-py[dask]"``.

:func:`risk_raster` gives exactly the values of the eager :func:`sandslope.risk_raster` for
any chunking: each cell's gradient is Horn's 3 x 3 finite difference, so every tile is
computed with a halo of one cell from its neighbours, and the map's outer border is padded with
NaN (nodata), which leaves border cells without a gradient exactly as in the eager raster. Only
the interior of each padded tile is kept.

Where the heights come from decides the memory a worker needs:

* **A store** (a path to a ``.npy`` file, a GeoTIFF, a PDS3 DTM or a ``.zarr`` array, or an array-like
  such as a ``zarr.Array`` that slices lazily and pickles as a reference): each task reads its
  own tile and its one-cell halo straight from the store, computes, and lets go. Tiles depend
  on nothing else, so memory per worker is a few tiles, whatever the size of the DEM. This is
  the way to run a DEM larger than memory. A dask array that does nothing but read such a
  store (``da.from_zarr``, ``da.from_array`` on a zarr array) is read the same way, in its own
  chunks.
* **A dask array** computed by some other graph: the halos are cut from the neighbouring
  chunks (``dask.array.overlap``). Dask computes each chunk once and must keep it until its
  neighbours have taken their halos, so a worker holds about one row of chunks across the map:
  memory grows with the map's width in chunks (measured in docs/python.md). Store such a DEM
  first (``da.to_zarr``) when that is too much.

The planner's pitch table (the model at every pitch and its failure probability every 0.1
degree) depends only on the robot and terrain; each worker process builds it once and keeps it
for its next tiles (the first entries of a longer table are a shorter one's, bit for bit), so
tiles agree with each other and with the eager raster.
"""

from __future__ import annotations

import contextlib
import errno
import os
import sys
from typing import Any, Callable, Optional, Tuple, TypeVar

import dask.array as da
import numpy as np

from . import _sandslope
from ._inputs import _cell_size, _robot, _row_widths, _terrain
from . import risk_raster as _eager_risk_raster

__all__ = ["risk_raster"]

T = TypeVar("T")

#: Tile side for stores that do not say how they are chunked, cells (8 MiB of float64).
DEFAULT_TILE = 1024


def _tile(
    block: np.ndarray,
    cell_x: float,
    cell_y: float,
    options: dict,
    rows: Optional[Tuple[int, int]] = None,
    widths: Optional[np.ndarray] = None,
) -> np.ndarray:
    """The two bands of one tile padded by one cell on every side, without the padding.

    ``widths``: the map's east-west cell size of each row (m), of which the tile of map rows
    ``rows`` (``(top, bottom)``, without its halo) takes its own rows' and its halo rows'
    (beyond the map, the edge row's: those rows are NaN and their values dropped). A cell's
    values depend on its 3 x 3 window and its own row's width only, so every tile gives the
    eager raster's values."""
    if widths is not None and rows is not None:
        r0, r1 = rows
        halo = np.clip(np.arange(r0 - 1, r1 + 1), 0, len(widths) - 1)
        options = dict(options, row_widths_m=widths[halo])
    bands = _eager_risk_raster(block, (cell_x, cell_y), **options)
    return bands[:, 1:-1, 1:-1]


def _overlap_tile(
    block: np.ndarray,
    cell_x: float,
    cell_y: float,
    options: dict,
    widths: Optional[np.ndarray] = None,
    block_info: Optional[dict] = None,
) -> np.ndarray:
    """:func:`_tile` of a chunk cut with its halo by ``dask.array.overlap``."""
    rows = None
    if widths is not None:
        (_, _), (r0, r1), _ = block_info[None]["array-location"]
        rows = (r0, r1)
    return _tile(block, cell_x, cell_y, options, rows, widths)


def _npy_header(f: Any) -> Tuple[Tuple[int, ...], bool, np.dtype]:
    """Shape, Fortran order and dtype of an open ``.npy`` file, left at the first element."""
    version = np.lib.format.read_magic(f)
    if version == (1, 0):
        return np.lib.format.read_array_header_1_0(f)
    return np.lib.format.read_array_header_2_0(f)


def _read_npy_window(path: str, top: int, bottom: int, left: int, right: int) -> np.ndarray:
    """Rows ``top:bottom``, columns ``left:right`` of a 2-D ``.npy`` file, read row by row.

    Plain reads rather than a memory map: faulting in a mapped window maps whole neighbouring
    pages (fault-around), which on an 8192-wide float64 DEM made a 1024 x 1024 window cost
    74 MiB of resident memory instead of 8.
    """
    with open(path, "rb") as f:
        shape, fortran, dtype = _npy_header(f)
        if fortran or dtype.hasobject:
            return np.load(path, mmap_mode="r")[top:bottom, left:right]
        start, row_bytes, item = f.tell(), shape[1] * dtype.itemsize, dtype.itemsize
        out = np.empty((bottom - top, right - left), dtype=dtype)
        for i, r in enumerate(range(top, bottom)):
            f.seek(start + r * row_bytes + left * item)
            f.readinto(memoryview(out[i]).cast("B"))
        return out


def _zarr() -> Any:
    try:
        import zarr
    except ImportError as e:
        raise ValueError("reading .zarr and GeoTIFF DEMs tile by tile needs zarr: pip install zarr") from e
    return zarr


def _with_array(source: Any, use: Callable[[Any], T]) -> T:
    """Calls ``use`` on the array behind a source other than ``.npy``: a GeoTIFF path through
    ``tifffile``'s zarr view (which reads only the strips or tiles a window touches), a
    ``.zarr`` path, any other object as it is."""
    if not isinstance(source, (str, os.PathLike)):
        # A zarr array (or xarray over one) has imported zarr when it was unpickled here.
        zarr = sys.modules.get("zarr")
        with _one_chunk_at_a_time(zarr) if zarr is not None else contextlib.nullcontext():
            return use(source)
    path = os.fspath(source)
    zarr = _zarr()
    with _one_chunk_at_a_time(zarr):
        if path.lower().endswith((".tif", ".tiff")):
            import tifffile

            with tifffile.imread(path, aszarr=True) as store:
                return use(zarr.open(store, mode="r"))
        return use(zarr.open_array(path, mode="r"))


def _one_chunk_at_a_time(zarr: Any) -> Any:
    """zarr 3 decodes up to 10 chunks of a read at once; a window with its halo touches up to 9,
    so that held 146 MiB for a 1024 x 1024 float64 window, against 39 MiB one at a time."""
    config = getattr(zarr, "config", None)
    if config is not None and config.get("async.concurrency", None) is not None:
        return config.set({"async.concurrency": 1})
    return contextlib.nullcontext()


def _is_npy(source: Any) -> bool:
    return isinstance(source, (str, os.PathLike)) and os.fspath(source).lower().endswith(".npy")


def _is_pds3(source: Any) -> bool:
    """A path to a PDS3 DTM: an ``.img`` with its label attached or beside it, or its ``.lbl``."""
    return isinstance(source, (str, os.PathLike)) and os.fspath(source).lower().endswith((".img", ".lbl"))


def _read_window(source: Any, top: int, bottom: int, left: int, right: int) -> np.ndarray:
    """Rows ``top:bottom``, columns ``left:right`` of a store."""
    if _is_pds3(source):
        # Read by sandslope's own PDS3 reader (sample types, scaling, special pixels as NaN),
        # only the window's samples.
        return _sandslope.pds3_window(os.fspath(source), top, bottom, left, right)
    if _is_npy(source):
        return _read_npy_window(os.fspath(source), top, bottom, left, right)
    return _with_array(source, lambda a: np.asarray(a[top:bottom, left:right]))


def _window_tile(
    source: Any,
    shape: Tuple[int, int],
    cell_x: float,
    cell_y: float,
    options: dict,
    widths: Optional[np.ndarray] = None,
    block_info: Optional[dict] = None,
) -> np.ndarray:
    """Reads one tile and its one-cell halo from the store (NaN beyond the map) and returns
    its two bands."""
    (_, _), (r0, r1), (c0, c1) = block_info[None]["array-location"]
    rows, cols = shape
    top, bottom = max(r0 - 1, 0), min(r1 + 1, rows)
    left, right = max(c0 - 1, 0), min(c1 + 1, cols)
    padded = np.full((r1 - r0 + 2, c1 - c0 + 2), np.nan)
    window = _read_window(source, top, bottom, left, right)
    padded[top - (r0 - 1) : bottom - (r0 - 1), left - (c0 - 1) : right - (c0 - 1)] = window
    del window
    return _tile(padded, cell_x, cell_y, options, (r0, r1), widths)


def _tiles(chunks: Any, shape: Tuple[int, ...]) -> Tuple[Tuple[int, ...], ...]:
    """``chunks`` as dask's explicit block sizes for ``shape``, or a ValueError naming it."""
    message = f"chunks = {chunks!r} must be a tile size in cells of at least 1: an int, (rows, cols), or dask block sizes"
    if any(isinstance(c, (int, np.integer)) and not isinstance(c, bool) and c < 1 for c in np.ravel(np.array(chunks, dtype=object))):
        raise ValueError(message)
    try:
        return da.core.normalize_chunks(chunks, shape, dtype=np.float64)
    except (ValueError, TypeError, ZeroDivisionError) as e:
        raise ValueError(f"{message} ({e})") from e


def _is_store(dem: Any) -> bool:
    """A path, or an array-like that is neither NumPy nor dask and slices lazily."""
    if isinstance(dem, (str, os.PathLike)):
        return True
    if isinstance(dem, (da.Array, np.ndarray)):
        return False
    return hasattr(dem, "shape") and hasattr(dem, "__getitem__")


def _tiff_nodata(source: Any) -> Optional[float]:
    """The GDAL_NODATA tag of a GeoTIFF path, read by the same code as ``read_raster``."""
    if not (isinstance(source, (str, os.PathLike)) and os.fspath(source).lower().endswith((".tif", ".tiff"))):
        return None
    return _sandslope.geotiff_nodata(os.fspath(source))


def _store_behind(z: da.Array) -> Any:
    """The lazy array a dask array reads its chunks from, when it is nothing more than that
    (``da.from_zarr``, ``da.from_array`` on a zarr array, xarray or rioxarray opened with
    ``chunks=``): Dask keeps the source as the only key of an ``original-`` layer beside the
    layer of getters. ``None`` for anything computed, or held in memory."""
    layers = z.__dask_graph__().layers
    if len(layers) != 2:
        return None
    originals = [layer for name, layer in layers.items() if str(name).startswith("original-")]
    if len(originals) != 1 or len(originals[0]) != 1:
        return None
    (source,) = originals[0].values()
    source = getattr(source, "value", source)  # a task-spec DataNode in some Dask versions
    if isinstance(source, np.ndarray) or tuple(getattr(source, "shape", ())) != z.shape:
        return None
    return source if hasattr(source, "__getitem__") else None


def _store_shape(source: Any) -> Tuple[Tuple[int, int], Optional[Tuple[int, int]]]:
    """Shape and native chunks of a store, checked here, on the client."""
    if isinstance(source, (str, os.PathLike)) and not os.path.exists(source):
        raise FileNotFoundError(errno.ENOENT, f"dem = {os.fspath(source)!r}: no such file or folder", os.fspath(source))
    try:
        if _is_pds3(source):
            info = _sandslope.pds3_info(os.fspath(source))
            shape, native = (info["rows"], info["cols"]), None
        elif _is_npy(source):
            with open(source, "rb") as f:
                shape, native = _npy_header(f)[0], None
        else:
            shape, native = _with_array(source, lambda a: (tuple(getattr(a, "shape", ())), getattr(a, "chunks", None)))
    except ValueError as e:
        if _is_npy(source) and not _is_pds3(source):
            raise ValueError(f"dem = {os.fspath(source)!r}: not a .npy file: {e}") from e
        raise
    except Exception as e:  # a file that is not an array: the reader says why
        raise ValueError(f"dem = {source!r}: cannot be read as an array: {e}") from e
    if len(shape) != 2:
        raise ValueError(f"dem must be a 2-D array (rows, cols), row 0 at the north (got shape {shape})")
    if not (isinstance(native, tuple) and len(native) == 2 and all(isinstance(c, int) for c in native)):
        native = None
    return (int(shape[0]), int(shape[1])), native


def _pds3_cell_size(dem: Any, row_widths_m: Any) -> tuple:
    """``cell_size_m = None``: the cell size from a PDS3 DTM's label, and its row widths when
    none are given (an equirectangular DTM's rows narrow towards the pole)."""
    if not _is_pds3(dem):
        raise ValueError("cell_size_m = None takes the cell size from a PDS3 DTM's label; give it in metres for any other dem")
    if not os.path.exists(dem):
        raise FileNotFoundError(errno.ENOENT, f"dem = {os.fspath(dem)!r}: no such file or folder", os.fspath(dem))
    info = _sandslope.pds3_info(os.fspath(dem))
    return (info["cell_x_m"], info["cell_y_m"]), info["row_widths_m"] if row_widths_m is None else row_widths_m


def _check_widths(widths: Optional[np.ndarray], rows: int) -> None:
    """One finite, positive row width per row of the DEM, when widths are given."""
    if widths is not None and not (len(widths) == rows and np.all(np.isfinite(widths)) and np.all(widths > 0)):
        raise ValueError(
            f"row_widths_m must hold one finite width greater than 0 (m) per row of the dem: "
            f"{len(widths)} values for {rows} rows"
        )


def risk_raster(
    dem: Any,
    cell_size_m: Any,
    *,
    robot: Any,
    terrain: Any,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
    max_roll_deg: float = _sandslope.DEFAULT_MAX_ROLL_DEG,
    descent: str = "symmetric",
    allow_metastable: bool = False,
    nodata: Optional[float] = None,
    chunks: Any = None,
    row_widths_m: Any = None,
) -> da.Array:
    """Lazy ``(2, H, W)`` float32 dask array: the two bands of :func:`sandslope.risk_raster`
    (best-heading P(failure), steepest usable climb azimuth) for a 2-D DEM, row 0 at the north.

    ``dem`` is one of:

    * a path to a ``.npy`` file, a PDS3 DTM as HiRISE publishes them (``.img`` with its label
      attached or a ``.lbl`` beside it, or the ``.lbl``: read by sandslope's PDS3 reader, the
      same heights as :func:`sandslope.read_raster`), a GeoTIFF (``.tif``, read through
      ``tifffile``) or a ``.zarr`` array (both need ``zarr``), or an array-like that slices lazily and
      pickles cheaply (``zarr.Array``): each task reads its tile and one-cell halo from it, so
      memory per worker is bounded by a few tiles whatever the DEM's size;
    * a dask array that only reads a store (``da.from_zarr(path)``, ``da.from_array`` on a
      zarr array): read as that store, in the dask array's chunks;
    * any other dask array: halos are cut from neighbouring chunks, and a worker holds about a
      row of chunks (see the module's notes);
    * a NumPy array (in memory; chunked like a dask array).

    ``cell_size_m``: ground cell size in metres, one number or ``(cell_x, cell_y)``; ``None``
    for a PDS3 DTM takes the label's (as :func:`sandslope.read_raster` gives it in
    ``geo["cell_x_m"]``, ``geo["cell_y_m"]``: ``MAP_SCALE`` on the body's sphere, at the DTM's
    middle), and ``row_widths_m`` too when the DTM is equirectangular (its rows narrow
    towards the pole).

    ``row_widths_m``: on a geographic DEM, the east-west cell size of each row in metres, one
    per row of the whole DEM (:func:`sandslope.read_raster`'s ``geo["row_widths_m"]``), as the
    eager function takes it; each tile uses its own rows'.

    ``chunks``: tile shape (an int or ``(rows, cols)``, any form ``dask.array`` accepts);
    default: the dask array's chunks, a store's own chunks, or 1024 x 1024.

    Same other arguments and the same values as the eager function, whatever the chunking,
    including at chunk seams and on the map border. Robot and terrain are checked here, at once;
    they are pickled to the workers, so this runs on a ``dask.distributed`` cluster of worker
    processes (a store must then be readable from every worker: a path on a shared file
    system, or a zarr store the workers can reach). Call ``.compute()``, ``da.to_zarr`` or
    ``.store`` to evaluate.
    """
    if cell_size_m is None:
        cell_size_m, row_widths_m = _pds3_cell_size(dem, row_widths_m)
    cx, cy = _cell_size(cell_size_m)
    widths = None if row_widths_m is None else np.asarray(_row_widths(row_widths_m), dtype=np.float64)

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
    meta = np.empty((0, 0, 0), dtype=np.float32)

    if isinstance(dem, da.Array) and _store_behind(dem) is not None:
        # Read the source window by window, in the dask array's own tiles.
        if chunks is None:
            chunks = dem.chunks
        dem = _store_behind(dem)
    if not _is_store(dem):
        z = da.asarray(dem)
        if z.ndim != 2:
            raise ValueError(f"dem must be a 2-D array (rows, cols), row 0 at the north (got shape {z.shape})")
        if chunks is not None:
            z = z.rechunk(_tiles(chunks, z.shape))
        elif isinstance(dem, np.ndarray):
            z = z.rechunk(DEFAULT_TILE)
        if not np.issubdtype(z.dtype, np.floating):
            z = z.astype(np.float64)  # room for the NaN padding
        _check_widths(widths, z.shape[0])
        padded = da.overlap.overlap(z, depth={0: 1, 1: 1}, boundary={0: np.nan, 1: np.nan})
        return padded.map_blocks(
            _overlap_tile,
            cx,
            cy,
            options,
            widths=widths,
            dtype=np.float32,
            chunks=((2,),) + z.chunks,
            new_axis=0,
            meta=meta,
            token="sandslope-risk-raster",
        )

    # A store: one independent task per tile, each reading its own window.
    shape, native = _store_shape(dem)
    _check_widths(widths, shape[0])
    if nodata is None:
        options["nodata"] = _tiff_nodata(dem)
    tiles = _tiles(chunks if chunks is not None else (native or DEFAULT_TILE), shape)
    return da.map_blocks(
        _window_tile,
        dem,
        shape,
        cx,
        cy,
        options,
        widths=widths,
        dtype=np.float32,
        chunks=((2,),) + tuple(tiles),
        meta=meta,
        token="sandslope-risk-raster-window",
    )
