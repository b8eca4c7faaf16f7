#!/usr/bin/env python3
"""Write a coupled case whose cost is the exchange: many cells, few particles.

    make_overhead_case.py CELLS STEPS OUTDIR [--particles P]

writes OUTDIR/case.yaml and OUTDIR/openfoam/ (coredemFoam + coredem-dem, cpu backend,
2 threads): a cube of n x n x n cells of 3.33 mm with n = round(CELLS^(1/3)), P glass beads
(default 100) resting on the bottom, air rising at 0.3 m/s, fixed CFD step 1 ms, STEPS steps,
no checkpoints, no snapshots. Used by overhead.sh (docs/performance.md, "Coupling overhead").
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_case as mc  # noqa: E402  (the dictionaries of the DPMFoam comparison)

H = 0.01 / 3.0  # m, cell size (as the fluidized bed's)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cells", type=int)
    ap.add_argument("steps", type=int)
    ap.add_argument("outdir")
    ap.add_argument("--particles", type=int, default=100)
    a = ap.parse_args()
    n = max(2, round(a.cells ** (1.0 / 3.0)))
    if a.steps < 1 or a.particles < 1:
        sys.exit("make_overhead_case.py: STEPS and --particles must be >= 1")
    side = n * H
    per_row = int(side / (1.05 * mc.D_P))
    if a.particles > per_row * per_row:
        sys.exit(f"make_overhead_case.py: {a.particles} particles do not fit one layer of a {n}^3 grid")
    dt = 1.0e-3
    o = os.path.join(a.outdir, "openfoam")
    mc.BOX = (side, side, side)
    mc.CELLS = (n, n, n)
    mc.U_IN = 0.3
    mc.foam(f"{o}/system/blockMeshDict", a.particles, "dictionary", "system", "blockMeshDict",
            mc.block_mesh("patch", "patch"))
    pos = []
    for k in range(a.particles):
        i, j = k % per_row, k // per_row
        pos.append(((i + 0.5) * 1.05 * mc.D_P, 0.5 * mc.D_P * 1.02, (j + 0.5) * 1.05 * mc.D_P))
    mc.write_coredem(a.outdir, a.particles, dt * a.steps, 1e9, pos, heat=True)
    # overwrite the generated case.yaml's time/grid/walls for this cube
    path = os.path.join(a.outdir, "coredem", "case.yaml")
    text = open(path).read()
    text = text.replace("  adaptive: {courant: 0.5, dt_min: 1.0e-5, dt_max: 1.0e-3, max_growth: 1.2}\n", "")
    text = text.replace("  dt: 5.0e-4\n", f"  dt: {dt}\n")
    text = text.replace(f"name: dpmfoam-peer-{a.particles}", f"name: overhead-{n**3}")
    # a 10^6-cell step takes minutes on a loaded 2-core machine: generous deadlines
    text = text.replace("  case: openfoam\n", "  case: openfoam\n  timeout_s: 1800\n")
    text = text.replace("  threads: 2\n", "  threads: 2\n  timeout_s: 1800\n")
    os.makedirs(a.outdir, exist_ok=True)
    # write_coredem wrote into OUTDIR/coredem: move it up one level
    import shutil
    src = os.path.join(a.outdir, "coredem")
    shutil.rmtree(os.path.join(a.outdir, "openfoam"), ignore_errors=True)
    shutil.move(os.path.join(src, "openfoam"), os.path.join(a.outdir, "openfoam"))
    with open(os.path.join(a.outdir, "case.yaml"), "w") as f:
        f.write(text)
    shutil.rmtree(src)
    print(f"cells = {n**3} ({n}^3), particles = {a.particles}, steps = {a.steps}, dt = {dt}")


if __name__ == "__main__":
    main()
