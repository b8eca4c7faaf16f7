#!/usr/bin/env python3
"""Check the parameter translation of make_deck.py with LIGGGHTS itself.

    verify_restitution.py [--liggghts BIN] [--keep DIR]

Runs two tiny serial LIGGGHTS decks with exactly the contact settings of the packed deck
(same pair style, wall fix, property/global values and time step), no gravity:

1. particle-particle: two spheres touching, approaching head-on at 0.5 m/s each;
2. particle-wall: one sphere touching the plane z = 0, approaching it at 0.5 m/s;

each at the deck's dt = t_col/50 and at dt/4, and prints the measured rebound ratio
|v_n,out / v_n,in| against e_n = 0.97 (docs/physics.md Eq. 11/13) and, for the pair, the contact
duration against t_col (docs/physics.md Eq. 12). Exit status 1 if a rebound ratio is off by more than
TOL_E (dt) or TOL_E_FINE (dt/4), see below, or the duration by more than 2 time steps.
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_deck  # noqa: E402

# LIGGGHTS' velocity Verlet evaluates the dashpot with half-step velocities, so the rebound
# ratio carries an O(dt/t_col) integrator error on top of the exact translation of Eq. 13:
# measured +1.2e-3 (pair) and +7.8e-4 (wall) at dt = t_col/50, +2.9e-4 and +1.8e-4 at dt/4.
# The check therefore runs the deck's dt (tolerance TOL_E) and dt/4 (tolerance TOL_E_FINE):
# convergence towards e_n as dt shrinks is what shows the translation is right.
TOL_E = 2.0e-3
TOL_E_FINE = 5.0e-4
REFINE = 4
V0 = 0.5          # m/s approach speed of each body
STEPS = 200       # 4 t_col at the deck's dt: the contact (1 t_col) is long over


def deck(mat, kind, refine):
    d = mat["d_p"]
    r = 0.5 * d
    half = 20.0 * d
    gap = 1.0e-9 * d  # start just apart, so the whole contact is resolved
    if kind == "pp":
        atoms = [(1, -r - 0.5 * gap, 0.0, 0.0, V0), (2, r + 0.5 * gap, 0.0, 0.0, -V0)]
        lo = -half
        walls = ""
        probe = "variable va equal vx[1]\nvariable vb equal vx[2]\n"
    else:
        atoms = [(1, 0.0, 0.0, r + gap, -V0)]
        lo = 0.0
        walls = (f"fix wallzlo all wall/gran {make_deck.WALL_MODEL} primitive type 2 zplane 0.0 "
                 f"{make_deck.WALL_SETTINGS}\n")
        probe = "variable va equal vz[1]\nvariable vb equal 0.0\n"
    lines = [
        "units si", "atom_style granular", "atom_modify map array", "boundary f f f",
        "newton off", "communicate single vel yes",
        f"region box block {-half!r} {half!r} {-half!r} {half!r} {lo!r} {half!r} units box",
        "create_box 2 box",
        f"neighbor {0.1 * d!r} bin", "neigh_modify delay 0 every 1 check yes",
        make_deck.property_block(mat),
        f"pair_style gran {make_deck.MODEL}", "pair_coeff * *",
        walls,
    ]
    for aid, x, y, z, v in atoms:
        # create_atoms single places at exact coordinates; then set diameter, density, velocity.
        lines.append(f"create_atoms 1 single {x!r} {y!r} {z!r} units box")
    lines.append(f"set group all diameter {d!r}")
    lines.append(f"set group all density {mat['rho_p']!r}")
    for aid, x, y, z, v in atoms:
        comp = "vx" if kind == "pp" else "vz"
        lines.append(f"set atom {aid} {comp} {v!r}")
    lines += [
        "fix integr all nve/sphere",
        f"timestep {mat['dt'] / refine!r}",
        probe,
        "compute cpa all contact/atom",
        "compute csum all reduce sum c_cpa",
        "thermo_style custom step v_va v_vb c_csum",
        "thermo_modify format float %.17g norm no",
        "thermo 1",
        f"run {STEPS * refine}",
    ]
    return "\n".join(lines) + "\n"


def run(binary, workdir, kind, mat, refine=1):
    path = os.path.join(workdir, f"in.{kind}.dt{refine}")
    with open(path, "w") as f:
        f.write(deck(mat, kind, refine))
    proc = subprocess.run([binary, "-in", path, "-log", "none"], cwd=workdir,
                          capture_output=True, text=True, timeout=120)
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout[-3000:] + proc.stderr[-3000:])
        raise SystemExit(f"error: LIGGGHTS failed on the {kind} deck ({path})")
    rows = []
    for line in proc.stdout.splitlines():
        m = re.match(r"^\s*(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s*$", line)
        if m:
            rows.append((int(m.group(1)), float(m.group(2)), float(m.group(3)), float(m.group(4))))
    if len(rows) != STEPS * refine + 1:
        raise SystemExit(f"error: expected {STEPS + 1} thermo rows from the {kind} deck, "
                         f"got {len(rows)}")
    return rows


def rebound(rows):
    """|relative normal velocity after / before| from the first and last thermo rows."""
    return abs((rows[-1][1] - rows[-1][2]) / (rows[0][1] - rows[0][2]))


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--liggghts", default=os.environ.get("LIGGGHTS", "liggghts"))
    ap.add_argument("--keep", help="write the decks to this directory and keep them")
    args = ap.parse_args(argv)
    if shutil.which(args.liggghts) is None:
        raise SystemExit(f"error: '{args.liggghts}' not found; install it with "
                         "scripts/install-deps.sh --with-peers (Debian package liggghts)")
    mat = make_deck.material()
    workdir = args.keep or tempfile.mkdtemp(prefix="coredem-lig-e-")
    os.makedirs(workdir, exist_ok=True)
    ok = True
    try:
        pp = run(args.liggghts, workdir, "pp", mat)
        e_pp = rebound(pp)
        # contact steps: steps whose end-of-step state has the pair in contact (csum = 2)
        n_contact = sum(1 for row in pp[1:] if row[3] > 0)
        dur = n_contact * mat["dt"]
        e_pw = rebound(run(args.liggghts, workdir, "pw", mat))
        e_pp_fine = rebound(run(args.liggghts, workdir, "pp", mat, REFINE))
        e_pw_fine = rebound(run(args.liggghts, workdir, "pw", mat, REFINE))
    finally:
        if not args.keep:
            shutil.rmtree(workdir, ignore_errors=True)
    e_n = mat["e_n"]
    print(f"e_n target = {e_n}; dt = t_col/50 = {mat['dt']:.6e} s")
    checks = [
        ("particle-particle, dt", e_pp, TOL_E),
        ("particle-wall, dt", e_pw, TOL_E),
        (f"particle-particle, dt/{REFINE}", e_pp_fine, TOL_E_FINE),
        (f"particle-wall, dt/{REFINE}", e_pw_fine, TOL_E_FINE),
    ]
    for name, e, tol in checks:
        print(f"{name:24s} rebound ratio = {e:.6f}  (e - e_n = {e - e_n:+.2e}, tolerance {tol:.0e})")
        if abs(e - e_n) > tol:
            print(f"FAIL: {name}: rebound ratio {e:.6f} is off e_n = {e_n} by more than {tol}")
            ok = False
    print(f"pair contact duration = {dur:.6e} s = {n_contact} steps; t_col = {mat['t_col']:.6e} s "
          f"= {mat['t_col'] / mat['dt']:.1f} steps (tolerance 2 steps)")
    if abs(dur - mat["t_col"]) > 2.0 * mat["dt"]:
        print("FAIL: pair contact duration differs from t_col by more than 2 steps")
        ok = False
    print("restitution check:", "PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
