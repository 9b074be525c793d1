#!/usr/bin/env python3
"""Benchmark of `sandslope plan` on a 4096 x 4096 DEM, against scikit-image's MCP_Geometric.

What it does (run from anywhere; takes a few minutes the first time):
1. pip-installs numpy, tifffile and scikit-image if missing;
2. builds the release binary (`cargo build --release -p sandslope-cli`);
3. writes a synthetic dune field as a float32 GeoTIFF (4096 x 4096 cells of 0.25 m, heights
   from a sum of sines with slopes up to about 30 degrees, deflate-compressed, tiled 256 x 256
   as GDAL writes large rasters);
4. times `sandslope plan --objective time` (the time route plus the distance route, run
   concurrently) from near the south-west corner to near the north-east corner, `--repeat`
   times (default 5), under /usr/bin/time -v for the CPU time (user + system) and the peak
   memory (maximum resident set size), and reports each run, the median and how many runs met
   the 10 s target;
5. times `skimage.graph.MCP_Geometric` on the same grid with an isotropic per-cell cost
   (1 / level speed * sec(slope) per metre: one cost per cell, no heading) between the same
   cells, once after each sandslope run (the two take turns, so each pair sees the same load
   from whatever else runs on the machine), with its wall and CPU time, and prints the ratios
   of the medians, wall and CPU, and of each pair. The load average (1 minute) is printed
   with every run. `--baseline EXE` times another sandslope binary in the same turns (for
   instance the main branch's, before and after a change) and says whether its `--json`
   output is byte for byte the same.

The binary is `target/release/sandslope`, or `$CARGO_TARGET_DIR/release/sandslope` when that
is set (the script builds it there). bench/plan/README.md has the last measurements.

Usage: python3 bench/plan/run.py [--size 4096] [--repeat 5] [--max-memory GIB] [--no-mcp] [--work DIR]
                                  [--search auto|full|corridor] [--coarse-factor N] [--corridor-width CELLS]
                                  [--gap] [--baseline EXE]

`--search`, `--coarse-factor` and `--corridor-width` are passed to `sandslope plan` (by default
none, so plan's `auto` decides: full resolution up to 4096 x 4096, corridor above). `--gap` times
the full-resolution search (`--search full`) and the corridor search (`--search corridor` with the
given factor and width) once each, interleaved, `--repeat` times, and prints the corridor
routes' excess cost over the full optimum (time for the time route, length for the distance
route): the corridor's optimality gap on this map.

`--size 16384` is issue 24's scale (2.7e8 cells): the DEM (about 1 GiB of float32 before
deflate) is written 256 rows at a time, so generating it holds a few tens of MiB, and
MCP_Geometric is skipped there (its float64 cost grid alone is 2 GiB). `--max-memory` is passed
to `sandslope plan` (for instance 4, the issue's limit: plan then says what it would need and
refuses, exit code 2, which the script reports instead of timing).
"""
import argparse
import os
import re
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def ensure(packages):
    missing = []
    for mod, pkg in packages:
        try:
            __import__(mod)
        except ImportError:
            missing.append(pkg)
    if missing:
        subprocess.check_call([sys.executable, "-m", "pip", "install", "--quiet", *missing])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=4096)
    ap.add_argument("--cell", type=float, default=0.25)
    ap.add_argument("--repeat", type=int, default=5, help="runs of sandslope plan (the median is compared)")
    ap.add_argument("--max-memory", type=float, help="GiB, passed to sandslope plan --max-memory")
    ap.add_argument("--no-mcp", action="store_true", help="skip MCP_Geometric (always skipped above 8192 x 8192)")
    ap.add_argument("--search", choices=["auto", "full", "corridor"], help="passed to sandslope plan")
    ap.add_argument("--coarse-factor", type=int, help="passed to sandslope plan")
    ap.add_argument("--corridor-width", type=int, help="passed to sandslope plan")
    ap.add_argument("--risk-map", action="store_true",
                    help="also write the --risk-map GeoTIFF (streamed band by band with the corridor search)")
    ap.add_argument("--gap", action="store_true", help="compare --search full and --search corridor")
    ap.add_argument("--baseline", help="another sandslope binary, timed in turn with this one (and its --json compared)")
    ap.add_argument("--work", default=os.path.join(ROOT, "target", "bench-plan"),
                    help="where the DEM is written (default target/bench-plan)")
    args = ap.parse_args()
    ensure([("numpy", "numpy"), ("tifffile", "tifffile"), ("skimage", "scikit-image")])
    import numpy as np
    import tifffile

    subprocess.check_call(["cargo", "build", "--release", "-q", "-p", "sandslope-cli"], cwd=ROOT)
    exe = os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "sandslope")

    n, cell = args.size, args.cell
    work = args.work
    os.makedirs(work, exist_ok=True)
    dem_path = os.path.join(work, f"dunes-v2-{n}.tif")
    def heights(r0, r1):
        """Rows r0..r1 of the dune field (float32)."""
        x = (np.arange(n) + 0.5) * cell
        y = (n - np.arange(r0, r1) - 0.5) * cell
        if n > 16384:
            # The same field by the angle-sum identities (sines of columns and of rows only,
            # not one per cell: minutes instead of over an hour at 32768 x 32768).
            y = y[:, None]
            a, b = 2 * np.pi * x / 40.0, 0.8 * np.sin(2 * np.pi * y / 90.0)
            m = 3.0 * (0.6 + 0.4 * np.cos(2 * np.pi * y / 130.0))
            p, q = 2 * np.pi * x / 11.0, 2 * np.pi * y / 11.0
            return (m * (np.sin(a) * np.cos(b) + np.cos(a) * np.sin(b))
                    + 0.25 * (np.sin(p) * np.cos(q) + np.cos(p) * np.sin(q))).astype(np.float32)
        X, Y = np.meshgrid(x, y)
        # Dune crests every ~40 m with amplitude up to 3 m (steepest ~ 3 * 2 pi / 40 = 0.47,
        # 25 deg), modulated along the crests, plus smaller superimposed dunes (0.25 m, 11 m):
        # slopes up to ~30 deg, so direct climbs often fail and routes must switch back.
        return (3.0 * np.sin(2 * np.pi * X / 40.0 + 0.8 * np.sin(2 * np.pi * Y / 90.0))
                * (0.6 + 0.4 * np.cos(2 * np.pi * Y / 130.0))
                + 0.25 * np.sin(2 * np.pi * (X + Y) / 11.0)).astype(np.float32)

    def tiles():
        for r0 in range(0, n, 256):
            band = heights(r0, min(n, r0 + 256))
            if band.shape[0] < 256:
                band = np.pad(band, ((0, 256 - band.shape[0]), (0, 0)))
            for c0 in range(0, n, 256):
                yield np.ascontiguousarray(band[:, c0:c0 + 256])

    if not os.path.exists(dem_path):
        assert n % 256 == 0, "--size must be a multiple of 256"
        t0 = time.perf_counter()
        # Above 16384 x 16384 uncompressed BigTIFF (4 GiB at 32768: Deflate would take longer
        # than the plan).
        big = n > 16384
        tifffile.imwrite(
            dem_path + ".part", tiles(), shape=(n, n), dtype=np.float32, tile=(256, 256),
            compression=None if big else "zlib", bigtiff=big,
            extratags=[(33550, "d", 3, (cell, cell, 0.0)), (33922, "d", 6, (0, 0, 0, 0.0, n * cell, 0.0)),
                       (42113, "s", 0, "-9999", False)])
        os.replace(dem_path + ".part", dem_path)
        print(f"wrote {dem_path} ({os.path.getsize(dem_path) / 2**20:.0f} MiB) in {time.perf_counter() - t0:.0f} s")
    start = (int(0.03 * n), int(0.97 * n))  # col, row: near the south-west corner
    goal = (int(0.97 * n), int(0.03 * n))  # near the north-east corner
    cmd = ["/usr/bin/time", "-v", exe, "plan", "--dem", dem_path, "--start-px", f"{start[0]},{start[1]}",
           "--goal-px", f"{goal[0]},{goal[1]}", "--objective", "time", "--json"]
    if args.max_memory is not None:
        cmd += ["--max-memory", str(args.max_memory)]
    corridor = []
    if args.coarse_factor is not None:
        corridor += ["--coarse-factor", str(args.coarse_factor)]
    if args.corridor_width is not None:
        corridor += ["--corridor-width", str(args.corridor_width)]
    if args.gap:
        gap(cmd, corridor, args.repeat)
        return
    if args.search is not None:
        cmd += ["--search", args.search]
    cmd += corridor
    if args.risk_map:
        cmd += ["--risk-map", os.path.join(work, f"risk-{n}.tif")]
    mcp = None if args.no_mcp or n > 8192 else mcp_runner(heights(0, n), cell, start, goal)
    # sandslope, its baseline (--baseline) and MCP_Geometric take turns, so that each pair of
    # timings sees the same load from whatever else runs on the machine.
    exes = [("sandslope", exe)] + ([("baseline", args.baseline)] if args.baseline else [])
    runs = {name: [] for name, _ in exes}
    t_mcp, cpu_mcp = [], []
    outputs = {}
    for i in range(args.repeat):
        for name, path in exes:
            load = os.getloadavg()[0]
            t0 = time.perf_counter()
            p = subprocess.run([cmd[0], cmd[1], path] + cmd[3:], capture_output=True, text=True)
            wall = time.perf_counter() - t0
            rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr).group(1))
            cpu = sum(float(re.search(f"{f} time \\(seconds\\): ([\\d.]+)", p.stderr).group(1)) for f in ["User", "System"])
            if p.returncode == 2 and "--max-memory" in p.stderr:
                print("\n".join(l for l in p.stderr.split("\tCommand being timed")[0].splitlines()
                                if not l.startswith("Command exited")))
                print(f"refused after {wall:.2f} s wall, peak RSS {rss_kb / 1024:.0f} MiB")
                return
            if p.returncode != 0:
                print(p.stderr)
                sys.exit(1)
            runs[name].append((wall, rss_kb, load, cpu))
            outputs.setdefault(name, p.stdout)
            print(f"run {i + 1}: {name} {wall:.2f} s wall, {cpu:.2f} s CPU, peak RSS {rss_kb / 1024:.0f} MiB"
                  f" (load average {load:.2f})", flush=True)
        if mcp is not None:
            load = os.getloadavg()[0]
            wall, cpu = mcp()
            t_mcp.append(wall)
            cpu_mcp.append(cpu)
            print(f"run {i + 1}: MCP_Geometric {wall:.2f} s wall, {cpu:.2f} s CPU (load average {load:.2f})", flush=True)
    print(outputs["sandslope"])
    if args.baseline:
        print("--json identical to the baseline's:", outputs["sandslope"] == outputs["baseline"])
    median = lambda xs: sorted(xs)[len(xs) // 2]
    for name, rs in runs.items():
        walls = sorted(w for w, _, _, _ in rs)
        rss = max(r for _, r, _, _ in rs)
        print(f"{name} plan ({n} x {n}, time + distance routes), {args.repeat} runs: "
              + ", ".join(f"{w:.2f} s" for w, _, _, _ in rs)
              + f" wall (median {median(walls):.2f} s, max {walls[-1]:.2f} s); peak RSS {rss / 1024:.0f} MiB"
              + f" ({rss * 1024 / (n * n):.1f} bytes a cell); load average "
              + ", ".join(f"{l:.1f}" for _, _, l, _ in rs))
        print(f"target < 10 s: met in {sum(w < 10.0 for w in walls)} of {len(walls)} runs")
    if not t_mcp:
        return
    print("skimage MCP_Geometric (isotropic, 8-connected): " + ", ".join(f"{t:.2f} s" for t in t_mcp)
          + f" wall (median {median(t_mcp):.2f} s); CPU " + ", ".join(f"{c:.2f} s" for c in cpu_mcp)
          + f" (median {median(cpu_mcp):.2f} s)")
    for name, rs in runs.items():
        wall, cpu = median([w for w, _, _, _ in rs]), median([c for _, _, _, c in rs])
        print(f"time ratio {name} / MCP_Geometric: {wall / median(t_mcp):.3f} wall (medians; per run "
              + ", ".join(f"{w / t:.3f}" for (w, _, _, _), t in zip(rs, t_mcp))
              + f"), {cpu / median(cpu_mcp):.3f} CPU (medians); MCP_Geometric / {name} {median(t_mcp) / wall:.2f}x wall")


def mcp_runner(z, cell, start, goal):
    """A function timing one MCP_Geometric search on heights `z` between the same cells."""
    import numpy as np
    from skimage.graph import MCP_Geometric
    # Isotropic per-cell cost: seconds per metre at the cell's own slope, level-sand speed
    # 0.15 m/s (the model's level speed for the default robot and terrain), sec(slope)
    # for the surface length.
    gy, gx = np.gradient(z.astype(np.float64), cell)
    cost = np.sqrt(1.0 + gx * gx + gy * gy) / 0.15
    del gx, gy

    def run():
        t0, c0 = time.perf_counter(), time.process_time()
        m = MCP_Geometric(cost, fully_connected=True, sampling=(cell, cell))
        m.find_costs([(start[1], start[0])], [(goal[1], goal[0])], find_all_ends=True)
        m.traceback((goal[1], goal[0]))
        return time.perf_counter() - t0, time.process_time() - c0

    return run


def timed(cmd):
    """Runs cmd (under /usr/bin/time -v): wall s, user + sys s, peak RSS KiB and the JSON."""
    import json
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        print(p.stderr)
        sys.exit(1)
    field = lambda name: re.search(name + r": ([\d.:]+)", p.stderr).group(1)
    cpu = float(field("User time \\(seconds\\)")) + float(field("System time \\(seconds\\)"))
    rss = int(field("Maximum resident set size \\(kbytes\\)"))
    return wall, cpu, rss, json.loads(p.stdout)


def gap(cmd, corridor, repeat):
    """Times the full and the corridor search, interleaved, and prints the corridor's gap."""
    runs = {"full": [], "corridor": []}
    for _ in range(repeat):
        for mode in runs:
            extra = ["--search", mode] + (corridor if mode == "corridor" else [])
            runs[mode].append(timed(cmd + extra))
    for mode, rs in runs.items():
        print(f"--search {mode}: " + ", ".join(f"{w:.2f} s wall / {c:.2f} s CPU / {r / 1024:.0f} MiB" for w, c, r, _ in rs))
    full, corr = runs["full"][0][3], runs["corridor"][0][3]
    print("corridor:", corr.get("search"))
    for objective, key in [("time", "time_s"), ("distance", "length_m")]:
        a, b = full["routes"][objective], corr["routes"][objective]
        if a["found"] and b["found"] and a[key] and b[key]:
            print(f"{objective}: full {a[key]:.3f}, corridor {b[key]:.3f}, gap {100 * (b[key] / a[key] - 1):+.3f} %")
        else:
            print(f"{objective}: full found {a['found']}, corridor found {b['found']}")


if __name__ == "__main__":
    main()
