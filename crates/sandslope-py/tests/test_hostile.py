"""Hostile input from Python (issue 21): the CLI's size caps hold here too, decided before
anything is allocated (a 1e5 x 1e5 phase or risk map aborted the interpreter), and complex
numbers are refused instead of being cut to their real part with only a warning."""

import time

import numpy as np
import pytest

import sandslope

AXIS = np.logspace(4, 7, 100_000)  # 100,000 values: 1e10 cells squared


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


def test_complex_numbers_are_refused_not_truncated():
    with pytest.raises(ValueError, match=r"slope_deg must be real numbers, not complex"):
        sandslope.predict("paper-hexapod", np.array([10 + 1j]), terrain="glass-beads-300um")
    with pytest.raises(ValueError, match=r"dem must be real numbers"):
        sandslope.risk_raster(np.ones((4, 4), dtype=complex), 1.0, robot="paper-hexapod", terrain="glass-beads-300um")
