#!/usr/bin/env bash
# Do web consoles slow the daemon's other clients? (issue 19) While a job streams to lamina-sim
# (115200 baud, real time), CLIENTS RPC clients call job.list and machine.status as fast as they
# are answered for SECONDS, first with no console open, then with CONSOLES consoles logged in
# and subscribed over the WebSocket (bench/console_load.cpp), side by side in one run. Prints
# both latency lines, the consoles' update rate, and the simulator's starvation count. Under that
# load the first console presses Hold and Resume HOLDS times: each hold's time from the console to
# the controller (the '!' in lamina-sim's log, on the same CLOCK_MONOTONIC) is printed.
# Usage: bench/console_latency.sh [BUILD_DIR] [CLIENTS=50] [SECONDS=10] [CONSOLES=5] [HOLDS=3]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
clients=${2:-50}
seconds=${3:-10}
consoles=${4:-5}
holds=${5:-3}
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$work"' EXIT
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
rig_http="127.0.0.1:$port"
source "$root/bench/cell_rig.sh"
echo "no console:    $("$build/bench/daemon_rpc_load" "$LAMINA_SOCKET" "$clients" "$seconds")"
"$build/bench/console_load" "$port" bench bench "$consoles" "$((seconds + 2))" "$holds" > "$work/consoles.json" &
consoles_pid=$!
sleep 1  # logged in and subscribed
echo "$consoles consoles: $("$build/bench/daemon_rpc_load" "$LAMINA_SOCKET" "$clients" "$seconds")"
wait "$consoles_pid"
echo "consoles:      $(cat "$work/consoles.json")"
python3 - "$work/consoles.json" "$work/exec.jsonl" <<'PY'
import json, sys
sent = json.load(open(sys.argv[1]))["hold_sent_mono_s"]
holds = [r["mono_s"] for r in map(json.loads, open(sys.argv[2])) if r.get("event") == "realtime" and r.get("command") == "feed_hold"]
lat = [min((h - s for h in holds if h >= s), default=float("nan")) * 1000 for s in sent]
print("console hold → controller (ms): " + ", ".join(f"{x:.1f}" for x in lat) + (f"; max {max(lat):.1f}" if lat else ""))
PY
status=$(python3 -c "
import socket; s=socket.create_connection(('127.0.0.1',$control)); s.sendall(b'status\n'); print(s.makefile().readline())")
echo "simulator: state $(echo "$status" | json 'd["state"]'), executed $(echo "$status" | json 'd["executed_blocks"]') blocks, starvation events $(echo "$status" | json 'd["starvation"]')"
"$lamina" cancel "$id" > /dev/null
