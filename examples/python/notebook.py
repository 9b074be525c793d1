"""sandslope from Python, notebook style: run it top to bottom, or cell by cell (`# %%` marks
cells for Jupyter, VS Code and Spyder).

    pip install "crates/sandslope-py[dask]" matplotlib
    python examples/python/notebook.py [--out DIR]

1. predict over an array of slopes (speed, regime, anchoring time);
2. a phase map over (k_n, k_s) drawn with matplotlib (skipped, with a note, without it);
3. a risk raster of a synthetic dune field computed tile by tile with Dask, checked against
   the eager raster.
"""

# %%
import argparse
import os
import time

import numpy as np

import sandslope

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--out", default=".", help="folder for the figures (default: current folder)")
args, _ = ap.parse_known_args()
os.makedirs(args.out, exist_ok=True)

robot = sandslope.Robot.preset("paper-hexapod")
terrain = sandslope.Terrain.preset("glass-beads-300um")
print(robot)
print(terrain)

# %% 1. The model over a slope array: one call, NumPy in and out.
slopes = np.arange(0.0, 31.0, 2.0)
p = sandslope.predict(robot, slopes, terrain=terrain)
print(f"\n{'slope':>5} {'speed cm/s':>10} {'t1 ms':>6}  regime")
for s, v, t1, code in zip(slopes, p["speed_m_s"], p["t1_s"], p["regime"]):
    print(f"{s:5.0f} {v * 100:10.2f} {t1 * 1e3:6.1f}  {sandslope.REGIMES[code]}")

# Broadcasting: a payload sweep at three slopes, shape (3, 5).
heavy = sandslope.predict(robot, [[10.0], [15.0], [20.0]], terrain=terrain, mass_kg=np.linspace(0.35, 1.5, 5))
print("\nspeed (cm/s) at 10, 15, 20 deg for masses 0.35 to 1.5 kg:\n", np.round(heavy["speed_m_s"] * 100, 2))

# %% 2. Phase map at 20 degrees: which terrains the robot can climb.
k_n = np.geomspace(7e3, 7e7, 400)
k_s = np.geomspace(2e3, 2e8, 400)
t0 = time.perf_counter()
m = sandslope.phase(robot, 20, k_n, k_s, terrain=terrain)
print(f"\nphase map 400 x 400 in {(time.perf_counter() - t0) * 1e3:.1f} ms: {m['counts']}")
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import BoundaryNorm, ListedColormap
except ImportError:
    plt = None
    print("matplotlib is not installed: the phase-map figure is skipped (pip install matplotlib)")
if plt is not None:
    # The CLI's regime palette (crates/sandslope-render/src/figures/palette.rs).
    colours = ListedColormap(["#426ec9", "#d63830", "#f7d643", "#a8e296"])
    fig, ax = plt.subplots(figsize=(6, 5), dpi=120)
    mesh = ax.pcolormesh(m["k_n"], m["k_s"], m["regime"].T, cmap=colours,
                         norm=BoundaryNorm([-0.5, 0.5, 1.5, 2.5, 3.5], 4), shading="auto")
    # The success boundary s = s_min (the paper's black line).
    ax.contour(m["k_n"], m["k_s"], m["step_m"].T, levels=[robot.min_step_m], colors="k", linewidths=1)
    at = terrain.at(20)
    ax.plot(at["k_n"], at["k_s"], marker="*", color="w", markeredgecolor="k", markersize=14)
    ax.set(xscale="log", yscale="log", xlabel="k_n (N/m³)", ylabel="k_s (N/m³)",
           title="Regimes at 20°, paper hexapod (★ glass beads)")
    bar = fig.colorbar(mesh, ax=ax, ticks=[0, 1, 2, 3])
    bar.ax.set_yticklabels(sandslope.REGIMES)
    fig.tight_layout()
    path = os.path.join(args.out, "phase-map.png")
    fig.savefig(path)
    print(f"wrote {path}")

# %% 3. A risk raster, eagerly and tile by tile with Dask.
rows, cols, cell = 400, 300, 0.5
y, x = np.mgrid[0:rows, 0:cols] * cell
dem = 12.0 * np.sin(x / 15.0) * np.cos(y / 40.0) + 0.2 * x  # steep dunes on an 11 degree ramp (m)
eager = sandslope.risk_raster(dem, cell, robot=robot, terrain=terrain)
print(f"\nrisk raster {rows} x {cols}: best-heading p_fail >= 0.05 on {(eager[0] >= 0.05).mean():.1%} of cells "
      f"(up to {np.nanmax(eager[0]):.3f}), {np.isnan(eager[1]).mean():.1%} without a usable climb")
try:
    import dask.array as da

    import sandslope.dask
except ImportError:
    da = None
    print("dask is not installed: the Dask raster is skipped (pip install 'crates/sandslope-py[dask]')")
if da is not None:
    lazy = sandslope.dask.risk_raster(da.from_array(dem, chunks=(256, 192)), cell, robot=robot, terrain=terrain)
    print(f"lazy raster {lazy.shape}, {lazy.npartitions} tasks of chunks {lazy.chunksize}")
    tiled = lazy.compute()  # threads here; a dask.distributed Client runs it on a cluster
    assert np.array_equal(tiled, eager, equal_nan=True), "tiles differ from the eager raster"
    print("Dask raster equals the eager one, seams and border included")
    # A DEM larger than memory lives in a file: give its path (.npy, GeoTIFF, .zarr) and each
    # task reads only its tile and one-cell halo, so a worker holds a few tiles at most.
    import os
    import tempfile

    path = os.path.join(tempfile.mkdtemp(), "dem.npy")
    np.save(path, dem)
    from_file = sandslope.dask.risk_raster(path, cell, robot=robot, terrain=terrain, chunks=(256, 192))
    assert np.array_equal(from_file.compute(), eager, equal_nan=True), "tiles read from file differ"
    print(f"the same raster read tile by tile from {os.path.basename(path)}")
