#!/usr/bin/env python3
"""Make PNG plots of a CoReDEM run folder (timeseries.csv and the last particle snapshot).

Usage: plot_run.py RUN_DIR [--out DIR]

Writes DIR (default RUN_DIR/plots) /timeseries.png (particle temperature, kinetic energy,
time step and sub-cycles, ledgers) and /particles.png (side views of the last snapshot,
coloured by temperature). Needs Debian's python3-matplotlib, python3-h5py, python3-numpy;
run it with the interpreter CMake found (COREDEM_PYTHON, /usr/bin/python3 on Debian).
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_timeseries(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if len(rows) < 2:
        raise SystemExit(f"{path}: no data rows yet")
    header = rows[0]
    cols = {h: [] for h in header}
    for r in rows[1:]:
        if len(r) != len(header):
            continue
        for h, v in zip(header, r):
            cols[h].append(float(v) if v != "" else np.nan)
    return {h: np.asarray(v) for h, v in cols.items()}


# (title, y label, [(column, label)]) — panels whose columns are absent are skipped.
PANELS = [
    ("Particle temperature", "T_p [K]",
     [("mean_T_p", "mean"), ("min_T_p", "min"), ("max_T_p", "max")]),
    ("Kinetic energy", "E_kin [J]", [("dem.kinetic_energy_J", "particles")]),
    ("Heat exchange", "Q [J]",
     [("dem.heat_from_gas_J", "gas -> particles (DEM)"),
      ("gas.heat_from_particles_J", "particles -> gas (CFD)")]),
    ("Time step", "dt [s]", [("dt", "dt_CFD"), ("dt_dem", "dt_DEM")]),
    ("Contacts", "count", [("contacts", "contacts")]),
    ("Wall time per step", "s", [("wall_step_s", "step"), ("wall_dem_s", "DEM")]),
]


def plot_timeseries(ts, out):
    panels = [p for p in PANELS if any(c in ts for c, _ in p[2])]
    if not panels:
        return None
    n = len(panels)
    ncol = 2
    nrow = (n + 1) // 2
    fig, axes = plt.subplots(nrow, ncol, figsize=(11, 3.2 * nrow), squeeze=False)
    t = ts["t"]
    for ax, (title, ylabel, series) in zip(axes.flat, panels):
        for col, label in series:
            if col in ts:
                ax.plot(t, ts[col], label=label)
        ax.set_title(title)
        ax.set_xlabel("t [s]")
        ax.set_ylabel(ylabel)
        if title == "Time step":
            ax.set_yscale("log")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.tight_layout()
    path = os.path.join(out, "timeseries.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def last_snapshot(run_dir):
    index = os.path.join(run_dir, "snapshots", "index.csv")
    if not os.path.exists(index):
        return None
    with open(index) as f:
        rows = [r for r in csv.reader(f)][1:]
    if not rows:
        return None
    step, time_hex, rel = rows[-1]
    return int(step), float.fromhex(time_hex), os.path.join(run_dir, rel)


def vertical_axis(run_dir):
    """Index of the axis gravity points along in the run's case.yaml (z when unknown)."""
    try:
        import yaml

        with open(os.path.join(run_dir, "case.yaml")) as f:
            g = (yaml.safe_load(f) or {}).get("gravity", [0.0, 0.0, -9.81])
        return int(np.argmax(np.abs(np.asarray(g, dtype=float))))
    except Exception:  # no case file or no PyYAML: the usual z-up convention
        return 2


def plot_particles(run_dir, out):
    snap = last_snapshot(run_dir)
    if snap is None:
        return None
    import h5py

    step, time, path = snap
    with h5py.File(path, "r") as f:
        pos = f["/particles/position"][()]
        colour = None
        for name in ("temperature", "T_p", "T"):
            if "/particles/" + name in f:
                colour = f["/particles/" + name][()]
                break
        radius = None
        for name in ("radius", "diameter"):
            if "/particles/" + name in f:
                radius = f["/particles/" + name][()] * (1.0 if name == "radius" else 0.5)
                break
    up = vertical_axis(run_dir)
    across = [i for i in range(3) if i != up]
    names = "xyz"
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    pad = 0.05 * (float(max(hi - lo)) or 1e-3)
    kw = {"s": 8}
    if colour is not None:
        vmin, vmax = float(colour.min()), float(colour.max())
        if vmax - vmin < 1e-9:
            vmin, vmax = vmin - 1.0, vmax + 1.0
        kw.update(c=colour, cmap="inferno", vmin=vmin, vmax=vmax)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True)
    for ax, i in zip(axes, across):
        sc = ax.scatter(pos[:, i], pos[:, up], **kw)
        ax.set_xlim(lo[i] - pad, hi[i] + pad)
        ax.set_ylim(lo[up] - pad, hi[up] + pad)
        ax.set_aspect("equal")
        ax.set_xlabel(f"{names[i]} [m]")
        ax.set_ylabel(f"{names[up]} [m]")
        ax.set_title(f"side view ({names[i]}-{names[up]}), step {step}, t = {time:.4g} s, "
                     f"{len(pos)} particles", fontsize=9)
    if colour is not None:
        fig.colorbar(sc, ax=axes, label="T_p [K]", shrink=0.8)
    path_out = os.path.join(out, "particles.png")
    fig.savefig(path_out, dpi=110)
    plt.close(fig)
    return path_out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--out", help="output folder (default RUN_DIR/plots)")
    a = ap.parse_args()
    ts_path = os.path.join(a.run_dir, "timeseries.csv")
    if not os.path.exists(ts_path):
        sys.exit(f"{ts_path} not found: give a run folder made by 'coredem run'")
    out = a.out or os.path.join(a.run_dir, "plots")
    os.makedirs(out, exist_ok=True)
    made = [p for p in (plot_timeseries(read_timeseries(ts_path), out),
                        plot_particles(a.run_dir, out)) if p]
    for p in made:
        print(p)


if __name__ == "__main__":
    main()
