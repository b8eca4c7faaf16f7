#!/usr/bin/env bash
# Checks that every C++ source under version control follows the committed .clang-format
# (Debian's clang-format). Exit 0 when all are formatted, 1 with the list of files that are
# not (fix them with `make format`), 2 when clang-format is missing. Then the size rule:
# scripts/long-functions.py (exit 1 on a source file over 800 lines or a function over 150).
#
# Usage: scripts/check-format.sh
# The OpenFOAM participant's .C/.H files follow OpenFOAM's own layout and are not checked.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v clang-format >/dev/null 2>&1; then
  echo "check-format: error: clang-format not found; run scripts/install-deps.sh" >&2
  exit 2
fi

mapfile -t files < <(git ls-files '*.h' '*.cpp' '*.cu' '*.cuh')
bad=()
for f in "${files[@]}"; do
  if ! clang-format --dry-run --Werror "$f" >/dev/null 2>&1; then
    bad+=("$f")
  fi
done

if [[ ${#bad[@]} -gt 0 ]]; then
  echo "check-format: ${#bad[@]} of ${#files[@]} files differ from .clang-format:" >&2
  printf '  %s\n' "${bad[@]}" >&2
  echo "  run 'make format' and commit the result" >&2
  exit 1
fi
echo "check-format: all ${#files[@]} C++ files follow .clang-format ($(clang-format --version))"

# The size rule of docs/architecture.md: no non-test source file over 800 lines, no function
# over 150 (scripts/long-functions.py lists what exceeds it).
if ! /usr/bin/python3 scripts/long-functions.py; then
  echo "check-format: cut the functions/files above along their concerns (docs/architecture.md)" >&2
  exit 1
fi
echo "check-format: no source file over 800 lines, no function over 150"
