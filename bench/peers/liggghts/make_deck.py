#!/usr/bin/env python3
"""Write the LIGGGHTS version of a benchmark deck of bench/decks.md (`packed` or `agitated`).

    make_deck.py N STEPS OUTDIR [--deck packed|agitated] [--warmup W] [--skin METRES]
                 [--contacts]

writes OUTDIR/DECK.data (the N particles, read by `read_data`), OUTDIR/in.DECK (the LIGGGHTS
input) and, for `agitated`, OUTDIR/agitated.vel (the initial velocities, one particle per
line, for `coredem-bench dem --velocities`), and prints the derived parameters as
`key = value` lines.

The particle positions are computed here, in double precision, with the site order of
bench/decks.md (x fastest, then y, then z, stopping after N sites), so a partial top layer
is filled exactly as `coredem-bench dem --case DECK` fills it. The agitated deck's velocities
are generated here once (the generator and seed of `coredem-bench dem --case agitated`:
splitmix64 seeded with 20240611 ^ 0x5bd1e995a5a5a5a5, v = 0.5 (2u - 1) per component, particle
by particle) and written into both the LIGGGHTS data file and agitated.vel, so both codes start
from the same velocities whatever their own random generators; `ke_initial` (the translational
kinetic energy) lets compare.sh check that both read them.

The input runs W untimed steps (`run W`, as coredem-bench's --warmup) and then the timed
`run STEPS pre no` (continuing without a new set-up, as coredem-bench continues its loop).

Also importable: `material()` returns the contact parameters (used by verify_restitution.py).
"""

import argparse
import math
import os
import sys

# Common material of bench/decks.md (docs/physics.md §7, Patil glass).
D_P = 1.0e-3          # m
RHO_P = 2500.0        # kg/m^3
K_N = 1000.0          # N/m
E_N = 0.97
MU = 0.1
K_T = 2.0 / 7.0 * K_N  # N/m
ETA_T_FAC = 0.5        # eta_t = 1/2 eta_n
GRAVITY = 9.81         # m/s^2, along -z
SPACING_FAC = 0.9999   # packed lattice spacing s = 0.9999 d_p
AGITATED_SPACING_FAC = 1.2   # agitated lattice spacing s = 1.2 d_p
AGITATED_JITTER = 0.5        # m/s, each velocity component uniform in [-a, a)
AGITATED_SEED = 20240611     # bench/commands/dem.h
DECKS = ("packed", "agitated")


def eta_n(k_n, m_eff, e_n):
    """docs/physics.md Eq. 13: normal dashpot coefficient giving restitution e_n (N s/m)."""
    if e_n <= 0.0:
        return 2.0 * math.sqrt(k_n * m_eff)
    ln_e = math.log(e_n)
    return 2.0 * math.sqrt(k_n * m_eff) * abs(ln_e) / math.sqrt(math.pi ** 2 + ln_e ** 2)


def t_col(k_n, m_eff, eta):
    """docs/physics.md Eq. 12: duration of a linear spring-dashpot contact (s)."""
    return math.pi / math.sqrt(k_n / m_eff - eta ** 2 / (4.0 * m_eff ** 2))


def material():
    m = RHO_P * math.pi * D_P ** 3 / 6.0
    m_pp = 0.5 * m          # particle-particle m_eff = m_i m_j / (m_i + m_j)
    m_pw = m                # particle-wall m_eff = m_i
    eta_pp = eta_n(K_N, m_pp, E_N)
    eta_pw = eta_n(K_N, m_pw, E_N)
    tc = t_col(K_N, m_pp, eta_pp)
    # CoReDEM's step: the undamped pair contact duration pi sqrt(m_eff/k_n) over dt_factor 50
    # (docs/physics.md; the integrator's stability limit 2 sqrt(m_eff/k_n)-ish is far larger).
    t_und = math.pi * math.sqrt(m_pp / K_N)
    return {
        "d_p": D_P, "rho_p": RHO_P, "mass": m,
        "k_n": K_N, "k_t": K_T, "e_n": E_N, "mu": MU,
        "m_eff_pp": m_pp, "m_eff_pw": m_pw,
        "eta_n_pp": eta_pp, "eta_t_pp": ETA_T_FAC * eta_pp,
        "eta_n_pw": eta_pw, "eta_t_pw": ETA_T_FAC * eta_pw,
        "t_col": tc, "t_undamped": t_und, "dt": t_und / 50.0,
    }


def layout(n, deck="packed"):
    """Lattice counts and box of a deck for n particles (bench/decks.md)."""
    if n < 1:
        raise ValueError(f"N must be >= 1, got {n}")
    if deck not in DECKS:
        raise ValueError(f"deck must be one of {DECKS}, got {deck!r}")
    s = (SPACING_FAC if deck == "packed" else AGITATED_SPACING_FAC) * D_P
    # coredem-bench: llround(cbrt(n)); Python's round() rounds halves to even, which no
    # cube root of an integer hits exactly
    nx = ny = max(1, round(math.cbrt(n)))
    nz = -(-n // (nx * ny))
    box = (nx * s, ny * s, (2 if deck == "packed" else 1) * nz * s)
    return s, nx, ny, nz, box


def packed_layout(n):
    """Lattice counts and box of the packed deck for n particles (bench/decks.md)."""
    return layout(n, "packed")


class SplitMix64:
    """The generator of CoReDEM's particle sets (dem_system.cpp, Rng): splitmix64."""

    MASK = (1 << 64) - 1

    def __init__(self, seed):
        self.s = seed & self.MASK

    def next(self):
        self.s = (self.s + 0x9E3779B97F4A7C15) & self.MASK
        z = self.s
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & self.MASK
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & self.MASK
        return z ^ (z >> 31)

    def uniform(self):
        return (self.next() >> 11) * 2.0 ** -53   # [0, 1)


def agitated_velocities(n):
    """The agitated deck's initial velocities [(vx, vy, vz)], in site order."""
    rng = SplitMix64(AGITATED_SEED ^ 0x5BD1E995A5A5A5A5)
    return [tuple(AGITATED_JITTER * (2.0 * rng.uniform() - 1.0) for _ in range(3))
            for _ in range(n)]


def kinetic_energy(velocities, mass):
    return sum(0.5 * mass * (vx * vx + vy * vy + vz * vz) for vx, vy, vz in velocities)


def sites(n, s, nx, ny):
    """Yield (x, y, z) of the first n lattice sites, x fastest, then y, then z."""
    for idx in range(n):
        i = idx % nx
        j = (idx // nx) % ny
        k = idx // (nx * ny)
        yield ((i + 0.5) * s, (j + 0.5) * s, (k + 0.5) * s)


def write_data(path, n, s, nx, ny, box, velocities=None, deck="packed"):
    with open(path, "w") as f:
        f.write(f"LIGGGHTS data: CoReDEM {deck} deck, N = {n} (bench/peers/liggghts/make_deck.py)\n\n")
        f.write(f"{n} atoms\n2 atom types\n\n")
        f.write(f"0.0 {box[0]!r} xlo xhi\n0.0 {box[1]!r} ylo yhi\n0.0 {box[2]!r} zlo zhi\n\n")
        f.write("Atoms\n\n")
        # atom_style granular: atom-ID atom-type diameter density x y z
        lines = []
        for idx, (x, y, z) in enumerate(sites(n, s, nx, ny)):
            lines.append(f"{idx + 1} 1 {D_P!r} {RHO_P!r} {x!r} {y!r} {z!r}\n")
        f.writelines(lines)
        if velocities is not None:
            # atom_style granular: atom-ID vx vy vz omegax omegay omegaz
            f.write("\nVelocities\n\n")
            f.writelines(f"{idx + 1} {vx!r} {vy!r} {vz!r} 0.0 0.0 0.0\n"
                         for idx, (vx, vy, vz) in enumerate(velocities))


def write_velocities(path, velocities):
    with open(path, "w") as f:
        f.write("# vx vy vz (m/s), one particle per line in site order "
                "(bench/peers/liggghts/make_deck.py)\n")
        f.writelines(f"{vx!r} {vy!r} {vz!r}\n" for vx, vy, vz in velocities)


def property_block(mat):
    """fix property/global lines; atom type 1 = particles, type 2 = the walls."""
    def pair(v11, v12):
        # peratomtypepair 2: values 11 12 21 22 (22 is never used: walls do not touch walls)
        return f"{v11!r} {v12!r} {v12!r} {v11!r}"
    return "\n".join([
        f"fix kn all property/global kn peratomtypepair 2 {pair(mat['k_n'], mat['k_n'])}",
        f"fix kt all property/global kt peratomtypepair 2 {pair(mat['k_t'], mat['k_t'])}",
        "fix gn all property/global gamman_abs peratomtypepair 2 "
        f"{pair(mat['eta_n_pp'], mat['eta_n_pw'])}",
        "fix gt all property/global gammat_abs peratomtypepair 2 "
        f"{pair(mat['eta_t_pp'], mat['eta_t_pw'])}",
        "fix cof all property/global coefficientFriction peratomtypepair 2 "
        f"{pair(mat['mu'], mat['mu'])}",
    ])


# The contact-model settings; fix wall/gran wants them after the wall geometry.
WALL_MODEL = "model hooke/stiffness tangential history"
WALL_SETTINGS = "absolute_damping on tangential_damping on limitForce off"
MODEL = f"{WALL_MODEL} {WALL_SETTINGS}"


def write_input(path, n, steps, box, mat, skin, contacts, data_name, deck="packed", warmup=0):
    wall_lines = []
    for axis, lo, hi in (("x", 0.0, box[0]), ("y", 0.0, box[1]), ("z", 0.0, box[2])):
        for side, pos in (("lo", lo), ("hi", hi)):
            wall_lines.append(
                f"fix wall{axis}{side} all wall/gran {WALL_MODEL} primitive type 2 {axis}plane {pos!r}"
                f" {WALL_SETTINGS}")
    contact_block = ""
    if contacts:
        contact_block = f"""
# ---- after the timed run: count particle-particle contacts (not timed) ----
compute cpa all contact/atom
compute csum all reduce sum c_cpa
thermo_style custom step atoms ke c_csum
thermo_modify lost error norm no format float %.17g
run 0 post no
"""
    gravity = (f"fix gravi all gravity {GRAVITY!r} vector 0.0 0.0 -1.0" if deck == "packed"
               else "# no gravity (agitated deck)")
    warm = (f"# ---- untimed warm-up, as coredem-bench --warmup ----\nthermo {warmup}\nrun {warmup}\n"
            if warmup > 0 else "")
    timed_run = f"run             {steps} pre no" if warmup > 0 else f"run             {steps}"
    text = f"""# LIGGGHTS 3.8 input: CoReDEM `{deck}` benchmark deck (bench/decks.md), N = {n}
# Generated by bench/peers/liggghts/make_deck.py; see bench/peers/liggghts/README.md.
# m = {mat['mass']!r} kg, m_eff(pp) = {mat['m_eff_pp']!r} kg, m_eff(pw) = {mat['m_eff_pw']!r} kg
# eta_n(pp) = {mat['eta_n_pp']!r} N s/m, eta_n(pw) = {mat['eta_n_pw']!r} N s/m (docs/physics.md Eq. 13)
# t_col(pp) = {mat['t_col']!r} s (damped, docs/physics.md Eq. 12); dt = pi sqrt(m_eff/k_n)/50

units           si
atom_style      granular
atom_modify     map array
boundary        f f f
newton          off
communicate     single vel yes
# no domain split along z: the bed fills only the lower half of the box
processors      * * 1

read_data       {data_name}

neighbor        {skin!r} bin
neigh_modify    delay 0 every 1 check yes

{property_block(mat)}

pair_style      gran {MODEL}
pair_coeff      * *

{chr(10).join(wall_lines)}

{gravity}
fix integr all nve/sphere

timestep        {mat['dt']!r}

# thermo: kinetic energy and the timestep in full precision (compare.sh checks both)
thermo_style    custom step atoms ke dt
thermo_modify   lost error norm no format float %.17g
{warm}
# ---- timed run: no dumps, thermo only at the first and the last step ----
thermo          {steps}
{timed_run}
{contact_block}"""
    with open(path, "w") as f:
        f.write(text)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", type=int, help="particle count N")
    ap.add_argument("steps", type=int, help="time steps of the timed run")
    ap.add_argument("outdir", help="directory for in.DECK and DECK.data")
    ap.add_argument("--deck", choices=DECKS, default="packed", help="deck (default packed)")
    ap.add_argument("--warmup", type=int, default=0,
                    help="untimed steps before the timed run (coredem-bench --warmup; default 0)")
    ap.add_argument("--skin", type=float, default=0.1 * D_P,
                    help="neighbour skin in metres (default 0.1 d_p = 1e-4 m)")
    ap.add_argument("--contacts", action="store_true",
                    help="append an untimed `run 0` that counts particle-particle contacts")
    args = ap.parse_args(argv)
    if args.n < 1:
        ap.error(f"N must be a positive integer, got {args.n}")
    if args.steps < 1:
        ap.error(f"STEPS must be a positive integer, got {args.steps}")
    if not args.skin > 0.0:
        ap.error(f"--skin must be > 0 (metres), got {args.skin}")
    if args.warmup < 0:
        ap.error(f"--warmup must be >= 0, got {args.warmup}")
    os.makedirs(args.outdir, exist_ok=True)
    mat = material()
    deck = args.deck
    s, nx, ny, nz, box = layout(args.n, deck)
    vel = agitated_velocities(args.n) if deck == "agitated" else None
    write_data(os.path.join(args.outdir, f"{deck}.data"), args.n, s, nx, ny, box, vel, deck)
    if vel is not None:
        write_velocities(os.path.join(args.outdir, f"{deck}.vel"), vel)
    write_input(os.path.join(args.outdir, f"in.{deck}"), args.n, args.steps, box, mat,
                args.skin, args.contacts, f"{deck}.data", deck, args.warmup)
    print(f"deck = {deck}")
    print(f"n = {args.n}")
    print(f"steps = {args.steps}")
    print(f"warmup = {args.warmup}")
    for key in ("mass", "eta_n_pp", "eta_n_pw", "t_col", "dt"):
        print(f"{key} = {mat[key]!r}")
    print(f"ke_initial = {kinetic_energy(vel, mat['mass']) if vel else 0.0!r}")
    print(f"lattice = {nx} x {ny} x {nz}, spacing = {s!r}")
    print(f"box = {box[0]!r} x {box[1]!r} x {box[2]!r}")
    print(f"skin = {args.skin!r}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
