#!/usr/bin/env bash
# Runs the default case with the binaries of BUILD_DIR (default: build).
set -euo pipefail
build=${1:-build}
echo "run-default: nothing to run yet"
