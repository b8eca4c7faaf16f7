#!/usr/bin/env bash
# bench/remote/link.sh up NAME RTT_MS [MBIT] | down NAME | status NAME | clean
#
# An emulated remote DEM node for benchmarks (bench/remote/README.md). `up` creates a network
# namespace `coredem-link-NAME` joined to the host by a veth pair with private addresses
# (10.214.x.y/30), starts coredem-dem inside it bound to the namespace's address with CURVE and
# an allow-list holding one client key, and makes every byte between the host and that server
# take RTT_MS/2 each way (and at most MBIT Mbit/s each way when given): with `tc netem` on both
# ends of the veth where the kernel has it, else through coredem-relay started inside the
# namespace. RTT_MS 0 = the bare veth (no delay). Needs root and iproute2.
#
# `up` prints, and writes to $LINK_DIR/NAME/dem.yaml, the `dem:` section a case needs to use the
# server, e.g.
#   dem:
#     endpoint: tcp://10.214.3.6:5556
#     server_key: /tmp/coredem-link/NAME/keys/server/server.public
#     client_key: /tmp/coredem-link/NAME/keys/client
# and $LINK_DIR/NAME/env (LINK_ENDPOINT, LINK_SERVER_KEY, LINK_CLIENT_KEY, LINK_TIMERS_FILE,
# LINK_RTT_MS, LINK_MODE) for scripts: `source "$LINK_DIR/NAME/env"`. The server serves one
# session after the other until `down NAME`, which stops every process in the namespace and
# removes the veth pair, the namespace and $LINK_DIR/NAME. `clean` does that for every link
# (namespaces coredem-link-*), e.g. after a benchmark was killed.
#
# Environment: BUILD_DIR (default <project>/build: coredem-dem, coredem-relay),
#   LINK_DIR (default /tmp/coredem-link), DEM_ARGS (more coredem-dem options, e.g.
#   "--threads 2 --backend cpu"; the server always runs with --timers and writes each session's
#   stage times to $LINK_DIR/NAME/dem-timers.json).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
usage() { sed -n '2,27p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit 2; }
die() { echo "link.sh: error: $*" >&2; exit 2; }
if [[ "${1:-}" == clean ]]; then
  for n in $(ip netns list 2>/dev/null | sed -n 's/^coredem-link-\([^ ]*\).*/\1/p'); do
    "${BASH_SOURCE[0]}" down "$n"
  done
  exit 0
fi
[[ $# -ge 2 ]] || usage
cmd="$1"
name="$2"
[[ "$name" =~ ^[A-Za-z0-9_-]{1,24}$ ]] || die "NAME must be 1-24 letters, digits, - or _, got '$name'"
BUILD_DIR="${BUILD_DIR:-$root/build}"
LINK_DIR="${LINK_DIR:-/tmp/coredem-link}"
state="$LINK_DIR/$name"
ns="coredem-link-$name"
# veth names are at most 15 characters: a hash of NAME
h="$(printf '%s' "$name" | cksum | cut -d' ' -f1)"
host_veth="cl$(printf '%x' "$h" | cut -c1-7)h"
ns_veth="cl$(printf '%x' "$h" | cut -c1-7)n"
index=$((h % 16000))
net="10.214.$((index / 64))"
host_addr="$net.$(((index % 64) * 4 + 1))"
ns_addr="$net.$(((index % 64) * 4 + 2))"
dem_port=5555
relay_port=5556

link_down() {
  if ip netns list 2>/dev/null | grep -q "^$ns\b"; then
    local pids
    pids="$(ip netns pids "$ns" 2>/dev/null || true)"
    if [[ -n "$pids" ]]; then
      kill -TERM $pids 2>/dev/null || true
      for _ in $(seq 100); do
        pids="$(ip netns pids "$ns" 2>/dev/null || true)"
        [[ -z "$pids" ]] && break
        sleep 0.1
      done
      [[ -n "$pids" ]] && kill -KILL $pids 2>/dev/null || true
    fi
  fi
  ip link del "$host_veth" 2>/dev/null || true
  ip netns del "$ns" 2>/dev/null || true
  rm -rf "$state"
}

case "$cmd" in
down)
  link_down
  echo "link $name down"
  exit 0
  ;;
status)
  if ip netns list 2>/dev/null | grep -q "^$ns\b" && [[ -f "$state/env" ]]; then
    cat "$state/dem.yaml"
    echo "processes in $ns: $(ip netns pids "$ns" | tr '\n' ' ')"
    exit 0
  fi
  echo "link $name is not up"
  exit 1
  ;;
up) ;;
*) usage ;;
esac

[[ $# -ge 3 && $# -le 4 ]] || usage
rtt="$3"
mbit="${4:-0}"
[[ "$rtt" =~ ^[0-9]+([.][0-9]+)?$ ]] || die "RTT_MS must be a number >= 0, got '$rtt'"
[[ "$mbit" =~ ^[0-9]+([.][0-9]+)?$ ]] || die "MBIT must be a number >= 0, got '$mbit'"
[[ $(id -u) -eq 0 ]] || die "network namespaces need root"
command -v ip >/dev/null || die "the ip command is missing: install iproute2 (scripts/install-deps.sh)"
for p in coredem-dem coredem-relay; do
  [[ -x "$BUILD_DIR/bin/$p" ]] || die "$BUILD_DIR/bin/$p not found (build it, or set BUILD_DIR)"
done
one_way="$(awk -v r="$rtt" 'BEGIN { printf "%g", r / 2 }')"

link_down # a link of the same name left over
if ip -o addr show | grep -q " $host_addr/"; then
  die "$host_addr is already in use on this host (another link whose name has the same hash?): choose another NAME"
fi
mkdir -p "$state/keys"
trap 'echo "link.sh: up failed; removing the link" >&2; link_down' ERR
ip netns add "$ns"
ip link add "$host_veth" type veth peer name "$ns_veth" netns "$ns"
ip addr add "$host_addr/30" dev "$host_veth"
ip link set "$host_veth" up
ip netns exec "$ns" ip addr add "$ns_addr/30" dev "$ns_veth"
ip netns exec "$ns" ip link set "$ns_veth" up
ip netns exec "$ns" ip link set lo up

dem="$BUILD_DIR/bin/coredem-dem"
"$dem" --generate-curve-keys "$state/keys/server" >/dev/null
"$dem" --generate-client-key "$state/keys/client" >/dev/null
echo "$(head -c 40 "$state/keys/client/client.public") link-$name" >"$state/authorized_keys"
# shellcheck disable=SC2086  # DEM_ARGS is a list of options
# idle OpenMP threads off the cores between steps, as for the server that `coredem run` starts
OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}" ip netns exec "$ns" "$dem" --bind "tcp://$ns_addr:$dem_port" --curve-keys "$state/keys/server" \
  --client-keys "$state/authorized_keys" --endpoint-file "$state/dem-endpoint" \
  --timers --timers-every 0 --timers-file "$state/dem-timers.json" ${DEM_ARGS:-} \
  >"$state/dem.log" 2>&1 </dev/null &
for _ in $(seq 300); do
  [[ -s "$state/dem-endpoint" ]] && break
  kill -0 $! 2>/dev/null || break
  sleep 0.1
done
[[ -s "$state/dem-endpoint" ]] || { tail -5 "$state/dem.log" >&2; false; }

endpoint="tcp://$ns_addr:$dem_port"
mode="bare veth"
if [[ "$rtt" != "0" || "$mbit" != "0" ]]; then
  netem_args=()
  [[ "$rtt" != "0" ]] && netem_args+=(delay "${one_way}ms")
  [[ "$mbit" != "0" ]] && netem_args+=(rate "${mbit}mbit")
  if tc qdisc add dev "$host_veth" root netem "${netem_args[@]}" 2>/dev/null; then
    ip netns exec "$ns" tc qdisc add dev "$ns_veth" root netem "${netem_args[@]}"
    mode="tc netem"
  else
    ip netns exec "$ns" "$BUILD_DIR/bin/coredem-relay" --listen "$ns_addr:$relay_port" \
      --target "$ns_addr:$dem_port" --delay-ms "$one_way" --mbit "$mbit" \
      --port-file "$state/relay-port" >"$state/relay.log" 2>&1 </dev/null &
    for _ in $(seq 100); do
      [[ -s "$state/relay-port" ]] && break
      sleep 0.1
    done
    [[ -s "$state/relay-port" ]] || { cat "$state/relay.log" >&2; false; }
    endpoint="tcp://$ns_addr:$relay_port"
    mode="coredem-relay (no netem qdisc in this kernel)"
  fi
fi
trap - ERR

cat >"$state/dem.yaml" <<EOF
dem:
  endpoint: $endpoint
  server_key: $state/keys/server/server.public
  client_key: $state/keys/client
EOF
cat >"$state/env" <<EOF
LINK_ENDPOINT=$endpoint
LINK_SERVER_KEY=$state/keys/server/server.public
LINK_CLIENT_KEY=$state/keys/client
LINK_TIMERS_FILE=$state/dem-timers.json
LINK_RTT_MS=$rtt
LINK_MODE="$mode"
EOF
bw="unlimited bandwidth"
[[ "$mbit" != "0" ]] && bw="$mbit Mbit/s each way"
echo "link $name up: coredem-dem in namespace $ns at $ns_addr (host end $host_addr), round trip $rtt ms, $bw, by $mode"
echo "# a case's dem section ($state/dem.yaml; add backend/threads as needed):"
cat "$state/dem.yaml"
