#!/usr/bin/env python3
"""Times `calibrate --model simulate` on the paper's evidence (docs/calibration.md, "With the
simulator in place of the closed form"), and compares the fits of two builds.

Usage: python3 bench/calibrate/simulate_fit.py EXE [EXE2] [--threads N] [--json-out FILE]

Runs, from the repository root, the command the page names,

    EXE calibrate --observed data/paper-speeds.csv --forces data/example-force-tests.toml \
        --free plate_scale,error_floor --model simulate --json --out TMP/terrain.toml

once per binary (one after the other, the second build second), and prints for each: wall
time, CPU time (user + system of the process and its threads, from `os.wait4`), the achieved
parallelism CPU / wall, the 1-minute load average before and after (other users of the cores
slow the wall time, not the CPU time), the walks run, and the fit: every fitted value with its
68% interval, k_s(20)/k_s(0), chi^2, the floor and the pulls. With two binaries it prints them
side by side with each pair's relative difference and whether the two agree to 2 significant
digits. `--threads N` sets RAYON_NUM_THREADS (default: rayon's own, one per core).
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

ARGS = [
    "calibrate",
    "--observed",
    "data/paper-speeds.csv",
    "--forces",
    "data/example-force-tests.toml",
    "--free",
    "plate_scale,error_floor",
    "--model",
    "simulate",
    "--json",
]


def run(exe, threads):
    env = dict(os.environ)
    if threads:
        env["RAYON_NUM_THREADS"] = str(threads)
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryFile() as out, tempfile.TemporaryDirectory() as tmp:
        terrain = os.path.join(tmp, "terrain.toml")
        t0 = time.perf_counter()
        p = subprocess.Popen([exe, *ARGS, "--out", terrain], stdout=out, stderr=subprocess.DEVNULL, env=env)
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        if status != 0:
            raise SystemExit(f"{exe} {' '.join(ARGS)} failed (status {status})")
        out.seek(0)
        fit = json.load(out)
    cpu = usage.ru_utime + usage.ru_stime
    return {
        "exe": exe,
        "wall_s": wall,
        "cpu_s": cpu,
        "parallelism": cpu / wall if wall > 0 else float("nan"),
        "load_before": load0,
        "load_after": os.getloadavg()[0],
        "fit": fit,
    }


def rows(fit):
    """(name, value) of every number the comparison checks."""
    out = []
    for p in fit["parameters"]:
        for key in ("value", "lower", "upper"):
            out.append((f"{p['name']} {key}", p[key]))
    r = fit["shear_ratio_20"]
    for key in ("value", "lower", "upper"):
        out.append((f"k_s(20)/k_s(0) {key}", r[key]))
    out.append(("chi^2", fit["chi_squared"]))
    out.append(("error floor (m/s)", fit["error_floor_m_s"]))
    for p in fit["pulls"]:
        if p["kind"] == "speed":
            out.append((f"model speed {p['slope_deg']:g} deg (m/s)", p["model"]))
        out.append((f"pull {p['kind']} {p['slope_deg']:g} deg", p["pull"]))
    return out


def same_to_2_digits(a, b):
    """Both round to the same 2 significant digits (or differ by under 0.5e-2 of the larger)."""
    if a == b:
        return True
    if not (math.isfinite(a) and math.isfinite(b)):
        return False
    fmt = lambda v: f"{v:.1e}"
    return fmt(a) == fmt(b) or abs(a - b) <= 0.005 * max(abs(a), abs(b))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("exe", nargs="+")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--json-out")
    a = ap.parse_args()
    if len(a.exe) > 2:
        raise SystemExit("at most two binaries")
    runs = [run(exe, a.threads) for exe in a.exe]
    for r in runs:
        print(
            f"{r['exe']}: wall {r['wall_s']:.1f} s, CPU {r['cpu_s']:.1f} s, parallelism "
            f"{r['parallelism']:.2f}, load {r['load_before']:.1f} -> {r['load_after']:.1f}, "
            f"walks {r['fit']['walks']}"
        )
    table = [rows(r["fit"]) for r in runs]
    if len(runs) == 1:
        for name, v in table[0]:
            print(f"  {name}: {v:.6g}")
    else:
        bad = 0
        print(f"  {'quantity':36} {'first':>12} {'second':>12} {'rel diff':>9}  2 digits")
        for (name, x), (_, y) in zip(*table):
            ok = same_to_2_digits(x, y)
            bad += not ok
            rel = abs(x - y) / max(abs(x), abs(y)) if max(abs(x), abs(y)) > 0 else 0.0
            print(f"  {name:36} {x:12.5g} {y:12.5g} {rel:9.2e}  {'same' if ok else 'DIFFERENT'}")
        print(f"{bad} of {len(table[0])} numbers differ in their 2 significant digits")
    if a.json_out:
        with open(a.json_out, "w") as f:
            json.dump(runs, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
