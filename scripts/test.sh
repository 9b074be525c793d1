#!/usr/bin/env bash
# The project's one test command: every Rust test, then the Python package's tests.
#
# Needs the Rust toolchain and Python 3.9+ with pip (venv module). Creates .venv/ at the
# repository root (reused on later runs), installs maturin, pytest, numpy, dask, distributed,
# pandas, tifffile, zarr, xarray, dynamixel-sdk (the servo emulator's referee) and rasterio (whose wheels carry GDAL: the tests write every
# GeoTIFF layout with it) into it from PyPI, builds and installs crates/sandslope-py into it, and
# runs `cargo test --workspace --locked`, pytest and a short fuzz pass (the install and the
# fuzz pass's Rust half run beside the other stages, each one's output shown when it ends).
# Environment:
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
logs=$(mktemp -d)
# On any exit: the Rust fuzz pass (below) is stopped, and the Python tools' install is waited
# for (stopping pip midway would leave a broken venv for the next run).
tools=
fuzz=
on_exit() {
  [ -z "$fuzz" ] || kill "$fuzz" 2>/dev/null || true
  [ -z "$tools" ] || wait "$tools" 2>/dev/null || true
  rm -rf "$logs"
}
trap on_exit EXIT

py="$venv/bin/python"
# maturin's build backend runs the `maturin` program from PATH.
export PATH="$venv/bin:$PATH"
# The Python tools are downloaded and installed while cargo compiles: the install mostly waits
# on the network and the disk (30 s of CI's 616 s before it ran beside the tests, 2026-12-07).
# Its output is shown when it ends.
echo "== installing the Python test tools into $venv (beside cargo test; its output follows the tests)"
(
  start=$(seconds)
  if [ ! -x "$py" ]; then
    echo "== creating $venv"
    "$python" -m venv "$venv"
  fi
  "$py" -m pip install --quiet --disable-pip-version-check \
    "maturin>=1.9,<2" "pytest>=7" "numpy>=1.21" "dask[array]>=2023.1" "distributed>=2023.1" \
    "pandas>=1.5" "tifffile>=2023.1" "zarr>=2.13" "xarray>=2023.1" "rasterio>=1.3" \
    "rosbags>=0.10" "mcap>=1.2" "mcap-ros2-support>=0.5" "dynamixel-sdk>=4.1" "pytest-xdist>=3"
  echo $(($(seconds) - start)) >"$logs/tools.s"
) >"$logs/tools.log" 2>&1 &
tools=$!
t1=$(seconds)

echo "== cargo test --workspace --locked"
cargo test --workspace --locked
# The fuzzer's binary, on the features the tests just resolved (5 s: only sandslope-fuzz is
# compiled). scripts/fuzz.sh's own `cargo build -p sandslope-cli -p sandslope-fuzz` resolves
# the two packages' features alone and recompiled syn, nalgebra, the workspace's crates and the
# CLI: 43 s of CI's fuzz stage (2026-12-07), and a fuzzed CLI other than the tested one.
cargo build --workspace --locked --bins --tests
t2=$(seconds)

# The fuzz pass's Rust half (scripts/fuzz.sh with FUZZ_PREBUILT=1 and the Python targets left
# to the end, its two halves run apart; docs/robustness.md): 200 mutated inputs per reader,
# command and server target, one input at a time, so one core. It runs beside the extension's
# build and pytest, whose output comes first; its own is shown when it ends.
# Debug builds, already made above; any panic, abort, hang or peak over 1 GiB fails. Debug
# builds: the 10 s hang limit is for release builds, and a debug `report` takes about 8 times
# as long (2.3 s against 0.3 s on a mutated speeds table); on a machine shared with other
# builds one such run passed 10 s (a false hang). 60 s keeps a real hang (which never ends) caught.
fuzz_runs=200
fuzz_seed=${FUZZ_SEED:-1}
echo "== fuzz, short pass, Rust targets: $fuzz_runs mutated inputs per reader, command and server target (beside the next stages)"
(
  start=$(seconds)
  target/debug/sandslope-fuzz --runs "$fuzz_runs" --seed "$fuzz_seed" --timeout 60 --bin target/debug/sandslope &
  child=$!
  trap 'kill "$child" 2>/dev/null' TERM
  status=0
  wait "$child" || status=$?
  echo $(($(seconds) - start)) >"$logs/fuzz.s"
  exit $status
) >"$logs/fuzz.log" 2>&1 &
fuzz=$!

if ! wait "$tools"; then
  tools=
  cat "$logs/tools.log"
  echo "error: installing the Python test tools into $venv failed (above)" >&2
  exit 1
fi
tools=
cat "$logs/tools.log"

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

echo "== fuzz, short pass, Python readers: the same $fuzz_runs inputs per reader through the package"
"$py" scripts/fuzz_python.py --runs "$fuzz_runs" \
  --seed "$fuzz_seed" --timeout 60 --fuzz-bin target/debug/sandslope-fuzz
echo "== fuzz, short pass, Rust targets (started after cargo test):"
fuzz_status=0
wait "$fuzz" || fuzz_status=$?
fuzz=
cat "$logs/fuzz.log"
[ "$fuzz_status" -eq 0 ] || { echo "error: the Rust fuzz pass failed (above)" >&2; exit 1; }
t5=$(seconds)

echo "== disk: target/ $(du -sh target 2>/dev/null | cut -f1), $venv $(du -sh "$venv" 2>/dev/null | cut -f1)"
echo "== times: python tools $(cat "$logs/tools.s") s (beside cargo test), cargo test $((t2 - t1)) s, extension build $((t3 - t2)) s, pytest $((t4 - t3)) s, fuzz $((t5 - t4)) s after pytest (its Rust targets $(cat "$logs/fuzz.s") s, beside the extension and pytest), total $((t5 - t0)) s"
