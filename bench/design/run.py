#!/usr/bin/env python3
"""Benchmark of `sandslope design` on 10^5 designs, against `risk --solve slope` per design.

What it does (run from anywhere; builds the release binary the first time):
1. builds the release binary (`cargo build --release -p sandslope-cli`);
2. times `sandslope design` over 10 x 10 x 10 x 10 x 10 = 100 000 designs (leg radius, mass,
   leg width, hip height, leg speed) on the built-in terrain with the default CVs, writing every
   design to a CSV file, `--repeat` times (default 3), and reports each run, the median, how
   many runs met the 60 s target, the CPU time (user + system, all threads), the machine's core count and the 1-minute load average
   (2 cores are shared by several sessions on the development machine);
3. times `sandslope risk --solve slope` for a sample of the same designs, one process each, and
   prints the time 10^5 of them would take and the ratio to the median design run (until the
   risk command shared design's fast search, this was the general routine: adaptive Simpson
   quadrature of P(slippage) and P(not success) with Brent's method for each critical k_s; it
   now runs the same search, plus one reference quadrature and a process start per design);
4. checks that the sampled designs' safe-slope limits in the design CSV are the numbers
   `risk --solve slope` printed.

Usage: python3 bench/design/run.py [--repeat 3] [--sample 20]
"""
import argparse
import csv
import json
import os
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

VARY = [
    "leg_radius_m=0.03:0.06:10",
    "mass_kg=0.2:2.0:10:log",
    "leg_width_m=0.005:0.03:10:log",
    "hip_height_m=0.0:0.06:10",
    "leg_speed_rad_s=3:12:10",
]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--sample", type=int, default=20, help="designs timed with risk --solve slope")
    args = ap.parse_args()
    subprocess.check_call(["cargo", "build", "--release", "-q", "-p", "sandslope-cli"], cwd=ROOT)
    exe = os.path.join(ROOT, "target", "release", "sandslope")
    work = os.path.join(ROOT, "target", "bench-design")
    os.makedirs(work, exist_ok=True)
    out_csv = os.path.join(work, "designs.csv")
    cmd = [exe, "design", "--vary", ",".join(VARY), "--slope-target", "15", "--csv", out_csv, "--json"]

    print(f"cores: {os.cpu_count()}, load average (1 min) before: {os.getloadavg()[0]:.2f}")
    times, cpus = [], []
    for i in range(args.repeat):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        res = subprocess.run(cmd, check=True, capture_output=True)
        dt = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        times.append(dt)
        cpus.append(cpu)
        summary = json.loads(res.stdout)
        print(
            f"run {i + 1}: {dt:.2f} s wall, {cpu:.2f} s CPU (all threads) for {summary['designs_evaluated']} designs "
            f"({summary['invalid']} invalid), load average now {os.getloadavg()[0]:.2f}"
        )
    med = statistics.median(times)
    cpu_med = statistics.median(cpus)
    print(f"sandslope design, median of {len(times)}: {med:.2f} s wall; under 60 s in {sum(t < 60 for t in times)}/{len(times)} runs")
    print(f"median CPU {cpu_med:.2f} s: {cpu_med / 2:.1f} s of wall time on two otherwise idle cores")

    with open(out_csv) as f:
        rows = list(csv.DictReader(f))
    valid = [r for r in rows if r["valid"] == "true"]
    step = max(1, len(valid) // args.sample)
    sample = valid[::step][: args.sample]
    per = []
    for r in sample:
        robot = os.path.join(work, "robot.toml")
        with open(robot, "w") as f:
            f.write(
                f"mass_kg = {r['mass_kg']}\nleg_radius_m = {r['leg_radius_m']}\nleg_width_m = {r['leg_width_m']}\n"
                f"hip_height_m = {r['hip_height_m']}\nleg_speed_rad_s = {r['leg_speed_rad_s']}\n"
                "stance_legs = 3\nresponse_time_s = 0.2\n"
            )
        t0 = time.perf_counter()
        res = subprocess.run(
            [exe, "risk", "--robot", robot, "--solve", "slope", "--json"],
            check=True,
            capture_output=True,
        )
        per.append(time.perf_counter() - t0)
        want = json.loads(res.stdout)["safe_slope_deg"]
        got = float(r["safe_slope_deg"]) if r["safe_slope_deg"] else None
        if want != got:
            print(f"MISMATCH: design {r} has {got}, risk --solve slope {want}")
            sys.exit(1)
    mean = statistics.mean(per)
    print(
        f"risk --solve slope: {mean * 1e3:.1f} ms per design (mean of {len(per)}, one process each); "
        f"10^5 designs would take {mean * 1e5:.0f} s, {mean * 1e5 / med:.0f}x the design run"
    )
    print(f"safe-slope limits of the {len(per)} sampled designs: identical to risk --solve slope")


if __name__ == "__main__":
    main()
