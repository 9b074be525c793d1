"""The robot in the loop (docs/drive.md): servo logs, the stance-current inference of
``sandslope infer --servo-log`` and a run of ``sandslope drive --emulate``. Imported into
``sandslope``; the names are ``sandslope.read_servo_log``, ``sandslope.infer_servo_log`` and
``sandslope.drive``."""

from __future__ import annotations

import os
from typing import Any, Dict, Mapping, Optional, Tuple, Union

import numpy as np

from . import _sandslope
from ._inputs import RobotLike, TerrainLike, _robot, _terrain

#: The columns ``infer_servo_log`` reads from a log (docs/drive.md, "The log").
SERVO_COLUMNS = ("leg", "leg_angle_rad", "drive_torque_n_m")


def _frame(columns: Dict[str, np.ndarray], meta: Optional[Dict[str, str]] = None) -> Any:
    """The columns as a DataFrame whose ``attrs`` carry the log's header (``slope_deg``, ...),
    so that ``infer_servo_log`` finds the run's slope; a dict without pandas."""
    try:
        import pandas as pd
    except ImportError:
        return columns
    frame = pd.DataFrame(columns)
    frame.attrs.update(meta or {})
    return frame


def read_servo_log(path: Union[str, "os.PathLike[str]"]) -> Tuple[Any, Dict[str, str]]:
    """Reads a ``sandslope drive --log`` CSV: ``(log, meta)``, ``log`` a pandas DataFrame (a dict
    of NumPy columns without pandas) with the log's columns, ``meta`` its ``# key = value``
    header (``slope_deg``, ``k_n``, ``period_s``, ``ids``, ...). Errors name the file and line."""
    columns, meta, _notes = _sandslope.read_servo_log(os.fspath(path))
    return _frame(columns, dict(meta)), dict(meta)


def infer_servo_log(
    log: Union[str, "os.PathLike[str]", Mapping[str, Any]],
    robot: RobotLike = "paper-hexapod",
    terrain: TerrainLike = "glass-beads-300um",
    *,
    slope_deg: Optional[float] = None,
    k_s_prior: Optional[Tuple[float, float]] = None,
    grid_points: Optional[int] = None,
) -> Dict[str, Any]:
    """The sand's k_s at the run's slope from the servos' stance currents, as ``sandslope infer
    --servo-log FILE --json`` (docs/model.md §19): the dict with ``k_s``, ``k_s_lo``, ``k_s_hi``
    (the 90% interval), ``bound``, ``shear_load_n``, ``closed_form_shear_load_n``,
    ``speed_m_s``, ``speed_lo_m_s``, ``speed_hi_m_s`` (the climbing speed those sands give, with
    its 90% interval), ``p_slippage``, ``p_sinkage``, ``p_fail``, ``strides``, ``posterior``, ..., and ``notes``:
    what the log's reader repaired (a cut last row, empty values, repeats, rows out of order,
    gaps), the CLI's ``note:`` lines; empty for columns passed in.

    ``log`` is a log's path or its columns (a DataFrame or a mapping of arrays with ``leg``,
    ``leg_angle_rad`` and ``drive_torque_n_m``, one entry per servo per cycle, as
    ``read_servo_log`` and ``drive`` return). ``slope_deg`` defaults to the log's
    ``# slope_deg`` header (a path only). ``terrain`` gives k_n at the slope. The robot's
    stride simulator walks ``grid_points`` values of k_s over ``k_s_prior`` (seconds of CPU, the
    GIL released); left out, they are the CLI's defaults (41 over 1e4 to 1e9 N/m^3, from the
    library's constants)."""
    prior = None if k_s_prior is None else (float(k_s_prior[0]), float(k_s_prior[1]))
    points = None if grid_points is None else int(grid_points)
    if isinstance(log, (str, os.PathLike)):
        # A log's path: the request `infer --servo-log FILE` makes, read and answered in Rust.
        answer, notes = _sandslope.infer_servo_log_file(
            _robot(robot),
            _terrain(terrain),
            os.fspath(log),
            slope_deg=None if slope_deg is None else float(slope_deg),
            k_s_prior=prior,
            grid_points=points,
        )
        answer["notes"] = list(notes)
        return answer
    columns = log
    if slope_deg is None:
        # A DataFrame from `read_servo_log` or `drive` carries its log's header in `attrs`.
        header = getattr(columns, "attrs", {}).get("slope_deg")
        if header is None:
            raise ValueError(
                "slope_deg: give the run's slope (degrees); these columns carry no log header "
                "(a DataFrame from read_servo_log or drive does, in its attrs)"
            )
        try:
            slope_deg = float(header)
        except ValueError:
            raise ValueError(f"slope_deg: the log's header says slope_deg = {header!r}, not a number") from None
    missing = [c for c in SERVO_COLUMNS if c not in columns]
    if missing:
        raise ValueError(f"log: the column(s) {', '.join(missing)} are missing (docs/drive.md, 'The log')")
    answer = _sandslope.infer_servo_log(
        _robot(robot),
        _terrain(terrain),
        float(slope_deg),
        np.ascontiguousarray(columns["leg"], dtype=np.int64),
        np.ascontiguousarray(columns["leg_angle_rad"], dtype=np.float64),
        np.ascontiguousarray(columns["drive_torque_n_m"], dtype=np.float64),
        k_s_prior=prior,
        grid_points=points,
    )
    answer["notes"] = []
    return answer


def drive_defaults() -> Dict[str, Any]:
    """``drive``'s defaults (``sandslope drive``'s flag defaults, from one typed set in the Rust
    crate): ``slope_deg``, ``duration_s``, ``rate_hz``, ``hold_s``, ``current_limit_ma``,
    ``temperature_limit_c``, ``watchdog_s``, ``bus_watchdog_s``, ``stand_s``,
    ``emulate_noise_ma``, ``emulate_seed``, ``live``."""
    return dict(_sandslope.drive_defaults())


def drive(
    robot: RobotLike = "paper-hexapod",
    terrain: TerrainLike = "glass-beads-300um",
    slope_deg: Optional[float] = None,
    duration_s: Optional[float] = None,
    *,
    emulate: bool = True,
    k_s: Optional[float] = None,
    noise_ma: Optional[float] = None,
    seed: Optional[int] = None,
    weaken: Optional[Tuple[float, float]] = None,
    stop_on_risk: Optional[float] = None,
    hold_s: Optional[float] = None,
    rate_hz: Optional[float] = None,
    live: Optional[bool] = None,
    force: Optional[bool] = None,
    window: Optional[int] = None,
    clock: Optional[str] = None,
) -> Tuple[Any, Dict[str, Any]]:
    """A run of ``sandslope drive --emulate`` (docs/drive.md): the robot's alternating tripod
    sent to a bus of emulated XL330s on a pseudo-terminal, byte for byte Protocol 2.0 through
    the same bus code as a robot, the servos' currents from the stride simulator on ``terrain``
    at ``slope_deg`` (``k_s`` overrides the sand's, ``noise_ma`` the current noise's SD, ``seed``
    its seed, ``weaken=(seconds, k_s)`` weakens it mid-run), with ``drive``'s defaults for
    whatever is left out (``drive_defaults()``: the one typed set ``sandslope drive``'s flags
    take theirs from; position profile, the servos' IDs 1 to 6). ``live`` estimates k_s
    after every stance (off by default, as ``drive --live``), pooled over every stance so far
    or the last ``window``; ``stop_on_risk`` halts the gait when the pooled P(fail), the larger
    of the simulator's and the closed form's, passes it. A slope beyond the calibrated safe
    slope is refused unless ``force=True`` (as ``drive --force``; off when left out).
    ``clock`` is the emulator's clock (``drive --emulate-clock``): ``"real"`` (the default: a run
    of S seconds takes S seconds, the driving loop's real timing) or ``"virtual"`` (simulated
    time: the run takes its computing time, for tests and batch runs).

    Returns ``(log, report)``: ``log`` the servo log's columns (a pandas DataFrame, or a dict of
    NumPy arrays without pandas; ``infer_servo_log`` reads it), ``report`` what ``drive --json``
    prints (``outcome``: ``completed``, ``interrupted``, ``halted`` or ``failed``, with
    ``time_s``, and ``p_fail`` or ``error``; ``cycles``, ``rate_hz``, ``cycle_jitter_ms``,
    ``max_cycle_ms``, ``setup``, ``live``: one record per stance,
    ``torque_off``) and ``emulator``, the virtual servos' last word. The run takes
    ``duration_s`` plus a second of wall time on the real clock and releases the GIL; it cannot be interrupted from
    Python. A robot is driven from the command line (``sandslope drive --port``) only."""
    if not emulate:
        raise ValueError(
            "emulate=False: sandslope.drive drives the emulator only; drive a robot with "
            "`sandslope drive --port /dev/ttyUSB0` (its safety exits: Ctrl-C, signals, the log)"
        )
    columns, report = _sandslope.drive(
        _robot(robot),
        _terrain(terrain),
        None if slope_deg is None else float(slope_deg),
        None if duration_s is None else float(duration_s),
        k_s=None if k_s is None else float(k_s),
        noise_ma=None if noise_ma is None else float(noise_ma),
        seed=None if seed is None else int(seed),
        weaken=None if weaken is None else (float(weaken[0]), float(weaken[1])),
        stop_on_risk=None if stop_on_risk is None else float(stop_on_risk),
        hold_s=None if hold_s is None else float(hold_s),
        rate_hz=None if rate_hz is None else float(rate_hz),
        live=None if live is None else bool(live),
        force=None if force is None else bool(force),
        window=None if window is None else int(window),
        clock=None if clock is None else str(clock),
    )
    # `drive --json`'s bus budget: none for the emulator, whose pseudo-terminal is not limited.
    report.setdefault("bus_max_rate_hz", None)
    slope = float(drive_defaults()["slope_deg"] if slope_deg is None else slope_deg)
    return _frame(columns, {"slope_deg": repr(slope)}), report


def read_bag(
    path: Union[str, "os.PathLike[str]"],
    topic: Optional[str] = None,
    *,
    frame: Optional[str] = None,
    joints: Optional[Any] = None,
    effort_unit: str = "n_m",
    legs: int = 6,
    force_axis: Optional[str] = None,
    position_topic: Optional[str] = None,
    position_axis: Optional[str] = None,
) -> Any:
    """Reads a ROS 2 bag (a folder with ``metadata.yaml``, or an ``.mcap`` or ``.db3`` file;
    docs/bags.md) as ``sandslope track`` and ``sandslope infer --servo-log`` read it, into a
    pandas DataFrame (a dict of NumPy columns without pandas):

    - a pose topic (``geometry_msgs/PoseStamped``, ``nav_msgs/Odometry``,
      ``geometry_msgs/TransformStamped``, ``tf2_msgs/TFMessage`` with ``frame`` the child
      frame): the plain motion-capture columns ``time_s, x_m, y_m, z_m``, on the regular grid
      of frames ``track`` analyses (NaN where no position); ``df.attrs["body"]`` names it;
    - a ``sensor_msgs/JointState`` topic: the servo log's columns (``leg``,
      ``leg_angle_rad``, ``drive_torque_n_m``, ...), ``joints`` the joint names in leg order,
      ``effort_unit`` ``"n_m"``, ``"a"`` or ``"ma"``, ``legs`` the robot's 2 * stance_legs;
      ``df.attrs["notes"]`` says how the joints were mapped;
    - a ``geometry_msgs/WrenchStamped`` topic: a ``fit`` trial's columns ``time_s,
      position_m, force_n`` (the force along ``force_axis``, required: ``"z"``, ``"-z"``,
      ...; the intruder's travel on ``position_topic``, with ``frame`` and
      ``position_axis``, as a bag trial's manifest keys say); ``df.attrs["body"]`` names the
      position's topic;
    - no ``topic``: the bag's topics (``name, type, encoding, messages``).

    Errors (a ValueError) name the file, the topic and where in the file."""
    p = os.fspath(path)
    if topic is None:
        rows = _sandslope.bag_topics(p)
        cols = {k: [r[i] for r in rows] for i, k in enumerate(("name", "type", "encoding", "messages"))}
        return _frame(cols)
    kinds = {name: typ for name, typ, _, _ in _sandslope.bag_topics(p)}
    if kinds.get(topic, "").replace("/msg/", "/") == "sensor_msgs/JointState":
        names = None if joints is None else [str(j) for j in joints]
        columns, notes = _sandslope.read_bag_joints(p, int(legs), topic, names, str(effort_unit))
        df = _frame(columns)
        if hasattr(df, "attrs"):
            df.attrs["notes"] = notes
        return df
    if kinds.get(topic, "").replace("/msg/", "/") == "geometry_msgs/WrenchStamped":
        if force_axis is None:
            raise ValueError(
                f"topic `{topic}` is a WrenchStamped: give force_axis, the force component that the sand's "
                "resistance makes grow (\"z\", \"-z\", \"x\", ...)"
            )
        columns, body = _sandslope.read_bag_load_cell(p, force_axis, topic, position_topic, frame, position_axis)
    else:
        columns, body = _sandslope.read_bag_poses(p, topic, frame)
    df = _frame(columns)
    if hasattr(df, "attrs"):
        df.attrs["body"] = body
    return df
