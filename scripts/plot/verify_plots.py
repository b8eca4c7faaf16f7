#!/usr/bin/env python3
"""Plots of `coredem verify` (docs/verification.md), like the seed's Figs. 5-12.

Usage: verify_plots.py DIR [--dpi N]

Reads DIR/<case>/verify.csv (written by `coredem verify`: a comment line
"# case=...;family=...;quantity=...", a header with t, sim:X / ref:X pairs and error columns)
and writes one figure per family to DIR/plots/<family>.png: the simulated values (markers)
over the analytic solution (lines), seed variants and MFiX cases in separate panels, and the
error against time.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

TITLES = {
    "contact-conduction": "Particle-particle contact conduction (docs/physics.md §8.1)",
    "gas-lens": "Particle-fluid-particle conduction through the gas lens (docs/physics.md §8.2)",
    "convection": "Particle-gas convection (docs/physics.md §8.3)",
    "radiation": "Radiation, RK4 reference (docs/physics.md §8.4)",
    "reaction": "Heterogeneous reaction A(g) + 2B(s) -> C(g) + D(s) (docs/physics.md §8.5)",
}


def read_case(path):
    with open(path) as f:
        meta_line = f.readline().lstrip("#").strip()
        meta = dict(kv.split("=", 1) for kv in meta_line.split(";"))
        rows = list(csv.reader(f))
    header, data = rows[0], rows[1:]
    cols = {h: [float(r[i]) for r in data] for i, h in enumerate(header)}
    return meta, cols


def thin(xs, n=60):
    """Every k-th index so that about n markers are drawn."""
    k = max(1, len(xs) // n)
    return list(range(0, len(xs), k))


def draw_curves(ax, cases, colours, reaction, title, fractions=False):
    markers = "os^v"
    for ci, (name, cols) in cases:
        t = cols["t"]
        idx = thin(t)
        colour = colours[ci % len(colours)]
        quantities = [h[4:] for h in cols if h.startswith("sim:")]
        if reaction:
            quantities = [q for q in quantities if q.startswith("X_") == fractions]
        for qi, q in enumerate(quantities):
            c = colours[(ci + qi) % len(colours)] if fractions else colour
            label = q if fractions else (name if qi == 0 else None)
            ax.plot(t, cols["ref:" + q], "-", color=c, lw=1.0, label=label)
            ax.plot([t[i] for i in idx], [cols["sim:" + q][i] for i in idx],
                    markers[qi % len(markers)], ms=3, mfc="none", color=c)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("mass fraction" if fractions else ("particle mass (kg)" if reaction else "T (K)"))
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=6 if len(cases) > 4 else 7, loc="best")


def plot_family(family, cases, out, dpi):
    """MFiX cases and seed variants in separate panels (their time scales differ), errors last."""
    reaction = family == "reaction"
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    ordered = list(enumerate(sorted(cases.items())))
    groups = [("seed variants: simulation (markers), analytic (lines)",
               [c for c in ordered if not c[1][0].startswith("mfix-")]),
              ("MFiX case: simulation (markers), analytic (lines)",
               [c for c in ordered if c[1][0].startswith("mfix-")])]
    groups = [g for g in groups if g[1]]
    if reaction:  # particle mass and the solid mass fractions (seed Figs. 11-12)
        groups = [("particle mass: simulation (markers), analytic (lines)", ordered, False),
                  ("solid mass fractions: simulation (markers), analytic (lines)", ordered, True)]
    else:
        groups = [(title, group, False) for title, group in groups]
    fig, axes = plt.subplots(1, len(groups) + 1, figsize=(5.2 * (len(groups) + 1), 4.2))
    for ax, (title, group, fractions) in zip(axes, groups):
        draw_curves(ax, group, colours, reaction, title, fractions)
    axe = axes[-1]
    for ci, (name, cols) in ordered:
        colour = colours[ci % len(colours)]
        pts = [(t, e) for t, e in zip(cols["t"], cols["error"]) if e > 0]
        axe.semilogy([p[0] for p in pts], [p[1] for p in pts], "-", color=colour, lw=1.0, label=name)
        if reaction and "fraction_error" in cols:
            pts = [(t, e) for t, e in zip(cols["t"], cols["fraction_error"]) if e > 0]
            axe.semilogy([p[0] for p in pts], [p[1] for p in pts], "--", color=colour, lw=1.0,
                         label=name + " (mass fractions, absolute)")
    axe.set_xlabel("t (s)")
    axe.set_ylabel("relative error" + (" (mass); absolute (fractions)" if reaction else ""))
    axe.set_title("error vs time", fontsize=9)
    axe.legend(fontsize=6, loc="best")
    fig.suptitle(TITLES.get(family, family), fontsize=10)
    fig.tight_layout()
    path = os.path.join(out, f"{family}.png")
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--dpi", type=int, default=90)
    a = ap.parse_args()
    families = {}
    for name in sorted(os.listdir(a.dir)):
        p = os.path.join(a.dir, name, "verify.csv")
        if os.path.isfile(p):
            meta, cols = read_case(p)
            families.setdefault(meta["family"], {})[meta["case"]] = cols
    if not families:
        print(f"{a.dir}: no */verify.csv", file=sys.stderr)
        return 1
    out = os.path.join(a.dir, "plots")
    os.makedirs(out, exist_ok=True)
    for family, cases in families.items():
        print(plot_family(family, cases, out, a.dpi))
    return 0


if __name__ == "__main__":
    sys.exit(main())
