#!/usr/bin/env bash
# The project's one test command: every Rust test, then the Python package's tests.
#
# Needs the Rust toolchain and Python 3.9+ with pip (venv module). Creates .venv/ at the
# repository root (reused on later runs), installs maturin, pytest, numpy, dask, distributed,
# pandas, tifffile, zarr, xarray, dynamixel-sdk (the servo emulator's referee) and rasterio (whose wheels carry GDAL: the tests write every
# GeoTIFF layout with it) into it from PyPI, builds and installs crates/sandslope-py into it, and
# runs `cargo test --workspace --locked` and pytest. Environment:
#   PYTHON=python3.11   interpreter that creates the venv (default: python3)
#   SANDSLOPE_VENV=DIR  where the venv lives (default: .venv)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
venv=${SANDSLOPE_VENV:-$root/.venv}
python=${PYTHON:-python3}

# A one-shot build: Cargo's incremental caches (GBs of target/debug/incremental, reused only by
# the next edit-and-rebuild) are not written unless the caller asks for them
# (CARGO_INCREMENTAL=1 bash scripts/test.sh). docs/building.md states the disk this leaves.
export CARGO_INCREMENTAL=${CARGO_INCREMENTAL:-0}

seconds() { date +%s; }
t0=$(seconds)

if [ ! -x "$venv/bin/python" ]; then
  echo "== creating $venv"
  "$python" -m venv "$venv"
fi
py="$venv/bin/python"
# maturin's build backend runs the `maturin` program from PATH.
export PATH="$venv/bin:$PATH"
echo "== installing the Python test tools into $venv"
"$py" -m pip install --quiet --disable-pip-version-check \
  "maturin>=1.9,<2" "pytest>=7" "numpy>=1.21" "dask[array]>=2023.1" "distributed>=2023.1" \
  "pandas>=1.5" "tifffile>=2023.1" "zarr>=2.13" "xarray>=2023.1" "rasterio>=1.3" \
  "rosbags>=0.10" "mcap>=1.2" "mcap-ros2-support>=0.5" "dynamixel-sdk>=4.1" "pytest-xdist>=3"
t1=$(seconds)

echo "== cargo test --workspace --locked"
cargo test --workspace --locked
# The fuzzer's binary, on the features the tests just resolved (5 s: only sandslope-fuzz is
# compiled). scripts/fuzz.sh's own `cargo build -p sandslope-cli -p sandslope-fuzz` resolves
# the two packages' features alone and recompiled syn, nalgebra, the workspace's crates and the
# CLI: 43 s of CI's fuzz stage (2026-12-07), and a fuzzed CLI other than the tested one.
cargo build --workspace --locked --bins --tests
t2=$(seconds)

# Built in place (pip builds local directories in-tree), so Cargo uses the workspace's
# target/ and its lock file. The tests build it in Cargo's dev profile, on the dependencies
# `cargo test` just compiled (the library itself is opt-level 2 in dev, Cargo.toml): 79 s of
# CPU against a full optimised rebuild of every dependency in the shipped profile
# ([profile.python-ext], what `pip install ./crates/sandslope-py` uses), which took 154 s wall
# of CI's 837 s; pytest's 112 tests took 63 s of CPU on it (measured 2026-12-07, load ~12).
# SANDSLOPE_PY_PROFILE=python-ext tests the shipped profile instead.
profile=${SANDSLOPE_PY_PROFILE:-dev}
echo "== building and installing crates/sandslope-py: Cargo compiles the extension (profile $profile);"
echo "   pip says when the wheel is built"
MATURIN_PEP517_ARGS="--profile $profile" "$py" -m pip install --disable-pip-version-check \
  --no-build-isolation --no-deps --force-reinstall ./crates/sandslope-py
t3=$(seconds)

echo "== pytest crates/sandslope-py/tests"
# The CLI built by `cargo test` above: the Python results are compared with it. Two workers
# (pytest-xdist, one per core; PYTEST_WORKERS to change): the 130 tests took 87 s on CI's clean
# clone in one process, 52 s in two (2026-12-07), most of them waiting on one walk or one CLI.
SANDSLOPE_CLI="$root/target/debug/sandslope" "$py" -m pytest crates/sandslope-py/tests -q -p no:cacheprovider \
  -n "${PYTEST_WORKERS:-2}"
t4=$(seconds)

echo "== fuzz, short pass: 200 mutated inputs per reader, command and server target (scripts/fuzz.sh; docs/robustness.md)"
# Debug builds, already made by cargo test above; any panic, abort, hang or peak over 1 GiB fails.
# Debug builds: the 10 s hang limit is for release builds, and a debug `report` takes about 8
# times as long (2.3 s against 0.3 s on a mutated speeds table); on a machine shared with other
# builds one such run passed 10 s (a false hang). 60 s keeps a real hang (which never ends) caught.
FUZZ_PREBUILT=1 FUZZ_PROFILE=debug FUZZ_TIMEOUT=60 SANDSLOPE_VENV="$venv" bash scripts/fuzz.sh 200
t5=$(seconds)

echo "== disk: target/ $(du -sh target 2>/dev/null | cut -f1), $venv $(du -sh "$venv" 2>/dev/null | cut -f1)"
echo "== times: python tools $((t1 - t0)) s, cargo test $((t2 - t1)) s, extension build $((t3 - t2)) s, pytest $((t4 - t3)) s, fuzz $((t5 - t4)) s, total $((t5 - t0)) s"
