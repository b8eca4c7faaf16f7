#!/usr/bin/env python3
"""Patil bed-cooling validation plots (docs/validation.md, docs/physics.md §9.1).

Usage: validation_patil.py --run LABEL=RUN_DIR [--run ...] [--out DIR] [--summary FILE]

Reads each run's timeseries.csv and writes to DIR (default docs/img/validation):
  patil_temperature.png  mean particle temperature (°C) vs time for every run, the seed's
                         reported trends (90 − 3.0 t °C for 75 g, 90 − 2.5 t °C for 125 g,
                         ±3 °C) and the adiabatic energy-balance bound
                         M c_p,p dT̄/dt = −ṁ_g (h_g(T̄) − h_g(T_in)) (the gas leaves at the
                         mean bed temperature), ṁ_g = ρ_g,in U A, of each run's inventory and
                         cross-section; with a constant-property gas h_g = c_p,g (T − T_in) and
                         T̄ = T_in + (T0 − T_in) exp(−t/τ), τ = M c_p,p / (ρ_g U A c_p,g); with the
                         ideal gas h_g is the NASA-7 enthalpy and ρ_g,in = p M/(R T_in) of the
                         run's own constant/thermophysicalProperties (p: pRef plus the run's
                         mean gas.pressure_drop_Pa, the inlet's absolute pressure), and τ is
                         the initial time constant M c_p,p (T0 − T_in) / (ṁ_g (h_g(T0) − h_g(T_in))))
  patil_ledger.png       energy-ledger closure of every run: particle side
                         |ΔΣ m c T − (Q_gas + Q_rad + Q_wall)| and gas side
                         |balance.heat_residual_J| relative to the heat removed
The run label must start with the inventory ('75g' or '125g'); the cross-section A is read from
the run's case file (walls.box, x and z extents), U from the run's openfoam/0/U, T_in and (constant
gas) ρ_g, c_p,g from its case file.
--summary writes a Markdown table of the end values (mean T, bound, ledger residuals).
Interpreter: COREDEM_PYTHON (/usr/bin/python3 with numpy, matplotlib, yaml-free parsing).
"""
import argparse
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from plot_run import read_timeseries  # noqa: E402  (same folder)

CP_P = 840.0  # J/kg/K, glass (docs/physics.md §7), = the case files' materials[0].cp
T0_C = 90.0
SEED = {"75g": 3.0, "125g": 2.5}  # °C/s, docs/physics.md §9.1 fits


def case_numbers(run_dir):
    """Cross-section, inlet velocity and gas properties from the run's copy of the case."""
    text = None
    for name in ("case.yaml",):
        p = os.path.join(run_dir, name)
        if os.path.exists(p):
            text = open(p).read()
    if text is None:
        raise SystemExit(f"{run_dir}: no case.yaml in the run folder")
    box = re.search(r"box:\s*\{min:\s*\[([^\]]*)\],\s*max:\s*\[([^\]]*)\]", text)
    lo = [float(v) for v in box.group(1).split(",")]
    hi = [float(v) for v in box.group(2).split(",")]
    area = (hi[0] - lo[0]) * (hi[2] - lo[2])

    def gas(key):
        m = re.search(r"gas_properties:.*?\n\s+" + key + r":\s*([0-9.eE+-]+)", text, re.S)
        return float(m.group(1)) if m else None

    u = None
    ufile = os.path.join(run_dir, "openfoam", "0", "U")
    if os.path.exists(ufile):
        m = re.search(r"inlet\s*\{[^}]*uniform \(0 ([0-9.eE+-]+) 0\)", open(ufile).read())
        u = float(m.group(1)) if m else None
    out = {"area": area, "u": u if u is not None else 1.54, "tin": gas("temperature")}
    thermo = os.path.join(run_dir, "openfoam", "constant", "thermophysicalProperties")
    if re.search(r"gas_properties:[^\n]*\n(\s+[^\n]*\n)*?\s+model:\s*ideal_gas", text) and \
            os.path.exists(thermo):
        out.update(ideal_gas_numbers(open(thermo).read(), thermo))
    else:
        cp, rho = gas("cp"), gas("density")
        out.update({"rho": rho, "h": lambda T: cp * T})
    return out


def ideal_gas_numbers(text, path):
    """Molar mass, pRef and the sensible enthalpy h(T) [J/kg] of the run's one-species ideal gas."""
    species = re.search(r"species\s*\(\s*(\w+)\s*\)", text)
    if species is None:
        raise SystemExit(f"{path}: the Patil plots expect a gas of one species (air)")
    mw = float(re.search(r"molWeight\s+([0-9.eE+-]+)", text).group(1)) * 1e-3
    tcommon = float(re.search(r"Tcommon\s+([0-9.eE+-]+)", text).group(1))
    lo = [float(v) for v in re.search(r"lowCpCoeffs\s*\(([^)]*)\)", text).group(1).split()]
    hi = [float(v) for v in re.search(r"highCpCoeffs\s*\(([^)]*)\)", text).group(1).split()]
    pref = float(re.search(r"pRef\s+([0-9.eE+-]+)", text).group(1))
    r_gas = 8.314462618  # J/mol/K

    def h(T):
        a = lo if T <= tcommon else hi
        return r_gas / mw * T * (a[0] + T * (a[1] / 2 + T * (a[2] / 3 + T * (a[3] / 4 + T * a[4] / 5))) +
                                 a[5] / T)

    return {"h": h, "molar_mass": mw, "p_ref": pref, "rho": None}


def adiabatic_bound(cn, mass, tt, p_in):
    """Mean bead temperature [°C] on tt of the energy balance with the gas leaving at T̄, and τ."""
    tin = cn["tin"]
    rho = cn["rho"] if cn["rho"] is not None else p_in * cn["molar_mass"] / (8.314462618 * tin)
    mdot = rho * cn["u"] * cn["area"]
    capacity = mass * CP_P

    def rate(T):
        return -mdot * (cn["h"](T) - cn["h"](tin)) / capacity

    T, out = T0_C + 273.15, [T0_C]
    for t0, t1 in zip(tt[:-1], tt[1:]):  # RK4, 200 steps of at most 0.05 s: τ ≥ 20 s here
        dt = t1 - t0
        k1 = rate(T)
        k2 = rate(T + 0.5 * dt * k1)
        k3 = rate(T + 0.5 * dt * k2)
        k4 = rate(T + dt * k3)
        T += dt * (k1 + 2 * k2 + 2 * k3 + k4) / 6
        out.append(T - 273.15)
    tau = capacity * (T0_C + 273.15 - tin) / (mdot * (cn["h"](T0_C + 273.15) - cn["h"](tin)))
    return np.array(out), tau


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--run", action="append", required=True, help="LABEL=RUN_DIR")
    ap.add_argument("--out", default="docs/img/validation")
    ap.add_argument("--summary", default=None)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    runs = []
    for spec in args.run:
        label, _, d = spec.partition("=")
        ts = read_timeseries(os.path.join(d, "timeseries.csv"))
        runs.append((label, d, ts, case_numbers(d)))

    colors = {"75g": "tab:blue", "125g": "tab:red"}
    fig, ax = plt.subplots(figsize=(8, 5))
    tmax = max(ts["t"][-1] for _, _, ts, _ in runs)
    tt = np.linspace(0.0, max(tmax, 1e-3), 200)
    for inv, rate in SEED.items():
        if not any(l.startswith(inv) for l, *_ in runs):
            continue
        ax.fill_between(tt, T0_C - rate * tt - 3.0, T0_C - rate * tt + 3.0, color=colors[inv], alpha=0.12,
                        label=f"seed trend {inv}: 90 − {rate} t °C ± 3 °C")
    rows = []
    for label, d, ts, cn in runs:
        inv = "125g" if label.startswith("125g") else "75g"
        cold = "cold" in label
        t = np.concatenate([[0.0], ts["t"]])
        tp = np.concatenate([[T0_C], ts["mean_T_p"] - 273.15])
        ax.plot(t, tp, color=colors[inv], ls="--" if cold else "-", lw=1.5, label=label)
        mass = ts["dem.particle_mass_kg"][-1]
        p_in = cn.get("p_ref", 0.0) + float(np.mean(ts["gas.pressure_drop_Pa"]))
        bound, tau = adiabatic_bound(cn, mass, tt, p_in)
        bound_end, _ = adiabatic_bound(cn, mass, np.linspace(0.0, ts["t"][-1], 201), p_in)
        ax.plot(tt, bound, color=colors[inv], ls=":", lw=1,
                label=f"adiabatic bound {label} (τ = {tau:.1f} s)" if not cold else None)
        # Ledger: particle side (E0 = M c_p T0 exactly: all beads start at 363.15 K).
        e0 = mass * CP_P * 363.15
        q = ts["dem.heat_from_gas_J"] + ts.get("dem.heat_radiation_J", 0 * ts["t"]) + \
            ts.get("dem.heat_wall_J", 0 * ts["t"])
        dE = ts["dem.thermal_energy_J"] - e0
        rows.append({"label": label, "dir": d, "t": ts["t"], "dE": dE, "q": q,
                     "part_res": np.abs(dE - q), "gas_res": np.abs(ts["balance.heat_residual_J"]),
                     "wall": ts.get("dem.heat_wall_J", 0 * ts["t"]), "gasq": ts["dem.heat_from_gas_J"],
                     "tend": ts["t"][-1], "Tend": ts["mean_T_p"][-1] - 273.15,
                     "bound_end": bound_end[-1],
                     "seed_end": T0_C - SEED[inv] * ts["t"][-1], "tau": tau, "e0": e0,
                     # wall seconds per simulated second over the sampled rows
                     "wall_s": float(np.nansum(ts["wall_step_s"]) / np.nansum(ts["dt"]))})
    ax.set_xlabel("t [s]")
    ax.set_ylabel("mean particle temperature [°C]")
    ax.set_title("Patil bed cooling: mean T_p (solid adiabatic walls, dashed walls at 20 °C)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower left")
    ax.set_xlim(0, max(tmax, 1e-3))
    lo = min(min(r["Tend"] for r in rows), min(T0_C - SEED[k] * tmax for k in SEED) - 3) - 1
    ax.set_ylim(lo, T0_C + 1)
    fig.tight_layout()
    out1 = os.path.join(args.out, "patil_temperature.png")
    fig.savefig(out1, dpi=90)
    plt.close(fig)

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for r in rows:
        removed = np.maximum(np.abs(r["dE"]), 1e-300)
        ax[0].semilogy(r["t"], np.maximum(r["part_res"] / removed, 1e-18), label=r["label"])
        ax[1].semilogy(r["t"], np.maximum(r["gas_res"] / np.maximum(np.abs(r["gasq"]), 1e-300), 1e-18),
                       label=r["label"])
    ax[0].set_title("particles: |ΔΣmcT − (Q_gas + Q_rad + Q_wall)| / |ΔΣmcT|", fontsize=9)
    ax[1].set_title("gas vs particles: |balance.heat_residual_J| / |Q_gas|", fontsize=9)
    for a in ax:
        a.set_xlabel("t [s]")
        a.grid(alpha=0.3, which="both")
        a.legend(fontsize=7)
    fig.tight_layout()
    out2 = os.path.join(args.out, "patil_ledger.png")
    fig.savefig(out2, dpi=90)
    plt.close(fig)

    if args.summary:
        with open(args.summary, "w") as f:
            f.write("| run | t_end [s] | mean T_p [°C] | seed trend [°C] | adiabatic bound [°C] (τ) | "
                    "heat to gas [J] | heat to walls [J] | particle ledger residual [J] | "
                    "gas-particle residual [J] | wall s per simulated s |\n|---|---|---|---|---|---|---|---|---|---|\n")
            for r in rows:
                f.write(f"| {r['label']} | {r['tend']:.3f} | {r['Tend']:.3f} | {r['seed_end']:.2f} | "
                        f"{r['bound_end']:.3f} ({r['tau']:.1f} s) | {-r['gasq'][-1]:.4f} | "
                        f"{0.0 - r['wall'][-1] + 0.0:.4f} | {r['part_res'][-1]:.2e} | {r['gas_res'][-1]:.2e} | "
                        f"{r['wall_s']:.0f} |\n")
    for p in (out1, out2):
        print(f"plot: {p} ({os.path.getsize(p) // 1024} kB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
