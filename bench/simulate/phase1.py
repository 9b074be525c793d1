#!/usr/bin/env python3
"""The paper's phase 1 in simulated walks (docs/simulate.md, "Phase 1").

Usage: python3 bench/simulate/phase1.py [--sandslope target/release/sandslope] [--only NAME]
       [--pitch locked|free]

[holds]     What holds the body in phase 1 (touchdown t0 to anchoring t1): the sand's mean
            along-slope and normal force on the belly, the old tripod and the new tripod,
            against m g sin(theta) and m g cos(theta), with the belly one-sided (the default)
            and two-faced (--two-faced-belly), at the default step.
[phase1]    Per slope: backward slip s1, the most negative speed in phase 1 and t1 (docs/model.md
            §11: dv/dt turning from negative to positive), each at the walk's default step and at
            a quarter of it, beside the closed form's t1 and s1 = 1/2 g sin(theta) t1^2. With
            --pitch free each cell is an ensemble of 8 walks (the mass perturbed by 1e-9
            between walks): the mean over the walks.
[servo]     The same with the legs turned by the servo's motor (--actuator servo), with each
            belly, and each walk's largest servo torque and unconverged steps.
[t1scaling] t1, s1 and the lowest speed at 10 to 24 degrees under each contact scaling, pitch
            locked, at the default step and a quarter of it.
[weak]      The default law on legs as weak in shear as the force tests' plate
            (--terrain data/example-force-tests.toml), locked at dt and dt/4, and free ensembles.
[sweep]     The report's 14 slopes, pitch locked, at the default step and a quarter of it: speed,
            t1 and the lowest speed in phase 1.
Every number comes from `sandslope simulate --json` (its `phase1`, `t1_s`, `slip_m`, `closed_form`).
"""

import argparse
import concurrent.futures
import json
import math
import subprocess

SLOPES = [0, 10, 15, 20, 24]
MASS_KG, G = 0.35, 9.81
BELLIES = [("one-sided (default)", []), ("two-faced", ["--two-faced-belly"])]


def run(exe, args):
    extra = [] if ("--ensemble" in args or "--slopes" in args) else ["--scaling-spread", "off"]
    out = subprocess.run([exe, "simulate", *args, *extra, "--json"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def one(exe, args):
    d = run(exe, args)
    return d[0] if isinstance(d, list) else d


def f(v, k=2):
    return "-" if v is None else f"{v:.{k}f}"


def mean(xs):
    xs = [x for x in xs if x is not None]
    return sum(xs) / len(xs) if xs else None


def summary(d):
    """A walk's phase-1 numbers, or an ensemble's means over its walks."""
    walks = d.get("summaries") or [d]
    p1 = [w["phase1"] for w in walks]
    return {
        "speed": d["speed_m_s"] * 100,
        "sd": d.get("speed_sd_m_s"),
        "s1": mean([None if w["slip_m"] is None else w["slip_m"] * 1e3 for w in walks]),
        "vmin": mean([None if p is None else p["min_speed_m_s"] * 100 for p in p1]),
        "t1": None if d["t1_s"] is None else d["t1_s"] * 1e3,
        "regime": d["regime"],
        "over": d.get("pitched_over"),
        "torque": max((s["peak_servo_torque_n_m"] for w in walks for s in w["steps"] if not s["warmup"]), default=None),
        "dt": walks[0]["dt_s"],
        "unconverged": sum(w["unconverged_steps"] for w in walks),
        "cf": walks[0]["closed_form"],
        "p1": p1[0],
    }


def walks(exe, extra, pitch, quarter, slopes=SLOPES):
    """Each slope's walk at its default step and (with `quarter`) at a quarter of it; with the
    pitch free, ensembles of 8."""
    ens = ["--ensemble", "8"] if pitch == "free" else []
    base = {s: ["--slope", str(s), "--body-pitch", pitch, *ens, *extra] for s in slopes}
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        first = {s: pool.submit(one, exe, a) for s, a in base.items()}
        out = {(s, False): summary(j.result()) for s, j in first.items()}
        if quarter:
            jobs = {s: pool.submit(one, exe, [*a, "--dt", repr(out[(s, False)]["dt"] / 4)]) for s, a in base.items()}
            out.update({(s, True): summary(j.result()) for s, j in jobs.items()})
    return out


def holds(exe, pitch):
    print(f"pitch {pitch}: mean sand force over phase 1, N (along slope, normal to it)\n")
    print("| belly | slope deg | m g sin, m g cos | belly | old tripod | new tripod | s1 mm | lowest speed cm/s |")
    print("|---|---:|---|---|---|---|---:|---:|")
    for label, extra in BELLIES:
        w = walks(exe, extra, pitch, False)
        for s in SLOPES:
            d = w[(s, False)]
            p = d["p1"] or {}
            r = math.radians(s)

            def pair(v):
                return "-" if not v else f"{v[0]:+.2f}, {v[1]:+.2f}"

            print(
                f"| {label} | {s} | {MASS_KG * G * math.sin(r):.2f}, {MASS_KG * G * math.cos(r):.2f} | "
                f"{pair(p.get('belly_n'))} | {pair(p.get('old_tripod_n'))} | {pair(p.get('new_tripod_n'))} | "
                f"{f(d['s1'], 3)} | {f(d['vmin'], 2)} |"
            )
    print()


def phase1_table(exe, pitch, rows, torque=False):
    what = "ensembles of 8, means over the walks" if pitch == "free" else "single walks"
    print(f"pitch {pitch} ({what}); each number at the default step (dt/4 in brackets); closed form beside\n")
    print(
        "| variant | slope deg | dt ms | speed cm/s | s1 mm | lowest speed in phase 1 cm/s | t1 ms | "
        "closed form t1 ms | closed form s1 mm |" + (" peak torque N m | unconverged steps |" if torque else "") + " regime |"
        + (" pitched over |" if pitch == "free" else "")
    )
    print("|---|---:|---:|---|---|---|---|---:|---:|" + ("---:|---:|" if torque else "") + "---|" + ("---|" if pitch == "free" else ""))
    for label, extra in rows:
        w = walks(exe, extra, pitch, True)
        for s in SLOPES:
            d, q = w[(s, False)], w[(s, True)]
            cf = d["cf"]

            def both(key, k):
                return f"{f(d[key], k)} ({f(q[key], k)})"

            speed = both("speed", 2)
            if pitch == "free":
                speed += f" +/- {f(d['sd'] * 100, 2)}"
            cf_s1 = None if cf["t1_s"] is None else 0.5 * G * math.sin(math.radians(s)) * cf["t1_s"] ** 2 * 1e3
            print(
                f"| {label} | {s} | {d['dt'] * 1e3:g} | {speed} | {both('s1', 3)} | {both('vmin', 2)} | {both('t1', 1)} | "
                f"{f(cf['t1_s'] and cf['t1_s'] * 1e3, 1)} | {f(cf_s1, 2)} |"
                + (f" {f(d['torque'], 3)} | {d['unconverged']} ({q['unconverged']}) |" if torque else "")
                + f" {d['regime']} ({q['regime']}) |"
                + (f" {d['over']}/8 ({q['over']}/8) |" if pitch == "free" else "")
            )
    print()


def t1_scaling(exe):
    slopes = [10, 15, 20, 24]
    print("pitch locked; t1 ms at the default step (dt/4 in brackets); s1 mm and lowest speed cm/s at the default step\n")
    print("| scaling | " + " | ".join(f"{s} deg t1 ms" for s in slopes) + " | s1 mm at 10, 15, 20, 24 | lowest speed cm/s at 10, 15, 20, 24 |")
    print("|---|" + "---|" * len(slopes) + "---|---|")
    cf = None
    for scaling in ["motion", "li2013", "components"]:
        w = walks(exe, ["--rft-scaling", scaling], "locked", True, slopes)
        cf = [w[(s, False)]["cf"] for s in slopes]
        cells = [f"{f(w[(s, False)]['t1'], 1)} ({f(w[(s, True)]['t1'], 1)})" for s in slopes]
        s1 = ", ".join(f(w[(s, False)]["s1"], 3) for s in slopes)
        vmin = ", ".join(f(w[(s, False)]["vmin"], 2) for s in slopes)
        print(f"| `{scaling}` | " + " | ".join(cells) + f" | {s1} | {vmin} |")
    t1 = [c["t1_s"] for c in cf]
    s1 = ", ".join(f"{0.5 * G * math.sin(math.radians(s)) * t ** 2 * 1e3:.2f}" for s, t in zip(slopes, t1))
    vmin = ", ".join(f"{-G * math.sin(math.radians(s)) * t * 100:.1f}" for s, t in zip(slopes, t1))
    print("| closed form | " + " | ".join(f"{t * 1e3:.1f}" for t in t1) + f" | {s1} | {vmin} |")
    print()


def weak(exe):
    terrain = ["--terrain", "data/example-force-tests.toml"]
    phase1_table(exe, "locked", [("plate-strength legs", terrain)])
    phase1_table(exe, "free", [("plate-strength legs", terrain)])


def sweep(exe):
    slopes = "0,2,4,6,8,10,12,14,15,16,18,20,22,24"
    a = run(exe, ["--slopes", slopes, "--body-pitch", "locked"])
    q = run(exe, ["--slopes", slopes, "--body-pitch", "locked", "--dt", repr(a[0]["dt_s"] / 4)])
    print("| slope deg | speed cm/s at dt | at dt/4 | t1 ms at dt | at dt/4 | t1 change ms | lowest speed in phase 1 mm/s | regime (dt/4) |")
    print("|---:|---:|---:|---:|---:|---:|---:|---|")
    for x, y in zip(a, q):
        t0 = None if x["t1_s"] is None else x["t1_s"] * 1e3
        t4 = None if y["t1_s"] is None else y["t1_s"] * 1e3
        ch = None if t0 is None or t4 is None else t4 - t0
        vmin = "(none)" if not x["phase1"] else f"{x['phase1']['min_speed_m_s'] * 1e3:.2f}"
        print(
            f"| {x['slope_deg']:g} | {x['speed_m_s'] * 100:.2f} | {y['speed_m_s'] * 100:.2f} | {f(t0, 2)} | {f(t4, 2)} | "
            f"{'-' if ch is None else f'{ch:+.2f}'} | {vmin} | {x['regime']} ({y['regime']}) |"
        )
    print()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sandslope", default="target/release/sandslope")
    ap.add_argument("--only", choices=["holds", "phase1", "servo", "t1scaling", "weak", "sweep"])
    ap.add_argument("--pitch", default="locked", choices=["locked", "free"])
    a = ap.parse_args()
    exe = a.sandslope
    tables = {
        "holds": lambda: holds(exe, a.pitch),
        "phase1": lambda: phase1_table(exe, a.pitch, BELLIES),
        "servo": lambda: phase1_table(
            exe, a.pitch, [(f"servo, {b}", ["--actuator", "servo", *x]) for b, x in BELLIES], torque=True
        ),
        "t1scaling": lambda: t1_scaling(exe),
        "weak": lambda: weak(exe),
        "sweep": lambda: sweep(exe),
    }
    for name, table in tables.items():
        if a.only in (None, name):
            print(f"## {name}\n")
            table()


if __name__ == "__main__":
    main()
