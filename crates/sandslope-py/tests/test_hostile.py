"""Hostile input from Python (issue 21): the CLI's size caps hold here too, decided before
anything is allocated (a 1e5 x 1e5 phase or risk map aborted the interpreter), and complex
numbers are refused instead of being cut to their real part with only a warning."""

import signal
import time

import numpy as np
import pytest

import sandslope

AXIS = np.logspace(4, 7, 100_000)  # 100,000 values: 1e10 cells squared


@pytest.fixture
def sigint_raises():
    """Ctrl-C raises KeyboardInterrupt during the test, whatever the shell that started Python
    did: a background job of a non-interactive shell inherits SIGINT ignored, Python then
    installs no handler, and `_thread.interrupt_main` does nothing (seen when the test command
    was started with `&`: these tests failed with DID NOT RAISE)."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def refused_fast(call, match):
    start = time.monotonic()
    with pytest.raises(ValueError, match=match):
        call()
    assert time.monotonic() - start < 2.0


def test_huge_maps_are_refused_before_allocating():
    refused_fast(lambda: sandslope.phase("paper-hexapod", 10.0, AXIS, AXIS), r"at most 268435456 cells \(here 100000 x 100000\)")
    refused_fast(
        lambda: sandslope.risk_map("paper-hexapod", 10.0, AXIS, AXIS, terrain="glass-beads-300um"),
        r"at most 16777216 cells \(here 100000 x 100000\)",
    )
    refused_fast(lambda: sandslope.risk("paper-hexapod", np.zeros(70_000), terrain="glass-beads-300um"), r"len\(slope_deg\) = 70000 must be at most 65536")
    refused_fast(
        lambda: sandslope.payload_envelope("paper-hexapod", np.zeros(70_000), terrain="glass-beads-300um"),
        r"len\(slope_deg\) = 70000 must be at most 65536",
    )
    with pytest.raises(ValueError, match=r"slope_deg must be real numbers, not complex"):
        sandslope.payload_envelope("paper-hexapod", np.array([10 + 1j]), terrain="glass-beads-300um")


def test_complex_numbers_are_refused_not_truncated():
    with pytest.raises(ValueError, match=r"slope_deg must be real numbers, not complex"):
        sandslope.predict("paper-hexapod", np.array([10 + 1j]), terrain="glass-beads-300um")
    with pytest.raises(ValueError, match=r"dem must be real numbers"):
        sandslope.risk_raster(np.ones((4, 4), dtype=complex), 1.0, robot="paper-hexapod", terrain="glass-beads-300um")


def test_python_speaks_python(cli, tmp_path):
    """Issue 28 item 9: touchdowns from a file as the CLI reads them; CAUSES from the library;
    the CLI's extrapolation warning; a clean dir(); errors naming Python arguments."""
    import os
    import warnings

    root = os.path.join(os.path.dirname(__file__), "..", "..", "..")
    capture = os.path.join(root, "examples", "tracking", "slope20-vicon.csv")
    log = os.path.join(root, "examples", "tracking", "slope20-touchdowns.txt")
    from_file = sandslope.track([capture], touchdowns=[log])
    want = cli.json("track", capture, "--touchdowns", log)
    assert from_file["t1_s"] == pytest.approx(want["t1_s"], rel=1e-12)
    with pytest.raises(ValueError, match="touchdowns must hold, per recording, a list of times"):
        sandslope.track([capture], touchdowns=[[0.2, "x"]])
    assert sandslope.CAUSES[-1] == "robust_step" and len(sandslope.CAUSES) == 6
    assert not {"np", "os", "Any", "Dict"} & set(dir(sandslope))
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        sandslope.predict("paper-hexapod", [10, 30], terrain="glass-beads-300um")
    assert any("30 deg are above the terrain's last measured point (24 deg)" in str(x.message) for x in w)
    manifest = tmp_path / "m.toml"
    trial = tmp_path / "t.csv"
    trial.write_text("depth_mm,force_counts\n0,0\n1,10\n2,20\n")
    (tmp_path / "s.csv").write_text("displacement_mm,force_n\n0,0\n1,1\n2,2\n")
    manifest.write_text(
        '[penetration]\ndisk_radius_m = 0.01\n[shear]\nplate_width_m = 0.03\nplate_depth_m = 0.02\n'
        '[[trial]]\nkind = "penetration"\nslope_deg = 0\nfile = "t.csv"\n'
        '[[trial]]\nkind = "shear"\nslope_deg = 0\nfile = "s.csv"\n'
    )
    with pytest.raises(ValueError, match="counts_per_newton= in Python"):
        sandslope.fit(str(manifest))


def test_ctrl_c_stops_a_long_risk_call(sigint_raises):
    """Issue 21: `risk` over the cap of 65,536 slopes ran for over a minute with the GIL
    released and ignored Ctrl-C until it finished. It now works in chunks and checks for a
    pending signal between them: a SIGINT 0.5 s in raises KeyboardInterrupt within seconds."""
    import _thread
    import threading

    slopes = np.linspace(0.0, 24.0, 65_536)
    timer = threading.Timer(0.5, _thread.interrupt_main)  # simulates SIGINT (Ctrl-C)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sandslope.risk("paper-hexapod", slopes, terrain="glass-beads-300um")
    finally:
        timer.cancel()
    # The whole call takes 30 s or more on two cores; a chunk is a fraction of a second.
    assert time.monotonic() - start < 8.0


def test_ctrl_c_stops_a_long_phase_call(sigint_raises):
    """Issue 21: `phase` at its cap (2^28 cells) ran with the GIL released to the end, seconds
    to minutes, whatever the user pressed. It now writes the map in blocks of about 2^20 cells
    and checks for a pending signal between them: a SIGINT 0.3 s in raises KeyboardInterrupt
    at once, where the whole call takes 2.2 s on this 2-core machine (regime only)."""
    import _thread
    import threading

    k_n = np.geomspace(1e4, 1e7, 16_384)
    k_s = np.geomspace(1e3, 1e8, 16_384)
    robot = sandslope.Robot.preset("paper-hexapod")
    timer = threading.Timer(0.3, _thread.interrupt_main)  # simulates SIGINT (Ctrl-C)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sandslope.phase(robot, 20.0, k_n, k_s, regime_only=True)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 1.0


def test_ctrl_c_stops_a_long_plan_call(sigint_raises):
    """Issue 21: `plan` ran its searches to the end with the GIL released, whatever the user
    pressed. The search now runs on a thread of its own and polls a stop flag that Ctrl-C
    raises. On a 4000 x 4000 level map whose goal lies behind a column of missing heights, the
    search settles the whole west side (about 12 million cells) before reporting no route: 6.6 s
    uninterrupted on this 2-core machine under load. A SIGINT 0.5 s in raises KeyboardInterrupt
    after 1.2 s: the planner's set-up (about 1 s at this size, not interruptible) and then the
    search's first progress report. The same call is then run to its end: without the stop
    flag, the interrupt would only be raised after the call returns, so the interrupted call
    must take well under the whole call's time (half, here), whatever the machine's speed."""
    import _thread
    import threading

    dem = np.zeros((4000, 4000))
    dem[:, 3000] = np.nan

    def call():
        return sandslope.plan(dem, 1.0, robot="paper-hexapod", terrain="glass-beads-300um",
                              start=(1, 1), goal=(2000, 3500), objective="distance")

    timer = threading.Timer(0.5, _thread.interrupt_main)  # simulates SIGINT (Ctrl-C)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    interrupted = time.monotonic() - start
    assert interrupted < 3.0, interrupted

    start = time.monotonic()
    assert not call()["routes"]["distance"]["found"]  # no route: the goal is behind the missing column
    whole = time.monotonic() - start
    assert interrupted < 0.5 * whole, (interrupted, whole)


def test_ctrl_c_stops_the_simulators_calibration(sigint_raises, root, monkeypatch):
    """`calibrate(model="simulate")` runs for tens of seconds with the GIL released (about a
    minute of CPU for the paper's evidence in a release build, docs/calibration.md; several
    times that in the tests' debug build). The fit runs on its own thread while the caller's
    looks for a signal every 50 ms, and a signal stops the simulator's walks: a SIGINT 1 s in
    raises KeyboardInterrupt within seconds."""
    import _thread
    import threading

    monkeypatch.chdir(root)
    timer = threading.Timer(1.0, _thread.interrupt_main)  # simulates SIGINT (Ctrl-C)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sandslope.calibrate(
                observed="data/paper-speeds.csv",
                forces="data/example-force-tests.toml",
                free=["plate_scale", "error_floor"],
                model="simulate",
            )
    finally:
        timer.cancel()
    assert time.monotonic() - start < 8.0
