#!/usr/bin/env python3
"""Check and tabulate the runs of compare.sh.

    report.py WORKDIR N STEPS WARMUP REPEAT "DECKS" "NP:THREADS ..." LOAD_MAX SKIN

reads, for each deck and pairing, WORKDIR/DECK/deck.txt (make_deck.py's parameters) and in
WORKDIR/DECK/npR_tT/: screen.liggghts.<r> (LIGGGHTS' screen output with the input echoed),
ours.<r>.json (`coredem-bench dem --json`), load.{liggghts,ours}.<r> (1-min load average before
the run), r = 1..REPEAT.

Before a ratio is printed every run is checked against the intended deck. LIGGGHTS: the echoed
`neighbor SKIN bin`, `neigh_modify delay 0 every 1 check yes`, `timestep DT`, `run WARMUP` and
`run STEPS [pre no]`; the thermo `Dt` column equal to DT; the timed run's thermo from step
WARMUP to WARMUP+STEPS with N atoms throughout; its `Loop time ... on NP procs for STEPS steps
with N atoms`; an MPI grid of NP ranks; no dangerous neighbour builds; the step-0 kinetic energy
equal to make_deck.py's ke_initial. CoReDEM: case, particles, steps, warm-up, threads, dt_dem,
skin and ke_initial as intended. A mismatch is printed as CHECK FAILED and the exit status is 6
(0 otherwise; 1 if a LIGGGHTS output file is missing).
"""

import json
import math
import os
import re
import statistics
import sys

D_P = 1.0e-3


def rel_ok(a, b, tol):
    return abs(a - b) <= tol * max(abs(a), abs(b), 1e-300)


def read_params(path):
    out = {}
    with open(path) as f:
        for line in f:
            if " = " in line:
                k, v = line.split(" = ", 1)
                out[k.strip()] = v.strip()
    return out


def thermo_blocks(text):
    """[(header, rows)] of the thermo tables (rows: lists of words)."""
    blocks = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        if re.match(r"^\s*Step\s+Atoms\s", lines[i]):
            head = lines[i].split()
            rows = []
            i += 1
            while i < len(lines) and re.match(r"^\s*\d+\s", lines[i]):
                rows.append(lines[i].split())
                i += 1
            blocks.append((head, rows))
        else:
            i += 1
    return blocks


def parse_liggghts(path, n, steps, warmup, np_, par, skin):
    """(figures, [problems])"""
    text = open(path).read()
    bad = []
    dt = float(par["dt"])
    loop_re = r"Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms"
    loops = list(re.finditer(loop_re, text))
    want = [warmup, steps] if warmup > 0 else [steps]
    got = [int(m.group(3)) for m in loops]
    # the timed loop: the second run with a warm-up, else the first (the third, if any, is the
    # untimed `run 0` that counts contacts)
    k = 1 if warmup > 0 else 0
    if len(loops) <= k or got[:len(want)] != want:
        raise ValueError(f"{path}: loops of {got} steps, expected {want} (then the run 0)")
    loop = loops[k].groups()
    tail = text[loops[k].end():]
    out = {"loop": float(loop[0])}
    out["pss"] = n * steps / out["loop"]
    # echoed input
    def echoed(pattern, what):
        if not re.search(pattern, text, re.M):
            bad.append(f"input line '{what}' not echoed by LIGGGHTS")
    m = re.search(r"^neighbor\s+(\S+)\s+bin", text, re.M)
    if not m or not rel_ok(float(m.group(1)), skin, 1e-12):
        bad.append(f"neighbor skin {m.group(1) if m else 'missing'}, expected {skin!r}")
    echoed(r"^neigh_modify\s+delay 0 every 1 check yes\s*$", "neigh_modify delay 0 every 1 check yes")
    m = re.search(r"^timestep\s+(\S+)", text, re.M)
    if not m or not rel_ok(float(m.group(1)), dt, 1e-15):
        bad.append(f"timestep {m.group(1) if m else 'missing'}, expected {dt!r}")
    if warmup > 0:
        echoed(rf"^run\s+{warmup}\s*$", f"run {warmup}")
        echoed(rf"^run\s+{steps}\s+pre no\s*$", f"run {steps} pre no")
    else:
        echoed(rf"^run\s+{steps}\s*$", f"run {steps}")
    # thermo: Dt, step range, atoms, initial kinetic energy
    blocks = [b for b in thermo_blocks(text) if "Dt" in b[0]]
    if len(blocks) < 1:
        bad.append("no thermo output with Dt")
    else:
        for head, rows in blocks:
            idt = head.index("Dt")
            for r in rows:
                if not rel_ok(float(r[idt]), dt, 1e-15):
                    bad.append(f"thermo Dt {r[idt]} at step {r[0]}, expected {dt!r}")
                    break
                if int(r[1]) != n:
                    bad.append(f"{r[1]} atoms at step {r[0]}, expected {n}")
                    break
        first = blocks[0][1][0]
        ke0 = float(first[blocks[0][0].index("KinEng")])
        ke_int = float(par["ke_initial"])
        if int(first[0]) != 0:
            bad.append(f"first thermo step {first[0]}, expected 0")
        if not (rel_ok(ke0, ke_int, 1e-9) or (ke_int == 0 and ke0 == 0)):
            bad.append(f"kinetic energy at step 0 {ke0!r} J, make_deck.py {ke_int!r} J")
        out["ke0"] = ke0
        timed_rows = blocks[-1][1]
        if (int(timed_rows[0][0]) != warmup or int(timed_rows[-1][0]) != warmup + steps):
            bad.append(f"timed run from step {timed_rows[0][0]} to {timed_rows[-1][0]}, expected "
                       f"{warmup} to {warmup + steps}")
    # per-run figures: those printed after the timed loop
    grid = re.search(r"(\d+) by (\d+) by (\d+) MPI processor grid", text)
    out["grid"] = "x".join(grid.groups()) if grid else "?"
    if grid and math.prod(int(g) for g in grid.groups()) != np_:
        bad.append(f"MPI grid {out['grid']}, expected {np_} ranks")
    builds = re.search(r"Neighbor list builds = (\d+)", tail)
    out["builds"] = int(builds.group(1)) if builds else None
    dang = re.search(r"Dangerous builds = (\d+)", tail)
    if dang and int(dang.group(1)) != 0:
        bad.append(f"{dang.group(1)} dangerous neighbour builds")
    mem = re.search(r"Memory usage per processor = (\S+) Mbytes", text)
    out["mem_mb"] = float(mem.group(1)) if mem else math.nan
    out["split"] = {k: float(v) for k, v in
                    re.findall(r"^(Pair|Neigh|Comm|Outpt|Other)\s+time \(%\) = (\S+)", tail, re.M)[:5]}
    m = re.search(r"Step\s+Atoms\s+KinEng\s+csum\s*\n\s*\d+\s+\d+\s+\S+\s+(\S+)", text)
    out["cpp"] = float(m.group(1)) / n if m else math.nan
    return out, bad


def parse_ours(path, deck, n, steps, warmup, threads, par, skin):
    text = open(path).read()
    found = None
    dec = json.JSONDecoder()
    for i, c in enumerate(text):
        if c == "{":
            try:
                obj, _ = dec.raw_decode(text[i:])
            except ValueError:
                continue
            if isinstance(obj, dict) and "particle_steps_per_s" in obj:
                found = obj
    if found is None:
        raise ValueError(f"{path}: no JSON object with 'particle_steps_per_s'")
    bad = []
    want = {"case": deck, "particles": n, "steps": steps, "warmup": warmup, "threads": threads}
    for k, v in want.items():
        if found.get(k) != v:
            bad.append(f"{k} = {found.get(k)!r}, expected {v!r}")
    if not rel_ok(float(found.get("dt_dem", math.nan)), float(par["dt"]), 1e-6):
        bad.append(f"dt_dem = {found.get('dt_dem')}, expected {float(par['dt']):.6e}")
    if not rel_ok(float(found.get("skin_factor", math.nan)), skin / D_P, 1e-3):
        bad.append(f"skin_factor = {found.get('skin_factor')}, expected {skin / D_P:g}")
    ke_int = float(par["ke_initial"])
    ke = float(found.get("ke_initial", math.nan))
    if not (rel_ok(ke, ke_int, 1e-9) or (ke_int == 0 and ke == 0)):
        bad.append(f"ke_initial = {ke!r} J, make_deck.py {ke_int!r} J")
    return {"pss": float(found["particle_steps_per_s"]), "raw": found,
            "cpp": float(found.get("contacts_per_particle", math.nan))}, bad


def fmt(v, spec):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "n/a"
    return format(v, spec)


def main(argv):
    if len(argv) != 9:
        print(__doc__, file=sys.stderr)
        return 1
    work = argv[0]
    n, steps, warmup, repeat = map(int, argv[1:5])
    decks, pairs = argv[5].split(), argv[6].split()
    load_max, skin = float(argv[7]), float(argv[8])
    rows, problems, notes = [], [], []
    for deck in decks:
        par = read_params(os.path.join(work, deck, "deck.txt"))
        for pair in pairs:
            np_, th = map(int, pair.split(":"))
            rdir = os.path.join(work, deck, f"np{np_}_t{th}")
            lig, ours, loads = [], [], []
            for r in range(1, repeat + 1):
                try:
                    f, bad = parse_liggghts(os.path.join(rdir, f"screen.liggghts.{r}"), n, steps,
                                            warmup, np_, par, skin)
                    lig.append(f)
                    problems += [f"{deck} {np_} rank(s), LIGGGHTS run {r}: {b}" for b in bad]
                except OSError as e:
                    print(f"report.py: {e}", file=sys.stderr)
                    return 1
                except ValueError as e:  # not the intended loops: a mismatch, not a crash
                    problems.append(f"{deck} {np_} rank(s), LIGGGHTS run {r}: {e}")
                p = os.path.join(rdir, f"ours.{r}.json")
                if os.path.exists(p):
                    try:
                        f, bad = parse_ours(p, deck, n, steps, warmup, th, par, skin)
                        ours.append(f)
                        problems += [f"{deck} {th} thread(s), CoReDEM run {r}: {b}" for b in bad]
                    except ValueError as e:
                        problems.append(str(e))
                for code in ("ours", "liggghts"):
                    lp = os.path.join(rdir, f"load.{code}.{r}")
                    if os.path.exists(lp):
                        loads.append(float(open(lp).read().split()[0]))
            if not lig:
                continue
            lig_m = statistics.median(x["pss"] for x in lig)
            ours_m = statistics.median(x["pss"] for x in ours) if ours else math.nan
            rows.append((deck, np_, th, lig_m, ours_m, ours_m / lig_m, max(loads) if loads else
                         math.nan, lig, ours))
    print()
    if problems:
        for p in problems:
            print(f"CHECK FAILED: {p}")
        print("\nNo ratios: the runs above did not match the intended deck.")
        return 6
    print(f"N = {n}, {warmup} untimed + {steps} timed steps, {repeat} runs of each code, "
          "interleaved (CoReDEM, LIGGGHTS, ...); medians of particle-steps/s over the timed loops")
    print(f"{'deck':9s} {'LIGGGHTS':>12s} {'CoReDEM':>10s} {'LIGGGHTS':>11s} {'CoReDEM':>11s} "
          f"{'ours/LIGGGHTS':>14s} {'max load':>9s} {'nbr builds':>11s} {'contacts/p':>11s}")
    print(f"{'':9s} {'ranks':>12s} {'threads':>10s} {'p-steps/s':>11s} {'p-steps/s':>11s}"
          f"{'':>15s} {'before':>9s} {'LIG / ours':>11s} {'LIG / ours':>11s}")
    for deck, np_, th, lig_m, ours_m, ratio, load, lig, ours in rows:
        label = " LOADED" if load >= load_max else ""
        ob = ours[-1]["raw"].get("rebuilds") if ours else None
        print(f"{deck:9s} {np_:>12d} {th:>10d} {lig_m:11.4e} {fmt(ours_m, '11.4e'):>11s} "
              f"{fmt(ratio, '14.3f'):>14s} {load:9.2f} {str(lig[0]['builds']) + ' / ' + str(ob):>11s} "
              f"{fmt(lig[-1]['cpp'], '.2f') + ' / ' + fmt(ours[-1]['cpp'] if ours else math.nan, '.2f'):>11s}"
              f"{label}")
    print()
    for deck, np_, th, lig_m, ours_m, ratio, load, lig, ours in rows:
        print(f"{deck} {np_}/{th}: LIGGGHTS per run " + ", ".join(format(x["pss"], ".3e") for x in lig)
              + ("; CoReDEM per run " + ", ".join(format(x["pss"], ".3e") for x in ours) if ours else ""))
        split = lig[0]["split"]
        total = sum(split.values())
        if total > 0:
            print("   LIGGGHTS time split (run 1): "
                  + ", ".join(f"{k} {100 * v / total:.0f}%" for k, v in split.items()))
    print("Checked before the ratios: LIGGGHTS' echoed neighbour, timestep and run lines, its thermo "
          "Dt, step range and atom count, its loop's step and rank counts, no dangerous builds, and "
          "both codes' initial kinetic energy against make_deck.py's (same particles and velocities).")
    print(f"LOADED: the 1-min load average before a run of that row was >= {load_max}.")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
