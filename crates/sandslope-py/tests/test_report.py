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


def test_report_html_is_the_clis_page(cli, tmp_path):
    # The page Python writes is the CLI's, byte for byte, for the same (default) inputs.
    value = sandslope.report(html=tmp_path / "py")
    cli.run("report", "--out", tmp_path / "cli")
    page = (tmp_path / "py" / "index.html").read_bytes()
    assert page == (tmp_path / "cli" / "index.html").read_bytes()
    assert (tmp_path / "py" / "report.json").read_bytes() == (tmp_path / "cli" / "report.json").read_bytes()
    assert json.loads((tmp_path / "py" / "report.json").read_text()) == value
    # Its sections, in the order a reader meets them: the plain answer before the evidence.
    text = page.decode()
    ids = ["answer", "numbers", "simulator-table", "figures"]
    at = [text.find(f'id="{i}"') for i in ids]
    assert all(a >= 0 for a in at), dict(zip(ids, at))
    assert at == sorted(at), dict(zip(ids, at))
    # Self-contained: figures inline, no scripts, no network.
    assert text.count("<svg") == text.count("<figure ") >= 5
    assert "<script" not in text and "http://" not in text.replace("http://www.w3.org", "")


def test_report_html_refuses_a_file(tmp_path):
    f = tmp_path / "page.html"
    f.write_text("mine")
    with pytest.raises(ValueError, match="html"):
        sandslope.report(html=f)
    assert f.read_text() == "mine"
