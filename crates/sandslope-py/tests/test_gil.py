"""Heavy calls release the GIL: another Python thread keeps running meanwhile."""

import threading
import time

import numpy as np

import sandslope


def assert_releases_the_gil(call):
    """Runs `call` on another thread while this one wakes every 2 ms: holding the GIL for the
    whole call would leave this thread a handful of wake-ups at most."""
    done = threading.Event()
    elapsed = []

    def heavy():
        t = time.perf_counter()
        call()
        elapsed.append(time.perf_counter() - t)
        done.set()

    ticks = 0
    th = threading.Thread(target=heavy)
    th.start()
    while not done.is_set():
        time.sleep(0.002)
        ticks += 1
    th.join()
    assert ticks >= 0.05 * elapsed[0] / 0.002 and ticks > 10, (ticks, elapsed)


def test_risk_releases_the_gil(robot, terrain):
    def call():
        # One adaptive quadrature per slope, about a millisecond each.
        for _ in range(3):
            sandslope.risk(robot, np.linspace(0, 30, 400), terrain=terrain, cv_n=0.1, cv_s=0.2)

    assert_releases_the_gil(call)


def test_simulate_releases_the_gil():
    # A 150 s walk: about 0.15 s of CPU.
    assert_releases_the_gil(
        lambda: sandslope.simulate("paper-hexapod", "glass-beads-300um", 10, 150, sample_rate_hz=10)
    )


def test_calibrate_releases_the_gil(root):
    robot, terrain = sandslope.Robot.preset("paper-hexapod"), sandslope.Terrain.preset("glass-beads-300um")
    speeds, forces = root / "data/paper-speeds.csv", str(root / "data/example-force-tests.toml")

    def call():
        # docs/calibration.md's joint fit, about 30 ms each (profile intervals included).
        for _ in range(10):
            sandslope.calibrate(robot, terrain, observed=speeds, forces=forces, free="plate_scale,error_floor")

    assert_releases_the_gil(call)
