"""The paper reproduced and confronted (``sandslope report``). Imported into ``sandslope``; the
name is ``sandslope.report``."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Optional, Sequence, Union

from . import _sandslope
from ._inputs import RobotLike, TerrainLike, _robot, _source, _terrain

_PathLike = Union[str, "os.PathLike[str]"]


def report(
    robot: RobotLike = "paper-hexapod",
    terrain: TerrainLike = "glass-beads-300um",
    *,
    observed: Optional[_PathLike] = None,
    forces: Optional[_PathLike] = None,
    t1: Optional[_PathLike] = None,
    tracks: Optional[Dict[float, Union[_PathLike, Sequence[_PathLike]]]] = None,
    tracks_format: Optional[str] = None,
    tracks_body: Optional[str] = None,
    tracks_upslope: Optional[Sequence[float]] = None,
    max_risk: float = _sandslope.DEFAULT_MAX_RISK,
    simulator_fit: bool = False,
    html: Optional[_PathLike] = None,
) -> Dict[str, Any]:
    """The paper reproduced and confronted (``sandslope report``), as ``report.json``'s dict.

    On the defaults it is the paper's own evidence: its five speeds, the built-in terrain and
    the paper's force tests as its text reports them. ``observed`` (speeds CSV), ``forces`` (a
    terrain file with ``k_s_sd``), ``t1`` (anchoring-time CSV) and ``tracks``
    (``{slope_deg: path or [paths]}`` of motion-capture recordings, read as :func:`track` reads
    them) make it a report on your own campaign, as the CLI's flags of the same names.
    ``simulator_fit=True`` (``report --simulator-fit``) adds the stride simulator's joint fit of
    the same evidence (``simulator_fit``; about 8 minutes of CPU on the paper's evidence, docs/calibration.md).
    ``html="out/"`` also writes the page into that folder (made if missing): ``out/index.html``
    and ``out/report.json``, byte for byte what ``sandslope report --out out/`` writes for the
    same inputs.

    Returns exactly the keys and values of ``report.json`` (docs/commands.md, ``sandslope report``): ``figures``,
    ``speeds``, ``tracks``, ``calibration``, ``paper_vs_model``, ``disagreements``, ``inputs``.
    """
    track_list = None
    if tracks is not None:
        track_list = []
        for slope, paths in tracks.items():
            if isinstance(paths, (str, os.PathLike)):
                paths = [paths]
            track_list.append((float(slope), [os.fspath(p) for p in paths]))
    text = _sandslope.report(
        _robot(robot),
        _terrain(terrain),
        _source(robot, "a sandslope.Robot"),
        _source(terrain, "a sandslope.Terrain"),
        observed=None if observed is None else os.fspath(observed),
        forces=None if forces is None else os.fspath(forces),
        t1=None if t1 is None else os.fspath(t1),
        tracks=track_list,
        tracks_format=tracks_format,
        tracks_body=tracks_body,
        tracks_upslope=None if tracks_upslope is None else [float(v) for v in tracks_upslope],
        max_risk=float(max_risk),
        simulator_fit=bool(simulator_fit),
        html=None if html is None else os.fspath(html),
    )
    return json.loads(text)
