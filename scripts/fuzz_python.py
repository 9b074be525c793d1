"""Mutation fuzz of the Python package's readers (issue 21), with the inputs of the Rust fuzzer.

    python scripts/fuzz_python.py --runs N --fuzz-bin target/release/sandslope-fuzz [TARGET...]

For each target, `sandslope-fuzz --emit` writes N mutated inputs (the same ones, by index, as the
Rust reader targets), and a child interpreter calls the Python reader on each, in chunks, under a
4 GiB address-space limit. An exception other than the documented ones (ValueError, OSError,
TypeError, KeyError) is a defect, as is a child killed by a signal (an abort: the interpreter
died), or one input running longer than the timeout (a hang). Exit code 1 if any target had one.
"""

import argparse
import os
import resource
import selectors
import shutil
import subprocess
import sys
import tempfile
import time

# target -> (the Rust fuzzer's target whose inputs are used, the call)
TARGETS = {
    "py-read-raster": ("read-raster", "sandslope.read_raster(path)"),
    "py-robot": ("read-robot", "sandslope.Robot.from_toml(path)"),
    "py-terrain": ("read-terrain", "sandslope.Terrain.from_toml(path)"),
    "py-track": ("read-mocap", "sandslope.track([path], slope_deg=20.0)"),
    "py-fit": ("read-manifest", "sandslope.fit(path, counts_per_newton=2000.0)"),
    # Each speed inverted alone (the cheapest fit): the reader and the inversion on mutated speeds.
    "py-calibrate": ("read-speeds", "sandslope.calibrate(observed=path, law='per-slope')"),
}
EXPECTED = (ValueError, OSError, TypeError, KeyError)
CHUNK = 200


def child(target, files):
    import sandslope  # noqa: F401  (used by the eval'd call)

    call = compile(TARGETS[target][1], "<call>", "eval")
    for i, path in files:
        print(f"START {i}", flush=True)
        try:
            eval(call, {"sandslope": sandslope, "path": path})
        except EXPECTED:
            pass
        except BaseException as e:  # pyo3's PanicException derives from BaseException
            print(f"DEFECT {i} {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}", flush=True)
    print("END", flush=True)


def limit_memory():
    cap = 4 << 30
    resource.setrlimit(resource.RLIMIT_AS, (cap, cap))


def run_chunk(target, files, timeout):
    """Runs `files` in a child; returns (defect lines, aborted index or None, hung index or None)."""
    args = [sys.executable, __file__, "--child", target] + [f"{i}={p}" for i, p in files]
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                            preexec_fn=limit_memory)
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    defects, current, last = [], None, time.monotonic()
    while True:
        if not sel.select(timeout=0.5):
            if time.monotonic() - last > timeout:
                proc.kill()
                proc.wait()
                return defects, None, current
            continue
        line = proc.stdout.readline()
        if not line:
            break
        last = time.monotonic()
        if line.startswith("START"):
            current = int(line.split()[1])
        elif line.startswith("DEFECT"):
            defects.append(line.strip())
        elif line.startswith("END"):
            current = None
    code = proc.wait()
    if code != 0 and current is None and not defects:
        # Died before its first input: the package itself cannot be imported.
        raise SystemExit(f"the fuzz child exited with {code} before its first input (is sandslope installed?)")
    return defects, (current if code != 0 else None), None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=10.0)
    ap.add_argument("--fuzz-bin")
    ap.add_argument("targets", nargs="*")
    ap.add_argument("--child", nargs="+", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        target, *items = a.child
        child(target, [(int(s.split("=", 1)[0]), s.split("=", 1)[1]) for s in items])
        return 0
    if not a.fuzz_bin:
        ap.error("--fuzz-bin (the sandslope-fuzz binary, which writes the inputs) is required")
    names = a.targets or list(TARGETS)
    failed = False
    print(f"{'target':<17} {'runs':>8} {'defects':>8} {'aborts':>7} {'hangs':>6} {'peak MiB':>9} {'seconds':>8}")
    for name in names:
        if name not in TARGETS:
            print(f"no target {name}; targets: {' '.join(TARGETS)}", file=sys.stderr)
            return 2
        rust_target = TARGETS[name][0]
        start = time.monotonic()
        defects, aborts, hangs = [], [], []
        with tempfile.TemporaryDirectory() as d:
            subprocess.run([a.fuzz_bin, "--emit", rust_target, "--seed", str(a.seed), "--from", "0", "--to",
                            str(a.runs), "--dir", d], check=True)
            files = sorted(((int(f.split("-", 1)[0]), os.path.join(d, f)) for f in os.listdir(d)))
            if rust_target == "read-manifest":
                # The trial files the example manifest names, beside each mutated manifest.
                src = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "measurements")
                for f in os.listdir(src):
                    if f.endswith(".csv"):
                        shutil.copy(os.path.join(src, f), d)
            pending = files
            while pending:
                chunk, pending = pending[:CHUNK], pending[CHUNK:]
                found, aborted, hung = run_chunk(name, chunk, a.timeout)
                defects += found
                stuck = aborted if aborted is not None else hung
                if stuck is not None:
                    (aborts if aborted is not None else hangs).append(f"input {stuck} ({rust_target}, seed {a.seed})")
                    pending = [f for f in chunk if f[0] > stuck] + pending
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
        bad = bool(defects or aborts or hangs)
        failed |= bad
        print(f"{name:<17} {a.runs:>8} {len(defects):>8} {len(aborts):>7} {len(hangs):>6} {peak:>9.1f} "
              f"{time.monotonic() - start:>8.1f}")
        for line in (defects + aborts + hangs)[:10]:
            print(f"    {line}")
        sys.stdout.flush()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
