#!/usr/bin/env python3
"""ctest bench.peer_scripts: the peer decks describe the same systems as coredem-bench.

    check_peer_scripts.py COREDEM_BENCH

1. make_deck.py's agitated velocities (its splitmix64 copy) are coredem-bench's own: the
   initial kinetic energy of `coredem-bench dem --case agitated` without and with
   --velocities FILE equals make_deck.py's ke_initial to 1e-12 (relative), N = 1000 and 1001;
2. a velocity file with the wrong particle count is refused (exit status != 0);
3. dpmfoam/make_case.py gives DPMFoam's collision sub-step (OpenFOAM 1912's estimate:
   pair R = d/4, U = 2 U_max; wall R = d/2, U = U_max) equal to dt_DEM at the design speed,
   to 1e-12 relative, for the pair and the wall model;
4. dpmfoam/report.py's sub-step check passes a synthetic log with the intended counts and
   fails (exit 4) one with 2x the counts;
5. liggghts/report.py's deck check passes a synthetic LIGGGHTS screen output that matches the
   deck and reports each of a wrong timestep, skin, step count and initial kinetic energy;
6. the hopper deck (N = 60): coredem-bench settles it into a deck directory; make_hopper.py's
   hopper.data holds the same particles and its ke_initial equals coredem-bench's for the
   primitive and stl variants (1e-12); the STL files have 64 facets around per profile segment;
   a second run reuses the settled bed; hopper_report.py's rate fit is exact on a straight line.
No timing is measured or asserted.
"""

import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "liggghts"))
sys.path.insert(0, os.path.join(HERE, "dpmfoam"))
import make_deck  # noqa: E402
import make_case  # noqa: E402

failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def ours_ke(bench, n, vel=None):
    cmd = [bench, "dem", "--case", "agitated", "--particles", str(n), "--steps", "1",
           "--warmup", "0", "--threads", "1", "--json"]
    if vel:
        cmd += ["--velocities", vel]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)["ke_initial"]


def load(name, path):
    import importlib.util
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def liggghts_screen(n, steps, warmup, np_, dt, skin, ke0):
    """A LIGGGHTS 3.8 screen output (-echo screen) of make_deck.py's input, as it prints it."""
    def thermo(a, b):
        return (f"    Step    Atoms         KinEng             Dt \n"
                f"{a:8d} {n:8d} {ke0!r} {dt!r} \n{b:8d} {n:8d} {ke0!r} {dt!r} \n")

    def loop(k):
        return (f"Loop time of 0.5 on {np_} procs for {k} steps with {n} atoms, finish time x\n\n"
                "Pair  time (%) = 0.3 (60)\nNeigh time (%) = 0 (0)\nComm  time (%) = 0.1 (20)\n"
                "Outpt time (%) = 0 (0)\nOther time (%) = 0.1 (20)\n"
                "Neighbor list builds = 0\nDangerous builds = 0\n")
    return (f"read_data agitated.data\n  1 by 1 by {np_} MPI processor grid\n"
            f"neighbor        {skin!r} bin\nneigh_modify    delay 0 every 1 check yes\n"
            f"timestep        {dt!r}\nthermo {warmup}\nrun {warmup}\n"
            f"Memory usage per processor = 8.2 Mbytes\n{thermo(0, warmup)}{loop(warmup)}"
            f"thermo          {steps}\nrun             {steps} pre no\n"
            f"{thermo(warmup, warmup + steps)}{loop(steps)}")


def check_liggghts_report(tmp):
    rep = load("lig_report", os.path.join(HERE, "liggghts", "report.py"))
    mat = make_deck.material()
    n, steps, warmup, np_, skin = 1000, 30, 20, 2, 1e-4
    ke = make_deck.kinetic_energy(make_deck.agitated_velocities(n), mat["mass"])
    par = {"dt": repr(mat["dt"]), "ke_initial": repr(ke)}
    good = liggghts_screen(n, steps, warmup, np_, mat["dt"], skin, ke)
    cases = {
        "matching": (good, None),
        "timestep": (good.replace(f"timestep        {mat['dt']!r}", "timestep 1.7e-06"), "timestep"),
        "skin": (good.replace(f"neighbor        {skin!r}", "neighbor 0.0002"), "skin"),
        "steps": (good.replace(f"for {steps} steps", f"for {steps - 1} steps"), "loops of"),
        "kinetic energy": (good.replace(f" {ke!r} ", f" {1.01 * ke!r} ", 1), "kinetic energy"),
    }
    for name, (text, expect) in cases.items():
        path = os.path.join(tmp, "screen")
        with open(path, "w") as f:
            f.write(text)
        try:
            _, bad = rep.parse_liggghts(path, n, steps, warmup, np_, par, skin)
        except ValueError as e:
            bad = [str(e)]
        if expect is None:
            check(not bad, f"liggghts report.py accepts a matching screen output ({bad})")
        else:
            check(any(expect in b for b in bad),
                  f"liggghts report.py reports a wrong {name} ({bad})")


def check_hopper(bench, tmp):
    import make_hopper  # noqa: E402
    rep = load("hop_report", os.path.join(HERE, "liggghts", "hopper_report.py"))
    deck = os.path.join(tmp, "hopper")
    n = 60
    base = [bench, "dem", "--case", "hopper", "--particles", str(n), "--deck-dir", deck,
            "--threads", "1", "--json"]
    out = subprocess.run(base + ["--settle-only"], check=True, capture_output=True, text=True)
    first = json.loads(out.stdout)
    check(not first["cached"] and first["settle_steps"] > 0,
          f"hopper: coredem-bench settles N={n} into the deck directory")
    kv = make_hopper.read_deck(deck)
    rows = make_hopper.read_particles(deck)
    check(int(kv["n"]) == n and len(rows) == n, f"hopper: hopper.particles holds {n} particles")
    for name, tri in (("hopper.stl", 2 * 64 * 2), ("cone.stl", 2 * 64), ("bin.stl", 2 * 64)):
        got = rep.stl_triangles(os.path.join(deck, name))
        check(got == tri, f"hopper: {name} has {got} triangles, expected {tri}")
    for walls in ("primitive", "stl"):
        r = subprocess.run([sys.executable, os.path.join(HERE, "liggghts", "make_hopper.py"), deck,
                            "10", "--walls", walls], check=True, capture_output=True, text=True)
        par = dict(line.split(" = ", 1) for line in r.stdout.splitlines() if " = " in line)
        ours = json.loads(subprocess.run(base + ["--walls", walls, "--steps", "1", "--warmup", "0"],
                                         check=True, capture_output=True, text=True).stdout)
        ke, ke_l = ours["ke_initial"], float(par["ke_initial"])
        check(abs(ke - ke_l) <= 1e-12 * max(abs(ke), 1e-300) and ours["deck_cached"],
              f"hopper {walls}: the settled bed is reused and make_hopper.py's ke_initial "
              f"{ke_l!r} = coredem-bench's {ke!r}")
        check(abs(float(par["dt"]) - ours["dt_dem"]) <= 1e-6 * ours["dt_dem"],
              f"hopper {walls}: the same timestep")
    with open(os.path.join(deck, "hopper.data")) as f:
        text = f.read()
    atoms = text.split("Atoms\n\n", 1)[1].split("\n\nVelocities", 1)[0].splitlines()
    same = len(atoms) == n and all(
        [float(w) for w in a.split()[4:7]] == list(rows[i][:3]) for i, a in enumerate(atoms))
    check(same, "hopper: hopper.data has hopper.particles' positions, in order, exactly")
    samples = [(0.01 * k, 1000.0 * 0.01 * k) for k in range(20)]
    rate = rep.fit_rate(samples, 200, 0.2, 0.8)[0]
    check(rate is not None and abs(rate - 1000.0) < 1e-9,
          f"hopper_report.py's fit of a straight line: {rate}")


def main(bench):
    mass = make_deck.material()["mass"]
    with tempfile.TemporaryDirectory() as tmp:
        for n in (1000, 1001):
            vel = make_deck.agitated_velocities(n)
            ke = make_deck.kinetic_energy(vel, mass)
            path = os.path.join(tmp, f"v{n}.vel")
            make_deck.write_velocities(path, vel)
            k_deck, k_file = ours_ke(bench, n), ours_ke(bench, n, path)
            check(abs(k_deck - ke) <= 1e-12 * ke,
                  f"N={n}: coredem-bench's own agitated velocities = make_deck.py's "
                  f"(KE {k_deck!r} vs {ke!r})")
            check(abs(k_file - ke) <= 1e-12 * ke,
                  f"N={n}: coredem-bench --velocities reads make_deck.py's file (KE {k_file!r})")
        r = subprocess.run([bench, "dem", "--case", "agitated", "--particles", "999", "--steps",
                            "1", "--velocities", os.path.join(tmp, "v1000.vel")],
                           capture_output=True, text=True)
        check(r.returncode != 0 and "1000 velocities for 999" in r.stderr,
              "a velocity file for another N is refused")

        for u in (make_case.U_SUB, 0.5):
            par = make_case.parameters(u)
            for key in ("dt_dem_dpmfoam_pair", "dt_dem_dpmfoam_wall"):
                check(abs(par[key] - par["dt_dem"]) <= 1e-12 * par["dt_dem"],
                      f"design speed {u} m/s: {key} {par[key]:.6g} = dt_DEM {par['dt_dem']:.6g}")
            # independent restatement of OpenFOAM's formula (PairSpringSliderDashpot)
            dtp = (5.429675 * (make_case.D_P / 4) * (make_case.RHO_P / (
                par["estar_pp"] * math.sqrt(2 * u))) ** 0.4 / par["resolution_steps_pair"])
            check(abs(dtp - par["dt_dem"]) <= 1e-12 * par["dt_dem"],
                  f"design speed {u} m/s: OpenFOAM pair estimate with R = d/4, U = 2u")

        dpm_report = load("dpm_report", os.path.join(HERE, "dpmfoam", "report.py"))
        par = make_case.parameters()
        params = os.path.join(tmp, "parameters.txt")
        with open(params, "w") as f:
            f.write(f"dt_dem_coredem = {par['dt_dem']!r}\n")
            f.write(f"substep_velocity_exact = {par['substep_velocity']!r}\n")
        for factor, expect_ok in ((1, True), (2, False)):
            log = os.path.join(tmp, f"log{factor}")
            with open(log, "w") as f:
                for k in range(10):
                    dt = 1e-4
                    f.write(f"deltaT = {dt}\nTime = {(k + 1) * dt}\n")
                    f.write(f"    {factor * math.ceil(dt / par['dt_dem'])} move-collide subCycles\n")
            ok, ratio, _ = dpm_report.check_substeps(log, params, 0.10)
            check(ok == expect_ok and abs(ratio - factor) < 1e-12,
                  f"dpmfoam report.py sub-step check on {factor}x the intended counts: "
                  f"{'passes' if expect_ok else 'fails'} (ratio {ratio})")
        check_liggghts_report(tmp)
        check_hopper(bench, tmp)
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
