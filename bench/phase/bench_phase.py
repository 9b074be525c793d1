#!/usr/bin/env python3
"""Times `sandslope phase` against a straightforward NumPy implementation of the same
equations (docs/model.md §3-§6) on a 4096 x 4096 (k_n, k_s) grid, in one run, and
prints the ratio. The issue requires sandslope to be at least 50x faster.

Usage (from anywhere):  python3 bench/phase/bench_phase.py [--n 4096] [--slope 20] [--repeat 3]

- Builds the release binary first (`cargo build --release -p sandslope-cli`, not timed).
- Installs numpy with pip if it is missing.
- Robot and terrain are the built-in presets, read through `sandslope presets show`, so
  both implementations use the same numbers.
- sandslope is timed end to end as a process (start-up, loading, the map, the JSON
  summary); NumPy is timed in-process (meshgrid + every equation over the full grid),
  which favours NumPy. Best of --repeat runs each.
- The regime counts of both are compared cell for cell in total, as a correctness check.
"""
import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def ensure_numpy():
    try:
        import numpy  # noqa: F401
    except ImportError:
        base = [sys.executable, "-m", "pip", "install", "--quiet", "numpy"]
        for extra in ([], ["--user"], ["--user", "--break-system-packages"]):
            if subprocess.call(base + extra) == 0:
                break
        else:
            sys.exit("could not pip-install numpy")
        import site
        import importlib

        importlib.invalidate_caches()
        sys.path.append(site.getusersitepackages())
    import numpy

    return numpy


def load_toml(text):
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        subprocess.check_call([sys.executable, "-m", "pip", "install", "--quiet", "tomli"])
        import tomli as tomllib
    return tomllib.loads(text)


def phase_numpy(np, robot, repose_deg, slope_deg, k_n, k_s):
    """Regime codes (0 sinkage, 1 slippage, 2 metastable, 3 success) and net step, rows = k_s."""
    g = 9.81
    th = math.radians(slope_deg)
    m, R, W, h = robot["mass_kg"], robot["leg_radius_m"], robot["leg_width_m"], robot["hip_height_m"]
    omega, n, dt = robot["leg_speed_rad_s"], robot["stance_legs"], robot["response_time_s"]
    A = robot.get("leg_contact_area_m2", W * R)
    s_min = robot.get("min_step_m", R)
    d_max = 2 * R - h
    half = math.pi / omega
    KN, KS = np.meshgrid(k_n, k_s)
    d_n = m * g * math.cos(th) / n / (KN * A)
    sunk = d_n >= d_max
    if "level_step_m" in robot:
        s_star = np.full_like(KN, robot["level_step_m"])
    else:
        x = d_n + h - R
        s_star = np.where(sunk, 0.0, 2.0 * np.sqrt(np.maximum(R * R - x * x, 0.0)))
    F_a = m * (g * math.sin(th) + R * omega / dt) / n
    d_s = np.sqrt(F_a / (KS * W))
    anchored = d_s <= d_max
    phi0 = math.asin((h - R) / R)
    t1 = (np.arcsin(np.clip((d_s + h) / R - 1.0, -1.0, 1.0)) - phi0) / omega
    gs = g * math.sin(th)
    step = s_star * ((half - t1) / half) ** 2 - gs * t1 * (half - t1) - 0.5 * gs * t1 * t1
    step = np.where(anchored, step, np.nan)
    regime = np.full(KN.shape, 3, dtype=np.int8)
    regime[step < s_min] = 2
    regime[(step <= 0) | ~anchored] = 1
    if repose_deg is not None and slope_deg >= repose_deg:
        regime[:] = 1
    regime[sunk] = 0
    return regime, step


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=4096)
    ap.add_argument("--slope", type=float, default=20.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    np = ensure_numpy()

    subprocess.check_call(["cargo", "build", "--release", "--quiet", "-p", "sandslope-cli"], cwd=ROOT)
    exe = os.path.join(ROOT, "target", "release", "sandslope")
    robot = load_toml(subprocess.check_output([exe, "presets", "show", "paper-hexapod"], text=True))
    terrain = load_toml(subprocess.check_output([exe, "presets", "show", "glass-beads-300um"], text=True))
    kn_axis, ks_axis = (7e3, 7e7), (2e3, 2e8)
    n = args.n
    cmd = [
        exe, "phase", "--slope", str(args.slope),
        "--k-n", f"{kn_axis[0]}:{kn_axis[1]}:{n}:log", "--k-s", f"{ks_axis[0]}:{ks_axis[1]}:{n}:log", "--json",
    ]

    def child_cpu():
        r = resource.getrusage(resource.RUSAGE_CHILDREN)
        return r.ru_utime + r.ru_stime

    rust_times, rust_cpu, summary = [], [], None
    for _ in range(args.repeat):
        c0, t0 = child_cpu(), time.perf_counter()
        out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
        rust_times.append(time.perf_counter() - t0)
        rust_cpu.append(child_cpu() - c0)
        summary = json.loads(out)[0]

    k_n = np.geomspace(kn_axis[0], kn_axis[1], n)
    k_s = np.geomspace(ks_axis[0], ks_axis[1], n)
    np_times, np_cpu = [], []
    for _ in range(args.repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        regime, step = phase_numpy(np, robot, terrain.get("repose_deg"), args.slope, k_n, k_s)
        np_times.append(time.perf_counter() - t0)
        np_cpu.append(time.process_time() - c0)

    names = ["sinkage", "slippage", "metastable", "success"]
    np_counts = {name: int((regime == k).sum()) for k, name in enumerate(names)}
    mismatch = sum(abs(np_counts[k] - summary["counts"][k]) for k in names)
    t_rust, t_np = min(rust_times), min(np_times)
    print(f"grid {n} x {n} = {n * n:,} cells at {args.slope} deg, robot paper-hexapod, cores: {os.cpu_count()}")
    print(f"sandslope phase (whole process, best of {args.repeat}): {t_rust * 1e3:9.1f} ms wall, "
          f"{min(rust_cpu) * 1e3:9.1f} ms CPU (all threads)")
    print(f"NumPy {np.__version__} (in-process, best of {args.repeat}):     {t_np * 1e3:9.1f} ms wall, "
          f"{min(np_cpu) * 1e3:9.1f} ms CPU")
    print(f"regime counts sandslope: {summary['counts']}")
    print(f"regime counts NumPy:     {np_counts}  (total |difference| = {mismatch} cells)")
    ratio = t_np / t_rust
    print(f"CPU-time ratio NumPy / sandslope: {min(np_cpu) / min(rust_cpu):.1f}x (less sensitive to other load)")
    print(f"ratio NumPy / sandslope (wall): {ratio:.1f}x  (target >= 50x: {'met' if ratio >= 50 else 'NOT met'})")


if __name__ == "__main__":
    main()
