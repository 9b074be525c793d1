#!/usr/bin/env python3
"""The paper's phase 1 in simulated walks (issue 59, item 2; docs/simulate.md, "Phase 1").

Usage: python3 bench/simulate/phase1.py [--sandslope target/release/sandslope] [--only NAME]

[holds] What holds the body in phase 1 (touchdown t0 to anchoring t1): the sand's mean
        along-slope and normal force on the belly, the old tripod and the new tripod, against
        m g sin(theta) and m g cos(theta), with the belly as resistive force theory's two-faced
        plate (--two-faced-belly) and one-sided (the default since 2026-12-07), at the default step.
[phase1] Per slope: backward slip s1, the most negative speed in phase 1 and t1 (docs/model.md
        §11: dv/dt turning from negative to positive), each at the default step and at a
        quarter of it, beside the closed form's t1 and s1 = 1/2 g sin(theta) t1^2.
Every number comes from `sandslope simulate --json` (its `phase1`, `t1_s`, `slip_m`, `closed_form`).
"""

import argparse
import concurrent.futures
import json
import math
import subprocess

SLOPES = [0, 10, 15, 20, 24]
MASS_KG, G = 0.35, 9.81


def one(exe, args):
    out = subprocess.run([exe, "simulate", *args, "--json"], capture_output=True, text=True, check=True)
    d = json.loads(out.stdout)
    return d[0] if isinstance(d, list) else d


def f(v, k=2):
    return "-" if v is None else f"{v:.{k}f}"


def walks(exe, extra, quarter):
    jobs = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        for s in SLOPES:
            args = ["--slope", str(s), *extra]
            jobs[(s, False)] = pool.submit(one, exe, args)
            if quarter:
                jobs[(s, True)] = pool.submit(one, exe, [*args, "--dt", "0.000125"])
        return {k: v.result() for k, v in jobs.items()}


def holds(exe, pitch):
    print(f"pitch {pitch}: mean sand force over phase 1, N (along slope, normal to it)\n")
    print("| belly | slope deg | m g sin, m g cos | belly | old tripod | new tripod | s1 mm | lowest speed cm/s |")
    print("|---|---:|---|---|---|---|---:|---:|")
    for label, extra in [("two-faced", ["--two-faced-belly"]), ("one-sided (default)", [])]:
        w = walks(exe, ["--body-pitch", pitch, *extra], False)
        for s in SLOPES:
            d = w[(s, False)]
            p = d["phase1"] or {}
            r = math.radians(s)
            pair = lambda v: "-" if not v else f"{v[0]:+.2f}, {v[1]:+.2f}"
            print(
                f"| {label} | {s} | {MASS_KG * G * math.sin(r):.2f}, {MASS_KG * G * math.cos(r):.2f} | "
                f"{pair(p.get('belly_n'))} | {pair(p.get('old_tripod_n'))} | {pair(p.get('new_tripod_n'))} | "
                f"{f(d['slip_m'] and d['slip_m'] * 1e3, 3)} | {f(p.get('min_speed_m_s') and p['min_speed_m_s'] * 100, 2)} |"
            )
    print()


def phase1(exe, pitch):
    print(f"pitch {pitch}: dt 0.5 ms (dt/4 0.125 ms); closed form beside\n")
    print(
        "| belly | slope deg | speed cm/s | s1 mm | lowest speed in phase 1 cm/s | t1 ms | "
        "closed form t1 ms | closed form s1 mm | regime |"
    )
    print("|---|---:|---|---|---|---|---:|---:|---|")
    for label, extra in [("two-faced", ["--two-faced-belly"]), ("one-sided (default)", [])]:
        w = walks(exe, ["--body-pitch", pitch, *extra], True)
        for s in SLOPES:
            d, q = w[(s, False)], w[(s, True)]
            cf = d["closed_form"]

            def both(get, k):
                return f"{f(get(d), k)} ({f(get(q), k)})"

            slip = lambda x: None if x["slip_m"] is None else x["slip_m"] * 1e3
            vmin = lambda x: None if not x["phase1"] else x["phase1"]["min_speed_m_s"] * 100
            t1 = lambda x: None if x["t1_s"] is None else x["t1_s"] * 1e3
            print(
                f"| {label} | {s} | {both(lambda x: x['speed_m_s'] * 100, 2)} | {both(slip, 3)} | "
                f"{both(vmin, 2)} | {both(t1, 1)} | {f(cf['t1_s'] and cf['t1_s'] * 1e3, 1)} | "
                f"{f(cf['slip_m'] and cf['slip_m'] * 1e3, 2)} | {d['regime']} ({q['regime']}) |"
            )
    print()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sandslope", default="target/release/sandslope")
    ap.add_argument("--only", choices=["holds", "phase1"])
    ap.add_argument("--pitch", default="locked", choices=["locked", "free"])
    a = ap.parse_args()
    if a.only in (None, "holds"):
        holds(a.sandslope, a.pitch)
    if a.only in (None, "phase1"):
        phase1(a.sandslope, a.pitch)


if __name__ == "__main__":
    main()
