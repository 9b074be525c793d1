"""Robot and Terrain: construction, files, presets, repr, dicts, equality, pickling, errors."""

import copy
import errno
import pickle

import pytest

import sandslope
from sandslope import Robot, Terrain

PAPER = dict(
    mass_kg=0.35,
    leg_radius_m=0.04,
    leg_width_m=0.01,
    hip_height_m=0.03,
    leg_speed_rad_s=6.283185307179586,
    stance_legs=3,
    response_time_s=0.2,
)


def test_keywords_build_the_preset_robot(robot):
    assert Robot(**PAPER) == robot
    assert robot.to_dict() == PAPER
    assert robot.mass_kg == 0.35
    # 2R - h = 0.08 - 0.03; s_min defaults to R.
    assert robot.max_depth_m == pytest.approx(0.05, rel=1e-12)
    assert robot.min_step_m == 0.04


def test_optional_keys_round_trip():
    r = Robot(**PAPER, level_step_m=0.07, min_step_m=0.03)
    assert r.to_dict()["level_step_m"] == 0.07
    assert Robot(**r.to_dict()) == r
    assert r != Robot(**PAPER)
    assert "level_step_m=0.07" in repr(r)


def test_repr_is_readable_and_evaluates_back(robot, terrain):
    assert repr(robot).startswith("Robot(mass_kg=0.35, leg_radius_m=0.04,")
    assert eval(repr(robot), {"Robot": Robot}) == robot
    assert eval(repr(terrain), {"Terrain": Terrain}) == terrain
    assert 'name="glass-beads-300um"' in repr(terrain) and "repose_deg=25.0" in repr(terrain)


@pytest.mark.parametrize("protocol", [2, pickle.HIGHEST_PROTOCOL])
def test_pickle_round_trip(robot, terrain, protocol):
    for obj in (robot, terrain, Robot(**PAPER, min_step_m=0.03), Terrain.constant(7e5, 2e6)):
        back = pickle.loads(pickle.dumps(obj, protocol=protocol))
        assert back == obj and type(back) is type(obj)
    assert copy.deepcopy(terrain) == terrain


def test_terrain_keywords_and_lookup():
    t = Terrain(points=[{"slope_deg": 20, "k_n": 6e5, "k_s": 1e6}, {"slope_deg": 0, "k_n": 7e5, "k_s": 2e6}],
                repose_deg=25, name="two")
    # Points come back sorted; halfway between them the values are the means (docs/model.md §7).
    assert [p["slope_deg"] for p in t.to_dict()["points"]] == [0.0, 20.0]
    at = t.at(10)
    assert at["k_n"] == pytest.approx(6.5e5) and at["k_s"] == pytest.approx(1.5e6)
    assert not at["extrapolated"] and at["k_n_sd"] is None
    # Beyond the last point: extrapolated linearly (-5e4 per degree), flagged.
    beyond = t.at(24)
    assert beyond["k_s"] == pytest.approx(8e5) and beyond["extrapolated"]
    assert t.repose_deg == 25 and t.name == "two"


def test_files_and_presets(tmp_path, robot):
    f = tmp_path / "r.toml"
    f.write_text("\n".join(f"{k} = {v}" for k, v in PAPER.items()))
    assert Robot.from_toml(f) == robot
    assert sandslope.presets()["paper-hexapod"]["kind"] == "robot"
    assert sandslope.presets()["glass-beads-300um"]["kind"] == "terrain"
    # Preset names and paths are accepted wherever a robot or terrain is, as on the CLI.
    p = sandslope.predict(str(f), 10, terrain="glass-beads-300um")
    assert sandslope.REGIMES[int(p["regime"])] == "success"


def test_file_or_preset_follows_the_cli_rule(tmp_path, monkeypatch, cli):
    """A name is a file when it exists or ends in .toml, else a preset (sandslope-io's rule,
    the one the command line applies), and an unknown name gets the CLI's message."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "paper-hexapod").write_text("\n".join(f"{k} = {v}" for k, v in {**PAPER, "mass_kg": 0.9}.items()))
    assert Robot.load("paper-hexapod").mass_kg == 0.9  # the file, which shadows the preset
    assert Robot.load(tmp_path / "paper-hexapod") == Robot.load("paper-hexapod")
    (tmp_path / "paper-hexapod").unlink()
    assert Robot.load("paper-hexapod") == Robot.preset("paper-hexapod")
    with pytest.raises(ValueError) as e:
        sandslope.predict("no-such-robot", 10)
    assert str(e.value) == cli.error("predict", "--slope", "10", "--robot", "no-such-robot")
    with pytest.raises(FileNotFoundError, match="cannot read missing.toml") as e:
        Terrain.load("missing.toml")  # ends in .toml: a file, and it is not there
    assert not isinstance(e.value, ValueError) and e.value.errno == errno.ENOENT


def test_errors_carry_the_cli_message(tmp_path, cli):
    bad = tmp_path / "bad.toml"
    bad.write_text("\n".join(f"{k} = {v}" for k, v in {**PAPER, "hip_height_m": 0.09}.items()))
    with pytest.raises(ValueError) as e:
        Robot.from_toml(bad)
    assert str(e.value) == cli.error("predict", "--slope", "10", "--robot", bad)
    assert "hip_height_m = 0.09" in str(e.value) and str(bad) in str(e.value)

    unknown = tmp_path / "unknown.toml"
    unknown.write_text("\n".join(f"{k} = {v}" for k, v in {**PAPER, "mass": 1}.items()))
    with pytest.raises(ValueError) as e:
        Robot.from_toml(unknown)
    assert str(e.value) == cli.error("predict", "--slope", "10", "--robot", unknown)
    assert "unknown field `mass`" in str(e.value)

    with pytest.raises(ValueError, match=r"^hip_height_m = 0.09 must be between 0 and 2 \* leg_radius_m"):
        Robot(**{**PAPER, "hip_height_m": 0.09})
    with pytest.raises(ValueError, match="missing field `stance_legs`"):
        Robot(**{k: v for k, v in PAPER.items() if k != "stance_legs"})
    with pytest.raises(ValueError, match=r"points\[0\]\.k_n = -1 must be"):
        Terrain(points=[{"slope_deg": 0, "k_n": -1, "k_s": 1}])
    with pytest.raises(ValueError, match="not a built-in robot .built-in: paper-hexapod"):
        Robot.preset("nope")
    with pytest.raises(ValueError, match="mass_kg = 0 must be"):
        Robot(**PAPER).with_mass(0)
    with pytest.raises(FileNotFoundError, match="cannot read"):
        Terrain.from_toml(tmp_path / "missing.toml")
    with pytest.raises(FileNotFoundError, match="cannot read"):
        Robot.from_toml(tmp_path / "missing.toml")
    with pytest.raises(FileNotFoundError):
        sandslope.report(observed=tmp_path / "missing.csv")
