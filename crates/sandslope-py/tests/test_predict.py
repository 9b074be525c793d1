"""predict: values against the CLI and by hand, NumPy broadcasting, NaN for null, errors."""

import math

import numpy as np
import pytest

import sandslope

KEYS = ["slope_deg", "k_n", "k_s", "d_n_m", "level_step_m", "d_s_m", "t1_s", "slip_m", "propulsion_m",
        "step_m", "speed_m_s", "model_speed_m_s", "k_s_margin", "critical_k_s_progress", "critical_k_s_robust"]


def same(a, b):
    """Equal to the last bits of a decimal round trip (the CLI prints shortest round-trip floats)."""
    if b is None:
        return math.isnan(a)
    return a == pytest.approx(b, rel=1e-13, abs=0)


def test_regimes_contract():
    assert sandslope.REGIMES == ("sinkage", "slippage", "metastable", "success")
    # The field engineer's words of docs/model.md §6, one per regime, in the same order.
    assert sandslope.OUTCOMES == ("sinks", "slides back", "climbs slowly and may stall", "climbs steadily")
    assert "OUTCOMES" in dir(sandslope)


@pytest.mark.parametrize("slope", [0, 7.5, 20, 24, -12, 26, 40])
def test_terrain_lookup_matches_cli(cli, robot, terrain, slope):
    want = cli.json("predict", "--slope", slope)
    got = sandslope.predict(robot, slope, terrain=terrain)
    for k in KEYS:
        assert same(float(got[k]), want[k]), k
    assert sandslope.REGIMES[int(got["regime"])] == want["regime"]
    assert sandslope.CAUSES[int(got["cause"])] == want["cause"]
    assert bool(got["extrapolated"]) == want["extrapolated"]


def test_overrides_and_mass_match_cli(cli, robot, terrain):
    want = cli.json("predict", "--slope", 15, "--mass", 1.0, "--k-s", 8e5)
    got = sandslope.predict(robot, 15, k_s=8e5, terrain=terrain, mass_kg=1.0)
    for k in KEYS:
        assert same(float(got[k]), want[k]), k


def test_hand_worked_twenty_degrees(robot):
    # docs/model.md worked example (crates/sandslope/src/model.rs): 20 deg, k_n 7e5, k_s 1e6.
    p = sandslope.predict(robot, 20, 7e5, 1e6)
    assert float(p["d_s_m"]) == pytest.approx(7.33519e-3, rel=1e-5)
    assert float(p["t1_s"]) == pytest.approx(0.0296045, rel=1e-5)
    assert float(p["step_m"]) == pytest.approx(0.0217682, rel=1e-5)
    assert float(p["speed_m_s"]) == pytest.approx(0.0435363, rel=1e-5)
    assert sandslope.REGIMES[int(p["regime"])] == "metastable"
    assert sandslope.CAUSES[int(p["cause"])] == "short_step"


def test_broadcasting_follows_numpy(robot):
    slopes = np.array([[0.0], [10.0], [22.0]])  # (3, 1)
    k_s = np.geomspace(5e3, 5e6, 4)  # (4,)
    p = sandslope.predict(robot, slopes, 7e5, k_s)
    assert p["speed_m_s"].shape == (3, 4) and p["regime"].dtype == np.int8
    for i in range(3):
        for j in range(4):
            one = sandslope.predict(robot, float(slopes[i, 0]), 7e5, float(k_s[j]))
            for k in KEYS + ["regime"]:
                a, b = p[k][i, j], one[k]
                assert (a == b) or (np.isnan(a) and np.isnan(b)), (k, i, j)
    # Scalars give 0-d arrays; a mass array broadcasts too.
    assert sandslope.predict(robot, 10, 7e5, 1e6)["step_m"].shape == ()
    heavy = sandslope.predict(robot, 10, 7e5, 1e6, mass_kg=[0.35, 1.0, 3.0])
    assert heavy["d_n_m"].shape == (3,)
    # d_n grows in proportion to the mass.
    assert heavy["d_n_m"][1] / heavy["d_n_m"][0] == pytest.approx(1.0 / 0.35)
    with pytest.raises(ValueError, match="cannot be broadcast"):
        sandslope.predict(robot, [1, 2, 3], 7e5, [1e6, 2e6])


def test_null_is_nan(robot):
    # Below the anchoring threshold k_s = F_a / (W d_max^2) = 5864.3 on level sand: no anchoring.
    p = sandslope.predict(robot, 0, 7e5, 5000)
    assert sandslope.CAUSES[int(p["cause"])] == "no_anchoring"
    for k in ["t1_s", "slip_m", "propulsion_m", "step_m", "speed_m_s"]:
        assert np.isnan(p[k]), k
    assert not np.isnan(p["d_s_m"])


def test_errors_carry_the_cli_message(cli, robot, terrain):
    with pytest.raises(ValueError) as e:
        sandslope.predict(robot, 95, terrain=terrain)
    assert str(e.value) == cli.error("predict", "--slope", "95").replace("--slope", "slope_deg")
    with pytest.raises(ValueError, match=r"^slope_deg\[2\] = 95 must be strictly between -90 and 90 degrees$"):
        sandslope.predict(robot, [0, 10, 95], terrain=terrain)
    with pytest.raises(ValueError, match=r"^k_s\[1\] = -1 must be a finite number greater than 0$"):
        sandslope.predict(robot, 10, 7e5, [1e6, -1])
    with pytest.raises(ValueError) as e:
        sandslope.predict(robot, 10, k_n=0, terrain=terrain)
    assert str(e.value) == cli.error("predict", "--slope", "10", "--k-n", "0").replace("--k-n", "k_n")
    with pytest.raises(ValueError, match="mass_kg = -2 must be"):
        sandslope.predict(robot, 10, 7e5, 1e6, mass_kg=-2)
    with pytest.raises(ValueError, match="give both k_n and k_s, or a terrain"):
        sandslope.predict(robot, 10, 7e5)


def test_the_closed_form_refuses_a_spoke_robot_that_simulate_walks(robot, terrain):
    # docs/model.md §15: the closed form is derived for the C-leg; the simulator walks any shape.
    keys = robot.to_dict()
    assert "leg_shape" not in keys  # the default, c_leg, is not written
    spoke = sandslope.Robot(**keys, leg_shape="spoke")
    assert spoke.to_dict()["leg_shape"] == "spoke"
    with pytest.raises(ValueError, match='leg_shape = "spoke": the closed form'):
        sandslope.predict(spoke, 10, 7e5, 1e6)
    _, summary = sandslope.simulate(spoke, terrain, 0.0, duration_s=2.0, scaling_spread=False)
    assert summary["shape"] == "spoke"
    with pytest.raises(ValueError, match="unknown variant `wheel`, expected one of `c_leg`, `spoke`, `foot`"):
        sandslope.Robot(**keys, leg_shape="wheel")
