#!/usr/bin/env python3
"""Benchmark of `sandslope plan` on a MOLA-shaped PDS3 DTM larger than memory (issue 56).

What it does (run from anywhere):
1. builds the release binary (`cargo build --release -p sandslope-cli`; `$CARGO_TARGET_DIR`
   honoured, as in run.py);
2. writes, under `--work` (default target/bench-plan), a global MOLA MEGDR-layout DTM: a
   detached label `MEGT90N000HB.LBL` over `MEGT90N000HB.IMG`, `--lines` x 2 `--lines` MSB 16-bit
   heights (default 23 040 x 46 080: 128 pixels a degree, 1.06e9 cells, 2.1 GB), labelled as
   the MEGDRs are (SIMPLE CYLINDRICAL on the 3396 km sphere, CENTER_LONGITUDE 180, the
   1-based projection offsets LINE 11 520.5 and SAMPLE 23 040.5). The heights are ridges of
   up to 1.1 km every 40 cells (18.5 km) with a 100 m ripple, slopes up to about 20 degrees
   at 463 m a cell, written 256 lines at a time (a few MiB held);
3. times `sandslope plan --objective time --json` (the time and distance routes) from 3% to
   97% of the map's columns and rows (south-west to north-east) under `/usr/bin/time -v`,
   and prints the wall time, CPU time (user + system), peak RSS and the routes.

Usage: python3 bench/plan/mola.py [--work DIR] [--lines N] [--max-memory GIB] [--keep]

The DTM is deleted afterwards unless `--keep`. Needs numpy. bench/plan/README.md has the
measurements.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def label(lines, samples, ppd):
    """The MEGDR label, its statements as the MEGDR labels write them."""
    s = [
        ("PDS_VERSION_ID", "PDS3"),
        ("RECORD_TYPE", "FIXED_LENGTH"),
        ("RECORD_BYTES", str(2 * samples)),
        ("FILE_RECORDS", str(lines)),
        ("^IMAGE", '"MEGT90N000HB.IMG"'),
        ("DATA_SET_ID", '"MGS-M-MOLA-5-MEGDR-L3-V1.0 (synthetic heights, sandslope bench)"'),
        ("TARGET_NAME", "MARS"),
        ("OBJECT", "IMAGE"),
        ("  LINES", str(lines)),
        ("  LINE_SAMPLES", str(samples)),
        ("  SAMPLE_TYPE", "MSB_INTEGER"),
        ("  SAMPLE_BITS", "16"),
        ("  UNIT", "METER"),
        ("  SCALING_FACTOR", "1"),
        ("  OFFSET", "0"),
        ("END_OBJECT", "IMAGE"),
        ("OBJECT", "IMAGE_MAP_PROJECTION"),
        ("  MAP_PROJECTION_TYPE", '"SIMPLE CYLINDRICAL"'),
        ("  A_AXIS_RADIUS", "3396.0 <KM>"),
        ("  B_AXIS_RADIUS", "3396.0 <KM>"),
        ("  C_AXIS_RADIUS", "3396.0 <KM>"),
        ("  FIRST_STANDARD_PARALLEL", '"N/A"'),
        ("  POSITIVE_LONGITUDE_DIRECTION", '"EAST"'),
        ("  CENTER_LATITUDE", "0.0 <DEGREE>"),
        ("  CENTER_LONGITUDE", "180.0 <DEGREE>"),
        ("  MAP_PROJECTION_ROTATION", "0.0"),
        ("  MAP_RESOLUTION", f"{ppd} <PIXEL/DEGREE>"),
        ("  MAP_SCALE", f"{3396.0 * 3.141592653589793 / 180 / ppd:.3f} <KM/PIXEL>"),
        ("  MAXIMUM_LATITUDE", f"{lines / ppd / 2:.1f} <DEGREE>"),
        ("  MINIMUM_LATITUDE", f"{-lines / ppd / 2:.1f} <DEGREE>"),
        ("  WESTERNMOST_LONGITUDE", f"{180 - samples / ppd / 2:.1f} <DEGREE>"),
        ("  EASTERNMOST_LONGITUDE", f"{180 + samples / ppd / 2:.1f} <DEGREE>"),
        ("  LINE_PROJECTION_OFFSET", f"{lines / 2 + 0.5} <PIXEL>"),
        ("  SAMPLE_PROJECTION_OFFSET", f"{samples / 2 + 0.5} <PIXEL>"),
        ("END_OBJECT", "IMAGE_MAP_PROJECTION"),
    ]
    return "".join(f"{k:<32}= {v}\r\n" for k, v in s) + "END\r\n"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--work", default=os.path.join(ROOT, "target", "bench-plan"))
    ap.add_argument("--lines", type=int, default=23040, help="lines (the map is twice as wide)")
    ap.add_argument("--max-memory", type=float, help="GiB, passed to sandslope plan --max-memory")
    ap.add_argument("--keep", action="store_true", help="keep the DTM")
    ap.add_argument("--extra", default="", help="more arguments for sandslope plan")
    args = ap.parse_args()
    import numpy as np

    subprocess.check_call(["cargo", "build", "--release", "-q", "-p", "sandslope-cli"], cwd=ROOT)
    exe = os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "sandslope")
    lines, samples = args.lines, 2 * args.lines
    ppd = lines // 180
    os.makedirs(args.work, exist_ok=True)
    lbl = os.path.join(args.work, "MEGT90N000HB.LBL")
    img = os.path.join(args.work, "MEGT90N000HB.IMG")
    if not (os.path.exists(img) and os.path.getsize(img) == 2 * lines * samples):
        t0 = time.perf_counter()
        x = np.arange(samples, dtype=np.float64)
        with open(img + ".part", "wb") as f:
            for r0 in range(0, lines, 256):
                y = np.arange(r0, min(lines, r0 + 256), dtype=np.float64)[:, None]
                z = (1000.0 * np.sin(2 * np.pi * x / 40.0 + 0.8 * np.sin(2 * np.pi * y / 90.0))
                     * (0.6 + 0.4 * np.cos(2 * np.pi * y / 130.0))
                     + 100.0 * np.sin(2 * np.pi * (x + y) / 11.0) - 2000.0)
                f.write(np.round(z).astype(">i2").tobytes())
        os.replace(img + ".part", img)
        print(f"wrote {img} ({os.path.getsize(img) / 2**30:.2f} GiB) in {time.perf_counter() - t0:.0f} s", flush=True)
    with open(lbl, "w") as f:
        f.write(label(lines, samples, ppd))
    start = (int(0.03 * samples), int(0.97 * lines))
    goal = (int(0.97 * samples), int(0.03 * lines))
    cmd = ["/usr/bin/time", "-v", exe, "plan", "--dem", lbl, "--start-px", f"{start[0]},{start[1]}",
           "--goal-px", f"{goal[0]},{goal[1]}", "--objective", "time", "--json"] + args.extra.split()
    if args.max_memory is not None:
        cmd += ["--max-memory", str(args.max_memory)]
    print(" ".join(cmd[2:]), flush=True)
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    field = lambda name: re.search(name + r": ([\d.:]+)", p.stderr).group(1)
    cpu = float(field("User time \\(seconds\\)")) + float(field("System time \\(seconds\\)"))
    rss = int(field("Maximum resident set size \\(kbytes\\)"))
    print("\n".join(l for l in p.stderr.split("\tCommand being timed")[0].splitlines()
                    if not l.startswith("Command exited")))
    print(f"exit {p.returncode}: {wall:.1f} s wall, {cpu:.1f} s CPU, peak RSS {rss} KiB "
          f"({rss / 2**20:.2f} GiB), load average {load:.1f} before")
    if p.returncode == 0:
        print(json.dumps(json.loads(p.stdout), indent=1))
    if not args.keep:
        os.remove(img)
        os.remove(lbl)
    sys.exit(p.returncode)


if __name__ == "__main__":
    main()
