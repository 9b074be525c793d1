"""Issue 24: the GeoTIFF layouts GDAL writes, written here by GDAL itself (rasterio's bundled
GDAL) from one synthetic DEM, in a projected and in a geographic CRS: `sandslope plan` must
find the same route on every layout (the same cells, so the same coordinates in its GeoJSON),
and on the geographic grid a route as long as the haversine length of its lon/lat polyline
(within 0.5 %).

The committed fixtures of crates/sandslope-io/tests/fixtures/gdal were made by GDAL once; this
test makes them with whatever GDAL rasterio carries on the machine that runs it. Skipped where
rasterio is not installed (scripts/test.sh installs it)."""

import json
import math

import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio")
import rasterio.shutil  # noqa: E402  (the COG driver's copy)
from rasterio.transform import from_origin  # noqa: E402

# rasterio's own use of the affine package's `*` (its PendingDeprecationWarning is not ours).
pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")

COLS, ROWS = 64, 50
START, GOAL = "6,44", "57,5"  # col,row: south-west to north-east, across the hill

# A hill of whole metres (so that every sample type holds the same heights exactly), 5 m of
# base so that 0 can be the nodata value of the unsigned types, and one nodata cell in the corner.
_col, _row = np.meshgrid(np.arange(COLS), np.arange(ROWS))
HEIGHTS = np.round(5 + 60 * np.exp(-(((_col - 30) / 12.0) ** 2 + ((_row - 22) / 9.0) ** 2)))

# (name, dtype, nodata, GDAL creation options); every layout issue 24 lists.
LAYOUTS = [
    ("strips-none-f32", "float32", -32768, {}),
    ("tiles-deflate-pred3-f32", "float32", -32768,
     {"tiled": True, "blockxsize": 16, "blockysize": 16, "compress": "deflate", "predictor": 3}),
    ("tiles-lzw-pred3-f32", "float32", -32768,
     {"tiled": True, "blockxsize": 16, "blockysize": 16, "compress": "lzw", "predictor": 3}),
    ("strips-lzw-pred2-i16", "int16", -32768, {"compress": "lzw", "predictor": 2, "blockysize": 7}),
    ("strips-lzw-pred2-i16-bigendian", "int16", -32768,
     {"compress": "lzw", "predictor": 2, "endianness": "big"}),
    ("strips-zstd-pred2-i32", "int32", -32768, {"compress": "zstd", "predictor": 2, "blockysize": 9}),
    ("tiles-zstd-pred3-f64", "float64", -32768,
     {"tiled": True, "blockxsize": 32, "blockysize": 32, "compress": "zstd", "predictor": 3}),
    ("strips-deflate-u8", "uint8", 0, {"compress": "deflate"}),
    ("tiles-deflate-pred2-u16", "uint16", 0,
     {"tiled": True, "blockxsize": 16, "blockysize": 16, "compress": "deflate", "predictor": 2}),
    ("bigtiff-deflate-tiles-f32", "float32", -32768,
     {"bigtiff": "yes", "tiled": True, "blockxsize": 16, "blockysize": 16, "compress": "deflate"}),
    ("cog-deflate-f32", "float32", -32768, {"driver": "COG", "compress": "deflate", "blocksize": 16}),
    ("pixel-is-point-f32", "float32", -32768, {"point": True}),
]

# Projected: UTM zone 33N, 25 m cells. Geographic: WGS84, 1 arc-second cells at 40 N.
CRSES = {
    "utm": ("EPSG:32633", 500000.0, 4430000.0, 25.0, 25.0),
    "wgs84": ("EPSG:4326", 10.0, 40.02, 1 / 3600, 1 / 3600),
}


def write(path, crs_name, dtype, nodata, options):
    crs, west, north, dx, dy = CRSES[crs_name]
    options = dict(options)
    driver = options.pop("driver", "GTiff")
    point = options.pop("point", False)
    z = HEIGHTS.astype(dtype)
    z[0, 0] = nodata
    profile = dict(width=COLS, height=ROWS, count=1, dtype=dtype, crs=crs, nodata=nodata,
                   transform=from_origin(west, north, dx, dy), **options)
    if driver == "COG":
        # The COG driver copies a source dataset: write a plain one, add overviews, copy.
        src = str(path) + ".src.tif"
        with rasterio.open(src, "w", driver="GTiff", **{k: v for k, v in profile.items()
                                                        if k not in ("compress", "blocksize")}) as d:
            d.write(z, 1)
            d.build_overviews([2, 4])
        rasterio.shutil.copy(src, path, driver="COG", compress=options["compress"],
                             blocksize=options["blocksize"])
    else:
        with rasterio.open(path, "w", driver=driver, **profile) as d:
            if point:
                d.update_tags(AREA_OR_POINT="Point")
            d.write(z, 1)
    with rasterio.open(path) as d:  # GDAL reads back what it wrote
        assert np.array_equal(d.read(1), z), path
        if point:
            assert d.tags().get("AREA_OR_POINT") == "Point"
        if driver == "COG":
            assert d.overviews(1), "the COG carries its overviews"


def route(cli, dem, tmp_path):
    out = tmp_path / (dem.stem + ".geojson")
    summary = cli.json("plan", "--dem", dem, "--start-px", START, "--goal-px", GOAL, "--objective", "time",
                       "--geojson", out)
    features = json.loads(out.read_text())["features"]
    time = next(f for f in features if f["properties"]["objective"] == "time")
    return summary["routes"]["time"], np.array(time["geometry"]["coordinates"])


def haversine(lonlat):
    r = 6371008.8  # the mean Earth radius (IUGG): within 0.3 % of WGS84's lengths at 40 N
    lon, lat = np.radians(lonlat[:, 0]), np.radians(lonlat[:, 1])
    a = np.sin(np.diff(lat) / 2) ** 2 + np.cos(lat[:-1]) * np.cos(lat[1:]) * np.sin(np.diff(lon) / 2) ** 2
    return float(np.sum(2 * r * np.arcsin(np.sqrt(a))))


@pytest.mark.parametrize("crs_name", sorted(CRSES))
def test_every_gdal_layout_plans_the_same_route(cli, tmp_path, crs_name):
    routes = {}
    for name, dtype, nodata, options in LAYOUTS:
        path = tmp_path / f"{crs_name}-{name}.tif"
        write(path, crs_name, dtype, nodata, options)
        routes[name] = route(cli, path, tmp_path)
    first, (summary, coords) = next(iter(routes.items()))
    assert summary["found"] and len(coords) > 10
    for name, (s, c) in routes.items():
        # The same cells: the same coordinates (PixelIsPoint too: GDAL moves its tie point by
        # half a cell, and the reader moves it back), the same length and time.
        np.testing.assert_allclose(c, coords, rtol=0, atol=1e-9 * max(1.0, np.abs(coords).max()),
                                   err_msg=f"{name} against {first}")
        assert s["length_m"] == pytest.approx(summary["length_m"], rel=1e-12), name
        assert s["time_s"] == pytest.approx(summary["time_s"], rel=1e-12), name
    if crs_name == "wgs84":
        # The GeoJSON is lon/lat (RFC 7946), and the route's ground length is the polyline's.
        assert 10.0 < coords[:, 0].min() and coords[:, 0].max() < 10.0 + COLS / 3600
        along = haversine(coords)
        assert abs(summary["length_m"] - along) < 0.005 * along, (summary["length_m"], along)
    else:
        # Metres in the UTM grid: the polyline's planar length is the route's horizontal length,
        # which the 3-D length exceeds by the climb only (a few per cent on this hill).
        planar = float(np.sum(np.hypot(*np.diff(coords, axis=0).T)))
        assert planar <= summary["length_m"] < 1.05 * planar, (summary["length_m"], planar)
        assert math.isclose(coords[0][0], 500000.0 + 6.5 * 25.0)
