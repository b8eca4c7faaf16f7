# shellcheck shell=bash
# bench/peers/liggghts/common.sh: shell helpers shared by compare.sh and hopper.sh (sourced).
#
# The sourcing script sets SCRIPT (its name, for messages) and, before calling check_load,
# LOAD_MAX, LOAD_WAIT and ALLOW_LOAD; before require_peer_tools / liggghts_run, LIGGGHTS,
# MPIRUN, MPI_FLAGS and RUN_TIMEOUT.

die() { echo "$SCRIPT: error: $*" >&2; exit 2; }

# python3, timeout, LIGGGHTS and the MPI launcher must be there (exit 2 with how to get them).
require_peer_tools() {
  command -v python3 >/dev/null || die "python3 not found (it generates the deck)"
  command -v timeout >/dev/null || die "timeout (coreutils) not found"
  command -v "$LIGGGHTS" >/dev/null ||
    die "LIGGGHTS executable '$LIGGGHTS' not found. Install it with: scripts/install-deps.sh --with-peers (Debian packages liggghts, openmpi-bin; or apt-get install -y liggghts openmpi-bin), or point LIGGGHTS= at it."
  command -v "$MPIRUN" >/dev/null ||
    die "MPI launcher '$MPIRUN' not found. Install it with: scripts/install-deps.sh --with-peers (Debian package openmpi-bin), or point MPIRUN= at it."
}

# The load average before a run; refuses (exit 5) at >= LOAD_MAX unless ALLOW_LOAD=1.
above_max() { python3 -c "import sys; sys.exit(0 if float('$1') >= float('$LOAD_MAX') else 1)"; }
check_load() { # $1 = file to record it in, $2 = label
  local load waited=0
  load="$(cut -d' ' -f1 /proc/loadavg)"
  if [[ "$ALLOW_LOAD" != 1 ]]; then
    while above_max "$load" && [[ $waited -lt $LOAD_WAIT ]]; do
      sleep 5
      waited=$((waited + 5))
      load="$(cut -d' ' -f1 /proc/loadavg)"
    done
    [[ $waited -gt 0 ]] && echo "  (waited $waited s for the load average to fall)"
  fi
  echo "$load" >"$1"
  if above_max "$load"; then
    if [[ "$ALLOW_LOAD" == 1 ]]; then
      echo "  $2: load average $load >= $LOAD_MAX: LOADED (ALLOW_LOAD=1)"
    else
      echo "$SCRIPT: error: load average $load >= LOAD_MAX=$LOAD_MAX before $2 after waiting $LOAD_WAIT s; wait for a quiet machine or set ALLOW_LOAD=1 (such runs are labelled LOADED)" >&2
      exit 5
    fi
  else
    echo "  $2: load average $load"
  fi
}

# One LIGGGHTS run: $1 = directory to run in, $2 = input file (in $1), $3 = ranks,
# $4 = screen output file, $5 = load record file, $6 = label, $7 = 1 to print the command.
# As root it adds --allow-run-as-root; --oversubscribe only when the ranks exceed the cores.
# A failure prints the last 30 lines of the output and exits 2.
liggghts_run() {
  local rc=0 mpi_args=(-np "$3")
  [[ "$(id -u)" == 0 ]] && mpi_args+=(--allow-run-as-root)
  [[ "$3" -gt "$(nproc)" ]] && mpi_args+=(--oversubscribe)
  # shellcheck disable=SC2206
  [[ -n "$MPI_FLAGS" ]] && mpi_args+=($MPI_FLAGS)
  [[ "$7" == 1 ]] && echo "  LIGGGHTS: $MPIRUN ${mpi_args[*]} $LIGGGHTS -in $2 -log none -echo screen   (in $1)"
  check_load "$5" "$6"
  (cd "$1" && timeout "$RUN_TIMEOUT" "$MPIRUN" "${mpi_args[@]}" "$LIGGGHTS" -in "$2" -log none -echo screen \
    >"$4" 2>&1) || rc=$?
  if [[ $rc -ne 0 ]]; then
    tail -n 30 "$4" >&2 || true
    [[ $rc -eq 124 ]] && die "LIGGGHTS did not finish within RUN_TIMEOUT=$RUN_TIMEOUT s"
    die "LIGGGHTS failed (exit $rc); its last output is above"
  fi
}
