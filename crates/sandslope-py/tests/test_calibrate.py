"""sandslope.calibrate against `sandslope calibrate --json` (docs/calibration.md): the same
request, so the same keys and values, and the same refusals in Python's words."""

import json

import pytest

import sandslope

SPEEDS = "data/paper-speeds.csv"
FORCES = "data/example-force-tests.toml"


def _cli_json(cli, tmp_path, *flags):
    out = tmp_path / "cli-terrain.toml"
    p = cli.run("calibrate", *flags, "--out", out, "--json")
    assert out.exists()
    return json.loads(p.stdout)


def test_the_docs_example_equals_the_cli(cli, root, tmp_path, monkeypatch):
    """The command at the top of docs/calibration.md, key for key and value for value (the
    paths given as the CLI was given them, from the same folder: the repose record names the
    force-test file as given)."""
    expected = _cli_json(cli, tmp_path, "--observed", SPEEDS, "--forces", FORCES, "--free", "plate_scale,error_floor")
    monkeypatch.chdir(root)
    got = sandslope.calibrate(observed=SPEEDS, forces=FORCES, free=["plate_scale", "error_floor"])
    assert got["repose"]["source"] == f"carried over from --forces {FORCES}"
    assert got == expected
    assert got["mode"] == "joint"
    # The calibrated terrain and robot are ready for the other functions.
    terrain = sandslope.Terrain(**got["terrain"])
    assert terrain.name == "calibrated-forces"
    sandslope.Robot(**got["robot"])


def test_per_slope_and_a_comma_list(cli, root, tmp_path):
    """The per-slope law (another answer's shape), from Robot and Terrain objects, and `free`
    as the command line's comma list (here empty) are the CLI's."""
    expected = _cli_json(cli, tmp_path, "--observed", SPEEDS, "--law", "per-slope", "--name", "mine")
    got = sandslope.calibrate(
        sandslope.Robot.preset("paper-hexapod"),
        "glass-beads-300um",
        observed=str(root / SPEEDS),
        law="per-slope",
        name="mine",
        free="",
    )
    assert got == expected
    assert got["mode"] == "per-slope" and got["terrain"]["name"] == "mine"


@pytest.mark.parametrize(
    "flags, keywords, renames",
    [
        (["--repose", "95"], {"repose": 95}, [("--repose", "repose")]),
        (["--k-n", "0"], {"k_n": 0}, [("--k-n", "k_n")]),
        (["--error-floor", "-0.1"], {"error_floor": -0.1}, [("--error-floor", "error_floor")]),
        (["--free", "nope"], {"free": ["nope"]}, [("--free", "free")]),
        (
            ["--law", "per-slope", "--t1", "t1.csv"],
            {"law": "per-slope", "t1": "t1.csv"},
            [("--law per-slope", 'law="per-slope"'), ("--free", "free"), ("--t1", "t1"), ("--error-floor", "error_floor")],
        ),
    ],
)
def test_bad_values_raise_the_cli_message_in_python_words(cli, root, tmp_path, flags, keywords, renames):
    message = cli.error("calibrate", "--observed", SPEEDS, *flags, "--out", tmp_path / "never.toml")
    for flag, keyword in renames:
        message = message.replace(flag, keyword)
    with pytest.raises(ValueError) as e:
        sandslope.calibrate(observed=root / SPEEDS, **keywords)
    assert str(e.value) == message
    assert not (tmp_path / "never.toml").exists()


def test_bad_names_and_files():
    with pytest.raises(ValueError, match='law = "cubic" must be one of "linear", "coulomb", "per-slope"'):
        sandslope.calibrate(observed="x.csv", law="cubic")
    with pytest.raises(ValueError, match='model = "fem" must be one of "closed-form", "simulate"'):
        sandslope.calibrate(observed="x.csv", model="fem")
    with pytest.raises(ValueError, match="no-such-speeds.csv"):
        sandslope.calibrate(observed="no-such-speeds.csv")
