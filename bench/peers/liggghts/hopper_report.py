#!/usr/bin/env python3
"""Check and tabulate the runs of hopper.sh.

    hopper_report.py WORKDIR N STEPS WARMUP REPEAT "VARIANTS" "NP:THREADS ..." LOAD_MAX SKIN
                     SAMPLE FIT_LO FIT_HI

reads WORKDIR/deck/hopper.deck (coredem-bench's deck parameters) and, for each variant (primitive,
stl, primitive_closed, stl_closed, none) and pairing, WORKDIR/VARIANT/params.txt (make_hopper.py's
parameters) and in WORKDIR/VARIANT/npR_tT/: screen.liggghts.<r> (LIGGGHTS' screen output with the
input echoed), ours.<r>.json (`coredem-bench dem --case hopper --json`), ours.<r>.samples
(its --samples-out), load.{liggghts,ours}.<r>, r = 1..REPEAT.

Checks before any figure is printed (a mismatch prints CHECK FAILED, exit 6):
- LIGGGHTS, as report.py for the other decks: the echoed neighbour, timestep and run lines, the
  thermo Dt, step range and atom count (N throughout: no particle lost), the loop's step and
  rank counts, no dangerous builds, the step-0 kinetic energy equal to that of hopper.particles;
  and for the hopper: `read_data hopper.data`, the pair style (hooke/stiffness, tangential
  history, absolute damping, limitForce off), the friction table (mu of hopper.deck for 1-1 and
  1-2), the wall fixes of the variant with the deck's radius and floor height and the meshes
  imported with as many triangles as their STL files have, gravity on (off for `none`);
- CoReDEM: case, walls, closed, particles, steps, warm-up, threads, sample interval, dt_dem, skin,
  ke_initial (equal to LIGGGHTS' step-0 value to 1e-9), the deck directory and its geometry;
  its discharge fit recomputed here from its samples gives the same rate.
The discharge rate of both codes is the same least-squares fit: discharged mass (particles below
the outlet plane z = 0 times m) against time over the samples between FIT_LO and FIT_HI of N
discharged (up to the end of the run if it ends earlier), compared with Beverloo's
W = C rho_b sqrt(g) (D_o - k d_p)^2.5, C = 0.58, k = 1.5, band C 0.55-0.65, k 1.3-2.9, rho_b
measured in the settled bed (hopper.deck rho_bulk).
"""

import json
import math
import os
import re
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import report  # noqa: E402  (parse_liggghts, thermo_blocks, read_params, rel_ok)

BEV_C, BEV_K = 0.58, 1.5
BEV_C_LO, BEV_C_HI, BEV_K_LO, BEV_K_HI = 0.55, 0.65, 1.3, 2.9


def beverloo(deck):
    rho_b = float(deck["rho_bulk"]) or 0.6 * float(deck["rho_p"])
    g, d, do = float(deck["gravity"]), float(deck["d_p"]), float(deck["outlet_d"])

    def w(c, k):
        return c * rho_b * math.sqrt(g) * (do - k * d) ** 2.5
    return w(BEV_C, BEV_K), w(BEV_C_LO, BEV_K_HI), w(BEV_C_HI, BEV_K_LO), rho_b


def fit_rate(samples, n, lo, hi):
    """samples [(t, count)]: (particles/s or None, t0, t1, points, complete, discharged at end)."""
    c_lo, c_hi = lo * n, hi * n
    pts = [(t, c) for t, c in samples if c_lo <= c <= c_hi]
    end = samples[-1][1] / n if samples else 0.0
    complete = bool(samples) and samples[-1][1] >= c_hi
    if len(pts) < 3:
        return None, math.nan, math.nan, len(pts), complete, end
    m = len(pts)
    st = sum(t for t, _ in pts)
    sc = sum(c for _, c in pts)
    stt = sum(t * t for t, _ in pts)
    stc = sum(t * c for t, c in pts)
    slope = (stc - st * sc / m) / (stt - st * st / m)
    return slope, pts[0][0], pts[-1][0], m, complete, end


def stl_triangles(path):
    with open(path) as f:
        return sum(1 for line in f if line.strip().startswith("facet"))


def liggghts_hopper(path, n, steps, warmup, np_, par, skin, deck, deckdir, variant):
    """report.parse_liggghts plus the hopper's checks, its discharge samples and wall touches."""
    out, bad = report.parse_liggghts(path, n, steps, warmup, np_, par, skin)
    text = open(path).read()
    walls, closed = variant.replace("_closed", ""), variant.endswith("_closed")

    def need(pattern, what):
        if not re.search(pattern, text, re.M):
            bad.append(f"{what} not in LIGGGHTS' echoed input/output")
    need(r"^read_data\s+hopper\.data\s*$", "read_data hopper.data")
    need(r"^pair_style\s+gran model hooke/stiffness tangential history absolute_damping on "
         r"tangential_damping on limitForce off\s*$", "the pair style hooke/stiffness ...")
    mu = float(deck["mu"])
    m = re.search(r"^fix cof all property/global coefficientFriction peratomtypepair 2 (.*)$",
                  text, re.M)
    if not m or any(not report.rel_ok(float(v), mu, 1e-12) for v in m.group(1).split()):
        bad.append(f"friction table {m.group(1) if m else 'missing'}, expected mu = {mu!r}")
    model = r"model hooke/stiffness tangential history"
    settings = r"absolute_damping on tangential_damping on limitForce off"
    fixes = {}
    if walls == "stl":
        for mesh in ("hopper", "bin"):
            need(rf"^fix {mesh} all mesh/surface file {mesh}\.stl type 2\s*$", f"mesh {mesh}.stl")
            tri = stl_triangles(os.path.join(deckdir, f"{mesh}.stl"))
            need(rf"Import and parallelization of mesh {mesh} containing {tri} triangle",
                 f"mesh {mesh} imported with its {tri} triangles")
        fixes["whopper"] = r"mesh n_meshes 2 meshes hopper bin"
    elif walls == "primitive":
        need(r"^fix cone all mesh/surface file cone\.stl type 2\s*$", "mesh cone.stl")
        tri = stl_triangles(os.path.join(deckdir, "cone.stl"))
        need(rf"Import and parallelization of mesh cone containing {tri} triangle",
             f"mesh cone imported with its {tri} triangles")
        fixes["wcone"] = r"mesh n_meshes 1 meshes cone"
        fixes["wcyl"] = r"primitive type 2 zcylinder (\S+) 0\.0 0\.0"
    if walls != "none":
        fixes["wfloor"] = r"primitive type 2 zplane (\S+)"
        if closed:
            fixes["wplate"] = r"primitive type 2 zplane 0\.0"
        need(r"^fix gravi all gravity 9\.81\S* vector 0\.0 0\.0 -1\.0\s*$", "gravity along -z")
    elif re.search(r"^fix \S+ all gravity", text, re.M):
        bad.append("gravity on in the `none` variant")
    for fid, geo in fixes.items():
        mm = re.search(rf"^fix {fid} all wall/gran {model} {geo} {settings}\s*$", text, re.M)
        if not mm:
            bad.append(f"wall fix {fid} ({geo}) with the deck's contact model not echoed")
        elif fid == "wcyl" and not report.rel_ok(float(mm.group(1)), float(deck["r_cyl"]), 1e-12):
            bad.append(f"zcylinder radius {mm.group(1)}, hopper.deck r_cyl {deck['r_cyl']}")
        elif fid == "wfloor" and not report.rel_ok(float(mm.group(1)), float(deck["z_floor"]),
                                                   1e-12):
            bad.append(f"floor at {mm.group(1)}, hopper.deck z_floor {deck['z_floor']}")
    extra = set(re.findall(r"^fix (\S+) all wall/gran", text, re.M)) - set(fixes) - {
        f + "c" for f in fixes}
    if extra:
        bad.append(f"unexpected wall fixes {sorted(extra)}")
    # discharge samples: every thermo row with nout (steps de-duplicated)
    dt = float(par["dt"])
    samples = {}
    for head, rows in report.thermo_blocks(text):
        if "nout" not in head:
            continue
        i = head.index("nout")
        for r in rows:
            samples[int(r[0])] = float(r[i])
    if not samples:
        bad.append("no thermo column nout (particles below the outlet)")
    out["samples"] = [(s * dt, c) for s, c in sorted(samples.items())]
    # wall touches after the run (untimed run 0)
    m = re.search(r"^\s*Step\s+Atoms\s+KinEng\s+csum((?:\s+twall\[\d+\])*)\s*\n\s*(.*)$", text,
                  re.M)
    if m:
        vals = m.group(2).split()
        out["cpp"] = float(vals[3]) / n
        out["touch"] = sum(float(v) for v in vals[4:]) / n if len(vals) > 4 else 0.0
    else:
        out["touch"] = math.nan
    return out, bad


def ours_hopper(path, samples_path, n, steps, warmup, threads, par, skin, deck, deckdir, variant,
                sample, fit_lo, fit_hi):
    text = open(path).read()
    found = None
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("{"):
            try:
                obj = json.loads(line)
            except ValueError:
                continue
            if obj.get("case") == "hopper" and "particle_steps_per_s" in obj:
                found = obj
    if found is None:
        raise ValueError(f"{path}: no hopper JSON object with 'particle_steps_per_s'")
    bad = []
    walls, closed = variant.replace("_closed", ""), variant.endswith("_closed")
    want = {"case": "hopper", "walls": walls, "closed": closed, "particles": n, "steps": steps,
            "warmup": warmup, "threads": threads, "sample_every": sample,
            "deck_dir": os.path.realpath(deckdir)}
    for k, v in want.items():
        got = found.get(k)
        if k == "deck_dir" and got is not None:
            got = os.path.realpath(got)
        if got != v:
            bad.append(f"{k} = {got!r}, expected {v!r}")
    if not report.rel_ok(float(found.get("dt_dem", math.nan)), float(par["dt"]), 1e-6):
        bad.append(f"dt_dem = {found.get('dt_dem')}, expected {float(par['dt']):.6e}")
    if not report.rel_ok(float(found.get("skin_factor", math.nan)), skin / float(deck["d_p"]),
                         1e-3):
        bad.append(f"skin_factor = {found.get('skin_factor')}, expected "
                   f"{skin / float(deck['d_p']):g}")
    if not report.rel_ok(float(found.get("ke_initial", math.nan)), float(par["ke_initial"]), 1e-9):
        bad.append(f"ke_initial = {found.get('ke_initial')!r} J, hopper.particles "
                   f"{par['ke_initial']} J")
    geo = found.get("geometry", {})
    for k in ("outlet_d", "r_cyl", "h_cone", "h_top", "z_floor"):
        if not report.rel_ok(float(geo.get(k, math.nan)), float(deck[k]), 1e-9):
            bad.append(f"geometry {k} = {geo.get(k)}, hopper.deck {deck[k]}")
    samples = []
    with open(samples_path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                w = line.split()
                samples.append((float(w[0]), float(w[1])))
    dis = found.get("discharge", {})
    rate = fit_rate(samples, n, fit_lo, fit_hi)[0]
    theirs = dis.get("rate_particles_per_s")
    if (rate is None) != (theirs is None) or (
            rate is not None and not report.rel_ok(rate, float(theirs), 1e-6)):
        bad.append(f"discharge rate {theirs} particles/s in the JSON, {rate} refitted from its "
                   "samples")
    return {"pss": float(found["particle_steps_per_s"]), "raw": found, "samples": samples,
            "cpp": float(found.get("contacts_per_particle", math.nan)),
            "touch": float(found.get("wall_contacts_per_particle", math.nan)),
            "wall_step": found.get("wall_contacts_per_step")}, bad


def fmt(v, spec):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "n/a"
    return format(v, spec)


def main(argv):
    if len(argv) != 12:
        print(__doc__, file=sys.stderr)
        return 1
    work = argv[0]
    n, steps, warmup, repeat = map(int, argv[1:5])
    variants, pairs = argv[5].split(), argv[6].split()
    load_max, skin = float(argv[7]), float(argv[8])
    sample = int(argv[9])
    fit_lo, fit_hi = float(argv[10]), float(argv[11])
    deckdir = os.path.join(work, "deck")
    deck = report.read_params(os.path.join(deckdir, "hopper.deck"))
    mass = float(deck["mass"])
    w_bev, w_lo, w_hi, rho_b = beverloo(deck)
    rows, problems = [], []
    for variant in variants:
        par = report.read_params(os.path.join(work, variant, "params.txt"))
        for pair in pairs:
            np_, th = map(int, pair.split(":"))
            rdir = os.path.join(work, variant, f"np{np_}_t{th}")
            lig, ours, loads = [], [], []
            for r in range(1, repeat + 1):
                try:
                    f, bad = liggghts_hopper(os.path.join(rdir, f"screen.liggghts.{r}"), n, steps,
                                             warmup, np_, par, skin, deck, deckdir, variant)
                    lig.append(f)
                    problems += [f"{variant} {np_} rank(s), LIGGGHTS run {r}: {b}" for b in bad]
                except OSError as e:
                    print(f"hopper_report.py: {e}", file=sys.stderr)
                    return 1
                except ValueError as e:
                    problems.append(f"{variant} {np_} rank(s), LIGGGHTS run {r}: {e}")
                p = os.path.join(rdir, f"ours.{r}.json")
                if os.path.exists(p):
                    try:
                        f, bad = ours_hopper(p, os.path.join(rdir, f"ours.{r}.samples"), n, steps,
                                             warmup, th, par, skin, deck, deckdir, variant, sample,
                                             fit_lo, fit_hi)
                        ours.append(f)
                        problems += [f"{variant} {th} thread(s), CoReDEM run {r}: {b}" for b in bad]
                    except (ValueError, OSError) as e:
                        problems.append(f"{variant} {th} thread(s), CoReDEM run {r}: {e}")
                for code in ("ours", "liggghts"):
                    lp = os.path.join(rdir, f"load.{code}.{r}")
                    if os.path.exists(lp):
                        loads.append(float(open(lp).read().split()[0]))
            if not lig:
                continue
            lig_m = statistics.median(x["pss"] for x in lig)
            ours_m = statistics.median(x["pss"] for x in ours) if ours else math.nan
            rows.append((variant, np_, th, lig_m, ours_m, ours_m / lig_m,
                         max(loads) if loads else math.nan, lig, ours))
    print()
    if problems:
        for p in problems:
            print(f"CHECK FAILED: {p}")
        print("\nNo figures: the runs above did not match the intended deck.")
        return 6
    print(f"hopper deck, N = {n}: D_o = {1e3 * float(deck['outlet_d']):.3g} mm, "
          f"R_c = {1e3 * float(deck['r_cyl']):.3g} mm, 30 deg cone, mu = {deck['mu']}; "
          f"{warmup} untimed + {steps} timed steps from the opening, {repeat} runs of each code, "
          "interleaved; medians of particle-steps/s over the timed loops")
    print(f"{'variant':17s} {'LIGGGHTS':>8s} {'CoReDEM':>8s} {'LIGGGHTS':>11s} {'CoReDEM':>11s} "
          f"{'ours/LIG':>9s} {'max load':>9s} {'nbr builds':>11s} {'discharged':>13s} "
          f"{'wall touches/p':>15s}")
    print(f"{'':17s} {'ranks':>8s} {'threads':>8s} {'p-steps/s':>11s} {'p-steps/s':>11s}"
          f"{'':>10s} {'before':>9s} {'LIG / ours':>11s} {'LIG / ours':>13s} {'LIG / ours':>15s}")
    for variant, np_, th, lig_m, ours_m, ratio, load, lig, ours in rows:
        label = " LOADED" if load >= load_max else ""
        ob = ours[-1]["raw"].get("rebuilds") if ours else None
        ld = lig[-1]["samples"][-1][1] / n if lig[-1]["samples"] else math.nan
        od = ours[-1]["samples"][-1][1] / n if ours and ours[-1]["samples"] else math.nan
        lt = lig[-1].get("touch", math.nan)
        ot = ours[-1]["touch"] if ours else math.nan
        print(f"{variant:17s} {np_:>8d} {th:>8d} {lig_m:11.4e} {fmt(ours_m, '11.4e'):>11s} "
              f"{fmt(ratio, '9.3f'):>9s} {load:9.2f} {str(lig[0]['builds']) + ' / ' + str(ob):>11s} "
              f"{fmt(100 * ld, '.1f') + '% / ' + fmt(100 * od, '.1f') + '%':>13s} "
              f"{fmt(lt, '.3f') + ' / ' + fmt(ot, '.3f'):>15s}{label}")
    print()
    print(f"Beverloo W = C rho_b sqrt(g) (D_o - k d_p)^2.5 = {w_bev:.4e} kg/s (C = {BEV_C}, "
          f"k = {BEV_K}, rho_b = {rho_b:.1f} kg/m^3 measured in the settled bed), band "
          f"{w_lo:.4e} .. {w_hi:.4e} kg/s (C {BEV_C_LO}-{BEV_C_HI}, k {BEV_K_LO}-{BEV_K_HI})")
    print(f"discharge rate: least-squares slope of the discharged mass over {100 * fit_lo:.0f}-"
          f"{100 * fit_hi:.0f} % of N discharged (last run of each code)")
    for variant, np_, th, lig_m, ours_m, ratio, load, lig, ours in rows:
        if variant.endswith("_closed") or variant == "none":
            continue
        for code, runs in (("LIGGGHTS", lig), ("CoReDEM", ours)):
            if not runs:
                continue
            rate, t0, t1, pts, complete, end = fit_rate(runs[-1]["samples"], n, fit_lo, fit_hi)
            if rate is None:
                print(f"  {variant:9s} {code:8s} n/a ({pts} samples in the window; the run ends at "
                      f"{100 * end:.1f} % discharged: more STEPS)")
                continue
            w = rate * mass
            band = "in the band" if w_lo <= w <= w_hi else "OUTSIDE the band"
            print(f"  {variant:9s} {code:8s} {w:.4e} kg/s = {rate:.0f} particles/s, "
                  f"{w / w_bev:.3f} x Beverloo, {band} (t = {t0:.4f}..{t1:.4f} s, {pts} samples"
                  f"{'' if complete else ', window not completed: fitted up to the end'})")
    by = {(v, np_, th): (lig_m, ours_m, lig, ours) for v, np_, th, lig_m, ours_m, _, _, lig, ours
          in rows}
    cost_rows = []
    for pair in pairs:
        np_, th = map(int, pair.split(":"))
        ref = by.get(("none", np_, th))
        if not ref:
            continue
        for v in ("primitive_closed", "stl_closed"):
            if (v, np_, th) in by:
                cost_rows.append((v, np_, th, by[(v, np_, th)], ref))
    if cost_rows:
        print()
        print("Cost of the walls: the settled bed at rest in the hopper (outlet closed) against the "
              "same bed without walls or gravity (`none`); ns per particle-step (medians), the "
              "difference per wall touch")
        print(f"{'variant':17s} {'ranks/thr':>9s} {'code':>8s} {'closed':>9s} {'none':>9s} "
              f"{'walls':>9s} {'walls %':>8s} {'touches/p':>10s} {'ns/touch':>9s}")
        for v, np_, th, (lm, om, lig, ours), (rlm, rom, rlig, rours) in cost_rows:
            for code, a, b, runs, who in (("LIGGGHTS", lm, rlm, lig, np_), ("CoReDEM", om, rom, ours,
                                                                             th)):
                if not runs or math.isnan(a) or math.isnan(b):
                    continue
                ta, tb = 1e9 / a, 1e9 / b
                touch = runs[-1].get("touch", math.nan)
                per = (ta - tb) / touch if touch and not math.isnan(touch) else math.nan
                print(f"{v:17s} {who:>9d} {code:>8s} {ta:9.1f} {tb:9.1f} {ta - tb:9.1f} "
                      f"{100 * (ta - tb) / ta:7.1f}% {fmt(touch, '10.3f'):>10s} "
                      f"{fmt(per, '9.1f'):>9s}")
        print("(touches: LIGGGHTS counts the particles touching each wall fix, CoReDEM its wall "
              "contacts, both at the end of the run; `none` loses contacts as the bed relaxes "
              "without gravity, so part of the difference is the pair work of the held bed)")
    print()
    for variant, np_, th, lig_m, ours_m, ratio, load, lig, ours in rows:
        print(f"{variant} {np_}/{th}: LIGGGHTS per run "
              + ", ".join(format(x["pss"], ".3e") for x in lig)
              + ("; CoReDEM per run " + ", ".join(format(x["pss"], ".3e") for x in ours)
                 if ours else ""))
    print("Checked before the figures: LIGGGHTS' echoed neighbour, timestep, run, read_data, pair "
          "style, friction and wall lines (radius, floor, meshes with their triangle counts), its "
          "thermo Dt, step range and atom count, loop step and rank counts, no dangerous builds; "
          "both codes' initial kinetic energy against hopper.particles (same settled bed), "
          "CoReDEM's deck, geometry and its own rate fit.")
    print(f"LOADED: the 1-min load average before a run of that row was >= {load_max}.")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
