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


def test_stiff_level_sand_steps_the_rigid_rolling_step():
    # A physical limit worked out by hand (docs/simulate.md, "On level sand the legs roll"), with
    # the body's pitch locked (the free body somersaults on such sand): on
    # sand so stiff that the legs barely sink (k_n = k_s = 1e8 N/m^3, d_n = 0.03 mm) a C-leg of
    # radius R = 0.04 m with the belly h = 0.03 m below the hips rolls on its arc from
    # touchdown (phi0 = asin((h - R)/R)) until its tip points down, then pivots on its tip until
    # the belly lands: R (pi/2 - phi0) + R cos(phi0) + 2R sqrt(1 - (h/2R)^2) = 185.8 mm per
    # step, more than twice the closed form's s* = 2 sqrt(R^2 - (h - R)^2) = 77.5 mm.
    r, h = 0.04, 0.03
    phi0 = math.asin((h - r) / r)
    rolling = r * (math.pi / 2 - phi0) + r * math.cos(phi0) + 2 * r * math.sqrt(1 - (h / (2 * r)) ** 2)
    traj, m = sandslope.simulate(
        "paper-hexapod", "glass-beads-300um", 0, 2.5, k_n=1e8, k_s=1e8, body_pitch="locked"
    )
    assert m["step_m"] == pytest.approx(rolling, rel=0.03)
    assert m["closed_form"]["level_step_m"] == pytest.approx(2 * math.sqrt(r * r - (h - r) ** 2), rel=1e-3)
    # The body vaults: at the tip's pivot the axle line is up to 2R above the sand.
    assert traj["z_m"].max() == pytest.approx(2 * r, rel=0.03)


def test_body_pitch_locked_is_the_cli_flag(cli):
    # The body held parallel to the slope (docs/model.md §15): no pitch in the trajectory, and
    # the same walk as `simulate --body-pitch locked --json`.
    want = cli.json("simulate", "--slope", 20, "--duration", 3, "--body-pitch", "locked")
    traj, got = sandslope.simulate("paper-hexapod", "glass-beads-300um", 20, 3, body_pitch="locked")
    assert got["body_pitch"] == want["body_pitch"] == "locked"
    assert got["speed_m_s"] == pytest.approx(want["speed_m_s"], rel=1e-12)
    assert (traj["pitch_rad"] == 0.0).all() and got["max_pitch_deg"] == 0.0
    # Locked is the default, in Python as on the command line.
    _, default = sandslope.simulate("paper-hexapod", "glass-beads-300um", 20, 3)
    assert default["body_pitch"] == "locked" and default["speed_m_s"] == got["speed_m_s"]
    with pytest.raises(ValueError, match=r'body_pitch = "sideways": expected "free" or "locked"'):
        sandslope.simulate("paper-hexapod", "glass-beads-300um", 20, 3, body_pitch="sideways")


def test_rft_scaling_is_the_cli_flag(cli):
    want = cli.json("simulate", "--slope", 20, "--duration", 3, "--rft-scaling", "components")
    _, got = sandslope.simulate("paper-hexapod", "glass-beads-300um", 20, 3, rft_scaling="components")
    assert got["rft_scaling"] == want["rft_scaling"] == "components"
    assert got["speed_m_s"] == pytest.approx(want["speed_m_s"], rel=1e-12)
    with pytest.raises(ValueError, match=r'rft_scaling = "shear": expected "motion" or "components"'):
        sandslope.simulate("paper-hexapod", "glass-beads-300um", 20, 3, rft_scaling="shear")


def test_the_scaling_spread_is_the_cli_key_and_bounds_the_three_walks(cli):
    # One slope carries the spread by default, as the CLI's --json does; each scaling's speed is
    # that scaling's own walk, and at 24 degrees motion slides where components climbs
    # (docs/simulate.md, "The scaling as model uncertainty").
    want = cli.json("simulate", "--slope", 24, "--duration", 3)
    _, got = sandslope.simulate("paper-hexapod", "glass-beads-300um", 24, 3)
    assert got["scaling_spread"] == want["scaling_spread"]
    spread = got["scaling_spread"]
    speeds = {}
    for name in ("motion", "li2013", "components"):
        _, own = sandslope.simulate("paper-hexapod", "glass-beads-300um", 24, 3, rft_scaling=name, scaling_spread=False)
        assert own["scaling_spread"] is None
        speeds[name] = own["speed_m_s"]
    assert [w["speed_m_s"] for w in spread["walks"]] == [speeds["motion"], speeds["li2013"], speeds["components"]]
    assert spread["min_speed_m_s"] == min(speeds.values()) and spread["max_speed_m_s"] == max(speeds.values())
    assert spread["walks"][0]["regime"] == "slippage" and spread["walks"][2]["regime"] == "success"
    assert spread["regimes_agree"] is False


def test_mechanisms_are_the_cli_flags(cli):
    # docs/model.md §20's switches: the same walk as the CLI's flags, echoed under the same key.
    want = cli.json(
        "simulate", "--slope", 20, "--duration", 3, "--leg-friction", 0.3, "--duty-cycle", 0.6, "--disturbed-sand", 0.5
    )
    _, got = sandslope.simulate(
        "paper-hexapod", "glass-beads-300um", 20, 3, leg_friction=0.3, duty_cycle=0.6, disturbed_sand=0.5
    )
    assert got["mechanisms"] == want["mechanisms"] == {"leg_friction": 0.3, "duty_cycle": 0.6, "disturbed_sand": 0.5}
    assert got["speed_m_s"] == pytest.approx(want["speed_m_s"], rel=1e-12)
    with pytest.raises(ValueError, match=r"duty_cycle = 0.95 must be between 0.1 and 0.9"):
        sandslope.simulate("paper-hexapod", "glass-beads-300um", 20, 3, duty_cycle=0.95)


def test_an_ensemble_is_the_cli_ensemble(cli):
    # `simulate --ensemble N --json`, key for key and number for number (docs/simulate.md,
    # "Pitch free"): the free body at 10 degrees, three walks 1e-9 apart in mass.
    want = cli.json("simulate", "--slope", 10, "--duration", 2, "--body-pitch", "free", "--ensemble", 3)
    got = sandslope.simulate_ensemble("paper-hexapod", "glass-beads-300um", 10, 3, 2, body_pitch="free")
    assert set(got) == set(want)
    assert got["walks"] == 3 and len(got["summaries"]) == 3
    assert got["speed_m_s"] == pytest.approx(want["speed_m_s"], rel=1e-12)
    assert got["regimes"] == want["regimes"]
    with pytest.raises(ValueError, match=r"walks = 1 must be a whole number of walks from 2 to 1000"):
        sandslope.simulate_ensemble("paper-hexapod", "glass-beads-300um", 10, 1, 2)


def test_the_convergence_check_is_the_cli_check(cli):
    # `simulate --check-convergence --json`, key for key: the built-in robot at 10 degrees,
    # pitch locked, 3 s walks at the default step, a quarter of it and a tenth of the creep.
    want = cli.json("simulate", "--slope", 10, "--duration", 3, "--check-convergence")
    got = sandslope.check_convergence("paper-hexapod", "glass-beads-300um", 10, 3)
    assert set(got) == set(want)
    assert [r["refinement"] for r in got["refinements"]] == ["quarter_step", "tenth_creep"]
    assert got["refinements"][0]["answer"]["dt_s"] == pytest.approx(got["walk"]["dt_s"] / 4, rel=1e-15)
    assert got["walk"]["speed_m_s"] == pytest.approx(want["walk"]["speed_m_s"], rel=1e-12)
    assert got["converged"] is want["converged"] is True
    assert got["refinements"][0]["spread_within"] is want["refinements"][0]["spread_within"] is True
    assert got["walk"]["step_speed_sd_m_s"] == pytest.approx(want["walk"]["step_speed_sd_m_s"], rel=1e-12, abs=1e-15)
    with pytest.raises(ValueError, match=r"walks = 1 must be a whole number of walks from 2 to 1000"):
        sandslope.check_convergence("paper-hexapod", "glass-beads-300um", 10, 2, walks=1)
    # Several slopes: the list `--slopes` prints, each the one-slope check.
    many = sandslope.check_convergence("paper-hexapod", "glass-beads-300um", [0, 10], 3)
    assert isinstance(many, list) and [c["slope_deg"] for c in many] == [0.0, 10.0]
    assert many[1] == got
    with pytest.raises(ValueError, match=r"an ensemble walks one slope"):
        sandslope.check_convergence("paper-hexapod", "glass-beads-300um", [0, 10], 2, walks=2)
