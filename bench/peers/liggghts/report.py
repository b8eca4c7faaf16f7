#!/usr/bin/env python3
"""Parse the runs of compare.sh and print the comparison table.

    report.py WORKDIR N STEPS NP THREADS REPEAT

reads WORKDIR/screen.liggghts.<r> (LIGGGHTS screen output) and, where present,
WORKDIR/ours.<r>.json (stdout of `coredem-bench dem ... --json`) for r = 1..REPEAT.
Exit status 0 if every LIGGGHTS run parsed, 1 otherwise; the status of our runs is printed.
"""

import json
import math
import os
import re
import statistics
import sys


def parse_liggghts(path, n, steps):
    text = open(path).read()
    loops = re.findall(r"Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms", text)
    if not loops or int(loops[0][2]) != steps or int(loops[0][3]) != n:
        raise ValueError(f"{path}: no 'Loop time ... for {steps} steps with {n} atoms'")
    out = {"loop": float(loops[0][0])}
    out["pss"] = n * steps / out["loop"]
    grid = re.search(r"(\d+) by (\d+) by (\d+) MPI processor grid", text)
    out["grid"] = "x".join(grid.groups()) if grid else "?"
    builds = re.search(r"Neighbor list builds = (\d+)", text)
    out["builds"] = int(builds.group(1)) if builds else None
    mem = re.search(r"Memory usage per processor = (\S+) Mbytes", text)
    out["mem_mb"] = float(mem.group(1)) if mem else math.nan
    # Time split of the timed run (LIGGGHTS' own breakdown).
    out["split"] = {k: float(v) for k, v in
                    re.findall(r"^(Pair|Neigh|Comm|Outpt|Other)\s+time \(%\) = (\S+)", text, re.M)[:5]}
    # The untimed `run 0` after the timed run prints c_csum: the sum over particles of their
    # particle-particle contact counts (each pair counted at both ends).
    m = re.search(r"Step\s+Atoms\s+KinEng\s+csum\s*\n\s*\d+\s+\d+\s+\S+\s+(\S+)", text)
    out["cpp"] = float(m.group(1)) / n if m else math.nan
    return out


def parse_ours(path):
    text = open(path).read()
    dec = json.JSONDecoder()
    found = None
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

    def num(*keys):
        for k in keys:
            v = found.get(k)
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                return float(v)
        return math.nan

    return {
        "pss": float(found["particle_steps_per_s"]),
        "cpp": num("contacts_per_particle", "contacts_per_particle_pp"),
        "bpp": num("bytes_per_particle", "memory_bytes_per_particle"),
        "loop": num("loop_seconds", "loop_time_s", "seconds", "elapsed_s", "wall_s"),
        "raw": found,
    }


def fmt(v, spec):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "n/a"
    return format(v, spec)


def main(argv):
    work, n, steps, np_, threads, repeat = argv[0], *map(int, argv[1:6])
    lig, ours, ours_errors = [], [], []
    for r in range(1, repeat + 1):
        lig.append(parse_liggghts(os.path.join(work, f"screen.liggghts.{r}"), n, steps))
        p = os.path.join(work, f"ours.{r}.json")
        if os.path.exists(p):
            try:
                ours.append(parse_ours(p))
            except ValueError as e:
                ours_errors.append(str(e))

    def med(rows, key):
        return statistics.median(row[key] for row in rows)

    lig_pss = med(lig, "pss")
    lig_bpp = lig[0]["mem_mb"] * 1048576 * np_ / n
    print()
    print(f"{'code':9s} {'parallelism':>13s} {'loop [s]':>9s} {'particle-steps/s':>17s} "
          f"{'(best)':>11s} {'contacts/particle':>18s} {'bytes/particle':>15s}")
    print(f"{'LIGGGHTS':9s} {f'{np_} MPI ' + lig[0]['grid']:>13s} {fmt(med(lig, 'loop'), '.3f'):>9s} "
          f"{fmt(lig_pss, '.4e'):>17s} {fmt(max(x['pss'] for x in lig), '.3e'):>11s} "
          f"{fmt(lig[-1]['cpp'], '.3f'):>18s} {fmt(lig_bpp, '.0f'):>15s}")
    if ours:
        ours_pss = med(ours, "pss")
        print(f"{'CoReDEM':9s} {f'{threads} threads':>13s} {fmt(med(ours, 'loop'), '.3f'):>9s} "
              f"{fmt(ours_pss, '.4e'):>17s} {fmt(max(x['pss'] for x in ours), '.3e'):>11s} "
              f"{fmt(ours[-1]['cpp'], '.3f'):>18s} {fmt(ours[-1]['bpp'], '.0f'):>15s}")
        print(f"\nratio ours/LIGGGHTS (median particle-steps/s): {ours_pss / lig_pss:.3f}")
    print()
    print(f"runs: {repeat} of each, interleaved (LIGGGHTS, CoReDEM, LIGGGHTS, ...); median shown, "
          "best in brackets.")
    print("LIGGGHTS per run [particle-steps/s]: "
          + ", ".join(format(x["pss"], ".3e") for x in lig))
    if ours:
        print("CoReDEM  per run [particle-steps/s]: "
              + ", ".join(format(x["pss"], ".3e") for x in ours))
    split = lig[0]["split"]
    if split:
        total = sum(split.values())
        print("LIGGGHTS time split (run 1): "
              + ", ".join(f"{k} {100 * v / total:.0f}%" for k, v in split.items() if total > 0)
              + "  (Other = integration, gravity and the six wall fixes)")
    print(f"LIGGGHTS neighbour-list builds during the timed loop: {lig[0]['builds']}")
    if ours:
        raw = ours[-1]["raw"]
        extras = [f"{k} = {raw[k]}" for k in ("rebuilds", "skin_factor", "wall_contacts_per_particle",
                                              "setup_s", "stage_s") if k in raw]
        if extras:
            print("CoReDEM (last run): " + ", ".join(extras))
    print("Timed loops only: LIGGGHTS' 'Loop time' (read_data, setup, the first neighbour build and")
    print("force evaluation excluded); CoReDEM's own timed step loop (its setup excluded).")
    print("contacts/particle: LIGGGHTS counts particle-particle contacts per particle after the last")
    print("step (each pair at both ends, walls not counted); CoReDEM as its JSON reports it.")
    print("bytes/particle: LIGGGHTS' own 'Memory usage per processor' x ranks / N.")
    for e in ours_errors:
        print(f"CoReDEM output not parsable: {e}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
