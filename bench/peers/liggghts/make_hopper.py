#!/usr/bin/env python3
"""Write the LIGGGHTS version of the `hopper` deck of bench/decks.md.

    make_hopper.py DECKDIR STEPS [--walls primitive|stl|none] [--closed] [--warmup W]
                   [--skin METRES] [--sample K] [--contacts]

DECKDIR is a deck directory written by `coredem-bench dem --case hopper --deck-dir DECKDIR
--settle-only` (or any hopper run with --deck-dir): hopper.deck (the parameters), hopper.particles
(the settled bed: positions, velocities, spins in global-id order), hopper.stl, cone.stl and
bin.stl (ASCII). This script adds DECKDIR/hopper.data (the same particles for `read_data`, atom ID
= global id + 1) and DECKDIR/in.hopper_VARIANT (VARIANT = primitive, stl, none, with `_closed`
for --closed), and prints the derived parameters as `key = value` lines (hopper_report.py reads
them).

The walls, as CoReDEM's variants (bench/commands/hopper.cpp):
  stl        fix mesh/surface hopper.stl + bin.stl (the same files CoReDEM reads with readStl),
             one fix wall/gran ... mesh n_meshes 2 meshes hopper bin
  primitive  LIGGGHTS has no cone primitive: the cone is cone.stl (mesh), the cylinder is the
             primitive `zcylinder R_c 0 0` (infinite, as CoReDEM's primitive cylinder here: it
             is the bin's wall too); CoReDEM's primitive variant uses its analytic cone instead
  none       the settled bed alone: no walls, no gravity (reference for the wall cost)
plus, except for `none`, the bin's floor `zplane z_floor` and with --closed the outlet plate
`zplane 0`. Every wall has the wall material type 2 (m_eff = m in the damping table).

The contact law is make_deck.py's (hooke/stiffness, absolute damping, tangential history,
limitForce off; same k_n, k_t, gamma tables) with the hopper's friction mu = 0.5 for
particle-particle and particle-wall pairs.

The input runs W untimed steps (`run W`) and then the timed `run STEPS pre no`; thermo every K
steps (--sample, as coredem-bench --sample) prints the number of particles below the outlet
plane z = 0 (`v_nout`), from which hopper_report.py fits the discharge rate. With --contacts an
untimed `run 0` afterwards counts particle-particle contacts (compute contact/atom) and the
particles touching each wall (the wall fixes re-created with store_force yes).
"""

import argparse
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import make_deck  # noqa: E402  (material(), property_block(), the contact-model strings)

VARIANTS = ("primitive", "stl", "none")


def read_deck(deckdir):
    path = os.path.join(deckdir, "hopper.deck")
    if not os.path.exists(path):
        raise SystemExit(f"make_hopper.py: {path} not found: write the deck first with "
                         f"coredem-bench dem --case hopper --particles N --deck-dir {deckdir} "
                         "--settle-only")
    out = {}
    with open(path) as f:
        for line in f:
            if " = " in line and not line.startswith("#"):
                k, v = line.split(" = ", 1)
                out[k.strip()] = v.strip()
    return out


def read_particles(deckdir):
    rows = []
    with open(os.path.join(deckdir, "hopper.particles")) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                rows.append(tuple(float(w) for w in line.split()))
    return rows


def hopper_material(deck):
    """make_deck.material() with the hopper's friction; checks the deck's other constants."""
    mat = make_deck.material()
    for key in ("d_p", "rho_p", "k_n", "e_n"):
        if not math.isclose(float(deck[key]), mat[key], rel_tol=1e-12):
            raise SystemExit(f"make_hopper.py: hopper.deck {key} = {deck[key]}, make_deck.py "
                             f"{mat[key]!r}: the decks share the glass of bench/decks.md")
    mat["mu"] = float(deck["mu"])
    if not math.isclose(float(deck["dt"]), mat["dt"], rel_tol=1e-9):
        raise SystemExit(f"make_hopper.py: hopper.deck dt = {deck['dt']}, make_deck.py "
                         f"{mat['dt']!r}")
    return mat


def kinetic_energy(rows, mass):
    return sum(0.5 * mass * (r[3] * r[3] + r[4] * r[4] + r[5] * r[5]) for r in rows)


def write_data(path, deck, rows):
    box = [float(v) for v in deck["box"].split()]
    d, rho = float(deck["d_p"]), float(deck["rho_p"])
    with open(path, "w") as f:
        f.write(f"LIGGGHTS data: CoReDEM hopper deck, N = {len(rows)} "
                "(bench/peers/liggghts/make_hopper.py from hopper.particles)\n\n")
        f.write(f"{len(rows)} atoms\n2 atom types\n\n")
        f.write(f"{box[0]!r} {box[1]!r} xlo xhi\n{box[2]!r} {box[3]!r} ylo yhi\n"
                f"{box[4]!r} {box[5]!r} zlo zhi\n\n")
        f.write("Atoms\n\n")
        # atom_style granular: atom-ID atom-type diameter density x y z
        f.writelines(f"{i + 1} 1 {d!r} {rho!r} {r[0]!r} {r[1]!r} {r[2]!r}\n"
                     for i, r in enumerate(rows))
        # atom_style granular: atom-ID vx vy vz omegax omegay omegaz
        f.write("\nVelocities\n\n")
        f.writelines(f"{i + 1} {r[3]!r} {r[4]!r} {r[5]!r} {r[6]!r} {r[7]!r} {r[8]!r}\n"
                     for i, r in enumerate(rows))


def wall_fix(fid, geometry, store=False):
    store_kw = " store_force yes" if store else ""
    return (f"fix {fid} all wall/gran {make_deck.WALL_MODEL} {geometry}{store_kw} "
            f"{make_deck.WALL_SETTINGS}")


def walls(deck, variant, closed):
    """[(fix id, wall geometry words)] and the mesh/surface lines."""
    meshes, fixes = [], []
    if variant == "none":
        return meshes, fixes
    if variant == "stl":
        meshes = ["fix hopper all mesh/surface file hopper.stl type 2",
                  "fix bin all mesh/surface file bin.stl type 2"]
        fixes.append(("whopper", "mesh n_meshes 2 meshes hopper bin"))
    else:
        meshes = ["fix cone all mesh/surface file cone.stl type 2"]
        fixes.append(("wcone", "mesh n_meshes 1 meshes cone"))
        fixes.append(("wcyl", f"primitive type 2 zcylinder {float(deck['r_cyl'])!r} 0.0 0.0"))
    fixes.append(("wfloor", f"primitive type 2 zplane {float(deck['z_floor'])!r}"))
    if closed:
        fixes.append(("wplate", "primitive type 2 zplane 0.0"))
    return meshes, fixes


def write_input(path, deck, mat, variant, closed, steps, warmup, skin, sample, contacts):
    n = int(deck["n"])
    meshes, fixes = walls(deck, variant, closed)
    wall_lines = "\n".join(meshes + [wall_fix(fid, geo) for fid, geo in fixes])
    gravity = (f"fix gravi all gravity {float(deck['gravity'])!r} vector 0.0 0.0 -1.0"
               if variant != "none" else "# no gravity (the settled bed alone)")
    warm = (f"# ---- untimed warm-up, as coredem-bench --warmup ----\nrun             {warmup}\n"
            if warmup > 0 else "")
    timed_run = f"run             {steps} pre no" if warmup > 0 else f"run             {steps}"
    contact_block = ""
    if contacts:
        refix = []
        names = []
        for fid, geo in fixes:
            refix.append(f"unfix {fid}")
            refix.append(wall_fix(f"{fid}c", geo, store=True))
            refix.append(f"variable t_{fid} atom \"(f_force_{fid}c[1]^2+f_force_{fid}c[2]^2"
                         f"+f_force_{fid}c[3]^2)>0\"")
            names.append(f"v_t_{fid}")
        wall_count = ""
        cols = ""
        if names:
            wall_count = f"compute twall all reduce sum {' '.join(names)}\n"
            cols = " " + " ".join(f"c_twall[{i + 1}]" for i in range(len(names)))
        contact_block = f"""
# ---- after the timed run (not timed): particle-particle contacts (compute contact/atom) and,
# per wall fix, the particles touching it: the wall fixes are re-created with store_force yes
# (fresh contact history; run 0 only evaluates the forces of the current positions) ----
compute cpa all contact/atom
compute csum all reduce sum c_cpa
{chr(10).join(refix)}
{wall_count}thermo_style custom step atoms ke c_csum{cols}
thermo_modify lost error norm no format float %.17g
run 0 post no
"""
    text = f"""# LIGGGHTS 3.8 input: CoReDEM `hopper` benchmark deck (bench/decks.md), N = {n},
# walls {variant}{' (outlet closed)' if closed else ''}
# Generated by bench/peers/liggghts/make_hopper.py; see bench/peers/liggghts/README.md.
# D_o = {deck['outlet_d']} m, R_c = {deck['r_cyl']} m, cone half-angle {deck['half_angle_deg']} deg,
# cone height {deck['h_cone']} m, walls up to {deck['h_top']} m, bin floor at {deck['z_floor']} m
# mu = {mat['mu']!r} (particle-particle and particle-wall); k_n, k_t, gamma as make_deck.py

units           si
atom_style      granular
atom_modify     map array
boundary        f f f
newton          off
communicate     single vel yes
processors      * * 1

read_data       hopper.data

neighbor        {skin!r} bin
neigh_modify    delay 0 every 1 check yes

{make_deck.property_block(mat)}

pair_style      gran {make_deck.MODEL}
pair_coeff      * *

{wall_lines}

{gravity}
fix integr all nve/sphere

timestep        {mat['dt']!r}

# discharged: particles whose centre lies below the outlet plane z = 0
region          below block INF INF INF INF INF 0.0 units box
variable        nout equal count(all,below)
thermo_style    custom step atoms ke v_nout dt
thermo_modify   lost error norm no format float %.17g
thermo          {sample}
{warm}
# ---- timed run: no dumps, thermo every {sample} steps ----
{timed_run}
{contact_block}"""
    with open(path, "w") as f:
        f.write(text)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("deckdir", help="deck directory written by coredem-bench dem --case hopper")
    ap.add_argument("steps", type=int, help="time steps of the timed run")
    ap.add_argument("--walls", choices=VARIANTS, default="primitive")
    ap.add_argument("--closed", action="store_true", help="keep the outlet plate (bed at rest)")
    ap.add_argument("--warmup", type=int, default=0, help="untimed steps first (default 0)")
    ap.add_argument("--skin", type=float, default=1e-4, help="neighbour skin in metres")
    ap.add_argument("--sample", type=int, default=500, help="thermo (discharge count) every K steps")
    ap.add_argument("--contacts", action="store_true",
                    help="append an untimed `run 0` that counts contacts and wall touches")
    args = ap.parse_args(argv)
    if args.steps < 1:
        ap.error(f"STEPS must be a positive integer, got {args.steps}")
    if args.warmup < 0 or args.sample < 1 or not args.skin > 0:
        ap.error("--warmup >= 0, --sample >= 1 and --skin > 0 required")
    if args.walls == "none" and args.closed:
        ap.error("--closed needs walls (primitive or stl)")
    deck = read_deck(args.deckdir)
    mat = hopper_material(deck)
    rows = read_particles(args.deckdir)
    n = int(deck["n"])
    if len(rows) != n or any(len(r) != 9 for r in rows):
        raise SystemExit(f"make_hopper.py: hopper.particles has {len(rows)} rows of 9 numbers "
                         f"expected, hopper.deck says n = {n}")
    for f in ("hopper.stl", "cone.stl", "bin.stl"):
        if not os.path.exists(os.path.join(args.deckdir, f)):
            raise SystemExit(f"make_hopper.py: {f} missing in {args.deckdir}")
    variant = args.walls + ("_closed" if args.closed else "")
    write_data(os.path.join(args.deckdir, "hopper.data"), deck, rows)
    write_input(os.path.join(args.deckdir, f"in.hopper_{variant}"), deck, mat, args.walls,
                args.closed, args.steps, args.warmup, args.skin, args.sample, args.contacts)
    ke = kinetic_energy(rows, mat["mass"])
    print("deck = hopper")
    print(f"variant = {variant}")
    print(f"input = in.hopper_{variant}")
    print(f"n = {n}")
    print(f"steps = {args.steps}")
    print(f"warmup = {args.warmup}")
    print(f"sample = {args.sample}")
    for key in ("mass", "eta_n_pp", "eta_n_pw", "t_col", "dt", "mu"):
        print(f"{key} = {mat[key]!r}")
    print(f"ke_initial = {ke!r}")
    for key in ("outlet_d", "r_cyl", "h_cone", "h_top", "z_floor", "rho_bulk", "d_p", "gravity"):
        print(f"{key} = {deck[key]}")
    print(f"skin = {args.skin!r}")
    print(f"wall_fixes = {' '.join(fid for fid, _ in walls(deck, args.walls, args.closed)[1])}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
