#!/usr/bin/env python3
"""Writes dune.asc: a synthetic crescent (barchan-like) sand dune for `sandslope plan`.

ESRI ASCII grid, 200 x 200 cells of 0.3 m (a 60 m x 60 m map), heights in metres, lower-left
corner at (0, 0). Standard library only, deterministic.

Shape: height H = 6 m along a crest that bends downwind at its ends (crest line
x_c(y) = 30 + 6 ((y - 30) / 30)^2 m). Across the crest, a Gaussian profile whose width is
L_w = 14 m on the windward (west) side and L_l = 8 m on the lee (east) side, so the steepest
windward slope is H sqrt(2/e) / L_w = 0.37 (20 deg) and the steepest lee slope is
H sqrt(2/e) / L_l = 0.64 (33 deg, beyond the 25 deg repose of glass beads). Along the crest a
Gaussian envelope of width 14 m lets the dune taper at both ends. Small ripples
(2 cm, 1.5 m wavelength) make the surface less ideal. A 3 x 4 m nodata patch on the lee
flank stands for a missing survey area.

Usage: python3 make_dune.py [output.asc]
"""
import math
import sys

N, CELL, H = 200, 0.3, 6.0
L_WIND, L_LEE, L_CREST = 14.0, 8.0, 14.0
NODATA = -9999.0


def height(x, y):
    u = x - (30.0 + 6.0 * ((y - 30.0) / 30.0) ** 2)
    width = L_WIND if u < 0 else L_LEE
    profile = math.exp(-((u / width) ** 2))
    envelope = math.exp(-(((y - 30.0) / L_CREST) ** 2))
    ripples = 0.02 * math.sin(2 * math.pi * (x + 0.3 * y) / 1.5)
    return H * profile * envelope + ripples


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "dune.asc"
    lines = [f"ncols {N}", f"nrows {N}", "xllcorner 0.0", "yllcorner 0.0", f"cellsize {CELL}",
             f"NODATA_value {NODATA:g}"]
    for row in range(N):
        y = (N - row - 0.5) * CELL  # row 0 is the northern edge
        vals = []
        for col in range(N):
            x = (col + 0.5) * CELL
            hole = 44.0 <= x <= 47.0 and 40.0 <= y <= 44.0
            vals.append(f"{NODATA:g}" if hole else f"{height(x, y):.3f}")
        lines.append(" ".join(vals))
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
