#!/usr/bin/env bash
# laminad under load (issue 7): while a job streams to lamina-sim (115200 baud, real time), 50
# clients call job.list and machine.status as fast as they are answered for 20 s. Prints the
# latency percentiles and the simulator's starvation count (must stay 0: serving clients must
# not starve the CNC). Usage: bench/daemon_latency.sh [BUILD_DIR] [CLIENTS] [SECONDS]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
clients=${2:-50}
seconds=${3:-20}
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$work"' EXIT
source "$root/bench/cell_rig.sh"
echo "load: $("$build/bench/daemon_rpc_load" "$LAMINA_SOCKET" "$clients" "$seconds")"
status=$(printf 'status\n' | python3 -c "
import socket,sys; s=socket.create_connection(('127.0.0.1',$control)); s.sendall(b'status\n'); print(s.makefile().readline())")
echo "simulator: state $(echo "$status" | json 'd["state"]'), executed $(echo "$status" | json 'd["executed_blocks"]') blocks, starvation events $(echo "$status" | json 'd["starvation"]')"
"$lamina" cancel "$id" > /dev/null
