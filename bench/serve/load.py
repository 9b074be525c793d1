#!/usr/bin/env python3
"""Load test of `sandslope serve` on loopback: N requests at once (one thread each, released
together), every one checked answered with 200, latencies reported (p50, p99, max).

Bounded: one round of N requests (default 200) to 127.0.0.1 only, then the server is stopped.

    cargo build --release -p sandslope-cli
    python3 bench/serve/load.py [--requests 200] [--rounds 3] [--mix basic|all] [--bin target/release/sandslope]
"""
import argparse
import http.client
import subprocess
import threading
import time


def paths(n, mix="basic"):
    """The requests of one round: `basic` predict, sweep and phase; `all` also risk curves and
    4 s simulator walks (one in six each)."""
    out = []
    for i in range(n):
        if mix == "all" and i % 6 == 4:
            out.append(f"/api/risk?slope=0:24:25&mass={0.3 + (i % 5) * 0.1:.1f}")
            continue
        if mix == "all" and i % 6 == 5:
            out.append(f"/api/simulate?slope={i % 20}&duration=4")
            continue
        k = i % 4
        if k in (0, 1):
            out.append(f"/api/predict?slope={i % 35}&mass={0.2 + (i % 7) * 0.1:.1f}")
        elif k == 2:
            out.append(f"/api/sweep?from=0&to=30&step=0.5&mass={0.3 + (i % 5) * 0.1:.1f}")
        else:
            out.append(f"/api/phase?slope={i % 25}&k-n=1e4:1e7:100&k-s=1e3:1e8:100")
    return out


def one_round(port, n, mix):
    gate = threading.Barrier(n)
    results = [None] * n

    def worker(i, path):
        gate.wait()
        t = time.perf_counter()
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
        c.request("GET", path)
        r = c.getresponse()
        body = r.read()
        results[i] = (r.status, len(body), time.perf_counter() - t)
        c.close()

    threads = [threading.Thread(target=worker, args=(i, p)) for i, p in enumerate(paths(n, mix))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return results


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="target/release/sandslope")
    ap.add_argument("--requests", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--mix", choices=["basic", "all"], default="basic")
    a = ap.parse_args()
    server = subprocess.Popen([a.bin, "serve", "--port", "0"], stdout=subprocess.PIPE, text=True)
    try:
        line = server.stdout.readline().strip()
        port = int(line.rsplit(":", 1)[1].rstrip("/"))
        for k in range(a.rounds):
            res = one_round(port, a.requests, a.mix)
            lost = [r for r in res if r is None or r[0] != 200]
            lat = sorted(r[2] * 1e3 for r in res if r)
            q = lambda p: lat[round((len(lat) - 1) * p)]
            print(f"round {k + 1}: {a.requests} requests, {a.requests - len(lost)} answered 200, "
                  f"p50 {q(0.5):.1f} ms, p99 {q(0.99):.1f} ms, max {lat[-1]:.1f} ms")
    finally:
        server.terminate()
        server.wait()


if __name__ == "__main__":
    main()
