"""What the Python functions take, checked and converted into what the extension takes: a
robot or terrain (an object, a preset name or a TOML path, as the command line's
``--robot``/``--terrain``), real-valued arrays, and a DEM with its cell size and row widths.
Shared by the package's functions and by :mod:`sandslope.dask`."""

from __future__ import annotations

import os
from typing import Any, List, Optional, Tuple, Union

import numpy as np

from ._sandslope import Robot, Terrain

RobotLike = Union[Robot, str, "os.PathLike[str]"]
TerrainLike = Union[Terrain, str, "os.PathLike[str]"]


def _robot(robot: RobotLike) -> Robot:
    """A Robot, a preset name or a TOML path (as the CLI's ``--robot FILE|PRESET``)."""
    if isinstance(robot, Robot):
        return robot
    if isinstance(robot, (str, os.PathLike)):
        # The command line's rule (sandslope-io): a file if it exists or ends in .toml, else a preset.
        return Robot.load(os.fspath(robot))
    raise TypeError(f"robot must be a sandslope.Robot, a preset name or a TOML path, not {type(robot).__name__}")


def _terrain(terrain: TerrainLike) -> Terrain:
    """A Terrain, a preset name or a TOML path (as the CLI's ``--terrain FILE|PRESET``)."""
    if isinstance(terrain, Terrain):
        return terrain
    if isinstance(terrain, (str, os.PathLike)):
        return Terrain.load(os.fspath(terrain))
    raise TypeError(
        f"terrain must be a sandslope.Terrain, a preset name or a TOML path, not {type(terrain).__name__}"
    )


def _source(x: Any, default: str) -> str:
    """How an answer names a robot or terrain: its preset name or path as given, else `default`."""
    if isinstance(x, (str, os.PathLike)):
        return os.fspath(x)
    return default


def _float_array(name: str, x: Any) -> np.ndarray:
    _refuse_complex(name, x)
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name} must be a number or an array of numbers: {e}") from None


def _refuse_complex(name: str, x: Any) -> None:
    """A complex value would be cast to its real part with only NumPy's ComplexWarning."""
    if np.iscomplexobj(x):
        raise ValueError(f"{name} must be real numbers, not complex ({np.asarray(x).dtype})")


def _cell_size(cell_size_m: Any) -> Tuple[float, float]:
    if np.ndim(cell_size_m) == 0:
        c = float(cell_size_m)
        return c, c
    pair = tuple(float(v) for v in cell_size_m)
    if len(pair) != 2:
        raise ValueError(f"cell_size_m must be one number or (cell_x, cell_y), not {cell_size_m!r}")
    return pair  # type: ignore[return-value]


def _row_widths(row_widths_m: Any) -> Optional[List[float]]:
    """Each row's east-west cell size (m) as the extension takes it, or None."""
    if row_widths_m is None:
        return None
    w = _float_array("row_widths_m", row_widths_m)
    if w.ndim != 1:
        raise ValueError(f"row_widths_m must be a 1-D array, one width per row of the dem (got shape {w.shape})")
    return w.tolist()


def _dem(dem: Any) -> np.ndarray:
    _refuse_complex("dem", dem)
    z = np.asarray(dem)
    if z.ndim != 2:
        raise ValueError(f"dem must be a 2-D array (rows, cols), row 0 at the north (got shape {z.shape})")
    return np.ascontiguousarray(z, dtype=np.float64)
