#!/usr/bin/env python3
"""Summarise a bench/peers/dpmfoam/compare.sh run.

    report.py WORK_DIR N SIM_SECONDS
    report.py --check-substeps LOG.DPMFoam PARAMETERS.txt   (the sub-step check alone)

WORK_DIR holds dpmfoam/ (the DPMFoam case after its run, with time.txt) and coredem-run/ (the
`coredem run` folder) with coredem.time.txt. Prints wall and CPU seconds per simulated second
for both, the ratio, and the pressure drop and bed height of both beds averaged over the
field writes of the second half of the run:

  * pressure drop: rho_g * (mean kinematic p of the bottom cell layer - mean of the top layer)
    (cell centres, the same for both codes; it includes the gas column, rho_g g H ~ 2.4 Pa);
  * bed height: 2 x the solid-volume-weighted mean height of the cells,
    2 sum((1-alpha) y) / sum(1-alpha): the height of a uniform bed with the same centroid.

Sub-step check: DPMFoam logs "N move-collide subCycles" for every CFD step (no line: 1). The
intended count of a CFD step of deltaT is ceil(deltaT / dt_dem_coredem), CoReDEM's own
sub-cycling, with dt_dem_coredem from WORK_DIR/parameters.txt (make_case.py's output). The
report prints both totals, DPMFoam's mean sub-step and the speed of its fastest particle
that its counts imply (its sub-step goes as U^(-1/5), equal to dt_DEM at the design speed
substep_velocity); if the totals differ by more than SUBSTEP_TOL (env, default 0.10), the
codes did not run the same collision sub-step: it says so loudly, prints the CPU-time ratio
also per collision sub-cycle, and exits with status 4 (the figures are still printed).
"""

import csv
import math
import os
import re
import sys

CELLS = (12, 60, 3)
HEIGHT = 0.2
RHO_G = 1.204


def read_internal(path, ncells):
    with open(path) as f:
        text = f.read()
    m = re.search(r"internalField\s+uniform\s+([^;]+);", text)
    if m:
        return [float(m.group(1))] * ncells
    m = re.search(r"internalField\s+nonuniform\s+List<scalar>\s*(\d+)\s*\(", text)
    if not m:
        raise ValueError(f"{path}: no scalar internalField")
    n = int(m.group(1))
    body = text[m.end():]
    vals = body[: body.index(")")].split()
    if n != ncells or len(vals) != n:
        raise ValueError(f"{path}: {len(vals)} values, expected {ncells}")
    return [float(v) for v in vals]


def time_dirs(case):
    out = []
    for d in os.listdir(case):
        try:
            t = float(d)
        except ValueError:
            continue
        if t > 0:
            out.append((t, os.path.join(case, d)))
    return sorted(out)


def bed_figures(case, alpha_name, sim):
    nx, ny, nz = CELLS
    ncells = nx * ny * nz
    h = HEIGHT / ny
    dps, heights = [], []
    for t, d in time_dirs(case):
        if t < 0.5 * sim - 1e-12:
            continue
        a_path, p_path = os.path.join(d, alpha_name), os.path.join(d, "p")
        if not (os.path.exists(a_path) and os.path.exists(p_path)):
            continue
        alpha = read_internal(a_path, ncells)
        p = read_internal(p_path, ncells)
        bottom = [p[c] for c in range(ncells) if (c // nx) % ny == 0]
        top = [p[c] for c in range(ncells) if (c // nx) % ny == ny - 1]
        dps.append(RHO_G * (sum(bottom) / len(bottom) - sum(top) / len(top)))
        s = sum(1.0 - a for a in alpha)
        sy = sum((1.0 - a) * ((c // nx) % ny + 0.5) * h for c, a in enumerate(alpha))
        heights.append(2.0 * sy / s if s > 0 else float("nan"))
    if not dps:
        return None
    return sum(dps) / len(dps), sum(heights) / len(heights), len(dps)


def read_time(path):
    """(wall, cpu) from /usr/bin/time -f '%e %U %S', or None while the program runs."""
    if not os.path.exists(path):
        return None
    with open(path) as f:
        vals = f.read().split()
    if len(vals) < 3:
        return None
    try:
        wall, user, sys_ = (float(x) for x in vals[-3:])
    except ValueError:
        return None
    return wall, user + sys_


def ours_dp_ledger(run, sim):
    path = os.path.join(run, "timeseries.csv")
    if not os.path.exists(path):
        return None
    vals = []
    with open(path) as f:
        for row in csv.DictReader(f):
            try:
                t = float(row.get("time", row.get("t", "nan")))
                v = float(row["gas.pressure_drop_Pa"])
            except (KeyError, ValueError):
                continue
            if t >= 0.5 * sim:
                vals.append(v)
    return sum(vals) / len(vals) if vals else None


def read_parameters(path):
    """key = value lines of make_case.py (value: the first word)."""
    out = {}
    with open(path) as f:
        for line in f:
            if " = " in line:
                k, v = line.split(" = ", 1)
                out[k.strip()] = v.split()[0] if v.split() else ""
    return out


def dpm_steps(log):
    """[(deltaT, subCycles)] per CFD step of a DPMFoam log (no subCycles line: 1)."""
    steps, dt = [], None
    with open(log) as f:
        for line in f:
            m = re.match(r"^deltaT = (\S+)", line)
            if m:
                dt = float(m.group(1))
                continue
            if re.match(r"^Time = \S+", line):
                if dt is None:
                    raise ValueError(f"{log}: 'Time =' before any 'deltaT =' line")
                steps.append([dt, 1])
                continue
            m = re.search(r"(\d+) move-collide subCycles", line)
            if m and steps:
                steps[-1][1] = int(m.group(1))
    return [tuple(s) for s in steps]


def check_substeps(log, params_path, tol):
    """Compares DPMFoam's sub-cycle counts with ceil(deltaT/dt_DEM); returns (ok, ratio, lines)."""
    par = read_parameters(params_path)
    try:
        dt_dem = float(par["dt_dem_coredem"])
        u_sub = float(par["substep_velocity_exact"])
    except KeyError as e:
        raise ValueError(f"{params_path}: no {e} (written by make_case.py of this version)")
    steps = dpm_steps(log)
    if not steps:
        raise ValueError(f"{log}: no CFD step ('deltaT =' / 'Time =' lines)")
    n_dpm = sum(n for _, n in steps)
    # the float division can land a hair above an integer: do not count that as one more
    n_int = sum(max(1, math.ceil(dt / dt_dem * (1 - 1e-12))) for dt, _ in steps)
    t = sum(dt for dt, _ in steps)
    sub = t / n_dpm
    ratio = n_dpm / n_int
    # dt_col(U) = dt_DEM (U/u_sub)^(-1/5)  =>  U = u_sub (dt_DEM/dt_col)^5 (approximate: ceil)
    u_of = lambda dt, n: u_sub * (dt_dem * n / dt) ** 5
    u_first, u_last = u_of(*steps[0]), u_of(*steps[-1])
    ok = abs(ratio - 1.0) <= tol
    lines = [
        f"DPMFoam collision sub-cycles: {n_dpm} over {len(steps)} CFD steps "
        f"(mean {n_dpm / len(steps):.1f}, max {max(n for _, n in steps)}); intended "
        f"(ceil(deltaT / dt_DEM), dt_DEM = {dt_dem:.6g} s as CoReDEM): {n_int}; ratio {ratio:.3f}",
        f"DPMFoam mean collision sub-step {sub:.4g} s = {sub / dt_dem:.3f} x dt_DEM; its counts "
        f"imply a fastest particle of ~{u_first:.3g} m/s (first step) to ~{u_last:.3g} m/s (last) "
        f"against the design speed {u_sub:g} m/s",
    ]
    if not ok:
        lines.append(
            f"SUB-STEP MISMATCH: DPMFoam took {ratio:.2f} x the intended collision sub-cycles "
            f"(tolerance {tol:g}): the codes did not run the same dt_DEM, so the time ratio is not "
            f"like-for-like. DPMFoam's sub-step follows its fastest particle (U^-1/5); regenerate "
            f"with make_case.py --substep-velocity (compare.sh: SUBSTEP_VELOCITY=) near the "
            f"speeds above.")
    return ok, ratio, lines


def main():
    tol = float(os.environ.get("SUBSTEP_TOL", "0.10"))
    if len(sys.argv) == 4 and sys.argv[1] == "--check-substeps":
        ok, _, lines = check_substeps(sys.argv[2], sys.argv[3], tol)
        print("\n".join(lines))
        return 0 if ok else 4
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    work, n, sim = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
    rows = {}
    dpm = os.path.join(work, "dpmfoam")
    if read_time(os.path.join(dpm, "time.txt")):
        wall, cpu = read_time(os.path.join(dpm, "time.txt"))
        rows["DPMFoam"] = (wall, cpu, bed_figures(dpm, "alpha.air", sim))
    elif os.path.exists(os.path.join(dpm, "log.DPMFoam")):
        # still running (or stopped): its rate so far from the log, scaled to SIM_SECONDS
        text = open(os.path.join(dpm, "log.DPMFoam")).read()
        times = [float(x) for x in re.findall(r"^Time = (\S+)", text, re.M)]
        ex = re.findall(r"ExecutionTime = (\S+) s\s+ClockTime = (\S+) s", text)
        if times and ex:
            t_done = times[-1] if len(ex) == len(times) else times[len(ex) - 1]
            cpu, wall = float(ex[-1][0]), float(ex[-1][1])
            print(f"DPMFoam has not finished: {t_done} of {sim} s simulated after {wall:.0f} s "
                  f"(CPU {cpu:.0f} s); its row is scaled to {sim} s from that rate")
            rows["DPMFoam"] = (wall * sim / t_done, cpu * sim / t_done,
                               bed_figures(dpm, "alpha.air", sim))
    run = os.path.join(work, "coredem-run")
    if read_time(os.path.join(work, "coredem.time.txt")) and os.path.isdir(run):
        wall, cpu = read_time(os.path.join(work, "coredem.time.txt"))
        rows["CoReDEM"] = (wall, cpu, bed_figures(os.path.join(run, "openfoam"), "alphac", sim))
    if not rows:
        print("no run finished")
        return 1
    print()
    print(f"N = {n}, {sim} s simulated")
    print(f"{'code':<8} {'wall s':>9} {'wall s/sim s':>13} {'cpu s/sim s':>12} "
          f"{'dp [Pa]':>9} {'bed H [m]':>10} {'writes':>6}")
    for name, (wall, cpu, bed) in rows.items():
        dp, hb, k = bed if bed else (math.nan, math.nan, 0)
        print(f"{name:<8} {wall:9.1f} {wall / sim:13.4g} {cpu / sim:12.4g} {dp:9.1f} {hb:10.4f} {k:6d}")
    mass = 2500.0 * math.pi * 1e-9 / 6.0
    print(f"bed weight per area: {n * mass * 9.81 / (0.04 * 0.01):.1f} Pa "
          f"(+ gas column rho_g g H = {RHO_G * 9.81 * HEIGHT:.1f} Pa)")
    ledger = ours_dp_ledger(run, sim) if "CoReDEM" in rows else None
    if ledger is not None:
        print(f"CoReDEM gas.pressure_drop_Pa (inlet - outlet patch means, every step, second half): {ledger:.1f} Pa")
    status, sub_ratio = 0, None
    if "DPMFoam" in rows:
        params = os.path.join(work, "parameters.txt")
        if not os.path.exists(params):
            print(f"DPMFoam sub-step check: {params} missing (make_case.py output)", file=sys.stderr)
            status = 4
        else:
            ok, sub_ratio, lines = check_substeps(os.path.join(dpm, "log.DPMFoam"), params, tol)
            print("\n".join(lines))
            status = 0 if ok else 4
    if "DPMFoam" in rows and "CoReDEM" in rows:
        print(f"ratio DPMFoam/CoReDEM wall time: {rows['DPMFoam'][0] / rows['CoReDEM'][0]:.2f}  "
              f"(CPU time: {rows['DPMFoam'][1] / rows['CoReDEM'][1]:.2f})")
        if status == 4 and sub_ratio:
            print(f"  per collision sub-cycle (CPU time / {sub_ratio:.3f}): "
                  f"{rows['DPMFoam'][1] / sub_ratio / rows['CoReDEM'][1]:.2f}  (an estimate: "
                  "DPMFoam's cost taken as proportional to its sub-cycles)")
    return status


if __name__ == "__main__":
    sys.exit(main())
