#!/usr/bin/env python3
"""Checks a streamed `plan --risk-map` of a DEM larger than memory against the in-memory map of
a window that fits (issue 56).

What it does: cuts the window `--rows R0:R1 --cols C0:C1` out of `--dem` (a north-up GeoTIFF
such as run.py's 32768 x 32768 dune field) into a GeoTIFF of its own with the same cells,
plans on it with `--search full --risk-map` (the planner holding the whole window in memory),
and compares that risk map with the same window of `--risk` (the streamed map of the whole
DEM, written band by band), band by band, bit for bit, on the window's interior (its outermost
ring of cells has no Horn gradient in the cut-out, so it differs by construction). Prints the
cells compared and how many differ. Needs numpy, tifffile and rasterio (for the windowed reads).

Usage: python3 bench/plan/risk_window.py --dem DEM.tif --risk RISK.tif --rows R0:R1 --cols C0:C1
                                         [--exe sandslope] [--work DIR]
"""
import argparse
import os
import subprocess
import sys

import numpy as np
import rasterio
import tifffile
from rasterio.windows import Window


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dem", required=True)
    ap.add_argument("--risk", required=True)
    ap.add_argument("--rows", required=True, help="R0:R1, rows of the window")
    ap.add_argument("--cols", required=True, help="C0:C1, columns of the window")
    ap.add_argument("--exe", default="sandslope")
    ap.add_argument("--work", default=".")
    args = ap.parse_args()
    r0, r1 = (int(v) for v in args.rows.split(":"))
    c0, c1 = (int(v) for v in args.cols.split(":"))
    window = Window(c0, r0, c1 - c0, r1 - r0)
    with rasterio.open(args.dem) as dem:
        z = dem.read(1, window=window)
        t = dem.transform
    west, north = t.c + c0 * t.a, t.f + r0 * t.e
    cut = os.path.join(args.work, "window-dem.tif")
    tifffile.imwrite(cut, z, extratags=[(33550, "d", 3, (t.a, -t.e, 0.0)),
                                        (33922, "d", 6, (0, 0, 0, west, north, 0.0))])
    out = os.path.join(args.work, "window-risk.tif")
    h, w = z.shape
    cmd = [args.exe, "plan", "--dem", cut, "--start-px", "2,2", "--goal-px", f"{w - 3},{h - 3}",
           "--objective", "distance", "--search", "full", "--risk-map", out, "--json"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with rasterio.open(out) as small, rasterio.open(args.risk) as big:
        for band in (1, 2):
            a = small.read(band)[1:-1, 1:-1]
            b = big.read(band, window=window)[1:-1, 1:-1]
            differ = int(np.count_nonzero(a.view(np.uint32) != b.view(np.uint32)))
            print(f"band {band}: {a.size} cells compared, {differ} differ (bit for bit)")
            if differ:
                sys.exit(1)


if __name__ == "__main__":
    main()
