"""The Python functions of fit, calibrate, report, risk and phase take the request layer's field
tables: each keyword a table gives Python is a parameter of the function (of ``fit``,
``calibrate`` and ``report`` every one), with the table's default, in the public function and
in the compiled core's stub alike, so the command line's flags and Python's keywords cannot
drift apart."""

import inspect
import os
import re

import pytest

import sandslope
from sandslope import _sandslope

# (table, public function, its parameters that are no field of the table, whether every
# keyword of the table must be a parameter).
CASES = [
    ("fit", "fit", {"manifest", "air"}, True),
    ("calibrate", "calibrate", {"robot", "terrain"}, True),
    ("report", "report", {"robot", "terrain", "html"}, True),
    ("risk", "risk", {"robot", "terrain"}, False),
    ("risk", "risk_map", {"robot", "terrain", "mass_kg"}, False),
    ("risk", "safe_slope", {"robot", "terrain"}, False),
    ("risk", "safe_mass", {"robot", "terrain"}, False),
    ("risk", "payload_envelope", {"robot", "terrain"}, False),
    ("phase", "phase", {"robot", "terrain", "repose_deg", "regime_only"}, False),
]

# fit's `air` keyword is the two switches --air-curve and --air-mean in one word.
AIR = {"auto": set(), "curve": {"air-curve"}, "mean": {"air-mean"}}


def table_default(default, kind):
    """A table's default as Python writes it."""
    if kind == "switch":
        return False
    if default is None:
        return None
    if kind == "number":
        return float(default)
    if kind == "whole":
        return int(default)
    return default


def same_default(python, table):
    # An empty sequence is Python's way of giving no list (calibrate's `free=()`).
    if table is None and python in ((), []):
        return True
    return python == table


def stub_defaults(name):
    """The stub's parameters of `_sandslope.NAME` with the text of their defaults."""
    stub = open(os.path.join(os.path.dirname(sandslope.__file__), "_sandslope.pyi")).read()
    body = re.search(rf"\ndef {name}\((.*?)\) ->", stub, re.S).group(1)
    out = {}
    for part in re.split(r",\s*(?![^\[]*\])", body):
        m = re.match(r"\s*(\w+)\s*:[^=]*?(?:=\s*(.+?))?\s*$", part, re.S)
        if m:
            out[m.group(1)] = m.group(2)
    return out


@pytest.mark.parametrize("command,name,extras,every", CASES, ids=[c[1] for c in CASES])
def test_python_keywords_are_the_tables(command, name, extras, every):
    rows = {k: table_default(d, kind) for k, d, kind in _sandslope.request_keywords(command)}
    params = inspect.signature(getattr(sandslope, name)).parameters
    for keyword, param in params.items():
        assert keyword in rows or keyword in extras, f"{name}: {keyword} is no field of {command}'s table"
        if keyword in rows and param.default is not inspect.Parameter.empty:
            assert same_default(param.default, rows[keyword]), (name, keyword, param.default, rows[keyword])
    if every:
        assert set(rows) <= set(params), f"{name} lacks {set(rows) - set(params)}"
    # The compiled core's stub writes the same defaults.
    for keyword, text in stub_defaults(name).items():
        if keyword in rows and text is not None and text != "...":
            assert same_default(eval(text), rows[keyword]), (name, keyword, text, rows[keyword])


def test_the_max_risk_default_is_the_tables():
    rows = {k: d for k, d, _ in _sandslope.request_keywords("risk")}
    assert float(rows["max_risk"]) == _sandslope.DEFAULT_MAX_RISK == 0.05
    report = {k: d for k, d, _ in _sandslope.request_keywords("report")}
    assert report["max_risk"] == rows["max_risk"]


def test_fit_air_words():
    assert list(AIR) == ["auto", "curve", "mean"]
    assert inspect.signature(sandslope.fit).parameters["air"].default == "auto"
    with pytest.raises(ValueError, match=r'air = "both" must be "auto", "curve" or "mean"'):
        sandslope.fit("no-such-manifest.toml", air="both")


def test_python_drive_takes_drives_table():
    """``sandslope.drive``'s keywords are drive's table's (besides the robot, the terrain, the
    bus choice and the live switch), each None for the table's default, which
    ``drive_defaults()`` gives: the numbers the command line's flags default to."""
    rows = {k: table_default(d, kind) for k, d, kind in _sandslope.request_keywords("drive")}
    params = inspect.signature(sandslope.drive).parameters
    for keyword, param in params.items():
        assert keyword in rows or keyword in {"robot", "terrain", "emulate", "live"}, keyword
        if keyword in rows:
            assert param.default is None, (keyword, param.default)
    for keyword, text in stub_defaults("drive").items():
        if keyword in rows:
            assert text == "None", (keyword, text)
    defaults = sandslope.drive_defaults()
    for keyword in ["slope_deg", "duration_s", "rate_hz", "hold_s", "current_limit_ma", "temperature_limit_c",
                    "watchdog_s", "bus_watchdog_s"]:
        assert defaults[keyword] == rows[keyword], keyword
    assert defaults["emulate_noise_ma"] == rows["noise_ma"] and str(defaults["emulate_seed"]) == rows["seed"]


def test_python_plan_takes_plans_table():
    """``sandslope.plan``'s keywords with a default of the table's carry it (``objective``,
    the table's ``objectives``, a word or a list of them; ``descent``, ``max_roll_deg``,
    ``time_weight``, ``allow_metastable``)."""
    rows = {k: table_default(d, kind) for k, d, kind in _sandslope.request_keywords("plan")}
    params = inspect.signature(sandslope.plan).parameters
    assert params["objective"].default == rows["objectives"] == "time"
    for keyword in ["descent", "max_roll_deg", "time_weight", "allow_metastable", "cv_n", "cv_s"]:
        assert same_default(params[keyword].default, rows[keyword]), keyword
