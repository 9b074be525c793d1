"""sandslope.report(...) is report.json: the same value, key for key, as the CLI writes."""

import json

import pytest

import sandslope


def _cli_report(cli, tmp_path, *args):
    out = tmp_path / "rep"
    cli.run("report", "--out", out, *args)
    return json.loads((out / "report.json").read_text())


def test_default_report_equals_report_json(cli, tmp_path):
    assert sandslope.report() == _cli_report(cli, tmp_path)


def test_report_on_own_tracks_equals_report_json(cli, tmp_path, root):
    # The README's --tracks example, run from the repository root with repository paths.
    d = "examples/tracking"
    tracks = {0: f"{d}/level-plain.csv", 10: f"{d}/slope10-motive123.csv", 20: [f"{d}/slope20-motive125.csv", f"{d}/slope20-vicon.csv"]}
    args = [f"--tracks=0={d}/level-plain.csv", f"--tracks=10={d}/slope10-motive123.csv"]
    args += [f"--tracks=20={d}/slope20-motive125.csv", f"--tracks=20={d}/slope20-vicon.csv", "--tracks-body", "robot"]
    expected = _cli_report(cli, tmp_path, *args)
    assert sandslope.report(tracks=tracks, tracks_body="robot") == expected


def test_report_errors_name_the_python_argument():
    with pytest.raises(ValueError, match="max_risk"):
        sandslope.report(max_risk=1.5)
