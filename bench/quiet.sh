# shellcheck shell=bash
# Sourced by the benchmark scripts (bench/ab.sh, bench/coupling/staggered.sh,
# bench/remote/overhead.sh): waits for a quiet machine before a timed run.
#
#   wait_quiet    waits up to 240 s for the 1-minute load average to fall below LOAD_MAX
#                 (default 0.5) and prints "load L", or "load L LOADED" when it did not: one
#                 reading decides both the wait and the label, and a LOADED run proves nothing
#                 about a ratio (docs/performance.md).
LOAD_MAX="${LOAD_MAX:-0.5}"
_quiet_below_max() { awk -v l="$1" -v m="$LOAD_MAX" 'BEGIN { exit !(l + 0 < m + 0) }'; }
wait_quiet() {
  local w=0 l
  l="$(cut -d' ' -f1 /proc/loadavg)"
  while ! _quiet_below_max "$l" && [[ $w -lt 240 ]]; do
    sleep 5
    w=$((w + 5))
    l="$(cut -d' ' -f1 /proc/loadavg)"
  done
  if _quiet_below_max "$l"; then echo "load $l"; else echo "load $l LOADED"; fi
}
