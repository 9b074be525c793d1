"""risk, risk_map, safe_slope, safe_mass, payload_envelope against the CLI; the missing-SD
message."""

import numpy as np
import pytest

import sandslope


def test_risk_matches_cli(cli, robot, terrain):
    slopes = [0, 10, 20, 24]
    want = cli.json("risk", "--slope", ",".join(map(str, slopes)), "--cv-n", 0.1, "--cv-s", 0.3)
    got = sandslope.risk(robot, slopes, terrain=terrain, cv_n=0.1, cv_s=0.3)
    for i, w in enumerate(want):
        assert got["slope_deg"][i] == w["slope_deg"]
        assert got["p_fail"][i] == pytest.approx(w["p_fail"], rel=1e-12, abs=1e-300)
        assert got["p_not_success"][i] == pytest.approx(w["p_not_success"], rel=1e-12, abs=1e-300)
        for k, v in w["p_regime"].items():
            assert got["p_regime"][k][i] == pytest.approx(v, rel=1e-12, abs=1e-300), k
        assert got["cv_n_source"][i] == w["cv_n_source"] and got["cv_s"][i] == w["cv_s"]
    # The keys of risk --json, no more (issue 22), and the same regimes.
    assert set(got) == set(want[0])
    assert set(got["p_regime"]) == set(want[0]["p_regime"])
    total = sum(got["p_regime"].values())
    np.testing.assert_allclose(total, 1.0, atol=1e-8)
    # Failure becomes likelier as the slope steepens on this terrain.
    assert (np.diff(got["p_fail"]) > 0).all()
    assert got["p_fail"].shape == (4,) and sandslope.risk(robot, 10, terrain=terrain, cv_n=0.1, cv_s=0.3)[
        "p_fail"
    ].shape == ()


def test_no_uncertainty_is_the_certain_regime(robot, terrain):
    # cv = 0: the probabilities are the indicator of predict's regime.
    for slope in (0, 20, 24.5):
        r = sandslope.risk(robot, slope, terrain=terrain, cv_n=0, cv_s=0)
        regime = sandslope.REGIMES[int(sandslope.predict(robot, slope, terrain=terrain)["regime"])]
        assert float(r["p_regime"][regime]) == 1.0


def test_one_uncertainty_rule(cli, robot, terrain, root, tmp_path):
    # docs/model.md §9: a given CV, else the table's SD over its value, else 0.1 / 0.2.
    # A table without SDs (the built-in terrain carries SDs since its joint calibration).
    bare = tmp_path / "bare.toml"
    bare.write_text("[[points]]\nslope_deg = 0.0\nk_n = 7.0e5\nk_s = 2.0e6\n")
    plain = sandslope.risk(robot, [0, 10], terrain=sandslope.Terrain.from_toml(bare))
    assert list(plain["cv_n_source"]) == ["default", "default"] and (plain["cv_s"] == 0.2).all()
    want = cli.json("risk", "--slope", "0,10", "--terrain", str(bare))
    assert [p["p_fail"] for p in want] == pytest.approx(list(plain["p_fail"]), rel=1e-12, abs=1e-300)
    uncertain = root / "examples" / "phase" / "uncertain-sand.toml"
    table = sandslope.risk(robot, 10, terrain=uncertain, cv_s=0.05)
    assert table["cv_n_source"] == "table" and table["cv_s_source"] == "given" and table["cv_s"] == 0.05
    at = sandslope.Terrain.from_toml(uncertain).at(10)
    assert float(table["cv_n"]) == pytest.approx(at["k_n_sd"] / at["k_n"], rel=1e-12)
    with pytest.raises(ValueError, match="cv_s = -1 must be"):
        sandslope.risk(robot, 10, terrain=terrain, cv_n=0.1, cv_s=-1)
    with pytest.raises(ValueError, match=r"slope_deg\[1\] = 95 must be"):
        sandslope.risk(robot, [10, 95], terrain=terrain)


def test_solvers_match_cli(cli, robot, root):
    uncertain = root / "examples" / "phase" / "uncertain-sand.toml"
    want = cli.json("risk", "--terrain", uncertain, "--solve", "slope", "--max-risk", 0.1)
    got = sandslope.safe_slope(robot, terrain=uncertain, max_risk=0.1)
    # One library value: the same keys and the same numbers, bit for bit.
    assert got == want
    # Both limits, named apart: the robot stops climbing (metastable) before it fails.
    assert got["success_slope_deg"] < got["safe_slope_deg"]
    assert got["success_limit"]["kind"] == "limit"
    # On the built-in glass beads p_fail stays low up to the repose: kind "repose", not 24.999.
    builtin = sandslope.safe_slope(robot, terrain="glass-beads-300um")
    assert builtin["limit"]["kind"] == "repose" and builtin["safe_slope_deg"] == 25.0
    want = cli.json("risk", "--terrain", uncertain, "--slope", 10, "--solve", "mass")
    got = sandslope.safe_mass(robot, 10, terrain=uncertain)
    assert got == want
    # The payload is the heaviest safe mass less the robot's own.
    assert got["max_payload_kg"] == pytest.approx(got["max_mass_kg"] - robot.mass_kg, abs=1e-12)


def test_payload_envelope_is_the_cli_envelope(cli, robot, root):
    uncertain = root / "examples" / "phase" / "uncertain-sand.toml"
    want = cli.json("risk", "--terrain", uncertain, "--slope", "0,8,-12", "--solve", "mass", "--max-risk", 0.1)
    got = sandslope.payload_envelope(robot, [0, 8, -12], terrain=uncertain, max_risk=0.1)
    # One library value: the same keys and numbers, bit for bit.
    assert got == want
    # Each point is the one-slope search, whose payload is its mass less the robot's own.
    for p in got["points"]:
        one = sandslope.safe_mass(robot, p["slope_deg"], terrain=uncertain, max_risk=0.1)
        assert (p["max_mass_kg"], p["limit"]) == (one["max_mass_kg"], one["limit"])
        assert p["max_payload_kg"] == pytest.approx(p["max_mass_kg"] - robot.mass_kg, abs=1e-12)
    # A descent is felt as the climb of its size (docs/model.md §8).
    assert got["points"][2]["max_mass_kg"] == sandslope.safe_mass(robot, 12, terrain=uncertain, max_risk=0.1)["max_mass_kg"]
    with pytest.raises(ValueError, match=r"slope_deg\[1\] = 95 must be"):
        sandslope.payload_envelope(robot, [10, 95], terrain=uncertain)
    with pytest.raises(ValueError, match="max_risk = 1 must be"):
        sandslope.payload_envelope(robot, [10], terrain=uncertain, max_risk=1)


def test_risk_map_is_the_cli_map(cli, robot, terrain):
    # `risk --map --json` and risk_map serialise one library value: the same keys; the
    # summary equal, the axes and cells (arrays here, nested lists [k_n][k_s] there) equal.
    want = cli.json(
        "risk", "--slope", 20, "--map", "--k-n", "1e5:1e7:4", "--k-s", "1e5:1e7:5", "--cv-n", 0.1, "--max-risk", 0.2
    )
    got = sandslope.risk_map(
        robot, 20, np.geomspace(1e5, 1e7, 4), np.geomspace(1e5, 1e7, 5), terrain=terrain, cv_n=0.1, max_risk=0.2
    )
    assert set(got) == set(want)
    arrays = {"k_n", "k_s", "p_fail", "p_not_success"}
    assert {k: v for k, v in got.items() if k not in arrays} == {k: v for k, v in want.items() if k not in arrays}
    for k in arrays:
        np.testing.assert_array_equal(got[k], np.array(want[k]), err_msg=k)
    assert got["p_fail"].shape == (4, 5) and got["cells"] == 20
    assert got["cells_below_max_risk"] == int((got["p_fail"] < 0.2).sum())
    # Without axes: the library's one default grid, the CLI's without --k-n/--k-s (200 x 200
    # log-spaced around the terrain's medians at the slope), the same numbers.
    want = cli.json("risk", "--slope", 20, "--map")
    got = sandslope.risk_map(robot, 20, terrain=terrain)
    assert got["k_n_axis"] == want["k_n_axis"] and got["k_s_axis"] == want["k_s_axis"]
    assert got["k_n_axis"]["min"] == pytest.approx(got["terrain_k_n"] / 100, rel=1e-15)
    assert got["k_s_axis"]["max"] == pytest.approx(got["terrain_k_s"] * 100, rel=1e-15)
    assert got["p_fail"].shape == (200, 200) and got["cells_below_max_risk"] == want["cells_below_max_risk"]
    np.testing.assert_array_equal(got["p_fail"], np.array(want["p_fail"]))


def test_risk_map_matches_pointwise_risk(robot):
    t = sandslope.Terrain.constant(7e5, 1.5e6)
    k_n, k_s = np.geomspace(1e5, 1e7, 4), np.geomspace(1e5, 1e7, 5)
    m = sandslope.risk_map(robot, 20, k_n, k_s, terrain=t, cv_n=0.1, cv_s=0.2)
    assert m["p_fail"].shape == (4, 5)
    for i, kn in enumerate(m["k_n"]):
        for j, ks in enumerate(m["k_s"]):
            one = sandslope.risk(robot, 20, terrain=sandslope.Terrain.constant(kn, ks), cv_n=0.1, cv_s=0.2)
            # The map shares the critical-strength curve between cells (docs/phase-and-risk.md);
            # the library keeps it within 1e-6 of the per-cell quadrature.
            assert m["p_fail"][i, j] == pytest.approx(float(one["p_fail"]), abs=1e-6)


def test_defaults_are_the_documented_ones_everywhere(cli):
    """max_risk 0.05 (docs/model.md §9) and max_roll_deg 20 (§8) are one constant each, which
    every Python signature and the CLI's help show."""
    import inspect

    import sandslope.dask

    for f in (sandslope.risk_map, sandslope.safe_slope, sandslope.safe_mass, sandslope.payload_envelope,
              sandslope.report):
        assert inspect.signature(f).parameters["max_risk"].default == 0.05, f.__name__
    for f in (sandslope.plan, sandslope.risk_raster, sandslope.dask.risk_raster):
        assert inspect.signature(f).parameters["max_roll_deg"].default == 20.0, f.__name__
    assert "[default: 0.05]" in cli.run("risk", "--help").stdout
    assert "[default: 20]" in cli.run("plan", "--help").stdout
