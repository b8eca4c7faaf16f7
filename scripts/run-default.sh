#!/usr/bin/env bash
# Runs the default demonstration with the binaries of BUILD_DIR (default: build).
#
# At this stage: a two-process loopback exchange of one coupling step of realistic size.
# `coredem-loopback serve` runs as its own process on an ephemeral tcp loopback port; the
# exchange client handshakes, configures a 100 x 400 x 10 = 4e5-cell coupling grid with 4
# species, sends every GasFields array (u_g, grad_p, T_g, rho_g, mu_g, kappa_g, cp_g, Y_g),
# receives the Sources (eps_g, K_sl, K_sl_Us, H, H_Tp, R_species, Q_hom), prints what was
# sent and how long it took, and shuts the server down. No process is left behind.
set -euo pipefail
build=${1:-build}
bin="$build/bin/coredem-loopback"
if [[ ! -x $bin ]]; then
  echo "run-default: $bin not found; build first (make run does it)" >&2
  exit 1
fi

workdir=$(mktemp -d "${TMPDIR:-/tmp}/coredem-run.XXXXXX")
server_pid=""
cleanup() {
  if [[ -n $server_pid ]] && kill -0 "$server_pid" 2>/dev/null; then
    kill "$server_pid" 2>/dev/null || true
    wait "$server_pid" 2>/dev/null || true
  fi
  rm -rf "$workdir"
}
trap cleanup EXIT

# The server stops by itself after Shutdown, or after 120 s without requests (safety net).
"$bin" serve --endpoint 'tcp://127.0.0.1:*' --endpoint-file "$workdir/endpoint" \
  --idle-limit 120 &
server_pid=$!

for _ in $(seq 200); do
  [[ -s $workdir/endpoint ]] && break
  kill -0 "$server_pid" 2>/dev/null || { echo "run-default: loopback server failed to start" >&2; exit 1; }
  sleep 0.05
done
[[ -s $workdir/endpoint ]] || { echo "run-default: loopback server did not publish its endpoint" >&2; exit 1; }
endpoint=$(cat "$workdir/endpoint")
echo "run-default: loopback server (pid $server_pid) on $endpoint"

"$bin" exchange --endpoint "$endpoint" --grid 100 400 10 --species 4 --steps 1 \
  --timeout 60 --shutdown

# Wait for the server to exit on its own after Shutdown (at most 10 s).
for _ in $(seq 200); do
  kill -0 "$server_pid" 2>/dev/null || break
  sleep 0.05
done
if kill -0 "$server_pid" 2>/dev/null; then
  echo "run-default: server still running after Shutdown; stopping it" >&2
  exit 1
fi
wait "$server_pid"
server_pid=""
echo "run-default: done"
