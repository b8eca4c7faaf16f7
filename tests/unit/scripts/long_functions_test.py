#!/usr/bin/python3
"""scripts/long-functions.py over fixtures/shapes.cpp: the functions it finds, their lengths,
and its findings and exit code against the limits. Usage: long_functions_test.py SOURCE_DIR"""
import os
import subprocess
import sys

root = sys.argv[1]
script = os.path.join(root, "scripts", "long-functions.py")
fixture = os.path.join(root, "tests", "unit", "scripts", "fixtures", "shapes.cpp")


def run(*args):
    r = subprocess.run([sys.executable, script, *args, fixture], capture_output=True, text=True)
    return r.returncode, [line.split(":", 1)[1] for line in r.stdout.splitlines()]


failures = []
rc, found = run("--list", "--max", "1000")
expected = ["6: cFunction 3", "18: Point::Point 5", "23: Point::sum 1", "24: Point::operator== 1",
            "32: twice 8", "45: Point2::method 8", "54: kLambda (lambda) 1"]
if rc != 0 or found != expected:
    failures.append(f"--list: exit {rc}, found {found}, expected {expected}")
rc, found = run("--max", "7", "--max-file", "50")
expected = ["1: file: 56 lines (limit 50)", "32: function twice: 8 lines (limit 7)",
            "45: function Point2::method: 8 lines (limit 7)"]
if rc != 1 or found != expected:
    failures.append(f"limits 7/50: exit {rc}, found {found}, expected {expected}")
rc, found = run()
if rc != 0 or found:
    failures.append(f"default limits: exit {rc}, found {found}, expected none")
for f in failures:
    print("FAIL", f)
print("long_functions_test:", "FAILED" if failures else "passed")
sys.exit(1 if failures else 0)
