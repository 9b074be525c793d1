"""The keywords of a walk are the request layer's field table: the Python layer's
``WalkSettings``, the stub's signatures and the extension's reading of them cannot drift."""

import os
import re

import pytest

import sandslope
from sandslope import _sandslope


def test_walk_settings_are_the_tables_keywords():
    table = dict(_sandslope.walk_keyword_defaults())
    assert set(sandslope.WalkSettings.__annotations__) == set(table)
    # Defaults as the table states them, the CLI's: 0.5 and 1 the library's own (§20).
    assert float(table["duty_cycle"]) == 0.5
    assert float(table["sample_rate_hz"]) == 120.0
    assert table["body_pitch"] == "locked" and table["actuator"] == "ideal"


def test_the_three_stubs_take_the_shared_keywords():
    stub = open(os.path.join(os.path.dirname(sandslope.__file__), "_sandslope.pyi")).read()
    for name in ["simulate", "simulate_ensemble", "check_convergence"]:
        body = re.search(rf"def {name}\((.*?)\) ->", stub, re.S).group(1)
        assert "**keywords: Unpack[WalkSettings]" in body, name


def test_the_new_switches_reach_the_simulator_and_bad_keywords_are_named():
    # With the two-faced belly the stance asks more torque than the servo's motor gives at the
    # gait's leg speed (docs/model.md §20.6): the servo lags and the walk differs.
    _, ideal = sandslope.simulate("paper-hexapod", "glass-beads-300um", 10, 2, two_faced_belly=True)
    _, servo = sandslope.simulate(
        "paper-hexapod", "glass-beads-300um", 10, 2, two_faced_belly=True, actuator="servo"
    )
    assert servo["speed_m_s"] != ideal["speed_m_s"]
    # The default belly pushes only: a different walk from the two-faced one; naming it is the default.
    _, default = sandslope.simulate("paper-hexapod", "glass-beads-300um", 10, 2)
    _, named = sandslope.simulate("paper-hexapod", "glass-beads-300um", 10, 2, one_sided_belly=True)
    assert default == named and default["speed_m_s"] != ideal["speed_m_s"]
    with pytest.raises(ValueError):
        sandslope.simulate("paper-hexapod", "glass-beads-300um", 10, 2, one_sided_belly=True, two_faced_belly=True)
    with pytest.raises(ValueError, match=r'actuator = "motor": expected "ideal" or "servo"'):
        sandslope.simulate("paper-hexapod", "glass-beads-300um", 10, 2, actuator="motor")
    with pytest.raises(TypeError, match="unexpected keyword argument 'wings'"):
        sandslope.simulate("paper-hexapod", "glass-beads-300um", 10, 2, wings=1)
