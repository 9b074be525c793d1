#!/usr/bin/env python3
"""The 600 s run at 1 turn/s (docs/drive.md, "Before it moves"): no goal a servo would reject.

Not part of the test suite (it takes about 15 minutes of wall time, little CPU). Runs:

1. `drive --dry-run --duration 600 --rate 1` (position profile): refused before anything moves,
   naming the longest run that fits (254 s) and the fix, `--profile velocity`;
2. `drive --dry-run --duration 600 --rate 1 --profile velocity`: every Goal Velocity within the
   Velocity Limit the setup writes (2 omega = 524 units at the paper's omega);
3. `drive --emulate --profile velocity --duration 600`: the emulated XL330-M288s answer any
   goal outside their ranges with a Data Range Error, which the driver's once-a-second read-back
   turns into exit 3; the run must complete (exit 0), torque off on every servo, and the log
   must hold 600 s of rows with the legs turning at 1 turn/s;
4. `drive --emulate --duration 250` (position profile, within its 254.6 s): the last goals
   within 1,048,575 pulses, the run completed.

Usage: python3 bench/drive/long_run.py [path/to/sandslope]   (default: target/release/sandslope,
else target/debug/sandslope). Prints one line per run and a summary for docs/drive.md.
"""

import csv
import math
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LIMIT = 1_048_575


def binary() -> str:
    if len(sys.argv) > 1:
        return sys.argv[1]
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "sandslope"
        if p.exists():
            return str(p)
    sys.exit("no sandslope binary: cargo build --release -p sandslope-cli, or give its path")


def run(*args):
    t0 = time.monotonic()
    p = subprocess.run([binary(), *args], capture_output=True, text=True)
    return p, time.monotonic() - t0


def rows(log: Path):
    with open(log) as f:
        body = [line for line in f if not line.startswith("#")]
    return list(csv.DictReader(body))


def main():
    out = []
    p, _ = run("drive", "--dry-run", "--duration", "600", "--rate", "1")
    m = re.search(r"lasts ([0-9.]+) s", p.stderr)
    assert p.returncode == 2 and m and "--profile velocity" in p.stderr, p.stderr
    out.append(f"position dry run 600 s: refused (exit 2), the longest run {m.group(1)} s")

    p, _ = run("drive", "--dry-run", "--duration", "600", "--rate", "1", "--profile", "velocity")
    assert p.returncode == 0, p.stderr
    limit = int(re.search(r"# write Velocity Limit \(44\) = (\d+)", p.stdout).group(1))
    goals = [int(line.rsplit(",", 1)[1]) for line in p.stdout.splitlines() if line and line[0].isdigit()]
    assert goals and max(abs(g) for g in goals) <= limit, (max(goals), limit)
    out.append(f"velocity dry run 600 s: {len(goals)} goals, largest |Goal Velocity| {max(abs(g) for g in goals)} <= Velocity Limit {limit}")

    with tempfile.TemporaryDirectory() as d:
        for label, extra, duration in (
            ("velocity", ["--profile", "velocity"], 600),
            ("position", [], 250),
        ):
            log = Path(d) / f"{label}.csv"
            p, wall = run("drive", "--emulate", "--duration", str(duration), "--watchdog", "2", "--log", str(log), *extra)
            assert p.returncode == 0, p.stderr[-2000:]
            assert "emulator: torque off on every servo" in p.stderr, p.stderr[-2000:]
            r = rows(log)
            t = [float(x["time_s"]) for x in r]
            goal = [int(x["goal_position"]) for x in r]
            pos = [int(x["present_position"]) for x in r]
            leg0 = [(float(x["time_s"]), float(x["leg_angle_rad"])) for x in r if x["leg"] == "0" and float(x["time_s"]) > 1]
            n = len(leg0)
            mt = sum(a for a, _ in leg0) / n
            ma = sum(b for _, b in leg0) / n
            slope = sum((a - mt) * (b - ma) for a, b in leg0) / sum((a - mt) ** 2 for a, _ in leg0)
            rate = re.search(r"cycles at ([0-9.]+) Hz", p.stderr).group(1)
            line = (
                f"emulated {label} run {duration} s: completed in {wall:.0f} s wall, last row t = {max(t):.2f} s, "
                f"{len(r) // 6} cycles at {rate} Hz, leg 0 at {slope / (2 * math.pi):.4f} turns/s, "
                f"largest |present position| {max(abs(x) for x in pos)} pulses"
            )
            if label == "position":
                assert max(abs(g) for g in goal) <= LIMIT
                line += f", largest |goal| {max(abs(g) for g in goal)} <= {LIMIT}"
            out.append(line)
            print(line, flush=True)
    print("\n".join(out))


if __name__ == "__main__":
    main()
