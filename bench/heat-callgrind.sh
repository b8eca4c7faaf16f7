#!/usr/bin/env bash
# bench/heat-callgrind.sh BUILD_DIR [N] [STEPS] [BASE_BUILD_DIR]
#
# Instructions of the DEM heat stage (docs/performance.md "Heat stage"), counted by callgrind
# (valgrind), so that the figures do not depend on the machine's load: coredem-bench dem
# --case packed --coupled --skin 0.1 --threads 1, N particles (default 20000), STEPS sub-steps
# (default 40), on the lattice deck and with --jitter 0.02 (bench/decks.md), each with and
# without --heat; the heat stage is the difference (the mechanics are identical). Prints the
# totals and the heat stage in instructions per particle and sub-step. With BASE_BUILD_DIR, the
# same for that build first and the change. Needs valgrind; a run of N = 20000 takes about a
# minute per deck and build.
set -euo pipefail
[[ $# -ge 1 ]] || { sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
command -v valgrind >/dev/null || { echo "heat-callgrind.sh: valgrind not found" >&2; exit 2; }
new="$1/bin/coredem-bench"
n="${2:-20000}"
steps="${3:-40}"
base="${4:+$4/bin/coredem-bench}"
for b in "$new" ${base:+"$base"}; do
  [[ -x "$b" ]] || { echo "heat-callgrind.sh: $b not found; build the target coredem-bench" >&2; exit 2; }
done
out="$(mktemp -d "${TMPDIR:-/tmp}/coredem-heat-cg.XXXXXX")"
trap 'rm -rf "$out"' EXIT

count() { # binary extra-args... -> total instructions
  local bin="$1"; shift
  valgrind --tool=callgrind --callgrind-out-file="$out/cg.out" "$bin" dem --case packed \
    --particles "$n" --steps "$steps" --warmup 0 --skin 0.1 --threads 1 --coupled "$@" \
    >"$out/run.log" 2>&1 || { cat "$out/run.log" >&2; exit 1; }
  sed -n 's/^summary: *\([0-9]*\).*/\1/p' "$out/cg.out"
}

declare -A heat
for tag in ${base:+base} new; do
  bin="$new"
  [[ "$tag" == base ]] && bin="$base"
  for deck in lattice jitter; do
    extra=()
    [[ "$deck" == jitter ]] && extra=(--jitter 0.02)
    off=$(count "$bin" "${extra[@]}")
    on=$(count "$bin" "${extra[@]}" --heat)
    heat[$tag.$deck]=$((on - off))
    awk -v t="$tag" -v d="$deck" -v on="$on" -v off="$off" -v n="$n" -v s="$steps" 'BEGIN {
      printf "%-4s %-7s total %.1f M with heat, %.1f M without; heat stage %.1f M = %.0f per particle and sub-step\n",
             t, d, on / 1e6, off / 1e6, (on - off) / 1e6, (on - off) / (n * s) }'
  done
done
if [[ -n "$base" ]]; then
  for deck in lattice jitter; do
    awk -v d="$deck" -v b="${heat[base.$deck]}" -v w="${heat[new.$deck]}" 'BEGIN {
      printf "change  %-7s heat stage %+.1f %%\n", d, 100 * (w - b) / b }'
  done
fi
