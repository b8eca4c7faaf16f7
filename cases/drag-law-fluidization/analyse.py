#!/usr/bin/env python3
"""Minimum fluidization velocity of each drag law from the campaign's summary.csv.

For every law (the `models.drag` column) the bed's pressure drop Δp_bed = Δp − ρ_g g H_column is
taken against the superficial velocity U. The packed branch (the points below 85 % of the bed's
weight per area W, up to the first point above it) is fitted with Δp_bed = a U + b U² (Ergun's
form, least squares); U_mf is where that fit reaches W. The fluidized plateau is the mean of
Δp_bed / W over the points at U ≥ 1.2 U_mf. References: Wen & Yu's correlation
(Re_mf = sqrt(33.7² + 0.0408 Ar) − 33.7) and Ergun's equation at the packed bed's voidage
(from `bed_height_m`, the bed's mean over the packed points).

    analyse.py SUMMARY.csv --case bed/case.yaml --out PLOT_DIR
writes PLOT_DIR/umf.md (the table, also printed) and PLOT_DIR/fluidization_curves.png.
"""
import argparse
import csv
import math
import sys
from pathlib import Path

import numpy as np
import yaml


def case_numbers(path):
    c = yaml.safe_load(Path(path).read_text())
    gas = c["gas_properties"]
    mat = {m["name"]: m for m in c["materials"]}
    (p,) = c["particles"]
    rho_p = p.get("density") or mat[p["material"]]["density"]
    lo, hi = c["walls"]["box"]["min"], c["walls"]["box"]["max"]
    g = math.sqrt(sum(x * x for x in c["gravity"]))
    up = max(range(3), key=lambda i: abs(c["gravity"][i]))
    area = math.prod(hi[i] - lo[i] for i in range(3) if i != up)
    return dict(n=p["count"], d=p["diameter"], rho_p=rho_p, rho_g=gas["density"],
                mu=gas["viscosity"], g=g, area=area, height=hi[up] - lo[up])


def ergun_gradient(eps, u, k):
    s = 1.0 - eps
    return (150.0 * s * s * k["mu"] * u / (eps**3 * k["d"] ** 2)
            + 1.75 * s * k["rho_g"] * u * u / (eps**3 * k["d"]))


def ergun_umf(eps, k):
    """U where Ergun's gradient equals the bed's buoyant weight per volume (1-eps)(rho_p-rho_g)g."""
    s = 1.0 - eps
    a = 150.0 * s * s * k["mu"] / (eps**3 * k["d"] ** 2)
    b = 1.75 * s * k["rho_g"] / (eps**3 * k["d"])
    w = s * (k["rho_p"] - k["rho_g"]) * k["g"]
    return (-a + math.sqrt(a * a + 4 * b * w)) / (2 * b)


def wen_yu_umf(k):
    ar = k["d"] ** 3 * k["rho_g"] * (k["rho_p"] - k["rho_g"]) * k["g"] / k["mu"] ** 2
    re = math.sqrt(33.7**2 + 0.0408 * ar) - 33.7
    return re * k["mu"] / (k["rho_g"] * k["d"])


def read_summary(path, label):
    rows = list(csv.DictReader(open(path, newline="")))
    if not rows:
        sys.exit(f"{path}: no members")
    cols = rows[0].keys()
    ucol = next((c for c in cols if "superficial_velocity" in c), None)
    dpcol = next((c for c in cols if "pressure_drop_Pa" in c), None)
    hcol = next((c for c in cols if "bed_height_m" in c), None)
    if not (ucol and dpcol and hcol):
        sys.exit(f"{path}: expected columns for the inlet velocity, the pressure drop and "
                 f"bed_height_m; found {', '.join(cols)}")
    laws = {}
    for r in rows:
        if r.get("status") != "done" or not r[dpcol]:
            print(f"{path}: member {r.get('member')} ({r.get('models.drag', label)}, U = {r[ucol]}) is "
                  f"{r.get('status')}: left out", file=sys.stderr)
            continue
        laws.setdefault(r.get("models.drag", label), []).append(
            (float(r[ucol]), float(r[dpcol]), float(r[hcol])))
    return {law: sorted(v) for law, v in laws.items()}


def analyse(points, k, weight):
    u = np.array([p[0] for p in points])
    dp = np.array([p[1] for p in points]) - k["rho_g"] * k["g"] * k["height"]
    h = np.array([p[2] for p in points])
    packed = []
    for i in range(len(u)):
        if dp[i] >= 0.85 * weight:
            break
        packed.append(i)
    res = dict(u=u, dp=dp, packed=packed, umf=float("nan"), plateau=float("nan"),
               eps=float("nan"))
    if len(packed) >= 2:
        a, b = np.linalg.lstsq(np.column_stack([u[packed], u[packed] ** 2]), dp[packed],
                               rcond=None)[0]
        res["umf"] = (-a + math.sqrt(a * a + 4 * b * weight)) / (2 * b) if b > 0 else weight / a
        res["fit"] = (a, b)
        solid = k["n"] * math.pi / 6 * k["d"] ** 3
        res["eps"] = float(np.mean(1.0 - solid / (k["area"] * h[packed])))
    fl = u >= 1.2 * res["umf"]
    if fl.any():
        res["plateau"] = float(np.mean(dp[fl]) / weight)
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("summary")
    ap.add_argument("--case", required=True, help="the campaign's base case.yaml")
    ap.add_argument("--out", required=True, help="folder for umf.md and fluidization_curves.png")
    ap.add_argument("--label", default="the case's law",
                    help="the law's name when the sweep does not sweep models.drag")
    a = ap.parse_args()
    k = case_numbers(a.case)
    weight = k["n"] * k["rho_p"] * math.pi / 6 * k["d"] ** 3 * k["g"] / k["area"]
    weight *= 1.0 - k["rho_g"] / k["rho_p"]
    laws = read_summary(a.summary, a.label)
    wy = wen_yu_umf(k)
    results = {law: analyse(p, k, weight) for law, p in laws.items()}
    eps_all = [r["eps"] for r in results.values() if not math.isnan(r["eps"])]
    eps_bed = float(np.mean(eps_all)) if eps_all else float("nan")
    eu = ergun_umf(eps_bed, k) if eps_all else float("nan")
    lines = [
        f"Bed weight per area W = {weight:.1f} Pa; packed-bed voidage from bed_height_m "
        f"{eps_bed:.3f} (mean over laws); U_mf: Wen & Yu's correlation {wy:.3f} m/s, Ergun at "
        f"that voidage {eu:.3f} m/s.",
        "",
        "| drag law | packed points | U_mf (m/s) | vs Wen–Yu | vs Ergun(ε_bed) | bed voidage | "
        "plateau Δp_bed / W |",
        "|---|---|---|---|---|---|---|",
    ]
    for law, r in results.items():
        pct = lambda x, ref: f"{100 * (x / ref - 1):+.1f} %" if not math.isnan(x) else "–"
        lines.append(f"| {law} | {len(r['packed'])} | {r['umf']:.3f} | {pct(r['umf'], wy)} | "
                     f"{pct(r['umf'], eu)} | {r['eps']:.3f} | {r['plateau']:.3f} |")
    text = "\n".join(lines) + "\n"
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "umf.md").write_text(text)
    print(text, end="")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for law, r in results.items():
        ax.plot(r["u"], r["dp"], "o-", ms=4, lw=1.2, label=f"{law} (U_mf {r['umf']:.2f} m/s)")
    uu = np.linspace(0.0, max(max(r["u"]) for r in results.values()), 200)
    if eps_all:
        bed_h = k["n"] * math.pi / 6 * k["d"] ** 3 / (k["area"] * (1 - eps_bed))
        ax.plot(uu, np.minimum(ergun_gradient(eps_bed, uu, k) * bed_h, weight), "k--", lw=1,
                label=f"Ergun, ε = {eps_bed:.3f}")
    ax.axhline(weight, color="grey", lw=1, label="bed weight per area")
    ax.axvline(wy, color="grey", ls=":", lw=1, label=f"U_mf Wen & Yu {wy:.3f} m/s")
    ax.set_xlabel("superficial velocity U [m/s]")
    ax.set_ylabel("bed pressure drop Δp − ρ_g g H [Pa]")
    ax.set_title("Fluidization curves by drag law (2000 glass beads, 1 mm, air)")
    ax.set_ylim(0, 1.35 * weight)
    ax.legend(fontsize=7.5, loc="lower right")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "fluidization_curves.png", dpi=130)
    print(f"wrote {out / 'umf.md'} and {out / 'fluidization_curves.png'}")


if __name__ == "__main__":
    main()
