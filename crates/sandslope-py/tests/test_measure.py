"""fit and track on the repository's example recordings, against the CLI's JSON."""

import numpy as np
import pandas as pd
import pytest

import sandslope

MANIFEST = "examples/measurements/manifest.toml"
TRACKING = "examples/tracking"


def test_fit_matches_cli(cli, root):
    want = cli.json("fit", MANIFEST, "--counts-per-newton", 2000)
    got = sandslope.fit(root / MANIFEST, counts_per_newton=2000)
    assert isinstance(got["points"], pd.DataFrame) and isinstance(got["trials"], pd.DataFrame)
    assert len(got["points"]) == len(want["points"]) and len(got["trials"]) == len(want["trials"])
    for i, w in enumerate(want["points"]):
        row = got["points"].iloc[i]
        assert row["slope_deg"] == w["slope_deg"]
        for key in ("k_n", "k_s", "k_n_sd", "k_s_sd", "trials_penetration", "trials_shear"):
            assert row[key] == pytest.approx(w[key], rel=1e-12), (i, key)
    # Nested fields of the trials become dotted columns.
    assert got["trials"]["dropped.malformed"].sum() == sum(t["dropped"]["malformed"] for t in want["trials"])
    # The fitted terrain is a Terrain whose points are the per-slope means.
    t = got["terrain"]
    assert isinstance(t, sandslope.Terrain)
    pts = t.to_dict()["points"]
    np.testing.assert_allclose([p["k_n"] for p in pts], [w["k_n"] for w in want["points"]], rtol=1e-12)
    p = sandslope.predict("paper-hexapod", 12, terrain=t)
    assert p["speed_m_s"] > 0


def test_fit_errors(root, tmp_path):
    with pytest.raises(ValueError, match="depth_window = \\(0.03, 0.005\\) must be"):
        sandslope.fit(root / MANIFEST, depth_window=(0.03, 0.005))
    with pytest.raises(FileNotFoundError, match="cannot read"):
        sandslope.fit(tmp_path / "none.toml")  # a missing file, as Python's open says it
    with pytest.raises(ValueError, match='air = "both" must be'):
        sandslope.fit(root / MANIFEST, air="both")


def test_track_matches_cli(cli, root):
    files = [f"{TRACKING}/slope20-vicon.csv"]
    lines = (root / TRACKING / "slope20-touchdowns.txt").read_text().splitlines()
    touchdowns = [float(x) for x in lines if x.strip() and not x.startswith("#")]
    want = cli.json("track", *files, "--touchdowns", f"{TRACKING}/slope20-touchdowns.txt", "--slope", 20)
    got = sandslope.track([root / f for f in files], 20, touchdowns=[touchdowns])
    for key in ("speed_m_s", "speed_sd_m_s", "t1_s", "slip_m", "step_m", "steps", "period_s"):
        assert got[key] == pytest.approx(want[key], rel=1e-12), key
    assert isinstance(got["per_step"], pd.DataFrame) and len(got["per_step"]) == want["steps"]
    np.testing.assert_allclose(got["per_step"]["speed_m_s"], [s["speed_m_s"] for s in want["per_step"]], rtol=1e-12)
    assert got["recordings"]["format"][0] == "vicon"
    # The same keys as --json, down to each step's and recording's (one answer, issue 40).
    assert set(got) == set(want)
    assert list(got["per_step"].columns) == list(want["per_step"][0])
    assert list(got["recordings"].columns) == list(want["recordings"][0])
    # The paper's 4.98 cm/s at 20 degrees (examples/tracking/truth.csv), to within the noise.
    assert got["speed_m_s"] == pytest.approx(0.0498, abs=0.003)


def test_track_estimated_touchdowns_and_bodies(cli, root):
    f = root / TRACKING / "slope10-motive123.csv"
    want = cli.json("track", f, "--body", "robot", "--slope", 10)
    got = sandslope.track(f, 10, body="robot")
    assert got["speed_m_s"] == pytest.approx(want["speed_m_s"], rel=1e-12)
    assert got["recordings"]["touchdowns"][0] == "estimated"
    with pytest.raises(ValueError, match="(?i)body"):
        sandslope.track(f, 10)
    with pytest.raises(ValueError, match="cutoff_hz = -1 must be"):
        sandslope.track(f, 10, body="robot", cutoff_hz=-1)


def test_track_leg_speed_is_the_cli_leg_speed_override(cli, root):
    """`leg_speed_rad_s` replaces the robot's leg speed as `track --leg-speed` does: the stride
    period is 2 pi / omega (3 rad/s: 2.0944 s, worked out by hand) and the answer the CLI's."""
    f = root / TRACKING / "slope10-motive123.csv"
    want = cli.json("track", f, "--body", "robot", "--slope", 10, "--leg-speed", 3)
    got = sandslope.track(f, 10, body="robot", leg_speed_rad_s=3)
    assert got["period_s"] == pytest.approx(2.0943951023931953, rel=1e-15)
    for key in ("period_s", "speed_m_s", "steps", "t1_s"):
        assert got[key] == pytest.approx(want[key], rel=1e-12), key
    message = cli.error("track", f, "--body", "robot", "--slope", 10, "--leg-speed", 0)
    with pytest.raises(ValueError) as e:
        sandslope.track(f, 10, body="robot", leg_speed_rad_s=0)
    assert str(e.value) == message.replace("--leg-speed", "leg_speed_rad_s")
