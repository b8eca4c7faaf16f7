#!/usr/bin/env python3
"""Constant-property vs ideal-gas runs of the same case, side by side (docs/validation.md).

Usage: gas_model_compare.py --pair LABEL=CONSTANT_RUN,IDEAL_GAS_RUN [--pair ...]
                            [--times T1,T2,...] [--out DIR] [--summary FILE]

For every pair, reads both runs' timeseries.csv and writes to DIR (default docs/img/validation):
  gas_model_<LABEL>.png   mean particle temperature, bed height, pressure drop and (when the
                          case has gas species leaving) the dry, N2-free outlet mole fractions
                          x_CO, x_CO2, x_H2, constant (solid) vs ideal gas (dashed), against time
--summary writes a Markdown table per pair with the values at --times (the row of each run
nearest to each time; default: the last time both runs reached): mean T_p, bed height, pressure
drop, heat the particles gave the gas (convection, radiation), the coupled-ledger residuals
balance.heat_residual_J and balance.radiation_residual_J, and the outlet composition.
Bed height and pressure drop fluctuate in a bubbling bed: the table gives their mean over the
last 0.1 s before each time. Interpreter: COREDEM_PYTHON (/usr/bin/python3 with numpy, matplotlib).
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from plot_run import read_timeseries  # noqa: E402  (same folder)

MOLAR_MASS = {"CO": 0.028010, "CO2": 0.044009, "H2": 0.002016}  # kg/mol, docs/physics.md §6
WINDOW = 0.1  # s, averaging window of the fluctuating columns


def load(run_dir):
    path = os.path.join(run_dir, "timeseries.csv")
    if not os.path.isfile(path):
        sys.exit(f"gas_model_compare: no {path}: is {run_dir} a run folder of coredem run?")
    return read_timeseries(path)


def outlet_fractions(ts):
    """Dry, N2-free outlet mole fractions (x_CO, x_CO2, x_H2) per row, or None."""
    flows = {}
    for name, m in MOLAR_MASS.items():
        key = f"gas.outflow.{name}_kg_per_s"
        if key not in ts:
            return None
        flows[name] = np.asarray(ts[key]) / m
    total = flows["CO"] + flows["CO2"] + flows["H2"]
    with np.errstate(invalid="ignore", divide="ignore"):
        return {k: np.where(total > 0, v / total, np.nan) for k, v in flows.items()}, total


def at(ts, column, t, window=0.0):
    """Value of `column` at the row nearest to t, or its mean over (t - window, t]."""
    times = np.asarray(ts["t"])
    values = np.asarray(ts[column])
    if window > 0:
        sel = (times > t - window) & (times <= t + 1e-12)
        if sel.any():
            return float(np.mean(values[sel]))
    return float(values[np.argmin(np.abs(times - t))])


def plot_pair(label, const, ideal, out):
    panels = [("mean_T_p", "mean particle temperature [K]"),
              ("bed_height_m", "bed height [m]"),
              ("gas.pressure_drop_Pa", "pressure drop [Pa]")]
    comp = outlet_fractions(const), outlet_fractions(ideal)
    n = len(panels) + (1 if comp[0] and comp[1] else 0)
    fig, axes = plt.subplots(1, n, figsize=(4.2 * n, 3.6))
    for ax, (col, title) in zip(axes, panels):
        for ts, style, name in ((const, "-", "constant"), (ideal, "--", "ideal gas")):
            if col in ts:
                ax.plot(ts["t"], ts[col], style, lw=1.2, label=name)
        ax.set_xlabel("t [s]")
        ax.set_ylabel(title)
        ax.legend(fontsize=8)
    if n > len(panels):
        ax = axes[-1]
        for (fractions, _), style, name in ((comp[0], "-", "constant"),
                                            (comp[1], "--", "ideal gas")):
            ts = const if name == "constant" else ideal
            for k, color in (("CO", "C0"), ("CO2", "C1"), ("H2", "C2")):
                ax.plot(ts["t"], fractions[k], style, color=color, lw=1.2,
                        label=f"x_{k} ({name})")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("outlet mole fraction, dry N2-free [-]")
        ax.set_ylim(0, 1)
        ax.legend(fontsize=7)
    fig.suptitle(f"{label}: constant-property gas (solid) vs ideal gas (dashed)")
    fig.tight_layout()
    path = os.path.join(out, f"gas_model_{label}.png")
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def summary_rows(label, const, ideal, times):
    lines = [f"**{label}**", "",
             "| t [s] | model | mean T_p [K] | bed height [mm] | Δp [Pa] | Q_conv to gas [J] | "
             "Q_rad to gas [J] | convection residual [J] | radiation residual [J] | x_CO | x_CO2 "
             "| x_H2 |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for t in times:
        for name, ts in (("constant", const), ("ideal gas", ideal)):
            comp = outlet_fractions(ts)
            x = ["–", "–", "–"]
            if comp:
                fr, _ = comp
                i = int(np.argmin(np.abs(np.asarray(ts["t"]) - t)))
                x = [f"{fr[k][i]:.3f}" for k in ("CO", "CO2", "H2")]
            rad = at(ts, "balance.radiation_residual_J", t) \
                if "balance.radiation_residual_J" in ts else float("nan")
            lines.append(
                f"| {at(ts, 't', t):.3f} | {name} | {at(ts, 'mean_T_p', t):.3f} | "
                f"{1e3 * at(ts, 'bed_height_m', t, WINDOW):.2f} | "
                f"{at(ts, 'gas.pressure_drop_Pa', t, WINDOW):.1f} | "
                f"{-at(ts, 'dem.heat_from_gas_J', t):.4g} | "
                f"{-at(ts, 'dem.heat_radiation_J', t):.3g} | "
                f"{at(ts, 'balance.heat_residual_J', t):.2e} | {rad:.1e} | "
                + " | ".join(x) + " |")
    lines.append("")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pair", action="append", required=True,
                    help="LABEL=CONSTANT_RUN,IDEAL_GAS_RUN")
    ap.add_argument("--times", default=None, help="comma-separated times of the summary (s)")
    ap.add_argument("--out", default="docs/img/validation")
    ap.add_argument("--summary", default=None)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    lines = []
    for spec in a.pair:
        label, _, dirs = spec.partition("=")
        const_dir, _, ideal_dir = dirs.partition(",")
        if not label or not const_dir or not ideal_dir:
            sys.exit(f"gas_model_compare: --pair {spec!r}: give LABEL=CONSTANT_RUN,IDEAL_GAS_RUN")
        const, ideal = load(const_dir), load(ideal_dir)
        print(plot_pair(label, const, ideal, a.out))
        common = min(const["t"][-1], ideal["t"][-1])
        times = [float(x) for x in a.times.split(",")] if a.times else [common]
        lines += summary_rows(label, const, ideal, [t for t in times if t <= common + 1e-9])
    text = "\n".join(lines)
    if a.summary:
        with open(a.summary, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
