#!/usr/bin/env python3
"""sandslope.phase against NumPy in the same process, on an N x N (k_n, k_s) grid.

Usage (inside an environment where `import sandslope` works, e.g. after bash scripts/test.sh:
`.venv/bin/python bench/python/bench_phase.py [--n 2048] [--slope 20] [--repeat 5]`).

Three implementations of the same equations (docs/model.md §3-§6), each returning the regime
(int8) and the net step (float64) of every cell:

- sandslope.phase: the library's PhaseMap (per-axis parts once, binary search for the regime
  thresholds within each k_s row, rows in parallel), written straight into the output arrays;
- "plain" NumPy: every equation evaluated over the full grid (np.meshgrid), the direct
  translation of the model, as bench/phase/bench_phase.py does;
- "separable" NumPy: a well-written vectorised peer that also evaluates the k_n-only parts
  (d_n, s*) once per column and the k_s-only parts (d_s, t1 and the step terms) once per row,
  and broadcasts only the final step and regime over the grid.

Both NumPy peers are checked cell for cell against sandslope (regimes equal; steps equal to
1e-12 relative). Timings are wall-clock, best of --repeat, after one warm-up call each. The
issue's target: sandslope.phase at least 20x faster than the plain NumPy implementation.
"""

import argparse
import math
import os
import time

import numpy as np

import sandslope


def parts(robot, slope_deg):
    r = robot.to_dict()
    g = 9.81
    th = math.radians(slope_deg)
    m, R, W, h = r["mass_kg"], r["leg_radius_m"], r["leg_width_m"], r["hip_height_m"]
    omega, n, dt = r["leg_speed_rad_s"], r["stance_legs"], r["response_time_s"]
    return dict(
        g=g,
        th=th,
        m=m,
        R=R,
        W=W,
        h=h,
        omega=omega,
        n=n,
        dt=dt,
        A=r.get("leg_contact_area_m2", W * R),
        s_min=r.get("min_step_m", R),
        level=r.get("level_step_m"),
        d_max=2 * R - h,
        half=math.pi / omega,
        phi0=math.asin((h - R) / R),
    )


def phase_plain(robot, slope_deg, k_n, k_s):
    """Every equation over the full grid; rows = k_s, as sandslope stores them."""
    p = parts(robot, slope_deg)
    g, th, R, h, half, d_max = p["g"], p["th"], p["R"], p["h"], p["half"], p["d_max"]
    KN, KS = np.meshgrid(k_n, k_s)
    d_n = p["m"] * g * math.cos(th) / p["n"] / (KN * p["A"])
    sunk = d_n >= d_max
    if p["level"] is not None:
        s_star = np.full_like(KN, p["level"])
    else:
        x = d_n + h - R
        s_star = np.where(sunk, 0.0, 2.0 * np.sqrt(np.maximum(R * R - x * x, 0.0)))
    F_a = p["m"] * (g * math.sin(th) + R * p["omega"] / p["dt"]) / p["n"]
    d_s = np.sqrt(F_a / (KS * p["W"]))
    anchored = d_s <= d_max
    t1 = (np.arcsin(np.clip((d_s + h) / R - 1.0, -1.0, 1.0)) - p["phi0"]) / p["omega"]
    gs = g * math.sin(th)
    left = half - t1
    step = s_star * (left / half) ** 2 - gs * t1 * left - 0.5 * gs * t1 * t1
    step = np.where(anchored, step, np.nan)
    regime = np.full(KN.shape, 3, dtype=np.int8)
    regime[step < p["s_min"]] = 2
    regime[(step <= 0) | ~anchored] = 1
    regime[sunk] = 0
    return regime, step


def phase_separable(robot, slope_deg, k_n, k_s):
    """Per-axis parts once, then the step and the regime broadcast over the grid."""
    p = parts(robot, slope_deg)
    g, th, R, h, half, d_max = p["g"], p["th"], p["R"], p["h"], p["half"], p["d_max"]
    d_n = p["m"] * g * math.cos(th) / p["n"] / (k_n * p["A"])  # per column
    sunk = d_n >= d_max
    if p["level"] is not None:
        s_star = np.full_like(k_n, p["level"])
    else:
        x = d_n + h - R
        s_star = np.where(sunk, 0.0, 2.0 * np.sqrt(np.maximum(R * R - x * x, 0.0)))
    F_a = p["m"] * (g * math.sin(th) + R * p["omega"] / p["dt"]) / p["n"]
    d_s = np.sqrt(F_a / (k_s * p["W"]))  # per row
    anchored = d_s <= d_max
    t1 = (np.arcsin(np.clip((d_s + h) / R - 1.0, -1.0, 1.0)) - p["phi0"]) / p["omega"]
    gs = g * math.sin(th)
    left = half - t1
    scale = np.where(anchored, (left / half) ** 2, np.nan)[:, None]
    offset = (gs * t1 * left + 0.5 * gs * t1 * t1)[:, None]
    step = s_star[None, :] * scale
    step -= offset  # NaN rows stay NaN
    regime = np.where(step >= p["s_min"], np.int8(3), np.int8(2))
    regime[~(step > 0)] = 1  # s <= 0 or no anchoring (NaN)
    regime[:, sunk] = 0
    return regime, step


def best(f, repeat):
    """Best wall time and best CPU time (all threads of this process) over `repeat` calls."""
    f()  # warm-up: page-in, caches, thread pool
    wall, cpu = [], []
    out = None
    for _ in range(repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        out = f()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return (min(wall), min(cpu)), out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=2048)
    ap.add_argument("--slope", type=float, default=20.0)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    robot = sandslope.Robot.preset("paper-hexapod")
    n = args.n
    k_n = np.geomspace(7e3, 7e7, n)
    k_s = np.geomspace(2e3, 2e8, n)

    t_ss, m = best(lambda: sandslope.phase(robot, args.slope, k_n, k_s), args.repeat)
    # The NumPy peers run on sandslope's own axis values, so cells can be compared exactly.
    kn, ks = m["k_n"], m["k_s"]
    t_plain, (r_plain, s_plain) = best(lambda: phase_plain(robot, args.slope, kn, ks), args.repeat)
    t_sep, (r_sep, s_sep) = best(lambda: phase_separable(robot, args.slope, kn, ks), args.repeat)

    for name, r, s in (("plain", r_plain, s_plain), ("separable", r_sep, s_sep)):
        np.testing.assert_array_equal(r.T, m["regime"], err_msg=f"{name} regimes")
        np.testing.assert_allclose(s.T, m["step_m"], rtol=1e-12, atol=1e-15, err_msg=f"{name} steps")

    print(f"phase map {n} x {n} = {n * n:,} cells at {args.slope} deg, paper-hexapod, {os.cpu_count()} cores, "
          f"NumPy {np.__version__}; best of {args.repeat}; load average {os.getloadavg()[0]:.1f}")
    print(f"  {'':18} {'wall ms':>9} {'ratio':>7}   {'CPU ms':>9} {'ratio':>7}")
    for name, (w, c) in (("sandslope.phase", t_ss), ("NumPy (plain)", t_plain), ("NumPy (separable)", t_sep)):
        print(f"  {name:18} {w * 1e3:9.1f} {w / t_ss[0]:6.1f}x   {c * 1e3:9.1f} {c / t_ss[1]:6.1f}x")
    print("  target: sandslope.phase >= 20x faster (wall) than plain NumPy; CPU time counts every thread,")
    print("  so its ratio is the speed-up per core. Regimes identical cell for cell; steps equal to 1e-12.")


if __name__ == "__main__":
    main()
