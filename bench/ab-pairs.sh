#!/usr/bin/env bash
# bench/ab-pairs.sh BASE_BUILD_DIR NEW_BUILD_DIR DECK THREADS [PAIRS] [STEPS]
#
# Paired A/B of two builds of coredem-bench on one deck (bench/decks.md): PAIRS (default 8) pairs
# of `coredem-bench dem --case DECK --particles 100000 --steps STEPS (default 200) --warmup 20
# --threads THREADS --json`, in ABBA order (base first in odd pairs, new first in even ones),
# each pair started on a quiet machine (bench/quiet.sh: load printed, LOADED when it did not fall
# below LOAD_MAX). Prints each pair's particle-steps/s and new/base, then the median ratio. Two
# runs a few seconds apart see the same machine speed, so the per-pair ratio is steadier than a
# ratio of medians where the machine's own speed drifts between runs (docs/performance.md).
set -euo pipefail
[[ $# -ge 4 ]] || { sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
base="$1/bin/coredem-bench"
new="$2/bin/coredem-bench"
deck="$3"
threads="$4"
pairs="${5:-8}"
steps="${6:-200}"
for b in "$base" "$new"; do
  [[ -x "$b" ]] || { echo "ab-pairs.sh: $b not found; build the target coredem-bench there" >&2; exit 2; }
done
# shellcheck source=bench/quiet.sh
source "$here/quiet.sh" # wait_quiet
one() { # binary -> particle-steps/s
  "$1" dem --case "$deck" --particles 100000 --steps "$steps" --warmup 20 --threads "$threads" \
    --json | python3 -c 'import json, sys; print(json.load(sys.stdin)["particle_steps_per_s"])'
}
ratios=()
echo "ab-pairs.sh: $deck, $threads thread(s), $pairs pairs of $steps steps; $(nproc) cores"
for ((k = 1; k <= pairs; ++k)); do
  load="$(wait_quiet)"
  if ((k % 2)); then a="$(one "$base")"; b="$(one "$new")"; else b="$(one "$new")"; a="$(one "$base")"; fi
  r="$(python3 -c "print('%.3f' % ($b / $a))")"
  ratios+=("$r")
  printf '%s pair %d  %s  base %.4g  new %.4g  new/base %s\n' "$(date +%H:%M:%S)" "$k" "$load" "$a" "$b" "$r"
done
python3 - "${ratios[@]}" <<'PY'
import statistics, sys
v = [float(x) for x in sys.argv[1:]]
print("median new/base %.3f (min %.3f, max %.3f, %d pairs)" % (statistics.median(v), min(v), max(v), len(v)))
PY
