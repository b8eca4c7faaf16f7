#!/usr/bin/env python3
"""CLG gasifier plots (docs/validation.md, docs/physics.md §9.2): outlet gas and solid conversion.

Usage: validation_clg.py RUN_DIR [--out DIR] [--summary FILE]

Reads RUN_DIR/timeseries.csv (coredemFoam's gas.outflow.<species>_kg_per_s: species leaving
through the boundary, kg/s), RUN_DIR/case.yaml (species molar masses, solid_species order) and
the particle snapshots (RUN_DIR/snapshots/index.csv; per-particle mass and solid mass fractions)
and writes to DIR (default RUN_DIR/plots):
  clg_outlet.png      dry, N2-free mole fractions of CO, CO2 and H2 in the outlet gas vs time
                      (x_k = ṅ_k / (ṅ_CO + ṅ_CO2 + ṅ_H2), ṅ_k = ṁ_k / M_k; shown once that sum
                      exceeds 1e-6 of the N2 flow), and the outlet
                      molar flows of CO, CO2, H2 (dry) vs time
  clg_conversion.png  carbon conversion X_C = 1 − m_C(t)/m_C(0) and carrier conversion
                      ξ = 1 − m_Fe2O3 / m_Fe2O3,eq (docs/physics.md §6.3, m_eq = m_Fe2O3 + (3 M_Fe2O3 /
                      (2 M_Fe3O4)) m_Fe3O4) summed over all particles, vs time
--summary writes a Markdown table (end values). Interpreter: COREDEM_PYTHON (numpy,
matplotlib, h5py, yaml).
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from plot_run import read_timeseries  # noqa: E402  (same folder)
import yaml  # noqa: E402

DRY = ["CO", "CO2", "H2"]


def conversion_from_snapshots(run_dir, solid):
    """(t, X_C, xi) from every snapshot; None when there are no snapshots or species."""
    import h5py

    index = os.path.join(run_dir, "snapshots", "index.csv")
    if not os.path.exists(index) or not solid:
        return None
    names = [s["name"] for s in solid]
    molar = {s["name"]: float(s["molar_mass"]) for s in solid}
    out_t, out_xc, out_xi = [], [], []
    with open(index, newline="") as f:
        rows = list(csv.DictReader(f))
    c0 = None
    for r in rows:
        t = float.fromhex(r["time_hex"])
        with h5py.File(os.path.join(run_dir, r["file"]), "r") as h:
            m = h["/particles/mass"][()]
            y = h["/particles/species"][()]
        if y.ndim != 2 or y.shape[1] != len(names):
            raise SystemExit(f"{r['file']}: {y.shape} species columns, solid_species lists {len(names)}")
        tot = {n: float(np.sum(m * y[:, k])) for k, n in enumerate(names)}
        if c0 is None:
            c0 = tot.get("C", 0.0)
        xc = 1.0 - tot.get("C", 0.0) / c0 if c0 and c0 > 0 else np.nan
        if "Fe2O3" in tot and "Fe3O4" in tot:
            eq = tot["Fe2O3"] + tot["Fe3O4"] * 3.0 * molar["Fe2O3"] / (2.0 * molar["Fe3O4"])
            xi = 1.0 - tot["Fe2O3"] / eq if eq > 0 else np.nan
        else:
            xi = np.nan
        out_t.append(t)
        out_xc.append(xc)
        out_xi.append(xi)
    return np.asarray(out_t), np.asarray(out_xc), np.asarray(out_xi)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run_dir")
    ap.add_argument("--out", default=None)
    ap.add_argument("--summary", default=None)
    args = ap.parse_args()
    run = args.run_dir
    out = args.out or os.path.join(run, "plots")
    os.makedirs(out, exist_ok=True)
    case = yaml.safe_load(open(os.path.join(run, "case.yaml")))
    molar = {s["name"]: float(s["molar_mass"]) for s in case.get("species", [])}
    ts = read_timeseries(os.path.join(run, "timeseries.csv"))
    t = ts["t"]
    flows = {}
    for s in DRY:
        col = f"gas.outflow.{s}_kg_per_s"
        if col not in ts:
            raise SystemExit(f"{run}/timeseries.csv has no column {col}: coredemFoam of this build "
                             f"does not report outlet species flows, or the case has no gas species {s}")
        flows[s] = ts[col] / molar[s]  # mol/s
    total = sum(flows.values())
    # Mole fractions only where the dry N2-free flow is measurable (> 1e-6 of the N2 flow; before
    # the product gas reaches the outlet the flows are round-off).
    n2 = ts["gas.outflow.N2_kg_per_s"] / molar["N2"] if "N2" in molar else total
    safe = np.where(total > 1e-6 * np.abs(n2), total, np.nan)

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for s in DRY:
        ax[0].plot(t, flows[s] / safe, label=s)
        ax[1].plot(t, flows[s] * 1e6, label=s)
    ax[0].set_ylabel("dry, N2-free mole fraction [-]")
    ax[0].set_title("outlet gas composition (dry, N2-free)", fontsize=9)
    ax[0].set_ylim(0, 1)
    ax[1].set_ylabel("outlet molar flow [µmol/s]")
    ax[1].set_title("outlet flows of CO, CO2, H2", fontsize=9)
    for a in ax:
        a.set_xlabel("t [s]")
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.tight_layout()
    out1 = os.path.join(out, "clg_outlet.png")
    fig.savefig(out1, dpi=90)
    plt.close(fig)

    conv = conversion_from_snapshots(run, case.get("solid_species", []))
    out2 = None
    if conv is not None:
        tc, xc, xi = conv
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(tc, xc * 100, "o-", ms=3, label="carbon conversion X_C")
        ax.plot(tc, xi * 100, "s-", ms=3, label="carrier conversion ξ (Fe2O3 → Fe3O4)")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("conversion [%]")
        ax.set_title("solid conversion (all particles)", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        out2 = os.path.join(out, "clg_conversion.png")
        fig.savefig(out2, dpi=90)
        plt.close(fig)

    if args.summary:
        with open(args.summary, "w") as f:
            f.write("| t [s] | x_CO | x_CO2 | x_H2 | ṅ_CO+CO2+H2 [µmol/s] | X_C [%] | ξ [%] |\n"
                    "|---|---|---|---|---|---|---|\n")
            n = len(t)
            for k in sorted(set([max(0, n // 4 - 1), max(0, n // 2 - 1), max(0, 3 * n // 4 - 1), n - 1])):
                xc_k = xi_k = float("nan")
                if conv is not None:
                    j = int(np.argmin(np.abs(conv[0] - t[k])))
                    xc_k, xi_k = conv[1][j] * 100, conv[2][j] * 100
                f.write(f"| {t[k]:.3f} | {flows['CO'][k] / safe[k]:.3f} | {flows['CO2'][k] / safe[k]:.3f} | "
                        f"{flows['H2'][k] / safe[k]:.3f} | {total[k] * 1e6:.3f} | {xc_k:.3f} | {xi_k:.4f} |\n")
    for p in (out1, out2):
        if p:
            print(f"plot: {p} ({os.path.getsize(p) // 1024} kB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
