#!/usr/bin/env python3
"""Synthetic motion-capture recordings for the `sandslope track` example.

Writes, next to this script, recordings of a body that follows a known speed profile per
step (the same profile as `sandslope::gait::synthetic::StepProfile`, re-implemented here
independently), at 120 frames/s with touchdowns every T/2 = 0.5 s:

  touchdown at rest -> backward slip to -V_s at t1 (v = -V_s sin(pi tau / 2 t1))
  -> propulsion to V_p at lift-off t3 (raised cosine) -> back to 0 at the next touchdown.

Three slopes (0, 10, 20 deg), each in a different format, climbing along a tilted
direction with lateral sway, 0.3 mm Gaussian noise per axis, and a few occlusions:

  level-plain.csv            plain CSV, metres, 0 deg
  slope10-motive123.csv      OptiTrack Motive 1.23, metres, Y-up, two rigid bodies
  slope20-motive125.csv      OptiTrack Motive 1.25, millimetres, export rate 120 of 240
  slope20-vicon.csv          Vicon Nexus Trajectories, mm, Z-up
  slope20-touchdowns.txt     the true touchdown times of slope20-vicon.csv
  truth.csv                  the true t1, slip, step and speed of each slope

Deterministic (seeded). Run: python3 examples/tracking/generate.py
"""
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
FPS = 120.0
STEP = 0.5  # T/2, s


class Profile:
    """Speed profile of one step; V_p chosen so the step-averaged speed is `speed`."""

    def __init__(self, t1, t3, vs, speed):
        self.t1, self.t3, self.vs = t1, t3, vs
        # The step is linear in V_p: step = a V_p + b.
        a = (t3 - t1) / 2 + 2 * (STEP - t3) / math.pi
        b = -2 * vs * t1 / math.pi - vs * (t3 - t1) / 2
        self.vp = (speed * STEP - b) / a

    def within(self, tau):
        """Displacement from touchdown to tau in [0, STEP]."""
        t1, t3, vs, vp = self.t1, self.t3, self.vs, self.vp
        slip = lambda u: -vs * (2 * t1 / math.pi) * (1 - math.cos(math.pi * u / (2 * t1))) if t1 > 0 else 0.0
        d = t3 - t1
        push = lambda u: -vs * u + 0.5 * (vp + vs) * (u - d / math.pi * math.sin(math.pi * u / d))
        ll = STEP - t3
        lift = lambda w: vp * (2 * ll / math.pi) * math.sin(0.5 * math.pi * w / ll)
        if tau <= t1:
            return slip(tau)
        if tau <= t3:
            return slip(t1) + push(tau - t1)
        return slip(t1) + push(d) + lift(min(tau, STEP) - t3)

    def step(self):
        return self.within(STEP)

    def slip(self):
        return 2 * self.vs * self.t1 / math.pi

    def position(self, t):
        k = math.floor(t / STEP)
        return k * self.step() + self.within(t - k * STEP)


def trajectory(profile, seconds, offset, up, side, origin, noise, rng, gaps):
    """Rows of (time, [x, y, z] or None) in metres."""
    rows = []
    for i in range(int(seconds * FPS)):
        t = i / FPS
        s = profile.position(t - offset + 2 * STEP)
        sway = 0.01 * math.sin(2 * math.pi * t)
        p = [origin[k] + up[k] * s + side[k] * sway + rng.gauss(0, noise) for k in range(3)]
        hidden = any(a <= i < b for a, b in gaps)
        rows.append((t, None if hidden else p))
    return rows


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def fmt(x):
    return f"{x:.6f}"


def write_plain(path, rows):
    with open(path, "w") as f:
        f.write("time_s,x_m,y_m,z_m\n")
        for t, p in rows:
            cells = ["", "", ""] if p is None else [fmt(c) for c in p]
            f.write(f"{t:.6f},{','.join(cells)}\n")


def write_motive(path, rows, version, scale, units, capture_rate, bodies):
    """bodies: list of (name, rows); the first is the robot."""
    meta = [
        "Format Version", version, "Take Name", "example", "Take Notes", "",
        "Capture Frame Rate", f"{capture_rate:.6f}", "Export Frame Rate", f"{FPS:.6f}",
        "Capture Start Time", "2025-01-01 10.00.00.000 AM", "Capture Start Frame", "0",
        "Total Frames in Take", str(2 * len(rows)), "Total Exported Frames", str(len(rows)),
        "Rotation Type", "Quaternion", "Length Units", units, "Coordinate Space", "Global",
    ]
    n = len(bodies)
    lines = [",".join(meta), ""]
    lines.append(",Type," + ",".join(["Rigid Body"] * 8 * n))
    lines.append(",Name," + ",".join(name for name, _ in bodies for _ in range(8)))
    lines.append(",ID," + ",".join(str(i + 1) for i in range(n) for _ in range(8)))
    if version == "1.25":
        lines.append(",Parent," + ",".join([""] * 8 * n))
    kinds = ["Rotation"] * 4 + ["Position"] * 3 + ["Mean Marker Error"]
    lines.append(",," + ",".join(kinds * n))
    lines.append("Frame,Time (Seconds)," + ",".join(["X", "Y", "Z", "W", "X", "Y", "Z", ""] * n))
    for i, (t, _) in enumerate(rows):
        cells = [str(i), f"{t:.6f}"]
        for _, body_rows in bodies:
            p = body_rows[i][1]
            if p is None:
                cells += [""] * 8
            else:
                cells += ["0.000000", "0.000000", "0.000000", "1.000000"]
                cells += [fmt(c * scale) for c in p] + ["0.000210"]
        lines.append(",".join(cells))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def write_vicon(path, rows):
    lines = ["Trajectories", "120", ",,robot:CoM,,", "Frame,Sub Frame,X,Y,Z", ",,mm,mm,mm"]
    for i, (_, p) in enumerate(rows):
        cells = ["", "", ""] if p is None else [f"{c * 1000:.3f}" for c in p]
        lines.append(f"{i + 1},0,{','.join(cells)}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    rng = random.Random(2026)
    noise = 3e-4
    theta = math.radians(20)
    slopes = {
        # slope: profile (t1 s, t3 s, V_s m/s, target speed m/s, loosely the paper's)
        0: Profile(0.0, 0.35, 0.0, 0.157),
        10: Profile(0.06, 0.38, 0.08, 0.110),
        20: Profile(0.12, 0.40, 0.15, 0.0498),
    }
    with open(os.path.join(HERE, "truth.csv"), "w") as f:
        f.write("slope_deg,t1_s,slip_m,step_m,speed_m_s\n")
        for deg, p in slopes.items():
            f.write(f"{deg},{p.t1},{p.slip():.6f},{p.step():.6f},{p.step() / STEP:.6f}\n")

    # 0 deg: plain CSV, metres, travel along +x on level ground (z up).
    rows = trajectory(slopes[0], 12, 0.15, [1, 0, 0], [0, 1, 0], [0.1, 0.2, 0.05], noise, rng, [(300, 306)])
    write_plain(os.path.join(HERE, "level-plain.csv"), rows)

    # 10 deg: Motive 1.23, metres, Y-up frame, climbing along -z tilted up in y; a second
    # rigid body (a fixed reference) so --body is needed.
    up10 = unit([0, math.sin(math.radians(10)), -math.cos(math.radians(10))])
    rows = trajectory(slopes[10], 12, 0.3, up10, [1, 0, 0], [0, 0.1, 0.4], noise, rng, [(500, 508)])
    ref = [(t, [0.5, 0.0, 0.0]) for t, _ in rows]
    write_motive(os.path.join(HERE, "slope10-motive123.csv"), rows, "1.23", 1.0, "Meters", 120.0,
                 [("robot", rows), ("reference", ref)])

    # 20 deg: Motive 1.25 in millimetres exported at 120 of a 240 frames/s capture, with a
    # 40-frame occlusion (longer than --max-gap: splits the recording).
    up20 = unit([math.cos(theta), 0, math.sin(theta)])
    rows = trajectory(slopes[20], 12, 0.05, up20, [0, 1, 0], [-0.3, 0.0, 0.02], noise, rng,
                      [(200, 204), (700, 740)])
    write_motive(os.path.join(HERE, "slope20-motive125.csv"), rows, "1.25", 1000.0, "Millimeters", 240.0,
                 [("robot", rows)])

    # 20 deg again: Vicon Nexus, mm, frame 1 at t = 0, with the true touchdowns logged.
    offset = 0.2
    rows = trajectory(slopes[20], 12, offset, up20, [0, 1, 0], [0.0, 0.3, 0.0], noise, rng, [(900, 907)])
    write_vicon(os.path.join(HERE, "slope20-vicon.csv"), rows)
    with open(os.path.join(HERE, "slope20-touchdowns.txt"), "w") as f:
        f.write("# touchdown times, s, in the recording's clock (gait controller log)\n")
        k = 0
        while offset + k * STEP < 12:
            f.write(f"{offset + k * STEP:.4f}\n")
            k += 1


if __name__ == "__main__":
    main()
