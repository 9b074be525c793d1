#!/usr/bin/env python3
"""The force balance along the slope over one step (docs/simulate.md, "What cannot hold the
body on the steep slope"), from the stride probe's CSV.

The probe (a test the suite ignores) walks the built-in robot and writes, at every integration
step, the body's along-slope position and speed and the sand's force on the belly and on each
tripod (slope frame, N):

    PROBE_SLOPE=24 PROBE_SCALING=motion PROBE_OUT=/tmp/probe_24.csv \\
        cargo test --release -p sandslope --lib simulate::stride_probe -- --ignored
    (PROBE_DT, default 0.0005; PROBE_DURATION, default 4; PROBE_KS: one k_s at every slope
    with k_n 7e5 instead of the built-in terrain; PROBE_PITCH=free)

Usage: python3 bench/simulate/force_balance.py SLOPE_DEG /tmp/probe_24.csv [STEP]

Prints, for the step that starts at STEP x T/2 (default 4, the fifth step; tripod STEP mod 2
touches down), each window's displacement, mean speed and mean forces, the stance tripod's
mean along-slope push over mid-stance (100 to 400 ms) beside gravity's pull m g sin(theta), when
the belly leaves the sand after touchdown and when the speed is lowest in the step's first
50 ms (the end of phase 1 where the body slides back).
"""

import csv
import math
import sys

MASS_KG, G, HALF_S = 0.35, 9.81, 0.5
WINDOWS_S = [(0, 0.02), (0.02, 0.1), (0.1, 0.2), (0.2, 0.3), (0.3, 0.4), (0.4, 0.45), (0.45, 0.5)]


def main():
    slope = float(sys.argv[1])
    rows = list(csv.DictReader(open(sys.argv[2])))
    step = int(sys.argv[3]) if len(sys.argv) > 3 else 4
    d = {k: [float(r[k]) for r in rows] for k in rows[0]}
    dt = d["t_s"][1] - d["t_s"][0]
    th = math.radians(slope)
    new, old = ("t0", "t1") if step % 2 == 0 else ("t1", "t0")
    i0 = int(round(step * HALF_S / dt)) - 1
    print(f"{slope} deg: m g sin = {MASS_KG * G * math.sin(th):.3f} N, m g cos = {MASS_KG * G * math.cos(th):.3f} N")
    print("| window ms | dx mm | mean speed cm/s | belly x, z N | new tripod x, z N | old tripod x, z N |")
    print("|---|---:|---:|---|---|---|")
    for a, b in WINDOWS_S:
        ia, ib = i0 + int(round(a / dt)), i0 + int(round(b / dt))

        def mean(k, ia=ia, ib=ib):
            return sum(d[k][ia + 1 : ib + 1]) / (ib - ia)

        dx = (d["x_m"][ib] - d["x_m"][ia]) * 1e3
        print(
            f"| {a * 1e3:.0f}-{b * 1e3:.0f} | {dx:.2f} | {mean('vx_m_s') * 100:.2f} | "
            f"{mean('belly_x'):+.2f}, {mean('belly_z'):+.2f} | {mean(new + '_x'):+.2f}, {mean(new + '_z'):+.2f} | "
            f"{mean(old + '_x'):+.2f}, {mean(old + '_z'):+.2f} |"
        )
    ia, ib = i0 + int(round(0.1 / dt)), i0 + int(round(0.4 / dt))
    fx = sum(d[new + "_x"][ia + 1 : ib + 1]) / (ib - ia)
    fz = sum(d[new + "_z"][ia + 1 : ib + 1]) / (ib - ia)
    print(f"mid-stance push {fx:.3f} N over {fz:.3f} N normal (ratio {fx / fz:.3f}); m g sin {MASS_KG * G * math.sin(th):.3f} N")
    n = int(round(HALF_S / dt))
    print(f"step {(d['x_m'][i0 + n] - d['x_m'][i0]) * 1e3:.2f} mm")
    early = range(i0 + 1, i0 + int(round(0.05 / dt)) + 1)
    off = next((i for i in early if d["belly_z"][i] == 0.0 and d["belly_x"][i] == 0.0), None)
    low = min(early, key=lambda i: d["vx_m_s"][i])
    on = abs(d["belly_z"][i0 + 1]) > 0.0
    print(
        f"belly {'in' if on else 'off'} the sand at touchdown, "
        + (f"off it {(off - i0) * dt * 1e3:.1f} ms after; " if on and off is not None else "")
        + f"lowest speed in the first 50 ms {d['vx_m_s'][low] * 100:.2f} cm/s at {(low - i0) * dt * 1e3:.1f} ms"
    )


if __name__ == "__main__":
    main()
