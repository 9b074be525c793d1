"""Reading a large ROS 2 bag: `sandslope track` against the Python `rosbags` reader on the same
bag (docs/bags.md).

The bag (MCAP storage, written by `rosbags`) holds a simulated walk's poses at 120 Hz on
`/mocap/robot/pose` and, to make it large, a camera-sized topic (`sensor_msgs/Image`, 640 x 480
mono, 30 Hz) as a lab's bag would. Timed, each from a warm page cache (the file read once
before): `cat` (the disk's speed, here the page cache's), `sandslope track --topic` (reads
every chunk, decodes the pose topic, analyses the walk) and `rosbags`' AnyReader deserialising
the pose topic. Peak memory is the child's maximum resident set (GNU time's %M).

    python bench/bags/run.py --size-mb 1024 --cli target/release/sandslope
"""

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

TS = get_typestore(Stores.ROS2_HUMBLE)
T = TS.types
T0 = 1_700_000_000_000_000_000


def header(ns, frame):
    return T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9),
                                    frame_id=frame)


def write_bag(path, walk_csv, size_mb):
    frame = pd.read_csv(walk_csv)
    period = frame["time_s"].iloc[-1] + frame["time_s"].iloc[1]
    image_bytes = 640 * 480
    images = int(size_mb * 2**20 / image_bytes)
    duration = images / 30.0
    q = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
    pixels = np.random.default_rng(1).integers(0, 255, image_bytes, dtype=np.uint8)
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        pose_c = w.add_connection("/mocap/robot/pose", "geometry_msgs/msg/PoseStamped", typestore=TS)
        cam_c = w.add_connection("/camera/image_raw", "sensor_msgs/msg/Image", typestore=TS)
        k, i = 0, 0
        n_poses = int(duration * 120)
        rows = frame[["x_m", "y_m", "z_m"]].to_numpy()
        step = rows[-1] - rows[0] + (rows[1] - rows[0])
        while k < n_poses or i < images:
            tp, ti = k / 120.0, i / 30.0
            if k < n_poses and (i >= images or tp <= ti):
                lap, j = divmod(k, len(rows))
                p = rows[j] + lap * step
                ns = T0 + round(tp * 1e9)
                msg = T["geometry_msgs/msg/PoseStamped"](header=header(ns, "world"), pose=T["geometry_msgs/msg/Pose"](
                    position=T["geometry_msgs/msg/Point"](x=float(p[0]), y=float(p[1]), z=float(p[2])), orientation=q))
                w.write(pose_c, ns, TS.serialize_cdr(msg, "geometry_msgs/msg/PoseStamped"))
                k += 1
            else:
                ns = T0 + round(ti * 1e9)
                msg = T["sensor_msgs/msg/Image"](header=header(ns, "camera"), height=480, width=640, encoding="mono8",
                                                 is_bigendian=0, step=640, data=pixels)
                w.write(cam_c, ns, TS.serialize_cdr(msg, "sensor_msgs/msg/Image"))
                i += 1
    return n_poses, images, period


def timed(cmd):
    """Wall seconds and peak resident MiB of a command."""
    t = time.perf_counter()
    p = subprocess.run(["/usr/bin/time", "-f", "%M", *map(str, cmd)], capture_output=True, text=True)
    wall = time.perf_counter() - t
    if p.returncode != 0:
        sys.exit(f"{cmd} failed: {p.stderr}")
    return wall, int(p.stderr.strip().splitlines()[-1]) / 1024


ROSBAGS_READ = """
import sys
from pathlib import Path
from rosbags.highlevel import AnyReader
n = 0
with AnyReader([Path(sys.argv[1])]) as r:
    conns = [c for c in r.connections if c.topic == '/mocap/robot/pose']
    for c, t, raw in r.messages(connections=conns):
        m = r.deserialize(raw, c.msgtype)
        n += 1
print(n)
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size-mb", type=float, default=1024)
    ap.add_argument("--cli", default="target/release/sandslope")
    ap.add_argument("--keep", help="folder to keep the bag in")
    a = ap.parse_args()
    work = Path(a.keep or tempfile.mkdtemp(prefix="sandslope-bag-bench-"))
    walk = work / "walk.csv"
    subprocess.run([a.cli, "simulate", "--slope", "10", "--duration", "10", "--out", walk], check=True,
                   capture_output=True)
    bag = work / "bag"
    if bag.exists():
        shutil.rmtree(bag)
    n_poses, images, _ = write_bag(bag, walk, a.size_mb)
    mcap = next(bag.glob("*.mcap"))
    size = mcap.stat().st_size / 2**20
    subprocess.run(["cat", mcap], stdout=subprocess.DEVNULL, check=True)
    rows = []
    for name, cmd in [
        ("cat (page cache)", ["cat", mcap]),
        ("sandslope track --topic", [a.cli, "track", bag, "--topic", "/mocap/robot/pose", "--slope", "10", "--json"]),
        ("rosbags AnyReader (pose topic)", [sys.executable, "-c", ROSBAGS_READ, bag]),
    ]:
        wall, rss = timed(cmd if name != "cat (page cache)" else ["sh", "-c", f"cat '{mcap}' > /dev/null"])
        rows.append((name, wall, size / wall, rss))
    print(f"bag: {size:.0f} MiB, {n_poses} poses, {images} images (MCAP, rosbags' writer)")
    print(f"{'reader':34} {'wall s':>8} {'MiB/s':>8} {'peak MiB':>9}")
    for name, wall, rate, rss in rows:
        print(f"{name:34} {wall:8.2f} {rate:8.0f} {rss:9.0f}")
    if not a.keep:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
