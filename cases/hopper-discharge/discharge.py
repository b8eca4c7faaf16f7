#!/usr/bin/python3
"""Discharge rate of a hopper-discharge run from its particle snapshots, against Beverloo.

Usage: cases/hopper-discharge/discharge.py RUN_DIR [--outlet 0.008] [--d 0.001]
Prints the discharged mass against time (particles whose centre is below the outlet plane
z = 0 by more than one diameter), the rate fitted over 20-80 % discharged and Beverloo's
W = C rho_b sqrt(g) (D_o - k d)^2.5 with C = 0.58, k = 1.5 (band C 0.55-0.65, k 1.3-2.9;
rho_b = 0.6 rho_p, a random loose packing: the run does not measure it), and writes
RUN_DIR/plots/discharge.png when matplotlib is there.
"""
import argparse
import glob
import math
import os

import h5py
import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run")
    ap.add_argument("--outlet", type=float, default=0.008, help="outlet diameter (m)")
    ap.add_argument("--d", type=float, default=0.001, help="particle diameter (m)")
    ap.add_argument("--rho", type=float, default=2500.0, help="particle density (kg/m3)")
    a = ap.parse_args()
    files = sorted(glob.glob(os.path.join(a.run, "snapshots", "particles_*.h5")))
    if not files:
        raise SystemExit(f"{a.run}: no snapshots/particles_*.h5 (run the case first)")
    t, m, total = [], [], None
    for f in files:
        with h5py.File(f, "r") as h:
            z = h["/particles/position"][:, 2]
            mass = h["/particles/mass"][:]
            time = float(h["/meta"].attrs["time"])
        total = mass.sum() if total is None else total
        t.append(time)
        m.append(mass[z < -a.d].sum())
    t, m = np.array(t), np.array(m)
    sel = (m >= 0.2 * total) & (m <= 0.8 * total)
    if sel.sum() < 3:
        raise SystemExit("fewer than 3 snapshots between 20 % and 80 % discharged: run longer")
    w = np.polyfit(t[sel], m[sel], 1)[0]
    rho_b, g = 0.6 * a.rho, 9.81
    bev = lambda c, k: c * rho_b * math.sqrt(g) * (a.outlet - k * a.d) ** 2.5
    print(f"discharged {m[-1] / total:.1%} of {total * 1e3:.3f} g by t = {t[-1]:.3f} s")
    print(f"rate (20-80 %): {w * 1e3:.3f} g/s;  Beverloo (C 0.58, k 1.5): {bev(0.58, 1.5) * 1e3:.3f} g/s"
          f", band {bev(0.55, 2.9) * 1e3:.3f}-{bev(0.65, 1.3) * 1e3:.3f} g/s")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    os.makedirs(os.path.join(a.run, "plots"), exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(t, m * 1e3, "o-", ms=3, label="discharged (DEM)")
    t0 = t[sel][0]
    ax.plot(t[sel], (m[sel][0] + bev(0.58, 1.5) * (t[sel] - t0)) * 1e3, "--",
            label="Beverloo slope (C 0.58, k 1.5)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("discharged mass (g)")
    ax.legend()
    fig.tight_layout()
    out = os.path.join(a.run, "plots", "discharge.png")
    fig.savefig(out, dpi=120)
    print(f"plot: {out}")


if __name__ == "__main__":
    main()
