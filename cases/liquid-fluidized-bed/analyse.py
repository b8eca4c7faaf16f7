#!/usr/bin/env python3
"""Bed expansion of the liquid-fluidized bed campaign against Richardson & Zaki.

For each member (drag law, superficial velocity U) the bed voidage is measured from the particle
snapshots after `--from` seconds: the bed's height is taken as twice the distance between the
25th and 75th percentiles of the centres' elevations (in a uniformly expanded bed the middle
half of the particles fills half the bed; the distributor layer and the loose surface do not
enter), eps = 1 - N V_p / (A H), averaged over the snapshots. Richardson & Zaki:
U = U_t eps^n, with U_t the terminal velocity of one bead (Schiller-Naumann drag, the dilute
limit of the laws compared) and n from Garside & Al-Dibouni (1977),
(5.1 - n)/(n - 2.7) = 0.1 Re_t^0.9. The column's walls are frictionless and the fluid slips at
them, so no wall correction of U_t applies.

    analyse.py CAMPAIGN_DIR --case case.yaml --out PLOT_DIR [--from 0.6]
writes PLOT_DIR/expansion.md (the table, also printed) and PLOT_DIR/bed_expansion.png.
"""
import argparse
import csv
import math
import sys
from pathlib import Path

import h5py
import numpy as np
import yaml


def case_numbers(path):
    c = yaml.safe_load(Path(path).read_text())
    gas = c["gas_properties"]
    mat = {m["name"]: m for m in c["materials"]}
    (p,) = c["particles"]
    lo, hi = c["walls"]["box"]["min"], c["walls"]["box"]["max"]
    up = max(range(3), key=lambda i: abs(c["gravity"][i]))
    (plane,) = c["walls"]["planes"]
    return dict(n=p["count"], d=p["diameter"], rho_p=p.get("density") or mat[p["material"]]["density"],
                rho=gas["density"], mu=gas["viscosity"],
                g=math.sqrt(sum(x * x for x in c["gravity"])), up=up,
                area=math.prod(hi[i] - lo[i] for i in range(3) if i != up),
                floor=plane["point"][up])


def terminal_velocity(k):
    """U_t of one sphere with the Schiller-Naumann drag: C_D Re^2 = 4/3 Ar, by bisection on Re."""
    ar = k["d"] ** 3 * k["rho"] * (k["rho_p"] - k["rho"]) * k["g"] / k["mu"] ** 2
    lo, hi = 1e-9, 1e6
    for _ in range(200):
        re = math.sqrt(lo * hi)
        cd = 24.0 / re * (1.0 + 0.15 * re**0.687)
        lo, hi = (re, hi) if cd * re * re < 4.0 / 3.0 * ar else (lo, re)
    re = math.sqrt(lo * hi)
    return re * k["mu"] / (k["rho"] * k["d"]), re


def garside_al_dibouni_n(re_t):
    a = 0.1 * re_t**0.9
    return (5.1 + 2.7 * a) / (1.0 + a)


def snapshot_voidage(run, k, t_from):
    index = run / "snapshots" / "index.csv"
    if not index.exists():
        return float("nan"), 0
    values = []
    for row in csv.DictReader(open(index, newline="")):
        if float.fromhex(row["time_hex"]) <= t_from:
            continue
        with h5py.File(run / row["file"], "r") as f:
            y = f["particles/position"][:, k["up"]]
        y25, y75 = np.percentile(y - k["floor"], [25, 75])
        h = 2.0 * (y75 - y25)
        values.append(1.0 - k["n"] * math.pi / 6 * k["d"] ** 3 / (k["area"] * h))
    return (float(np.mean(values)) if values else float("nan")), len(values)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaign")
    ap.add_argument("--case", required=True, help="the campaign's base case.yaml")
    ap.add_argument("--out", required=True)
    ap.add_argument("--from", dest="t_from", type=float, default=0.6,
                    help="average the snapshots after this time, s (default 0.6)")
    a = ap.parse_args()
    k = case_numbers(a.case)
    camp = Path(a.campaign)
    rows = list(csv.DictReader(open(camp / "summary.csv", newline="")))
    ucol = next(c for c in rows[0] if "superficial_velocity" in c)
    ut, re_t = terminal_velocity(k)
    n = garside_al_dibouni_n(re_t)
    laws = {}
    for r in rows:
        if r.get("status") != "done":
            print(f"member {r['member']} ({r['models.drag']}, U = {r[ucol]}) is {r.get('status')}: "
                  "left out", file=sys.stderr)
            continue
        eps, count = snapshot_voidage(camp / "members" / r["member"] / "run", k, a.t_from)
        laws.setdefault(r["models.drag"], []).append((float(r[ucol]), eps, count))
    lines = [f"U_t = {ut:.4f} m/s (Re_t = {re_t:.1f}, Schiller-Naumann), n = {n:.3f} "
             "(Garside & Al-Dibouni); eps_RZ = (U/U_t)^(1/n).", "",
             "| drag law | U (m/s) | snapshots | bed voidage | Richardson–Zaki | difference |",
             "|---|---|---|---|---|---|"]
    worst = {}
    for law, pts in laws.items():
        for u, eps, count in sorted(pts):
            rz = (u / ut) ** (1.0 / n)
            lines.append(f"| {law} | {u:g} | {count} | {eps:.3f} | {rz:.3f} | {eps - rz:+.3f} |")
            worst[law] = max(worst.get(law, 0.0), abs(eps - rz))
    lines.append("")
    lines.append("Largest |eps - eps_RZ| per law: " +
                 ", ".join(f"{law} {w:.3f}" for law, w in worst.items()) + ".")
    text = "\n".join(lines) + "\n"
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "expansion.md").write_text(text)
    print(text, end="")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 5))
    for law, pts in laws.items():
        pts = sorted(pts)
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", label=law)
    uu = np.linspace(0.5 * min(p[0] for v in laws.values() for p in v),
                     1.1 * max(p[0] for v in laws.values() for p in v), 100)
    ax.plot(uu, (uu / ut) ** (1.0 / n), "k--", label=f"Richardson–Zaki, n = {n:.2f}")
    ax.set_xlabel("superficial water velocity U [m/s]")
    ax.set_ylabel("bed voidage ε [-]")
    ax.set_title("Liquid fluidization: bed expansion (1 mm glass in water)")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "bed_expansion.png", dpi=130)
    print(f"wrote {out / 'expansion.md'} and {out / 'bed_expansion.png'}")


if __name__ == "__main__":
    main()
