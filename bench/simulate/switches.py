#!/usr/bin/env python3
"""Each switch's effect on the free body (docs/simulate.md, "The free body's switches").

Usage: python3 bench/simulate/switches.py [--sandslope target/release/sandslope] [--robot-dir DIR]

Pitch-free ensembles of eight walks (`simulate --body-pitch free --ensemble 8`, the robot's
mass perturbed by 1e-9 between walks) at 0, 10, 15, 20 and 24 degrees, at the free body's
default step (T / 16000, 62.5 us) and at a quarter of it (15.6 us), one row per switch: the defaults (the one-sided
belly), the two-faced belly, the servo actuator, and the body's pitch inertia from its parts
(`pitch_inertia_kg_m2` in a robot file: six XL330-M288 servos of 18 g at the hips, x = 0 and
+/- (L/2 - R) = 0.07 m, the other 0.242 kg spread evenly over L = 0.22 m: 1.329e-3 kg m^2,
against the default m L^2 / 12 = 1.412e-3), and at half and twice the default. Each cell:
mean speed +/- SD of the walks in cm/s, mean t1 in ms, how many pitched over, the regime.
Every number comes from `sandslope simulate --json`. `--only TEXT` keeps the rows whose label
contains TEXT (the first two rows are phase1.py's `--only phase1 --pitch free` table as well).
"""

import argparse
import concurrent.futures
import json
import os
import subprocess
import tempfile

SLOPES = [0, 10, 15, 20, 24]
PRESET = "paper-hexapod"
INERTIA = {"parts": 1.329e-3, "half": 7.06e-4, "double": 2.823e-3}


def robot_file(exe, folder, name, inertia):
    text = subprocess.run([exe, "presets", "show", PRESET], capture_output=True, text=True, check=True).stdout
    path = os.path.join(folder, f"{name}.toml")
    with open(path, "w") as f:
        f.write(text + f"pitch_inertia_kg_m2 = {inertia}\n")
    return path


def ensemble(exe, args):
    cmd = [exe, "simulate", "--body-pitch", "free", "--ensemble", "8", *args, "--json"]
    d = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
    return d[0] if isinstance(d, list) else d


def cell(d):
    t1 = "-" if d.get("t1_s") is None else f"t1 {1e3 * d['t1_s']:.1f} ms"
    return (
        f"{100 * d['speed_m_s']:.2f} +/- {100 * d['speed_sd_m_s']:.2f}, {t1}, "
        f"{d['pitched_over']}/{d['walks']}, {d['regime']}"
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sandslope", default="target/release/sandslope")
    ap.add_argument("--only", help="one row label")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        rows = [
            ("one-sided belly (default)", []),
            ("two-faced belly", ["--two-faced-belly"]),
            ("servo actuator", ["--actuator", "servo"]),
        ]
        for name, inertia in INERTIA.items():
            rows.append((f"pitch inertia {inertia:.3e} kg m^2 ({name})", ["--robot", robot_file(a.sandslope, folder, name, inertia)]))
        if a.only:
            rows = [r for r in rows if a.only in r[0]]
        print("| switch | slope deg | dt = T / 16000 (default) | dt / 4 |")
        print("|---|---:|---|---|")
        with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
            for label, extra in rows:
                first = {s: pool.submit(ensemble, a.sandslope, ["--slope", str(s), *extra]) for s in SLOPES}
                dt = {s: first[s].result()["summaries"][0]["dt_s"] for s in SLOPES}
                quarter = {s: pool.submit(ensemble, a.sandslope, ["--slope", str(s), *extra, "--dt", repr(dt[s] / 4)]) for s in SLOPES}
                for s in SLOPES:
                    print(f"| {label} | {s} | {cell(first[s].result())} | {cell(quarter[s].result())} |", flush=True)


if __name__ == "__main__":
    main()
