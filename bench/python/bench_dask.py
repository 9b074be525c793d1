#!/usr/bin/env python3
"""sandslope.dask.risk_raster on a large DEM: wall time and peak memory per worker.

Usage (inside an environment with `sandslope[dask]`, e.g. after bash scripts/test.sh:
`.venv/bin/python bench/python/bench_dask.py [--source npy|tiff|zarr|dask] [--n 8192] [--chunk 1024]
[--workers 2] [--dir DIR]`).

The DEM is a synthetic dune field on 0.5 m cells, n x n, and comes from one of:
- `npy`, `tiff`, `zarr` (a store): written first to a file in --dir (default: a temporary
  folder; 0.5 GiB at n = 8192) one strip of rows at a time; each task then reads its own tile
  and one-cell halo from the file (tiled, zlib-compressed GeoTIFF; zarr in chunk-sized chunks).
- `from-zarr`: the zarr file opened as a dask array, `da.from_zarr(path)` (read as its store).
- `dask` (a computed dask array): `da.fromfunction`, each chunk generated on the worker that needs
  it, so no process ever holds the whole map; the halos are cut from neighbouring chunks.
Each tile of the raster is
reduced where it is made to a few numbers (mean best-heading p_fail, share of cells with a
usable climb), as a pipeline that stores tiles would consume them, so the client holds no band
either. Runs on a `dask.distributed.LocalCluster` of worker
processes with one thread each (the library parallelises inside a task with rayon; set
RAYON_NUM_THREADS to change that). Peak memory per worker is the resident-set high-water mark
(VmHWM) of each worker process, including the Python interpreter and libraries; the
baseline of an idle worker is printed beside it.
"""

import argparse
import os
import resource
import tempfile
import time

import numpy as np


def dunes(i, j):
    """Heights (m) at rows i, columns j: dunes on an 8.5 degree ramp, 0.5 m cells."""
    x, y = 0.5 * j, 0.5 * i
    return 4.0 * np.sin(x / 25.0) * np.cos(y / 40.0) + 0.15 * x + 0.5 * np.sin(x / 3.1 + y / 4.3)


def tile_stats(bands):
    """Per tile: sum and count of the finite best-heading p_fail, cells with a usable climb."""
    p = bands[0]
    finite = np.isfinite(p)
    out = np.array([p[finite].sum(), finite.sum(), np.isfinite(bands[1]).sum()], dtype=np.float64)
    return out.reshape(3, 1, 1)


def write_store(kind, n, chunk, folder):
    """Writes the dune field to a .npy, GeoTIFF or .zarr file, a strip of rows at a time."""
    strip = max(chunk, 1)
    rows = lambda r0: np.mgrid[r0:min(r0 + strip, n), 0:n]  # noqa: E731
    if kind == "npy":
        path = os.path.join(folder, "dem.npy")
        out = np.lib.format.open_memmap(path, mode="w+", dtype=np.float64, shape=(n, n))
        for r0 in range(0, n, strip):
            out[r0:r0 + strip] = dunes(*rows(r0))
        out.flush()
        del out
    elif kind == "tiff":
        import tifffile

        path = os.path.join(folder, "dem.tif")
        source = np.load(write_store("npy", n, chunk, folder), mmap_mode="r")
        tifffile.imwrite(path, source, tile=(256, 256), compression="zlib", bigtiff=True)
    else:
        import zarr

        path = os.path.join(folder, "dem.zarr")
        out = zarr.open_array(path, mode="w", shape=(n, n), chunks=(chunk, chunk), dtype="f8")
        for r0 in range(0, n, strip):
            out[r0:r0 + strip] = dunes(*rows(r0))
    return path


def peak_rss_mib():
    """This process's resident-set high-water mark, MiB: VmHWM on Linux (its own, whereas
    ru_maxrss also keeps the peak of the process that started it), else ru_maxrss."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=8192)
    ap.add_argument("--chunk", type=int, default=1024)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--source", choices=["npy", "tiff", "zarr", "from-zarr", "dask"], default="npy")
    ap.add_argument("--eager", action="store_true",
                    help="also time the eager sandslope.risk_raster on the whole DEM in memory (the peer)")
    ap.add_argument("--dir", default=None, help="folder for the DEM file (default: a temporary one)")
    args = ap.parse_args()

    import dask.array as da
    from distributed import Client, LocalCluster

    import sandslope
    import sandslope.dask

    robot = sandslope.Robot.preset("paper-hexapod")
    terrain = sandslope.Terrain.preset("glass-beads-300um")
    n, c = args.n, args.chunk
    folder = args.dir or tempfile.mkdtemp(prefix="sandslope-bench-")
    if args.source == "dask":
        dem = da.fromfunction(dunes, shape=(n, n), chunks=c, dtype=np.float64)
    else:
        t0 = time.perf_counter()
        dem = write_store(args.source.replace("from-", ""), n, c, folder)
        if args.source == "from-zarr":
            dem = da.from_zarr(dem)
        print(f"wrote {dem} in {time.perf_counter() - t0:.1f} s")
    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None,
                      memory_limit=0) as cluster, Client(cluster) as client:
        idle = client.run(peak_rss_mib)
        raster = sandslope.dask.risk_raster(dem, 0.5, robot=robot, terrain=terrain, chunks=c)
        # Each tile is reduced where it is made (the two steps fuse into one task), as a
        # pipeline that stores tiles (to_zarr, store) would consume them.
        stats = raster.map_blocks(tile_stats, dtype=np.float64, chunks=((3,),) + tuple((1,) * len(c) for c in
                                                                                   raster.chunks[1:]))
        t0 = time.perf_counter()
        totals = client.compute(stats.sum(axis=(1, 2)), sync=True)
        wall = time.perf_counter() - t0
        mean_p, climbable = totals[0] / totals[1], totals[2] / (n * n)
        peaks = client.run(peak_rss_mib)
    chunk_mib = c * c * 8 / 2**20
    print(f"DEM {n} x {n} from {args.source} ({n * n * 8 / 2**30:.2f} GiB as float64), chunks {c} x {c} ({chunk_mib:.0f} MiB each), "
          f"{raster.npartitions} tiles, {args.workers} worker processes x 1 thread, {os.cpu_count()} cores")
    print(f"  wall time            {wall:8.1f} s  ({n * n / wall / 1e6:.2f} Mcells/s)")
    for w, peak in sorted(peaks.items()):
        print(f"  peak RSS {w.rsplit(':', 1)[-1]:>6}        {peak:8.0f} MiB  (idle {idle[w]:.0f} MiB; "
              f"{(peak - idle[w]) / chunk_mib:.1f} float64 chunks above idle)")
    print(f"  mean best-heading p_fail {mean_p:.3e}, cells with a usable climb {climbable:.1%}")
    if args.eager:
        # The peer: the whole map at once in this process (rayon on every core), same values.
        z = np.load(dem) if isinstance(dem, str) and dem.endswith(".npy") else np.asarray(dem)
        t0 = time.perf_counter()
        bands = sandslope.risk_raster(z, 0.5, robot=robot, terrain=terrain)
        eager = time.perf_counter() - t0
        p = bands[0][np.isfinite(bands[0])]
        print(f"  eager risk_raster    {eager:8.1f} s  in one process, peak RSS {peak_rss_mib():.0f} MiB; "
              f"Dask / eager wall = {wall / eager:.2f}; same mean p_fail: {abs(p.mean() - mean_p) <= 1e-6 * max(mean_p, 1e-30)}")


if __name__ == "__main__":
    main()
