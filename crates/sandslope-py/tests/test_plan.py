"""risk_raster and plan on an elevation array, against `sandslope plan` on the same DEM."""

from pathlib import Path

import numpy as np
import pytest
import tifffile

import sandslope

DUNE = "examples/planning/dune.asc"


@pytest.fixture(scope="module")
def dune(root):
    z, geo = sandslope.read_raster(root / DUNE)
    return z, geo


def test_read_raster(dune):
    z, geo = dune
    assert z.shape == (200, 200) and geo["cell_x"] == 0.3 and geo["cell_y"] == 0.3
    assert geo["west"] == 0.0 and geo["north"] == pytest.approx(60.0)
    # The file's NODATA_value cells come back as NaN.
    text = (Path(__file__).resolve().parents[3] / DUNE).read_text().split("\n", 6)[6]
    assert np.isnan(z).sum() == text.split().count("-9999") > 0


def test_risk_raster_equals_the_cli(cli, robot, terrain, dune, tmp_path):
    z, geo = dune
    out = tmp_path / "risk.tif"
    cli.run("plan", "--dem", DUNE, "--start-px", "100,150", "--goal-px", "100,50", "--risk-map", out)
    want = tifffile.imread(out)  # (rows, cols, 2)
    got = sandslope.risk_raster(z, 0.3, robot=robot, terrain=terrain)
    assert got.shape == (2, 200, 200) and got.dtype == np.float32
    for band in range(2):
        np.testing.assert_array_equal(got[band], want[..., band])
    # The map border has no gradient; the interior has one.
    assert np.isnan(got[0, 0]).all() and np.isnan(got[0, :, -1]).all()
    assert np.isfinite(got[0, 1:-1, 1:-1]).mean() > 0.9


def test_nodata_and_flat_ground(robot, terrain):
    z = np.zeros((6, 7))
    z[3, 3] = -9999
    got = sandslope.risk_raster(z, 1.0, robot=robot, terrain=terrain, nodata=-9999)
    # Cells whose 3 x 3 window holds the nodata cell have no gradient.
    assert np.isnan(got[0, 2:5, 2:5]).all()
    # Level ground elsewhere: p_fail is the level-ground risk, and no heading climbs.
    level = float(sandslope.risk(robot, 0, terrain=terrain)["p_fail"])
    assert got[0, 1, 1] == pytest.approx(level, abs=1e-6)
    assert np.isnan(got[1, 1, 1])


def test_plan_matches_the_cli(cli, robot, terrain, dune):
    z, _ = dune
    want = cli.json("plan", "--dem", DUNE, "--start-px", "100,150", "--goal-px", "100,50", "--objective", "time,risk")
    result = sandslope.plan(z, 0.3, robot=robot, terrain=terrain, start=(150, 100), goal=(50, 100),
                            objective=["time", "risk"])
    got = result["routes"]
    assert set(got) == {"time", "risk", "distance"}
    for name, w in want["routes"].items():
        g = got[name]
        assert g["found"] == w["found"]
        if not w["found"]:
            assert g["reason"] == w["reason"]
            continue
        for k in ["length_m", "time_s", "survival", "max_pitch_deg", "max_roll_deg", "edges_over_roll_limit",
                  "regimes"]:
            assert g[k] == pytest.approx(w[k], rel=1e-12), (name, k)
        assert (g["rows"][0], g["cols"][0]) == (150, 100) and (g["rows"][-1], g["cols"][-1]) == (50, 100)
        assert len(g["steps"]["pitch_deg"]) == len(g["rows"]) - 1
        # Coordinates are cell centres; the route length is the sum of its edge lengths.
        assert g["x_m"][0] == pytest.approx(100.5 * 0.3) and g["y_m"][0] == pytest.approx(60 - 150.5 * 0.3)
        assert g["steps"]["length_m"].sum() == pytest.approx(g["length_m"], rel=1e-9)


GEO = "crates/sandslope-io/tests/fixtures/gdal/geo-wgs84.tif"


def test_a_geographic_dem_with_its_row_widths_plans_and_maps_as_the_cli(cli, robot, terrain, root, tmp_path):
    """Issue 24: a GeoTIFF in degrees (EPSG:4326, 1 arc-second cells) has one east-west cell
    size per row; read_raster gives them and plan and risk_raster with row_widths_m give the
    CLI's routes and risk map (without them, the mid-latitude width for every row, they differ)."""
    z, geo = sandslope.read_raster(root / GEO)
    widths = geo["row_widths_m"]
    assert widths.shape == (z.shape[0],) and widths[0] < geo["cell_x_m"] < widths[-1]  # north to south
    cell = (geo["cell_x_m"], geo["cell_y_m"])
    want = cli.json("plan", "--dem", GEO, "--start-px", "5,10", "--goal-px", "55,40", "--objective", "time,risk")
    got = sandslope.plan(z, cell, robot=robot, terrain=terrain, start=(10, 5), goal=(40, 55),
                         objective=["time", "risk"], row_widths_m=widths)["routes"]
    for name, w in want["routes"].items():
        assert w["found"] and got[name]["found"], name
        for k in ["length_m", "time_s", "survival", "max_pitch_deg", "max_roll_deg"]:
            assert got[name][k] == pytest.approx(w[k], rel=1e-12), (name, k)
    # x_m is metres east of the west edge along the cell's own parallel: the longitude offset
    # times the parallel's radius on WGS84, N(lat) cos(lat), worked out here from the degrees.
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    route = got["time"]
    lat = np.radians(geo["north"] - (route["rows"] + 0.5) * geo["cell_y"])
    parallel = a / np.sqrt(1 - e2 * np.sin(lat) ** 2) * np.cos(lat)
    east = np.radians((route["cols"] + 0.5) * geo["cell_x"]) * parallel
    np.testing.assert_allclose(route["x_m"], east, rtol=1e-6)
    # Rows far apart differ: one mid-latitude width for all would be off by more than that.
    assert np.ptp(widths) / np.mean(widths) > 1e-4
    out = tmp_path / "risk.tif"
    cli.run("plan", "--dem", GEO, "--start-px", "5,10", "--goal-px", "55,40", "--risk-map", out)
    want = tifffile.imread(out)
    rows = sandslope.risk_raster(z, cell, robot=robot, terrain=terrain, row_widths_m=widths)
    for band in range(2):
        np.testing.assert_array_equal(rows[band], want[..., band])
    mid = sandslope.risk_raster(z, cell, robot=robot, terrain=terrain)
    # The climb azimuths (band 1) follow each row's width: atan(dc w / (dr dy)).
    assert not np.array_equal(mid[1], want[..., 1], equal_nan=True)
    with pytest.raises(ValueError, match="row_widths_m"):
        sandslope.risk_raster(z, cell, robot=robot, terrain=terrain, row_widths_m=widths[:-1])


def test_plan_errors(robot, terrain, dune):
    z, _ = dune
    with pytest.raises(ValueError, match=r"start = \(500, 3\) is outside the map"):
        sandslope.plan(z, 0.3, robot=robot, terrain=terrain, start=(500, 3), goal=(50, 100))
    with pytest.raises(ValueError, match="on the map border"):
        sandslope.plan(z, 0.3, robot=robot, terrain=terrain, start=(0, 3), goal=(50, 100))
    with pytest.raises(ValueError, match="objective = \"fast\" must be"):
        sandslope.plan(z, 0.3, robot=robot, terrain=terrain, start=(150, 100), goal=(50, 100), objective="fast")
    with pytest.raises(ValueError, match="max_roll_deg = 95 must be strictly between 0 and 90"):
        sandslope.risk_raster(z, 0.3, robot=robot, terrain=terrain, max_roll_deg=95)
    with pytest.raises(ValueError, match="dem must be a 2-D array"):
        sandslope.risk_raster(z[0], 0.3, robot=robot, terrain=terrain)


def test_plan_with_terrain_classes_matches_the_cli(cli, robot, terrain, dune, tmp_path):
    """Classes as `plan --classes --class-terrain` takes them: a band of weak sand (k_s far too
    low to anchor) across the dune; the time route keeps off it, the distance route does not,
    and every figure equals the command line's on the same class raster."""
    z, geo = dune
    classes = np.ones(z.shape)
    classes[:150, 95:105] = 2.0  # a gap in the south lets the time route round it
    classes[np.isnan(z)] = np.nan
    weak = tmp_path / "weak.toml"
    weak.write_text("[[points]]\nslope_deg = 0.0\nk_n = 7.0e5\nk_s = 1.0e3\n")
    tif = tmp_path / "classes.tif"
    # Aligned with dune.asc: 0.3 m cells, north-west corner (0, 60); -1 marks no class.
    tifffile.imwrite(tif, np.where(np.isnan(classes), -1, classes).astype(np.int16), extratags=[
        (33550, "d", 3, (0.3, 0.3, 0.0), True), (33922, "d", 6, (0, 0, 0, geo["west"], geo["north"], 0), True),
        (42113, "s", 0, "-1", True)])
    want = cli.json("plan", "--dem", DUNE, "--start-px", "60,100", "--goal-px", "140,100", "--classes", tif,
                    "--class-terrain", f"1=glass-beads-300um,2={weak}")
    got = sandslope.plan(z, 0.3, robot=robot, terrain=terrain, start=(100, 60), goal=(100, 140),
                         classes=classes, class_terrains={1: "glass-beads-300um", 2: weak})["routes"]
    assert want["routes"]["time"]["found"]
    assert want["routes"]["time"]["regimes"]["slippage"] == 0
    assert want["routes"]["distance"]["regimes"]["slippage"] > 0
    for name, w in want["routes"].items():
        for k in ["found", "length_m", "time_s", "survival", "regimes"]:
            assert got[name][k] == (w[k] if w[k] is None else pytest.approx(w[k], rel=1e-12)), (name, k)
    with pytest.raises(ValueError, match=r"classes: class 2 \(\d+ cells\) has no terrain \(given: 1\)"):
        sandslope.plan(z, 0.3, robot=robot, terrain=terrain, start=(100, 60), goal=(100, 140),
                       classes=classes, class_terrains={1: terrain})
    with pytest.raises(ValueError, match="give both or neither"):
        sandslope.plan(z, 0.3, robot=robot, terrain=terrain, start=(100, 60), goal=(100, 140), classes=classes)
    with pytest.raises(ValueError, match=r"classes has shape \(3, 3\)"):
        sandslope.plan(z, 0.3, robot=robot, terrain=terrain, start=(100, 60), goal=(100, 140),
                       classes=np.ones((3, 3)), class_terrains={1: terrain})


WALL = """ncols 6
nrows 5
xllcorner 0
yllcorner 0
cellsize 1
""" + "0 0 3 6 6 6\n" * 5


def test_a_route_not_found_has_the_keys_of_plan_json(cli, robot, terrain, tmp_path):
    """A 3 m step per 1 m cell (71.6 deg, far above any repose): no time or risk route leaves the
    start. Each route has exactly the keys and values of `plan --json` (nulls for the figures
    of a route not found), the found distance route those keys plus its arrays."""
    dem = tmp_path / "wall.asc"
    dem.write_text(WALL)
    want = cli.json("plan", "--dem", dem, "--start-px", "1,2", "--goal-px", "4,2", "--objective", "time,risk")
    z, geo = sandslope.read_raster(dem)
    got = sandslope.plan(z, 1.0, robot=robot, terrain=terrain, start=(2, 1), goal=(2, 4),
                         objective=["time", "risk"])["routes"]
    assert set(got) == set(want["routes"]) == {"time", "risk", "distance"}
    for name in ("time", "risk"):
        assert want["routes"][name]["found"] is False
        assert got[name] == want["routes"][name], name
    w, g = want["routes"]["distance"], got["distance"]
    assert w["found"] and set(g) == set(w) | {"rows", "cols", "x_m", "y_m", "z_m", "steps"}
    for k, v in w.items():
        assert g[k] == (pytest.approx(v, rel=1e-12) if isinstance(v, float) else v), k


def test_objectives_a_comma_text_or_a_list(robot, terrain):
    """``objective`` is read by the field table's parser: a list of words, one text as
    ``--objective`` takes it (``"time,risk"``) and a list of such texts are one request, and a
    word that is no objective inside a text is named."""
    z = np.add.outer(np.zeros(12), 0.05 * np.arange(12))  # a 0.05 m rise per 0.3 m cell, east
    ask = dict(robot=robot, terrain=terrain, start=(6, 2), goal=(6, 9))
    lists = sandslope.plan(z, 0.3, objective=["time", "risk"], **ask)["routes"]
    text = sandslope.plan(z, 0.3, objective="time,risk", **ask)["routes"]
    mixed = sandslope.plan(z, 0.3, objective=["time, risk"], **ask)["routes"]
    assert list(lists) == list(text) == list(mixed) == ["time", "risk", "distance"]
    for name in lists:
        assert lists[name]["found"] and lists[name]["length_m"] > 2.0
        assert text[name]["length_m"] == mixed[name]["length_m"] == lists[name]["length_m"]
    with pytest.raises(ValueError, match="objective = \"fast\" must be"):
        sandslope.plan(z, 0.3, objective="time,fast", **ask)
