#!/usr/bin/env bash
# Mutation fuzz of every reader and every command that reads a file, of the Python
# package's readers (issue 21), and of `sandslope serve` (issue 39: `serve-requests`, mutated
# HTTP requests, and `serve-connections`, connection patterns, each under a load mix, with the
# latencies printed); docs/robustness.md.
#
#   scripts/fuzz.sh N [TARGET...]     N mutated inputs per target (default 1000)
#
# Reports, per target, panics, aborts, hangs (over 10 s) and peak memory, and exits 1 if any
# target had a panic, abort, hang or a peak above 1 GiB. Failing inputs are kept in fuzz-out/.
# Environment:
#   FUZZ_PROFILE=debug   use debug builds (what scripts/test.sh's short pass does; default release)
#   FUZZ_SEED=S          another sequence of inputs (default 1)
#   FUZZ_TIMEOUT=SECONDS one input running longer is a hang (default 10, for release builds)
#   SANDSLOPE_VENV=DIR   the venv with the Python package (default .venv); the Python targets
#                        are skipped, with a note, when it has no sandslope
#   FUZZ_PREBUILT=1      use the binaries already in target/ (scripts/test.sh builds them with
#                        its tests' features: this script's own build, of two packages alone,
#                        resolves other features and recompiles half the workspace)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-1000}
shift || true
profile=${FUZZ_PROFILE:-release}
seed=${FUZZ_SEED:-1}
timeout=${FUZZ_TIMEOUT:-10}
venv=${SANDSLOPE_VENV:-$PWD/.venv}
flag=--release
dir=release
if [ "$profile" = debug ]; then flag=; dir=debug; fi

if [ "${FUZZ_PREBUILT:-0}" != 1 ]; then
  cargo build $flag --locked -p sandslope-cli -p sandslope-fuzz
fi
bin=target/$dir
rust_targets=()
py_targets=()
for t in "$@"; do
  case $t in py-*) py_targets+=("$t") ;; *) rust_targets+=("$t") ;; esac
done

status=0
if [ $# -eq 0 ] || [ ${#rust_targets[@]} -gt 0 ]; then
  "$bin/sandslope-fuzz" --runs "$runs" --seed "$seed" --timeout "$timeout" --bin "$bin/sandslope" ${rust_targets[@]+"${rust_targets[@]}"} || status=1
fi
if [ $# -eq 0 ] || [ ${#py_targets[@]} -gt 0 ]; then
  if [ -x "$venv/bin/python" ] && "$venv/bin/python" -c "import sandslope" 2>/dev/null; then
    "$venv/bin/python" scripts/fuzz_python.py --runs "$runs" --seed "$seed" --timeout "$timeout" --fuzz-bin "$bin/sandslope-fuzz" \
      ${py_targets[@]+"${py_targets[@]}"} || status=1
  else
    echo "note: no sandslope Python package in $venv: the Python readers were not fuzzed (run scripts/test.sh first)"
  fi
fi
exit $status
