#!/usr/bin/env python3
"""sandslope.phase against NumPy in the same process, on an N x N (k_n, k_s) grid.

Usage (inside an environment where `import sandslope` works, e.g. after bash scripts/test.sh:
`.venv/bin/python bench/python/bench_phase.py [--n 2048] [--slope 20] [--repeat 9]`).

Three implementations of the same equations (docs/model.md §3-§6), each returning the regime
(int8) and the net step (float64) of every cell:

- sandslope.phase: the library's PhaseMap (per-axis parts once, binary search for the regime
  thresholds within each k_s row, rows in parallel), written straight into the output arrays;
- "plain" NumPy: every equation evaluated over the full grid (np.meshgrid), the direct
  translation of the model, as bench/phase/bench_phase.py does;
- "separable" NumPy: a well-written vectorised peer that also evaluates the k_n-only parts
  (d_n, s*) once per column and the k_s-only parts (d_s, t1 and the step terms) once per row,
  and broadcasts only the final step and regime over the grid.

Regime only (`sandslope.phase(..., regime_only=True)`, no step array) against the same two
peers asked for the regime only: the plain one still builds every equation over the grid; the
separable one compares each column's s* with two per-row thresholds (s > 0 iff
s* > (drag + slip) / scale, s >= s_min iff s* >= (s_min + drag + slip) / scale), two
broadcast comparisons and no float array over the grid.

Every peer is checked cell for cell against sandslope (regimes equal; steps equal to 1e-12
relative). Timings are wall-clock and CPU time (all threads of the process): after one
warm-up call each, the implementations run in turn (interleaved) --repeat times and the
medians are printed, so load from other work on the machine hits all of them alike. The
issue's targets: sandslope.phase at least 20x faster than the plain NumPy implementation,
and at least 3x the separable one with the regime only on both sides.
"""

import argparse
import math
import os
import statistics
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


def regime_separable(robot, slope_deg, k_n, k_s):
    """Regime only: each column's s* against two per-row thresholds, no step over the grid."""
    p = parts(robot, slope_deg)
    g, th, R, h, half, d_max = p["g"], p["th"], p["R"], p["h"], p["half"], p["d_max"]
    d_n = p["m"] * g * math.cos(th) / p["n"] / (k_n * p["A"])
    sunk = d_n >= d_max
    if p["level"] is not None:
        s_star = np.full_like(k_n, p["level"])
    else:
        x = d_n + h - R
        s_star = np.where(sunk, 0.0, 2.0 * np.sqrt(np.maximum(R * R - x * x, 0.0)))
    F_a = p["m"] * (g * math.sin(th) + R * p["omega"] / p["dt"]) / p["n"]
    d_s = np.sqrt(F_a / (k_s * p["W"]))
    anchored = d_s <= d_max
    t1 = (np.arcsin(np.clip((d_s + h) / R - 1.0, -1.0, 1.0)) - p["phi0"]) / p["omega"]
    gs = g * math.sin(th)
    left = half - t1
    scale = (left / half) ** 2
    offset = gs * t1 * left + 0.5 * gs * t1 * t1
    with np.errstate(divide="ignore", invalid="ignore"):
        above0 = np.where(anchored, offset / scale, np.inf)[:, None]  # s > 0 iff s* > this
        above1 = np.where(anchored, (p["s_min"] + offset) / scale, np.inf)[:, None]
    regime = (s_star[None, :] > above0).view(np.int8) + (s_star[None, :] >= above1).view(np.int8)
    regime += 1
    regime[:, sunk] = 0
    return regime


def interleaved(fs, repeat):
    """Median wall and CPU time (all threads of this process) of each function, run in turn."""
    outs = [f() for f in fs]  # warm-up: page-in, caches, thread pool
    wall, cpu = [[] for _ in fs], [[] for _ in fs]
    for _ in range(repeat):
        for k, f in enumerate(fs):
            c0, t0 = time.process_time(), time.perf_counter()
            outs[k] = f()
            wall[k].append(time.perf_counter() - t0)
            cpu[k].append(time.process_time() - c0)
    return [(statistics.median(w), statistics.median(c)) for w, c in zip(wall, cpu)], outs


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=2048)
    ap.add_argument("--slope", type=float, default=20.0)
    ap.add_argument("--repeat", type=int, default=9)
    args = ap.parse_args()
    robot = sandslope.Robot.preset("paper-hexapod")
    n = args.n
    k_n = np.geomspace(7e3, 7e7, n)
    k_s = np.geomspace(2e3, 2e8, n)

    m = sandslope.phase(robot, args.slope, k_n, k_s)
    # The NumPy peers run on sandslope's own axis values, so cells can be compared exactly.
    kn, ks = m["k_n"], m["k_s"]
    names = ["sandslope.phase", "NumPy (plain)", "NumPy (separable)"]
    times, (m, (r_plain, s_plain), (r_sep, s_sep)) = interleaved(
        [
            lambda: sandslope.phase(robot, args.slope, k_n, k_s),
            lambda: phase_plain(robot, args.slope, kn, ks),
            lambda: phase_separable(robot, args.slope, kn, ks),
        ],
        args.repeat,
    )
    for name, r, s in (("plain", r_plain, s_plain), ("separable", r_sep, s_sep)):
        np.testing.assert_array_equal(r.T, m["regime"], err_msg=f"{name} regimes")
        np.testing.assert_allclose(s.T, m["step_m"], rtol=1e-12, atol=1e-15, err_msg=f"{name} steps")
    times_r, (mr, (r_plain, _), r_sep) = interleaved(
        [
            lambda: sandslope.phase(robot, args.slope, k_n, k_s, regime_only=True),
            lambda: phase_plain(robot, args.slope, kn, ks),
            lambda: regime_separable(robot, args.slope, kn, ks),
        ],
        args.repeat,
    )
    assert "step_m" not in mr
    for name, r in (("plain", r_plain), ("separable, regime only", r_sep)):
        np.testing.assert_array_equal(r.T, m["regime"], err_msg=f"{name} regimes")

    print(f"phase map {n} x {n} = {n * n:,} cells at {args.slope} deg, paper-hexapod, {os.cpu_count()} cores, "
          f"NumPy {np.__version__}; medians of {args.repeat} interleaved runs; load average {os.getloadavg()[0]:.1f}")
    for title, rows in (("regime and step", times), ("regime only", times_r)):
        t_ss = rows[0]
        print(f"  {title + ':':18} {'wall ms':>9} {'ratio':>7}   {'CPU ms':>9} {'ratio':>7}")
        for name, (w, c) in zip(names, rows):
            print(f"  {name:18} {w * 1e3:9.1f} {w / t_ss[0]:6.1f}x   {c * 1e3:9.1f} {c / t_ss[1]:6.1f}x")
    print("  targets: sandslope.phase >= 20x faster (wall) than plain NumPy, >= 3x the separable peer with the")
    print("  regime only on both sides; CPU time counts every thread, so its ratio is the speed-up per core.")
    print("  Regimes identical cell for cell; steps equal to 1e-12.")


if __name__ == "__main__":
    main()
