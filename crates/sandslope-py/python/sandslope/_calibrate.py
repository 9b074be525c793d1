"""The joint calibration of ``sandslope calibrate`` (docs/calibration.md). Imported into
``sandslope``; the name is ``sandslope.calibrate``."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Optional, Sequence, Union

from . import _sandslope
from ._inputs import RobotLike, TerrainLike, _robot, _source, _terrain

_PathLike = Union[str, "os.PathLike[str]"]


def _free(free: Union[str, Sequence[str]]) -> list:
    """``free`` as the command line's ``--free LIST`` takes it: a comma list or a sequence."""
    if isinstance(free, str):
        return free.split(",")
    items = list(free)
    for item in items:
        if not isinstance(item, str):
            raise TypeError(f"free must be a comma list or a sequence of str, not one holding {item!r}")
    return items


def calibrate(
    robot: RobotLike = "paper-hexapod",
    terrain: TerrainLike = "glass-beads-300um",
    *,
    observed: Optional[_PathLike] = None,
    forces: Optional[_PathLike] = None,
    t1: Optional[_PathLike] = None,
    free: Union[str, Sequence[str]] = (),
    error_floor: Optional[float] = None,
    law: str = "linear",
    model: str = "closed-form",
    k_n: Optional[float] = None,
    name: Optional[str] = None,
    repose: Optional[float] = None,
) -> Dict[str, Any]:
    """The unmeasured quantities fitted to speeds, anchoring times and force tests together
    (``sandslope calibrate --json``, docs/calibration.md).

    Each keyword is the flag of the same name: ``observed`` (speeds CSV
    ``slope_deg,speed_m_s,speed_sd_m_s``), ``forces`` (a terrain file or preset with ``k_s_sd``
    per slope: the shape of k_s and its k_n), ``t1`` (anchoring-time CSV
    ``slope_deg,t1_s,t1_sd_s``), ``free`` (quantities fitted besides k_s, a comma list or a
    sequence, each ``KEY`` or ``KEY=MIN:MAX``: any robot key, ``plate_scale``,
    ``error_floor``), ``error_floor`` (a fixed model-error floor, m/s), ``law`` (``"linear"``,
    ``"coulomb"`` or ``"per-slope"``, without ``forces``), ``model`` (``"closed-form"`` or
    ``"simulate"``: minutes of CPU), ``k_n`` (N/m^3 at every slope), ``name`` and ``repose``
    (degrees) written into the terrain. ``robot`` and ``terrain`` are ``--robot`` and
    ``--terrain``: the robot fitted and the source of k_n (without ``forces`` or ``k_n``) and of
    the angle of repose. The fit runs with the GIL released.

    Returns exactly the keys and values of ``calibrate --json``: for a joint fit ``mode``,
    ``parameters``, ``chi_squared``, ``dof``, ``chi_squared_per_dof``, ``error_floor_m_s``,
    ``pulls``, ``shear_ratio_20``, ``shear``, ``robot``, ``terrain``, ``warnings``, ``repose``
    (...); for ``law="per-slope"`` ``mode``, ``law``, ``residuals``, ``rmse_m_s``,
    ``chi_squared``, ``terrain``, ``repose``. ``sandslope.Terrain(**out["terrain"])`` is the
    calibrated terrain, ``sandslope.Robot(**out["robot"])`` the fitted robot. Bad input raises
    ValueError with the command line's message, naming the keyword.
    """
    t = _terrain(terrain)
    text = _sandslope.calibrate(
        _robot(robot),
        t,
        _source(terrain, t.name or "a sandslope.Terrain"),
        observed=None if observed is None else os.fspath(observed),
        forces=None if forces is None else os.fspath(forces),
        t1=None if t1 is None else os.fspath(t1),
        free=_free(free),
        error_floor=None if error_floor is None else float(error_floor),
        law=law,
        model=model,
        k_n=None if k_n is None else float(k_n),
        name=name,
        repose=None if repose is None else float(repose),
    )
    return json.loads(text)
