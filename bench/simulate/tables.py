#!/usr/bin/env python3
"""The tables of docs/simulate.md, regenerated from `sandslope simulate --json`.

Usage: python3 bench/simulate/tables.py [--sandslope target/release/sandslope] [--only NAME]

Prints, in the order docs/simulate.md shows them (NAME in brackets):
1. [elements] the leg cut into 16, 32 (the default) and 64 elements, pitch locked, at the
   paper's slopes: speed and t1;
2. [closed] simulator (body pitch locked, the default) against the closed form on the
   built-in robot and terrain at 0, 5, 10, 15, 20 and 24 degrees, 10 s walks, with the speed
   and t1 again at a quarter of the default step (the convergence check beside every number);
3. [rolling] the level step on stiff sand (k_n = k_s = 1e8) against the rigid rolling step
   worked out by hand from the robot's geometry and the closed form's s*;
4. [free] the same walks as [closed] with the body pitch free, at its default step and a
   quarter of it;
5. [regimes] the regimes in (k_s, slope) against the closed form's at k_n = 7e5, pitch locked;
6. [level] the level stride against the paper's 15.7 cm/s: one switch at a time, each at the
   default step and a quarter of it;
7. [mechanisms] each switch of docs/model.md §20 across the paper's slopes, at the default
   step and a quarter of it;
8. [shape] the level walk's within-stride speed, from `simulate --out` sampled at 120 Hz as
   the paper's motion capture was;
9. [spread] the paper's slopes under each contact scaling, against the paper's speeds.
Every number comes from the CLI's JSON or CSV; nothing here computes physics beyond a finite
difference of the sampled positions and the rigid rolling step's geometry.
"""

import argparse
import csv
import json
import math
import os
import subprocess
import tempfile

PAPER_LEVEL_CM_S = (15.7, 0.97)
PAPER_CM_S = {0: 15.7, 10: 11.0, 15: 10.5, 20: 4.98, 24: 5.6}


def run(exe, args):
    """`simulate --json`, one walk a slope (the contact scalings' spread off)."""
    extra = [] if ("--ensemble" in args or "--check-convergence" in args) else ["--scaling-spread", "off"]
    out = subprocess.run([exe, "simulate", *args, *extra, "--json"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def one(exe, args):
    d = run(exe, args)
    return d[0] if isinstance(d, list) else d


def f(v, k=1):
    return "-" if v is None else f"{v:.{k}f}"


def scaled(v, s):
    return None if v is None else v * s


def quarter_dt(exe, args):
    """The walk's default step, and the same walk at a quarter of it."""
    d = one(exe, args)
    q = one(exe, [*args, "--dt", repr(d["dt_s"] / 4)])
    return d, q


def against_closed_form(exe, pitch):
    print(
        "| slope deg | speed cm/s sim | at dt/4 | closed form | t1 ms sim | at dt/4 | closed form "
        "| step mm sim | closed form | largest pitch deg | regime (cause) sim | at dt/4 | closed form |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---|")
    for s in [0, 5, 10, 15, 20, 24]:
        d, q = quarter_dt(exe, ["--slope", str(s), "--body-pitch", pitch])
        c = d["closed_form"]
        print(
            f"| {s} | {f(d['speed_m_s'] * 100)} | {f(q['speed_m_s'] * 100)} | {f(scaled(c['speed_m_s'], 100))} "
            f"| {f(scaled(d['t1_s'], 1e3))} | {f(scaled(q['t1_s'], 1e3))} | {f(scaled(c['t1_s'], 1e3))} "
            f"| {f(d['step_m'] * 1e3)} | {f(scaled(c['step_m'], 1e3))} | {f(d['max_pitch_deg'], 0)} "
            f"| {d['regime']} ({d['cause']}) | {q['regime']} | {c['regime']} |"
        )


def regimes(exe):
    letter = {"sinkage": "K", "slippage": "S", "metastable": "M", "success": "+"}
    ks = ["1e4", "3e4", "1e5", "3e5", "1e6", "3e6", "1e7"]
    print("| k_s N/m^3 | " + " | ".join(f"{s} deg" for s in range(0, 25, 4)) + " |")
    print("|---:|" + "---|" * 7)
    agree = total = 0
    for k in ks:
        cells = []
        for d in run(exe, ["--slopes", "0:24:7", "--k-s", k, "--duration", "6", "--body-pitch", "locked"]):
            cf = d["closed_form"]["regime"]
            total += 1
            agree += d["regime"] == cf
            cells.append(f"{letter[d['regime']]} / {letter[cf]}")
        print(f"| {k} | " + " | ".join(cells) + " |")
    print(f"\n{agree} of {total} cells agree.")


def robot_file(exe, directory, name, extra):
    """The built-in robot's file (`presets show paper-hexapod`) with `extra` lines appended."""
    text = subprocess.run([exe, "presets", "show", "paper-hexapod"], capture_output=True, text=True, check=True).stdout
    path = os.path.join(directory, f"{name}.toml")
    with open(path, "w") as fh:
        fh.write(text + extra)
    return path


def mechanism_rows(tmp):
    """The switches of docs/model.md §20, one at a time."""
    return [
        ("leg-sand friction mu = 0.3 (`--leg-friction 0.3`)", ["--leg-friction", "0.3"]),
        ("leg-sand friction mu = 0.1", ["--leg-friction", "0.1"]),
        ("duty cycle 0.7: stance half turn slower (`--duty-cycle 0.7`)", ["--duty-cycle", "0.7"]),
        ("duty cycle 0.3: stance half turn faster", ["--duty-cycle", "0.3"]),
        ("disturbed sand at half strength (`--disturbed-sand 0.5`)", ["--disturbed-sand", "0.5"]),
        ("disturbed sand at a tenth of its strength", ["--disturbed-sand", "0.1"]),
    ]


def mechanisms(exe):
    """Each switch of docs/model.md §20 across the paper's slopes: speed at the default step
    and at a quarter of it."""
    slopes = [0, 10, 15, 20, 24]
    print("| switch | " + " | ".join(f"{s} deg cm/s (dt/4)" for s in slopes) + " | regimes |")
    print("|---|" + "---:|" * len(slopes) + "---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, args in [("the defaults", []), *mechanism_rows(tmp)]:
            a = ["--slopes", ",".join(map(str, slopes)), "--body-pitch", "locked", *args]
            d = run(exe, a)
            q = run(exe, [*a, "--dt", repr(d[0]["dt_s"] / 4)])
            cells = [f"{f(x['speed_m_s'] * 100)} ({f(y['speed_m_s'] * 100)})" for x, y in zip(d, q)]
            regimes = "".join({"success": "+", "metastable": "M", "slippage": "S", "sinkage": "K"}[x["regime"]] for x in d)
            print(f"| {name} | " + " | ".join(cells) + f" | {regimes} |")


def level_stride(exe):
    lo, hi = PAPER_LEVEL_CM_S[0] - 2 * PAPER_LEVEL_CM_S[1], PAPER_LEVEL_CM_S[0] + 2 * PAPER_LEVEL_CM_S[1]
    with tempfile.TemporaryDirectory() as tmp:
        rows = [
            ("the defaults (pitch locked)", []),
            ("pitch free", ["--body-pitch", "free"]),
            ("`--rft-scaling components`", ["--rft-scaling", "components"]),
            ("`--rft-scaling li2013` (k_s not used)", ["--rft-scaling", "li2013"]),
            ("Li et al.'s ratio, k_s = 0.185 k_n", ["--k-s", repr(0.185 * 7e5)]),
            ("k_n halved (3.5e5)", ["--k-n", "3.5e5"]),
            ("k_n / 10 (7e4)", ["--k-n", "7e4"]),
            ("hip height h = 0.02 m", ["--hip-height", "0.02"]),
            ("hip height h = 0.05 m", ["--hip-height", "0.05"]),
            ("hip height h = 0.07 m (belly 1 cm above the leg tips)", ["--hip-height", "0.07"]),
            (
                "XL330-M288 torque limit, 0.52 N m",
                ["--robot", robot_file(exe, tmp, "m288", "servo_torque_limit_n_m = 0.52\n")],
            ),
            (
                "XL330-M077 torque limit, 0.215 N m",
                ["--robot", robot_file(exe, tmp, "m077", "servo_torque_limit_n_m = 0.215\n")],
            ),
            *mechanism_rows(tmp),
        ]
        print(
            "| switch (level sand, one at a time) | speed cm/s | at dt/4 | step mm | t1 ms | largest depth mm "
            "| peak servo torque N m | stalled s per step | regime |"
        )
        print("|---|---:|---:|---:|---:|---:|---:|---:|---|")
        for name, args in rows:
            a = ["--slope", "0", *args]
            if "--body-pitch" not in a:
                a += ["--body-pitch", "locked"]
            d, q = quarter_dt(exe, a)
            steps = [s for s in d["steps"] if not s["warmup"]]
            torque = max((s["peak_servo_torque_n_m"] for s in steps), default=None)
            stall = sum(s["stall_s"] for s in steps) / max(len(steps), 1)
            inside = " (within 2 SD)" if lo <= d["speed_m_s"] * 100 <= hi else ""
            print(
                f"| {name} | {f(d['speed_m_s'] * 100)}{inside} | {f(q['speed_m_s'] * 100)} | {f(d['step_m'] * 1e3)} "
                f"| {f(scaled(d['t1_s'], 1e3))} | {f(d['max_depth_m'] * 1e3)} | {f(torque, 3)} | {f(stall, 3)} "
                f"| {d['regime']} |"
            )
    print(f"\nThe paper: {PAPER_LEVEL_CM_S[0]} +/- {PAPER_LEVEL_CM_S[1]} cm/s (2 SD: {lo:.1f} to {hi:.1f}).")


def shape(exe):
    """Within-stride speed of the level walk at 120 Hz, the steps after the first stride
    averaged: its minimum, its peak and when it comes after touchdown, and the share of the
    step spent below 20% of the mean speed."""
    print(
        "| level walk | mean cm/s | min cm/s | peak cm/s | peak at ms after touchdown "
        "| share of the step below 20% of the mean |"
    )
    print("|---|---:|---:|---:|---:|---:|")
    for name, extra in [("the defaults (h = 0.03 m)", []), ("hip height h = 0.07 m", ["--hip-height", "0.07"])]:
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "walk.csv")
            subprocess.run(
                [exe, "simulate", "--slope", "0", "--body-pitch", "locked", "--scaling-spread", "off", "--out", out, *extra],
                capture_output=True,
                check=True,
            )
            with open(out) as fh:
                rows = [(float(r["time_s"]), float(r["x_m"])) for r in csv.DictReader(fh)]
        v = [
            (rows[i][0], (rows[i + 1][1] - rows[i - 1][1]) / (rows[i + 1][0] - rows[i - 1][0]))
            for i in range(1, len(rows) - 1)
        ]
        half, k, stats = 0.5, 2, []
        while (k + 1) * half <= v[-1][0]:
            seg = [(t - k * half, s) for t, s in v if k * half <= t < (k + 1) * half]
            mean = sum(s for _, s in seg) / len(seg)
            peak_t, peak = max(seg, key=lambda p: p[1])
            low = sum(1 for _, s in seg if s < 0.2 * mean) / len(seg)
            stats.append((mean, min(s for _, s in seg), peak, peak_t, low))
            k += 1
        m = [sum(x[i] for x in stats) / len(stats) for i in range(5)]
        print(
            f"| {name} | {m[0] * 100:.1f} | {m[1] * 100:.1f} | {m[2] * 100:.1f} | {m[3] * 1e3:.0f} "
            f"| {m[4] * 100:.0f}% |"
        )


def elements(exe):
    """The leg's elements (robot key `leg_elements`) halved and doubled from the default 32:
    speed cm/s and t1 ms at the paper's slopes, pitch locked, the default step."""
    slopes = [0, 10, 15, 20, 24]
    print("| elements a leg | " + " | ".join(f"{s} deg" for s in slopes) + " |")
    print("|---:|" + "---|" * len(slopes))
    with tempfile.TemporaryDirectory() as tmp:
        for n in [16, 32, 64]:
            args = ["--slopes", ",".join(map(str, slopes)), "--body-pitch", "locked"]
            if n != 32:
                args += ["--robot", robot_file(exe, tmp, f"e{n}", f"leg_elements = {n}\n")]
            cells = [
                f"{d['speed_m_s'] * 100:.2f}, {f(scaled(d['t1_s'], 1e3))}" + (f" ({d['regime']})" if d["regime"] != "success" else "")
                for d in run(exe, args)
            ]
            print(f"| {n}{' (default)' if n == 32 else ''} | " + " | ".join(cells) + " |")


def rolling(exe):
    """The level step on stiff sand against the rigid rolling step worked out by hand (a leg
    that rolls on its arc like a wheel's rim, then pivots on its tip until the belly lands) and
    the closed form's s* (the hip's chord with the leg's circle held fixed)."""
    text = subprocess.run([exe, "presets", "show", "paper-hexapod"], capture_output=True, text=True, check=True).stdout
    robot = {k.strip(): float(v) for k, v in (l.split("=") for l in text.splitlines() if "=" in l and not l.startswith("#"))}
    r, h = robot["leg_radius_m"], robot["hip_height_m"]
    phi0 = math.asin((h - r) / r)
    parts = [r * (math.pi / 2 - phi0), r * math.cos(phi0), 2 * r * math.sqrt(1 - (h / (2 * r)) ** 2)]
    print(f"rigid rolling step by hand (R = {r * 1e3:g} mm, h = {h * 1e3:g} mm, phi0 = {math.degrees(phi0):.1f} deg): "
          + " + ".join(f"{p * 1e3:.1f}" for p in parts) + f" = {sum(parts) * 1e3:.1f} mm\n")
    print("| sand | simulated step mm | steps measured | step / rolling step | closed form s* mm | speed cm/s |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, args in [("stiff, k_n = k_s = 1e8", ["--k-n", "1e8", "--k-s", "1e8"]), ("the built-in terrain", [])]:
        d = one(exe, ["--slope", "0", "--body-pitch", "locked", *args])
        print(
            f"| {name} | {d['step_m'] * 1e3:.1f} | {d['steps_measured']} | {d['step_m'] / sum(parts):.3f} "
            f"| {d['closed_form']['level_step_m'] * 1e3:.1f} | {d['speed_m_s'] * 100:.1f} |"
        )


def spread(exe):
    """The paper's slopes under each contact scaling, pitch locked, the default step."""
    slopes = list(PAPER_CM_S)
    walks = {
        x: run(exe, ["--slopes", ",".join(map(str, slopes)), "--body-pitch", "locked", "--rft-scaling", x])
        for x in ["motion", "li2013", "components"]
    }
    print("| slope deg | `motion` (default) | `li2013` | `components` | spread (largest - smallest) | paper |")
    print("|---:|---|---|---|---:|---:|")
    for i, s in enumerate(slopes):
        v = [walks[x][i]["speed_m_s"] * 100 for x in walks]
        cells = [f"{walks[x][i]['speed_m_s'] * 100:.1f} ({walks[x][i]['regime']})" for x in walks]
        print(f"| {s} | " + " | ".join(cells) + f" | {max(v) - min(v):.1f} | {PAPER_CM_S[s]} |")
    for x, w in walks.items():
        rms = math.sqrt(sum((d["speed_m_s"] * 100 - PAPER_CM_S[s]) ** 2 for d, s in zip(w, slopes)) / len(slopes))
        print(f"\nroot-mean-square distance from the paper's speeds under `{x}`: {rms:.1f} cm/s", end="")
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sandslope", default="target/release/sandslope")
    ap.add_argument(
        "--only", choices=["elements", "closed", "rolling", "free", "regimes", "level", "mechanisms", "shape", "spread"]
    )
    a = ap.parse_args()
    exe = a.sandslope
    tables = {
        "elements": lambda: elements(exe),
        "closed": lambda: against_closed_form(exe, "locked"),
        "rolling": lambda: rolling(exe),
        "free": lambda: against_closed_form(exe, "free"),
        "regimes": lambda: regimes(exe),
        "level": lambda: level_stride(exe),
        "mechanisms": lambda: mechanisms(exe),
        "shape": lambda: shape(exe),
        "spread": lambda: spread(exe),
    }
    for name, table in tables.items():
        if a.only in (None, name):
            print(f"## {name}\n")
            table()
            print()


if __name__ == "__main__":
    main()
