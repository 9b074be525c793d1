"""ROS 2 bags in and MCAP out (docs/bags.md), checked with writers and readers that are not
sandslope's: `rosbags` (MCAP and SQLite3 storage) and `mcap` + `mcap-ros2-support`.

The inputs are a simulated walk (`simulate --out`, plain CSV) and an emulated drive's servo
log (`drive --emulate --log`, CSV); the bags hold the same numbers as messages, so `track` and
`infer --servo-log` must answer on the bag what they answer on the CSV."""

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from mcap_ros2.writer import Writer as McapRos2Writer
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

ROOT = Path(__file__).resolve().parents[3]
TS = get_typestore(Stores.ROS2_HUMBLE)
T0_NS = 1_700_000_000_000_000_000  # the bags' clock: a wall-clock epoch time, as a lab's


def _cli() -> Path:
    given = os.environ.get("SANDSLOPE_CLI")
    if given:
        return Path(given)
    subprocess.run(["cargo", "build", "--quiet", "-p", "sandslope-cli"], cwd=ROOT, check=True)
    return ROOT / "target" / "debug" / "sandslope"


def run(*args, code=0):
    p = subprocess.run([str(_cli()), *map(str, args)], capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == code, f"sandslope {' '.join(map(str, args))}: exit {p.returncode}\n{p.stderr}"
    return p


def run_json(*args):
    return json.loads(run(*args, "--json").stdout)


def msg(typename, **fields):
    return TS.types[typename](**fields)


def stamp(ns):
    return msg("builtin_interfaces/msg/Time", sec=int(ns // 1_000_000_000), nanosec=int(ns % 1_000_000_000))


def header(ns, frame="world"):
    return msg("std_msgs/msg/Header", stamp=stamp(ns), frame_id=frame)


def point(x, y, z):
    return msg("geometry_msgs/msg/Point", x=float(x), y=float(y), z=float(z))


def vector(x, y, z):
    return msg("geometry_msgs/msg/Vector3", x=float(x), y=float(y), z=float(z))


def quat():
    return msg("geometry_msgs/msg/Quaternion", x=0.0, y=0.0, z=0.0, w=1.0)


def pose_stamped(ns, p):
    pose = msg("geometry_msgs/msg/Pose", position=point(*p), orientation=quat())
    return msg("geometry_msgs/msg/PoseStamped", header=header(ns), pose=pose)


def transform(ns, child, p):
    tr = msg("geometry_msgs/msg/Transform", translation=vector(*p), rotation=quat())
    return msg("geometry_msgs/msg/TransformStamped", header=header(ns), child_frame_id=child, transform=tr)


def odometry(ns, p):
    cov = np.zeros(36)
    pose = msg("geometry_msgs/msg/PoseWithCovariance",
               pose=msg("geometry_msgs/msg/Pose", position=point(*p), orientation=quat()), covariance=cov)
    twist = msg("geometry_msgs/msg/TwistWithCovariance",
                twist=msg("geometry_msgs/msg/Twist", linear=vector(0, 0, 0), angular=vector(0, 0, 0)),
                covariance=cov)
    return msg("nav_msgs/msg/Odometry", header=header(ns), child_frame_id="base_link", pose=pose, twist=twist)


def write_rosbags(path, storage, topics):
    """A bag folder written by `rosbags`: topics is {name: (type, [(ns, message), ...])}."""
    with Writer(path, version=9, storage_plugin=storage) as w:
        conns = {name: w.add_connection(name, typ, typestore=TS) for name, (typ, _) in topics.items()}
        merged = sorted((ns, name, m) for name, (_, items) in topics.items() for ns, m in items)
        for ns, name, m in merged:
            w.write(conns[name], ns, TS.serialize_cdr(m, topics[name][0]))


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    """A simulated 10-degree walk as plain CSV, and its `track` answer."""
    d = tmp_path_factory.mktemp("walk")
    csv = d / "walk.csv"
    run("simulate", "--slope", "10", "--duration", "6", "--out", csv)
    frame = pd.read_csv(csv)
    rows = [(T0_NS + round(t * 1e9), (x, y, z)) for t, x, y, z in frame[["time_s", "x_m", "y_m", "z_m"]].itertuples(index=False)]
    return d, csv, rows, run_json("track", csv, "--slope", "10")


def assert_same_track(bag_answer, csv_answer):
    a, b = bag_answer, csv_answer
    assert a["steps"] == b["steps"] and a["steps"] >= 4
    assert a["speed_m_s"] == pytest.approx(b["speed_m_s"], rel=1e-3)
    assert a["step_m"] == pytest.approx(b["step_m"], rel=1e-3)
    assert bag_answer["recordings"][0]["frame_rate_hz"] == pytest.approx(120.0, rel=1e-9)


def test_track_reads_poses_from_an_mcap_bag_as_from_the_csv(walk):
    d, _, rows, expected = walk
    bag = d / "poses_mcap"
    noise = [(ns, msg("std_msgs/msg/String", data="x")) for ns, _ in rows[::10]]
    write_rosbags(bag, StoragePlugin.MCAP, {
        "/mocap/robot/pose": ("geometry_msgs/msg/PoseStamped", [(ns, pose_stamped(ns, p)) for ns, p in rows]),
        "/chatter": ("std_msgs/msg/String", noise),
    })
    # The only pose topic is taken without --topic; naming it gives the same answer.
    assert_same_track(run_json("track", bag, "--slope", "10"), expected)
    got = run_json("track", bag, "--topic", "/mocap/robot/pose", "--slope", "10")
    assert_same_track(got, expected)
    assert got["recordings"][0]["body"] == "/mocap/robot/pose"
    # The single .mcap file inside the folder reads alike.
    single = next(bag.glob("*.mcap"))
    assert_same_track(run_json("track", single, "--topic", "/mocap/robot/pose", "--slope", "10"), expected)


def test_track_reads_a_tf_frame_from_an_sqlite3_bag(walk):
    d, _, rows, expected = walk
    bag = d / "tf_db3"
    tf = [(ns, msg("tf2_msgs/msg/TFMessage", transforms=[transform(ns, "base_link", p), transform(ns, "leg_0", (0, 0, 0))]))
          for ns, p in rows]
    write_rosbags(bag, StoragePlugin.SQLITE3, {"/tf": ("tf2_msgs/msg/TFMessage", tf)})
    got = run_json("track", bag, "--topic", "/tf", "--frame", "base_link", "--slope", "10")
    assert_same_track(got, expected)
    # Two child frames and no --frame: the error lists them.
    err = run("track", bag, "--topic", "/tf", code=2).stderr
    assert "--frame" in err and "base_link" in err and "leg_0" in err, err
    err = run("track", bag, "--topic", "/tf", "--frame", "nope", code=2).stderr
    assert "no child frame `nope`" in err, err


def test_track_reads_odometry_written_by_mcap_ros2_support(walk):
    d, _, rows, expected = walk
    path = d / "odom.mcap"
    with open(path, "wb") as f:
        w = McapRos2Writer(f)
        schema = w.register_msgdef("nav_msgs/Odometry", TS.generate_msgdef("nav_msgs/msg/Odometry", ros_version=2)[0])
        for ns, p in rows:
            o = odometry(ns, p)
            w.write_message("/odom", schema, {
                "header": {"stamp": {"sec": o.header.stamp.sec, "nanosec": o.header.stamp.nanosec}, "frame_id": "odom"},
                "child_frame_id": "base_link",
                "pose": {"pose": {"position": {"x": p[0], "y": p[1], "z": p[2]},
                                  "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}},
                         "covariance": [0.0] * 36},
                "twist": {"twist": {"linear": {"x": 0.0, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.0}},
                          "covariance": [0.0] * 36},
            }, log_time=ns, publish_time=ns)
        w.finish()
    assert_same_track(run_json("track", path, "--topic", "/odom", "--slope", "10"), expected)


def test_several_pose_topics_are_listed_when_none_is_chosen(walk):
    d, _, rows, _ = walk
    bag = d / "two_topics"
    few = rows[:50]
    write_rosbags(bag, StoragePlugin.MCAP, {
        "/a/pose": ("geometry_msgs/msg/PoseStamped", [(ns, pose_stamped(ns, p)) for ns, p in few]),
        "/b/pose": ("geometry_msgs/msg/PoseStamped", [(ns, pose_stamped(ns, p)) for ns, p in few]),
        "/chatter": ("std_msgs/msg/String", [(ns, msg("std_msgs/msg/String", data="x")) for ns, _ in few]),
    })
    err = run("track", bag, code=2).stderr
    assert "--topic" in err and "/a/pose (geometry_msgs/msg/PoseStamped, 50 messages)" in err and "/b/pose" in err, err
    # A topic of the wrong type names the topic and its type.
    err = run("track", bag, "--topic", "/chatter", code=2).stderr
    assert "`/chatter` is std_msgs/msg/String" in err, err


@pytest.fixture(scope="module")
def servo_run(tmp_path_factory):
    """An emulated 6 s drive at 20 degrees on sand of k_s = 2.5e5 N/m^3, logged as CSV."""
    d = tmp_path_factory.mktemp("drive")
    log = d / "run.csv"
    run("drive", "--emulate", "--slope", "20", "--emulate-k-s", "2.5e5", "--duration", "6", "--log", log)
    return d, log, pd.read_csv(log, comment="#")


INFER = ("--grid-points", "9", "--k-s-prior", "3e4:3e7", "--slope", "20")
K_T = 0.52 / 1.47  # the XL330's torque constant, N m/A (stall torque over stall current, datasheet)


def joint_states(frame, effort):
    """One JointState per bus cycle: the leg angles and `effort(row)` of legs 0 to 5."""
    out = []
    for t, cycle in frame.groupby("time_s", sort=True):
        cycle = cycle.sort_values("leg")
        ns = T0_NS + round((t + 10.0) * 1e9)
        out.append((ns, msg("sensor_msgs/msg/JointState", header=header(ns, ""),
                             name=[f"leg{k}" for k in cycle["leg"]],
                             position=cycle["leg_angle_rad"].to_numpy(float),
                             velocity=np.zeros(len(cycle)),
                             effort=np.array([effort(r) for r in cycle.itertuples()], float))))
    return out


def sig3(x):
    return float(f"{x:.3g}")


def test_infer_servo_log_reads_joint_states_as_the_csv(servo_run):
    d, log, frame = servo_run
    expected = run_json("infer", "--servo-log", log, *INFER)
    # Torque in N m (the message's unit), SQLite3 storage.
    bag = d / "joints_db3"
    write_rosbags(bag, StoragePlugin.SQLITE3,
                  {"/joint_states": ("sensor_msgs/msg/JointState", joint_states(frame, lambda r: r.drive_torque_n_m))})
    got = run_json("infer", "--servo-log", bag, *INFER)
    for key in ("k_s", "k_s_lo", "k_s_hi"):
        assert sig3(got[key]) == sig3(expected[key]), (key, got[key], expected[key])
    assert got["strides"] == expected["strides"]
    # Current in mA in each leg's sense, MCAP storage, the joints named out of order.
    bag = d / "joints_mcap"
    states = joint_states(frame, lambda r: r.drive_torque_n_m / K_T * 1000.0)
    write_rosbags(bag, StoragePlugin.MCAP, {"/robot/joint_states": ("sensor_msgs/msg/JointState", states)})
    got = run_json("infer", "--servo-log", bag, "--effort-unit", "ma",
                   "--joints", "leg0,leg1,leg2,leg3,leg4,leg5", *INFER)
    for key in ("k_s", "k_s_lo", "k_s_hi"):
        assert sig3(got[key]) == sig3(expected[key]), (key, got[key], expected[key])
    err = run("infer", "--servo-log", bag, "--joints", "leg0,leg1", *INFER, code=2).stderr
    assert "6 legs" in err, err


def test_bad_bags_name_file_topic_and_offset(walk, tmp_path):
    d, _, rows, _ = walk
    bag = tmp_path / "good"
    write_rosbags(bag, StoragePlugin.MCAP,
                  {"/pose": ("geometry_msgs/msg/PoseStamped", [(ns, pose_stamped(ns, p)) for ns, p in rows])})
    good = next(bag.glob("*.mcap")).read_bytes()
    # Cut short.
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(good[: len(good) // 2])
    err = run("track", cut, "--topic", "/pose", code=2).stderr
    assert str(cut) in err and "byte offset" in err and "cut short" in err, err
    # A chunk's bytes changed: its CRC (written by mcap-ros2-support) no longer matches.
    from mcap.writer import CompressionType
    whole = tmp_path / "whole.mcap"
    with open(whole, "wb") as f:
        w = McapRos2Writer(f, compression=CompressionType.NONE)
        schema = w.register_msgdef("geometry_msgs/PoseStamped",
                                   TS.generate_msgdef("geometry_msgs/msg/PoseStamped", ros_version=2)[0])
        for ns, p in rows:
            w.write_message("/pose", schema, {
                "header": {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}, "frame_id": "world"},
                "pose": {"position": {"x": p[0], "y": p[1], "z": p[2]},
                         "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}}, log_time=ns, publish_time=ns)
        w.finish()
    run("track", whole, "--topic", "/pose")
    bad = bytearray(whole.read_bytes())
    bad[len(bad) // 3] ^= 0xFF
    crc = tmp_path / "crc.mcap"
    crc.write_bytes(bytes(bad))
    err = run("track", crc, "--topic", "/pose", code=2).stderr
    assert str(crc) in err and "byte offset" in err and "CRC" in err, err
    # An encoding other than CDR.
    from mcap.writer import Writer as RawWriter
    odd = tmp_path / "json.mcap"
    with open(odd, "wb") as f:
        w = RawWriter(f)
        w.start()
        s = w.register_schema("geometry_msgs/msg/PoseStamped", "jsonschema", b"{}")
        c = w.register_channel("/pose", "json", s)
        w.add_message(c, log_time=1, publish_time=1, data=b"{}")
        w.finish()
    err = run("track", odd, "--topic", "/pose", code=2).stderr
    assert str(odd) in err and "`/pose`" in err and "encoding `json`" in err, err
    # A metadata.yaml declaring a billion messages.
    forged = tmp_path / "forged"
    shutil.copytree(bag, forged)
    meta = (forged / "metadata.yaml").read_text()
    (forged / "metadata.yaml").write_text(meta.replace(f"message_count: {len(rows)}", "message_count: 1000000000"))
    err = run("track", forged, "--topic", "/pose", code=2).stderr
    assert "metadata.yaml" in err and "1000000000" in err, err


def read_back(path):
    """Every message of an MCAP file sandslope wrote, decoded by `mcap` + `mcap-ros2-support` and
    by `rosbags`: {topic: [(log_time, message), ...]} from the first, the count from the second."""
    from rosbags.highlevel import AnyReader
    topics = {}
    with open(path, "rb") as f:
        for _schema, channel, message, decoded in make_reader(f, decoder_factories=[DecoderFactory()]).iter_decoded_messages():
            assert channel.message_encoding == "cdr" and _schema.encoding == "ros2msg"
            topics.setdefault(channel.topic, []).append((message.log_time, decoded))
    with AnyReader([Path(path)]) as r:
        decoded = sum(1 for c, _t, raw in r.messages() if r.deserialize(raw, c.msgtype) is not None)
    assert decoded == sum(len(v) for v in topics.values())
    for items in topics.values():
        times = [t for t, _ in items]
        assert times == sorted(times), "log times must not go back"
    return topics


def test_simulate_out_mcap_reads_back_and_tracks_as_the_csv(walk):
    d, _, rows, expected = walk
    path = d / "walk.mcap"
    run("simulate", "--slope", "10", "--duration", "6", "--out", path)
    topics = read_back(path)
    assert set(topics) == {"/sandslope/pose", "/tf", "/joint_states", "/sandslope/leg_forces"}
    assert all(len(v) == len(rows) for v in topics.values())
    # The pose is the CSV's position; the TF tree is world -> base_link -> leg_0..leg_5.
    _, last = topics["/sandslope/pose"][-1]
    assert [last.pose.position.x, last.pose.position.y, last.pose.position.z] == pytest.approx(list(rows[-1][1]), abs=1e-12)
    _, tf = topics["/tf"][0]
    assert [t.child_frame_id for t in tf.transforms] == ["base_link"] + [f"leg_{j}" for j in range(6)]
    assert_same_track(run_json("track", path, "--topic", "/sandslope/pose", "--slope", "10"), expected)


def test_drive_log_mcap_reads_back_and_infers(tmp_path):
    path = tmp_path / "run.mcap"
    run("drive", "--emulate", "--slope", "20", "--emulate-k-s", "2.5e5", "--duration", "6", "--live", "--log", path)
    topics = read_back(path)
    assert {"/sandslope/run", "/joint_states", "/sandslope/commands", "/sandslope/verdict"} <= set(topics)
    assert len(topics["/joint_states"]) == len(topics["/sandslope/commands"]) > 100
    assert "slope_deg = 20" in topics["/sandslope/run"][0][1].data
    assert len(topics.get("/sandslope/live", [])) >= 1
    # The verdict is the outcome as `drive --json` gives it, not Rust's Result wrapper.
    verdict = json.loads(topics["/sandslope/verdict"][-1][1].data)
    assert "Ok" not in verdict and verdict["outcome"] == "completed", verdict
    _, js = topics["/joint_states"][-1]
    assert list(js.name) == [f"leg_{j}" for j in range(6)]
    # The slope from the bag's /sandslope/run header, as from a CSV log's `# slope_deg` line.
    got = run_json("infer", "--servo-log", path, *INFER[:-2])
    assert got["k_s_lo"] < got["k_s"] < got["k_s_hi"]


def test_plan_risk_map_as_nav2_map_and_occupancy_grid(tmp_path):
    import tifffile
    from ruamel.yaml import YAML  # installed with rosbags
    dem = ROOT / "examples" / "planning" / "dune.asc"
    args = ("plan", "--dem", dem, "--start", "52,30", "--goal", "30,30", "--objective", "time,risk")
    run(*args, "--risk-map", tmp_path / "risk.tif")
    run(*args, "--risk-map", tmp_path / "risk.yaml")
    run(*args, "--risk-map", tmp_path / "risk.mcap")
    bands = tifffile.imread(tmp_path / "risk.tif")  # (rows, cols, 2): p_fail, climb azimuth
    p_fail = bands[..., 0].astype(np.float64)
    meta = YAML(typ="safe").load((tmp_path / "risk.yaml").read_text())
    assert meta["image"] == "risk.pgm" and meta["mode"] == "raw" and meta["negate"] == 0
    assert meta["resolution"] == pytest.approx(0.3) and meta["origin"] == [0.0, 0.0, 0.0]
    assert meta["occupied_thresh"] == 0.05 and meta["free_thresh"] == 0.0
    pgm = (tmp_path / "risk.pgm").read_bytes()
    assert pgm.startswith(b"P5\n")
    body = pgm.split(b"\n255\n", 1)[1]
    pixels = np.frombuffer(body, np.uint8).reshape(200, 200)
    want = np.where(np.isfinite(p_fail), np.round(100 * np.nan_to_num(p_fail)), 255)
    assert (pixels == want.reshape(200, 200)).all()
    topics = read_back(tmp_path / "risk.mcap")
    _, grid = topics["/sandslope/risk_map"][0]
    assert (grid.info.width, grid.info.height) == (200, 200) and grid.info.resolution == pytest.approx(0.3)
    # OccupancyGrid's row 0 is the south edge: the image's last row.
    data = np.asarray(grid.data, np.int16).reshape(200, 200)
    south = pixels[-1].astype(np.int16)
    assert (data[0] == np.where(south == 255, -1, south)).all()
    assert {"/sandslope/route/time", "/sandslope/route/risk"} <= set(topics)


def test_read_bag_gives_the_csv_columns(walk, servo_run):
    import sandslope
    d, csv, rows, _ = walk
    bag = d / "poses_mcap"  # written by test_track_reads_poses_from_an_mcap_bag_as_from_the_csv
    if not bag.exists():
        write_rosbags(bag, StoragePlugin.MCAP, {
            "/mocap/robot/pose": ("geometry_msgs/msg/PoseStamped", [(ns, pose_stamped(ns, p)) for ns, p in rows])})
    topics = sandslope.read_bag(bag)
    assert "/mocap/robot/pose" in list(topics["name"])
    poses = sandslope.read_bag(bag, "/mocap/robot/pose")
    expected = pd.read_csv(csv)
    assert list(poses.columns) == ["time_s", "x_m", "y_m", "z_m"]
    assert len(poses) == len(expected)
    for c in ("time_s", "x_m", "y_m", "z_m"):
        assert np.allclose(poses[c], expected[c], rtol=0, atol=1e-9), c
    dd, _log, frame = servo_run
    jbag = dd / "joints_py"
    write_rosbags(jbag, StoragePlugin.MCAP,
                  {"/joint_states": ("sensor_msgs/msg/JointState", joint_states(frame, lambda r: r.drive_torque_n_m))})
    got = sandslope.read_bag(jbag, "/joint_states")
    want, _meta = sandslope.read_servo_log(_log)
    for c in ("leg", "leg_angle_rad", "drive_torque_n_m"):
        assert np.array_equal(got[c].to_numpy(), want[c].to_numpy()), c
    with pytest.raises(ValueError, match="no topic `/nope`"):
        sandslope.read_bag(bag, "/nope")


# --- fit from load-cell bags (WrenchStamped + the intruder's pose) -------------------------

DISK_R = 0.01             # m: the disk's area pi r^2 (docs/measurements.md's manifest)
PLATE_W, PLATE_D = 0.03, 0.02
K_N, K_S = 7.0e5, 2.0e6   # N/m^3: the values the synthetic recordings are generated from


def wrench(ns, fz, frame="load_cell"):
    w = msg("geometry_msgs/msg/Wrench", force=vector(0.0, 0.0, fz), torque=vector(0, 0, 0))
    return msg("geometry_msgs/msg/WrenchStamped", header=header(ns, frame), wrench=w)


def quat_z(angle):
    return msg("geometry_msgs/msg/Quaternion", x=0.0, y=0.0, z=float(np.sin(angle / 2)), w=float(np.cos(angle / 2)))


def tf_stamped(ns, parent, child, p, q=None):
    tr = msg("geometry_msgs/msg/Transform", translation=vector(*p), rotation=q or quat())
    return msg("geometry_msgs/msg/TransformStamped", header=header(ns, parent), child_frame_id=child, transform=tr)


def load_cell_trials(rng):
    """Per trial (kind, slope, air, t, position, force): a disk pushed 40 mm at 5 cm/s, a plate
    dragged 100 mm at 5 cm/s, load cells at 100 Hz with 0.02 N noise on a 0.3 N offset; the
    measured runs' forces are k_n A d and k_s W_p d_p^2 (1 - exp(-x / 5 mm)) (docs/model.md §10)."""
    area = np.pi * DISK_R**2
    out = []
    t = np.arange(0, 0.8, 0.01)
    for air in (True, False):
        depth = 0.05 * t
        force = 0.3 + (0 if air else K_N * area * depth) + rng.normal(0, 0.02, t.size)
        out.append(("penetration", 0.0, air, t, depth, force))
    t = np.arange(0, 2.0, 0.01)
    for air in (True, False):
        x = 0.05 * t
        force = 0.3 + (0 if air else K_S * PLATE_W * PLATE_D**2 * (1 - np.exp(-x / 0.005))) + rng.normal(0, 0.02, t.size)
        out.append(("shear", 0.0, air, t, x, force))
    return out


def write_manifest(path, files):
    lines = [f"[penetration]\ndisk_radius_m = {DISK_R}\n[shear]\nplate_width_m = {PLATE_W}\nplate_depth_m = {PLATE_D}\n"]
    for (kind, slope, air, _t, _p, _f), (file, extra) in zip(load_cell_trials(np.random.default_rng(0)), files):
        lines.append(f'[[trial]]\nkind = "{kind}"\nslope_deg = {slope}\nfile = "{file}"\nair = {str(air).lower()}\n{extra}')
    path.write_text("\n".join(lines))


def test_fit_reads_wrenches_and_poses_from_bags_as_the_csv(tmp_path):
    trials = load_cell_trials(np.random.default_rng(7))
    csv_files, bag_files = [], []
    for i, (kind, _slope, _air, t, pos, force) in enumerate(trials):
        name = f"{kind}-{i}"
        col = "depth_m" if kind == "penetration" else "displacement_m"
        pd.DataFrame({"time_s": t, col: pos, "force_n": force}).to_csv(tmp_path / f"{name}.csv", index=False)
        csv_files.append((f"{name}.csv", ""))
        # The load cell at 100 Hz, reading compression negative along its own z; the intruder
        # tracked at 120 Hz by a clock 3 ms off the load cell's (so every force sample takes
        # an interpolated position: exact here, the motion being uniform).
        w_ns = [T0_NS + round(s * 1e9) for s in t]
        p_t = np.arange(-0.05, t[-1] + 0.05, 1 / 120) + 0.003
        speed = 0.05
        wrenches = [(ns, wrench(ns, -f)) for ns, f in zip(w_ns, force)]
        if kind == "penetration":
            # A PoseStamped topic in the world frame: the disk goes down from z = 0.2 m.
            poses = [(T0_NS + round(s * 1e9), pose_stamped(T0_NS + round(s * 1e9), (0.1, 0.0, 0.2 - speed * s)))
                     for s in p_t]
            write_rosbags(tmp_path / name, StoragePlugin.MCAP, {
                "/load_cell/wrench": ("geometry_msgs/msg/WrenchStamped", wrenches),
                "/rig/disk": ("geometry_msgs/msg/PoseStamped", poses),
            })
            bag_files.append((name, 'force_axis = "-z"\n'))
        else:
            # The plate as a TF frame two levels below the root: world -> (static, turned 90
            # degrees about z) rig -> (moving) carriage -> (moving) plate. In world the plate
            # moves along +y; the carriage carries the drag and the plate hangs 5 cm below it.
            tf = []
            for s in p_t:
                ns = T0_NS + round(s * 1e9)
                tf.append((ns, msg("tf2_msgs/msg/TFMessage", transforms=[
                    tf_stamped(ns, "rig", "carriage", (speed * s, 0.0, 0.3)),
                    tf_stamped(ns, "carriage", "plate", (0.0, 0.0, -0.05)),
                ])))
            static = [(T0_NS, msg("tf2_msgs/msg/TFMessage",
                                  transforms=[tf_stamped(T0_NS, "world", "rig", (1.0, 2.0, 0.0), quat_z(np.pi / 2))]))]
            write_rosbags(tmp_path / name, StoragePlugin.SQLITE3, {
                "/ft": ("geometry_msgs/msg/WrenchStamped", wrenches),
                "/tf": ("tf2_msgs/msg/TFMessage", tf),
                "/tf_static": ("tf2_msgs/msg/TFMessage", static),
            })
            bag_files.append((name, 'force_topic = "/ft"\nposition_topic = "/tf"\nframe = "plate"\nforce_axis = "-z"\n'))
    write_manifest(tmp_path / "csv.toml", csv_files)
    write_manifest(tmp_path / "bag.toml", bag_files)
    from_csv = run_json("fit", tmp_path / "csv.toml")
    from_bag = run_json("fit", tmp_path / "bag.toml")
    (pc,), (pb,) = from_csv["points"], from_bag["points"]
    # The stamps are whole nanoseconds (0.5 ns is 25 pm of travel at 5 cm/s): the fitted values
    # agree to 1e-9, their SDs (built from residuals of a few mN) to 1e-6.
    for key, rel in (("k_n", 1e-9), ("k_s", 1e-9), ("k_n_sd", 1e-6), ("k_s_sd", 1e-6)):
        assert pb[key] == pytest.approx(pc[key], rel=rel), (key, pb[key], pc[key])
    for tc, tb in zip(from_csv["trials"], from_bag["trials"]):
        assert (tb["rows"], tb["used"]) == (tc["rows"], tc["used"]), tb["file"]
    # The values the recordings were generated from (the noise leaves well under 1%).
    assert pb["k_n"] == pytest.approx(K_N, rel=0.01) and pb["k_s"] == pytest.approx(K_S, rel=0.01), pb
    # The same from Python.
    import sandslope
    py = sandslope.fit(tmp_path / "bag.toml")
    assert py["points"]["k_n"][0] == pytest.approx(pc["k_n"], rel=1e-9)
    # read_bag gives the trial's columns as fit reads them: the CSV's, to the stamps' nanosecond.
    _kind, _slope, _air, t, depth, force = trials[1]
    cols = sandslope.read_bag(tmp_path / "penetration-1", "/load_cell/wrench", force_axis="-z")
    assert list(cols.columns) == ["time_s", "position_m", "force_n"] and cols.attrs["body"] == "/rig/disk"
    assert np.allclose(cols["time_s"], t, rtol=0, atol=1e-9)
    assert np.allclose(cols["position_m"], depth, rtol=0, atol=1e-10)
    assert np.array_equal(cols["force_n"], force)
    with pytest.raises(ValueError, match="force_axis"):
        sandslope.read_bag(tmp_path / "penetration-1", "/load_cell/wrench")
    # A bag trial without force_axis, and CSV trials with bag keys, are refused by name.
    bad = tmp_path / "bad.toml"
    write_manifest(bad, [(f, "") for f, _ in bag_files])
    err = run("fit", bad, code=2).stderr
    assert "force_axis" in err and "[[trial]] #1" in err, err
    write_manifest(bad, [(f, 'force_axis = "z"\n') for f, _ in csv_files])
    err = run("fit", bad, code=2).stderr
    assert "force_axis are keys of a ROS 2 bag trial" in err, err


def test_track_composes_a_tf_frame_up_its_tree(walk):
    """base_link two levels below world: world -> (on /tf_static, at (1, 2, 0) turned 90 degrees
    about z) odom -> (on /tf, moving) carriage -> base_link. Composed, its position is the
    walk's again, so track answers as on the CSV."""
    d, _, rows, expected = walk
    bag = d / "tf_tree"
    tf = []
    for ns, p in rows:
        # The walk's world position w = (1, 2, 0) + R_z(90) q, so q = (w_y - 2, -(w_x - 1), w_z).
        q = (p[1] - 2.0, -(p[0] - 1.0), p[2])
        c = (0.5 * q[0], 0.01, 0.0)  # the carriage holds half of it
        tf.append((ns, msg("tf2_msgs/msg/TFMessage", transforms=[
            tf_stamped(ns, "odom", "carriage", c),
            tf_stamped(ns, "carriage", "base_link", (q[0] - c[0], q[1] - c[1], q[2] - c[2])),
        ])))
    static = [(rows[0][0], msg("tf2_msgs/msg/TFMessage",
                               transforms=[tf_stamped(rows[0][0], "world", "odom", (1.0, 2.0, 0.0), quat_z(np.pi / 2))]))]
    write_rosbags(bag, StoragePlugin.MCAP, {"/tf": ("tf2_msgs/msg/TFMessage", tf), "/tf_static": ("tf2_msgs/msg/TFMessage", static)})
    got = run_json("track", bag, "--topic", "/tf", "--frame", "base_link", "--slope", "10")
    assert_same_track(got, expected)
    assert got["recordings"][0]["body"] == "/tf base_link in world"
    # Python's track reads the same bag, topic and frame.
    import sandslope
    py = sandslope.track(bag, 10, topic="/tf", frame="base_link")
    assert py["speed_m_s"] == pytest.approx(got["speed_m_s"], rel=1e-12)
    assert list(py["recordings"]["body"]) == ["/tf base_link in world"]
