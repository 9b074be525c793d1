"""sandslope: whether, how fast and why a legged robot climbs a sand slope.

The shear-anchoring model of Liao and Qian, *Failure Mechanisms and Risk Estimation for Legged
Robot Locomotion on Granular Slopes* (arXiv:2603.06928), from Python. This package wraps the
Rust library (crate ``sandslope``) and its file readers (``sandslope-io``); it re-implements
nothing, so every number is the one the ``sandslope`` command-line tool prints.

On a slope ``theta`` each of the ``n`` stance legs carries the normal load
``F_N = m g cos(theta) / n`` and sinks to the normal equilibrium depth
``d_n = F_N / (k_n A_c)``; the downslope shear load ``F_a = m (g sin(theta) + R omega / dt) / n``
is held once the leg reaches the shear-equilibrium depth ``d_s = sqrt(F_a / (k_s W))``, at the
anchoring time ``t1``. Until then the robot slips back ``s1 = 1/2 g sin(theta) t1^2``; the net
step is ``s = s* ((T/2 - t1)/(T/2))^2 - 1/2 g sin(theta) t1 (T - t1)`` and the speed
``v = s / (T/2)``. Regimes (docs/model.md §6), in precedence order: sinkage
(``d_n >= 2R - h``), slippage (at/above repose, no anchoring, or ``s <= 0``), metastable
(``0 < s < s_min``), success.

Units are SI throughout: kg, m, s, N/m^3 for ``k_n`` and ``k_s``; angles in degrees.
Regimes are returned as ``int8`` codes, indices into :data:`REGIMES`.

Errors in inputs raise :class:`ValueError` with the CLI's message: the key, the value and the
valid range (and the file, for TOML files); a missing file raises :class:`FileNotFoundError`.
Heavy calls release the GIL and run in parallel on all cores.
"""

from __future__ import annotations

import os
import warnings as _warnings
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _sandslope
from ._inputs import (
    RobotLike,
    TerrainLike,
    _cell_size,
    _dem,
    _float_array,
    _robot,
    _row_widths,
    _terrain,
)
from ._calibrate import calibrate
from ._report import report
from ._sandslope import Robot, Terrain
from ._servo import drive, drive_defaults, infer_servo_log, read_bag, read_servo_log
from ._walk import WalkSettings

__all__ = [
    "REGIMES",
    "OUTCOMES",
    "CAUSES",
    "Robot",
    "Terrain",
    "presets",
    "predict",
    "phase",
    "risk",
    "risk_map",
    "safe_slope",
    "safe_mass",
    "payload_envelope",
    "plan",
    "risk_raster",
    "read_raster",
    "fit",
    "track",
    "calibrate",
    "simulate",
    "simulate_ensemble",
    "check_convergence",
    "report",
    "read_servo_log",
    "infer_servo_log",
    "drive",
    "drive_defaults",
    "read_bag",
    "WalkSettings",
]


def __dir__() -> Sequence[str]:
    """The public names only (PEP 562): not the modules and typing names this file imports."""
    return sorted(__all__ + ["__version__"])

__version__ = "0.1.0"

#: Regime names; every ``regime`` array holds int8 indices into this tuple.
REGIMES: Tuple[str, str, str, str] = tuple(_sandslope.REGIMES)  # type: ignore[assignment]

#: What ``REGIMES[i]`` means on the slope in a field engineer's words (docs/model.md §6).
OUTCOMES: Tuple[str, str, str, str] = tuple(_sandslope.OUTCOMES)  # type: ignore[assignment]

#: Finer reasons for a regime; ``predict(...)["cause"]`` holds int8 indices into this tuple
#: (the library's ``Cause::ALL``, so the two cannot drift).
CAUSES: Tuple[str, ...] = tuple(_sandslope.CAUSES)



def presets() -> Dict[str, Dict[str, str]]:
    """The built-in robots and terrains: ``{name: {"kind": "robot"|"terrain", "summary": ...}}``.

    Load one with :meth:`Robot.preset` or :meth:`Terrain.preset`.
    """
    return {name: {"kind": kind, "summary": summary} for name, kind, summary in _sandslope.preset_names()}


_PREDICT_FLOAT_KEYS = (
    "slope_deg",
    "k_n",
    "k_s",
    "d_n_m",
    "level_step_m",
    "d_s_m",
    "t1_s",
    "slip_m",
    "propulsion_m",
    "step_m",
    "speed_m_s",
    "k_s_margin",
)


def predict(
    robot: RobotLike,
    slope_deg: Any,
    k_n: Any = None,
    k_s: Any = None,
    *,
    terrain: Optional[TerrainLike] = None,
    mass_kg: Any = None,
) -> Dict[str, Any]:
    """Every model quantity (docs/model.md §3-§6) at each slope, as ``sandslope predict --json``.

    ``slope_deg``, ``k_n``, ``k_s`` and ``mass_kg`` are scalars or arrays, broadcast together by
    NumPy's rules. Give either ``k_n`` and ``k_s`` (N/m^3), or a ``terrain`` looked up at each
    slope (docs/model.md §7: linear in degrees, held below the first point, extrapolated and
    floored at 0 above the last); with a terrain, ``k_n`` or ``k_s`` (> 0) override it. ``mass_kg``
    replaces the robot's total mass. Negative slopes (descending) are evaluated as climbing
    ``|slope|`` (docs/model.md §8).

    Returns a dict of arrays of the broadcast shape, with the keys of ``predict --json``:

    - ``slope_deg``, ``k_n``, ``k_s`` (N/m^3): the inputs used;
    - ``regime`` (int8, index into :data:`REGIMES`) and ``cause`` (int8, into :data:`CAUSES`);
    - ``d_n_m``: normal equilibrium depth ``d_n = m g cos(theta) / (n k_n A_c)``;
    - ``level_step_m``: level-sand step ``s* = 2 sqrt(R^2 - (d_n + h - R)^2)``;
    - ``d_s_m``: shear-equilibrium depth ``d_s = sqrt(F_a / (k_s W))``;
    - ``t1_s``: anchoring time ``t1 = (asin((d_s + h)/R - 1) - phi0) / omega``;
    - ``slip_m``: backward slip ``s1 = 1/2 g sin(theta) t1^2``;
    - ``propulsion_m``: ``s2 = s* ((T/2 - t1)/(T/2))^2 - g sin(theta) t1 (T/2 - t1)``;
    - ``step_m``: net step ``s = s2 - s1``;
    - ``speed_m_s``: the speed the robot makes, ``v = s / (T/2)``, except where the regime rules
      it out (legs sinking, slope at or above repose: NaN); ``model_speed_m_s``: the stance
      model's ``v`` whatever the regime;
    - ``k_s_margin``: k_s over the smallest k_s that still gives progress (docs/model.md §13);
      ``critical_k_s_progress``, ``critical_k_s_robust``: the smallest k_s giving ``s > 0`` and
      ``s >= s_min``;
    - ``extrapolated`` (bool): a terrain value was extrapolated beyond its last point.

    Floats are NaN where the JSON has ``null`` (no anchoring: no t1, slip, step or speed).
    0-d inputs give 0-d arrays (use ``float(...)``).
    """
    robot = _robot(robot)
    terrain = None if terrain is None else _terrain(terrain)
    # Without a terrain both k_n and k_s are needed: the request layer checks it (point_terrain).
    inputs = {"slope_deg": _float_array("slope_deg", slope_deg)}
    for name, value in (("k_n", k_n), ("k_s", k_s), ("mass_kg", mass_kg)):
        if value is not None:
            inputs[name] = _float_array(name, value)
    try:
        shape = np.broadcast_shapes(*(a.shape for a in inputs.values()))
    except ValueError:
        shapes = ", ".join(f"{k} {a.shape}" for k, a in inputs.items())
        raise ValueError(f"the arguments cannot be broadcast together: {shapes}") from None
    flat = {k: np.ascontiguousarray(np.broadcast_to(a, shape)).reshape(-1) for k, a in inputs.items()}
    out = _sandslope.predict(
        robot,
        flat["slope_deg"],
        k_n=flat.get("k_n"),
        k_s=flat.get("k_s"),
        terrain=terrain,
        mass_kg=flat.get("mass_kg"),
    )
    if terrain is not None and (k_n is None or k_s is None):
        _warn_extrapolated(terrain, flat["slope_deg"])
    return {k: v.reshape(shape) for k, v in out.items()}


def _warn_extrapolated(terrain: Terrain, slopes: np.ndarray) -> None:
    """The CLI's warning when slopes lie above the terrain's last measured point (docs/model.md §7):
    the rule and the message are the request layer's; each slope is named once."""
    distinct = np.unique(np.abs(slopes[np.isfinite(slopes)]))
    warning = terrain._extrapolation_warning(distinct.tolist())
    if warning is not None:
        _warnings.warn(warning, UserWarning, stacklevel=3)


def _axis(name: str, x: Any) -> np.ndarray:
    a = _float_array(name, x)
    if a.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional (got shape {a.shape})")
    return np.ascontiguousarray(a)


def phase(
    robot: RobotLike,
    slope_deg: float,
    k_n_axis: Any,
    k_s_axis: Any,
    *,
    mass_kg: Optional[float] = None,
    terrain: Optional[TerrainLike] = None,
    repose_deg: Optional[float] = None,
    regime_only: bool = False,
) -> Dict[str, Any]:
    """The phase map (docs/model.md §6): the regime of every terrain ``(k_n, k_s)`` on a grid.

    ``k_n_axis`` and ``k_s_axis`` (N/m^3) are ascending and evenly spaced
    (``np.linspace``) or evenly spaced in logarithm (``np.geomspace``), as in
    ``sandslope phase --k-n MIN:MAX:N[:log|:lin]``. ``mass_kg`` replaces the robot's mass;
    at or above ``repose_deg`` (by default the ``terrain``'s angle of repose, if a terrain is
    given, as ``sandslope phase --terrain`` does) every cell slips.

    Returns a dict:

    - ``regime``: int8, shape ``(len(k_n_axis), len(k_s_axis))``, index into :data:`REGIMES`;
    - ``step_m``: float64, same shape, the net step ``s`` (NaN where the leg never anchors);
      left out with ``regime_only=True``, which skips computing and writing it
      (docs/python.md);
    - ``k_n``, ``k_s``: the axis values used (the library's, equal to the given ones to 1e-9);
    - ``counts``: cells per regime.

    Cell for cell this is what :func:`predict` gives (the library evaluates the k_n-only and
    k_s-only parts once per axis value, rows in parallel). Both arrays are transposed views of
    row-major ``(k_s, k_n)`` buffers, so ``regime.T`` is C-contiguous with one row per k_s
    (the layout of an image with k_s up).
    """
    robot = _robot(robot)
    if mass_kg is not None:
        robot = robot.with_mass(float(mass_kg))
    kn, ks = _axis("k_n_axis", k_n_axis), _axis("k_s_axis", k_s_axis)
    terrain = None if terrain is None else _terrain(terrain)
    out = _sandslope.phase(robot, float(slope_deg), kn, ks, terrain=terrain, repose_deg=repose_deg, regime_only=bool(regime_only))
    shape = (len(out["k_s"]), len(out["k_n"]))
    out["regime"] = out["regime"].reshape(shape).T
    if "step_m" in out:
        out["step_m"] = out["step_m"].reshape(shape).T
    return out


def risk(
    robot: RobotLike,
    slope_deg: Any,
    *,
    terrain: TerrainLike,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
) -> Dict[str, np.ndarray]:
    """Regime probabilities on uncertain terrain (docs/model.md §9), as ``sandslope risk --csv``.

    k_n and k_s at each slope are independent log-normals whose medians are the terrain's
    values; their coefficients of variation follow the one rule of docs/model.md §9: ``cv_n``
    /``cv_s`` when given, else the terrain's ``k_n_sd``/``k_s_sd`` over its value, else the
    defaults 0.1 and 0.2. Probabilities come from deterministic quadrature (reproducible to
    1e-9), not sampling.

    Returns arrays of the shape of ``slope_deg`` under the keys of ``sandslope risk --json``:
    ``slope_deg``, the ``cv_n``, ``cv_s`` used at each slope and where each came from
    (``cv_n_source``, ``cv_s_source``: ``"given"``, ``"table"`` or ``"default"``), ``p_fail`` =
    P(sinkage or slippage), ``p_not_success`` and ``p_regime`` (a dict of ``success``,
    ``metastable``, ``slippage``, ``sinkage``), and no other keys (issue 22: the same keys as
    ``--json``; ``pandas.DataFrame(r["p_regime"])`` gives the ``risk --csv`` regime columns).
    """
    robot, terrain = _robot(robot), _terrain(terrain)
    s = _float_array("slope_deg", slope_deg)
    out = _sandslope.risk(robot, np.ascontiguousarray(s).reshape(-1), terrain, cv_n=cv_n, cv_s=cv_s)

    def shaped(v: Any) -> Any:
        return {k: shaped(x) for k, x in v.items()} if isinstance(v, dict) else np.asarray(v).reshape(s.shape)

    return {k: shaped(v) for k, v in out.items()}


def risk_map(
    robot: RobotLike,
    slope_deg: float,
    k_n_axis: Any = None,
    k_s_axis: Any = None,
    *,
    terrain: TerrainLike,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
    mass_kg: Optional[float] = None,
    max_risk: float = _sandslope.DEFAULT_MAX_RISK,
) -> Dict[str, Any]:
    """P(failure) over a grid of median ``(k_n, k_s)`` at one slope (``sandslope risk --map``).

    The uncertainty (coefficients of variation) and the angle of repose are the terrain's at
    ``slope_deg`` (or ``cv_n``/``cv_s``). Axes as in :func:`phase`; by default the CLI's (the
    library's one default grid): 200 log-spaced values from the terrain's k_n / 100 to x 100
    and k_s / 1000 to x 100 at that slope.

    Returns the keys of ``sandslope risk --map --json`` (one library value): ``p_fail`` and
    ``p_not_success``, each of shape ``(len(k_n_axis), len(k_s_axis))``; ``k_n``, ``k_s`` (the
    axis values) and ``k_n_axis``, ``k_s_axis`` (``min``, ``max``, ``points``, ``scale``);
    ``cells`` and ``cells_below_max_risk`` (``p_fail < max_risk``); ``terrain_k_n``,
    ``terrain_k_s`` (the terrain's medians at this slope) and ``terrain_p_fail`` there; the
    ``cv_n``, ``cv_s`` used (rule of docs/model.md §9), their sources and ``defaults_used``;
    ``slope_deg``, ``max_risk`` and ``beyond_repose``.
    """
    robot, terrain = _robot(robot), _terrain(terrain)
    if mass_kg is not None:
        robot = robot.with_mass(float(mass_kg))
    kn = None if k_n_axis is None else _axis("k_n_axis", k_n_axis)
    ks = None if k_s_axis is None else _axis("k_s_axis", k_s_axis)
    out = _sandslope.risk_map(
        robot, float(slope_deg), kn, ks, terrain, max_risk=float(max_risk), cv_n=cv_n, cv_s=cv_s
    )
    shape = (len(out["k_s"]), len(out["k_n"]))
    for k in ("p_fail", "p_not_success"):
        out[k] = out[k].reshape(shape).T
    return out


def safe_slope(
    robot: RobotLike,
    *,
    terrain: TerrainLike,
    max_risk: float = _sandslope.DEFAULT_MAX_RISK,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
) -> Dict[str, Any]:
    """The two slope limits (``sandslope risk --solve slope --json``), named apart:
    ``success_slope_deg``, the steepest slope with P(not success) < ``max_risk`` from level up
    (it climbs steadily: it neither sinks, slides back nor may stall; "how steep can we go?"),
    and ``safe_slope_deg``, the steepest that is safe, ``p_fail`` = P(sinks or slides back) <
    ``max_risk`` (docs/model.md §9; between the two it climbs slowly and may stall). Each search scans
    every 0.5 deg, then bisects to 0.001 deg. ``limit["kind"]`` (and ``success_limit["kind"]``)
    is ``"limit"`` (the threshold crossed), ``"repose"`` (below the threshold up to the angle of
    repose, ``limit["repose_deg"]``, where the sand flows), ``"none_safe"`` or
    ``"beyond_range"``; a ``*_slope_deg`` is None unless a limit or the repose was found;
    ``cv_n``, ``cv_s`` and their sources are those where ``limit["p_fail"]`` was evaluated,
    ``defaults_used`` says whether a default CV was used anywhere in the table. The same keys
    as the CLI's JSON."""
    return _sandslope.safe_slope(
        _robot(robot), _terrain(terrain), max_risk=float(max_risk), cv_n=cv_n, cv_s=cv_s
    )


def safe_mass(
    robot: RobotLike,
    slope_deg: float,
    *,
    terrain: TerrainLike,
    max_risk: float = _sandslope.DEFAULT_MAX_RISK,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
) -> Dict[str, Any]:
    """The heaviest safe total mass at one slope (``sandslope risk --solve mass --json``, the same
    keys): ``max_mass_kg``, ``max_payload_kg`` (over the robot's own mass), the ``limit``, and
    the ``cv_n``, ``cv_s`` used there with their sources."""
    return _sandslope.safe_mass(
        _robot(robot), float(slope_deg), _terrain(terrain), max_risk=float(max_risk), cv_n=cv_n, cv_s=cv_s
    )


def payload_envelope(
    robot: RobotLike,
    slope_deg: Any,
    *,
    terrain: TerrainLike,
    max_risk: float = _sandslope.DEFAULT_MAX_RISK,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
) -> Dict[str, Any]:
    """The payload envelope: the heaviest safe total mass at each slope of ``slope_deg`` (one
    value or a sequence), as ``sandslope risk --slope A,B,... --solve mass --json`` prints it
    (the same keys and numbers): ``max_risk``, ``robot_mass_kg``, ``points`` (per slope, in the
    order given: ``slope_deg``, ``max_mass_kg``, ``max_payload_kg`` over the robot's own mass,
    the ``limit`` and the ``cv_n``, ``cv_s`` used there with their sources) and
    ``defaults_used``. Stops on Ctrl-C between chunks of slopes."""
    s = np.ascontiguousarray(_float_array("slope_deg", slope_deg)).reshape(-1)
    return _sandslope.payload_envelope(
        _robot(robot), s, _terrain(terrain), max_risk=float(max_risk), cv_n=cv_n, cv_s=cv_s
    )


def risk_raster(
    dem: Any,
    cell_size_m: Any,
    *,
    robot: RobotLike,
    terrain: TerrainLike,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
    max_roll_deg: float = _sandslope.DEFAULT_MAX_ROLL_DEG,
    descent: str = "symmetric",
    allow_metastable: bool = False,
    nodata: Optional[float] = None,
    row_widths_m: Any = None,
) -> np.ndarray:
    """The two bands of ``sandslope plan --risk-map`` for an elevation array.

    ``dem`` (m) is 2-D, row 0 at the north, columns to the east, NaN (or ``nodata``) for
    missing heights; ``cell_size_m`` is one number or ``(cell_x, cell_y)``. ``row_widths_m``:
    on a geographic DEM (degrees; an equirectangular map), whose cells narrow towards the pole,
    the east-west size of each row's cells in metres, one per row (what
    :func:`read_raster` gives as ``geo["row_widths_m"]``), used row by row as ``sandslope plan``
    does (docs/model.md §8). Heights are used as float32, as the CLI does. Each cell's gradient is Horn's 3 x 3 finite difference, so the
    map border and cells next to nodata have none (NaN).

    Returns float32 of shape ``(2, H, W)``: band 0 the lowest P(failure) over the 16 headings
    of the planner's grid (roll above ``max_roll_deg`` counts as failure), band 1 the azimuth
    (degrees clockwise from north) of the steepest climbing heading the time objective may use
    (success, or metastable with ``allow_metastable``); NaN where impassable or none.

    ``cv_n``/``cv_s``: coefficients of variation, by the rule of docs/model.md §9 (given, else
    the terrain's SDs, else 0.1 and 0.2), as ``sandslope plan --cv-n --cv-s``. For DEMs larger
    than memory use :func:`sandslope.dask.risk_raster` on the DEM's file, which gives the same
    values tile by tile. Repeated calls with the same robot and terrain reuse the model's
    pitch table (kept per process), so later calls are faster with the same results.
    """
    z = _dem(dem)
    cx, cy = _cell_size(cell_size_m)
    widths = _row_widths(row_widths_m)
    bands = _sandslope.risk_raster(
        z,
        cx,
        cy,
        _robot(robot),
        _terrain(terrain),
        nodata=None if nodata is None else float(nodata),
        cv_n=cv_n,
        cv_s=cv_s,
        max_roll_deg=float(max_roll_deg),
        descent=descent,
        allow_metastable=bool(allow_metastable),
        row_widths_m=widths,
    )
    return bands.reshape((2,) + z.shape)


def plan(
    dem: Any,
    cell_size_m: Any,
    *,
    robot: RobotLike,
    terrain: TerrainLike,
    start: Tuple[int, int],
    goal: Tuple[int, int],
    objective: Union[str, Sequence[str]] = "time",
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
    max_roll_deg: float = _sandslope.DEFAULT_MAX_ROLL_DEG,
    descent: str = "symmetric",
    allow_metastable: bool = False,
    time_weight: float = 1e-4,
    origin: Optional[Tuple[float, float]] = None,
    nodata: Optional[float] = None,
    classes: Any = None,
    class_terrains: Optional[Mapping[int, TerrainLike]] = None,
    row_widths_m: Any = None,
) -> Dict[str, Any]:
    """Heading-aware routes over an elevation array (``sandslope plan --json``, docs/model.md §8).

    ``start`` and ``goal`` are cells ``(row, col)`` of ``dem`` (NumPy index order: ``dem[row,
    col]``). ``objective``: ``"time"`` (fastest route through success cells), ``"risk"``
    (maximum survival, plus ``time_weight`` per second) and/or ``"distance"`` (shortest, physics
    ignored), a list of these words or one text as ``--objective`` takes it (``"time,risk"``);
    the distance route is always added for comparison, as the CLI does.

    Returns ``{"routes": {objective: route}, "extrapolation": None or {"max_pitch_deg",
    "last_point_deg"}}`` (set when a route climbs above the terrain's last measured point);
    each route has the figures of ``plan --json``
    (``found``, ``length_m``, ``time_s``, ``survival``, ``max_pitch_deg``, ``max_roll_deg``,
    ``edges_over_roll_limit``, ``regimes``; or ``found=False`` with ``reason`` and ``message``
    and those figures None, as ``plan --json`` has them null),
    its cells (``rows``, ``cols``), their coordinates ``x_m``, ``y_m`` (cell centres; x east and
    y north of ``origin``, the map's north-west corner, default ``(0, rows * cell_y)``; with
    ``row_widths_m``, x is measured along the cell's own row, in that row's cell widths) and
    heights ``z_m``, and per edge ``steps`` (heading, pitch, roll, length, regime, speed,
    p_fail, over the roll limit).

    Terrain classes (``plan --classes --class-terrain``): ``classes`` an array of the DEM's shape
    holding each cell's class number (NaN: none, impassable) and ``class_terrains`` a mapping
    ``{class: terrain}`` (Terrain, preset name or TOML path); ``terrain`` is then unused.

    ``row_widths_m``: each row's east-west cell size in metres on a geographic DEM, as in
    :func:`risk_raster` (``cell_size_m``'s ``cell_x`` stays the reference cell of the risk
    objective, ``geo["cell_x_m"]``).
    """
    z = _dem(dem)
    cx, cy = _cell_size(cell_size_m)
    class_args: Dict[str, Any] = {}
    if classes is not None:
        class_args["classes"] = _float_array("classes", classes)
    if class_terrains is not None:
        class_args["class_terrains"] = [(int(k), _terrain(t)) for k, t in dict(class_terrains).items()]
    names = [objective] if isinstance(objective, str) else [str(o) for o in objective]
    return _sandslope.plan(
        z,
        cx,
        cy,
        _robot(robot),
        _terrain(terrain),
        (int(start[0]), int(start[1])),
        (int(goal[0]), int(goal[1])),
        names,
        None if origin is None else (float(origin[0]), float(origin[1])),
        nodata=None if nodata is None else float(nodata),
        cv_n=cv_n,
        cv_s=cv_s,
        max_roll_deg=float(max_roll_deg),
        descent=descent,
        allow_metastable=bool(allow_metastable),
        time_weight=float(time_weight),
        row_widths_m=_row_widths(row_widths_m),
        **class_args,
    )


def read_raster(path: Union[str, "os.PathLike[str]"]) -> Tuple[np.ndarray, Dict[str, float]]:
    """Reads a GeoTIFF (``.tif``), ESRI ASCII grid (``.asc``) or PDS3 DTM (``.img``, ``.lbl``) as the CLI does.

    Returns ``(values, geo)``: a float64 array ``(rows, cols)`` with nodata as NaN, and
    ``geo = {"west", "north", "cell_x", "cell_y"}`` (map units) with the ground cell size in
    metres, ``"cell_x_m"``, ``"cell_y_m"``, and ``"row_widths_m"``: each row's east-west size
    where the rows differ (a geographic DEM, an equirectangular DTM), else None. Pass ``values``,
    ``(geo["cell_x_m"], geo["cell_y_m"])`` and ``row_widths_m=geo["row_widths_m"]`` to
    :func:`plan` or :func:`risk_raster`.
    """
    values, rows, cols, geo = _sandslope.read_raster(os.fspath(path))
    return values.reshape(rows, cols), geo


def _frame(rows: Any) -> Any:
    """A pandas DataFrame of a list of records when pandas is installed, else the list."""
    try:
        import pandas as pd
    except ImportError:
        return rows
    return pd.json_normalize(rows) if rows and any(isinstance(v, dict) for v in rows[0].values()) else pd.DataFrame(rows)


def fit(
    manifest: Union[str, "os.PathLike[str]"],
    *,
    depth_window: Optional[Tuple[float, float]] = None,
    plateau_from: Optional[float] = None,
    air: str = "auto",
    counts_per_newton: Optional[float] = None,
    skip_malformed: bool = False,
) -> Dict[str, Any]:
    """k_n and k_s per slope from load-cell recordings (``sandslope fit``, docs/model.md §10).

    ``manifest`` is the TOML manifest of the campaign (docs/measurements.md): disk area, shear
    plate, and one ``[[trial]]`` per CSV or ROS 2 bag (kind, slope, in-air or not; a bag's
    wrench and pose topics as docs/bags.md describes). k_n is the slope of force
    against depth over its linear part, divided by the disk area; k_s comes from the
    quasi-static shear plateau; in-air runs are subtracted (``air``: ``"auto"``, ``"curve"``
    or ``"mean"``). ``depth_window=(min, max)`` (m) and ``plateau_from`` (m) override the
    automatic choices; ``counts_per_newton`` converts a ``force_counts`` column.

    Returns ``{"points": per slope, "trials": per trial, "terrain": Terrain}``: ``points`` and
    ``trials`` are pandas DataFrames when pandas is installed (lists of dicts otherwise), with
    the fields of ``sandslope fit --json``; ``terrain`` is ready for :func:`predict`.
    """
    out = _sandslope.fit(
        os.fspath(manifest),
        depth_window=None if depth_window is None else (float(depth_window[0]), float(depth_window[1])),
        plateau_from=plateau_from,
        air=air,
        counts_per_newton=counts_per_newton,
        skip_malformed=skip_malformed,
    )
    out["points"] = _frame(out["points"])
    out["trials"] = _frame(out["trials"])
    return out


def track(
    paths: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]],
    slope_deg: Optional[float] = None,
    *,
    robot: RobotLike = "paper-hexapod",
    format: Optional[str] = None,
    body: Optional[str] = None,
    upslope: Optional[Sequence[float]] = None,
    max_gap: int = 10,
    cutoff_hz: float = 10.0,
    leg_speed_rad_s: Optional[float] = None,
    touchdowns: Optional[Sequence[Any]] = None,
    topic: Optional[str] = None,
    frame: Optional[str] = None,
) -> Dict[str, Any]:
    """Speed, anchoring time and slip from motion capture (``sandslope track``, docs/model.md §11).

    ``paths``: one recording or several at the same ``slope_deg`` (OptiTrack Motive CSV, Vicon
    Nexus CSV or plain ``time_s,x_m,y_m,z_m``, detected unless ``format`` is given; ``body``
    picks the rigid body or marker). Gaps up to ``max_gap`` frames are filled, longer ones split
    the recording; positions are differentiated with a zero-phase Butterworth low-pass at
    ``cutoff_hz``; touchdowns every T/2 (T = 2 pi / leg speed, from the robot or
    ``leg_speed_rad_s``) come from ``touchdowns`` (per recording, a list of times in s or the
    path of a touchdowns file, as ``track --touchdowns`` reads) or are
    estimated from the speed signal. ``upslope`` (x, y, z) fixes the upslope direction
    (estimated from the travel otherwise). A ROS 2 bag (a bag folder, ``.mcap`` or ``.db3``,
    docs/bags.md) is read as ``track --topic --frame`` reads it: ``topic`` a pose, odometry or
    TF topic (the bag's only one when omitted), ``frame`` the child frame on a TF topic,
    composed up its tree to the root.

    Returns the fields of ``sandslope track --json``: pooled means and SDs (``speed_m_s``,
    ``t1_s``, ``slip_m``, ``step_m``, ...), and ``recordings`` and ``per_step`` as pandas
    DataFrames when pandas is installed (lists of dicts otherwise).
    """
    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    out = _sandslope.track(
        [os.fspath(p) for p in paths],
        slope_deg=None if slope_deg is None else float(slope_deg),
        robot=_robot(robot),
        format=format,
        body=body,
        upslope=None if upslope is None else [float(v) for v in upslope],
        max_gap=int(max_gap),
        cutoff_hz=float(cutoff_hz),
        leg_speed_rad_s=None if leg_speed_rad_s is None else float(leg_speed_rad_s),
        touchdowns=None if touchdowns is None else [_touchdown_times(ts) for ts in touchdowns],
        topic=topic,
        frame=frame,
    )
    out["recordings"] = _frame(out["recordings"])
    out["per_step"] = _frame(out["per_step"])
    return out


def _touchdown_times(ts: Any) -> list:
    """One recording's touchdowns: a file (as the CLI's --touchdowns) or a sequence of times."""
    if isinstance(ts, (str, os.PathLike)):
        return _sandslope.read_touchdowns(os.fspath(ts))
    try:
        return [float(t) for t in ts]
    except (TypeError, ValueError):
        raise ValueError(
            "touchdowns must hold, per recording, a list of times in seconds or a touchdowns file path, "
            f"not {ts!r}"
        ) from None


def simulate_ensemble(
    robot: RobotLike,
    terrain: TerrainLike,
    slope_deg: float,
    walks: int,
    duration_s: float = 10.0,
    **settings: Any,
) -> Dict[str, Any]:
    """Walks the robot ``walks`` times (2 to 1000) at ``slope_deg``, the mass of walk k
    multiplied by ``1 + k 1e-9``, and returns the spread: the dict ``sandslope simulate
    --ensemble N --json`` prints (``speed_m_s``, ``speed_sd_m_s``, ``speed_se_m_s``, ``t1_s``,
    ``t1_se_s``, ``pitched_over``, ``regimes``, ``regime``, every walk's summary under
    ``summaries``).

    With ``body_pitch="free"`` the walk on a slope is chaotic (two walks 1e-9 apart part by
    tens of degrees of pitch within seconds), so the spread is the answer; with the pitch
    locked the walks agree to rounding (docs/simulate.md, "Pitch free"). The other keywords are
    :func:`simulate`'s (:class:`WalkSettings`).
    """
    return _sandslope.simulate_ensemble(
        _robot(robot),
        _terrain(terrain),
        float(slope_deg),
        float(duration_s),
        int(walks),
        **settings,
    )


def check_convergence(
    robot: RobotLike,
    terrain: TerrainLike,
    slope_deg: Union[float, Sequence[float]],
    duration_s: float = 10.0,
    *,
    walks: Optional[int] = None,
    **settings: Any,
) -> Union[Dict[str, Any], List[Dict[str, Any]]]:
    """Whether the walk at ``slope_deg`` is converged: the dict ``sandslope simulate
    --check-convergence --json`` prints (a sequence of slopes: the list ``--slopes`` prints,
    the slopes checked in parallel). The walk as asked (``walk``), again at a quarter of
    its time step and at a tenth of its creep speed (``refinements``, each with its answer, its
    changes and whether speed, the steps' spread, t1 and regime are within issue 38's tolerances:
    3% or 0.3 cm/s for speed and spread, 1 ms, the same), and ``converged`` if both are.

    The default step is shown converged for the built-in robot and terrain only
    (docs/simulate.md, "Checking convergence"); check a robot, terrain or mechanism of your
    own. With ``walks=N`` each setting is an ensemble of N walks and their means are compared:
    a single walk with ``body_pitch="free"`` on a slope is chaotic and cannot converge. The
    other keywords are :func:`simulate`'s (:class:`WalkSettings`).
    """
    slopes = [float(s) for s in slope_deg] if isinstance(slope_deg, (list, tuple, np.ndarray)) else float(slope_deg)
    return _sandslope.check_convergence(
        _robot(robot),
        _terrain(terrain),
        slopes,
        float(duration_s),
        None if walks is None else int(walks),
        **settings,
    )


def simulate(
    robot: RobotLike,
    terrain: TerrainLike,
    slope_deg: float,
    duration_s: float = 10.0,
    scaling_spread: bool = True,
    **settings: Any,
) -> Tuple[Any, Dict[str, Any]]:
    """Simulates the robot walking for ``duration_s`` seconds on ``terrain`` at ``slope_deg``
    (``sandslope simulate``, docs/model.md §15-§18).

    A planar body on C-legs in the alternating tripod, the sand pushing on every leg element by
    resistive force theory scaled to the terrain's k_n and k_s (``k_n``/``k_s`` override them at
    every slope, as ``--k-n``/``--k-s``); ``dt_s`` fixes the time step, ``creep_m_s`` the creep
    speed of the contact law's smoothing at rest (``--creep``, docs/model.md §17),
    ``sample_rate_hz`` the trajectory's sampling; ``body_pitch="locked"`` (the default) holds the
    body parallel to the slope, as the closed form assumes, the setting whose answers converge;
    ``"free"`` lets it pitch (``--body-pitch free``; chaotic on slopes, one walk is one draw of a spread, docs/simulate.md);
    ``rft_scaling="components"`` scales the sand's normal stress by k_n and its shear stress by
    k_s, ``"li2013"`` everything by one factor from k_n, instead of one scale following the
    motion (``--rft-scaling``, docs/model.md §16); ``servo_limit=False`` ignores the robot
    file's servo torque limit (``--no-servo-limit``). ``leg_friction``, ``duty_cycle`` and
    ``disturbed_sand`` switch on the candidate mechanisms of docs/model.md §20 (``--leg-friction``,
    ``--duty-cycle``, ``--disturbed-sand``; left out, each takes the CLI's default: off), as
    do ``two_faced_belly=True`` (``--two-faced-belly``: the belly pulled by the sand as well as
    pushed, §20.5; the default belly only pushes) and ``actuator="servo"``
    (``--actuator servo``, §20.6). The keywords are :class:`WalkSettings`, shared with
    :func:`simulate_ensemble` and :func:`check_convergence`; the extension reads them by the
    request layer's table, as ``sandslope simulate`` reads its flags. Negative slopes walk
    downhill.

    Returns ``(trajectory, summary)``: ``trajectory`` a pandas DataFrame (a dict of NumPy
    columns without pandas) with ``time_s``, ``x_m``, ``z_m``, ``pitch_rad``, ``vx_m_s``,
    ``vz_m_s`` and per leg j ``leg{j}_angle_rad``, ``leg{j}_depth_m``, ``leg{j}_force_x_n``,
    ``leg{j}_force_z_n``, ``leg{j}_torque_n_m``; ``summary`` the dict ``sandslope simulate
    --json`` prints (``speed_m_s``, ``t1_s``, ``slip_m``, ``step_m``, ``regime``, ``cause``,
    ``steps``, ``closed_form``, ...). ``summary["scaling_spread"]`` is the model uncertainty of
    the contact scaling (``--scaling-spread``, on by default here as for one slope on the command
    line): the slope walked again under the other two scalings (three walks instead of one), with
    ``min_speed_m_s``, ``max_speed_m_s``, ``range_m_s``, ``regimes_agree`` and each scaling's
    ``walks`` (``rft_scaling``, ``speed_m_s``, ``regime``, ``t1_s``). Which scaling the sand
    follows is not measured, and from about 20 degrees the regimes part (docs/simulate.md, "The
    scaling as model uncertainty"). ``scaling_spread=False`` walks once and gives ``None``.
    ``dt_s`` defaults to T / 2000 with the pitch locked, T / 16000 with it free.
    """
    columns, summary = _sandslope.simulate(
        _robot(robot),
        _terrain(terrain),
        float(slope_deg),
        float(duration_s),
        bool(scaling_spread),
        **settings,
    )
    try:
        import pandas as pd
    except ImportError:
        return columns, summary
    return pd.DataFrame(columns), summary
