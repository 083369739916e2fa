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
json() { python3 -c "import json,sys; d=json.load(sys.stdin); print(eval(sys.argv[1]))" "$1"; }

"$build/simulators/lamina-sim" --link "$work/cnc" --machine "$root/config/sim-machine.toml" --modbus 127.0.0.1:0 --control 127.0.0.1:0 \
  --log "$work/exec.jsonl" --pressure-ramp 0.5 > "$work/ready" 2>/dev/null &
for _ in $(seq 100); do [[ -s "$work/ready" ]] && break; sleep 0.1; done
modbus=$(head -1 "$work/ready" | json 'd["modbus_port"]')
control=$(head -1 "$work/ready" | json 'd["control_port"]')
cat > "$work/lamina.toml" <<TOML
state_dir = "$work/state"
[server]
socket = "$work/lamina.sock"
socket_group = ""
[link]
protocol = "grbl"
port = "$work/cnc"
[cell]
modbus = "127.0.0.1:$modbus"
[planner]
lamina = "$build/daemon/lamina"
TOML
"$build/daemon/laminad" --config "$work/lamina.toml" 2> "$work/laminad.log" &
export LAMINA_SOCKET="$work/lamina.sock"
for _ in $(seq 100); do [[ -S "$LAMINA_SOCKET" ]] && break; sleep 0.1; done
lamina="$build/daemon/lamina"
id=$("$lamina" submit "$root/examples/knob.stl" --set stock=5 --json | json 'd["id"]')
while true; do
  state=$("$lamina" job "$id" --json | json 'd["state"]')
  [[ $state == waiting_sheet ]] && break
  [[ $state == queued || $state == planning || $state == planned ]] || { "$lamina" job "$id" >&2; exit 1; }
  sleep 0.5
done
"$lamina" confirm "$id" 1 > /dev/null
sleep 3  # the CNC's queue fills
echo "load: $("$build/bench/daemon_rpc_load" "$LAMINA_SOCKET" "$clients" "$seconds")"
status=$(printf 'status\n' | python3 -c "
import socket,sys; s=socket.create_connection(('127.0.0.1',$control)); s.sendall(b'status\n'); print(s.makefile().readline())")
echo "simulator: state $(echo "$status" | json 'd["state"]'), executed $(echo "$status" | json 'd["executed_blocks"]') blocks, starvation events $(echo "$status" | json 'd["starvation"]')"
"$lamina" cancel "$id" > /dev/null
