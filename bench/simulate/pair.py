#!/usr/bin/env python3
"""Two sandslope builds' stride simulator, timed in one run (docs/simulate.md, "Speed").

Usage: python3 bench/simulate/pair.py BEFORE AFTER [--rounds 5]

Runs `simulate --json` on the built-in robot and terrain (10 s walks at the defaults) level, at
10 and 20 degrees and as the 31-slope sweep `--slopes 0:30:31`, alternating the two binaries
(which goes first flips every round, so drifting load falls on both alike), and prints the
median wall and CPU time (user + system, from `os.wait4`) of each and the ratio of CPU times.
"""

import argparse
import os
import statistics
import subprocess
import time

CASES = {
    "level": ["--slope", "0"],
    "10 degrees": ["--slope", "10"],
    "20 degrees": ["--slope", "20"],
    "31 slopes": ["--slopes", "0:30:31"],
}


def timed(exe, args):
    t0 = time.perf_counter()
    p = subprocess.Popen([exe, "simulate", *args, "--json"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(p.pid, 0)
    if status != 0:
        raise SystemExit(f"{exe} simulate {' '.join(args)} failed (status {status})")
    return time.perf_counter() - t0, usage.ru_utime + usage.ru_stime


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--rounds", type=int, default=5)
    a = ap.parse_args()
    builds = [("before", a.before), ("after", a.after)]
    times = {(b, c): [] for b, _ in builds for c in CASES}
    for r in range(a.rounds):
        for case, args in CASES.items():
            for name, exe in builds if r % 2 == 0 else builds[::-1]:
                times[(name, case)].append(timed(exe, args))
    print(f"load average {os.getloadavg()[0]:.1f}")
    for case in CASES:
        med = {b: [statistics.median(x[i] for x in times[(b, case)]) for i in (0, 1)] for b, _ in builds}
        print(
            f"{case}: before wall {med['before'][0]:.3f} s, CPU {med['before'][1]:.3f} s; "
            f"after wall {med['after'][0]:.3f} s, CPU {med['after'][1]:.3f} s; "
            f"CPU ratio {med['before'][1] / med['after'][1]:.2f}"
        )


if __name__ == "__main__":
    main()
