#!/usr/bin/env python3
"""Times `sandslope risk --map` against a NumPy/SciPy peer that shares its integration nodes
across all cells, on an N x N grid of median (k_n, k_s), in one run, compares the two maps
cell by cell and prints the ratio (issue 26: at least 5x the peer, equal within 1e-5).

Usage: python3 bench/risk/bench_risk.py [--n 1024] [--repeat 7] [--slope 20] [--cv-n 0.1 --cv-s 0.2]
       (e.g. .venv/bin/python bench/risk/bench_risk.py --n 4096 --repeat 3 for the large map)
Needs numpy and scipy; builds the release binary first (not timed).

The peer is written from docs/model.md (§3-§6 for the step, §9 for the risk, §13 for the
critical shear strength), not from sandslope's code. With x = ln k_n, per cell

    p_fail = Phi((x* - mu_n)/sigma_n) + integral over x > x* of
             phi((x - mu_n)/sigma_n)/sigma_n * Phi((g(x) - mu_s)/sigma_s) dx

where x* = ln k_n* (sinkage, §3) and g(x) = ln of the smallest k_s giving s > 0 (for
p_not_success: s >= s_min), solved in closed form from §4-§5: the step is a quadratic in the
anchoring time t1, so t1 is its smaller root, d_s = R (sin(omega t1 + phi0) + 1) - h, capped at
the deepest the leg reaches, and k_s = F_a / (W d_s^2). The integral is one quadrature shared by
every cell: graded Gauss-Legendre panels over ln k_n (width at most sigma_n, split at the kinks
of g found by bisection, geometrically refined towards x*, halved wherever g moves by more than
sigma_s within reach of the rows' medians; 5 nodes each). Then the normal-density weights form
one matrix W_n (columns x nodes), Phi((g - mu_s)/sigma_s) another, C_s (rows x nodes), per
curve, and the map is C_s @ W_n.T (BLAS), plus the sinkage term.

Timing, as in bench/phase: sandslope is timed as a whole process (`risk --map --json`:
start-up, the map, the JSON summary), the peer in-process for its computation only (nodes,
both matrices, both products, the sinkage term), which favours the peer. The two are run
interleaved, --repeat times each, and the medians compared (the machine is shared, so one
run is noisy); CPU times are printed too. One more sandslope run with --npy gives the arrays
that are compared cell by cell (not timed).
"""
import argparse
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "phase"))
from bench_phase import ROOT, load_toml  # noqa: E402

import numpy as np  # noqa: E402
from scipy.special import ndtr  # noqa: E402

G = 9.81
Z_MAX = 8.5  # window half-width, in sigma_n (the tails beyond are below 1e-16)
GL_X, GL_W = np.polynomial.legendre.leggauss(5)


class Model:
    """The closed-form model of docs/model.md for one robot at one slope."""

    def __init__(self, robot, slope_deg):
        th = math.radians(slope_deg)
        self.m, self.R, self.W, self.h = robot["mass_kg"], robot["leg_radius_m"], robot["leg_width_m"], robot["hip_height_m"]
        self.omega, self.n, self.dt = robot["leg_speed_rad_s"], robot["stance_legs"], robot["response_time_s"]
        self.A = robot.get("leg_contact_area_m2", self.W * self.R)
        self.s_min = robot.get("min_step_m", self.R)
        self.level = robot.get("level_step_m")
        self.d_max = 2 * self.R - self.h
        self.half = math.pi / self.omega  # T/2
        self.phi0 = math.asin((self.h - self.R) / self.R)
        self.load_n = self.m * G * math.cos(th) / self.n  # F_N per leg (§3)
        self.f_a = self.m * (G * math.sin(th) + self.R * self.omega / self.dt) / self.n  # F_a (§4)
        self.gs = G * math.sin(th)
        self.t_peak = (math.pi / 2 - self.phi0) / self.omega  # deepest point of the stance
        self.x_star = math.log(self.load_n / (self.A * self.d_max))  # ln k_n* (§3)

    def level_step(self, x):
        d_n = self.load_n / (np.exp(x) * self.A)
        if self.level is not None:
            return np.where(d_n >= self.d_max, 0.0, self.level)
        u = d_n + self.h - self.R
        return np.where(d_n >= self.d_max, 0.0, 2.0 * np.sqrt(np.maximum(self.R**2 - u * u, 0.0)))

    def critical(self, x, target):
        """(ln k_s giving s = target, inf where none does; capped flag) at x = ln k_n (§13)."""
        s_star = self.level_step(x)
        H, a = self.half, self.gs
        # s(t1) = s* (H - t1)^2 / H^2 - a t1 (2H - t1) / 2 = target, the smaller root (stable form).
        qa = s_star / H**2 + 0.5 * a
        qb = 2 * s_star / H + a * H
        qc = s_star - target
        ok = qc > 0
        with np.errstate(invalid="ignore", divide="ignore"):
            t1 = np.where(ok, 2 * qc / (qb + np.sqrt(np.maximum(qb * qb - 4 * qa * qc, 0.0))), np.nan)
            capped = ok & (t1 >= self.t_peak)
            d_s = np.where(capped, self.d_max, self.R * (np.sin(self.omega * t1 + self.phi0) + 1) - self.h)
            g = np.where(ok, np.log(self.f_a / (self.W * d_s * d_s)), np.inf)
        return g, capped

    def curves(self, x):
        g0, c0 = self.critical(x, 0.0)
        g1, c1 = self.critical(x, self.s_min)
        return (g0, g1), (np.isfinite(g0), c0, np.isfinite(g1), c1)


def nodes(model, mu_n, mu_s, sigma_n, sigma_s):
    """Graded Gauss-Legendre nodes over ln k_n shared by every cell: positions, weights, g0, g1."""
    lo = max(model.x_star, mu_n.min() - Z_MAX * sigma_n)
    hi = mu_n.max() + Z_MAX * sigma_n
    if lo >= hi:
        return np.empty(0), np.empty(0), np.empty(0), np.empty(0)
    edges = [np.linspace(lo, hi, int(math.ceil((hi - lo) / sigma_n)) + 1)]
    # Kinks of g (where it becomes finite, where the anchoring cap starts to bind): bisect the
    # switches of the flags seen on a fine grid.
    fine = np.linspace(lo, hi, 8 * len(edges[0]))
    _, flags = model.curves(fine)
    for i, f in enumerate(flags):
        k = np.nonzero(f[1:] != f[:-1])[0]
        a, b, fa = fine[k], fine[k + 1], f[k]
        for _ in range(60):
            mid = 0.5 * (a + b)
            left = model.curves(mid)[1][i] == fa
            a, b = np.where(left, mid, a), np.where(left, b, mid)
        edges.append(0.5 * (a + b))
    # Geometric refinement towards the sinkage threshold, where s* rises like a square root.
    if model.x_star > lo - 1e-12:
        edges.append(model.x_star + sigma_n * 0.5 ** np.arange(1, 40))
    e = np.unique(np.clip(np.concatenate(edges), lo, hi))
    band = (mu_s.min() - 9 * sigma_s, mu_s.max() + 9 * sigma_s)
    for _ in range(60):
        (g0, g1), _ = model.curves(e)
        split = np.zeros(len(e) - 1, dtype=bool)
        for g in (g0, g1):
            ga, gb = g[:-1], g[1:]
            both = np.isfinite(ga) & np.isfinite(gb)
            with np.errstate(invalid="ignore"):
                inside = (np.maximum(ga, gb) >= band[0]) & (np.minimum(ga, gb) <= band[1])
                split |= both & inside & (np.abs(gb - ga) > sigma_s)
        split &= np.diff(e) > 1e-10
        if not split.any():
            break
        e = np.sort(np.concatenate([e, 0.5 * (e[:-1] + e[1:])[split]]))
    mid, half = 0.5 * (e[:-1] + e[1:]), 0.5 * np.diff(e)
    x = (mid[:, None] + half[:, None] * GL_X[None, :]).ravel()
    w = (half[:, None] * GL_W[None, :]).ravel()
    (g0, g1), _ = model.curves(x)
    return x, w, g0, g1


def risk_map_peer(model, beyond_repose, k_n, k_s, cv_n, cv_s):
    """p_fail and p_not_success, shape (k_s, k_n), as sandslope stores them."""
    sigma_n, sigma_s = math.sqrt(math.log1p(cv_n**2)), math.sqrt(math.log1p(cv_s**2))
    mu_n, mu_s = np.log(k_n), np.log(k_s)
    p_sink = ndtr((model.x_star - mu_n) / sigma_n)
    if beyond_repose:
        p = np.broadcast_to(np.ones_like(p_sink), (len(k_s), len(k_n)))
        return p.copy(), p.copy()
    x, w, g0, g1 = nodes(model, mu_n, mu_s, sigma_n, sigma_s)
    z = (x[None, :] - mu_n[:, None]) / sigma_n
    W_n = np.where(np.abs(z) <= Z_MAX, w * np.exp(-0.5 * z * z) / (sigma_n * math.sqrt(2 * math.pi)), 0.0)
    slip = ndtr((g0[None, :] - mu_s[:, None]) / sigma_s) @ W_n.T
    not_success = ndtr((g1[None, :] - mu_s[:, None]) / sigma_s) @ W_n.T
    not_sunk = 1.0 - p_sink
    slip = np.clip(slip, 0.0, not_sunk)
    not_success = np.clip(not_success, slip, not_sunk)
    return p_sink + slip, p_sink + not_success


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=1024)
    ap.add_argument("--slope", type=float, default=20.0)
    ap.add_argument("--cv-n", type=float, default=0.1)
    ap.add_argument("--cv-s", type=float, default=0.2)
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()

    subprocess.check_call(["cargo", "build", "--release", "--quiet", "-p", "sandslope-cli"], cwd=ROOT)
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    exe = os.path.join(target, "release", "sandslope")
    robot = load_toml(subprocess.check_output([exe, "presets", "show", "paper-hexapod"], text=True))
    terrain = load_toml(subprocess.check_output([exe, "presets", "show", "glass-beads-300um"], text=True))
    n = args.n
    kn_axis, ks_axis = (7e3, 7e7), (1.4e3, 1.4e8)  # the built-in terrain's medians at 20 deg / 100 to x 100 and / 1000 to x 100
    cmd = [
        exe, "risk", "--map", "--slope", str(args.slope), "--cv-n", str(args.cv_n), "--cv-s", str(args.cv_s),
        "--k-n", f"{kn_axis[0]}:{kn_axis[1]}:{n}:log", "--k-s", f"{ks_axis[0]}:{ks_axis[1]}:{n}:log", "--json",
    ]
    model = Model(robot, args.slope)
    repose = terrain.get("repose_deg")
    beyond = repose is not None and args.slope >= repose

    def child_cpu():
        r = resource.getrusage(resource.RUSAGE_CHILDREN)
        return r.ru_utime + r.ru_stime

    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run(cmd + ["--npy", tmp], check=True, capture_output=True)
        ours = np.load(os.path.join(tmp, "p_fail.npy")), np.load(os.path.join(tmp, "p_not_success.npy"))
        k_n, k_s = np.load(os.path.join(tmp, "k_n.npy")), np.load(os.path.join(tmp, "k_s.npy"))
    risk_map_peer(model, beyond, k_n, k_s, args.cv_n, args.cv_s)  # warm-up (BLAS threads, pages)
    # The same kernel in process through the Python package, when it is installed: computation
    # against computation, the comparison the issue asks for (the process timing above adds
    # start-up, parsing and the JSON summary to sandslope's side only).
    try:
        import sandslope as ss

        py_robot, py_terrain = ss.Robot.preset("paper-hexapod"), ss.Terrain.preset("glass-beads-300um")

        def in_process():
            out = ss.risk_map(py_robot, args.slope, k_n, k_s, terrain=py_terrain, cv_n=args.cv_n, cv_s=args.cv_s)
            return out["p_fail"], out["p_not_success"]

        in_process()  # warm-up (thread pool, pages)
    except ImportError:
        in_process = None
    wall = {"sandslope": [], "peer": [], "in_process": []}
    cpu = {"sandslope": [], "peer": [], "in_process": []}
    for _ in range(args.repeat):  # interleaved
        if in_process is not None:
            c0, t0 = time.process_time(), time.perf_counter()
            ours_in = in_process()
            wall["in_process"].append(time.perf_counter() - t0)
            cpu["in_process"].append(time.process_time() - c0)
        c0, t0 = child_cpu(), time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        wall["sandslope"].append(time.perf_counter() - t0)
        cpu["sandslope"].append(child_cpu() - c0)
        c0, t0 = time.process_time(), time.perf_counter()
        peer = risk_map_peer(model, beyond, k_n, k_s, args.cv_n, args.cv_s)
        wall["peer"].append(time.perf_counter() - t0)
        cpu["peer"].append(time.process_time() - c0)

    # Peak resident memory of one more sandslope run, as /usr/bin/time -v reports it.
    peak_kib = None
    if os.path.exists("/usr/bin/time"):
        err = subprocess.run(["/usr/bin/time", "-v", *cmd], check=True, capture_output=True, text=True).stderr
        peak_kib = next((int(l.split(":")[1]) for l in err.splitlines() if "Maximum resident set size" in l), None)

    diff = max(float(np.max(np.abs(a - b))) for a, b in zip(ours, peer))
    if in_process is not None:
        # Python's arrays are (k_n, k_s); the CLI's .npy and the peer's, one row per k_s.
        diff_in = max(float(np.max(np.abs(a.T - b))) for a, b in zip(ours_in, peer))
    x, *_ = nodes(model, np.log(k_n), np.log(k_s), math.sqrt(math.log1p(args.cv_n**2)), math.sqrt(math.log1p(args.cv_s**2)))
    med = {k: statistics.median(v) for k, v in wall.items() if v}
    medc = {k: statistics.median(v) for k, v in cpu.items() if v}
    import scipy

    print(f"risk map {n} x {n} = {n * n:,} cells at {args.slope} deg, cv {args.cv_n}/{args.cv_s}, paper-hexapod, "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    print(f"medians of {args.repeat} interleaved runs each:")
    print(f"  sandslope risk --map (whole process)      {med['sandslope'] * 1e3:8.1f} ms wall {medc['sandslope'] * 1e3:8.1f} ms CPU"
          f"   (range {min(wall['sandslope']) * 1e3:.1f}-{max(wall['sandslope']) * 1e3:.1f} ms)")
    print(f"  NumPy {np.__version__}/SciPy {scipy.__version__} peer ({len(x)} nodes, in-process) "
          f"{med['peer'] * 1e3:8.1f} ms wall {medc['peer'] * 1e3:8.1f} ms CPU"
          f"   (range {min(wall['peer']) * 1e3:.1f}-{max(wall['peer']) * 1e3:.1f} ms)")
    if in_process is not None:
        print(f"  sandslope.risk_map (same kernel, in-process) {med['in_process'] * 1e3:8.1f} ms wall {medc['in_process'] * 1e3:8.1f} ms CPU"
              f"   (range {min(wall['in_process']) * 1e3:.1f}-{max(wall['in_process']) * 1e3:.1f} ms)")
    if peak_kib is not None:
        print(f"  sandslope peak resident memory (/usr/bin/time -v): {peak_kib / 1024:.0f} MiB")
    print(f"  largest |difference| over every cell of p_fail and p_not_success: {diff:.2e} (required <= 1e-5)")
    ratio = med["peer"] / med["sandslope"]
    print(f"  ratio peer / sandslope process: {ratio:.1f}x wall, {medc['peer'] / medc['sandslope']:.1f}x CPU")
    if in_process is not None:
        print(f"  largest |difference| in-process vs peer: {diff_in:.2e}")
        ratio = med["peer"] / med["in_process"]
        print(f"  ratio peer / sandslope in-process (computation against computation): {ratio:.1f}x wall, "
              f"{medc['peer'] / medc['in_process']:.1f}x CPU (target >= 5x: {'met' if ratio >= 5 else 'NOT met'})")


if __name__ == "__main__":
    main()
