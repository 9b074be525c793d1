"""Shared fixtures: the `sandslope` CLI the Python results are compared with, and the
built-in robot and terrain."""

import json
import os
import subprocess
from pathlib import Path

import pytest

import sandslope

ROOT = Path(__file__).resolve().parents[3]


def _cli_path() -> Path:
    given = os.environ.get("SANDSLOPE_CLI")
    if given:
        return Path(given)
    # Not run by scripts/test.sh: build the CLI (debug) once.
    subprocess.run(["cargo", "build", "--quiet", "-p", "sandslope-cli"], cwd=ROOT, check=True)
    return ROOT / "target" / "debug" / "sandslope"


class Cli:
    """Runs the `sandslope` binary."""

    def __init__(self, path: Path):
        self.path = path

    def run(self, *args, check=True):
        p = subprocess.run([str(self.path), *map(str, args)], capture_output=True, text=True, cwd=ROOT)
        if check and p.returncode != 0:
            raise AssertionError(f"sandslope {' '.join(map(str, args))} failed: {p.stderr}")
        return p

    def json(self, *args):
        return json.loads(self.run(*args, "--json").stdout)

    def error(self, *args):
        """The message the CLI prints for bad input (exit code 2), without `error: `."""
        p = self.run(*args, check=False)
        assert p.returncode == 2, p
        assert p.stderr.startswith("error: "), p.stderr
        return p.stderr[len("error: "):].rstrip("\n")


@pytest.fixture(scope="session")
def cli():
    path = _cli_path()
    assert path.exists(), f"no sandslope binary at {path}"
    return Cli(path)


@pytest.fixture(scope="session")
def robot():
    return sandslope.Robot.preset("paper-hexapod")


@pytest.fixture(scope="session")
def terrain():
    return sandslope.Terrain.preset("glass-beads-300um")


@pytest.fixture(scope="session")
def root():
    return ROOT
