#!/usr/bin/env python3
"""Make PNG plots of a CoReDEM run folder (timeseries.csv and the last particle snapshot).

Usage: plot_run.py RUN_DIR [--out DIR] [--interrupted]

Writes DIR (default RUN_DIR/plots) /timeseries.png (the panels the case computes: pressure
drop, bed height, particle temperature and heat only when heat is exchanged, kinetic energy,
time step, contacts, wall time; units on every axis) and /particles.png (side views of the
last output, coloured by temperature when it varies, else by speed). Needs Debian's python3-matplotlib, python3-h5py, python3-numpy;
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


# (title, y label with unit, [(column, label)], scale, kind) — a panel is drawn only when one of
# its columns is present and, for the heat panels, when the case computes heat (kind "heat":
# values beyond round-off, see computes_heat); an isothermal bed gets none of them.
PANELS = [
    ("Pressure drop (inlet - outlet)", "Δp [Pa]", [("gas.pressure_drop_Pa", "CFD")], 1.0, ""),
    ("Bed height", "H_bed [mm]", [("bed_height_m", "95th percentile of the centres + r")], 1e3,
     ""),
    ("Particle temperature", "T_p [K]",
     [("mean_T_p", "mean"), ("min_T_p", "min"), ("max_T_p", "max")], 1.0, "temperature"),
    ("Heat exchange", "Q [J]",
     [("dem.heat_from_gas_J", "gas -> particles (DEM)"),
      ("gas.heat_from_particles_J", "particles -> gas (CFD)")], 1.0, "heat"),
    ("Kinetic energy", "E_kin [J]", [("dem.kinetic_energy_J", "particles")], 1.0, ""),
    ("Time step", "Δt [s]", [("dt", "dt_CFD"), ("dt_dem", "dt_DEM")], 1.0, ""),
    ("Contacts", "contacts [-]", [("contacts", "particle-particle")], 1.0, ""),
    ("Wall time per step", "wall time [s]", [("wall_step_s", "step"), ("wall_dem_s", "DEM")], 1.0,
     ""),
]


def spread(ts, cols):
    vals = [ts[c][np.isfinite(ts[c])] for c in cols if c in ts]
    vals = [v for v in vals if v.size]
    if not vals:
        return 0.0
    allv = np.concatenate(vals)
    return float(allv.max() - allv.min())


def computes_heat(ts):
    """True when particle temperatures change (more than 1e-6 K over the run) or heat flows
    beyond round-off (more than 1e-9 of the particles' thermal energy, 1e-12 J without it)."""
    if spread(ts, ["mean_T_p", "min_T_p", "max_T_p"]) > 1e-6:
        return True
    scale = 1e-12
    if "dem.thermal_energy_J" in ts:
        scale = max(scale, 1e-9 * float(np.nanmax(np.abs(ts["dem.thermal_energy_J"]))))
    for c in ("dem.heat_from_gas_J", "gas.heat_from_particles_J", "dem.heat_radiation_J",
              "dem.heat_wall_J"):
        if c in ts and float(np.nanmax(np.abs(ts[c]))) > scale:
            return True
    return False


def panels_for(ts):
    heat = computes_heat(ts)
    out = []
    for title, ylabel, series, scale, kind in PANELS:
        if not any(c in ts for c, _ in series):
            continue
        if kind in ("temperature", "heat") and not heat:
            continue
        out.append((title, ylabel, series, scale))
    return out


def plot_timeseries(ts, out, note=""):
    panels = panels_for(ts)
    print("panels: " + ", ".join(p[0] for p in panels))
    if not panels:
        return None
    n = len(panels)
    ncol = 2
    nrow = (n + 1) // 2
    fig, axes = plt.subplots(nrow, ncol, figsize=(11, 3.2 * nrow), squeeze=False)
    t = ts["t"]
    for ax, (title, ylabel, series, scale) in zip(axes.flat, panels):
        for col, label in series:
            if col in ts:
                ax.plot(t, ts[col] * scale, label=label)
        ax.set_title(title)
        ax.set_xlabel("t [s]")
        ax.set_ylabel(ylabel)
        if title == "Time step":
            ax.set_yscale("log")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    if note:
        fig.suptitle(note, fontsize=9)
    fig.tight_layout()
    path = os.path.join(out, "timeseries.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def last_snapshot(run_dir):
    """(step, time, path) of the last output: outputs.csv (decimal times), else the older
    snapshots/index.csv (hex times)."""
    outputs = os.path.join(run_dir, "outputs.csv")
    if os.path.exists(outputs):
        with open(outputs, newline="") as f:
            rows = list(csv.DictReader(f))
        if rows:
            r = rows[-1]
            return int(r["step"]), float(r["time_s"]), os.path.join(run_dir, r["particles"])
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
        colour, colour_label = None, ""
        if "/particles/temperature" in f:
            temp = f["/particles/temperature"][()]
            if temp.size and float(temp.max() - temp.min()) > 1e-6:
                colour, colour_label = temp, "T_p [K]"
        if colour is None and "/particles/velocity" in f:
            colour = np.linalg.norm(f["/particles/velocity"][()], axis=1)
            colour_label = "|v_p| [m/s]"
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
        if colour_label.startswith("|v_p|"):
            vmin, vmax = float(colour.min()), max(float(colour.max()), float(colour.min()) + 1e-9)
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
        fig.colorbar(sc, ax=axes, label=colour_label, shrink=0.8)
    path_out = os.path.join(out, "particles.png")
    fig.savefig(path_out, dpi=110)
    plt.close(fig)
    return path_out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--out", help="output folder (default RUN_DIR/plots)")
    ap.add_argument("--interrupted", action="store_true",
                    help="the run stopped early (SIGINT/SIGTERM): say so in the title")
    a = ap.parse_args()
    ts_path = os.path.join(a.run_dir, "timeseries.csv")
    if not os.path.exists(ts_path):
        sys.exit(f"{ts_path} not found: give a run folder made by 'coredem run'")
    out = a.out or os.path.join(a.run_dir, "plots")
    os.makedirs(out, exist_ok=True)
    note = ""
    if a.interrupted:
        note = "run interrupted: plots up to its last step (continue with coredem resume)"
    made = [p for p in (plot_timeseries(read_timeseries(ts_path), out, note),
                        plot_particles(a.run_dir, out)) if p]
    for p in made:
        print(p)


if __name__ == "__main__":
    main()
