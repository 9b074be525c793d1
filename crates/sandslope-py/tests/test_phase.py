"""phase: shape and layout, every cell equal to predict and to the CLI's CSV, axis checks."""

import csv

import numpy as np
import pytest

import sandslope


def test_every_cell_matches_predict(robot):
    k_n = np.geomspace(1e4, 1e7, 23)
    k_s = np.geomspace(1e3, 1e8, 31)
    for slope in (0.0, 20.0):
        m = sandslope.phase(robot, slope, k_n, k_s)
        assert m["regime"].shape == (23, 31) and m["regime"].dtype == np.int8
        assert m["step_m"].shape == (23, 31) and m["step_m"].dtype == np.float64
        # The library's axis values agree with NumPy's to rounding; the map is computed on them.
        np.testing.assert_allclose(m["k_n"], k_n, rtol=1e-12)
        np.testing.assert_allclose(m["k_s"], k_s, rtol=1e-12)
        p = sandslope.predict(robot, slope, m["k_n"][:, None], m["k_s"][None, :])
        np.testing.assert_array_equal(m["regime"], p["regime"])
        np.testing.assert_array_equal(m["step_m"], p["step_m"])  # NaN where no anchoring
        assert sum(m["counts"].values()) == 23 * 31
        assert m["counts"]["success"] == int((m["regime"] == 3).sum())
        # All four regimes appear on this grid at 20 degrees.
        if slope == 20.0:
            assert set(np.unique(m["regime"])) == {0, 1, 2, 3}


def test_regime_only_gives_the_regime_of_predict_and_no_step(robot, terrain):
    # 23 x 31 (not multiples of four: the last codes of a row come from a partial byte).
    k_n = np.geomspace(1e4, 1e7, 23)
    k_s = np.geomspace(1e3, 1e8, 31)
    r = sandslope.phase(robot, 20.0, k_n, k_s, regime_only=True)
    assert "step_m" not in r
    assert r["regime"].shape == (23, 31) and r["regime"].dtype == np.int8
    p = sandslope.predict(robot, 20.0, r["k_n"][:, None], r["k_s"][None, :])
    np.testing.assert_array_equal(r["regime"], p["regime"])
    # Beyond the terrain's angle of repose: the full map's regimes and counts.
    r = sandslope.phase(robot, 26.0, k_n, k_s, terrain=terrain, regime_only=True)
    full = sandslope.phase(robot, 26.0, k_n, k_s, terrain=terrain)
    np.testing.assert_array_equal(r["regime"], full["regime"])
    assert r["counts"] == full["counts"]


def test_matches_the_cli_csv(cli, robot, terrain, tmp_path):
    out = tmp_path / "cells.csv"
    cli.run("phase", "--slope", 24, "--k-n", "1e4:1e7:17", "--k-s", "1e3:1e8:13:log", "--csv", out)
    rows = list(csv.DictReader(out.open()))
    m = sandslope.phase(robot, 24, np.geomspace(1e4, 1e7, 17), np.geomspace(1e3, 1e8, 13), terrain=terrain)
    assert len(rows) == 17 * 13
    for row in rows:
        i = int(np.argmin(abs(np.log(m["k_n"] / float(row["k_n"])))))
        j = int(np.argmin(abs(np.log(m["k_s"] / float(row["k_s"])))))
        assert sandslope.REGIMES[m["regime"][i, j]] == row["regime"]
        if row["step_m"]:
            assert m["step_m"][i, j] == pytest.approx(float(row["step_m"]), rel=1e-12)
        else:
            assert np.isnan(m["step_m"][i, j])


def test_repose_and_mass(robot, terrain):
    k = np.geomspace(1e5, 1e8, 5)
    # At or above the terrain's angle of repose (25 deg) everything slips unless it sinks.
    beyond = sandslope.phase(robot, 26, k, k, terrain=terrain)
    assert set(np.unique(beyond["regime"])) <= {0, 1}
    assert set(np.unique(sandslope.phase(robot, 26, k, k)["regime"])) != {1}
    # A heavier robot sinks at k_n where the light one does not: threshold 57225 * 3 kg / 0.35 kg.
    kn = np.linspace(1e5, 6e5, 6)
    light = sandslope.phase(robot, 0, kn, k)["regime"][:, -1]
    heavy = sandslope.phase(robot, 0, kn, k, mass_kg=3.0)["regime"][:, -1]
    assert (light != 0).all()
    np.testing.assert_array_equal(heavy == 0, kn <= 57225 * 3 / 0.35)


def test_axes_must_be_evenly_spaced(robot):
    with pytest.raises(ValueError, match="k_s_axis must be ascending and evenly spaced"):
        sandslope.phase(robot, 0, np.linspace(1e4, 1e6, 5), [1e3, 2e3, 5e3])
    with pytest.raises(ValueError, match="k_n_axis has 1 values; at least 2"):
        sandslope.phase(robot, 0, [1e5], [1e3, 2e3])
    m = sandslope.phase(robot, 0, np.linspace(0, 1e6, 11), np.logspace(3, 7, 9))
    assert m["k_n_scale"] == "linear" and m["k_s_scale"] == "log"
