"""examples/python/notebook.py runs from start to end (matplotlib optional) and checks itself."""

import subprocess
import sys


def test_notebook_runs(root, tmp_path):
    p = subprocess.run([sys.executable, str(root / "examples" / "python" / "notebook.py"), "--out", str(tmp_path)],
                       capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert p.returncode == 0, p.stderr
    assert "Dask raster equals the eager one" in p.stdout
    # Level sand is success and 30 degrees (beyond the angle of repose) slips.
    lines = p.stdout.splitlines()
    assert any(line.split()[:1] == ["0"] and line.endswith("success") for line in lines)
    assert any(line.split()[:1] == ["30"] and line.endswith("slippage") for line in lines)
