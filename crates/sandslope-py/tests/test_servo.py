"""The robot in the loop from Python (docs/drive.md): `sandslope.drive` runs the emulated
XL330s through the same pty and bus code as `sandslope drive --emulate`, `infer_servo_log`
returns what `infer --servo-log --json` prints, and bad input is a ValueError naming the
argument."""

import re
import math

import numpy as np
import pytest

import sandslope

# The paper-hexapod's leg speed: one turn per second (the robot file's leg_speed, the paper's).
OMEGA = 2 * math.pi


def _columns(log):
    return {k: np.asarray(log[k]) for k in ("time_s", "leg", "tripod", "leg_angle_rad", "drive_torque_n_m")}


@pytest.fixture(scope="module")
def run():
    # 3 s at 20 deg on emulated sand of k_s = 2.5e5 N/m^3 (docs/drive.md's worked example).
    # On the virtual clock: the run's timing is simulated, so it takes its computing time.
    return sandslope.drive(slope_deg=20, duration_s=3, k_s=2.5e5, seed=1, live=True, clock="virtual")


def test_drive_runs_the_gait_and_turns_the_torque_off(run):
    log, report = run
    c = _columns(log)
    # The outcome flat, not a Rust Result's {'Ok': ...} (issue 54).
    assert report["outcome"] == "completed", report["outcome"]
    assert "Ok" not in report and report["time_s"] >= 3.0
    assert report["torque_off"]["confirmed"] == [1, 2, 3, 4, 5, 6]
    assert report["emulator"].startswith("emulator: torque off on every servo")
    # Every leg turns at the robot file's omega once walking (a least-squares slope of its
    # angle over the gait, after the run-up): within 1%, the tolerance.
    walking = c["time_s"] > 0.5
    for leg in range(6):
        m = walking & (c["leg"] == leg)
        slope = np.polyfit(c["time_s"][m], c["leg_angle_rad"][m], 1)[0]
        assert abs(slope - OMEGA) < 0.01 * OMEGA, (leg, slope)
    # Tripod 1 follows tripod 0 by half a period: half a turn, pi, behind at the same time.
    t0 = c["time_s"][walking & (c["leg"] == 0)]
    a0 = c["leg_angle_rad"][walking & (c["leg"] == 0)]
    a1 = c["leg_angle_rad"][walking & (c["leg"] == 1)]
    assert set(c["tripod"][c["leg"] == 1]) == {1}
    lag = np.median(a0 - a1[: len(a0)])
    assert abs(abs(lag) - math.pi) < 0.05 * math.pi, lag
    # One live estimate per stance: two tripods, one stance each per 1 s period, after the
    # first stride; about 4 in 3 s.
    assert 2 <= len(report["live"]) <= 6, len(report["live"])
    assert len(t0) > 100


def test_infer_servo_log_equals_the_cli_on_the_same_log(cli, tmp_path):
    path = tmp_path / "run.csv"
    cli.run("drive", "--emulate", "--slope", "20", "--emulate-k-s", "2.5e5", "--duration", "4",
            "--watchdog", "2", "--emulate-clock", "virtual", "--log", path)
    expected = cli.json("infer", "--servo-log", path, "--grid-points", "9", "--k-s-prior", "3e4:3e7")
    got = sandslope.infer_servo_log(path, grid_points=9, k_s_prior=(3e4, 3e7))
    assert sorted(got) == sorted(expected)
    for key in ("k_s", "k_s_lo", "k_s_hi", "p_fail", "shear_load_n", "strides"):
        assert got[key] == pytest.approx(expected[key], rel=1e-12), key
    # The same from the log's columns, the slope given.
    log, meta = sandslope.read_servo_log(path)
    assert float(meta["slope_deg"]) == 20.0
    again = sandslope.infer_servo_log(log, slope_deg=20, grid_points=9, k_s_prior=(3e4, 3e7))
    assert again["k_s"] == pytest.approx(expected["k_s"], rel=1e-12)
    # The slope left out: the DataFrame carries the log's header (issue 58).
    if hasattr(log, "attrs"):
        header = sandslope.infer_servo_log(log, grid_points=9, k_s_prior=(3e4, 3e7))
        assert header["k_s"] == pytest.approx(expected["k_s"], rel=1e-12)
    # The emulated sand's k_s inside the 90% interval (docs/drive.md: 3 of 3 seeds).
    assert got["k_s_lo"] <= 2.5e5 <= got["k_s_hi"], got
    # A clean log: nothing repaired; columns passed in: nothing read, nothing repaired.
    # (A time gap is a slow cycle of the emulated run on a loaded machine, recorded truly, not
    # damage: the one note allowed, as in crates/sandslope-cli/tests/drive.rs.)
    assert [n for n in got["notes"] if "gap(s) in time" not in n] == [] and again["notes"] == []
    # A messy one: two rows written twice and the last row cut mid-way. The reader says so in
    # `notes`, the same list as the CLI's `--json`.
    lines = path.read_text().splitlines(keepends=True)
    body = [i for i, l in enumerate(lines) if not l.startswith("#")][1:]
    messy = lines[: body[200]] + [lines[body[200]], lines[body[201]]] + lines[body[200]:]
    messy[-1] = messy[-1][: len(messy[-1]) // 2]
    messy_path = tmp_path / "messy.csv"
    messy_path.write_text("".join(messy))
    expected = cli.json("infer", "--servo-log", messy_path, "--grid-points", "9", "--k-s-prior", "3e4:3e7")
    got = sandslope.infer_servo_log(messy_path, grid_points=9, k_s_prior=(3e4, 3e7))
    assert got["notes"] == expected["notes"]
    # (A time gap, a slow cycle of the emulated run on a loaded machine, may be noted beside.)
    assert len([n for n in got["notes"] if "gap(s) in time" not in n]) == 2, got["notes"]
    assert any("2 repeated row(s)" in n for n in got["notes"]), got["notes"]
    assert any("ends mid-row" in n for n in got["notes"]), got["notes"]


def test_bad_input_names_the_argument(run):
    log, _ = run
    c = _columns(log)
    with pytest.raises(ValueError, match="one length"):
        sandslope.infer_servo_log({"leg": c["leg"], "leg_angle_rad": c["leg_angle_rad"][:-1],
                                   "drive_torque_n_m": c["drive_torque_n_m"]}, slope_deg=20)
    bad = dict(c)
    bad["leg"] = c["leg"].copy()
    bad["leg"][5] = 6
    with pytest.raises(ValueError, match=r"leg\[5\] = 6: the robot has 6 legs"):
        sandslope.infer_servo_log(bad, slope_deg=20, grid_points=3)
    with pytest.raises(ValueError, match="drive_torque_n_m are missing"):
        sandslope.infer_servo_log({"leg": c["leg"], "leg_angle_rad": c["leg_angle_rad"]}, slope_deg=20)
    with pytest.raises(ValueError, match="slope_deg"):
        sandslope.infer_servo_log(c)
    with pytest.raises(ValueError, match="emulator only"):
        sandslope.drive(emulate=False)
    with pytest.raises(ValueError, match="stop_on_risk = 1.5 must be between 0 and 1"):
        sandslope.drive(stop_on_risk=1.5)
    with pytest.raises(ValueError, match="k_s"):
        sandslope.drive(k_s=-1.0)
    # The clock's two words are the drive table's `--emulate-clock` row's, named with the keyword.
    with pytest.raises(ValueError, match=r'clock = "wall" must be one of: real, virtual'):
        sandslope.drive(clock="wall")


def test_drive_releases_the_gil():
    from test_gil import assert_releases_the_gil

    assert_releases_the_gil(lambda: sandslope.drive(duration_s=1, live=False))


# `sandslope drive --help`'s flag for each of drive_defaults()'s keys (stand_s has no flag).
_FLAGS = {
    "slope_deg": "--slope", "duration_s": "--duration", "rate_hz": "--rate", "hold_s": "--hold",
    "current_limit_ma": "--current-limit", "temperature_limit_c": "--temperature-limit",
    "watchdog_s": "--watchdog", "bus_watchdog_s": "--bus-watchdog",
    "emulate_noise_ma": "--emulate-noise", "emulate_seed": "--emulate-seed",
}


def _help_default(help_text, flag):
    # clap renders `--rate <HZ>  ... [default: 50]`; the block of one flag runs to the next flag.
    # The help may wrap inside the brackets ("[default:" at a line's end, the value on the next).
    block = help_text.split(f"  {flag} ")[1].split("\n  -")[0]
    return float(re.search(r"\[default:\s+([^\]\s]+)\]", block).group(1))


def test_drive_defaults_are_the_clis(cli):
    """Python's defaults are the CLI's, read from the CLI's own help, not restated."""
    defaults = sandslope.drive_defaults()
    assert set(defaults) == set(_FLAGS) | {"stand_s", "live"}
    help_text = cli.run("drive", "--help").stdout
    for key, flag in _FLAGS.items():
        assert defaults[key] == _help_default(help_text, flag), key
    # `--live` is a flag: off unless given, so Python's default must be off too.
    assert defaults["live"] is False
    # And the Python function's signature states none of them.
    import inspect
    for name, p in inspect.signature(sandslope.drive).parameters.items():
        if name not in ("robot", "terrain", "emulate"):
            assert p.default is None, (name, p.default)
    for name in ("k_s_prior", "grid_points"):
        assert inspect.signature(sandslope.infer_servo_log).parameters[name].default is None


def test_drive_returns_the_keys_of_drive_json(cli, tmp_path):
    """`sandslope.drive`'s report has the keys `drive --emulate --json` prints, at every level
    (outcome, live record, inference, torque_off)."""
    expected = cli.json("drive", "--emulate", "--slope", "20", "--duration", "3", "--live",
                        "--watchdog", "2", "--emulate-clock", "virtual")
    _, got = sandslope.drive(slope_deg=20, duration_s=3, live=True, clock="virtual")

    def shape(v):
        if isinstance(v, dict):
            return {k: shape(x) for k, x in v.items() if k != "posterior"}
        if isinstance(v, list):
            return [shape(v[0])] if v and isinstance(v[0], dict) else "list"
        return "value"

    assert shape(got) == shape(expected)
    assert got["emulator"].startswith("emulator: torque off on every servo")
