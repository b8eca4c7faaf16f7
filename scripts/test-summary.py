#!/usr/bin/python3
"""The end of `make test`: what ran, by ctest label, and whether the run can be trusted.

Usage: scripts/test-summary.py BUILD_DIR JUNIT_XML

Reads the registered tests and their labels (`ctest --show-only=json-v1` in BUILD_DIR), their
results (JUNIT_XML, written by `ctest --output-junit`) and the test groups of the configuration
(BUILD_DIR/tests/test-groups.txt, cmake/CoredemTestGroups.cmake). Prints, per label, the tests
registered, passed, failed, skipped and not run, the groups opted out, and every skip with its
reason. Exit 1 (and says why) when
  * a test failed, or was registered but has no result (not run, timed out before reporting),
  * a test skipped for a reason that is not an expected one: the only expected skips are the
    CUDA-device tests on a machine without a GPU (and the converse no-device check on one with a
    GPU), the SIMD-lane tests on a processor without AVX or a build with FMA, and the tests of a
    group the user opted out of (COREDEM_TEST_OPT_OUT),
  * one of the labels unit, integration, e2e has no test, or a group that should run has none,
  * a group should run but cannot (state `missing`: e.g. COREDEM_OPENFOAM=AUTO and the OpenFOAM
    headers could not be prepared).
A skip is a GoogleTest GTEST_SKIP() (ctest: "Skipped", SKIP_REGULAR_EXPRESSION of
gtest_discover_tests); its reason is the line after "Skipped" in the test's output.
Standard library only.
"""
import collections
import json
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

KINDS = ("unit", "integration", "e2e")

# Reasons a skip is expected (regular expressions searched in the skip's reason).
EXPECTED_SKIPS = (
    (r"^CUDA backend not built", "CUDA backend not built (no nvcc, or COREDEM_CUDA=OFF)"),
    (r"^no CUDA device", "no CUDA device on this machine"),
    (r"^a CUDA device is present", "a CUDA device is present (the no-device check)"),
    (r"the processor has no AVX", "processor without AVX"),
    (r"needs SSE2 without FMA", "build with FMA (kernels::Double2 needs the x86-64 baseline)"),
)
OPTED_OUT = re.compile(r"^opted out \(COREDEM_TEST_OPT_OUT=([a-z-]+)\)")
# Groups whose tests do not carry the group's label (the ParaView tests sit among the openfoam
# group's results tests): their count is not checked, their skips are.
UNLABELLED_GROUPS = ("paraview",)


def registered_tests(build_dir):
    out = subprocess.run(["ctest", "--show-only=json-v1"], cwd=build_dir, check=True,
                         capture_output=True, text=True).stdout
    tests = {}
    for t in json.loads(out)["tests"]:
        labels, disabled = [], False
        for p in t.get("properties", []):
            if p["name"] == "LABELS":
                labels = list(p["value"])
            elif p["name"] == "DISABLED":
                disabled = bool(p["value"])
        tests[t["name"]] = {"labels": labels, "disabled": disabled}
    return tests


def results(junit):
    out = {}
    for case in ET.parse(junit).getroot().iter("testcase"):
        status = case.get("status", "")
        text = case.findtext("system-out") or ""
        skipped = case.find("skipped")
        message = skipped.get("message", "") if skipped is not None else ""
        if status == "run":
            state = "passed"
        elif status == "fail":
            state = "failed"
        elif status == "disabled" or message == "Disabled":
            state = "disabled"
        elif skipped is not None and ("SKIP" in message or "[  SKIPPED ]" in text):
            state = "skipped"
        else:
            state = "not run"  # e.g. the executable is missing
        reason = ""
        if state == "skipped":
            m = re.search(r": Skipped\n(.*)", text)
            reason = m.group(1).strip() if m else "(no reason in the output)"
        out[case.get("name")] = (state, reason)
    return out


def groups(build_dir):
    path = os.path.join(build_dir, "tests", "test-groups.txt")
    out = collections.OrderedDict()
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            name, state, reason = (line.rstrip("\n").split("\t") + ["", ""])[:3]
            out[name] = (state, reason)
    return out


def classify_skip(reason, group_states):
    m = OPTED_OUT.search(reason)
    if m:
        state = group_states.get(m.group(1), ("?", ""))[0]
        if state == "opted-out":
            return "opted out (%s)" % m.group(1)
        return None
    for pattern, what in EXPECTED_SKIPS:
        if re.search(pattern, reason):
            return what
    return None


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    build_dir, junit = sys.argv[1], sys.argv[2]
    tests = registered_tests(build_dir)
    ran = results(junit)
    group_states = groups(build_dir)
    problems = []

    counts = collections.OrderedDict()
    labels = list(KINDS) + [g for g in group_states if g not in UNLABELLED_GROUPS] + ["coverage"]
    for label in labels:
        counts[label] = collections.Counter()
    expected_skips = collections.Counter()
    for name, t in sorted(tests.items()):
        state, reason = ran.get(name, ("not run", ""))
        if t["disabled"]:
            state = "disabled"
        if state == "skipped":
            why = classify_skip(reason, group_states)
            if why is None:
                state = "skipped (unexpected)"
                problems.append("%s skipped: %s" % (name, reason))
            else:
                expected_skips[why] += 1
        elif state in ("failed", "not run", "disabled"):
            problems.append("%s %s" % (name, state))
        for label in t["labels"]:
            counts.setdefault(label, collections.Counter())
            counts[label]["registered"] += 1
            counts[label][state] += 1
        if (not any(k in t["labels"] for k in KINDS) and "coverage" not in t["labels"] and
                not name.endswith("_NOT_BUILT")):
            problems.append("%s has none of the labels %s" % (name, ", ".join(KINDS)))

    print("\n=== test summary (%s, %d tests registered) ===" % (os.path.abspath(build_dir),
                                                               len(tests)))
    print("%-12s" % "label" + "".join("%12s" % h for h in ("registered", "passed", "failed",
                                                           "skipped", "unexpected", "not run")))
    for label, c in counts.items():
        if label not in labels and not c["registered"]:
            continue
        row = [c["registered"], c["passed"], c["failed"], c["skipped"],
               c["skipped (unexpected)"], c["not run"] + c["disabled"]]
        print("%-12s" % label + "".join("%12d" % x for x in row))
    if expected_skips:
        print("expected skips:")
        for why, n in expected_skips.most_common():
            print("  %4d  %s" % (n, why))
    for name, (state, reason) in group_states.items():
        if state == "on":
            if name not in UNLABELLED_GROUPS and not counts[name]["registered"]:
                problems.append("test group %s should run but has no test registered" % name)
        elif state in ("opted-out", "n/a"):
            print("test group %-11s %s: %s" % (name, "opted out" if state == "opted-out"
                                                 else "not applicable", reason))
        else:
            problems.append("test group %s cannot run (%s): %s" % (name, state, reason))
    for kind in KINDS:
        if not counts[kind]["registered"]:
            problems.append("no %s test is registered" % kind)

    if problems:
        print("\nmake test FAILS (%d):" % len(problems))
        for p in problems:
            print("  " + p)
        return 1
    print("all registered tests ran; every skip is an expected one")
    return 0


if __name__ == "__main__":
    sys.exit(main())
