"""simulate: the trajectory DataFrame and the summary of `sandslope simulate --json`."""

import math

import pandas as pd
import pytest

import sandslope


def test_summary_is_the_cli_json_and_the_trajectory_a_frame(cli):
    want = cli.json("simulate", "--slope", 12, "--duration", 3)
    traj, got = sandslope.simulate("paper-hexapod", "glass-beads-300um", 12, 3)
    assert set(got) == set(want)
    for key in ("speed_m_s", "t1_s", "slip_m", "step_m", "max_depth_m"):
        assert got[key] == pytest.approx(want[key], rel=1e-12), key
    assert (got["regime"], got["cause"]) == (want["regime"], want["cause"])
    assert got["closed_form"] == want["closed_form"]
    assert len(got["steps"]) == len(want["steps"]) == 6
    assert isinstance(traj, pd.DataFrame)
    # 3 s at 120 Hz from t = 0: 361 samples; six legs of five columns each.
    assert len(traj) == 361 and traj["time_s"].iloc[-1] == pytest.approx(3.0)
    assert {"x_m", "z_m", "pitch_rad", "leg0_depth_m", "leg5_torque_n_m"} <= set(traj.columns)
    # The step speed is a difference of positions over T/2 = 0.5 s (samples 120 and 180).
    step3 = got["steps"][2]
    x = traj["x_m"].to_numpy()
    assert step3["touchdown_s"] == 1.0
    assert (x[180] - x[120]) / 0.5 == pytest.approx(step3["speed_m_s"], rel=1e-9)


def test_bad_input_is_a_value_error_naming_the_value_and_range(cli):
    with pytest.raises(ValueError, match=r"duration_s = -1 must be a number of seconds greater than 0"):
        sandslope.simulate("paper-hexapod", "glass-beads-300um", 10, -1)
    with pytest.raises(ValueError, match=r"dt_s = 0.05 must be greater than 0 and at most"):
        sandslope.simulate("paper-hexapod", "glass-beads-300um", 10, 5, dt_s=0.05)
    with pytest.raises(ValueError, match=r"slope_deg = 95"):
        sandslope.simulate("paper-hexapod", "glass-beads-300um", 95, 5)
    robot = sandslope.Robot(**{**sandslope.Robot.preset("paper-hexapod").to_dict(), "leg_elements": 8})
    _, m = sandslope.simulate(robot, "glass-beads-300um", 0, 2)
    assert m["leg_elements"] == 8 and math.isfinite(m["speed_m_s"])
