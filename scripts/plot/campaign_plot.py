#!/usr/bin/env python3
"""Plot one result of a campaign against one swept key (docs/campaigns.md).

    campaign_plot.py DIR/summary.csv --x gas.T_g --y mean_T_p --out DIR/plots/campaign.png \
        [--when "final value at t = 0.05 s"]

Reads summary.csv written by `coredem campaign collect`; members that are not done (empty
result) are left out. When more than one key was swept, one line per combination of the
other keys. Axes carry units (--unit KEY=UNIT from the sweep's collect.units, else units.py: from
the column or key name; [?] when unknown) and the title the time the plotted value refers to
(--when, given by `coredem campaign collect`). An x key whose values are all numbers (a swept
number, or a recorded param.* value) gives a numeric axis; other values a categorical one.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from units import label as unit_label  # noqa: E402


def number(text):
    try:
        return float(text)
    except ValueError:
        return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("summary")
    ap.add_argument("--x", required=True, help="swept key (a column of summary.csv)")
    ap.add_argument("--y", required=True, help="result (a column of summary.csv)")
    ap.add_argument("--out", required=True, help="PNG file")
    ap.add_argument("--title", default="campaign")
    ap.add_argument("--when", default="", help="the time the y value refers to (title)")
    ap.add_argument("--group", action="append", default=[],
                    help="another swept key: one line per value (repeatable)")
    ap.add_argument("--unit", action="append", default=[],
                    help="KEY=UNIT: the unit of a key or column (collect.units; repeatable)")
    a = ap.parse_args()
    units = dict(u.split("=", 1) for u in a.unit if "=" in u)

    def axis_label(name):
        base = name.split(":")[-1]
        return unit_label(name, units.get(name, units.get(base)))

    with open(a.summary, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{a.summary}: no members")
    for col in (a.x, a.y):
        if col not in rows[0]:
            sys.exit(f"{a.summary}: no column '{col}'; columns: {', '.join(rows[0].keys())}")
    for g in a.group:
        if g not in rows[0]:
            sys.exit(f"{a.summary}: no column '{g}' (--group)")
    # keys with a single value in the whole campaign, or fixed by the x value (a cfd.case folder
    # that goes with each param.U_in), do not split the lines
    xs_all = {r[a.x] for r in rows}
    a.group = [g for g in a.group if len({r[g] for r in rows}) > 1
               and len({(r[a.x], r[g]) for r in rows}) > len(xs_all)]
    groups = {}
    for r in rows:
        y = number(r[a.y])
        if y is None:
            continue
        x = number(r[a.x])
        label = ", ".join(f"{g}={r[g]}" for g in a.group)
        groups.setdefault(label, []).append((x if x is not None else r[a.x], y))

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for label, pts in sorted(groups.items()):
        numeric = all(isinstance(p[0], float) for p in pts)
        pts.sort(key=lambda p: p[0] if numeric else str(p[0]))  # noqa: E501
        xs = [p[0] for p in pts] if numeric else [str(p[0]) for p in pts]
        ax.plot(xs, [p[1] for p in pts], "o-", label=label or None)
    ax.set_xlabel(axis_label(a.x))
    ax.set_ylabel(axis_label(a.y))
    title = f"{a.title}: {a.y} vs {a.x}"
    if a.when:
        title += f"\n({a.when})"
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    if any(groups.keys()):
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)
    kind = "numeric" if all(all(isinstance(p[0], float) for p in pts) for pts in groups.values()) \
        else "categorical"
    print(f"x axis: {axis_label(a.x)} ({kind}); y axis: {axis_label(a.y)}; title: {title}"
          .replace("\n", " "))
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
