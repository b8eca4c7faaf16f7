#!/usr/bin/env python3
"""Mutation fuzz of the input files `coredem check` reads (docs/security.md "Input files").

    bench/fuzz/inputs.py COREDEM [--per-kind N] [--seed S] [--timeout T] [--work DIR]
                         [--kinds case,stl,polymesh,stages,sweep]

Starts from valid inputs (cases/fluidized-bed-cooling with its blockMesh-generated polyMesh, a
small ASCII and binary STL floor) and writes N mutants of each kind:

  case     case.yaml: numbers replaced by extremes (0, -1, 1e308, 1e-320, nan, inf, 2^64,
           4e9), lines deleted, duplicated or swapped, bytes inserted (NUL, invalid UTF-8,
           YAML punctuation), the text truncated;
  stl      an ASCII or binary STL used as walls.meshes[0].file: bytes flipped, the binary
           triangle count set to huge values, truncated, numbers replaced;
  polymesh constant/polyMesh/{points,faces,owner,boundary} of walls.meshes[0].from_cfd: counts
           and numbers replaced, lines deleted, truncated;
  stages   the `stages` list of a staged case (two stages) mutated as case.yaml is;
  sweep    a campaign sweep file (grid and explicit members, collect windows) mutated as
           case.yaml is, checked with `COREDEM check SWEEP` (every member pre-flighted, as
           `coredem campaign run` does before launching anything);

plus fixed special files (a FIFO as the STL and as boundary, points linked to /dev/zero, a
directory as the STL). Each mutant is checked with `COREDEM check` under a T-second timeout and a
2 GiB address-space limit, and counted by outcome:

  accepted   exit 0 (the mutant is still a valid case)
  refused    exit 2 with a message naming a file (case.yaml:LINE, the STL or polyMesh file)
  unnamed    exit 2 without a file name in the message
  internal   any other exit status (1: an internal error, e.g. bad_alloc; negative: a signal)
  hang       killed at the timeout

A robust reader has no internal, hang or unnamed outcome. Exit status 1 when there is one (the
first few are printed with the mutant kept in --work). No timing is measured.
"""

import argparse
import os
import random
import re
import resource
import shutil
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
EXTREMES = ["0", "-1", "1e308", "-1e308", "1e-320", "nan", "inf", "-inf", "18446744073709551616",
            "4000000000", "999999999999", "0.0", "1e-30", "1e30", ""]
JUNK = ["\x00", "\xff\xfe", "{", "}", "[", "]", ":", ",", "- ", "'", "\"", "#", "\t", "\n",
        "&a", "*a", "!!binary", "---\n", "? ", "|", ">"]
NUMBER = re.compile(rb"-?\d+(\.\d+)?([eE][-+]?\d+)?")


def mutate_text(rng, data):
    """One to three random edits of a text file (bytes)."""
    for _ in range(rng.randint(1, 3)):
        kind = rng.randrange(6)
        lines = data.split(b"\n")
        if kind == 0:
            nums = list(NUMBER.finditer(data))
            if nums:
                m = rng.choice(nums)
                data = data[:m.start()] + rng.choice(EXTREMES).encode() + data[m.end():]
        elif kind == 1 and len(lines) > 1:
            del lines[rng.randrange(len(lines))]
            data = b"\n".join(lines)
        elif kind == 2:
            i = rng.randrange(len(lines))
            lines.insert(i, lines[i])
            data = b"\n".join(lines)
        elif kind == 3 and len(lines) > 1:
            i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
            lines[i], lines[j] = lines[j], lines[i]
            data = b"\n".join(lines)
        elif kind == 4:
            p = rng.randrange(len(data) + 1)
            data = data[:p] + rng.choice(JUNK).encode("latin-1") + data[p:]
        else:
            data = data[:rng.randrange(len(data) + 1)]
    return data


def mutate_binary_stl(rng, data):
    data = bytearray(data)
    kind = rng.randrange(4)
    if kind == 0:
        data[80:84] = struct.pack("<I", rng.choice([0, 1, 3, 0xFFFFFFFF, 0x7FFFFFFF, 100000000]))
    elif kind == 1:
        for _ in range(rng.randint(1, 8)):
            data[rng.randrange(84, len(data))] = rng.randrange(256)
    elif kind == 2:
        off = 84 + 50 * rng.randrange(max(1, (len(data) - 84) // 50)) + 12
        data[off:off + 4] = struct.pack("<f", rng.choice([float("nan"), float("inf"), 1e38, 0.0]))
    else:
        del data[rng.randrange(len(data) + 1):]
    return bytes(data)


def floor_stl(ascii_):
    """Two triangles covering the box floor of fluidized-bed-cooling at y = 0.002."""
    tris = [((0, 0.002, 0), (0.02, 0.002, 0), (0.02, 0.002, 0.004)),
            ((0, 0.002, 0), (0.02, 0.002, 0.004), (0, 0.002, 0.004))]
    if ascii_:
        out = ["solid floor"]
        for t in tris:
            out.append("  facet normal 0 1 0\n    outer loop")
            out += ["      vertex %r %r %r" % v for v in t]
            out.append("    endloop\n  endfacet")
        out.append("endsolid floor\n")
        return "\n".join(out).encode()
    data = bytearray(b"floor".ljust(80, b" ")) + struct.pack("<I", len(tris))
    for t in tris:
        data += struct.pack("<3f", 0, 1, 0)
        for v in t:
            data += struct.pack("<3f", *v)
        data += b"\0\0"
    return bytes(data)


def limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))


def check(coredem, case_dir, timeout):
    sweep = os.path.join(case_dir, "sweep.yaml")
    target = sweep if os.path.exists(sweep) else case_dir
    try:
        r = subprocess.run([coredem, "check", target], capture_output=True, timeout=timeout,
                           preexec_fn=limit_memory)
    except subprocess.TimeoutExpired:
        return "hang", ""
    text = (r.stdout + r.stderr).decode("utf-8", "replace")
    if r.returncode == 0:
        return "accepted", text
    if r.returncode == 2:
        named = re.search(r"(case\.yaml:\d+|\.stl|polyMesh|sweep|case\.yaml)", text)
        return ("refused" if named else "unnamed"), text
    return "internal", text


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("coredem")
    ap.add_argument("--per-kind", type=int, default=200)
    ap.add_argument("--seed", type=int, default=20261204)
    ap.add_argument("--timeout", type=float, default=20.0)
    ap.add_argument("--work", default=None)
    ap.add_argument("--kinds", default="case,stl,polymesh,stages,sweep",
                    help="comma-separated kinds to mutate (default: all)")
    a = ap.parse_args()
    rng = random.Random(a.seed)
    work = a.work or tempfile.mkdtemp(prefix="coredem-fuzz-inputs-")
    base = os.path.join(work, "base")
    shutil.rmtree(base, ignore_errors=True)
    shutil.copytree(os.path.join(ROOT, "cases", "fluidized-bed-cooling"), base)
    env = dict(os.environ)
    env.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")  # Debian's openfoam etc tree
    subprocess.run(["blockMesh", "-case", os.path.join(base, "openfoam")], check=True,
                   capture_output=True, env=env)
    case_text = open(os.path.join(base, "case.yaml"), "rb").read()
    walls = b"walls:\n"
    stl_case = case_text.replace(walls, walls + b"  meshes: [{file: floor.stl}]\n", 1)
    cfd_case = case_text.replace(walls, walls + b"  meshes: [{from_cfd: [walls]}]\n", 1)
    poly = os.path.join(base, "openfoam", "constant", "polyMesh")
    poly_files = {f: open(os.path.join(poly, f), "rb").read()
                  for f in ("points", "faces", "owner", "boundary")}

    def fresh(name, case_bytes):
        d = os.path.join(work, name)
        shutil.rmtree(d, ignore_errors=True)
        shutil.copytree(base, d, symlinks=True)
        open(os.path.join(d, "case.yaml"), "wb").write(case_bytes)
        return d

    mutants = []  # (kind, label, directory)
    for k in range(a.per_kind):
        mutants.append(("case", "case-%d" % k, lambda k=k: fresh(
            "m", mutate_text(rng, case_text))))
    for k in range(a.per_kind):
        def stl(k=k):
            d = fresh("m", stl_case)
            ascii_ = k % 2 == 0
            data = floor_stl(ascii_)
            data = mutate_text(rng, data) if ascii_ else mutate_binary_stl(rng, data)
            open(os.path.join(d, "floor.stl"), "wb").write(data)
            return d
        mutants.append(("stl", "stl-%d" % k, stl))
    for k in range(a.per_kind):
        def polymesh(k=k):
            d = fresh("m", cfd_case)
            f = rng.choice(sorted(poly_files))
            open(os.path.join(d, "openfoam", "constant", "polyMesh", f), "wb").write(
                mutate_text(rng, poly_files[f]))
            return d
        mutants.append(("polymesh", "polymesh-%d" % k, polymesh))

    # Staged cases (case.yaml `stages`): the stage list mutated, each stage checked.
    staged_case = case_text + (b"stages:\n  - {name: settle, time.end: 0.01, models.heat: 'off'}\n"
                               b"  - name: blow\n    time.end: 0.02\n")
    for k in range(a.per_kind):
        mutants.append(("stages", "stages-%d" % k, lambda k=k: fresh(
            "m", staged_case[:len(case_text)] + mutate_text(rng, staged_case[len(case_text):]))))

    # Campaign sweeps over the base case (docs/campaigns.md): grid, explicit members, collect.
    sweep_text = (b"name: fuzz\nbase_case: .\nconcurrency: 2\nretries: 1\ngrid:\n"
                  b"  time.end: [0.01, 0.02]\n  particles[0].diameter: [1.0e-3, 1.2e-3]\n"
                  b"collect:\n  scalars: [mean@0.005..:mean_T_p, {max: bed_height_m, from: 0.005, to: 0.02}]\n")
    for k in range(a.per_kind):
        def sweep(k=k):
            d = fresh("m", case_text)
            open(os.path.join(d, "sweep.yaml"), "wb").write(mutate_text(rng, sweep_text))
            return d
        mutants.append(("sweep", "sweep-%d" % k, sweep))

    def special(kind, what):
        def make():
            d = fresh("m", stl_case if kind == "stl" else cfd_case)
            if what == "fifo-stl":
                os.mkfifo(os.path.join(d, "floor.stl"))
            elif what == "dir-stl":
                os.mkdir(os.path.join(d, "floor.stl"))
            elif what == "fifo-boundary":
                p = os.path.join(d, "openfoam", "constant", "polyMesh", "boundary")
                os.remove(p)
                os.mkfifo(p)
            elif what == "zero-points":
                p = os.path.join(d, "openfoam", "constant", "polyMesh", "points")
                os.remove(p)
                os.symlink("/dev/zero", p)
            return d
        return make
    for kind, what in (("stl", "fifo-stl"), ("stl", "dir-stl"), ("polymesh", "fifo-boundary"),
                       ("polymesh", "zero-points")):
        mutants.append((kind, what, special(kind, what)))

    kinds = set(a.kinds.split(","))
    mutants = [m for m in mutants if m[0] in kinds]
    counts = {}
    bad = []
    for kind, label, make in mutants:
        d = make()
        outcome, text = check(a.coredem, d, a.timeout)
        counts.setdefault(kind, {}).setdefault(outcome, 0)
        counts[kind][outcome] += 1
        if outcome in ("internal", "hang", "unnamed"):
            keep = os.path.join(work, "bad-" + label)
            shutil.rmtree(keep, ignore_errors=True)
            shutil.copytree(d, keep, symlinks=True)
            bad.append((label, outcome, text.strip().splitlines()[-1:] if text else [], keep))
        shutil.rmtree(d, ignore_errors=True)
    outcomes = ["accepted", "refused", "unnamed", "internal", "hang"]
    print("%-9s %6s " % ("kind", "total") + " ".join("%9s" % o for o in outcomes))
    for kind in ("case", "stl", "polymesh", "stages", "sweep"):
        c = counts.get(kind, {})
        print("%-9s %6d " % (kind, sum(c.values())) + " ".join("%9d" % c.get(o, 0)
                                                             for o in outcomes))
    for label, outcome, last, keep in bad[:10]:
        print("%s: %s: %s (kept in %s)" % (label, outcome, " ".join(last), keep))
    if not a.work and not bad:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
