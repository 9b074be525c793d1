#!/usr/bin/env python3
"""The tables of docs/simulate.md, regenerated from `sandslope simulate --json`.

Usage: python3 bench/simulate/tables.py [--sandslope target/release/sandslope]

Prints, in the order docs/simulate.md shows them:
1. simulator against closed form on the built-in robot and terrain at 0, 5, 10, 15, 20 and 24
   degrees (10 s walks, the defaults);
2. the simulated speed for five yield slips e_y (`--yield`), pitch-overs marked;
3. the regimes in (k_s, slope) against the closed form's (the phase diagram's) at k_n = 7e5.
Every number comes from the CLI's JSON; nothing here computes physics.
"""

import argparse
import json
import subprocess


def run(exe, args):
    out = subprocess.run([exe, "simulate", *args, "--json"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def f(v, k=1):
    return "-" if v is None else f"{v:.{k}f}"


def scaled(v, s):
    return None if v is None else v * s


def against_closed_form(exe):
    print(
        "| slope deg | speed cm/s sim | closed form | t1 ms sim | closed form | slip mm sim | closed form "
        "| step mm sim | closed form | largest pitch deg | regime (cause) sim | closed form |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|")
    for d in run(exe, ["--slopes", "0,5,10,15,20,24"]):
        c = d["closed_form"]
        print(
            f"| {d['slope_deg']:g} | {f(d['speed_m_s'] * 100)} | {f(scaled(c['speed_m_s'], 100))} "
            f"| {f(scaled(d['t1_s'], 1e3))} | {f(scaled(c['t1_s'], 1e3))} "
            f"| {f(scaled(d['slip_m'], 1e3))} | {f(scaled(c['slip_m'], 1e3))} "
            f"| {f(d['step_m'] * 1e3)} | {f(scaled(c['step_m'], 1e3))} | {f(d['max_pitch_deg'], 0)} "
            f"| {d['regime']} ({d['cause']}) | {c['regime']} |"
        )


def yield_sensitivity(exe):
    ys = ["1e-3", "3e-4", "1e-4", "3e-5", "1e-5"]
    slopes = [0, 10, 15, 20, 24]
    print("| slope deg | " + " | ".join(f"e_y = {y} m" for y in ys) + " |")
    print("|---:|" + "---|" * len(ys))
    res = {y: run(exe, ["--slopes", ",".join(map(str, slopes)), "--yield", y]) for y in ys}
    for i, s in enumerate(slopes):
        cells = []
        for y in ys:
            d = res[y][i]
            tumble = " (pitched over)" if d["pitch_over_s"] is not None else ""
            cells.append(f"{f(d['speed_m_s'] * 100)} cm/s{tumble}")
        print(f"| {s} | " + " | ".join(cells) + " |")


def regimes(exe):
    letter = {"sinkage": "K", "slippage": "S", "metastable": "M", "success": "+"}
    ks = ["1e4", "3e4", "1e5", "3e5", "1e6", "3e6", "1e7"]
    print("| k_s N/m^3 | " + " | ".join(f"{s} deg" for s in range(0, 25, 4)) + " |")
    print("|---:|" + "---|" * 7)
    agree = total = 0
    for k in ks:
        cells = []
        for d in run(exe, ["--slopes", "0:24:7", "--k-s", k, "--duration", "6"]):
            tumbled = d["pitch_over_s"] is not None
            cf = d["closed_form"]["regime"]
            total += 1
            agree += d["regime"] == cf and not tumbled
            cells.append(f"{letter[d['regime']]}{'^' if tumbled else ''} / {letter[cf]}")
        print(f"| {k} | " + " | ".join(cells) + " |")
    print(f"\n{agree} of {total} cells agree.")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sandslope", default="target/release/sandslope")
    exe = ap.parse_args().sandslope
    against_closed_form(exe)
    print()
    yield_sensitivity(exe)
    print()
    regimes(exe)


if __name__ == "__main__":
    main()
