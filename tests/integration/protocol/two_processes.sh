#!/usr/bin/env bash
# Two separate processes over tcp loopback: coredem-loopback serve + exchange (3 steps on a
# 40x20x5 grid), then Shutdown; the server must exit by itself with status 0.
set -euo pipefail
bin=$1
dir=$(mktemp -d)
trap 'kill "$server_pid" 2>/dev/null || true; rm -rf "$dir"' EXIT
"$bin" serve --endpoint 'tcp://127.0.0.1:*' --endpoint-file "$dir/endpoint" --idle-limit 60 &
server_pid=$!
for _ in $(seq 100); do [[ -s $dir/endpoint ]] && break; sleep 0.1; done
[[ -s $dir/endpoint ]] || { echo "server did not publish its endpoint"; exit 1; }
"$bin" exchange --endpoint "$(cat "$dir/endpoint")" --grid 40 20 5 --species 3 --steps 3 \
  --timeout 30 --shutdown | tee "$dir/out"
grep -q "checksums match" "$dir/out"
grep -q "shutdown acknowledged" "$dir/out"
# The server exits on its own after Shutdown (wait at most 10 s).
for _ in $(seq 100); do kill -0 "$server_pid" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$server_pid" 2>/dev/null; then echo "server still running after Shutdown"; exit 1; fi
wait "$server_pid"
