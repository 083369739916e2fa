# Sourced by the daemon benchmarks: lamina-sim (real time, 115200 baud) and laminad on $work,
# the example knob submitted, planned and its first sheet confirmed. Needs $root, $build, $work;
# $rig_tcp ("HOST:PORT", optional) also opens laminad's TCP listener with the token "bench";
# $rig_http ("HOST:PORT", optional) the web console, with the operator "bench" (password "bench").
# Leaves $lamina, $id, $control (the simulator's control port) and LAMINA_SOCKET set.
json() { python3 -c "import json,sys; d=json.load(sys.stdin); print(eval(sys.argv[1]))" "$1"; }

"$build/simulators/lamina-sim" --link "$work/cnc" --machine "$root/config/sim-machine.toml" --modbus 127.0.0.1:0 --control 127.0.0.1:0 \
  --log "$work/exec.jsonl" --pressure-ramp 0.5 > "$work/ready" 2>/dev/null &
for _ in $(seq 100); do [[ -s "$work/ready" ]] && break; sleep 0.1; done
modbus=$(head -1 "$work/ready" | json 'd["modbus_port"]')
control=$(head -1 "$work/ready" | json 'd["control_port"]')
tcp_lines=""
[[ -n "${rig_tcp:-}" ]] && tcp_lines=$'tcp = "'"$rig_tcp"$'"\ntoken = "bench"'
http_lines='listen = ""'
[[ -n "${rig_http:-}" ]] && http_lines=$'listen = "'"$rig_http"$'"\n[[http.users]]\nname = "bench"\nrole = "operator"\npassword_hash = "'"$(echo bench | "$build/daemon/laminad" --hash-password)"'"'
cat > "$work/lamina.toml" <<TOML
state_dir = "$work/state"
[server]
socket = "$work/lamina.sock"
socket_group = ""
$tcp_lines
[http]
$http_lines
[link]
protocol = "grbl"
port = "$work/cnc"
[cell]
modbus = "127.0.0.1:$modbus"
[planner]
lamina = "$build/daemon/lamina"
[jobs]
roots = ["$root/examples"]
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
