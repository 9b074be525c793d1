#!/usr/bin/env python3
"""Times `sandslope phase --csv` against a NumPy + pandas peer that computes the same map
(bench_phase.phase_numpy) and writes the same CSV (k_n,k_s,slope_deg,mass_kg,regime,step_m,
one row per cell, k_s-major), and `phase --plot` against the same run without output.

Usage: python3 bench/phase/bench_csv.py [--n 4096] [--repeat 1] [--dir /dev/shm]
Needs numpy and pandas; builds the release binary first (not timed). --dir is where both
write their file (default: the system's temporary folder); on a machine whose disk is the
bottleneck (1.2 GB per file at 4096 x 4096), /dev/shm (memory) times the formatting rather
than the disk.
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
from bench_phase import ROOT, load_toml, phase_numpy  # noqa: E402


def best(cmd, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    return min(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=4096)
    ap.add_argument("--slope", type=float, default=20.0)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--dir", default=None, help="folder both write their CSV into (default: system temp)")
    args = ap.parse_args()
    import numpy as np
    import pandas as pd

    subprocess.check_call(["cargo", "build", "--release", "--quiet", "-p", "sandslope-cli"], cwd=ROOT)
    exe = os.path.join(ROOT, "target", "release", "sandslope")
    robot = load_toml(subprocess.check_output([exe, "presets", "show", "paper-hexapod"], text=True))
    terrain = load_toml(subprocess.check_output([exe, "presets", "show", "glass-beads-300um"], text=True))
    n = args.n
    grid = ["--slope", str(args.slope), "--k-n", f"7e3:7e7:{n}:log", "--k-s", f"2e3:2e8:{n}:log", "--json"]
    with tempfile.TemporaryDirectory(dir=args.dir) as tmp:
        ours = os.path.join(tmp, "ours.csv")
        peer = os.path.join(tmp, "peer.csv")
        t_none = best([exe, "phase", *grid], args.repeat)
        t_csv = best([exe, "phase", *grid, "--csv", ours], args.repeat)
        t_plot = best([exe, "phase", *grid, "--plot", os.path.join(tmp, "p.png")], args.repeat)
        with open(ours, "rb") as f:
            rows = sum(1 for _ in f) - 1
        t0 = time.perf_counter()
        k_n = np.geomspace(7e3, 7e7, n)
        k_s = np.geomspace(2e3, 2e8, n)
        regime, step = phase_numpy(np, robot, terrain.get("repose_deg"), args.slope, k_n, k_s)
        names = np.array(["sinkage", "slippage", "metastable", "success"])
        KN, KS = np.meshgrid(k_n, k_s)
        pd.DataFrame({
            "k_n": KN.ravel(), "k_s": KS.ravel(), "slope_deg": args.slope, "mass_kg": robot["mass_kg"],
            "regime": names[regime.ravel()], "step_m": step.ravel(),
        }).to_csv(peer, index=False)
        t_peer = time.perf_counter() - t0
        with open(peer, "rb") as f:
            peer_rows = sum(1 for _ in f) - 1
    print(f"grid {n} x {n} = {n * n:,} cells ({rows:,} CSV rows), cores: {os.cpu_count()}")
    print(f"sandslope phase, no output:      {t_none * 1e3:9.1f} ms")
    print(f"sandslope phase --csv:           {t_csv * 1e3:9.1f} ms")
    print(f"sandslope phase --plot (png):    {t_plot * 1e3:9.1f} ms  ({t_plot / t_none:.2f}x the run without output; target <= 3x)")
    print(f"NumPy {np.__version__} + pandas {pd.__version__} map + to_csv: {t_peer * 1e3:9.1f} ms")
    print(f"rows written: sandslope {rows:,}, peer {peer_rows:,}; load average {os.getloadavg()[0]:.1f}")
    print(f"ratio peer / sandslope --csv: {t_peer / t_csv:.1f}x (target >= 8x)")


if __name__ == "__main__":
    main()
